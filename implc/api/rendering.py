"""The render behind `Surface.render`: size and backend resolved, the surface framed for
the picture's shape, its program compiled once (`compile_record`) and run by the backend's
runner, and what the picture needs said (`picture_checks`) put on the record."""

from __future__ import annotations

import time
from collections.abc import Mapping
from typing import Any

from ..errors import InputError, OptionError
from ..options import MAX_IMAGE
from .compiling import Framable, compile_record, resolve_method
from .records import Rendering


def picture_size(size: int | None, width: int | None, height: int | None) -> tuple[int, int]:
    """`size`, or `width`/`height` (each defaults to the other, then to 512)."""
    for key, value in (("size", size), ("width", width), ("height", height)):
        if value is not None and (isinstance(value, bool) or not isinstance(value, int)
                                  or not 1 <= value <= MAX_IMAGE):
            raise OptionError(f"{key} must be an integer from 1 to {MAX_IMAGE}, got {value!r}")
    width_, height_ = width or height or size or 512, height or width or size or 512
    return width_, height_


def choose_backend(backend: str | None, precision: str | None) -> str:
    """`backend` (default gl) at `precision` (`cl` at "double" is `cl-double`)."""
    from ..render.run import BACKENDS, REFERENCE, backend_for

    backend = backend or "gl"
    if backend not in BACKENDS and backend != REFERENCE:
        raise OptionError(f"unknown backend '{backend}'; choose from "
                          f"{', '.join([*BACKENDS, REFERENCE])}")
    try:
        return backend_for(backend, precision)
    except InputError as err:
        raise OptionError(err.message) from None


def render_surface(surface: Framable, size: int | None = 512, *, width: int | None,
                   height: int | None, backend: str | None, method: str | None,
                   precision: str | None, params: str, constants: Mapping[str, Any]) -> Rendering:
    """`Surface.render`."""
    from ..framing import check_frame
    from ..methods import METHODS
    from ..picture_checks import picture_warnings
    from ..render.run import (
        BACKENDS,
        REFERENCE,
        backend_target,
        open_runner,
        open_shader_runner,
        run_frame,
    )

    w, h = picture_size(size if width is None and height is None else None, width, height)
    backend = choose_backend(backend, precision)
    record, framing = surface.framed()
    notes: tuple[str, ...] = (framing.message(),) if framing is not None else ()
    check_frame(record, w, h)
    start = time.perf_counter()
    if backend == REFERENCE:
        resolved, values = resolve_method(surface, method, constants)
        runner = open_runner(record, REFERENCE, resolved, values, w, h)
        shader = None
    else:
        shader = compile_record(
            surface, record, backend_target(backend).name, method, emit="program",
            prefix="", flavor=BACKENDS[backend].flavor or None,
            precision=None if BACKENDS[backend].precision == "float"
            else BACKENDS[backend].precision, params=params, constants=constants, notes=notes)
        runner = open_shader_runner(shader, backend, record.view, w, h)
        notes = shader.notes
    result = run_frame(runner, time.perf_counter() - start)
    given_radius = surface.view_options.radius is not None
    max_steps = None
    if shader is not None and "max_steps" in METHODS[shader.method].reads:
        max_steps = shader.constants.max_steps
    picture = tuple(picture_warnings(record, result, given_radius, max_steps))
    return Rendering(record, backend, shader, result, picture, notes)

