"""Program + Target + Method -> shader text, through jinja2 templates.

Python decides what to compute (derive, optimize) and prints every expression and number;
templates (templates/<target>/) hold all shader text and do no math. Rendering is
strict: a name a template uses but emit does not give is an error, not an empty string.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import jinja2
import sympy

from .derive import Derivatives, current_max_derived
from .errors import InputError
from .methods import Constants, Method, get_method
from .optimize import Program, optimize
from .resources import data_dir
from .scene import SHADING, View, light_directions
from .surface import Surface
from .symbols import DIRECTION, POINT
from .targets import get_target

EMITS = ("program", "library")
PREFIX_CHARS = set("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_")


@dataclass(frozen=True)
class ShaderFunction:
    """One straight-line shader function: its inputs, code lines and returned values."""

    name: str
    uses_direction: bool
    assignments: tuple[tuple[str, str], ...]
    outputs: tuple[str, ...]
    program: Program


@lru_cache(maxsize=1)
def environment() -> jinja2.Environment:
    return jinja2.Environment(
        loader=jinja2.FileSystemLoader(str(data_dir("templates"))),
        undefined=jinja2.StrictUndefined,
        keep_trailing_newline=True,
        trim_blocks=True,
        lstrip_blocks=True,
        autoescape=False,
    )


def build_functions(expr: sympy.Expr, method: Method) -> dict[str, Program]:
    """Derive and optimize every function the method needs (jointly CSE'd per function).

    Raises `LimitError` first when the derivatives would exceed `--max-derived`."""
    return dict(_build_functions(expr, method.name, current_max_derived()))


@lru_cache(maxsize=32)
def _build_functions(
    expr: sympy.Expr, method_name: str, max_derived: int
) -> tuple[tuple[str, Program], ...]:
    method = get_method(method_name)
    derivatives = Derivatives(expr, max_derived)
    programs: dict[str, Program] = {}
    for name, quantities in method.all_functions().items():
        outputs = [e for q in quantities for e in derivatives.quantity(q)]
        needs_direction = any(q in ("dS", "d2S") for q in quantities)
        inputs = POINT + DIRECTION if needs_direction else POINT
        programs[name] = optimize(outputs, inputs)
    return tuple(programs.items())


def print_function(name: str, program: Program, printer) -> ShaderFunction:
    return ShaderFunction(
        name=name,
        uses_direction=len(program.inputs) == 6,
        assignments=tuple((s.name, printer.doprint(v)) for s, v in program.assignments),
        outputs=tuple(printer.doprint(o) for o in program.outputs),
        program=program,
    )


def emit(
    surface: Surface,
    target: str = "glsl",
    method: str = "hessian",
    constants: Constants | None = None,
    flavor: str | None = None,
    emit: str = "program",
    prefix: str = "",
    precision: str | None = None,
) -> str:
    """The complete shader text for `surface` (deterministic, byte for byte)."""
    tgt = get_target(target)
    meth = get_method(method)
    constants = constants or meth.defaults
    flavor = flavor or tgt.default_flavor
    if flavor not in tgt.flavors:
        choices = ", ".join(tgt.flavors)
        raise InputError(f"unknown {target} flavor '{flavor}'; choose from {choices}")
    if emit not in EMITS:
        raise InputError(f"unknown emit '{emit}'; choose from {', '.join(EMITS)}")
    if not set(prefix) <= PREFIX_CHARS or (prefix and prefix[0].isdigit()):
        raise InputError(f"--prefix must be letters, digits and '_' (got '{prefix}')")
    precision = precision or "float"
    if precision not in tgt.precisions:
        raise InputError(f"target {target} supports precision {', '.join(tgt.precisions)}")
    printer = tgt.printer(precision) if len(tgt.precisions) > 1 else tgt.printer()
    functions = {
        name: print_function(name, program, printer)
        for name, program in build_functions(surface.expr, meth).items()
    }
    context = {
        "surface": {"name": surface.name, "equation": surface.equation},
        "method": meth.name,
        "c": _print_constants(constants, printer),
        "taylor2": constants.taylor2,
        "functions": functions,
        "types": tgt.vector_types,
        "prefix": prefix,
        "flavor": tgt.flavors[flavor],
        "flavor_name": flavor,
        "precision": precision,
        "shading": _print_shading(surface.view, printer),
        "view": _print_view(surface.view, printer),
    }
    template = environment().get_template(tgt.templates[emit])
    return template.render(context)


def render_template(name: str, **context) -> str:
    """A helper template (vertex shader, validation harness) by its path under templates/."""
    return environment().get_template(name).render(context)


def _print_constants(c: Constants, printer) -> dict[str, str]:
    f = printer.float_literal
    return {
        "step": f(c.step),
        "tau1": f(c.tau1),
        "tau2": f(c.tau2),
        "tau3": f(c.tau3),
        "eps": f(c.eps),
        "max_steps": str(int(c.max_steps)),
        "refine_steps": str(int(c.refine_steps)),
    }


def _print_shading(view: View, printer) -> dict:
    f = printer.float_literal

    def vec(v) -> list[str]:
        return [f(x) for x in v]

    lights = [
        {"direction": vec(direction), "color": vec(light.color)}
        for light, direction in zip(SHADING.lights, light_directions(view), strict=True)
    ]
    return {
        "front": vec(SHADING.front),
        "back": vec(SHADING.back),
        "background": vec(SHADING.background),
        "ambient": f(SHADING.ambient),
        "specular": f(SHADING.specular),
        "shininess": f(SHADING.shininess),
        "lights": lights,
    }


def _print_view(view: View, printer) -> dict:
    f = printer.float_literal
    return {
        "eye": [f(x) for x in view.eye],
        "target": [f(x) for x in view.target],
        "up": [f(x) for x in view.up],
        "fov_y": f(view.fov_y_deg),
        "clip_center": [f(x) for x in view.clip_center],
        "clip_radius": f(view.clip_radius),
    }
