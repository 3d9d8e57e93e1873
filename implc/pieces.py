"""The printed pieces every lowering returns (the records templates/marcher.j2 and
templates/solver.j2 read) and the point functions: straight-line shader functions of the
point p (and direction d), each one jointly CSE'd Program of S's derivatives.

A lowering returns one variant of `Marcher`, named by its `kind`: `Marching` and
`IntervalMarching` here, and the exact method's `solver.Solving`, which holds that
solver's own record. Each variant has only the pieces its template prints, so this module
needs nothing from the lowerings that build them."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from functools import lru_cache
from typing import ClassVar

import sympy

from .derive import Derivatives
from .optimize import Program, optimize
from .symbols import DIRECTION, POINT

QUANTITY_ORDER = ("S", "dS", "d2S", "lap", "grad")
_LETTER = {"S": "S", "dS": "D", "d2S": "H", "lap": "L"}
RETURN_TYPE = {1: "real", 2: "vec2", 3: "vec3"}
COMPONENT = ("x", "y", "z")


def function_name(quantities: Sequence[str]) -> str:
    """The point function of a quantity set: S, grad, dS, SD, SDH, SDL, ..."""
    if len(quantities) == 1:
        return quantities[0]
    return "".join(_LETTER[q] for q in quantities)


@dataclass(frozen=True)
class ShaderFunction:
    """One straight-line shader function."""

    name: str
    comment: str
    params: tuple[tuple[str, str], ...]  # (abstract type, name)
    ret: str  # abstract type of the result
    lets: tuple[tuple[str, str, str], ...]  # (abstract type, name, printed value)
    outputs: tuple[str, ...]  # one value, or the components of the vector returned


@dataclass(frozen=True)
class PrintedBody:
    """A printed body: `lets` (abstract type, name, value) in order, then `values`."""

    lets: tuple[tuple[str, str, str], ...]
    values: tuple[str, ...]
    what: str = ""  # a comment for the reader of the shader


@dataclass(frozen=True)
class Marcher:
    """What every lowering prints for the skeleton: its functions, constants and ray
    record. `kind` names the variant, which templates/marcher.j2 branches on."""

    kind: ClassVar[str]
    form: str
    functions: tuple[ShaderFunction, ...]
    constants: tuple[tuple[str, str, str], ...]  # (abstract type, name, printed value)
    ray_fields: tuple[tuple[str, str, str], ...]  # beyond o, d, sm: (type, name, comment)
    ray: PrintedBody  # lets of ray_of(ro, rd, sm, hr) after oc = ro + sm rd; the fields' values
    carried: tuple[tuple[str, str], ...]  # see marcher.lower

    @property
    def carried_args(self) -> str:
        """", params" (the carried arguments, appended to a call), or ""."""
        return "".join(f", {name}" for _, name in self.carried)


@dataclass(frozen=True)
class Marching(Marcher):
    """A march by a step rule and a root test (templates/marcher.j2's own loop)."""

    kind: ClassVar[str] = "march"
    sample: PrintedBody
    fd: PrintedBody
    step: PrintedBody
    root: PrintedBody


@dataclass(frozen=True)
class IntervalMarching(Marcher):
    """The `interval` method's march over F's enclosures (templates/interval.j2)."""

    kind: ClassVar[str] = "interval"
    fd: PrintedBody
    monotone: bool  # with F''s enclosure (FD_range), a monotonic test


# --- derivation (cached: emit asks for the same programs for every target) -----------

def build_programs(expr: sympy.Expr, sets: tuple[tuple[str, ...], ...],
                   max_derived: int, precision: str = "float") -> dict[str, Program]:
    """The optimized Program of each point quantity set, for a shader in `precision`: in
    double summed axis by axis (optimize's `by_axis`: two registers a value)."""
    return dict(_build_programs(expr, sets, max_derived, precision == "double"))


@lru_cache(maxsize=64)
def _build_programs(expr, sets, max_derived, by_axis) -> tuple[tuple[str, Program], ...]:
    derivatives = Derivatives(expr, max_derived)
    result = []
    for quantities in sets:
        outputs = [e for q in quantities for e in derivatives.quantity(q)]
        directional = any(q in ("dS", "d2S") for q in quantities)
        result.append((function_name(quantities),
                       optimize(outputs, POINT + DIRECTION if directional else POINT,
                                by_axis)))
    return tuple(result)


def sym(name: str) -> sympy.Symbol:
    return sympy.Symbol(name, real=True)


def point_function(name: str, program: Program, printer,
                    carried: tuple[tuple[str, str], ...] = ()) -> ShaderFunction:
    directional = len(program.inputs) == 6
    params = (("vec3", "p"), ("vec3", "d")) if directional else (("vec3", "p"),)
    params += carried
    lets = [("real", v.name, f"p.{c}") for v, c in zip(POINT, COMPONENT, strict=True)]
    if directional:
        lets += [("real", v.name, f"d.{c}") for v, c in zip(DIRECTION, COMPONENT, strict=True)]
    lets += [("real", s.name, printer.doprint(v)) for s, v in program.assignments]
    outputs = tuple(printer.doprint(o) for o in program.outputs)
    what = ", ".join(_quantities_of(name))
    comment = f"{what} at the point p" + (" along the unit direction d" if directional else "")
    return ShaderFunction(name, comment, params, RETURN_TYPE[len(outputs)], tuple(lets),
                          outputs)


def _quantities_of(name: str) -> tuple[str, ...]:
    if name in QUANTITY_ORDER:
        return (name,)
    inverse = {v: k for k, v in _LETTER.items()}
    return tuple(inverse[c] for c in name)


def printed_lets(powers, printer) -> list[tuple[str, str, str]]:
    """Printed lets (type, name, value) of (symbol, value) pairs."""
    return [("real", k.name, printer.doprint(v)) for k, v in powers]
