"""Single rays through a library emit's `intersect`, on GL (tests/data/rays.frag.j2): the
tests of the exact and interval methods ask it for rays whose first root is known in
closed form."""

from __future__ import annotations

from pathlib import Path

import jinja2
import numpy as np

from implc.emit import emit, render_template
from implc.surface import Surface

DATA = Path(__file__).parent / "data"


def intersect(surface: Surface, method: str, rays: list[tuple]) -> np.ndarray:
    """(hit, t) of each (ro, rd, t0, t1); rd is normalised here."""
    uniforms = {"u_ro": [r[0] for r in rays],
                "u_rd": [tuple(np.asarray(r[1]) / np.linalg.norm(r[1])) for r in rays],
                "u_span": [(r[2], r[3]) for r in rays]}
    return _run(surface, method, "rays.frag.j2", len(rays), uniforms)[:, :2]


def shade(surface: Surface, gradients: list[tuple], rd: tuple) -> np.ndarray:
    """The library's `shade(g, rd)` colour (r, g, b) of each gradient g, seen along rd."""
    uniforms = {"u_g": [tuple(map(float, g)) for g in gradients], "u_rd": tuple(rd)}
    return _run(surface, "hessian", "shade.frag.j2", len(gradients), uniforms)[:, :3]


def _run(surface: Surface, method: str, harness: str, count: int, uniforms: dict) -> np.ndarray:
    """One pixel a case: the harness around the surface's GLSL library, (count, 4) floats."""
    import moderngl

    from implc.render.gl import context

    library = emit(surface, "glsl", method, None, "330", "library", "x_")
    env = jinja2.Environment(loader=jinja2.FileSystemLoader(str(DATA)),
                             undefined=jinja2.StrictUndefined)
    fragment = env.get_template(harness).render(count=count, library=library, prefix="x_")
    vertex = render_template("glsl/fullscreen.vert.j2", version="330 core")
    ctx = context()
    program = ctx.program(vertex_shader=vertex, fragment_shader=fragment)
    for name, value in uniforms.items():
        program[name].value = value
    out = ctx.texture((count, 1), 4, dtype="f4")
    aux = ctx.texture((count, 1), 4, dtype="f4")
    fbo = ctx.framebuffer(color_attachments=[out, aux])
    fbo.use()
    fbo.viewport = (0, 0, count, 1)
    ctx.vertex_array(program, []).render(mode=moderngl.TRIANGLES, vertices=3)
    return np.frombuffer(fbo.read(components=4, dtype="f4"), np.float32).reshape(-1, 4)
