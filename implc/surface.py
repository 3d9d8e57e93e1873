"""The `Surface` record: what every stage after the front end reads.

A plain record (expression, parameters, view, where it came from), with no knowledge of
files: reading TOML and SURFER's .jsurf files into one is implc/loaders/, so that the
stages that only use a surface (emit, the runners, the reports) do not import the readers,
and the readers' modules import this one, never the other way round.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import sympy

from .limits import Limits
from .resources import data_dir
from .scene import View
from .textform import to_text, value_text


@dataclass(frozen=True)
class Surface:
    name: str
    expr: sympy.Expr  # S(x, y, z); the surface is S = 0; parameters already substituted
    params: dict[str, sympy.Expr] = field(default_factory=dict)  # exact values
    view: View = field(default_factory=View)
    origin: str = "<equation>"  # file path, example name or "<equation>"
    # S with the parameters as symbols (front.param_symbol), for `--params uniform`;
    # None when the surface has no parameters (then it is `expr`)
    symbolic: sympy.Expr | None = None
    # what the command line says once about this input (a .jsurf file's ignored keys)
    notes: tuple[str, ...] = field(default=(), compare=False)
    # the limits it was read under; its derivatives are bounded by `limits.max_derived`
    limits: Limits = field(default_factory=Limits, compare=False)

    @property
    def equation(self) -> str:
        """The equation printed from the tree, in implc's own input language."""
        return to_text(self.expr)

    @property
    def symbolic_expr(self) -> sympy.Expr:
        return self.expr if self.symbolic is None else self.symbolic

    @property
    def symbolic_equation(self) -> str:
        """The equation with its parameters by name (what `--params uniform` compiles)."""
        return to_text(self.symbolic_expr)

    def equation_lines(self) -> list[str]:
        """The equation for people (`list`, `show`): with its parameters by name, as the
        file writes it, then, when the values change it, `with R = 1, r = 7/20: ...` and
        the equation with the values substituted (what `--params constant` compiles)."""
        lines = [self.symbolic_equation]
        if self.symbolic is not None and self.equation != lines[0]:
            values = ", ".join(f"{k} = {value_text(v)}" for k, v in self.params.items())
            lines.append(f"with {values}: {self.equation}")
        return lines

    def uniform_params(self) -> list[str]:
        """The parameters that stay free with `--params uniform`, sorted by name: every
        parameter, less those that only appear in constant exponents (`x^n`)."""
        free = {s.name for s in self.symbolic_expr.free_symbols}
        return sorted(name for name in self.params if name in free)

    def params_json(self) -> dict[str, float]:
        return {k: float(v) for k, v in sorted(self.params.items())}


def example_paths() -> dict[str, Path]:
    """Bundled examples by name (file stem), e.g. `cross-cap`, `torus`."""
    root = data_dir("examples")
    return {p.stem: p for p in sorted(root.rglob("*.toml"))}
