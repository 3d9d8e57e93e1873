"""The method registry: what each marcher of the paper needs and its default constants.

A method names the shader functions it needs (each a list of derived quantities that are
CSE'd together), its defaults, and the template block that implements its step rule and
root test (templates/<target>/marcher.*.j2 branches on `method.name`). The exact
definitions are in DESIGN.md section 4 and in the README.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, replace

# Functions every method's program uses: S for the residual and library users,
# grad for shading, SD = (F, F') for Newton-bisection refinement.
COMMON_FUNCTIONS: dict[str, tuple[str, ...]] = {
    "S": ("S",),
    "grad": ("grad",),
    "SD": ("S", "dS"),
}


@dataclass(frozen=True)
class Constants:
    """Every constant of a marcher; each is a command-line option."""

    step: float = 0.01  # base step b (Eq. 2)
    tau1: float = 0.01  # |F| <= tau1: near the surface, smaller steps
    tau2: float = 0.01  # |F| > tau2: far from it, step 2b
    tau3: float = 0.01  # |F'| <= tau3 near the surface: silhouette, step b/4
    eps: float = 1e-3  # finite-difference step of hessian-approx along the ray
    # Eq. 4 as printed ("paper"), "consistent" (h^2/8 and F''(t1) in r), or "extremum"
    # (consistent, plus the extremum of each end's quadratic model inside the step)
    taylor2: str = "paper"
    max_steps: int = 20000  # cap on march steps per ray (a safety bound, not a tuning knob)
    refine_steps: int = 10  # Newton-bisection iterations on the isolated interval

    def as_dict(self) -> dict:
        return asdict(self)


TAYLOR2_CHOICES = ("paper", "consistent", "extremum")


@dataclass(frozen=True)
class Method:
    name: str
    summary: str
    functions: dict[str, tuple[str, ...]]  # extra shader functions: name -> quantities
    defaults: Constants
    paper_column: str  # the column of the paper's Table 1 it reproduces ("" if none)

    def constants(self, **overrides) -> Constants:
        given = {k: v for k, v in overrides.items() if v is not None}
        if "taylor2" in given and given["taylor2"] not in TAYLOR2_CHOICES:
            raise ValueError(f"--taylor2 must be one of {', '.join(TAYLOR2_CHOICES)}")
        return replace(self.defaults, **given)

    def all_functions(self) -> dict[str, tuple[str, ...]]:
        return {**COMMON_FUNCTIONS, **self.functions}


METHODS: dict[str, Method] = {
    m.name: m
    for m in (
        Method("sign", "Eq. 2 steps; root where F changes sign between step ends",
               {"dS": ("dS",)}, Constants(), ""),
        Method("taylor", "Eq. 2 steps; first-order Taylor interval test (Eq. 3)",
               {}, Constants(), "Taylor Test"),
        Method("curvature", "b/2 where -Laplacian(S) < 0, else 2b; Taylor test (Eq. 3)",
               {"SDL": ("S", "dS", "lap")}, Constants(), "Mean Curvature"),
        Method("hessian", "Eq. 2 steps; Extended Taylor test (Eq. 4) with the exact Hessian",
               {"SDH": ("S", "dS", "d2S")}, Constants(step=0.002), "Hessian Exact"),
        Method("hessian-approx",
               "Eq. 2 steps; Eq. 4 with F'' as a finite difference of F' along the ray",
               {"dS": ("dS",)}, Constants(), "Hessian Approximate"),
    )
}


def get_method(name: str) -> Method:
    try:
        return METHODS[name]
    except KeyError:
        raise ValueError(f"unknown method '{name}'; choose from {', '.join(METHODS)}") from None
