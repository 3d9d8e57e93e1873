"""The target registry. Adding a target = a printer module, templates/<name>/, a validator
in implc/validate.py and one line here (see README "Adding a target")."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

from .glsl import FLAVORS as GLSL_FLAVORS
from .glsl import GlslPrinter
from .opencl import OpenclPrinter
from .wgsl import WgslPrinter


@dataclass(frozen=True)
class Target:
    name: str
    extension: str  # of a program; libraries use the same
    printer: Callable[[], object]
    flavors: dict[str, dict] = field(default_factory=lambda: {"default": {}})
    default_flavor: str = "default"
    vector_types: tuple[str, str, str] = ("float", "vec2", "vec3")
    precisions: tuple[str, ...] = ("float",)


TARGETS: dict[str, Target] = {
    "glsl": Target("glsl", "frag", GlslPrinter, GLSL_FLAVORS, "330"),
    "wgsl": Target("wgsl", "wgsl", WgslPrinter, vector_types=("f32", "vec2<f32>", "vec3<f32>")),
    # double precision: templates/opencl/ spell double/double2/double3 from `precision`
    "opencl": Target("opencl", "cl", OpenclPrinter, vector_types=("float", "float2", "float3"),
                     precisions=("float", "double")),
}


def get_target(name: str) -> Target:
    try:
        return TARGETS[name]
    except KeyError:
        raise ValueError(f"unknown target '{name}'; choose from {', '.join(TARGETS)}") from None
