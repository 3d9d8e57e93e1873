"""`implc.Surface`: a surface to compile, render and look at, from Python.

The same pipeline and defaults as the command line, which is a client of this class:
the method by surface (`exact` for polynomials to degree 20, `interval` where every
function has an interval rule, else `hessian`), automatic framing where no view is given,
limits against hostile input. A Surface is immutable: `with_params` and `with_view` return
new ones. Errors are exceptions (`InputError` with file, line, column and caret;
`OptionError` for an option that does not fit), never an exit or a print.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from functools import cached_property
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ..errors import OptionError
from ..limits import Limits
from ..scene import ViewOptions
from .sympy_input import equation_text

if TYPE_CHECKING:
    import sympy

    from ..scene import Framing, View
    from ..surface import Surface as SurfaceRecord
    from .exporting import HostFiles
    from .records import Rendering, Shader
    from .widget import Viewer

Point = tuple[float, float, float]
INLINE_SIZE = 256  # the side of the picture a notebook shows
_AXES = {"x": 0, "y": 1, "z": 2}


class Surface:
    """An implicit surface S(x, y, z) = 0.

    >>> import implc
    >>> s = implc.Surface("x^2 + y^2 + z^2 = 1")
    >>> s.degree, s.default_method
    (2, 'exact')
    """

    def __init__(self, equation: Any, *, params: Mapping[str, object] | None = None,
                 name: str | None = None, limits: Limits | None = None) -> None:
        """`equation`: text in implc's input language (`"x^2 + y^2 + z^2 = 1"`), a sympy
        expression or equation, or anything with `_sympy_()` (SageMath's symbolic
        expressions); checked by the same limits and function table as text. `params`:
        values of the equation's named parameters (numbers or constant expressions)."""
        self._init(None, equation_text(equation, limits or Limits()), _param_args(params),
                   limits, ViewOptions(), name)

    def _init(self, spec: str | None, equation: str | None, params: tuple[str, ...],
              limits: Limits | None, options: ViewOptions, name: str | None) -> None:
        self._spec, self._equation, self._params = spec, equation, params
        self._limits, self._options, self._name = limits or Limits(), options, name
        _ = self.record  # load now: a bad input raises here, not at the first render

    @classmethod
    def load(cls, path: str | Path, *, params: Mapping[str, object] | None = None,
             limits: Limits | None = None) -> Surface:
        """A surface file: TOML (docs/reference/input-language.md "Surface files") or SURFER's
        `.jsurf`."""
        return cls._make(str(path), None, _param_args(params), limits)

    @classmethod
    def example(cls, name: str, *, params: Mapping[str, object] | None = None,
                limits: Limits | None = None) -> Surface:
        """A bundled example by name (`implc.examples()` lists them), e.g. "cross-cap"."""
        return cls._make(name, None, _param_args(params), limits)

    @classmethod
    def _make(cls, spec: str | None, equation: str | None, params: tuple[str, ...],
              limits: Limits | None, options: ViewOptions = ViewOptions(),  # noqa: B008
              name: str | None = None) -> Surface:
        surface = cls.__new__(cls)
        surface._init(spec, equation, params, limits, options, name)
        return surface

    @classmethod
    def from_args(cls, spec: str | None, equation: str | None, params: tuple[str, ...],
                  limits: Limits, options: ViewOptions) -> Surface:
        """The command line's surface: a file or example name, or `-e` text, with
        `--param NAME=VALUE` strings (their errors point into the argument)."""
        return cls._make(spec, equation, params, limits, options)

    # --- what it is ----------------------------------------------------------------

    @cached_property
    def record(self) -> SurfaceRecord:
        """The loaded surface as the pipeline's stages read it (view not yet framed)."""
        import dataclasses

        from ..loaders import load_surface

        record = load_surface(self._spec, self._equation, self._params, self._limits)
        return dataclasses.replace(record, name=self._name) if self._name else record

    @property
    def name(self) -> str:
        return self.record.name

    @property
    def equation(self) -> str:
        """The equation as implc prints it from its tree, parameters by name."""
        return self.record.symbolic_equation

    @property
    def expr(self) -> sympy.Expr:
        """S as a sympy expression (parameters substituted); the surface is S = 0."""
        return self.record.expr

    @property
    def params(self) -> dict[str, float]:
        return self.record.params_json()

    @property
    def notes(self) -> tuple[str, ...]:
        """What loading had to say (a .jsurf file's keys implc does not use)."""
        return self.record.notes

    @cached_property
    def degree(self) -> int | None:
        """Total degree in x, y, z; None for a surface that is not a polynomial."""
        from ..derive import polynomial_degree

        return polynomial_degree(self.record.expr)

    @cached_property
    def default_method(self) -> str:
        """The method used when none is named: exact, interval or hessian."""
        from ..marcher import default_method

        return default_method(self.record.expr)

    @property
    def view(self) -> View:
        """The view every picture of it uses (framed for a square picture)."""
        return self.framed()[0].view

    def __repr__(self) -> str:
        kind = f"degree {self.degree}" if self.degree is not None else "not a polynomial"
        return f"<implc.Surface {self.name!r}: {self.equation} ({kind})>"

    # --- new surfaces from this one ------------------------------------------------

    def with_params(self, **values: object) -> Surface:
        """The same surface with these parameter values (numbers or constant
        expressions such as "(1 + sqrt(5))/2")."""
        merged = {arg.partition("=")[0]: arg for arg in self._params}
        merged.update({arg.partition("=")[0]: arg for arg in _param_args(values)})
        return self._make(self._spec, self._equation, tuple(merged.values()), self._limits,
                          self._options, self._name)

    def with_view(self, *, radius: float | None = None, center: Point | None = None,
                  eye: Point | None = None, target: Point | None = None,
                  up: Point | str | None = None, fov: float | None = None) -> Surface:
        """The same surface seen otherwise: each value overrides the file's [view] key of
        the same name; what neither sets is framed automatically. `up` may be an axis
        ("z", "-y") or a direction."""
        old = self._options

        def keep(new: Any, key: str) -> Any:
            return getattr(old, key) if new is None else new

        options = ViewOptions(
            radius=keep(_number(radius, "radius", 0.0, 1e6), "radius"),
            center=keep(_point(center, "center"), "center"),
            eye=keep(_point(eye, "eye"), "eye"), target=keep(_point(target, "target"), "target"),
            up=keep(_up(up), "up"), fov=keep(_number(fov, "fov", 0.0, 180.0), "fov"))
        return self._make(self._spec, self._equation, self._params, self._limits, options,
                          self._name)

    def framed(self) -> tuple[SurfaceRecord, Framing | None]:
        """The record with its view completed (for every picture size: the fov spans the
        shorter side), and what framing chose (None: nothing was left to choose)."""
        return self._framing

    @cached_property
    def _framing(self) -> tuple[SurfaceRecord, Framing | None]:
        from ..framing import frame

        return frame(self.record, self._options)

    @property
    def view_options(self) -> ViewOptions:
        """The view values given by `with_view` (None: not given)."""
        return self._options

    # --- what it becomes -----------------------------------------------------------

    def compile(self, target: str = "glsl", method: str | None = None, *,
                emit: str = "program", prefix: str = "", flavor: str | None = None,
                precision: str | None = None, params: str = "constant",
                **constants: Any) -> Shader:
        """The shader for `target` (glsl, wgsl, opencl, hlsl): a complete program or,
        with emit="library", the drop-in functions under `prefix`. `params="uniform"`
        keeps the parameters as uniforms; `constants` are the method's (step, tau1, ...,
        evaluation). Where float32 cannot hold the surface and no precision is named,
        `warnings` says so."""
        from .compiling import compile_surface

        return compile_surface(self, target, method, emit=emit, prefix=prefix,
                               flavor=flavor, precision=precision, params=params,
                               constants=constants)

    def export(self, host: str, method: str | None = None, *, precision: str | None = None,
               prefix: str | None = None, **constants: Any) -> HostFiles:
        """The files `host` loads (see `implc.HOSTS`: three, unity, ...), the parameters as
        its own controls and how to use them at the top; `.save(directory)` writes them."""
        from .exporting import export_surface

        return export_surface(self, host, method, precision=precision, prefix=prefix,
                              command=f"implc export {self.name!r} --host {host}",
                              constants=constants)

    def render(self, size: int = 512, *, width: int | None = None,
               height: int | None = None, backend: str | None = None,
               method: str | None = None, precision: str | None = None,
               params: str = "constant", **constants: Any) -> Rendering:
        """One frame, headless: backend "gl" (default; llvmpipe here), "gl-double",
        "wgpu", "cl", "cl-double", "hlsl-spirv" or "reference" (the exact CPU float64
        reference). `precision="double"` picks the backend's double sibling."""
        from .rendering import render_surface

        return render_surface(self, size, width=width, height=height, backend=backend,
                              method=method, precision=precision, params=params,
                              constants=constants)

    def view_page(self, method: str | None = None, *, webgpu: bool = True,
                  **constants: Any) -> str:
        """The self-contained HTML viewer page (`implc view`): WebGL2, WebGPU where the
        browser has it, orbit and zoom, a slider per parameter."""
        from ..view import viewer_page
        from .compiling import resolve_method

        method, values = resolve_method(self, method, constants)
        return viewer_page(self.framed()[0], method, values, webgpu=webgpu)

    def show(self, method: str | None = None, *, size: int = 384, webgpu: bool = True,
             backend: str = "webgl2", **constants: Any) -> Viewer:
        """The live viewer as a notebook widget (anywidget: JupyterLab, Notebook 7, VS Code,
        Colab, marimo): the shaders compiled here, drawn by the browser on a `size`-pixel
        square; `w.params = {"a": 0.3}` moves the picture, moving a slider sets
        `w.params`. Needs the `notebook` extra (`pip install implc[notebook]`)."""
        from ..view import viewer_data
        from .compiling import resolve_method

        try:
            from .widget import Viewer
        except ImportError as err:  # anywidget absent: say what to install
            raise ImportError("Surface.show() needs anywidget: pip install 'implc[notebook]'"
                              ) from err
        method, values = resolve_method(self, method, constants)
        data = viewer_data(self.framed()[0], method, values, webgpu=webgpu)
        return Viewer(data, size=size, backend=backend)

    def describe(self, method: str | None = None) -> str:
        """What implc understood and will compute (`implc show`): the equation, degree,
        derivatives, operation counts and float32's measures."""
        from ..methods import METHODS
        from ..show import describe

        return describe(self.record, METHODS[method or self.default_method])

    def to_jsurf(self) -> str:
        """The surface and its view as a SURFER/jsurf `.jsurf` file."""
        from ..loaders import to_jsurf

        return to_jsurf(self.framed()[0])

    def inline(self) -> Rendering:
        """The picture a notebook shows: 256² with the default method, rendered once (the
        PNG and the HTML forms share it). No GPU is assumed: headless GL (llvmpipe where
        there is no GPU), and where the kernel cannot open a GL context at all, the exact
        CPU reference (its caption names the backend; ~1.5-3 s at 256²)."""
        if "_inline" not in self.__dict__:
            from ..errors import ToolError
            from ..render.gl import context

            try:
                context()
                backend = "gl"
            except ToolError:
                backend = "reference"
            self.__dict__["_inline"] = self.render(INLINE_SIZE, backend=backend)
        rendering: Rendering = self.__dict__["_inline"]
        return rendering

    def _repr_png_(self) -> bytes:
        """Jupyter's inline picture (`inline`); the first in a fresh kernel, import
        included, takes about 1-2 s here (docs/api.md)."""
        return self.inline().png()

    def _repr_html_(self) -> str:
        """The same picture with its equation, method and warnings beside it."""
        return self.inline().html(f"{self.name}: {self.equation}")


def _param_args(params: Mapping[str, object] | None) -> tuple[str, ...]:
    """{"a": 0.5} -> ("a=0.5",): the values as implc's own parser reads them (never
    sympify): numbers, or constant expressions written as text."""
    args = []
    for name, value in (params or {}).items():
        if isinstance(value, bool):
            raise OptionError(f"parameter {name}: expected a number, got {value!r}")
        if isinstance(value, float) and not math.isfinite(value):
            raise OptionError(f"parameter {name}: expected a finite number, got {value!r}")
        if isinstance(value, (int, float, str)):
            text = repr(value) if not isinstance(value, str) else value
        elif hasattr(value, "_sympy_") or type(value).__module__.startswith("sympy"):
            text = equation_text(value, Limits(), value=True)
        else:
            raise OptionError(f"parameter {name}: expected a number or a constant "
                              f"expression, got {type(value).__name__}")
        args.append(f"{name}={text}")
    return tuple(args)


def _number(value: float | None, key: str, low: float, high: float) -> float | None:
    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, (int, float)) or \
            not low < float(value) < high:
        raise OptionError(f"{key} must be a number between {low:g} and {high:g} (exclusive), "
                          f"got {value!r}")
    return float(value)


def _point(value: object, key: str) -> Point | None:
    if value is None:
        return None
    try:
        values = tuple(float(v) for v in value)  # type: ignore[attr-defined]
    except (TypeError, ValueError):
        values = ()
    if len(values) != 3 or not all(math.isfinite(v) and abs(v) <= 1e6 for v in values):
        raise OptionError(f"{key} must be three finite numbers within 1e6 of the origin, "
                          f"got {value!r}")
    return (values[0], values[1], values[2])


def _up(value: object) -> Point | None:
    if isinstance(value, str):
        axis = value.strip().lower()
        sign = -1.0 if axis.startswith("-") else 1.0
        if axis.lstrip("+-") not in _AXES:
            raise OptionError(f"up must be x, y, z (or -x, -y, -z) or a direction, "
                              f"got {value!r}")
        index = _AXES[axis.lstrip("+-")]
        return (sign if index == 0 else 0.0, sign if index == 1 else 0.0,
                sign if index == 2 else 0.0)
    point = _point(value, "up")
    if point is not None and not any(point):
        raise OptionError("up must not be (0, 0, 0)")
    return point
