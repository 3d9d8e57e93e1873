"""The records the API returns: a compiled shader and a rendering.

Both are immutable and carry what the pipeline decided (the method, the evaluation form,
the view, the uniforms) and what a user should know (`warnings`, `notes`), so no client
decides it again. Both show themselves in Jupyter: a Rendering as its PNG, and as HTML
with a caption and its warnings (which a bare PNG would hide); a Shader as its summary,
warnings and text.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ..emit import CompiledShader, render_template
from ..errors import ValidationError
from ..fileio import write_atomic
from ..options import GPU_FAMILIES
from ..scene import View
from ..targets import get_target

if TYPE_CHECKING:
    import numpy as np

    from ..render.gpu_stats import GpuStats
    from ..render.result import RenderResult
    from ..surface import Surface as SurfaceRecord
    from ..validate import Verdict


@dataclass(frozen=True)
class Shader(CompiledShader):
    """A compiled shader: `text`, and the `target`, `method`, evaluation `form`, `flavor`,
    `precision`, `emit` form, `prefix`, `uniforms` and `constants` it was compiled with.
    `warnings` are what a user should know about its pictures (float32 that cannot hold
    the surface, a constant the method does not read); `notes` what was chosen for it
    (the framing)."""

    float32: str | None = None  # the float32 measure's finding alone (the CLI's remedy)

    @classmethod
    def of(cls, compiled: CompiledShader, **changes: Any) -> Shader:
        fields = {f.name: getattr(compiled, f.name) for f in dataclasses.fields(compiled)}
        return cls(**{**fields, **changes})

    def __str__(self) -> str:
        return self.text

    @property
    def extension(self) -> str:
        """The file extension this shader is saved with (`.frag`, `.wgsl`, `.cl`, ...)."""
        return get_target(self.target).emit_extensions[self.emit]

    def validate(self, name: str | None = None) -> Verdict:
        """Compile the text with its language's real compiler (glslangValidator, naga,
        PoCL, glslang's HLSL front end); raise ValidationError with the tool's messages
        if it refuses, else return the verdict."""
        from ..validate import validate_text

        name = name or f"<{self.method}>{self.extension}"
        verdict = validate_text(self.text, self.target, name)
        if not verdict.ok:
            raise ValidationError(verdict.render(name))
        return verdict

    def gpu_stats(self, families: Sequence[str] = GPU_FAMILIES) -> list[GpuStats]:
        """What AMD's compiler (ACO, in Mesa's RADV, on a null device: no GPU needed) makes
        of this program on each family: VGPRs, SGPRs, spills, scratch, waves per SIMD,
        instructions. For an HLSL or a desktop GLSL (330, 450) program; ToolError where
        RADV is absent."""
        from ..render.gpu_stats import gpu_stats

        return [rows[0] for rows in gpu_stats([self], families).values()]

    def save(self, path: str | Path) -> Path:
        """Write the text to `path` (atomically: no partial file) and return the path."""
        path = Path(path)
        write_atomic(path, self.text)
        return path

    def summary(self) -> str:
        """One line: target, emit form, method, evaluation form, precision, size."""
        parts = [f"{self.target} {self.emit}", f"method {self.method}", f"form {self.form}",
                 self.precision, f"{self.text.count(chr(10))} lines"]
        if self.prefix:
            parts.insert(1, f"prefix {self.prefix}")
        return " · ".join(parts)

    def _repr_html_(self) -> str:
        return render_template("notebook/shader.html.j2", summary=self.summary(),
                               warnings=list(self.warnings), text=self.text)


@dataclass(frozen=True)
class Rendering:
    """One frame of a surface: `image` (uint8, height x width x 3, row 0 on top), `aux`
    (per pixel: hit, t, steps, |S| at the hit), `hit_fraction`, the `view` it was taken
    from, `timing` (seconds: setup, compile, frame), and `warnings` and `notes`."""

    surface: SurfaceRecord  # the framed surface it shows
    backend: str
    shader: Shader | None  # None: the CPU reference, which runs no shader
    result: RenderResult
    picture_warnings: tuple[str, ...] = ()  # about the picture: nothing hit, clipped
    notes: tuple[str, ...] = ()

    @property
    def warnings(self) -> tuple[str, ...]:
        """What a user should know: the picture's warnings, then its shader's."""
        return self.picture_warnings + (self.shader.warnings if self.shader else ())

    @property
    def method(self) -> str:
        return "reference" if self.shader is None else self.shader.method

    @property
    def view(self) -> View:
        return self.surface.view

    @property
    def width(self) -> int:
        return self.result.width

    @property
    def height(self) -> int:
        return self.result.height

    @property
    def color(self) -> np.ndarray:
        """float32, height x width x 3, in [0, 1]."""
        return self.result.color

    @property
    def image(self) -> np.ndarray:
        """The picture as a PNG holds it: uint8, clipped and rounded."""
        import numpy as np

        image: np.ndarray = np.round(np.clip(self.result.color, 0.0, 1.0) * 255.0)
        return image.astype(np.uint8)

    @property
    def aux(self) -> dict[str, np.ndarray]:
        """hit (bool), t (distance from the eye), steps, residual (|S| at the hit)."""
        r = self.result
        return {"hit": r.hit, "t": r.t, "steps": r.steps, "residual": r.residual}

    @property
    def hit_fraction(self) -> float:
        return float(self.result.hit.mean())

    @property
    def timing(self) -> dict[str, float]:
        return dict(self.result.timing)

    def metadata(self) -> dict[str, Any]:
        """The JSON sidecar: camera, surface, method and timing, enough to recompute
        every pixel's ray."""
        from ..render.run import metadata

        return metadata(self.surface, self.backend, self.shader, self.result)

    def save(self, path: str | Path) -> list[Path]:
        """Write `path` (.png for people, .exr with R G B A Z steps for tools) and the JSON
        sidecar beside it; the paths written."""
        from ..fileio import check_output
        from ..render.image_io import write_render

        path = Path(path)
        check_output(path, (".png", ".exr"), what="a render",
                     sidecars=(".json",))
        return write_render(self.result, path, self.metadata())

    def png(self) -> bytes:
        """The picture as PNG bytes."""
        from PIL import Image

        return png_bytes(Image.fromarray(self.image, "RGB"))

    def _repr_png_(self) -> bytes:
        return self.png()

    def html(self, title: str | None = None) -> str:
        """The picture as an HTML figure: the PNG inline, a caption (backend, method, hit
        fraction, frame time) and every warning."""
        import base64

        caption = (f"{self.width}×{self.height} {self.backend}/{self.method} · "
                   f"{100 * self.hit_fraction:.1f} % hit · frame "
                   f"{1000 * self.timing.get('frame', 0.0):.1f} ms")
        return render_template("notebook/figure.html.j2",
                               png=base64.b64encode(self.png()).decode("ascii"),
                               width=self.width, height=self.height,
                               title=title or self.surface.name, caption=caption,
                               warnings=[w.removeprefix("implc: warning: ")
                                         for w in self.warnings])

    def _repr_html_(self) -> str:
        return self.html()

    def __repr__(self) -> str:
        return (f"<Rendering {self.surface.name!r} {self.width}x{self.height} "
                f"{self.backend}/{self.method}: {100 * self.hit_fraction:.1f} % hit>")


def png_bytes(image: Any) -> bytes:
    """A PIL image as PNG bytes (a thumbnail, a contact sheet)."""
    import io

    buffer = io.BytesIO()
    image.save(buffer, format="PNG")
    return buffer.getvalue()
