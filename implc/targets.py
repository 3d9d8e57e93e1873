"""THE target registry: one record per shader language, read by emit, validate, render,
corpus and the command line's choices and help.

A target is its printer (implc/backends/<name>.py, which also holds its function
spellings), its templates (templates/<name>/), the file extensions
`implc validate` reads as its language, the validator that runs its real compiler, the
render backends that run its program, and its flavours and precisions. Adding a target
is one record here plus those files (CONTRIBUTING.md "Adding a target").

Layering (docs/explanation/architecture.md "Layers"): the registry sits below emit, which
reads the printer,
templates, flavours and precisions from it. The validator and the runners sit above emit
(they compile and run what emit writes), so a record names them as "module:function"
strings, imported by `resolve` when they are called; the printers too ("module:Class"),
so that the registry is plain data the command line reads without importing sympy
(`implc --help` stays fast). tests/test_targets.py checks that every reference resolves.
"""

from __future__ import annotations

import importlib
import re
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field


def resolve(reference: str) -> Callable:
    """'implc.validate:validate_glsl' -> that function, imported now."""
    module, _, name = reference.partition(":")
    return getattr(importlib.import_module(module), name)


@dataclass(frozen=True)
class Backend:
    """A render backend: the runner of one target's program at one precision.

    A precision is a backend of its own (`cl`, `cl-double`); every runner factory has
    the same signature: (CompiledShader, View, width, height) -> Runner, the shader being
    its target's default flavour at the backend's precision (render/run.py).
    """

    runner: str  # "module:function", the runner factory
    about: str  # one line for `implc render --help`
    precision: str = "float"
    # "module:function" that opens the backend's runtime (a GL context, a wgpu device, an
    # OpenCL device) or raises ToolError saying why not: tests skip (or fail under CI) on it
    probe: str = ""
    # the flavour of the target's program it runs ("": the target's default)
    flavor: str = ""


# GLSL flavour -> how the program form is framed (read by templates/glsl/program.glsl.j2).
# `double`: how the flavour gets double precision (--precision double): "extension"
# (GL_ARB_gpu_shader_fp64, which GLSL 330 needs), "core" (GLSL 4.00 on), or None (GLSL ES
# and WebGL, hence Shadertoy, have no double).
GLSL_FLAVORS = {
    "330": {"version": "330 core", "es": False, "shadertoy": False, "double": "extension"},
    "450": {"version": "450 core", "es": False, "shadertoy": False, "double": "core"},
    "es300": {"version": "300 es", "es": True, "shadertoy": False, "double": None},
    "shadertoy": {"version": "", "es": False, "shadertoy": True, "double": None},
}


@dataclass(frozen=True)
class FloatRules:
    """What one flavour's language offers to keep its compiler from rewriting the
    error-free transformations of templates/eft.j2 (two_sum's error term is zero in the
    reals, so a compiler that reassociates or fuses float arithmetic may fold it away).
    `implc probe` measures whether they survive (docs/reference/float32-probe.md)."""

    # the `precise` qualifier (GLSL 4.00 on, HLSL): what a value is computed from is
    # neither reassociated nor contracted into an fma
    precise: bool = False
    # the float fused multiply-add's spelling; "" where the language has none for float
    # (GLSL 330 and ES 3.00, hence WebGL2 and Shadertoy; HLSL's fma is double-only, and
    # its mad may round twice)
    fma: str = ""
    # the language promises fma one rounding (OpenCL C); GLSL's and WGSL's take their
    # accuracy from a*b + c, two roundings allowed. two_prod uses fma only where it
    # does, else splits its factors (Dekker, Veltkamp); the probe measures both
    fma_exact: bool = False
    # a line that turns contraction (a*b + c into an fma) off inside a function body
    contract_off: str = ""
    # no guard in the language: each rounded sum the EFTs reason about passes through
    # min(x, FLT_MAX) (one operation, the identity on every float but NaN), which hides its
    # definition from pattern-matching rewrites (Mesa's NIR folds an unguarded two_sum's
    # error to 0: measured by `implc probe` on llvmpipe and lavapipe)
    barrier: bool = False

    @property
    def guard(self) -> str:
        """How the EFTs are guarded, in words (the probe's report, the docs)."""
        if self.precise:
            return "precise"
        if self.barrier:
            return "min(x, FLT_MAX) barrier (the language has no qualifier)"
        return self.contract_off or "none"


@dataclass(frozen=True)
class ParamLayout:
    """How the parameters of a `--params uniform` shader reach one emit form
    (docs/reference/drop-ins.md, "Parameters as uniforms"). `{uniform}` is u_param_<name>,
    `{prefix}` the --prefix."""

    uniform: str = "{uniform}"  # the name the host sets (a uniform, a struct field)
    ref: str = "{uniform}"  # how the shader's functions read it
    # byte offset of the first parameter in the program's uniform struct (4 bytes each),
    # for a language whose host writes the struct as bytes; None: set by name
    offset: int | None = None


@dataclass(frozen=True)
class Target:
    name: str
    printer_class: str  # "module:Class", the printer: (precision) when several, else ()
    templates: Mapping[str, str]  # emit form (program, library) -> path under templates/
    # emit form -> the extension of its file (goldens, `compile -o`); `compile -o` writes
    # any of them, `implc validate` reads them and `extensions`
    emit_extensions: Mapping[str, str]
    extensions: tuple[str, ...]  # shader files `implc validate` reads as this language
    validator: str  # "module:function": (text, name) -> validate.Verdict
    backends: Mapping[str, Backend]  # render backend name -> Backend
    flavors: Mapping[str, Mapping[str, object]] = field(default_factory=lambda: {"default": {}})
    default_flavor: str = "default"
    # precision -> the templates' `types` in it (real, vec2, vec3, vec4); the first is the
    # default precision
    vector_types: Mapping[str, tuple[str, ...]] = field(
        default_factory=lambda: {"float": ("float", "vec2", "vec3", "vec4")})
    # a precision whose built-ins lack pow and tan (GLSL's double): in it the camera, the
    # shading and the drop-in entry points (march, intersect) stay float, and only the
    # surface and its solver (S, grad, the ray record, trace) take the precision
    float_shading: tuple[str, ...] = ()
    int_type: str = "int"  # the marcher's loop counters and step counts
    # how the functions of a `--params uniform` shader read the parameters: "global"
    # (uniforms, a uniform struct) or "argument" (a Params struct that every function
    # evaluating S takes: OpenCL C has no program-scope variables set at run time)
    params_read_as: str = "global"
    # emit form -> how `--params uniform` parameters reach it (both forms by default)
    param_layout: Mapping[str, ParamLayout] = field(
        default_factory=lambda: {"program": ParamLayout(), "library": ParamLayout()})
    # name prefixes the language reserves (`--prefix gl_` would write an invalid shader)
    reserved_prefixes: tuple[str, ...] = ()
    # the shader stages `implc validate --stage` may choose (a language with one kind of
    # file, a compute shader or a kernel, has none to choose)
    stages: tuple[str, ...] = ()
    # flavour -> glslangValidator's flags that turn its program into Vulkan SPIR-V (GPU
    # statistics, render/gpu_stats.py); a flavour not here has no path to SPIR-V
    spirv_flags: Mapping[str, tuple[str, ...]] = field(default_factory=dict)
    # flavour -> how its error-free transformations are guarded (FloatRules); a flavour
    # not here has no guard and no fma
    float_rules: Mapping[str, FloatRules] = field(default_factory=dict)
    # the float32 probe's program (templates/eft.j2 run on known inputs: `implc probe`)
    eft_probe: str = ""

    def rules(self, flavor: str | None = None) -> FloatRules:
        """The FloatRules of `flavor` (default: the target's default flavour)."""
        return self.float_rules.get(flavor or self.default_flavor, FloatRules())

    @property
    def precisions(self) -> tuple[str, ...]:
        """The precisions the target prints in, the default first."""
        return tuple(self.vector_types)

    @property
    def compile_extensions(self) -> tuple[str, ...]:
        """The extensions `implc compile -o` writes in this language."""
        return tuple(dict.fromkeys(self.emit_extensions.values()))

    @property
    def printer(self) -> Callable[..., object]:
        """The printer class, imported now (it needs sympy)."""
        return resolve(self.printer_class)

    def make_printer(self, precision: str = "float"):
        """A printer for `precision` (a printer takes one only when there are several)."""
        return self.printer(precision) if len(self.precisions) > 1 else self.printer()


TARGETS: dict[str, Target] = {target.name: target for target in (
    Target(
        name="glsl",
        eft_probe="glsl/eft_probe.glsl.j2",
        printer_class="implc.backends.glsl:GlslPrinter",
        templates={"program": "glsl/program.glsl.j2", "library": "glsl/library.glsl.j2"},
        emit_extensions={"program": ".frag", "library": ".glsl"},
        extensions=(".frag", ".glsl", ".vert", ".comp"),
        validator="implc.validate:validate_glsl",
        backends={"gl": Backend("implc.render.gl:open_gl_runner",
                                "GLSL 330 on OpenGL (moderngl, EGL; llvmpipe here)",
                                probe="implc.render.gl:context"),
                  "gl-double": Backend("implc.render.gl:open_gl_runner",
                                       "the same with the surface solved in double "
                                       "(needs GL_ARB_gpu_shader_fp64)",
                                       precision="double",
                                       probe="implc.render.gl:double_context"),
                  "webgl2": Backend("implc.render.browser_runner:open_webgl2_runner",
                                    "GLSL ES 3.00 in Chromium's WebGL2 (ANGLE on SwiftShader; "
                                    "playwright)", flavor="es300",
                                    probe="implc.render.browser_runner:chromium_renderer")},
        flavors=GLSL_FLAVORS,
        default_flavor="330",  # also the program the gl backend runs (render/gl.py)
        vector_types={"float": ("float", "vec2", "vec3", "vec4"),
                      "double": ("double", "dvec2", "dvec3", "dvec4")},
        float_shading=("double",),
        # a library's uniforms are globals of the user's shader: they carry the prefix
        param_layout={"program": ParamLayout(),
                      "library": ParamLayout("{prefix}{uniform}", "{prefix}{uniform}")},
        reserved_prefixes=("gl_",),
        stages=("vert", "frag", "comp", "geom", "tesc", "tese"),
        # Vulkan's relaxed rules: the plain uniforms become one block at set 0, binding 0
        spirv_flags={flavor: ("-R", "--aml", "--amb") for flavor in ("330", "450")},
        # `precise` and fma came with GLSL 4.00 (ARB_gpu_shader5); 330 and ES 3.00 have
        # neither (nor has Shadertoy, which is WebGL2)
        float_rules={"450": FloatRules(precise=True, fma="fma"),
                     **{f: FloatRules(barrier=True) for f in ("330", "es300", "shadertoy")}},
    ),
    Target(
        name="wgsl",
        eft_probe="wgsl/eft_probe.wgsl.j2",
        printer_class="implc.backends.wgsl:WgslPrinter",
        templates={"program": "wgsl/program.wgsl.j2", "library": "wgsl/library.wgsl.j2"},
        emit_extensions={"program": ".wgsl", "library": ".wgsl"},
        extensions=(".wgsl",),
        validator="implc.validate:validate_wgsl",
        backends={"wgpu": Backend("implc.render.wgpu_runner:open_wgpu_runner",
                                  "WGSL compute shader on wgpu (Vulkan; lavapipe here)",
                                  probe="implc.devices:wgpu_device"),
                  "webgpu": Backend("implc.render.browser_runner:open_webgpu_runner",
                                    "WGSL in Chromium's WebGPU (Dawn on SwiftShader; "
                                    "playwright)",
                                    probe="implc.render.browser_runner:chromium_renderer")},
        # the program's parameters are fields of struct Uniforms after the camera (the
        # host writes it as bytes: render/wgpu_runner.py); a library's, of its Params
        param_layout={"program": ParamLayout(ref="u.{uniform}", offset=76),
                      "library": ParamLayout(ref="{prefix}params.{uniform}")},
        vector_types={"float": ("f32", "vec2<f32>", "vec3<f32>", "vec4<f32>")},
        int_type="i32",
        # WGSL's fma may be computed as e1 * e2 + e3 (its accuracy is "inherited" from
        # that: two roundings allowed), so two_prod splits its factors there too
        float_rules={"default": FloatRules(fma="fma", barrier=True)},
    ),
    Target(
        name="opencl",
        eft_probe="opencl/eft_probe.opencl.j2",
        printer_class="implc.backends.opencl:OpenclPrinter",
        templates={"program": "opencl/program.opencl.j2",
                   "library": "opencl/library.opencl.j2"},
        emit_extensions={"program": ".cl", "library": ".cl"},
        extensions=(".cl",),
        validator="implc.validate:validate_opencl",
        backends={
            "cl": Backend("implc.render.cl_runner:open_cl_runner",
                          "OpenCL C kernel, float (pyopencl; PoCL here)",
                          probe="implc.devices:opencl_device"),
            "cl-double": Backend("implc.render.cl_runner:open_cl_runner",
                                 "the same in double precision (needs cl_khr_fp64)",
                                 precision="double", probe="implc.devices:opencl_device"),
        },
        # templates/opencl/ also spell double/double3 from `precision`; the printer
        # checks the same names (backends/opencl.py PRECISIONS)
        vector_types={"float": ("float", "float2", "float3", "float4"),
                      "double": ("double", "double2", "double3", "double4")},
        params_read_as="argument",
        param_layout={"program": ParamLayout(ref="params.{uniform}"),
                      "library": ParamLayout(ref="params.{uniform}")},
        # OpenCL C contracts by default (FP_CONTRACT ON); fma is correctly rounded
        float_rules={"default": FloatRules(fma="fma", fma_exact=True,
                                           contract_off="#pragma OPENCL FP_CONTRACT OFF")},
    ),
    Target(
        name="hlsl",
        eft_probe="hlsl/eft_probe.hlsl.j2",
        printer_class="implc.backends.hlsl:HlslPrinter",
        templates={"program": "hlsl/program.hlsl.j2", "library": "hlsl/library.hlsl.j2"},
        emit_extensions={"program": ".hlsl", "library": ".hlsl"},
        extensions=(".hlsl",),
        validator="implc.validate:validate_hlsl",
        backends={"hlsl-spirv": Backend(
            "implc.render.hlsl_runner:open_hlsl_runner",
            "HLSL pixel shader through SPIR-V (glslang, spirv-cross) on OpenGL (llvmpipe)",
            probe="implc.render.hlsl_runner:toolchain")},
        vector_types={"float": ("float", "float2", "float3", "float4")},
        param_layout={"program": ParamLayout(),
                      "library": ParamLayout("{prefix}{uniform}", "{prefix}{uniform}")},
        spirv_flags={"default": ("-D", "-e", "main")},  # glslang's HLSL front end
        float_rules={"default": FloatRules(precise=True)},
    ),
)}


@dataclass(frozen=True)
class Probe:
    """A driver the float32 probe (`implc probe`, render/eft_probe.py) runs on: a backend
    (a render backend, or a browser's), the language and flavour it compiles, the
    function that runs the program ((text, cases as (op, a, b, n) rows) -> pairs) and the
    one that names the driver and its version."""

    backend: str
    target: str
    flavor: str | None
    runner: str  # "module:function"
    driver: str  # "module:function" -> the driver's name and version

    @property
    def title(self) -> str:
        tgt = get_target(self.target)
        flavor = f" {self.flavor}" if self.flavor else ""
        return f"{self.backend}: {self.target}{flavor} (guard: {tgt.rules(self.flavor).guard})"


# every float32 driver implc runs; webgl2 also stands for Shadertoy (WebGL2 in a page)
PROBES = (
    Probe("gl", "glsl", "330", "implc.render.eft_probe:run_gl",
          "implc.render.eft_probe:gl_driver"),
    Probe("gl", "glsl", "450", "implc.render.eft_probe:run_gl",
          "implc.render.eft_probe:gl_driver"),
    Probe("wgpu", "wgsl", None, "implc.render.eft_probe:run_wgpu",
          "implc.render.eft_probe:wgpu_driver"),
    Probe("cl", "opencl", None, "implc.render.eft_probe:run_cl",
          "implc.render.eft_probe:cl_driver"),
    Probe("hlsl-spirv", "hlsl", None, "implc.render.eft_probe:run_hlsl",
          "implc.render.eft_probe:gl_driver"),
    Probe("webgl2", "glsl", "es300", "implc.render.browser_probe:run_webgl2",
          "implc.render.browser_probe:browser_driver"),
    Probe("webgpu", "wgsl", None, "implc.render.browser_probe:run_webgpu",
          "implc.render.browser_probe:browser_driver"),
)
PROBE_BACKENDS = tuple(dict.fromkeys(p.backend for p in PROBES))



def get_target(name: str) -> Target:
    try:
        return TARGETS[name]
    except KeyError:
        raise ValueError(f"unknown target '{name}'; choose from {', '.join(TARGETS)}") from None


def target_of_file(suffix: str) -> Target | None:
    """The target whose language a shader file with this extension is written in."""
    return next((t for t in TARGETS.values() if suffix in t.extensions), None)


def flavor_problem(target: Target, flavor: str, precision: str = "float") -> str | None:
    """Why `flavor` is not one of `target`'s flavours, naming the choices, or cannot print
    in `precision` (None: it is and it can)."""
    if flavor in target.flavors:
        if precision == "double" and target.flavors[flavor].get("double", True) is None:
            able = [f for f, v in target.flavors.items() if v.get("double", True)]
            return (f"the {target.name} flavour {flavor} has no double precision: use "
                    f"--precision double with {' or '.join(able)}")
        return None
    if len(target.flavors) == 1:
        having = " and ".join(t.name for t in TARGETS.values() if len(t.flavors) > 1)
        return f"{target.name} has no flavours (--flavor applies to {having} only)"
    return f"unknown {target.name} flavour '{flavor}'; choose from {', '.join(target.flavors)}"


def where_precision(precision: str) -> str:
    """Which targets (and flavours) print in `precision` and which backends render in it,
    for a remedy: `-t glsl (flavour 330 or 450) or -t opencl; render -b gl-double or
    cl-double`."""
    shaders = []
    for target in TARGETS.values():
        if precision in target.precisions:
            able = [f for f in target.flavors if flavor_problem(target, f, precision) is None]
            shaders.append(f"-t {target.name}"
                           + (f" (flavour {' or '.join(able)})" if len(target.flavors) > 1
                              else ""))
    return f"{' or '.join(shaders)}; render -b {' or '.join(backends_in(precision))}"


def backends_in(precision: str) -> list[str]:
    """The render backends that run their program in `precision`."""
    return [name for target in TARGETS.values() for name, backend in target.backends.items()
            if backend.precision == precision]


_PREFIX_RE = re.compile(r"[A-Za-z0-9_]*\Z")


def prefix_problem(prefix: str, target: Target) -> str | None:
    """Why `prefix` cannot start every global name of a `target` shader (None: it can).

    It is glued to names (`cc_` + `S`, upper-cased before constants: `CC_STEP`), so it
    must be an identifier's start; `__` is reserved in GLSL (anywhere in a name), WGSL
    and OpenCL C (at the start), and a target may reserve prefixes of its own (GLSL:
    `gl_`)."""
    if not _PREFIX_RE.match(prefix):
        return f"--prefix must be letters, digits and '_' (got '{prefix}')"
    if prefix[:1].isdigit():
        return (f"--prefix must not start with a digit: names start with it, and a name "
                f"cannot (got '{prefix}')")
    if "__" in prefix:
        return f"--prefix must not contain '__': GLSL reserves such names (got '{prefix}')"
    for reserved in target.reserved_prefixes:
        if prefix.startswith(reserved):
            return (f"--prefix must not start with '{reserved}': {target.name} reserves names "
                    f"that start with it (got '{prefix}')")
    return None
