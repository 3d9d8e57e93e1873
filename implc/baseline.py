"""Hand-written baselines: the bar implc's generated marchers must meet.

`templates/baseline/<surface>.frag.j2` is a GLSL 330 program written by hand for one
surface (not generated), doing the same work as implc's program for a method: the same
step rule and root test, the same refinement after the march loop, the same camera, clip
sphere, shading and outputs (colour + aux). Its only template fields are the base step
and the shading constants, so that both run the same scene. `implc bench --baseline` (or
`make bench-baseline`) times them in turns with the generated programs and reports
generated / baseline speed.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

from .emit import CompiledShader, print_shading, render_template
from .errors import InputError
from .methods import Constants
from .surface import Surface
from .targets import get_target

if TYPE_CHECKING:
    from .render.gl import GlRunner

# (surface key, method) -> whether its hand-written test is second order (Eq. 4, F''
# in the interval) rather than first order (Eq. 3): the one switch of the template.
BASELINES: dict[tuple[str, str], bool] = {("cross-cap", "taylor"): False,
                                          ("cross-cap", "hessian"): True,
                                          ("barth-decic", "exact"): False}


def has_baseline(key: str, method: str) -> bool:
    return (key, method) in BASELINES


def baseline_program(key: str, method: str, constants: Constants, surface: Surface) -> str:
    """The hand-written program's text with this step and the surface's shading."""
    if not has_baseline(key, method):
        raise KeyError(f"no hand-written baseline for {key} with {method}")
    printer = get_target("glsl").printer()
    return render_template(f"baseline/{key}.frag.j2", method=method,
                           second_order=BASELINES[key, method],
                           step=printer.float_literal(constants.step),
                           shading=print_shading(surface.view, printer))


def open_baseline_runner(key: str, method: str, constants: Constants, surface: Surface,
                         width: int, height: int):
    from .render.gl import GlRunner

    vertex = render_template("glsl/fullscreen.vert.j2", version="330 core")
    return GlRunner(baseline_program(key, method, constants, surface), vertex, surface.view,
                    width, height)


@dataclass(frozen=True)
class SolverBaseline:
    """A hand-written solver for any polynomial surface, not one surface: its template
    under templates/baseline/ (the degree, S, grad and the ray polynomial's coefficients
    are its only fields, printed by implc's own printer) and the generated method it is
    the bar of."""

    template: str
    method: str
    about: str
    lowest_degree: int


# name -> the solver; scripts/yuksel_baseline.py times them against the generated method
SOLVERS: dict[str, SolverBaseline] = {
    "yuksel": SolverBaseline(
        "baseline/yuksel.frag.j2", "exact",
        "Yuksel's first-root solver (HPG 2022, cyPolynomial.h PolynomialFirstRoot), written "
        "spill-free after Peters et al. (VMV 2023)", 3),
}
# FindClosed's guard on its steps: bisection alone halves a chord of ~4 to float32's
# resolution in ~22 (Yuksel's loop has none; Peters' has 90)
SOLVER_MAX_STEPS = 48


def solver_program(name: str, surface: Surface, constants: Constants,
                   precision: str = "float", flavor: str = "330") -> str:
    """The hand-written solver's program for `surface` (polynomial, degree >= the
    solver's lowest), in `precision` (double: the surface and the solver, as implc's
    --precision double) and GLSL `flavor` (330 for the GL runner, 450 for SPIR-V)."""
    from math import comb

    from .pieces import build_programs, point_function
    from .raypoly import coefficient_program, ray_setup
    from .scaling import scale_exponent, scaled
    from .solver import check_exact

    solver = SOLVERS[name]
    degree = check_exact(surface.expr)
    if degree < solver.lowest_degree:
        raise InputError(f"the {name} baseline needs degree {solver.lowest_degree} or more "
                         f"(this surface has {degree})")
    target = get_target("glsl")
    printer = target.make_printer(precision)
    expr = scaled(surface.expr, scale_exponent(surface.expr))  # as compile_shader does
    programs = build_programs(expr, (("S",), ("grad",)), surface.limits.max_derived)
    functions = [point_function(f, program, printer) for f, program in programs.items()]
    _, ray = ray_setup(coefficient_program(expr, precision), printer, size=False)
    # level k (D_m = F^(m)/m!, m = n - k) -> i -> (i+1)/(i+1-m), the ratio of its
    # coefficients' binomials C(i+1, m)/C(i, m) (None for 1), for Horner's rule on x
    ratios = {k: {i: None if k == degree else printer.float_literal((i + 1) / (i + 1 - degree + k))
                  for i in range(degree - k, degree)} for k in range(3, degree + 1)}
    real, vec2, vec3, vec4 = target.vector_types[precision]
    shading = print_shading(surface.view, target.make_printer("float"))
    return render_template(
        solver.template, n=degree, flavor=target.flavors[flavor],
        double=precision == "double",
        types={"real": real, "vec2": vec2, "vec3": vec3, "vec4": vec4},
        functions=functions, ray=ray, w=ratios,
        q1=printer.float_literal(float(degree - 1)),
        q2=printer.float_literal(float(comb(degree, 2))),
        xtol=printer.float_literal(constants.xtol), ctol=printer.float_literal(constants.ctol),
        max_steps=SOLVER_MAX_STEPS, shading=shading)


def open_solver_runner(name: str, surface: Surface, constants: Constants, width: int,
                       height: int, precision: str = "float") -> GlRunner:
    """The GL runner (llvmpipe here) of the hand-written solver's program."""
    from .render.gl import GlRunner

    vertex = render_template("glsl/fullscreen.vert.j2", version="330 core")
    return GlRunner(solver_program(name, surface, constants, precision), vertex,
                    surface.view, width, height)


def solver_shader(name: str, surface: Surface, constants: Constants,
                  precision: str = "float") -> CompiledShader:
    """The hand-written solver's program as GLSL 450 in implc's compiled-shader record, so
    that render/gpu_stats.py takes it to SPIR-V and RADV as it takes implc's own."""
    text = solver_program(name, surface, constants, precision, flavor="450")
    return CompiledShader(text, "glsl", SOLVERS[name].method, "ray-poly", "program", "450",
                          precision, "", "constant", (), constants)
