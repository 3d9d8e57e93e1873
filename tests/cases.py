"""The test matrix, in one place: which surfaces, methods and flavours are pinned."""

from implc.methods import METHODS
from implc.surface import example_paths

PAPER = ("cross-cap", "miter", "steiner")
EXAMPLES = tuple(example_paths())
METHOD_NAMES = tuple(METHODS)
GLSL_FLAVORS = ("330", "450", "es300", "shadertoy")


def golden_cases() -> list[tuple[str, str, str, str]]:
    """(example, method, flavor, emit): every example with hessian in every flavour, every
    method on the paper surfaces, a library emit of each paper surface, and the gyroid
    with interval (program and library)."""
    cases = [(ex, "hessian", fl, "program") for ex in EXAMPLES for fl in GLSL_FLAVORS]
    cases += [(ex, m, "330", "program") for ex in PAPER for m in METHOD_NAMES if m != "hessian"]
    cases += [(ex, m, "330", "library") for ex in PAPER for m in ("hessian", "taylor")]
    cases += [("cross-cap", "exact", fl, "program") for fl in GLSL_FLAVORS if fl != "330"]
    cases += [("cross-cap", "exact", "330", "library")]
    cases += [("gyroid", "interval", "330", "program"), ("gyroid", "interval", "330", "library")]
    return cases


def golden_name(example: str, method: str, flavor: str, emit: str) -> str:
    if emit == "library":
        return f"{example}.{method}.library.glsl"
    return f"{example}.{method}.{flavor}.frag"


def opencl_golden_cases() -> list[tuple[str, str, str, str]]:
    """(example, method, precision, emit) of the OpenCL goldens: every example with hessian,
    every method on the paper surfaces, a library emit of each paper surface, and the
    double-precision Cross-Cap program."""
    cases = [(ex, "hessian", "float", "program") for ex in EXAMPLES]
    cases += [(ex, m, "float", "program") for ex in PAPER for m in METHOD_NAMES if m != "hessian"]
    cases += [(ex, "hessian", "float", "library") for ex in PAPER]
    cases += [("cross-cap", "hessian", "double", "program")]
    cases += [("cross-cap", "exact", "float", "library"),
              ("cross-cap", "exact", "double", "program")]
    cases += [("gyroid", "interval", "float", kind) for kind in ("program", "library")]
    return cases


def opencl_golden_name(example: str, method: str, precision: str, emit: str) -> str:
    """e.g. cross-cap.hessian.cl, cross-cap.hessian.double.cl, miter.hessian.library.cl"""
    parts = [example, method]
    parts += [precision] if precision != "float" else []
    parts += [emit] if emit != "program" else []
    return ".".join(parts) + ".cl"


def wgsl_golden_cases() -> list[tuple[str, str, str, str]]:
    """(example, method, taylor2, emit) of the WGSL goldens: every example with hessian,
    every method on the paper surfaces, the `--taylor2 consistent` branch of both Hessian
    methods on the Cross-Cap, and a library emit of each paper surface (hessian) and of
    the Cross-Cap with taylor."""
    cases = [(ex, "hessian", "paper", "program") for ex in EXAMPLES]
    cases += [(ex, m, "paper", "program") for ex in PAPER for m in METHOD_NAMES if m != "hessian"]
    cases += [("cross-cap", m, "consistent", "program") for m in ("hessian", "hessian-approx")]
    cases += [(ex, "hessian", "paper", "library") for ex in PAPER]
    cases += [("cross-cap", "taylor", "paper", "library"),
              ("cross-cap", "exact", "paper", "library")]
    cases += [("gyroid", "interval", "paper", kind) for kind in ("program", "library")]
    return cases


def wgsl_golden_name(example: str, method: str, taylor2: str, emit: str) -> str:
    """e.g. cross-cap.hessian.wgsl, cross-cap.hessian.consistent.wgsl,
    miter.hessian.library.wgsl"""
    parts = [example, method]
    parts += [taylor2] if taylor2 != "paper" else []
    parts += [emit] if emit != "program" else []
    return ".".join(parts) + ".wgsl"
