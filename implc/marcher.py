"""Lower a method (data, implc/methods.py) and an evaluation form to printed code pieces.

The marcher skeleton (templates/marcher.j2) is written once; what varies by method and
evaluation form is printed here, by the target's printer:
- `functions`: straight-line shader functions, of the point p (and direction d) or of
  the ray and its parameter s (each one jointly CSE'd where it is a Program);
- `ray`: the ray record's fields and how `ray_of(ro, rd)` fills them;
- `values_at(ray, s)`: the method's (F, F', X) at a march point; `fd(ray, s)`: (F, F')
  for the refinement;
- `step_size(ray, s, f0)`: the step rule; `root_in(f0, f1, h)`: the root test.

Evaluation forms (DESIGN.md section 2) say how a ray quantity at a ray parameter is
computed; a method never knows which one it gets:
- `point`: jointly CSE'd functions of p = ray.o + s*ray.d and d: `SDH(p, d)` returns
  (F, F', F'') together;
- `ray-poly` (polynomial S): the coefficients c_k of F(s) = S(o + s d), expanded about
  the middle of the march interval, are computed once per ray in `ray_of` and kept in
  the ray record; F' and F'' at s are Estrin sums over them (`ray_DH(ray, s)`), about n
  multiply-adds each for degree n. F itself (see RAY_DERIVATIVES) and quantities that
  are not ray derivatives (the Laplacian) stay point functions.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from functools import lru_cache
from math import comb

import sympy

from .derive import Derivatives, polynomial_degree, ray_coefficients
from .errors import InputError
from .methods import (
    CONSTANT_SYMBOLS,
    D0,
    D1,
    F0,
    F1,
    RAY_FUNCTIONS,
    RAY_QUANTITIES,
    X0,
    X1,
    Constants,
    H,
    Method,
    S,
)
from .optimize import Program, arrange_by_depth, count_ops, optimize
from .symbols import DIRECTION, POINT

FORMS = ("point", "ray-poly")
EVAL_CHOICES = ("auto", *FORMS)
# `auto` takes ray-poly for polynomials up to this degree (docs/RESULTS.md, "Evaluation
# forms"): as accurate as point evaluation at every degree measured (2 to 12), and faster
# on every bundled polynomial (degree 2 to 6, 3-26 %); above degree 6 the point form was
# as fast or faster with Horner's F' (sums of n-th powers evaluate cheaply at a point by
# power chains). With Estrin's F', ray-poly measured as fast or faster up to degree 12 in
# one run (RESULTS section 2); not re-decided on that alone.
AUTO_MAX_DEGREE = 6

# When the root test's inputs are ready, in operations (optimize.arrange_by_depth): the
# start sample (F0, F0', X0) first, then the step length h (after the step rule), then the
# end sample (F1, F1', X1), evaluated at s0 + h.
_H_DEPTH, _LATE = 10, 1000

QUANTITY_ORDER = ("S", "dS", "d2S", "lap", "grad")
# What the ray polynomial gives (by Estrin's scheme): F' and F''. F itself, whose sign is the
# answer, is the ray polynomial's only where that sign is certain: its float32 value, from
# coefficients rounded once per ray, errs by a smooth offset along the whole ray, which
# near a double line of a self-intersecting surface adds or removes a pair of roots
# (measured on the Cross-Cap, Miter and Roman surfaces with hessian at 512^2: 2-6
# false-hit pixels each where point evaluation has none). The marchers take F at the
# point (measured: the same false / missed / wrong-root counts as point evaluation on
# every bundled polynomial, docs/RESULTS.md); the exact solver's F (its P_n) is Estrin's
# h where |h| exceeds the bound of its rounding error (ROUND_ERR times the size of F's
# terms on the interval, in the ray record) and S at the point otherwise, which measured
# faster there (a march step decides a sign near the surface far more often than the
# solver, whose evaluations are mostly far from it) and as accurate.
RAY_DERIVATIVES = ("dS", "d2S")
_MARCH_POINT = "(ray.o + s0*ray.d) + h*ray.d"  # values_at's point: s = s0 + h
_DERIVATIVE_ORDER = {"S": 0, "dS": 1, "d2S": 2}
_LETTER = {"S": "S", "dS": "D", "d2S": "H", "lap": "L"}
_RETURN_TYPE = {1: "real", 2: "vec2", 3: "vec3"}
_COMPONENT = ("x", "y", "z")
REFINE_SET = ("S", "dS")


def function_name(quantities: Sequence[str]) -> str:
    """The point function of a quantity set: S, grad, dS, SD, SDH, SDL, ..."""
    if len(quantities) == 1:
        return quantities[0]
    return "".join(_LETTER[q] for q in quantities)


# From this degree the exact method isolates F's first root by Bernstein subdivision
# (Descartes' rule of signs on the Bernstein coefficients of a node, stackless: the next
# node follows from the current one) instead of the critical points level by level: it
# visits 3-6 nodes a ray and stops at the first root, where the levels find every root
# of every derivative. Measured at 512^2 (docs/RESULTS.md section 7): level by level
# against Bernstein, 19.2 / 19.7 ms at degree 6, 32.2 / 24.0 at 7, 46.6 / 32.8 at 8, 97 /
# 13-18 at 12.
BERNSTEIN_FROM = 7

# The exact method's highest degree. Float32 root isolation loses accuracy with the
# degree; measured at 512^2 (issue 21's note): 12 bad pixels of 262,144 at degree 14 and
# 17 at 18, against 0-3 at 10-12 (the limit there is the float32 ray coefficients).
EXACT_MAX_DEGREE = 20


def check_exact(expr: sympy.Expr) -> int:
    """The degree of S, or an InputError saying why `-m exact` does not apply."""
    from .methods import METHODS

    marching = ", ".join(m for m, meth in METHODS.items() if not meth.solves)
    degree = polynomial_degree(expr)
    if degree is None:
        raise InputError("-m exact needs a polynomial surface (it isolates the roots of the "
                         f"ray polynomial); this one is not: use one of {marching}")
    if degree > EXACT_MAX_DEGREE:
        raise InputError(f"-m exact supports degree up to {EXACT_MAX_DEGREE} (float32 root "
                         f"isolation is measured correct up to there); this surface has "
                         f"degree {degree}: use one of {marching}")
    return degree


def default_method(expr: sympy.Expr) -> str:
    """The method `-m` defaults to: `exact` where it applies (polynomials up to
    EXACT_MAX_DEGREE; measured the most accurate there, and the fastest up to degree 6),
    else `hessian`."""
    degree = polynomial_degree(expr)
    return "exact" if degree is not None and degree <= EXACT_MAX_DEGREE else "hessian"


def choose_form(expr: sympy.Expr, requested: str = "auto") -> str:
    """The evaluation form for `expr`: `point` or `ray-poly` (see AUTO_MAX_DEGREE)."""
    if requested not in EVAL_CHOICES:
        raise InputError(f"unknown evaluation form '{requested}'; choose from "
                         f"{', '.join(EVAL_CHOICES)}")
    degree = polynomial_degree(expr)
    if requested == "ray-poly" and degree is None:
        raise InputError("--eval ray-poly needs a polynomial surface; this one is not "
                         "(use --eval point or auto)")
    if requested != "auto":
        return requested
    return "ray-poly" if degree is not None and degree <= AUTO_MAX_DEGREE else "point"


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
class Code:
    """A printed body: `lets` (abstract type, name, value) in order, then `values`."""

    lets: tuple[tuple[str, str, str], ...]
    values: tuple[str, ...]
    what: str = ""  # a comment for the reader of the shader


@dataclass(frozen=True)
class Solver:
    """What templates/solver.j2 needs for the `exact` method on a degree-n polynomial."""

    degree: int
    bottom: int  # the level solved in closed form: 2 (a quadratic) or 1 (linear)
    closed: tuple[str, ...]  # that level's coefficients a_0.. (printed), lowest first
    # "levels" (critical points level by level) or "bernstein" (subdivision with
    # Descartes' rule of signs), by degree: see BERNSTEIN_FROM
    strategy: str = "levels"
    # bernstein: the lets (name, printed value) that give b0..bn, the Bernstein
    # coefficients of sum e_k w^k on w in [-1, 1] (see _bernstein_lets), and the depth of
    # a leaf node
    bernstein: tuple[tuple[str, str], ...] = ()
    depth: int = 0
    # bernstein: w_i = -1 + 2i/n (printed), where b_i sits in the node's control polygon,
    # whose zero starts the Newton (see _lower_solver)
    nodes: tuple[str, ...] = ()


@dataclass(frozen=True)
class Marcher:
    """Everything method- and form-specific the skeleton prints."""

    form: str
    functions: tuple[ShaderFunction, ...]
    constants: tuple[tuple[str, str, str], ...]  # (abstract type, name, printed value)
    ray_fields: tuple[tuple[str, str, str], ...]  # beyond o, d, sm: (type, name, comment)
    ray: Code  # lets of ray_of(ro, rd, sm, hr) after oc = ro + sm rd; the fields' values
    sample: Code
    fd: Code
    step: Code
    root: Code
    solver: Solver | None = None
    carried: tuple[tuple[str, str], ...] = ()  # see `lower`

    @property
    def carried_args(self) -> str:
        """", params" (the carried arguments, appended to a call), or ""."""
        return "".join(f", {name}" for _, name in self.carried)


# --- what a method evaluates where ---------------------------------------------------

def _applications(expr: sympy.Basic) -> list[sympy.Expr]:
    """Applications of ray quantities in `expr`, in a canonical order."""
    found = {a for a in sympy.preorder_traversal(expr)
             if isinstance(a, sympy.core.function.AppliedUndef)}
    return sorted(found, key=sympy.default_sort_key)


def _sample_groups(method: Method) -> dict[sympy.Expr, tuple[str, ...]]:
    """Evaluation point -> the quantities the sample needs there (canonical order)."""
    by_arg: dict[sympy.Expr, set[str]] = {}
    for expr in method.sample:
        for app in _applications(expr):
            by_arg.setdefault(app.args[0], set()).add(RAY_QUANTITIES[app.func.__name__])
    ordered = sorted(by_arg, key=lambda a: (a != S, sympy.default_sort_key(a)))
    return {a: tuple(q for q in QUANTITY_ORDER if q in by_arg[a]) for a in ordered}


def _split(quantities: tuple[str, ...], form: str) -> list[tuple[str, tuple[str, ...]]]:
    """A quantity set as (kind, subset) calls: `ray` (Estrin: F', F'') or `point` (F and
    the rest; see RAY_DERIVATIVES)."""
    if form == "point":
        return [("point", quantities)]
    ray = tuple(q for q in quantities if q in RAY_DERIVATIVES)
    rest = tuple(q for q in quantities if q not in RAY_DERIVATIVES)
    return [(kind, qs) for kind, qs in (("ray", ray), ("point", rest)) if qs]


def evaluations(method: Method, form: str) -> list[tuple[str, tuple[str, ...]]]:
    """Every (kind, quantity set) the method's program evaluates; S and grad (residual,
    shading, library users) first."""
    wanted = [("point", ("S",)), ("point", ("grad",))]
    sets = [*_sample_groups(method).values(), REFINE_SET]
    for quantities in sets:
        for call in _split(quantities, form):
            if call not in wanted:
                wanted.append(call)
    return wanted


def point_sets(method: Method, form: str = "point") -> tuple[tuple[str, ...], ...]:
    return tuple(q for kind, q in evaluations(method, form) if kind == "point")


# --- derivation (cached: emit asks for the same programs for every target) -----------

def build_programs(expr: sympy.Expr, sets: tuple[tuple[str, ...], ...],
                   max_derived: int) -> dict[str, Program]:
    """The optimized Program of each point quantity set."""
    return dict(_build_programs(expr, sets, max_derived))


@lru_cache(maxsize=64)
def _build_programs(expr, sets, max_derived) -> tuple[tuple[str, Program], ...]:
    derivatives = Derivatives(expr, max_derived)
    result = []
    for quantities in sets:
        outputs = [e for q in quantities for e in derivatives.quantity(q)]
        directional = any(q in ("dS", "d2S") for q in quantities)
        result.append((function_name(quantities),
                       optimize(outputs, POINT + DIRECTION if directional else POINT)))
    return tuple(result)


@lru_cache(maxsize=32)
def coefficient_program(expr: sympy.Expr) -> Program:
    """The ray polynomial's coefficients c_0..c_n from (o, d), jointly CSE'd."""
    coefficients = ray_coefficients(expr)
    if coefficients is None:
        raise InputError("the ray-poly form needs a polynomial surface")
    return optimize(list(coefficients), POINT + DIRECTION)


# --- printing ------------------------------------------------------------------------

def lower(method: Method, constants: Constants, expr: sympy.Expr, form: str, printer,
          prefix: str, max_derived: int,
          carried: tuple[tuple[str, str], ...] = ()) -> Marcher:
    """Print the method's pieces in `form` with `printer`; global names start with
    `prefix`.

    `carried`: arguments (abstract type, name) that every function evaluating S takes
    after its own, for a language whose functions cannot read run-time values any other
    way (OpenCL C's `--params uniform`: `(("Params", "params"),)`). The ray record
    carries them, so the march's own functions keep their signatures."""
    if method.solves:
        check_exact(expr)
        return _lower_solver(constants, expr, printer, prefix, max_derived, carried)
    const_names = {c: sympy.Symbol(prefix.upper() + c.name, real=True)
                   for c in CONSTANT_SYMBOLS}

    def show(expr: sympy.Basic) -> str:
        return printer.doprint(expr.xreplace(const_names))

    wanted = evaluations(method, form)
    programs = build_programs(expr, point_sets(method, form), max_derived)
    functions = [_point_function(name, program, printer, carried)
                 for name, program in programs.items()]
    fields, ray = (), Code((), ())  # the point form's ray record: o, d and sm only
    if form == "ray-poly":
        coefficients = coefficient_program(expr)
        n = len(coefficients.outputs) - 1
        fields, ray = _ray_setup(coefficients, printer)
        functions += [_estrin_function(q, n, printer) for kind, q in wanted if kind == "ray"]
    ray_fields, ray = _carry(carried, fields, ray)
    by_name = {f.name: f for f in functions}

    def call(kind: str, quantities: tuple[str, ...], arg: sympy.Expr,
             point: str | None = None) -> str:
        at = f"({show(arg)})" if arg.is_Add else show(arg)
        if kind == "ray":
            return f"{prefix}{_ray_name(quantities)}(ray, {show(arg)})"
        fn = by_name[function_name(quantities)]
        args = [point or f"ray.o + {at}*ray.d", "ray.d"][: len(fn.params) - len(carried)]
        args += _from_ray(carried)
        return f"{prefix}{fn.name}({', '.join(args)})"

    def calls(quantities: tuple[str, ...], arg: sympy.Expr, stem: str, lets: list,
              replace: dict, point: str | None = None) -> None:
        for kind, qs in _split(quantities, form):
            name = f"{stem}{len(lets)}"
            lets.append((_RETURN_TYPE[len(qs)], name, call(kind, qs, arg, point)))
            for i, q in enumerate(qs):
                part = name if len(qs) == 1 else f"{name}.{_COMPONENT[i]}"
                replace[_apply(q, arg)] = _sym(part)

    lets: list = []
    replace: dict = {}
    for arg, group in _sample_groups(method).items():
        # the march point s = s0 + h as (o + s0 d) + h d: o + s0 d is known a step early,
        # so the point is one operation after h, not two after s (templates/marcher.j2)
        calls(group, arg, "e", lets, replace, _MARCH_POINT if arg == S else None)
    sample = Code(tuple(lets), tuple(show(e.xreplace(replace)) for e in method.sample))
    lets, replace = [], {}
    calls(REFINE_SET, S, "e", lets, replace)
    fd = Code(tuple(lets), tuple(show(_apply(q, S).xreplace(replace)) for q in REFINE_SET))

    ends0 = {F0: _sym("f0.x"), D0: _sym("f0.y"), X0: _sym("f0.z")}
    ends1 = {F1: _sym("f1.x"), D1: _sym("f1.y"), X1: _sym("f1.z")}
    step = Code((), (show(method.step.xreplace(ends0)),))

    rule = method.root_rule(constants.taylor2)
    ends = {**ends0, **ends1}

    # the end sample is computed last: products and sums take it last (arranged after
    # every substitution, which would flatten the nesting again)
    names = {**ends, **const_names}
    lets, value = arrange_by_depth([(s, v.xreplace(names)) for s, v in rule.lets],
                                   rule.value.xreplace(names),
                                   {**dict.fromkeys(ends1.values(), _LATE), H: _H_DEPTH})
    root = Code(tuple(("real", s.name, printer.doprint(v)) for s, v in lets),
                (printer.doprint(value),), rule.what)

    used = set().union(*(e.free_symbols for e in (*method.sample, method.step, rule.value,
                                                    *(v for _, v in rule.lets))))
    values = constants.values()
    printed = tuple(("real", const_names[c].name, printer.float_literal(values[c]))
                    for c in CONSTANT_SYMBOLS if c in used)
    printed += (("int", prefix.upper() + "MAX_STEPS", str(int(constants.max_steps))),
                ("int", prefix.upper() + "REFINE_STEPS", str(int(constants.refine_steps))))
    return Marcher(form, tuple(functions), printed, ray_fields, ray, sample, fd, step, root,
                   carried=carried)


def _sym(name: str) -> sympy.Symbol:
    return sympy.Symbol(name, real=True)


def _apply(quantity: str, arg: sympy.Expr) -> sympy.Expr:
    fn = next(f for f in RAY_FUNCTIONS if RAY_QUANTITIES[f.__name__] == quantity)
    return fn(arg)


def _ray_name(quantities: tuple[str, ...]) -> str:
    return "ray_" + function_name(quantities)


def _point_function(name: str, program: Program, printer,
                    carried: tuple[tuple[str, str], ...] = ()) -> ShaderFunction:
    directional = len(program.inputs) == 6
    params = (("vec3", "p"), ("vec3", "d")) if directional else (("vec3", "p"),)
    params += carried
    lets = [("real", v.name, f"p.{c}") for v, c in zip(POINT, _COMPONENT, strict=True)]
    if directional:
        lets += [("real", v.name, f"d.{c}") for v, c in zip(DIRECTION, _COMPONENT, strict=True)]
    lets += [("real", s.name, printer.doprint(v)) for s, v in program.assignments]
    outputs = tuple(printer.doprint(o) for o in program.outputs)
    what = ", ".join(_quantities_of(name))
    comment = f"{what} at the point p" + (" along the unit direction d" if directional else "")
    return ShaderFunction(name, comment, params, _RETURN_TYPE[len(outputs)], tuple(lets),
                          outputs)


def _quantities_of(name: str) -> tuple[str, ...]:
    if name in QUANTITY_ORDER:
        return (name,)
    inverse = {v: k for k, v in _LETTER.items()}
    return tuple(inverse[c] for c in name)


def _ray_setup(coefficients: Program, printer) -> tuple[tuple, Code]:
    """The ray record's fields and ray_of's body. The polynomial is expanded about the
    middle of the march interval: the record's origin is o = ro + sm rd and
    F(s) = S(o + s d) = sum c_k s^k, so |s| is at most hr, half the chord): about the
    entry point its terms would be up to 3^n times larger
    for the same sum, and float32 Horner loses that much more to cancellation. `size`,
    sum |c_k| hr^k, bounds the terms of F on the interval: the unit of the rounding
    error in the exact solver's F. Storing the coefficients of F' and F'' as well
    measured slower on llvmpipe (a larger record, the same loop-invariant products)."""
    n = len(coefficients.outputs) - 1
    lets = [("real", v.name, f"oc.{c}") for v, c in zip(POINT, _COMPONENT, strict=True)]
    lets += [("real", v.name, f"rd.{c}") for v, c in zip(DIRECTION, _COMPONENT, strict=True)]
    lets += [("real", s.name, printer.doprint(v)) for s, v in coefficients.assignments]
    lets += [("real", f"c{k}", printer.doprint(o)) for k, o in enumerate(coefficients.outputs)]
    size = _horner([sympy.Abs(_sym(f"c{k}")) for k in range(n + 1)], _sym("hr"))
    lets.append(("real", "size", printer.doprint(size)))
    fields = (("real", "size", "sum |c_k| hr^k: the size of F's terms on the interval"),)
    fields += tuple(("real", f"c{k}", f"coefficient of u^{k}") for k in range(n + 1))
    return fields, Code(tuple(lets), ("size", *(f"c{k}" for k in range(n + 1))))


def _from_ray(carried: tuple[tuple[str, str], ...]) -> list[str]:
    """The carried arguments as a function of the ray reads them: ray.params, ..."""
    return [f"ray.{name}" for _, name in carried]


def _carry(carried: tuple[tuple[str, str], ...], fields: tuple,
           ray: Code) -> tuple[tuple, Code]:
    """The ray record with the carried arguments as fields (ray_of takes them)."""
    fields += tuple((kind, name, "carried for the functions that evaluate S")
                    for kind, name in carried)
    return fields, Code(ray.lets, ray.values + tuple(name for _, name in carried))


def _round_err(n: int, printer, prefix: str) -> tuple[str, str, str]:
    """ROUND_ERR: the rounding error of F (degree n) by Estrin's scheme is below
    gamma_m sum |c_k| |u|^k with m = 3 ceil(log2(n + 1)) (each term meets at most that many
    roundings: its power's squarings, its product, the sums up the tree), and m <= 2n for
    n >= 1, so below 2n eps sum |c_k| |u|^k (eps: the unit roundoff, gamma_m ~ m eps); twice
    that, in units of the ray record's `size`."""
    eps = 2.0**-53 if getattr(printer, "precision", "float") == "double" else 2.0**-24
    return ("real", prefix.upper() + "ROUND_ERR", printer.float_literal(4 * n * eps))


def _value_function(name: str, n: int, printer, prefix: str,
                    carried: tuple[tuple[str, str], ...]) -> ShaderFunction:
    """F at u = t - sm, by Estrin's scheme where its sign is certain (ROUND_ERR), else S at
    the point (see RAY_DERIVATIVES). Estrin's chain is about 2 log2(n) operations where
    Horner's is 2n: measured on x^18 + y^18 + z^18 = 1 at 512^2 (with Fh), 8 % a frame."""
    at_point = f"{prefix}S({', '.join(['ray.o + u*ray.d', *_from_ray(carried)])})"
    certain = f"{printer.doprint(sympy.Abs(_sym('h')))} > {prefix.upper()}ROUND_ERR*ray.size"
    value, powers = _estrin(_derivative_coefficients(n, 0), _sym("u"))
    return ShaderFunction(
        name, "F at u = t - sm: Estrin's value where its sign is certain, else S at the "
        "point", (("Ray", "ray"), ("real", "u")), "real",
        (*_lets(powers, printer), ("real", "h", printer.doprint(value))),
        (printer.print_select(certain, "h", at_point),))


def _horner(coefficients: Sequence[sympy.Expr], x: sympy.Expr) -> sympy.Expr:
    """sum_k coefficients[k] x^k as a Horner sum."""
    value: sympy.Expr = sympy.S.Zero
    for c in reversed(coefficients):
        value = value * x + c
    return value


def _derivative_coefficients(n: int, m: int) -> list[sympy.Expr]:
    """The coefficients k!/(k-m)! c_k of F^(m) over the ray record's c0..cn (loop
    invariant; storing them in the record measured no faster, see _ray_setup)."""
    return [sympy.ff(k, m) * _sym(f"ray.c{k}") for k in range(m, n + 1)]


def _estrin(coefficients: Sequence[sympy.Expr], x: sympy.Symbol,
            weights: Sequence[int] | None = None
            ) -> tuple[sympy.Expr, list[tuple[sympy.Symbol, sympy.Expr]]]:
    """sum_k weights[k] coefficients[k] x^k by Estrin's scheme, (c0 + c1 x) + x^2 (c2 + c3 x),
    pairs of pairs by x^4, ...; and the powers x^2, x^4, ... it reads, as lets. Its
    dependency chain is about 2 log2(n) operations where Horner's is 2n (GPU compilers,
    llvmpipe among them, keep a*b + c as two operations), and a march step is bound by its
    chain: with the march point of values_at (_MARCH_POINT), 2-6 % a frame
    (docs/RESULTS.md, section 3).

    A term's integer weight is multiplied onto the power of x it meets where it meets one,
    c3*(2.0*x), not onto its coefficient: in a march loop the coefficients are loop
    invariants, and a compiler keeps every product of them in a register for the whole
    loop (see _weighted_coefficients)."""
    # a term not yet combined is (coefficient, weight); a combined one is an expression
    terms: list = list(zip(coefficients, weights or [1] * len(coefficients), strict=True))
    powers, step = [], x

    def value(term) -> sympy.Expr:
        if not isinstance(term, tuple):
            return term
        c, w = term
        return c if w == 1 else sympy.Mul(w, c)

    def times(term, power: sympy.Expr) -> sympy.Expr:
        if not isinstance(term, tuple):
            return sympy.Mul(term, power, evaluate=False)
        c, w = term
        return sympy.Mul(c, power if w == 1 else sympy.Mul(w, power, evaluate=False),
                         evaluate=False)

    while len(terms) > 1:
        terms = [sympy.Add(value(terms[i]), times(terms[i + 1], step), evaluate=False)
                 if i + 1 < len(terms) else terms[i] for i in range(0, len(terms), 2)]
        if len(terms) > 1:
            square = _sym(f"{x.name}_{2 ** (len(powers) + 1)}")
            powers.append((square, sympy.Mul(step, step, evaluate=False)))
            step = square
    return (value(terms[0]) if terms else sympy.S.Zero), powers


def ray_quantity_ops(n: int, quantity: str) -> int:
    """Operations of a ray quantity (dS, d2S) of a degree-n ray polynomial by Estrin's
    scheme as the march evaluates it (_estrin_function), its powers of s and the integer
    factors on them included, the coefficients taken as given (`implc show`)."""
    m = _DERIVATIVE_ORDER[quantity]
    weights = _weighted_coefficients(n, m)[1] if n >= m else [1]
    value, powers = _estrin([_sym(f"a{k}") for k in range(len(weights))], _sym("s"), weights)
    return count_ops(value) + sum(count_ops(v) for _, v in powers)


def _estrin_derivative(n: int, m: int, x: sympy.Symbol):
    """F^(m) at x by Estrin's scheme: (value, the lets of its powers of x)."""
    return _estrin(_derivative_coefficients(n, m), x)


def _weighted_coefficients(n: int, m: int) -> tuple[list[sympy.Expr], list[int]]:
    """F^(m)'s coefficients (m >= 1) written over those of F', k c_k, with the integer
    weights (k-1)!/(k-m)! that make them k!/(k-m)! c_k (_estrin puts each weight on the
    power of s its term meets). So F'' in a march loop reads only the loop invariants F'
    holds already (up to degree 4): measured on the quartic paper surfaces (hessian,
    1024^2), the march step as fast as taylor's, where F'' over its own coefficients (6c3
    and 12c4, two more values live for the whole loop) cost 1.2-1.5 % a frame on the
    Steiner surface."""
    ks = range(m, n + 1)
    return [sympy.Mul(k, _sym(f"ray.c{k}")) for k in ks], [int(sympy.ff(k - 1, m - 1)) for k in ks]


def _lets(powers, printer) -> list[tuple[str, str, str]]:
    """Printed lets (type, name, value) of (symbol, value) pairs."""
    return [("real", k.name, printer.doprint(v)) for k, v in powers]


def _estrin_function(quantities: tuple[str, ...], n: int, printer) -> ShaderFunction:
    """F' and/or F'' at march parameter s (measured from the ray record's origin, the
    expansion point), each by Estrin's scheme in s."""
    powers: dict[sympy.Symbol, sympy.Expr] = {}  # s^2, s^4, ...: shared by F' and F''
    outputs = []
    for q in quantities:
        coefficients, weights = _weighted_coefficients(n, _DERIVATIVE_ORDER[q])
        value, used = _estrin(coefficients, _sym("s"), weights)
        powers.update(used)
        outputs.append(printer.doprint(value))
    what = ", ".join(quantities)
    return ShaderFunction(_ray_name(quantities),
                          f"{what} at march parameter s: Estrin's scheme on the ray polynomial",
                          (("Ray", "ray"), ("real", "s")), _RETURN_TYPE[len(outputs)],
                          tuple(_lets(powers.items(), printer)), tuple(outputs))


# --- the exact method: root isolation on the ray polynomial ------------------------------

def _lower_solver(constants: Constants, expr: sympy.Expr, printer, prefix: str,
                  max_derived: int, carried: tuple[tuple[str, str], ...]) -> Marcher:
    """The pieces of templates/solver.j2: S and grad at the point (shading, residual),
    the ray record with the coefficients, and P_k (k = 1..n), the (n-k)-th derivative of
    F, a degree-k polynomial in u = t - sm: by Estrin's scheme for k < n (the Newton loops
    that place the critical points are bound by their chains: 7 % a frame on the quartics,
    29 % at degree 12), F itself too, with the rounding bound ROUND_ERR states."""
    programs = build_programs(expr, (("S",), ("grad",)), max_derived)
    functions = [_point_function(name, program, printer, carried)
                 for name, program in programs.items()]
    coefficients = coefficient_program(expr)
    n = len(coefficients.outputs) - 1
    ray_fields, ray = _carry(carried, *_ray_setup(coefficients, printer))
    u = _sym("u")
    bernstein = n >= BERNSTEIN_FROM
    # P_k = F^(n-k): the derivatives, which only place the pieces (level by level), or F'
    # alone (Bernstein subdivision's Newton needs no other)
    for k in ((n - 1,) if bernstein else range(1, n)):
        m = n - k
        what = "F" + "'" * m if m < 4 else f"F^({m})"
        value, powers = _estrin_derivative(n, m, u)
        functions.append(ShaderFunction(
            f"P{k}", f"P{k} = {what}, degree {k} in u = t - sm",
            (("Ray", "ray"), ("real", "u")), "real", tuple(_lets(powers, printer)),
            (printer.doprint(value),)))
    # F itself, whose sign is the answer: Estrin where that sign is certain, else at the
    # point (see RAY_DERIVATIVES)
    functions.append(_value_function(f"P{n}", n, printer, prefix, carried))
    c = [_sym(f"ray.c{k}") for k in range(n + 1)]
    functions.append(ShaderFunction(
        "scale_at", "sum |c_k| |u|^k: the size of F's terms at u, the touch tolerance's unit "
        "(the reference's own: 1e-12 sum |a_k| s^k)", (("Ray", "ray"), ("real", "u")), "real",
        (), (printer.doprint(_horner([sympy.Abs(ck) for ck in c], sympy.Abs(u))),)))
    K = prefix.upper()
    printed = (("real", K + "TOUCH", printer.float_literal(constants.touch)),
               _round_err(n, printer, prefix),
               ("real", K + "XTOL", printer.float_literal(constants.xtol)),
               ("real", K + "CTOL", printer.float_literal(constants.ctol)),
               ("int", K + "NEWTON_STEPS", str(int(constants.newton_steps))),
               ("int", K + "CRIT_STEPS", str(int(constants.crit_steps))))
    bottom = 2 if n >= 3 else 1
    m = n - bottom
    closed = tuple(printer.doprint(v) for v in _derivative_coefficients(n, m))
    empty = Code((), ())
    solver = Solver(n, bottom, closed)
    if bernstein:
        coefficients = _bernstein_lets(n, printer)
        # Newton starts at the zero of the root node's control polygon (the points
        # (w_i, b_i)), not at the secant of its ends: at degree 18 F is far steeper at one
        # end than near the root, and the secant starts next to the other end. Measured on
        # x^18 + y^18 + z^18 = 1 at 512^2: 6.3 -> 4.5 Newton steps a hit pixel, 7 % a frame.
        nodes = tuple(printer.float_literal(-1 + 2 * i / n) for i in range(n + 1))
        solver = Solver(n, bottom, closed, "bernstein", coefficients, BERNSTEIN_DEPTH, nodes)
        value, powers = _estrin(c, u)
        functions.append(ShaderFunction(
            "Fh", "F at u by Estrin's scheme alone: the Newton loop's value, inside a bracket "
            f"whose ends P{n} confirmed", (("Ray", "ray"), ("real", "u")), "real",
            tuple(_lets(powers, printer)), (printer.doprint(value),)))
        printed += (("int", K + "MAX_NODES", str(BERNSTEIN_MAX_NODES)),
                    ("real", K + "MIN_WIDTH", printer.float_literal(2.0 ** -BERNSTEIN_DEPTH)))
    return Marcher("ray-poly", tuple(functions), printed, ray_fields, ray, empty, empty, empty,
                   empty, solver, carried)


def _bernstein_lets(n: int, printer) -> tuple[tuple[str, str], ...]:
    """b_0..b_n, the Bernstein coefficients of a node's polynomial sum_k e_k w^k on
    w in [-1, 1] (e_k: the Taylor coefficients about the node's middle, scaled to its half
    width): b_i = sum_k beta_ik e_k with beta_ik = sum_j C(i, j) C(n-i, k-j) (-1)^(k-j) /
    C(n, k), the blossom of w^k at i ones and n-i minus ones, so |beta_ik| <= 1 and the
    rounding of b is bounded by n eps sum |e_k| (about the node's start, as before, the
    bound grew like 3^n sum |e_k|: 57 wrong or missed pixels of 16,384 at degree 14).
    beta_(n-i),k = (-1)^k beta_ik: the even part (k even) and the odd part are summed once
    for i <= n/2 and give b_i and b_(n-i) by a sum and a difference."""
    e = [_sym(f"e{k}") for k in range(n + 1)]

    def beta(i: int, k: int) -> sympy.Rational:
        return sympy.Rational(sum(comb(i, j) * comb(n - i, k - j) * (-1) ** (k - j)
                                  for j in range(k + 1)), comb(n, k))

    lets: list[tuple[str, str]] = []
    for i in range(n // 2 + 1):
        even = sympy.Add(*(beta(i, k) * e[k] for k in range(0, n + 1, 2)))
        odd = sympy.Add(*(beta(i, k) * e[k] for k in range(1, n + 1, 2)))
        if 2 * i == n:  # the middle coefficient: its odd part is 0
            lets.append((f"b{i}", printer.doprint(even)))
            continue
        lets += [(f"be{i}", printer.doprint(even)), (f"bo{i}", printer.doprint(odd)),
                 (f"b{i}", f"be{i} + bo{i}"), (f"b{n - i}", f"be{i} - bo{i}")]
    return tuple(lets)


# Bernstein subdivision's bounds: a node narrower than 2^-14 of the chord is a leaf (its
# middle is a touching root when |F| there is within TOUCH), and a ray visits at most 96
# nodes (measured: 3-6 on average, 34 at most on Barth's decic at 256^2).
BERNSTEIN_DEPTH = 14
BERNSTEIN_MAX_NODES = 96
