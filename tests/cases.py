"""The test matrix, in one place: which surfaces, methods, flavours and precisions are
pinned, for every target of the registry (implc/targets.py) alike: a new target gets its
goldens from this list without editing it."""

from __future__ import annotations

from dataclasses import dataclass

from implc.methods import METHODS
from implc.surface import example_paths
from implc.targets import TARGETS

PAPER = ("cross-cap", "miter", "steiner")
EXAMPLES = tuple(example_paths())
METHOD_NAMES = tuple(METHODS)


@dataclass(frozen=True)
class GoldenCase:
    """One golden shader: tests/golden/<target>/<name>."""

    target: str
    example: str
    method: str
    emit: str = "program"
    flavor: str | None = None  # None: the target's default
    precision: str = "float"
    taylor2: str = "paper"

    @property
    def name(self) -> str:
        """e.g. cross-cap.hessian.330.frag (a flavour only where a target has several),
        cross-cap.exact.double.cl, cross-cap.hessian.consistent.wgsl,
        miter.hessian.library.glsl."""
        target = TARGETS[self.target]
        parts = [self.example, self.method]
        parts += [self.taylor2] if self.taylor2 != "paper" else []
        parts += [self.precision] if self.precision != "float" else []
        if len(target.flavors) > 1 and self.emit == "program":
            parts.append(self.flavor or target.default_flavor)
        parts += [self.emit] if self.emit != "program" else []
        return ".".join(parts) + target.emit_extensions[self.emit]

    @property
    def id(self) -> str:
        return f"{self.target}/{self.name}"


def golden_cases(target: str) -> list[GoldenCase]:
    """The goldens of one target: every example with hessian in every flavour; every
    method on the paper surfaces; a library emit of each paper surface with hessian and
    taylor; the Cross-Cap's exact solver in every other flavour, as a library and in
    every other precision (and hessian there too); the `--taylor2 consistent` branch of
    both Hessian methods; the gyroid with interval (program and library); Barth's decic
    with exact in every precision (the Bernstein walk, from degree 5, in float and in
    double's fewer registers: implc/walk_registers.py)."""
    t = TARGETS[target]
    other_flavors = [f for f in t.flavors if f != t.default_flavor]
    other_precisions = [p for p in t.precisions if p != "float"]

    def case(example: str, method: str, **options) -> GoldenCase:
        return GoldenCase(target, example, method, **options)

    cases = [case(ex, "hessian") for ex in EXAMPLES]
    cases += [case(ex, "hessian", flavor=fl) for ex in EXAMPLES for fl in other_flavors]
    cases += [case(ex, m) for ex in PAPER for m in METHOD_NAMES if m != "hessian"]
    cases += [case(ex, m, emit="library") for ex in PAPER for m in ("hessian", "taylor")]
    cases += [case("cross-cap", "exact", flavor=fl) for fl in other_flavors]
    cases += [case("cross-cap", m, precision=p) for p in other_precisions
              for m in ("hessian", "exact")]
    cases += [case("cross-cap", m, taylor2="consistent") for m in ("hessian", "hessian-approx")]
    cases += [case("cross-cap", "exact", emit="library")]
    cases += [case("gyroid", "interval", emit=kind) for kind in ("program", "library")]
    cases += [case("barth-decic", "exact", precision=p) for p in t.precisions]
    return cases


def all_golden_cases() -> list[GoldenCase]:
    return [c for target in TARGETS for c in golden_cases(target)]


def chmutov(n: int) -> str:
    """Chmutov's T_n(x) + T_n(y) + T_n(z) = 0 written out, as the degree sweep writes it
    (scripts/eval_forms.py): every power stands alone, so its ray coefficients take
    raypoly's Taylor shift."""
    import sympy

    x = sympy.Symbol("x")
    t = sympy.Poly(sympy.chebyshevt(n, x), x)
    return " + ".join(f"({c})*{v}^{k}" for (k,), c in t.terms() for v in "xyz") + " = 0"
