"""What every runner returns: the shaded image and its per-pixel aux buffers."""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np


@dataclass
class RenderResult:
    """Arrays have shape (height, width[, 3]); row 0 is the top of the image.

    `t` is the distance from the eye along the unit ray direction (0 where no hit);
    `steps` the number of march steps taken; `residual` |F| = |S| at the hit point.
    """

    color: np.ndarray  # float32 (H, W, 3) in [0, 1]
    hit: np.ndarray  # bool (H, W)
    t: np.ndarray  # float32 (H, W)
    steps: np.ndarray  # float32 (H, W)
    residual: np.ndarray  # float32 (H, W)
    timing: dict[str, float] = field(default_factory=dict)  # seconds, by phase

    @classmethod
    def from_buffers(cls, color: np.ndarray, aux: np.ndarray) -> RenderResult:
        """From the (H, W, 4) float buffers every shader writes, row 0 on top:
        colour (r, g, b, 1) and aux (hit, t, steps, |S|)."""
        return cls(
            color=np.ascontiguousarray(color[..., :3]),
            hit=aux[..., 0] > 0.5,
            t=np.ascontiguousarray(aux[..., 1]),
            steps=np.ascontiguousarray(aux[..., 2]),
            residual=np.ascontiguousarray(aux[..., 3]),
        )

    @property
    def height(self) -> int:
        return int(self.hit.shape[0])

    @property
    def width(self) -> int:
        return int(self.hit.shape[1])


class TimedRunner:
    """Base of the GPU runners: `frame()` = draw, wait for completion, read back, timed;
    `warm_up()` first, so that no timed frame holds the driver's compile."""

    def draw(self) -> None:
        raise NotImplementedError

    def read(self) -> RenderResult:
        raise NotImplementedError

    def warm_up(self) -> float:
        """Use the program once before any timed frame and return the seconds it took.

        A driver may compile a shader at its first use rather than when the program is
        built: llvmpipe does at the first draw (1.2 s for Barth's decic with `exact` at
        256², then 0.04 s a frame), lavapipe at the first dispatch, PoCL at the first
        launch of a work-group size. That compile is reported as its own figure
        (`timing.compile`) and kept out of `timing.frame`. The default uses one whole
        frame (read back, so it has waited); a runner that can trigger its compile with
        less work (GL: one pixel) overrides `first_use`."""
        start = time.perf_counter()
        self.first_use()
        return time.perf_counter() - start

    def first_use(self) -> None:
        self.draw()
        self.read()

    def frame(self) -> RenderResult:
        start = time.perf_counter()
        self.draw()
        result = self.read()
        result.timing["frame"] = time.perf_counter() - start
        return result
