"""What the command line offers, as plain data: the method names, the marcher's
constants, the evaluation forms and `auto`'s degree bound (its rule is implc/marcher.py's
choose_form), the exact method's degree bound, and the counts' wrong-root tolerance.

No sympy or numpy here, so that `implc --help`, `implc COMMAND --help` and `--version`
start in a fraction of the time the registries take to import (`make startup`). The
registries that do the work import these from here (methods.py, marcher.py, solver.py);
tests/test_startup.py checks that the names agree with them.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

# The methods of implc/methods.py's METHODS, in its order (the `-m` choices).
METHOD_NAMES = ("sign", "taylor", "curvature", "hessian", "hessian-approx", "exact", "interval")

# Evaluation forms (implc/marcher.py): how F, F', F'' are computed along a ray.
FORMS = ("point", "ray-poly")
EVAL_CHOICES = ("auto", *FORMS)
# `auto` takes ray-poly only up to this degree (where its march step is also the cheaper,
# implc/marcher.py choose_form): up to degree 12 its false / missed / wrong-root counts
# measured those of point evaluation to a few pixels (bundled polynomials, the sweeps,
# corpus rows 137, 163, 244 and 285 at 512^2), but on the degree-14 knot of corpus row 247
# F' and F'' from the ray's coefficients made taylor 1,850 / 0 / 657 against point's
# 309 / 0 / 75, and hessian 1,398 / 0 / 497 against 58 / 0 / 3
# (docs/journal/2026-12-01-marcher-and-forms.md)
AUTO_RAY_POLY_MAX_DEGREE = 12

# The exact method's highest degree. Float32 root isolation through the expanded ray
# polynomial loses accuracy with the degree and the coefficients' size; measured at 512^2
# (docs/journal/2026-12-02-every-degree.md): 9 bad pixels of 262,144 on the degree-14 knot and 3 on
# the
# degree-18 one, 0-5 on the gallery rows of degree 10-12, but thousands on Chmutov's
# surfaces from degree 13 (coefficients up to 2^(n-1), where every method fails).
EXACT_MAX_DEGREE = 20
MAX_IMAGE = 8192  # the largest image side, in pixels (render, bench, the API)


@dataclass(frozen=True)
class Constants:
    """Every compile-time option of a marcher; each is a command-line option."""

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
    # how the ray quantities are computed: "point", "ray-poly" or "auto" (implc/marcher.py)
    evaluation: str = "auto"
    # exact: |F| <= touch * sum |c_k| |u|^k at a critical point u is a touching root, an
    # order below the float64 reference's own relative tolerance (1e-12 sum |a_k| s^k, its
    # terms taken from the entry point, ours from the chord's middle): at 1e-12 one Miter
    # pixel at 1024^2, a ray passing 1e-6 from the z-axis where S >= 0 touches zero
    # (F's minimum 9e-13), counted as a touch that the reference rejects; 1e-9 and 1e-8
    # measured 1-2 and 8-16 false hits at 512^2 next to double lines. Newton stops when
    # its step is below xtol (times 1 + |u|) or after newton_steps iterations
    # (docs/explanation/methods.md, "The exact method")
    touch: float = 1e-13
    xtol: float = 1e-6
    # the same for the critical points (roots of F', F'', ...), which only split the ray
    # into monotonic pieces: placing one off by delta can hide only a pair of roots closer
    # than delta, a dip of F smaller than |F''| delta^2 / 8 (1e-8 |F''| at 3e-4), below
    # float32's resolution of F
    ctol: float = 3e-4
    # 12: the tail of slow lanes is cut and every degree up to 12 compiles (llvmpipe's
    # LLVM took minutes on a degree-10 solver at 15 and more)
    newton_steps: int = 12
    # the cap of the eager critical-point levels (P_3 .. P_(n-2), which only cut pieces
    # for the level above; the extremum that decides a touching root keeps newton_steps):
    # a loop runs as long as its slowest lane, and a lane near a double root of P_k
    # converges linearly, so the cap is the loop's cost. 8 instead of 12 measured 20-30 %
    # off the frame at degrees 6-12 with the same counts on every bundled polynomial and
    # on the degree sweeps but one wrong-root pixel (chmutov 12: 8 against 7 of 65,536);
    # 6 lost 25 pixels at degree 12
    crit_steps: int = 8

    def as_dict(self) -> dict:
        return asdict(self)


TAYLOR2_CHOICES = ("paper", "consistent", "extremum")

# The counts' wrong-root tolerance on t (metrics.compare; `implc compare --t-tol`; the
# distance implc/conditioning.py measures against), absolute, in scene units (the paper's
# surfaces fit in a clip sphere of radius ~1.5). A float32 marcher refined by 10
# Newton-bisection steps lands within ~1e-4 of the root it bracketed (float32 t near 5 is
# itself only good to ~5e-7, and a near-double root is conditioned like sqrt of that); a
# different root is typically >= 1e-2 away at the step sizes b = 0.002..0.01. 1e-3 sits
# between the two by an order of magnitude on each side.
T_TOL = 1e-3

# The unit roundoff of each precision a shader prints in (the solver's rounding bounds and
# touch tolerance, the float32 conditioning `implc show` measures)
UNIT_ROUNDOFF = {"float": 2.0**-24, "double": 2.0**-53}

# The AMD families whose compiler statistics `implc show --gpu-stats` and
# Shader.gpu_stats report by default (RADV's names: RDNA2 and RDNA3; render/gpu_stats.py)
GPU_FAMILIES = ("navi21", "gfx1100")
