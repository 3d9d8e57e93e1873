"""`implc export`: the files a host loads (implc/hosts.py), assembled from library emits.

This module only assembles: it compiles each shader a host names (the library emit, the
parameters as uniforms so that they can become the host's own controls: a Shader Graph
property, an ISF input, a Godot uniform with a hint_range), and renders the host's file
templates with them, the surface, its view and each parameter's range (the viewer's
sliders' rule). The templates say how to use the file at its top.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

from .emit import CompiledShader, compile_shader, param_range, render_template
from .errors import OptionError
from .hosts import Host
from .methods import Constants, get_method
from .scene import SHADING
from .surface import Surface
from .version import __version__


@dataclass(frozen=True)
class Control:
    """A parameter as a host's control: its name in the equation, the uniform the
    library reads, its value and range."""

    name: str
    uniform: str
    value: float
    low: float
    high: float


def stem(name: str, case: str) -> str:
    """The surface's name as an identifier for the host's files and functions:
    "Cross-Cap" -> cross_cap ("snake") or CrossCap ("pascal")."""
    words = re.findall(r"[A-Za-z0-9]+", name) or ["surface"]
    if case == "pascal":
        text = "".join(w[:1].upper() + w[1:] for w in words)
    else:
        text = "_".join(w.lower() for w in words)
    return text if not text[0].isdigit() else f"s{text}"


def export_files(surface: Surface, host: Host, method: str,
                 constants: Constants | None = None, precision: str = "float",
                 prefix: str | None = None, command: str = "") -> dict[str, str]:
    """{file name: text} of `host`'s files for the framed `surface` (the main file first),
    deterministic byte for byte. `command` is the line the files' headers quote."""
    if precision not in host.precisions:
        raise OptionError(f"--precision {precision}: the {host.name} host cannot take it "
                          f"({host.precision_reason})")
    meth = get_method(method)
    if meth.name in host.methods_refused:
        raise OptionError(f"-m {method}: the {host.name} host cannot take it "
                          f"({host.methods_refused[meth.name]})")
    name = stem(surface.name, host.stem_case)
    prefix = host.prefix.format(stem=stem(surface.name, "snake")) if prefix is None else prefix
    constants = constants or meth.defaults
    shaders: dict[str, CompiledShader] = {
        s.key: compile_shader(surface, s.target, method, constants, s.flavor, "library",
                              prefix, precision, params="uniform",
                              static_params=s.static_params,
                              declare_params=s.declare_params)
        for s in host.shaders}
    first = next(iter(shaders.values()))
    controls = [Control(u.name, u.uniform, u.value, *param_range(u.value))
                for u in first.uniforms]
    context = {
        "host": host, "stem": name, "prefix": prefix, "method": meth.name,
        "surface": {"name": surface.name, "equation": surface.symbolic_equation},
        "shaders": shaders, "controls": controls, "view": surface.view,
        "background": SHADING.background,
        "version": __version__, "command": command, "extras": host.extras,
    }
    return {pattern.format(stem=name): render_template(template, **context)
            for pattern, template in host.files.items()}

