"""Lower a method (data, implc/methods.py) and an evaluation form to printed code pieces.

The marcher skeleton (templates/marcher.j2) is written once; what varies by method and
evaluation form is printed here, by the target's printer:
- `functions`: straight-line shader functions, of the point p (and direction d) or of
  the ray and its parameter s (each one jointly CSE'd where it is a Program);
- `ray`: the ray record's fields and how `ray_of(ro, rd)` fills them;
- `values_at(ray, s)`: the method's (F, F', X) at a march point; `fd(ray, s)`: (F, F')
  for the refinement;
- `step_size(ray, s, f0)`: the step rule; `root_in(f0, f1, h)`: the root test.

Evaluation forms (docs/ARCHITECTURE.md) say how a ray quantity at a ray parameter is
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

import sympy

from .derive import DEFAULT_MAX_DERIVED, polynomial_degree
from .errors import InputError
from .interval import (
    check_interval,
    derivative_program,
    range_constants,
    range_function,
    range_program,
)
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
    constant_values,
)
from .optimize import arrange_by_depth
from .options import AUTO_RAY_POLY_MAX_DEGREE, EVAL_CHOICES, EXACT_MAX_DEGREE
from .pieces import (
    COMPONENT,
    QUANTITY_ORDER,
    RETURN_TYPE,
    IntervalMarching,
    Marcher,
    Marching,
    PrintedBody,
    build_programs,
    function_name,
    point_function,
    sym,
)
from .raypoly import (
    carry,
    coefficient_program,
    estrin_function,
    from_ray,
    horner_ops,
    ray_name,
    ray_quantity_ops,
    ray_setup,
)
from .solver import check_exact, lower_solver

# EVAL_CHOICES and AUTO_RAY_POLY_MAX_DEGREE (`auto`'s bound) are plain data in implc/options.py

# When the root test's inputs are ready, in operations (optimize.arrange_by_depth): the
# start sample (F0, F0', X0) first (depth 0), then the step length h, after the step rule,
# then the end sample (F1, F1', X1), evaluated at s0 + h, after everything else.
STEP_LENGTH_READY = 10
END_SAMPLE_READY = 1000
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
REFINE_SET = ("S", "dS")
# A root, not a pole (templates/marcher.j2's trace): a refined point is a root where |F|
# there is at most ACCEPT times |F| at its step's ends: their geometric mean where F
# changes sign over the step, the smaller one where not (a touching root), or F is 0 at an
# end. Toward a root F shrinks to float32's noise (the mean, not the smaller end, keeps a
# root near an end: the smaller one lost one on Steiner's surface on PoCL); toward a pole
# it grows past both ends (the larger end let a pole pass where an end fell nearer to it
# than the refined point); where a Taylor test fired on no root it stays. A ray refines at
# most CANDIDATES steps, a rejected one passed and the march going on behind it (4 lost
# 875 of 9216 pixels with taylor on 1/(x^2+y^2-0.5) + z: a ray crossing its pole cylinder
# twice meets a candidate or two beside each crossing; 8 lost none).
ACCEPT = 0.5
CANDIDATES = 16


def choose_form(method: Method, expr: sympy.Expr, requested: str = "auto",
                max_derived: int = DEFAULT_MAX_DERIVED) -> str:
    """The evaluation form `method`'s shader for `expr` uses when `requested` is asked (as
    `lower` prints it; what a render's sidecar records): the exact solver works on the ray
    polynomial, the interval method at points. A marcher takes what is asked, and under
    `auto` ray-poly where its march step evaluates fewer operations (step_ops) and the
    degree is at most AUTO_RAY_POLY_MAX_DEGREE (where it measured as accurate), else point:
    the faster form on every surface timed in both
    (docs/journal/2026-12-01-marcher-and-forms.md)."""
    if requested not in EVAL_CHOICES:
        raise InputError(f"unknown evaluation form '{requested}'; choose from "
                         f"{', '.join(EVAL_CHOICES)}")
    degree = polynomial_degree(expr)
    if requested == "ray-poly" and degree is None:
        raise InputError("--eval ray-poly needs a polynomial surface; this one is not "
                         "(use --eval point or auto)")
    if method.solves:
        return "ray-poly"
    if method.bounds or degree is None:
        return "point"
    if requested != "auto":
        return requested
    if degree > AUTO_RAY_POLY_MAX_DEGREE:
        return "point"
    cheaper = (step_ops(method, expr, "ray-poly", max_derived)
               < step_ops(method, expr, "point", max_derived))
    return "ray-poly" if cheaper else "point"


def step_ops(method: Method, expr: sympy.Expr, form: str,
             max_derived: int = DEFAULT_MAX_DERIVED) -> int:
    """Operations a march step of `method` evaluates in `form` (`--eval auto`'s measure,
    `implc show` prints it): its point functions after optimization, plus Estrin's sums
    for the ray derivatives. The ray coefficients, once a ray, are left out: counted
    over taylor's steps (about 30 a pixel at 512^2 on the sweep's surfaces), they would
    give Chmutov's surfaces the point form, which measured 2-9 % slower there."""
    degree = polynomial_degree(expr)
    programs = build_programs(expr, point_sets(method, form), max_derived)
    calls = [call for quantities in _sample_groups(method).values()
             for call in _split(quantities, form)]
    return sum(programs[function_name(qs)].ops_after if kind == "point" else
               sum(ray_quantity_ops(degree, q) for q in qs) for kind, qs in calls)


def default_method(expr: sympy.Expr) -> str:
    """The method `-m` defaults to: `exact` for polynomials up to EXACT_MAX_DEGREE (no false
    and no missed roots, the fastest there), `interval` for any other surface whose
    functions all have interval rules (no missed sign change; faster than hessian on every
    bundled non-polynomial, docs/RESULTS.md), else `hessian`."""
    degree = polynomial_degree(expr)
    if degree is not None and degree <= EXACT_MAX_DEGREE and not _exact_too_long(expr):
        return "exact"
    try:
        check_interval(expr)
    except InputError:
        return "hessian"
    return "interval"


# exact's ray coefficients by Horner's scheme (a polynomial written out at length, or
# whose tree would be too large), in operations, above which the default method is the
# interval walk: a product of ten dense quadratics expands to 1,771 monomials and 31,456
# operations, 4.4 s of compiling and a shader of 18,000 lines, where its interval program
# is S as written. The corpus's longest, row 246's degree-18 knot, takes 7,221.
EXACT_DEFAULT_MAX_OPS = 15_000


def _exact_too_long(expr: sympy.Expr) -> bool:
    ops = horner_ops(expr)
    return ops is not None and ops > EXACT_DEFAULT_MAX_OPS


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
        return lower_solver(constants, expr, printer, prefix, max_derived, carried)
    const_names = {c: sympy.Symbol(prefix.upper() + c.name, real=True)
                   for c in CONSTANT_SYMBOLS}
    if method.bounds:  # F's enclosure over a segment works on S's tree, at points
        form = "point"

    def print_expr(expr: sympy.Basic) -> str:
        """`expr` in the target's language, the method's constants by their shader names."""
        return printer.doprint(expr.xreplace(const_names))

    wanted = evaluations(method, form)
    programs = build_programs(expr, point_sets(method, form), max_derived, printer.precision)
    functions = [point_function(name, program, printer, carried)
                 for name, program in programs.items()]
    fields, ray = (), PrintedBody((), ())  # the point form's ray record: o, d and sm only
    if form == "ray-poly":
        coefficients = coefficient_program(expr, printer.precision)
        n = len(coefficients.outputs) - 1
        fields, ray = ray_setup(coefficients, printer, size=False)
        functions += [estrin_function(q, n, printer) for kind, q in wanted if kind == "ray"]
    ray_fields, ray = carry(carried, fields, ray)
    by_name = {f.name: f for f in functions}

    def call(kind: str, quantities: tuple[str, ...], arg: sympy.Expr,
             point: str | None = None) -> str:
        at = f"({print_expr(arg)})" if arg.is_Add else print_expr(arg)
        if kind == "ray":
            return f"{prefix}{ray_name(quantities)}(ray, {print_expr(arg)})"
        fn = by_name[function_name(quantities)]
        args = [point or f"ray.o + {at}*ray.d", "ray.d"][: len(fn.params) - len(carried)]
        args += from_ray(carried)
        return f"{prefix}{fn.name}({', '.join(args)})"

    def calls(quantities: tuple[str, ...], arg: sympy.Expr, stem: str, lets: list,
              replace: dict, point: str | None = None) -> None:
        for kind, qs in _split(quantities, form):
            name = f"{stem}{len(lets)}"
            lets.append((RETURN_TYPE[len(qs)], name, call(kind, qs, arg, point)))
            for i, q in enumerate(qs):
                part = name if len(qs) == 1 else f"{name}.{COMPONENT[i]}"
                replace[_apply(q, arg)] = sym(part)

    lets: list = []
    replace: dict = {}
    for arg, group in _sample_groups(method).items():
        # the march point s = s0 + h as (o + s0 d) + h d: o + s0 d is known a step early,
        # so the point is one operation after h, not two after s (templates/marcher.j2)
        calls(group, arg, "e", lets, replace, _MARCH_POINT if arg == S else None)
    sample = PrintedBody(tuple(lets), tuple(print_expr(e.xreplace(replace)) for e in method.sample))
    lets, replace = [], {}
    calls(REFINE_SET, S, "e", lets, replace)
    fd = PrintedBody(tuple(lets), tuple(print_expr(_apply(q, S).xreplace(replace))
                                        for q in REFINE_SET))

    ends0 = {F0: sym("f0.x"), D0: sym("f0.y"), X0: sym("f0.z")}
    ends1 = {F1: sym("f1.x"), D1: sym("f1.y"), X1: sym("f1.z")}
    step = PrintedBody((), (print_expr(method.step.xreplace(ends0)),))

    rule = method.root_rule(constants.taylor2)
    ends = {**ends0, **ends1}

    # the end sample is computed last: products and sums take it last (arranged after
    # every substitution, which would flatten the nesting again)
    names = {**ends, **const_names}
    lets, value = arrange_by_depth([(s, v.xreplace(names)) for s, v in rule.lets],
                                   rule.value.xreplace(names),
                                   {**dict.fromkeys(ends1.values(), END_SAMPLE_READY),
                                    H: STEP_LENGTH_READY})
    root = PrintedBody(tuple(("real", s.name, printer.doprint(v)) for s, v in lets),
                (printer.doprint(value),), rule.what)

    used = set().union(*(e.free_symbols for e in (*method.sample, method.step, rule.value,
                                                    *(v for _, v in rule.lets))))
    values = constant_values(constants)
    printed = tuple(("real", const_names[c].name, printer.float_literal(values[c]))
                    for c in CONSTANT_SYMBOLS if c in used)
    printed += (("real", prefix.upper() + "ACCEPT", printer.float_literal(ACCEPT)),
                ("int", prefix.upper() + "CANDIDATES", str(CANDIDATES)),
                ("int", prefix.upper() + "MAX_STEPS", str(int(constants.max_steps))),
                ("int", prefix.upper() + "REFINE_STEPS", str(int(constants.refine_steps))))
    if method.bounds:
        derivative = derivative_program(expr, max_derived)
        monotone = derivative is not None  # whether FD_range encloses F' too
        functions.append(range_function("FD_range", derivative, printer, prefix, carried)
                         if monotone else
                         range_function("F_range", range_program(expr), printer, prefix,
                                        carried))
        printed = range_constants(printer, prefix) + printed[-1:]  # and REFINE_STEPS
        return IntervalMarching(form, tuple(functions), printed, ray_fields, ray, carried, fd,
                                monotone)
    return Marching(form, tuple(functions), printed, ray_fields, ray, carried, sample, fd, step,
                    root)


def _apply(quantity: str, arg: sympy.Expr) -> sympy.Expr:
    fn = next(f for f in RAY_FUNCTIONS if RAY_QUANTITIES[f.__name__] == quantity)
    return fn(arg)
