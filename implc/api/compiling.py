"""The compile behind `Surface.compile`, `render` and `view_page`: the method and its
constants resolved once, the shader emitted once, and what a user should know about it
(float32 that cannot hold the surface, a constant the method does not read, what framing
chose) put on the record, phrased for a Python caller."""

from __future__ import annotations

from collections.abc import Mapping
from typing import TYPE_CHECKING, Any, Protocol

from ..errors import OptionError
from ..options import EVAL_CHOICES, METHOD_NAMES, TAYLOR2_CHOICES, Constants
from ..scene import ViewOptions
from .records import Shader

if TYPE_CHECKING:
    from ..scene import Framing
    from ..surface import Surface as SurfaceRecord


class Framable(Protocol):
    """What the compile and the render read of an `implc.Surface` (its own module
    imports them, so they name it by this shape instead)."""

    @property
    def default_method(self) -> str: ...

    @property
    def view_options(self) -> ViewOptions: ...

    def framed(self) -> tuple[SurfaceRecord, Framing | None]: ...

# the method constants a caller may set, by keyword (Constants' fields)
CONSTANT_NAMES = tuple(Constants.__dataclass_fields__)


def resolve_method(surface: Framable, method: str | None,
                   constants: Mapping[str, Any]) -> tuple[str, Constants]:
    """The method (the surface's default where None) and its constants with `constants`
    over its defaults; an unknown method or keyword raises."""
    if method is None:
        method = surface.default_method
    elif method not in METHOD_NAMES:
        raise OptionError(f"unknown method '{method}'; choose from {', '.join(METHOD_NAMES)}")
    unknown = sorted(set(constants) - set(CONSTANT_NAMES))
    if unknown:
        raise TypeError(f"unexpected keyword argument {unknown[0]!r} (the method constants: "
                        f"{', '.join(CONSTANT_NAMES)})")
    if constants.get("taylor2") not in (None, *TAYLOR2_CHOICES):
        raise OptionError(f"taylor2 must be one of {', '.join(TAYLOR2_CHOICES)}")
    if constants.get("evaluation") not in (None, *EVAL_CHOICES):
        raise OptionError(f"evaluation must be one of {', '.join(EVAL_CHOICES)}")
    from ..methods import METHODS

    return method, METHODS[method].constants(**constants)


def ignored_constants(method: str, given: Mapping[str, Any]) -> list[str]:
    """The constants given (not None) that `method` does not read, in Constants' order
    (the method's data says what it reads: `Method.reads`)."""
    from ..methods import METHODS

    reads = METHODS[method].reads
    return [name for name in CONSTANT_NAMES if given.get(name) is not None
            and name not in reads]


def float32_finding(record: SurfaceRecord, method: str) -> tuple[str | None, str | None]:
    """(float32's warning for `method`, or None; a note when it could not be measured)."""
    try:
        from ..float32 import float32_warning
    except ImportError as err:  # compiling needs sympy and jinja2 only; the measure numpy
        return None, f"float32 not measured ({err.name or 'numpy'} is not installed)"
    return float32_warning(record, method), None


def compile_record(surface: Framable, record: SurfaceRecord, target: str, method: str | None,
                   *, emit: str, prefix: str, flavor: str | None, precision: str | None,
                   params: str, constants: Mapping[str, Any],
                   notes: tuple[str, ...] = ()) -> Shader:
    """Compile `record` (the surface framed as the picture needs it) for `target`."""
    from ..emit import compile_shader
    from ..targets import TARGETS

    if target not in TARGETS:
        raise OptionError(f"unknown target '{target}'; choose from {', '.join(TARGETS)}")
    method, values = resolve_method(surface, method, constants)
    compiled = compile_shader(record, target, method, values, flavor, emit, prefix, precision,
                              params=params)
    warnings = []
    if ignored := ignored_constants(method, constants):
        warnings.append(f"{', '.join(ignored)}: not read by method {method}: ignored")
    float32 = None
    if precision is None:
        float32, note = float32_finding(record, method)
        notes = (*notes, note) if note else notes
        if float32:
            able = "double" in TARGETS[target].precisions
            warnings.append(f"{float32}; " + ("try precision='double'" if able else
                                              f"{target} has no double precision"))
    return Shader.of(compiled, warnings=tuple(warnings), notes=notes, float32=float32)


def compile_surface(surface: Framable, target: str, method: str | None, *, emit: str,
                    prefix: str, flavor: str | None, precision: str | None, params: str,
                    constants: Mapping[str, Any]) -> Shader:
    """`Surface.compile`: framed for a square picture, the framing said in `notes`."""
    record, framing = surface.framed()
    notes = (framing.message(),) if framing is not None else ()
    return compile_record(surface, record, target, method, emit=emit, prefix=prefix,
                          flavor=flavor, precision=precision, params=params,
                          constants=constants, notes=notes)
