"""The method registry: each marcher of the paper, defined once, as data.

A method is three sympy expressions (docs/ARCHITECTURE.md, "The methods"):
- `sample`: what it evaluates at a march point s, a triple (F, F', X) built from the ray
  quantities F(s), dF(s), d2F(s) and lap(s) (X is the method's extra value, 0 if none);
- `step`: the step length at the start of a step, a Piecewise over that end's sample
  (F0, D0, X0) and the constants only (a value it reads is carried from the step before,
  off the loop's dependency chain);
- `root`: does [s0, s0 + h] hold a root? A `Rule` (named intermediate values, then a
  boolean) over both ends' samples (F0, D0, X0), (F1, D1, X1) and h.
The marcher skeleton (templates/marcher.j2) is the same for every method, and the target
printers spell these expressions; nothing else branches on a method's name. The ray
quantities are supplied by an evaluation form (implc/marcher.py), which a method never
sees.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field, replace

import sympy
from sympy import Abs, Min, Ne, Piecewise

from .options import TAYLOR2_CHOICES, Constants

# The march parameter along the ray and the length of a step.
S = sympy.Symbol("s", real=True)
H = sympy.Symbol("h", real=True)
# The samples (F, F', X) at the start (0) and the end (1) of a step.
F0, D0, X0, F1, D1, X1 = sympy.symbols("F0 D0 X0 F1 D1 X1", real=True)
# Constants, printed as the shader's named constants (prefixed, upper case).
STEP, TAU1, TAU2, TAU3, EPS = sympy.symbols("STEP TAU1 TAU2 TAU3 EPS", real=True)
CONSTANT_SYMBOLS = (STEP, TAU1, TAU2, TAU3, EPS)

# Ray quantities a method may evaluate, as functions of the ray parameter, and the
# derived quantity (implc/derive.py) each one is.
F = sympy.Function("F")  # S(o + s d)
DF = sympy.Function("dF")  # F'(s) = grad S . d
D2F = sympy.Function("d2F")  # F''(s) = d^T H d
LAP = sympy.Function("lap")  # Laplacian of S at o + s d
RAY_QUANTITIES: dict[str, str] = {"F": "S", "dF": "dS", "d2F": "d2S", "lap": "lap"}
RAY_FUNCTIONS = (F, DF, D2F, LAP)


def constant_values(constants: Constants) -> dict[sympy.Symbol, float]:
    """The value of each constant symbol (Constants is plain data, implc/options.py)."""
    return {STEP: constants.step, TAU1: constants.tau1, TAU2: constants.tau2,
            TAU3: constants.tau3, EPS: constants.eps}


@dataclass(frozen=True)
class Rule:
    """A value computed through named intermediates: `lets` in order, then `value`."""

    value: sympy.Basic
    lets: tuple[tuple[sympy.Symbol, sympy.Basic], ...] = ()
    what: str = ""  # what it is, printed as a comment in the shader


# --- the pieces the paper's methods are made of --------------------------------------

def eq2(f: sympy.Expr, df: sympy.Expr) -> sympy.Expr:
    """Eq. 2: b/4 near the surface at a silhouette, b/2 near it, 2b far from it, else b."""
    near = Piecewise((STEP / 4, Abs(df) <= TAU3), (STEP / 2, True))
    return Piecewise((near, Abs(f) <= TAU1), (2 * STEP, Abs(f) > TAU2), (STEP, True))


def interval_test(start: sympy.Expr, *values: sympy.Expr, late: sympy.Expr = F1) -> sympy.Basic:
    """0 lies in [min, max] of `start` (the step's F0) and `values`.

    Asked as "sign(F0)·v <= 0 for some v", the same boolean: F0 > 0 makes max >= 0 hold
    already, so only min <= 0 is asked; F0 < 0 the mirror image; F0 = 0 both hold, and
    sign 0 makes every product 0. A value that is the step's `late` sample plus other
    terms, v = F1 + w, is asked as sign(F0)·F1 <= -sign(F0)·w, and those with F1 itself
    as one bound: sign(F0)·F1 <= max(0, -sign(F0)·w, ...). The rest go into one
    min(sign(F0)·v) <= 0.

    Exact in floating point: sign(F0) is +1, -1 or 0, so its products are exact, and a
    rounded sum F1 + w is <= 0 exactly when F1 <= -w (rounding is monotonic and a sum of
    floats rounds to 0 only when it is 0), so the boolean is that of v evaluated as
    F1 + w. F1 is the last value a march step computes; as a bound F1 is one comparison
    from the answer, not a sum, a product and a reduction: 7-12 % a frame on llvmpipe for
    the one reduction, and 4-10 % more for the bound
    (docs/journal/2026-12-01-marcher-and-forms.md)."""
    sigma = sympy.sign(start)

    def signed(v: sympy.Expr) -> sympy.Expr:  # sign(F0)*v, term by term (also exact)
        return sympy.Add(*(sigma * term for term in sympy.Add.make_args(v)))

    rest, bounds = [], []
    for v in values:
        w = v - late
        if v.has(late) and not w.has(late):
            bounds.append(signed(-w))
        else:
            rest.append(signed(v))
    tests = [Min(*rest) <= 0] if rest else []
    if bounds:
        tests.append(sigma * late <= sympy.Max(*bounds))
    return sympy.Or(*tests)


U0, U1, M0 = sympy.symbols("u0 u1 m0", real=True)
# how interval_test asks it, for the shader's comment
_ASKED = ("; 0 in [min, max] of F0, q, r, F1 is asked as sign(F0) q <= 0 or "
          "sign(F0) F1 <= max(0, sign(F0) (F1 - r))")

# Eq. 3: first-order Taylor extension towards the midpoint from both ends.
TAYLOR = Rule(interval_test(F0, F0 + D0 * H / 2, F1 - D1 * H / 2, F1),
              what="Eq. 3: first-order Taylor extension towards the midpoint from both ends"
              + _ASKED)
# Eq. 4 as printed: F''(t0) in both q and r, with h^2/2.
EQ4_PAPER = Rule(interval_test(F0, F0 + D0 * H / 2 + X0 * H**2 / 2,
                               F1 - D1 * H / 2 + X0 * H**2 / 2, F1),
                 what="Eq. 4 as printed: F''(t0) in both q and r, with h^2/2" + _ASKED)
# Eq. 4, consistent reading: second-order Taylor to the midpoint, (h/2)^2/2 = h^2/8.
_Q_CONSISTENT = F0 + D0 * H / 2 + X0 * H**2 / 8
_R_CONSISTENT = F1 - D1 * H / 2 + X1 * H**2 / 8
EQ4_CONSISTENT = Rule(interval_test(F0, _Q_CONSISTENT, _R_CONSISTENT, F1),
                      what="Eq. 4, consistent reading: second-order Taylor to the midpoint, "
                      "(h/2)^2/2 = h^2/8, F''(t1) in r" + _ASKED)
# implc's extension: also the extremum of each end's quadratic model inside the step,
# F(t0 + u) ~ F0 + F0' u + F0'' u^2/2 at u = -F0'/F0'' (and alike from t1), so a dip of F
# below zero between the ends (two close crossings) is seen too.
# (m1 is F1 minus a term, so that interval_test can ask it as a bound on F1 too)
EQ4_EXTREMUM = Rule(
    interval_test(F0, _Q_CONSISTENT, _R_CONSISTENT, F1, M0,
                  F1 - Piecewise((D1 * U1 / 2, (U1 > 0) & (U1 < H)), (0, True))),
    (
        (U0, Piecewise((-D0 / X0, Ne(X0, 0)), (-1, True))),
        (U1, Piecewise((D1 / X1, Ne(X1, 0)), (-1, True))),
        (M0, Piecewise((F0 + D0 * U0 / 2, (U0 > 0) & (U0 < H)), (F0, True))),
    ),
    "Eq. 4 consistent, plus implc's extension: the extremum of each end's quadratic model "
    "inside the step; 0 in [min, max] of F0, q, r, F1, m0, m1 is asked as "
    "sign(F0) min(q, m0) <= 0 or sign(F0) F1 <= max(0, sign(F0) (F1 - r), sign(F0) (F1 - m1))",
)
EQ4 = {"paper": EQ4_PAPER, "consistent": EQ4_CONSISTENT, "extremum": EQ4_EXTREMUM}


@dataclass(frozen=True)
class Method:
    """A marching method (sample, step, root), or with `solves` the exact root isolation
    of the ray polynomial (no marching; templates/solver.j2)."""

    name: str
    summary: str
    sample: tuple[sympy.Expr, sympy.Expr, sympy.Expr] = ()  # (F, F', X) at march point s
    step: sympy.Expr = sympy.S.Zero  # step length from the start sample (F0, D0, X0)
    root: Rule | Mapping[str, Rule] = Rule(sympy.false)  # one rule, or one per --taylor2
    defaults: Constants = field(default_factory=Constants)
    paper_column: str = ""  # the column of the paper's Table 1 it reproduces ("" if none)
    solves: bool = False  # exact: polynomial surfaces only
    # interval: no step rule or root test; F's enclosure over a segment decides
    # (implc/interval.py, templates/interval.j2)
    bounds: bool = False
    # how a method that takes no steps finds roots, in a few words (the viewer shows it
    # where a marcher shows its step)
    unmarched: str = ""

    @property
    def reads_taylor2(self) -> bool:
        """Whether --taylor2 selects among readings of this method's root test."""
        return not isinstance(self.root, Rule)

    @property
    def reads(self) -> frozenset[str]:
        """The command line's method constants (fields of Constants) that this method's
        shader depends on, from its data: the constant symbols of its sample, step and
        root expressions (every --taylor2 reading), `taylor2` where the root test has
        readings, and `max_steps` and `evaluation` for a marcher (the exact solver and
        the interval bisection print no step cap and choose no evaluation form: see
        marcher.lower). The command line warns about a constant given outside this."""
        rules = (self.root,) if isinstance(self.root, Rule) else tuple(self.root.values())
        exprs = (*self.sample, self.step, *(r.value for r in rules),
                 *(v for r in rules for _, v in r.lets))
        used = set().union(*(e.free_symbols for e in exprs))
        fields = {c.name.lower() for c in CONSTANT_SYMBOLS if c in used}
        if self.reads_taylor2:
            fields.add("taylor2")
        if not (self.solves or self.bounds):
            fields |= {"max_steps", "evaluation"}
        return frozenset(fields)

    def root_rule(self, taylor2: str) -> Rule:
        return self.root if isinstance(self.root, Rule) else self.root[taylor2]

    def constants(self, **overrides) -> Constants:
        given = {k: v for k, v in overrides.items() if v is not None}
        if "taylor2" in given and given["taylor2"] not in TAYLOR2_CHOICES:
            raise ValueError(f"--taylor2 must be one of {', '.join(TAYLOR2_CHOICES)}")
        return replace(self.defaults, **given)


METHODS: dict[str, Method] = {
    m.name: m
    for m in (
        Method("sign", "Eq. 2 steps; root where F changes sign between step ends",
               # F' is sampled with F, though Eq. 2 reads it only near the surface:
               # evaluated inside the step rule, on the branch that reads it, it was on
               # the loop's chain (a masked branch costs every lane) and measured 10-40 %
               # slower a frame (docs/journal/2026-12-01-marcher-and-forms.md)
               (F(S), DF(S), sympy.S.Zero), eq2(F0, D0),
               Rule(F0 * F1 < 0, what="the sign test: F changes sign between the ends")),
        Method("taylor", "Eq. 2 steps; first-order Taylor interval test (Eq. 3)",
               (F(S), DF(S), sympy.S.Zero), eq2(F0, D0), TAYLOR,
               paper_column="Taylor Test"),
        Method("curvature", "b/2 where -Laplacian(S) < 0, else 2b; Taylor test (Eq. 3)",
               # kappa = -Laplacian(S): b/2 where kappa < 0, 2b where kappa >= 0
               (F(S), DF(S), LAP(S)), Piecewise((STEP / 2, -X0 < 0), (2 * STEP, True)),
               TAYLOR, paper_column="Mean Curvature"),
        Method("hessian", "Eq. 2 steps; Extended Taylor test (Eq. 4) with the exact Hessian",
               (F(S), DF(S), D2F(S)), eq2(F0, D0), EQ4, Constants(step=0.002),
               "Hessian Exact"),
        Method("hessian-approx",
               "Eq. 2 steps; Eq. 4 with F'' as a finite difference of F' along the ray",
               (F(S), DF(S), (DF(S + EPS) - DF(S)) / EPS), eq2(F0, D0), EQ4,
               paper_column="Hessian Approximate"),
        Method("exact", "polynomial S: the first real root of the ray polynomial, isolated "
               "exactly (monotonic pieces between critical points; no marching)",
               solves=True, unmarched="no marching: exact root isolation"),
        # F and F' are sampled for the refinement only
        Method("interval", "any S: segments where F's interval enclosure excludes 0 are "
               "skipped, the others halved down to the leaf, where F's sign change is "
               "refined (no sign change missed)", (F(S), DF(S), sympy.S.Zero), bounds=True,
               unmarched="no marching: interval bisection"),
    )
}


def get_method(name: str) -> Method:
    try:
        return METHODS[name]
    except KeyError:
        raise ValueError(f"unknown method '{name}'; choose from {', '.join(METHODS)}") from None
