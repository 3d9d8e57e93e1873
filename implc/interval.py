"""The `interval` method's enclosure of F over a ray segment, printed from S's own tree.

For the segment s in [a, b] of the ray o + s d, every node of S's tree becomes an interval
[lo, hi] holding the node's values at every point of the segment (the natural interval
extension): x, y, z from the segment's ends, sums and products by their endpoint rules,
integer powers by parity (an even power of an interval holding 0 starts at 0), min/max
bound by bound, and every function by its `interval` rule in implc/functions.py. Nodes
are shared as sympy shares them (one interval per distinct subexpression), and the
program is a list of lets that a printer prints and implc/numeric.py evaluates: the shader
and the CPU reference run the same rules.

Outward widening. The shader computes each bound in floating point, so each rounded bound
is pushed outward by what its rounding may have cost: a sum, product or quotient of two
floats is correctly rounded (IEEE 754; GLSL 4.x, WGSL and OpenCL C require it for +, -, *,
and 2.5 ulp for /, which we take as 3), off by at most half a unit in the last place of
the result, that is |r| EPS / 2 with EPS = 2^-23 (2^-52 in double). Each such result r
is widened to r -/+ (|r| ULP + TINY) with ULP = 2 EPS (a unit for the result's
rounding, which needs half, and one for the widening's own subtraction; TINY = 2^-126,
float32's least normal, covers underflow to 0 and flushed subnormals).
Because min and max pick one of their (already widened) arguments exactly, and each step
widens by the rounding of its own result, every bound encloses the exact interval
extension of the rounded inputs by induction. Functions add their row's `error` (ulps
relative, and absolute), an implementation's accuracy as measured on llvmpipe and PoCL
(tests/test_interval_widening.py measures it against float64 and fails when a function errs
beyond its widening). An enclosure that overflows (inf, NaN) is never skipped: the march
splits it down to its resolution limit, where the sign test decides.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import sympy
from sympy import Abs, Max, Min, Piecewise

from .derive import DEFAULT_MAX_DERIVED, Derivatives
from .errors import InputError
from .functions import BIG, BY_SYMPY_NAME
from .pieces import ShaderFunction, sym
from .symbols import DIRECTION as DIRECTION_SYMBOLS
from .symbols import POINT

# The march's bounds: the walk starts with nodes of 2^-START of the chord (measured at
# 512^2 against starting with the whole chord, frame time / taylor's: gyroid 1.15 -> 1.01,
# csg 1.07 -> 1.05, blobs 0.50 -> 0.52; a hit ray's first levels never exclude 0, and 3
# cost the blobs' missing rays 1.34), a node no wider than 2^-DEPTH of the chord is a leaf
# (a sign change of F between its ends is a root, refined; else a touching root where |F|
# at its middle is at most TOUCH), and a ray visits at most MAX_NODES nodes.
DEPTH = 16
START = 2
MAX_NODES = 1024
TOUCH = 1e-7

# The segment [A, B] of the ray o + s d, |d| = 1: the inputs the printed program reads
# (names as the shader spells them, fields of the ray record).
A, B = sympy.symbols("a b", real=True)
ORIGIN = tuple(sympy.Symbol(f"ray.o.{c}", real=True) for c in "xyz")
DIRECTION = tuple(sympy.Symbol(f"ray.d.{c}", real=True) for c in "xyz")
# The widening's constants: ULP (a unit in the last place, relative) and TINY (absolute);
# the shader's named constants, their values by precision (WIDENING).
ULP, TINY = sympy.symbols("IV_ULP IV_TINY", real=True)
WIDENING = {"float": (2.0**-22, 2.0**-126), "double": (2.0**-51, 2.0**-1022)}


@dataclass(frozen=True)
class RangeProgram:
    """Lets (symbol, value) in order, then the enclosure (lo, hi) over [A, B] of each
    expression asked for, F's first; a segment where F is undefined throughout (the square
    root of a negative interval, ...) gets [1, 1], which the march skips. F's enclosure is
    exactly [-BIG, BIG] (see `unbounded`) where it holds 0 and a node of F's tree was
    unbounded on the segment (a pole of 1/u or tan, log at 0): F may jump through 0 there
    without a root."""

    assignments: tuple[tuple[sympy.Symbol, sympy.Basic], ...]
    bounds: tuple[tuple[sympy.Expr, sympy.Expr], ...]

    @property
    def lo(self) -> sympy.Expr:
        return self.bounds[0][0]

    @property
    def hi(self) -> sympy.Expr:
        return self.bounds[0][1]


def check_interval(expr: sympy.Expr) -> None:
    """An InputError naming the first function (or power) that has no interval rule."""
    range_program(expr)


@lru_cache(maxsize=64)
def range_program(*exprs: sympy.Expr) -> RangeProgram:
    """The enclosures of `exprs` over a ray segment, jointly (a subexpression they share
    is enclosed once), from their trees (see the module's doc). Cached: the default
    method's check, the lowering and `show` ask for the same program."""
    builder = _bounded(exprs[0]).copy()
    bounds = [builder.bound(exprs[0])]
    poles = list(builder.poles)  # F's own (F''s, of sqrt at 0 say, are not F's)
    bounds += [builder.bound(e) for e in exprs[1:]]
    if poles:  # marked only where 0 is held: what the march skips stays skipped
        lo, hi = bounds[0]
        pole = sympy.Or(*poles) & (lo <= 0) & (hi >= 0)
        bounds[0] = (Piecewise((-BIG, pole), (lo, True)), Piecewise((BIG, pole), (hi, True)))
    dead = sympy.Or(*builder.dead) if builder.dead else sympy.false
    if dead is not sympy.false:
        bounds = [tuple(Piecewise((1, dead), (v, True)) for v in pair) for pair in bounds]
    return RangeProgram(tuple(builder.lets), tuple(bounds))


@lru_cache(maxsize=16)
def _bounded(expr: sympy.Expr) -> _Builder:
    """A builder that has enclosed `expr`: F's program alone (the default method's check)
    and F's with F''s (the march) start from it, so F's tree is enclosed once."""
    builder = _Builder()
    builder.bound(expr)
    return builder


def unbounded(lo, hi):
    """Whether F's enclosure (lo, hi), numbers or arrays, is the pole mark [-BIG, BIG] (or
    overflowed past it): F may be discontinuous on the segment, and its sign change there
    is no root."""
    return (lo <= -BIG) & (hi >= BIG)


def _big_branch(value: sympy.Basic) -> sympy.Basic:
    """The condition under which `value` takes a +-BIG branch of its Piecewise (a rule's
    bound where the function is unbounded), else false."""
    if not isinstance(value, Piecewise):
        return sympy.false
    taken, earlier = [], []
    for branch, cond in value.args:
        if branch in (BIG, -BIG):
            taken.append(sympy.And(cond, *(sympy.Not(c) for c in earlier)))
        earlier.append(cond)
    return sympy.Or(*taken)


class _Builder:
    def __init__(self) -> None:
        self.lets: list[tuple[sympy.Symbol, sympy.Basic]] = []
        self.dead: list[sympy.Basic] = []
        self.poles: list[sympy.Basic] = []  # where a bound was unbounded (+-BIG)
        self.memo: dict[sympy.Basic, tuple[sympy.Expr, sympy.Expr]] = {}
        self.named: dict[sympy.Basic, sympy.Symbol] = {}  # a value let twice: one name

    def copy(self) -> _Builder:
        """An independent builder in this one's state (the cached one stays as it is)."""
        twin = _Builder()
        twin.lets, twin.dead, twin.poles = list(self.lets), list(self.dead), list(self.poles)
        twin.memo, twin.named = dict(self.memo), dict(self.named)
        return twin

    # --- lets and widening -------------------------------------------------------------
    def let(self, value: sympy.Basic, stem: str) -> sympy.Expr:
        if value.is_Atom:
            return value
        if value not in self.named:
            self.named[value] = sympy.Symbol(f"{stem}{len(self.lets)}", real=True)
            self.lets.append((self.named[value], value))
        return self.named[value]

    def widened(self, lo: sympy.Expr, hi: sympy.Expr, ulps: float = 1,
                absolute: float = 0) -> tuple[sympy.Expr, sympy.Expr]:
        """[lo, hi] pushed outward by each bound's rounding (ulps units of |bound|, plus
        absolute and TINY)."""
        for bound in (lo, hi):
            pole = _big_branch(bound)
            if pole is not sympy.false and pole not in self.poles:
                self.poles.append(pole)
        if ulps == 0 and absolute == 0:
            return self.let(lo, "lo"), self.let(hi, "hi")
        if lo.is_number and hi.is_number:  # a constant: printed as one literal
            return lo, hi
        lo, hi = self.let(lo, "r"), self.let(hi, "r")
        pad = ULP if ulps == 1 else ulps * ULP
        extra = absolute or TINY  # (an absolute error is far above TINY)
        return (self.let(lo - (Abs(lo) * pad + extra), "lo"),
                self.let(hi + (Abs(hi) * pad + extra), "hi"))

    # --- the tree ----------------------------------------------------------------------
    def bound(self, node: sympy.Basic) -> tuple[sympy.Expr, sympy.Expr]:
        if node not in self.memo:
            self.memo[node] = self._bound(node)
        return self.memo[node]

    def _bound(self, node: sympy.Basic) -> tuple[sympy.Expr, sympy.Expr]:
        if node.is_Number or node.is_NumberSymbol or (node.is_number and node.is_real):
            return node, node
        if node in POINT:  # o + s d over [a, b]: linear in s, its ends
            i = POINT.index(node)
            o, d = ORIGIN[i], DIRECTION[i]
            ends = (self.let(A * d, "r"), self.let(B * d, "r"))
            lo = self.let(o + Min(*ends, evaluate=False), "r")
            hi = self.let(o + Max(*ends, evaluate=False), "r")
            # the product's rounding and the sum's: a unit of each (the sum may cancel, so
            # the product's is in units of its own size)
            return (self.let(lo - ((Abs(lo) + Abs(ends[0]) + Abs(ends[1])) * ULP + TINY), "lo"),
                    self.let(hi + ((Abs(hi) + Abs(ends[0]) + Abs(ends[1])) * ULP + TINY), "hi"))
        if node in DIRECTION_SYMBOLS:  # (in F' = grad S . d) the ray's direction
            d = DIRECTION[DIRECTION_SYMBOLS.index(node)]
            return d, d
        if node.is_Symbol:  # a parameter read at run time: one value
            return node, node
        if node.is_Add:
            return self._fold(node.args, self._add)
        if node.is_Mul:
            coeff, rest = node.as_coeff_Mul()
            lo, hi = self._fold(sympy.Mul.make_args(rest), self._mul)
            if coeff == 1:
                return lo, hi
            if coeff == -1:
                return -hi, -lo
            return self.widened(coeff * lo, coeff * hi) if coeff > 0 else \
                self.widened(coeff * hi, coeff * lo)
        if node.is_Pow:
            return self._pow(node)
        return self._function(node)

    def _fold(self, args, combine):
        """Two at a time (each result rounded once), in sympy's canonical order; each
        operand with whether it is known >= 0 (sympy's assumptions: x^2, |x|, exp)."""
        ordered = sorted(args, key=sympy.default_sort_key)
        acc = (bool(ordered[0].is_nonnegative), self.bound(ordered[0]))
        for arg in ordered[1:]:
            acc = combine(acc, (bool(arg.is_nonnegative), self.bound(arg)))
        return acc[1]

    def _add(self, left, right):
        (p_pos, (a, b)), (q_pos, (c, d)) = left, right
        return p_pos and q_pos, self.widened(a + c, b + d)

    def _mul(self, left, right):
        (p_pos, (a, b)), (q_pos, (c, d)) = left, right
        return p_pos and q_pos, self._product(p_pos, (a, b), q_pos, (c, d))

    def _product(self, p_pos, left, q_pos, right):
        (a, b), (c, d) = left, right
        if p_pos and q_pos:
            return self.widened(a * c, b * d)
        if q_pos:  # [a, b] of either sign times [c, d] >= 0
            (a, b), (c, d) = (c, d), (a, b)
            p_pos = True
        if p_pos:  # [a, b] >= 0 times [c, d] of either sign
            return self.widened(Min(a * c, b * c, evaluate=False), Max(a * d, b * d,
                                                                       evaluate=False))
        products = [self.let(u * v, "r") for u in (a, b) for v in (c, d)]
        return self.widened(Min(*products, evaluate=False), Max(*products, evaluate=False))

    def _pow(self, node: sympy.Pow) -> tuple[sympy.Expr, sympy.Expr]:
        base, exp = node.base, node.exp
        a, b = self.bound(base)
        if exp.is_Integer:
            n = int(exp)
            if n < 0:
                return self._reciprocal(*self._pow(sympy.Pow(base, -n, evaluate=False)))
            if n % 2 == 0:  # even: of the least and the greatest |x|
                a, b = (self.let(Max(a, -b, 0, evaluate=False), "m"),
                        self.let(Max(-a, b, evaluate=False), "m"))
            # n - 1 products, each rounded: n - 1 units
            return self.widened(a**n, b**n, max(n - 1, 1))
        if not exp.is_number or not exp.is_real:
            raise InputError(f"-m interval has no interval rule for the power {node} with "
                             "a variable exponent; use another method (-m hessian)")
        # x^r, r not an integer: defined for x >= 0 (real roots of negative x are written
        # sign(x)|x|^r, implc/front/build.py), increasing for r > 0, decreasing for r < 0
        self.dead.append(b < 0)
        a = self.let(Max(a, 0, evaluate=False), "m")
        b = self.let(Max(b, 0, evaluate=False), "m")
        if exp.is_positive:
            return self.widened(a**exp, b**exp, 16)
        return self.widened(Piecewise((b**exp, b > 0), (BIG, True)),
                            Piecewise((a**exp, a > 0), (BIG, True)), 16)

    def _reciprocal(self, a, b):
        """1/[a, b]: [1/b, 1/a] when 0 is outside, else unbounded."""
        outside = (a > 0) | (b < 0)
        return self.widened(Piecewise((1 / b, outside), (-BIG, True)),
                            Piecewise((1 / a, outside), (BIG, True)), 3)

    def _function(self, node: sympy.Basic) -> tuple[sympy.Expr, sympy.Expr]:
        name = type(node).__name__
        row = BY_SYMPY_NAME.get(name)
        if name in ("Min", "Max"):  # bound by bound, exact
            make = Min if name == "Min" else Max
            bounds = [self.bound(a) for a in sorted(node.args, key=sympy.default_sort_key)]
            return (self.let(make(*(lo for lo, _ in bounds), evaluate=False), "lo"),
                    self.let(make(*(hi for _, hi in bounds), evaluate=False), "hi"))
        if row is None or row.interval is None:
            what = row.name if row else name
            raise InputError(f"-m interval has no interval rule for '{what}'; use another "
                             "method (-m hessian)")
        a, b = self.bound(node.args[0])
        a, b = self.let(a, "a"), self.let(b, "a")
        lo, hi, dead = row.interval(a, b, lambda value: self.let(value, "a"))
        if dead is not sympy.false:
            self.dead.append(dead)
        ulps, absolute = row.error
        return self.widened(lo, hi, ulps, absolute)


def derivative_program(expr: sympy.Expr,
                       max_derived: int = DEFAULT_MAX_DERIVED) -> RangeProgram | None:
    """F and F' = grad S . d enclosed jointly over a segment, or None where F may jump
    (sign's derivative is a delta, which has no interval rule): the march's monotonic test
    then does not apply. F' is derived under `--max-derived` (default: the current one)."""
    directional = Derivatives(expr, max_derived).quantity("dS")[0]
    try:
        return range_program(expr, directional)
    except InputError:
        return None


def range_function(name: str, program: RangeProgram, printer, prefix: str,
                   carried: tuple[tuple[str, str], ...] = ()) -> ShaderFunction:
    """`F_range(ray, a, b)` (or `DF_range`, F''s): the enclosure over [a, b] as (lo, hi),
    printed."""
    names = {ULP: sym(prefix.upper() + "IV_ULP"), TINY: sym(prefix.upper() + "IV_TINY")}
    with printer.sums_as_held():  # machine-made bounds: printed fast, not sorted to read
        lets = tuple(("real", name.name, printer.doprint(value.xreplace(names)))
                     for name, value in program.assignments)
        outputs = tuple(printer.doprint(v.xreplace(names)) for pair in program.bounds
                        for v in pair)
    params = (("Ray", "ray"), ("real", "a"), ("real", "b")) + carried
    what = "F's and F''s enclosures (lo, hi, lo', hi')" if len(outputs) == 4 else \
        "F's enclosure (lo, hi)"
    return ShaderFunction(name, f"{what} over the ray segment s in [a, b] (interval "
                          "arithmetic on the tree, widened outward)", params,
                          "vec4" if len(outputs) == 4 else "vec2", lets, outputs)


def range_constants(printer, prefix: str) -> tuple[tuple[str, str, str], ...]:
    """The interval march's named constants (type, name, printed value)."""
    K = prefix.upper()  # noqa: N806 (the constants' prefix, as the templates name it)
    ulp, tiny = WIDENING[printer.precision]
    return (("real", K + "IV_ULP", printer.float_literal(ulp)),
            ("real", K + "IV_TINY", printer.float_literal(tiny)),
            ("real", K + "START_WIDTH", printer.float_literal(2.0**-START)),
            ("real", K + "MIN_WIDTH", printer.float_literal(2.0**-DEPTH)),
            ("real", K + "TOUCH", printer.float_literal(TOUCH)),
            ("real", K + "BIG", printer.float_literal(BIG)),
            ("int", K + "DEPTH", str(DEPTH)),
            ("int", K + "MAX_NODES", str(MAX_NODES)))
