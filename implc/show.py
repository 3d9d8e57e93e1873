"""`implc show`: what implc understood and what it will compute, for people to read."""

from __future__ import annotations

import sympy

from .derive import Derivatives, polynomial_degree
from .emit import build_functions, function_quantities
from .float32 import float32_report
from .marcher import choose_form, evaluations, step_ops
from .methods import Constants, Method
from .options import AUTO_RAY_POLY_MAX_DEGREE, T_TOL
from .pieces import build_programs
from .raypoly import (
    HORNER_ABOVE,
    coefficient_program,
    coefficient_route,
    estrin_derivative_ops,
    ray_quantity_ops,
)
from .scaling import scale_exponent, scale_note
from .solver import (
    BERNSTEIN_FROM,
    BERNSTEIN_MAX_NODES,
    RECENTER_FROM,
    ROBUST_NEWTON_BELOW,
    exact_coefficients,
    in_chebyshev,
    re_expands,
    walk_cost,
)
from .surface import Surface
from .targets import where_precision
from .textform import to_text, value_text


def describe(surface: Surface, method: Method) -> str:
    d = Derivatives(surface.expr, surface.limits.max_derived)
    degree = polynomial_degree(surface.expr)
    equation, *substituted = surface.equation_lines()
    lines = [
        f"surface:   {surface.name} ({surface.origin})",
        f"equation:  {equation}",
        *(f"           {line}" for line in substituted),
        f"degree:    {degree if degree is not None else 'not a polynomial'}",
    ]
    if surface.params:
        lines.append("params:    " + ", ".join(f"{k} = {value_text(v)}"
                                               for k, v in surface.params.items()))
    if degree is not None:
        lines += _float32_lines(surface, degree, d.gradient)
    lines += [
        "",
        "derived (point form: p = (x, y, z), unit ray direction D = (dx, dy, dz)):",
        f"  dS/dx      = {_short(d.gradient[0])}",
        f"  dS/dy      = {_short(d.gradient[1])}",
        f"  dS/dz      = {_short(d.gradient[2])}",
        f"  Laplacian  = {_short(d.laplacian)}",
        f"  F'(t)      = grad S . D = {_short(d.directional)}",
        f"  F''(t)     = D^T H D = {_short(d.second_directional)}",
        "",
        f"point form: shader functions for method '{method.name}' (ops before -> after "
        "optimization):",
    ]
    total_before = total_after = 0
    for name, program in build_functions(surface.expr, method,
                                         surface.limits.max_derived).items():
        quantities = ", ".join(function_quantities(method)[name])
        lines.append(
            f"  {name:<5} ({quantities}): {program.ops_before:>6} -> {program.ops_after:<6}"
            f" ({len(program.assignments)} temporaries)"
        )
        total_before += program.ops_before
        total_after += program.ops_after
    lines.append(f"  total: {total_before} -> {total_after}")
    if method.bounds:
        lines += _interval_lines(surface)
    lines += _ray_poly_counts(surface, method, degree)
    return "\n".join(lines)


def _float32_lines(surface: Surface, degree: int,
                   gradient: tuple[sympy.Expr, ...]) -> list[str]:
    """How far float32 rounding moves the surface: S's at sampled points, and (where the
    exact method's Newton reads F from the ray's coefficients) theirs on the view's pixel
    rays (implc/conditioning.py); a warning, and the remedy, where either is too far."""
    report = float32_report(surface.expr, surface.view, degree, gradient)
    c, ray = report.point, report.ray
    if c is None:
        return ["float32:   not measured (S is not a polynomial in x, y, z as written, or it "
                "changes sign nowhere framing samples)"]
    lines = [f"float32:   a rounding of S moves the surface by {c.median:.1e} (median), "
             f"{c.p90:.1e} (p90) at {c.points:,} sampled points; {100 * c.far:.1f} % move "
             f"more than {T_TOL:g}, the distance the counts call a wrong root"]
    if report.point_warns:
        lines.append("           warning: float32 cannot hold this surface: expect wrong "
                     "pixels from every method (exact's own measure is below)")
    if ray is not None:
        lines.append(f"           exact's ray coefficients (its walk reads them from "
                     f"degree {ROBUST_NEWTON_BELOW}), rounded as its shader rounds them, move "
                     f"the first root by {ray.median:.1e} (median), {ray.p90:.1e} (p90) on "
                     f"{ray.points:,} pixel rays; {100 * ray.far:.2f} % more than {T_TOL:g}")
        if report.ray_warns:
            lines.append(f"           warning: {report.ray_pixels}")
    scale = scale_exponent(surface.expr)
    if scale:
        lines.append(f"           measured as the shader computes S: {scale_note(scale)}")
    if report.point_warns or report.ray_warns:
        lines.append("           in double it holds: --precision double with "
                     + where_precision("double"))
    return lines


def _interval_lines(surface: Surface) -> list[str]:
    """What one node of the interval walk evaluates (templates/interval.j2)."""
    from .interval import derivative_program, range_program

    joint = derivative_program(surface.expr, surface.limits.max_derived)
    program = joint or range_program(surface.expr)
    what = "F and F'" if joint else "F (no monotonic test: F' has no interval rule)"
    return ["", f"interval: per node, the enclosure of {what} over the segment: "
                f"{len(program.assignments)} lets"]


def _ray_poly_counts(surface: Surface, method: Method, degree: int | None) -> list[str]:
    """The ray-poly form's costs: once per ray (the coefficients) and per march step."""
    if degree is None:
        return ["", "ray-poly form: not available (S is not a polynomial)"]
    if method.bounds:
        return ["", "ray-poly form: not used (the interval method encloses S's tree over "
                    "segments)"]
    coefficients = coefficient_program(surface.expr, "float")
    if method.solves:
        chebyshev = in_chebyshev(surface.expr, "float")
        coefficients = exact_coefficients(surface.expr, "float")
        # double's program differs where powers stand alone on Horner's route, and where
        # double takes Horner's route for its registers (raypoly.DOUBLE_HORNER_FROM)
        double = coefficient_program(surface.expr, "double").ops_after
        route = coefficient_route(surface.expr)
        double_route = coefficient_route(surface.expr, "double")
        return [
            "",
            "exact (root isolation of the ray polynomial; no marching):",
            f"  coefficients c0..c{degree}, once per ray: {coefficients.ops_before} -> "
            f"{coefficients.ops_after} ops ({len(coefficients.assignments)} temporaries), "
            + (CHEBYSHEV_ROUTE if chebyshev else ROUTES[route]),
            *([f"  in double (--precision double): {double} ops (one Horner's rule a "
               "coefficient, in o^2 where its powers share a parity)"
               + ("" if double_route == route else
                  ", by Horner's scheme: the tree's power tables hold too many registers "
                  "in double")]
              if double != coefficients.ops_after else []),
            *_solver_lines(surface.expr, degree, coefficients.ops_after,
                           surface.limits.max_derived, chebyshev),
        ]
    quantities = [q for kind, qs in evaluations(method, "ray-poly") if kind == "ray"
                  for q in qs]
    per_step = ", ".join(f"{q} {ray_quantity_ops(degree, q)}"
                         for q in dict.fromkeys(quantities))
    point = [" + ".join(qs) for kind, qs in evaluations(method, "ray-poly")
             if kind == "point" and qs not in (("S",), ("grad",))]
    limit = surface.limits.max_derived
    costs = {form: step_ops(method, surface.expr, form, limit) for form in ("point", "ray-poly")}
    auto = choose_form(method, surface.expr, "auto", limit)
    return [
        "",
        f"per march step: point form {costs['point']} ops, ray-poly form "
        f"{costs['ray-poly']} ops; --eval auto takes {auto}"
        + (f" (ray-poly only up to degree {AUTO_RAY_POLY_MAX_DEGREE}, where it measured as "
           "accurate)" if degree > AUTO_RAY_POLY_MAX_DEGREE else ""),
        "ray-poly form:",
        f"  coefficients c0..c{degree}, once per ray: {coefficients.ops_before} -> "
        f"{coefficients.ops_after} ops ({len(coefficients.assignments)} temporaries)",
        f"  per evaluation, Estrin's scheme (powers of s included, shared between F' and "
        f"F''): "
        f"{per_step or 'none'}; F and {', '.join(point) or 'nothing else'} at the point",
    ]


ROUTES = {"tree": "by truncated arithmetic over S's tree as written, jointly CSE'd",
          "horner": f"by Horner's scheme nested over x, y, z, powers standing alone by a "
                    f"Taylor shift (S is written out at length: over {HORNER_ABOVE} "
                    f"operations; counted as printed for float32)"}


CHEBYSHEV_ROUTE = ("from S in Chebyshev's basis of the box that holds its surface (in float32, "
                   "where that basis holds S better than its monomials: implc/chebyshev.py)")


def _short(expr: sympy.Expr, limit: int = 200) -> str:
    text = to_text(expr)[: -len(" = 0")]
    return text if len(text) <= limit else text[:limit] + " ..."


def _solver_lines(expr: sympy.Expr, degree: int, coefficient_ops: int,
                  max_derived: int, chebyshev: bool) -> list[str]:
    """The exact solver's float32 strategy at this degree, its work per node or level,
    and (for the Bernstein walk) the operations a ray costs."""
    if chebyshev:  # S at the point by Clenshaw's recurrences
        from .chebyshev import chebyshev_program

        s_ops = chebyshev_program(expr).ops_after
    else:
        s_ops = build_programs(expr, (("S",),), max_derived)["S"].ops_after
    if degree < BERNSTEIN_FROM:
        # F (P_n): Estrin's value and S at the point, both computed; a Newton or Halley
        # iteration reads F, F' and F''
        f = estrin_derivative_ops(degree, 0) + s_ops + 6
        step = f + sum(estrin_derivative_ops(degree, m) for m in (1, 2) if m < degree)
        # the quartic's one loop solves F's root and an extremum: 2 x NEWTON_STEPS + 1
        steps = Constants().newton_steps
        cap = 2 * steps + 1 if degree == 4 else steps
        return [f"  strategy: critical points level by level (degree < {BERNSTEIN_FROM}): "
                f"derivatives P1..P{degree - 1} of F by Estrin's scheme, F by Estrin's "
                "scheme where its sign is certain, else S at the point",
                f"  per ray, about {coefficient_ops} + iterations x {step} operations (F, F' "
                f"and F'' at a Newton or Halley iteration): {coefficient_ops + 5 * step:,} at "
                f"5 iterations, {coefficient_ops + cap * step:,} at {cap}, the bound"
                + (f" of each of up to {degree - 1} rounds" if degree == 4 else "")]
    cost = walk_cost(degree, s_ops, chebyshev)
    node = cost.node + cost.node_end

    def per_ray(nodes: int, steps: int) -> str:
        total = coefficient_ops + cost.node_end + nodes * node + steps * cost.newton_step
        return f"{total:,} at {nodes} nodes and {steps} Newton steps"

    return [
        f"  strategy: Bernstein subdivision (degree >= {BERNSTEIN_FROM}): per node a Taylor "
        f"shift ({degree * (degree + 1) // 2} multiply-adds), {degree} scalings, the "
        f"Bernstein sums and the sign changes ({cost.node} operations) and F at the node's "
        f"end (S at the point, {cost.node_end}); then Newton, F "
        f"{'at the point' if degree < ROBUST_NEWTON_BELOW or chebyshev else 'by Estrin'} "
        "and F' by "
        f"Estrin's scheme, {cost.newton_step} a step",
        f"  per ray, about {coefficient_ops} + {cost.node_end} + nodes x {node} + Newton "
        f"steps x {cost.newton_step} operations: {per_ray(2, 5)}, {per_ray(6, 5)} "
        f"(measured: 2-6 nodes a ray on average, at most {BERNSTEIN_MAX_NODES}; 4.5 Newton "
        "steps a hit pixel at degree 18)",
        *([f"  a node in doubt re-expands F about its own middle (degree >= {RECENTER_FROM} "
           f"in Chebyshev's basis): {coefficient_ops} operations more each time, paid by the "
           f"SIMD group of any lane that does (measured on Chmutov's T16, T18, T20 at 256^2: "
           f"16 %, 22 %, 28 % of the pixels, 51 %, 60 %, 67 % of 8x8 groups)"]
          if re_expands(expr, "float") else []),
    ]
