"""Program + Target + Method -> shader text, through jinja2 templates.

Python decides what to compute (derive, optimize, implc/marcher.py's lowering of the
method) and prints every expression and number; templates hold all shader text, and the
only arithmetic they write is the algorithms' own, fixed for every surface (the march
loop, Newton-bisection, the exact solver's quadratic formula, Newton and Halley steps and
Bernstein walk in templates/solver/walk.j2). templates/marcher.j2 is the marcher skeleton of
every target, spelled by templates/<target>/lang.j2, inside the target's program or
library frame. Rendering is strict: a name a template uses but emit does not give is an
error, not an empty string.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cache

import jinja2
import sympy

from .derive import DEFAULT_MAX_DERIVED
from .errors import InputError, OptionError
from .front import param_symbol
from .marcher import choose_form, lower, point_sets
from .methods import Constants, Method, get_method
from .optimize import Program
from .pieces import build_programs, function_name
from .resources import cache_dir, data_dir
from .scaling import scale_exponent, scale_note, scaled
from .scene import SHADING, View, light_directions, shading_for
from .surface import Surface
from .targets import TARGETS, flavor_problem, get_target, prefix_problem

EMITS = ("program", "library")
PARAM_MODES = ("constant", "uniform")
PARAM_UNIFORM_PREFIX = "u_param_"  # parameter R is the uniform u_param_R
# levels of the camera's continued fraction for tan(fov_y/2) (templates/camera.j2)
CAMERA_LEVELS = 8


@dataclass(frozen=True)
class ParamUniform:
    """How one parameter reaches a `--params uniform` shader (docs/reference/drop-ins.md,
    "Parameters as uniforms"): `uniform` is the name the host sets (a GLSL uniform, a
    WGSL struct field), `ref` how the shader's code reads it."""

    name: str  # the parameter's name in the equation
    uniform: str
    ref: str
    value: float  # the surface's value (the default a host starts from)
    offset: int | None = None  # byte offset in the program's uniform struct, if it has one


# A parameter's control (the viewer's slider, a host's input) spans its value
# +- max(|value|, PARAM_MIN_HALF_WIDTH)
PARAM_MIN_HALF_WIDTH = 0.5


def param_range(value: float) -> tuple[float, float]:
    """The (low, high) of a parameter's control, to 6 significant digits (0.35 - 0.5 is
    -0.15, not -0.15000000000000002, in a host's file)."""
    half = max(abs(value), PARAM_MIN_HALF_WIDTH)
    return float(f"{value - half:.6g}"), float(f"{value + half:.6g}")


def param_uniforms(surface: Surface, target: str = "glsl", emit_form: str = "program",
                   prefix: str = "") -> list[ParamUniform]:
    """The parameters of `surface` as uniforms of a `--params uniform` shader, sorted by
    name (parameters only inside constant exponents stay constants, see
    `Surface.uniform_params`), laid out as the target's record says (`ParamLayout`)."""
    result = []
    layout = get_target(target).param_layout[emit_form]
    for i, name in enumerate(surface.uniform_params()):
        uniform = PARAM_UNIFORM_PREFIX + name
        if "__" in uniform:
            raise InputError(f"parameter '{name}' cannot be a shader uniform: names with "
                             "'__' are reserved in GLSL (rename it or use --params constant)")
        names = {"uniform": uniform, "prefix": prefix}
        offset = None if layout.offset is None else layout.offset + 4 * i
        result.append(ParamUniform(name, layout.uniform.format(**names),
                                   layout.ref.format(**names), float(surface.params[name]),
                                   offset))
    return result


@cache
def environment(target: str | None = None) -> jinja2.Environment:
    """The template environment; for a target, with its printer as the global `printer`,
    through which templates/<target>/lang.j2 spells select and the table's functions
    (an imported template sees globals, not the render's context)."""
    cache = cache_dir("templates")  # compiled templates: 0.3 s of every cold compile
    env = jinja2.Environment(
        loader=jinja2.FileSystemLoader(str(data_dir("templates"))),
        bytecode_cache=jinja2.FileSystemBytecodeCache(str(cache)) if cache else None,
        undefined=jinja2.StrictUndefined,
        keep_trailing_newline=True,
        trim_blocks=True,
        lstrip_blocks=True,
        autoescape=False,
    )
    # (abstract type, name) -> (the target's type, name), for function parameters
    env.filters["typed"] = lambda pair, types: (types[pair[0]], pair[1])
    env.filters["typed3"] = lambda field, types: (types[field[0]], *field[1:])
    if target is not None:
        env.globals["printer"] = get_target(target).make_printer()
    return env


def function_quantities(method: Method) -> dict[str, tuple[str, ...]]:
    """Shader function name -> the quantities it returns, for the method's program."""
    return {function_name(q): q for q in point_sets(method)}


def build_functions(expr: sympy.Expr, method: Method,
                    max_derived: int = DEFAULT_MAX_DERIVED) -> dict[str, Program]:
    """Derive and optimize every point function the method needs in the point form
    (jointly CSE'd per function).

    Raises `LimitError` first when the derivatives would exceed `--max-derived`."""
    return build_programs(expr, point_sets(method), max_derived)


@dataclass(frozen=True)
class CompiledShader:
    """What one compile decided, so that nothing above emit decides it again: the text
    and the form it was emitted in (a runner reads its uniforms, a sidecar its evaluation
    form). `warnings` and `notes` are filled by the caller that knows them (the API's
    float32 report, the framing)."""

    text: str
    target: str
    method: str
    form: str  # the evaluation form used: "point" or "ray-poly" (never "auto")
    emit: str  # "program" or "library"
    flavor: str
    precision: str
    prefix: str
    params: str  # "constant" or "uniform"
    uniforms: tuple[ParamUniform, ...]  # empty unless params == "uniform"
    constants: Constants
    warnings: tuple[str, ...] = ()
    notes: tuple[str, ...] = ()


def check_shader_options(target: str, flavor: str | None = None,
                         precision: str | None = None, prefix: str = "",
                         emit_form: str = "program", params: str = "constant") -> None:
    """Raise OptionError where a flavour, precision, prefix, emit form or parameter mode
    does not fit the target (the one place they are checked; the command line calls it
    before any work so that a bad option is reported first)."""
    tgt = get_target(target)
    if flavor is not None and (problem := flavor_problem(tgt, flavor, precision or "float")):
        raise OptionError(f"--flavor: {problem}")
    if precision is not None and precision not in tgt.precisions:
        others = [t.name for t in TARGETS.values() if precision in t.precisions]
        raise OptionError(f"--precision {precision}: {tgt.name} has "
                          f"{' or '.join(tgt.precisions)} only ({precision}: "
                          f"{', '.join(others)})")
    if problem := prefix_problem(prefix, tgt):
        raise OptionError(problem)
    if emit_form not in EMITS:
        raise OptionError(f"unknown emit '{emit_form}'; choose from {', '.join(EMITS)}")
    if params not in PARAM_MODES:
        raise OptionError(f"unknown --params '{params}'; choose from "
                          f"{', '.join(PARAM_MODES)}")
    if params == "uniform" and tgt.flavors[flavor or tgt.default_flavor].get("shadertoy"):
        raise OptionError("--params uniform: the shadertoy flavour has no uniforms of its "
                          "own: use --params constant (the default) with --flavor shadertoy")


def compile_shader(
    surface: Surface,
    target: str = "glsl",
    method: str = "hessian",
    constants: Constants | None = None,
    flavor: str | None = None,
    emit_form: str = "program",
    prefix: str = "",
    precision: str | None = None,
    evaluation: str | None = None,
    params: str = "constant",
    static_params: bool = False,
    declare_params: bool = True,
) -> CompiledShader:
    """The shader for `surface` (its text deterministic, byte for byte) and what was
    decided on the way.

    `params`: "constant" bakes the parameters' values into the expressions; "uniform"
    keeps them as uniforms the host sets at run time (`param_uniforms`), or, with
    `static_params` (a host's node function that takes them as inputs: implc/hosts.py),
    as globals that function sets before its calls (HLSL's `static`, GLSL's plain
    globals). `declare_params` False leaves the uniforms' declarations to the host (an
    ISF input, a Godot uniform with its hint_range: implc/hosts.py); the functions read
    them by the same names."""
    check_shader_options(target, flavor, precision, prefix, emit_form, params)
    tgt = get_target(target)
    meth = get_method(method)
    constants = constants or meth.defaults
    flavor = flavor or tgt.default_flavor
    precision = precision or "float"
    uniforms = param_uniforms(surface, target, emit_form, prefix) if params == "uniform" else []
    printer = tgt.make_printer(precision)
    expr, equation = surface.expr, surface.equation
    if uniforms:  # the parameters as symbols named as the shader reads them
        expr = surface.symbolic_expr.xreplace(
            {param_symbol(u.name): sympy.Symbol(u.ref, real=True) for u in uniforms})
        equation = surface.symbolic_equation
    scale = scale_exponent(surface.expr)  # S's constants brought near 1 for float32
    if scale:
        expr, equation = scaled(expr, scale), f"{equation} ({scale_note(scale)})"
    # the same form as with --params constant
    max_derived = surface.limits.max_derived
    form = choose_form(meth, surface.expr, evaluation or constants.evaluation, max_derived)
    carried = (("Params", "params"),) if uniforms and tgt.params_read_as == "argument" else ()
    marcher = lower(meth, constants, expr, form, printer, prefix, max_derived, carried)
    label = meth.name + (f" (Eq. 4: {constants.taylor2})" if meth.reads_taylor2 else "")
    types = _types(tgt, precision, prefix)
    literals = {"zero": 0.0, "half": 0.5, "one": 1.0, "four": 4.0}
    # the camera, the shading and the entry points: in the precision, or float (see
    # Target.float_shading)
    shade_precision = "float" if precision in tgt.float_shading else precision
    shade_printer = printer if shade_precision == precision else tgt.make_printer("float")
    context = {
        "surface": {"name": surface.name, "equation": equation},
        "params": [{"name": u.name, "uniform": u.uniform, "offset": u.offset,
                    "value": printer.float_literal(u.value),
                    "field": (types["real"], u.uniform, f"parameter {u.name}")}
                   for u in uniforms],
        "params_struct_size": _struct_size(tgt.param_layout[emit_form].offset, len(uniforms)),
        "method": meth.name,
        "method_label": label,
        "form": marcher.form,
        "marcher": marcher,
        "lang": f"{tgt.name}/lang.j2",
        "types": types,
        "lit": {k: printer.float_literal(v) for k, v in literals.items()},
        "shade_types": _types(tgt, shade_precision, prefix),
        "shade_lit": {k: shade_printer.float_literal(v) for k, v in literals.items()},
        "prefix": prefix,
        "flavor": tgt.flavors[flavor],
        "flavor_name": flavor,
        "rules": tgt.rules(flavor),  # for templates/eft.j2
        "precision": precision,
        "static_params": static_params,
        "declare_params": declare_params,
        "shading": print_shading(surface.view, shade_printer),
        "view": _print_view(surface.view, shade_printer),
        "camera": {"levels": [shade_printer.float_literal(float(k))
                              for k in range(2 * CAMERA_LEVELS + 1, 0, -2)],
                   "half_degree": shade_printer.float_literal(math.pi / 360)},
    }
    template = environment(tgt.name).get_template(tgt.templates[emit_form])
    return CompiledShader(template.render(context), tgt.name, meth.name, marcher.form,
                          emit_form, flavor, precision, prefix, params, tuple(uniforms),
                          constants)


def emit(
    surface: Surface,
    target: str = "glsl",
    method: str = "hessian",
    constants: Constants | None = None,
    flavor: str | None = None,
    emit_form: str = "program",
    prefix: str = "",
    precision: str | None = None,
    evaluation: str | None = None,
    params: str = "constant",
) -> str:
    """The shader text alone (`compile_shader(...).text`), for callers that need no more."""
    return compile_shader(surface, target, method, constants, flavor, emit_form, prefix,
                          precision, evaluation, params).text


def eft_probe_text(target: str, flavor: str | None, ops: dict[str, int], count: int,
                   prefix: str = "") -> str:
    """The float32 probe's program of `target` (templates/eft.j2 and its cases, `ops`:
    name -> number), for `count` cases: what `implc probe` runs on each driver."""
    tgt = get_target(target)
    flavor = flavor or tgt.default_flavor
    printer = tgt.make_printer()
    return environment(tgt.name).get_template(tgt.eft_probe).render(
        lang=f"{tgt.name}/lang.j2", types=_types(tgt, "float", prefix), prefix=prefix,
        rules=tgt.rules(flavor), flavor=tgt.flavors[flavor], ops=ops, count=count,
        lit={"zero": printer.float_literal(0.0)})


def _struct_size(offset: int | None, count: int) -> int:
    """Bytes of a uniform struct whose `count` parameters start at `offset`, rounded up to
    16 (a uniform buffer's alignment); 0 when the parameters are not laid out in bytes."""
    return 0 if offset is None else -(-(offset + 4 * count) // 16) * 16


def render_template(name: str, **context) -> str:
    """A helper template (vertex shader, validation harness) by its path under templates/."""
    return environment().get_template(name).render(context)


def _types(tgt, precision: str, prefix: str) -> dict:
    """The skeleton's abstract type names -> the target's spelling."""
    real, vec2, vec3, vec4 = tgt.vector_types[precision]
    return {"real": real, "vec2": vec2, "vec3": vec3, "vec4": vec4, "int": tgt.int_type,
            "bool": "bool",
            "Ray": prefix + "Ray", "Hit": prefix + "Hit", "Params": prefix + "Params"}


def print_shading(view: View, printer) -> dict:
    f = printer.float_literal
    shading = shading_for(view)

    def vec(v) -> list[str]:
        return [f(x) for x in v]

    lights = [
        {"direction": vec(direction), "color": vec(light.color)}
        for light, direction in zip(SHADING.lights, light_directions(view), strict=True)
    ]
    return {
        "front": vec(shading.front),
        "back": vec(shading.back),
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
