"""What every runner returns: the shaded image and its per-pixel aux buffers."""

from __future__ import annotations

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

    @property
    def height(self) -> int:
        return int(self.hit.shape[0])

    @property
    def width(self) -> int:
        return int(self.hit.shape[1])
