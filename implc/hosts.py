"""THE host registry: one record per engine or tool that drop-in shaders are pasted into
(three.js, Unity, Unreal, Godot, ISF hosts, WESL packages), read by `implc export`, the
API's `Surface.export` and the tests.

A host is data, like a target (implc/targets.py): the shaders it needs (a target and a
flavour each, always the library emit with the parameters as uniforms, so that they can
become the host's own controls), the files it loads (a name pattern and a template under
templates/hosts/<name>/), and what it cannot take. implc/export.py compiles the shaders
and renders the files; nothing else branches on a host's name. Adding a host is one
record here, its templates, its test and its section of docs/guide/hosts.md.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field


@dataclass(frozen=True)
class HostShader:
    """One library emit a host's files include, read by the templates as shaders[key]."""

    key: str  # the name its templates read it by
    target: str  # implc/targets.py
    flavor: str | None = None  # the target's flavour (None: its default)
    # the parameters as globals the host's function sets (its node's inputs) rather than
    # uniforms the host binds (emit.compile_shader's static_params)
    static_params: bool = False
    # False: the host's file declares the parameters' uniforms itself (an ISF input, a
    # Godot uniform with a hint_range), so the library only reads them (GLSL)
    declare_params: bool = True


@dataclass(frozen=True)
class Host:
    name: str
    about: str  # one line for `implc export --help`
    shaders: tuple[HostShader, ...]
    # file name pattern ({stem}: the surface's name as an identifier) -> its template
    # under templates/ (what the host loads; the first is the main one)
    files: Mapping[str, str]
    precisions: tuple[str, ...] = ("float",)  # what its shading language can solve in
    # why a precision the host lacks is refused (the message's reason)
    precision_reason: str = "the host's shading language has no double"
    # method -> why the host's shading language cannot run it (the refusal's reason)
    methods_refused: Mapping[str, str] = field(default_factory=dict)
    # a prefix for the library's global names when the caller gives none ({stem}_)
    prefix: str = "{stem}_"
    # how a name is spelled for the host's files: "snake" (my_surface) or "pascal"
    # (MySurface, Unity's and Unreal's custom nodes)
    stem_case: str = "snake"
    extras: Mapping[str, object] = field(default_factory=dict)  # what its templates read


# HLSL's keywords and type names that a parameter could be called: a node's input, named
# after its parameter, takes NAME_in instead of one of these or of the node's own names
# (its "reserved" extra, read by templates/hosts/node_inputs.j2)
HLSL_KEYWORDS = frozenset((
    "in", "out", "inout", "uniform", "static", "const", "extern", "shared", "groupshared",
    "volatile", "precise", "inline", "float", "half", "double", "int", "uint", "bool", "dword",
    "min16float", "min10float", "min16int", "min12int", "min16uint", "void", "vector",
    "matrix", "string", "struct", "class", "interface", "namespace", "typedef", "register",
    "packoffset", "cbuffer", "tbuffer", "texture", "sampler", "true", "false", "return", "if",
    "else", "for", "while", "do", "break", "continue", "discard", "switch", "case", "default",
    "linear", "centroid", "nointerpolation", "noperspective", "sample", "point", "line",
    "triangle", "lineadj", "triangleadj", "row_major", "column_major", "snorm", "unorm",
    "compile", "pass", "technique", "unsigned", "export",
))


HOSTS: dict[str, Host] = {host.name: host for host in (
    Host(
        name="three",
        about="three.js: an ES module for WebGLRenderer and WebGPURenderer (TSL)",
        # GLSL first: the controls' uniform names are its globals'. Its parameters are
        # globals the trace function sets: three binds no uniform a glslFn include declares
        shaders=(HostShader("glsl", "glsl", "es300", static_params=True),
                 HostShader("wgsl", "wgsl")),
        files={"{stem}.js": "hosts/three/module.js.j2"},
        precision_reason="WebGL2 and WebGPU shaders have no double",
    ),
    Host(
        name="unity",
        about="Unity Shader Graph: a Custom Function node's .hlsl file",
        shaders=(HostShader("hlsl", "hlsl", static_params=True),),
        files={"{stem}.hlsl": "hosts/unity/custom_function.hlsl.j2"},
        stem_case="pascal",
        extras={"reserved": HLSL_KEYWORDS | {
            "RayOrigin", "RayDirection", "TNear", "TFar", "Hit", "T", "Normal", "Color",
            "t", "normal", "color", "g"}},
    ),
    Host(
        name="unreal",
        about="Unreal Engine material: a Custom node's Code and the .ush it includes",
        shaders=(HostShader("hlsl", "hlsl", static_params=True),),
        # the node's Code first: it says how to set the node up
        files={"{stem}_CustomNode.hlsl": "hosts/unreal/custom_node.hlsl.j2",
               "{stem}.ush": "hosts/unreal/library.ush.j2"},
        stem_case="pascal",
        extras={"reserved": HLSL_KEYWORDS | {
            "RayOrigin", "RayDirection", "TNear", "TFar", "Hit", "T", "Normal", "Parameters",
            "t", "hit", "g", "MaterialFloat", "MaterialFloat2", "MaterialFloat3",
            "MaterialFloat4"}},
    ),
    Host(
        name="godot",
        about="Godot 4: a spatial .gdshader for a proxy sphere, the ray tracer in a "
              ".gdshaderinc, the parameters as uniforms with hint_range",
        # Godot's shading language is GLSL ES 3.00's core; the .gdshader declares the
        # parameters itself (hint_range), the include only reads them
        shaders=(HostShader("glsl", "glsl", "es300", declare_params=False),),
        files={"{stem}.gdshader": "hosts/godot/spatial.gdshader.j2",
               "{stem}.gdshaderinc": "hosts/godot/include.gdshaderinc.j2"},
        precision_reason="Godot's shading language has no double",
    ),
    Host(
        name="isf",
        about="ISF hosts (VDMX, Resolume, ossia score): a generator .fs, the parameters "
              "as its INPUTS",
        # GLSL ES 1.00 / 1.20, what ISF hosts compile: the es300 library is in that subset
        # but for the interval method's bit operations
        shaders=(HostShader("glsl", "glsl", "es300", declare_params=False),),
        files={"{stem}.fs": "hosts/isf/generator.fs.j2"},
        precision_reason="ISF shaders are GLSL ES 1.00 / GLSL 1.20, which have no double",
        methods_refused={"interval": "ISF shaders are GLSL ES 1.00 / GLSL 1.20, which have "
                                     "no integer bit operations; its stackless subdivision "
                                     "needs them"},
    ),
    Host(
        name="wesl",
        about="WESL (Bevy, the npm wesl linker): a package, the surface a module that a "
              "full-screen pass imports",
        shaders=(HostShader("wgsl", "wgsl"),),
        files={"{stem}.wesl": "hosts/wesl/surface.wesl.j2",
               "{stem}_draw.wesl": "hosts/wesl/draw.wesl.j2",
               "wesl.toml": "hosts/wesl/wesl.toml.j2"},
        precision_reason="WGSL has no double",
        prefix="",  # a module is its own namespace: package::{stem}::intersect
    ),
)}


def get_host(name: str) -> Host:
    """The record of `name`; an unknown name raises ValueError with a did-you-mean."""
    try:
        return HOSTS[name]
    except KeyError:
        import difflib

        close = difflib.get_close_matches(name, list(HOSTS), n=1, cutoff=0.6)
        hint = f"; did you mean '{close[0]}'?" if close else ""
        raise ValueError(f"unknown host '{name}'{hint} (choose from "
                         f"{', '.join(HOSTS)})") from None
