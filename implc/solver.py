"""The `exact` method: root isolation on the ray polynomial, lowered to the pieces of
templates/solver.j2 (critical points level by level up to degree 4, Bernstein subdivision
with Descartes' rule of signs from degree 5; see BERNSTEIN_FROM), and the rule that makes
it the default method."""

from __future__ import annotations

from dataclasses import dataclass
from math import comb, log2
from typing import ClassVar

import sympy

from .derive import polynomial_degree
from .errors import InputError
from .methods import Constants
from .optimize import Program, count_ops
from .options import EXACT_MAX_DEGREE, UNIT_ROUNDOFF
from .pieces import (
    Marcher,
    ShaderFunction,
    build_programs,
    point_function,
    printed_lets,
    sym,
)
from .raypoly import (
    carry,
    coefficient_program,
    derivative_coefficients,
    estrin,
    estrin_derivative,
    estrin_derivative_ops,
    from_ray,
    horner,
    ray_setup,
)
from .walk_registers import WalkRegisters, walk_registers

# From this degree the exact method isolates F's first root by Bernstein subdivision
# (Descartes' rule of signs on the Bernstein coefficients of a node, stackless: the next
# node follows from the current one) instead of the critical points level by level: it
# visits 2-6 nodes a ray on average and stops at the first root, where the levels find every root
# of every derivative. Measured at 512^2 (docs/journal/2026-12-02-every-degree.md), exact / taylor:
# degree 5-6 with the levels 0.84-1.03 (Taubin's heart, Barth's sextic, x^6 + y^6 + z^6),
# with Bernstein 0.41-0.46 and no more bad pixels (the heart 10 of 262,144 against the
# levels' 15) since each node's ends are F's robust values (see templates/solver/walk.j2); at
# degree 4 the levels stay faster (Cross-Cap 0.43 against 0.48) and exact (Bernstein
# misses 15 pixels where the Cross-Cap's sheets meet).
BERNSTEIN_FROM = 5

# Below this degree the Newton after the Bernstein walk takes F's robust value (P_n: S at
# the point where Estrin's sign is uncertain), from it Estrin's value of the chord's
# coefficients alone. Measured at 512^2: on Taubin's heart (degree 6, roots as flat as
# F ~ 1e-9 over 1e-2 of the ray) Estrin's value alone put 293 roots 1e-3 or more from
# their place, the robust one 8, and Barth's sextic ran faster with it (0.44 against
# 0.54 of taylor); at degree 9 (corpus row 163) it cost 15 % a frame for 1 pixel.
ROBUST_NEWTON_BELOW = 7

# The levels' F (P_n) is Estrin's value where its sign is certain, else S at the point,
# from this degree; below it S at the point alone (as the Bernstein walk's): a degree-2 or
# 3 program evaluates F at its few piece ends and Newton's iterates, and llvmpipe (as a
# SIMD group with lanes on both sides) computes both sides of the select, so Estrin's value
# only added its operations. Measured at 1024^2 on llvmpipe (CPU time, 2 compiled copies,
# 15 rounds, medians): frames 0.96-0.99 of the select's on Cayley's, Clebsch's and the
# ding-dong cubics, the Whitney umbrella and corpus row 48, the same false / missed /
# wrong-root counts at 512^2 on those and corpus rows 4, 17, 29, 59, 77, 192, 212, 218
# and 251 (docs/results-gpu.md). Degree 4 (the levels' lazy loop) is not measured here.
ESTRIN_FIRST_FROM = 4

# Bernstein subdivision's bounds: a node narrower than 2^-14 of the chord is a leaf (its
# middle is a touching root when |F| there is within TOUCH), and a ray visits at most 96
# nodes (measured at 192^2 on the sweep's degree 8, 13 and 16 surfaces: 1.6-5.6 a ray on
# average, p90 2-9, 42 at most, on Chmutov's T_13 + T_13 + T_13, whose sheets nearly meet).
BERNSTEIN_DEPTH = 14
BERNSTEIN_MAX_NODES = 96

# A node that must be halved is descended up to this many levels at once: to the deepest
# node at its left end that still holds its control polygon's first sign change (b_(i-1),
# b_i with i/n < 2^-L), where F's first root most likely is; skipping a level's left
# half costs a node either way, and the stackless walk moves up again by itself. Measured
# at 512^2 (docs/journal/2026-12-04-night.md): nodes a ray on Chmutov's T18 in double 4.46 ->
# 3.88, frames 0.89-0.95 of one level at a time on T12-T20, x^18 sums unchanged; up to 2
# levels about the same, 4 worse.
DESCENT_LEVELS = 3

# After a skipped node the walk's next node is the widest its position allows, unless
# F heads towards zero at the skipped node's end: then it is narrowed to the largest
# power of two within NEXT_REACH times the distance where the control polygon's last leg
# (b_(n-1), b_n) meets zero, by at most NEXT_HALVINGS halvings and not below 1/NEXT_FLOOR
# of the skipped node. A wide next node there would hold that zero with others and be
# halved again. Simulated (scripts/walk_sim.py, 64^2): the SIMD block's most nodes on
# Chmutov's T18 7.06 -> 5.86, T12 5.86 -> 5.08, T20 7.36 -> 6.13, x^18 sums 1.91 -> 1.71;
# factors 2, 3, 5 and 8 gave 8.10, 6.38, 5.92 and 6.61 on T18. Measured at 512^2
# (docs/journal/2026-12-04-night.md): frames 0.90-0.97 of the widest next node.
NEXT_REACH = 4
NEXT_HALVINGS = 4
NEXT_FLOOR = 4

# The walk's first node, the chord's left half, is narrowed the same way where F heads
# towards zero at the chord's start: to the largest power of two within FIRST_REACH times
# F's Newton step there (|F/F'|, F' = grad S . d at the point, once a ray), by at most
# FIRST_HALVINGS halvings (to 1/16 of the chord). Simulated (scripts/walk_sim.py, 64^2),
# the SIMD block's most nodes after the rules above: Chmutov's T18 5.86 -> 5.29, T12 5.08
# -> 4.80, T20 6.14 -> 5.57, x^18 sums 1.71 -> 1.79; factors 4, 16 and 32 gave 5.52, 5.73
# and 5.82 on T18. Measured at 512^2 (docs/journal/2026-12-04-night.md): frames 0.92-0.96 on
# Chmutov. (F' from the ray's coefficients by Estrin's scheme instead made x^9 and x^10
# sums and T5 1.35x slower with the same nodes, pixel for pixel: llvmpipe's code for the
# walk's loop, not the walk.)
FIRST_REACH = 8
FIRST_HALVINGS = 3

# Where the Newton after the walk reads Estrin's value of the chord's coefficients (from
# ROBUST_NEWTON_BELOW) in float32 and S stays in monomials (no gain from Chebyshev's basis,
# or --params uniform), this many Newton steps on F's robust value (S at the
# point) follow it, inside the root node. The chord's coefficients are a Taylor expansion
# about the chord's middle, computed from S's monomials: in float32 their rounding can be a
# share of terms far larger than F near its root (Chmutov's T_12 written in monomials, a
# clip radius of 1.5), and Estrin's root lands up to 1e-2 from the root. Measured at 256^2
# against the certified reference (scripts/float32_diagnosis.py): on T_12 with S in
# monomials, the float32 program 33 bad pixels, with one step on S 5, with two 5 (S at the
# point alone in float32, everything else in double: 2). Where S is in Chebyshev's basis
# the Newton reads S throughout instead (lower_solver). On x^12 and x^20 sums and Barth's
# decic the counts are unchanged (0 / 0 / 0, 0 / 0 / 0, 0 / 2 / 0). In double the
# coefficients hold the root and nothing follows Estrin's Newton (programs unchanged).
POLISH_STEPS = 2

# Where the ray's coefficients come from S in Chebyshev's basis (float32 from ROBUST_NEWTON_BELOW,
# implc/chebyshev.py), a node the walk would skip, or take as a root node, is decided again on F
# re-expanded about its own middle (ray_of called at the top of the walk's next round) when the
# expansion's middle lies outside the node and an inner Bernstein coefficient is within
# RECENTER_ERR times the coefficients' own error measured at the node's ends: |b_0 - F(a)| and
# |b_n - F(b)|, F there being S at the point, which the walk computes anyway. The power series
# about one point of the chord rounds to a share of its terms there (up to (1 + sqrt 2)^n times
# F's size at T_n), and a root pair skipped is a first root missed; a root node's one sign change
# may be three roots merged, and Newton took the last. These programs' Newton also takes F' from
# the gradient at the point (on the coefficients' slope it stopped short of the root). Chmutov
# T14-T20 at 512^2 (framed): 0-2 bad pixels on all six float32 renderers (and T20 the 7 false hits
# the double program has too), against 25-1,027 with
# one expansion; exact / taylor 0.43-0.65. The first test, 1e-4 of the size of F's terms on the
# node (scale_at), re-expanded 44-65 % of the walking pixels (0.54-0.81) and still missed root
# pairs on the default view; the history, measured: docs/results-float32.md.
RECENTER_ERR = 8.0
# The first expansion's centre, a share of the chord. At 512^2 on gl (bad pixels at
# T14-T20, against the certified reference): 0.5 (the middle) 0, 1, 0, 19, 39, 62, 41;
# 0.25 (the first node's middle) 2, 41, 33, 132, 35, 11, 26; 0.375 and 0.45 between
# them. The middle has the fewest in all and is within issue 48's 0.01 % (26) to T17;
# with a node re-expanded also where the centre is at its end (|nm| >= nr), worse at
# both (T17 151 and 150). It costs more: exact / taylor at 512^2 T16-T19 0.88, 0.98,
# 1.05, 1.02 against 0.84, 0.91, 0.98, 0.91 in the same run (docs/results-float32.md).
RECENTER_AT = 0.5
# ... from this degree: below it one expansion about the chord's middle was right on gl
# and wgpu (T7-T13: 0-2 bad pixels of 65,536 at 256^2; T14 4-7 and T15 9-15 were not)
# and the re-expansion cost 10-30 % a frame at T8-T13 (exact / taylor 0.47-0.60 ->
# 0.56-0.72)
RECENTER_FROM = 14

# EXACT_MAX_DEGREE, the exact method's highest degree (and why), is in implc/options.py


def check_exact(expr: sympy.Expr) -> int:
    """The degree of S, or an InputError saying why `-m exact` does not apply."""
    from .methods import METHODS

    marching = ", ".join(m for m, meth in METHODS.items() if not meth.solves)
    degree = polynomial_degree(expr)
    if degree is None:
        raise InputError("-m exact needs a polynomial surface (it isolates the roots of the "
                         f"ray polynomial); this one is not: use one of {marching}")
    if degree > EXACT_MAX_DEGREE:
        raise InputError(f"-m exact supports degree up to {EXACT_MAX_DEGREE} (float32 root "
                         f"isolation is measured correct up to there); this surface has "
                         f"degree {degree}: use one of {marching}")
    return degree


@dataclass(frozen=True)
class Solver:
    """What templates/solver.j2 needs for the `exact` method on a degree-n polynomial."""

    degree: int
    bottom: int  # the level solved in closed form: 2 (a quadratic) or 1 (linear)
    closed: tuple[str, ...]  # that level's coefficients a_0.. (printed), lowest first
    # "levels" (critical points level by level) or "bernstein" (subdivision with
    # Descartes' rule of signs), by degree: see BERNSTEIN_FROM
    strategy: str = "levels"
    # bernstein: the lets (name, printed value, pairs closed) that give b0..bn, the
    # Bernstein coefficients of sum e_k w^k on w in [-1, 1] (see bernstein_lets)
    bernstein: tuple[tuple[str, str, tuple[int, ...]], ...] = ()
    # bernstein: w_i = -1 + 2i/n (printed), where b_i sits in the node's control polygon,
    # whose zero starts the Newton (see lower_solver), and 2/n, their spacing
    control_w: tuple[str, ...] = ()
    control_step: str = ""
    # bernstein: the Newton after the walk takes F's robust value (ROBUST_NEWTON_BELOW)
    robust_newton: bool = False
    # bernstein: a descent's levels (see DESCENT_LEVELS), shallowest first: (L, the pairs
    # (b_(i-1), b_i) by i whose sign change sends it L levels down)
    descent: tuple[tuple[int, tuple[int, ...]], ...] = ()
    # bernstein: NEXT_REACH/n printed (the next node's reach is it times |b_n/(b_n -
    # b_(n-1))| times the skipped node's width), 1/NEXT_FLOOR printed, NEXT_HALVINGS
    next_reach: str = ""
    next_floor: str = ""
    next_halvings: int = 0
    # bernstein: FIRST_REACH printed, FIRST_HALVINGS
    first_reach: str = ""
    first_halvings: int = 0
    # bernstein, Newton on Estrin's value in float32: the Newton steps on F's robust value
    # after it (POLISH_STEPS; 0: none)
    polish: int = 0
    # bernstein, ray's coefficients from Chebyshev's basis: RECENTER_ERR and RECENTER_AT
    # printed ("": F is expanded once, about the chord's middle)
    recenter_err: str = ""
    recenter_at: str = ""
    # bernstein: Newton's start computed after the walk from the root node's coefficients
    # again, not kept through it (double: RDNA3 spilled the walk from degree 13)
    late_start: bool = False
    # bernstein: the walk's values in fewer registers (which, by precision: walk_registers.py)
    registers: WalkRegisters = WalkRegisters()


@dataclass(frozen=True)
class Solving(Marcher):
    """The `exact` method's lowering: templates/solver.j2 in place of the march."""

    kind: ClassVar[str] = "solve"
    solver: Solver


def _unit_roundoff(printer) -> float:
    """The unit roundoff of the precision `printer` prints in."""
    return UNIT_ROUNDOFF[printer.precision]


def _round_err(n: int, printer, prefix: str) -> tuple[str, str, str]:
    """ROUND_ERR: the rounding error of F (degree n) by Estrin's scheme is below
    gamma_m sum |c_k| |u|^k with m = 3 ceil(log2(n + 1)) (each term meets at most that many
    roundings: its power's squarings, its product, the sums up the tree), and m <= 2n for
    n >= 1, so below 2n eps sum |c_k| |u|^k (eps: the unit roundoff, gamma_m ~ m eps); twice
    that, in units of the ray record's `size`."""
    return ("real", prefix.upper() + "ROUND_ERR",
            printer.float_literal(4 * n * _unit_roundoff(printer)))


def _bisections(printer, prefix: str) -> tuple[str, str, str]:
    """BISECTIONS: the midpoints the levels' Newton takes besides its NEWTON_STEPS steps,
    as many as halve a bracket to the precision's resolution (24 in float32, 53 in double).
    It makes the loop's trip count unknown to the compiler (see templates/solver.j2)."""
    return ("int", prefix.upper() + "BISECTIONS", str(-int(log2(_unit_roundoff(printer)))))


def _touch(constants: Constants, printer) -> float:
    """TOUCH, the touching root's tolerance relative to the size of F's terms: the
    constant as measured in float32 (options.Constants.touch, far below float32's
    rounding, so that only an F that rounds to about 0 touches), scaled by the unit
    roundoff in double, where it keeps that meaning. Unscaled, 1e-13 is a thousand double
    roundings: on corpus row 247 (the degree-14 knot) the double walk took rays passing
    near a curve where S vanishes to high order as touches, 65 false hits and 25 wrong
    roots at 512^2 against the certified reference; scaled, 0 / 0 / 0 (the gallery's
    counts unchanged)."""
    return constants.touch * _unit_roundoff(printer) / UNIT_ROUNDOFF["float"]


def _value_function(name: str, n: int, printer, prefix: str,
                    carried: tuple[tuple[str, str], ...], certain_first: bool) -> ShaderFunction:
    """F at u = t - sm, whose sign is the answer: S at the point, or (certain_first)
    Estrin's value where its sign is certain (ROUND_ERR), else S at the point (see
    RAY_DERIVATIVES). Estrin's chain is about 2 log2(n) operations where Horner's is 2n:
    measured on x^18 + y^18 + z^18 = 1 at 512^2 (with Fh), 8 % a frame."""
    at_point = f"{prefix}S({', '.join(['ray.o + u*ray.d', *from_ray(carried)])})"
    if not certain_first:
        return ShaderFunction(name, "F at u = t - sm: S at the point",
                              (("Ray", "ray"), ("real", "u")), "real", (), (at_point,))
    certain = f"{printer.doprint(sympy.Abs(sym('h')))} > {prefix.upper()}ROUND_ERR*ray.size"
    value, powers = estrin(derivative_coefficients(n, 0), sym("u"))
    return ShaderFunction(
        name, "F at u = t - sm: Estrin's value where its sign is certain, else S at the "
        "point", (("Ray", "ray"), ("real", "u")), "real",
        (*printed_lets(powers, printer), ("real", "h", printer.doprint(value))),
        (printer.print_select(certain, "h", at_point),))


def _chebyshev(expr: sympy.Expr, precision: str, ray: bool) -> Program | None:
    """S (or, with `ray`, the ray's coefficients) from S in Chebyshev's basis of its box
    (implc/chebyshev.py), where exact's program takes them: in float32, from
    ROBUST_NEWTON_BELOW (where its Newton and walk read them), where that basis holds S
    better than its monomials; else None. The box is found by sampling S, with numpy or,
    where numpy cannot load (issue 43), in plain Python: the same box, the same program
    (issue 48)."""
    if precision != "float" or (polynomial_degree(expr) or 0) < ROBUST_NEWTON_BELOW:
        return None
    from .chebyshev import chebyshev_program, chebyshev_ray_program

    if chebyshev_program(expr) is None:
        return None
    return chebyshev_ray_program(expr) if ray else chebyshev_program(expr)


def in_chebyshev(expr: sympy.Expr, precision: str) -> bool:
    """Whether exact's program takes S and the ray's coefficients from S in Chebyshev's
    basis of its box (see _chebyshev)."""
    return _chebyshev(expr, precision, ray=False) is not None


def re_expands(expr: sympy.Expr, precision: str) -> bool:
    """Whether exact's program re-expands F about a node in doubt (RECENTER_ERR): from
    RECENTER_FROM, where its coefficients come from S in Chebyshev's basis."""
    return (polynomial_degree(expr) or 0) >= RECENTER_FROM and in_chebyshev(expr, precision)


def exact_coefficients(expr: sympy.Expr, precision: str) -> Program:
    """The program of the ray's coefficients exact's shader computes in `precision`."""
    chebyshev = _chebyshev(expr, precision, ray=True)
    return chebyshev if chebyshev is not None else coefficient_program(expr, precision)


def lower_solver(constants: Constants, expr: sympy.Expr, printer, prefix: str,
                  max_derived: int, carried: tuple[tuple[str, str], ...]) -> Solving:
    """The pieces of templates/solver.j2: S and grad at the point (shading, residual),
    the ray record with the coefficients, and P_k (k = 1..n), the (n-k)-th derivative of
    F, a degree-k polynomial in u = t - sm: by Estrin's scheme for k < n (the Newton loops
    that place the critical points are bound by their chains: 7 % a frame on the quartics,
    29 % at degree 12), F itself too, with the rounding bound ROUND_ERR states."""
    programs = build_programs(expr, (("S",), ("grad",)), max_derived, printer.precision)
    chebyshev = _chebyshev(expr, printer.precision, ray=False)
    if chebyshev is not None:  # where float32 cannot hold S's monomials
        programs["S"] = chebyshev
    functions = [point_function(name, program, printer, carried)
                 for name, program in programs.items()]
    coefficients = exact_coefficients(expr, printer.precision)
    n = len(coefficients.outputs) - 1
    u = sym("u")
    bernstein = n >= BERNSTEIN_FROM
    ray_fields, ray = carry(carried, *ray_setup(coefficients, printer, size=not bernstein))
    # P_k = F^(n-k): the derivatives, which only place the pieces (level by level), or F'
    # alone (Bernstein subdivision's Newton needs no other)
    for k in ((n - 1,) if bernstein else range(1, n)):
        m = n - k
        what = "F" + "'" * m if m < 4 else f"F^({m})"
        value, powers = estrin_derivative(n, m, u)
        functions.append(ShaderFunction(
            f"P{k}", f"P{k} = {what}, degree {k} in u = t - sm",
            (("Ray", "ray"), ("real", "u")), "real", tuple(printed_lets(powers, printer)),
            (printer.doprint(value),)))
    # F itself, whose sign is the answer: for the levels from ESTRIN_FIRST_FROM, Estrin where
    # that sign is certain, else at the point (see RAY_DERIVATIVES); below it and for the
    # Bernstein walk, at the point alone.
    # llvmpipe computes both sides of the select (as does a SIMD group with lanes on both),
    # so there Estrin's value only added its operations to every node's end: measured at
    # 512^2, exact / taylor 2-10 % lower (x^18 sums 0.73 -> 0.68, Chmutov T18 1.24 ->
    # 1.11, T12 0.72 -> 0.71, corpus rows 137 0.44 -> 0.41 and 244 0.57 -> 0.54), and the
    # same false / missed / wrong-root counts on T12, x^12 sums and rows 137, 163, 244,
    # 247 and 285 (docs/journal/2026-12-03.md)
    certain_first = not bernstein and n >= ESTRIN_FIRST_FROM
    functions.append(_value_function(f"P{n}", n, printer, prefix, carried, certain_first))
    c = [sym(f"ray.c{k}") for k in range(n + 1)]
    functions.append(ShaderFunction(
        "scale_at", "sum |c_k| |u|^k: the size of F's terms at u, the touch tolerance's unit "
        "(the reference's own: 1e-12 sum |a_k| s^k)", (("Ray", "ray"), ("real", "u")), "real",
        (), (printer.doprint(horner([sympy.Abs(ck) for ck in c], sympy.Abs(u))),)))
    K = prefix.upper()
    bottom = 2 if n >= 3 else 1
    printed = (("real", K + "TOUCH", printer.float_literal(_touch(constants, printer))),
               *((_round_err(n, printer, prefix),) if certain_first else ()),
               *((_bisections(printer, prefix),) if bernstein or root_levels(n, bottom)
                 else ()),
               ("real", K + "XTOL", printer.float_literal(constants.xtol)),
               ("real", K + "CTOL", printer.float_literal(constants.ctol)),
               ("int", K + "NEWTON_STEPS", str(int(constants.newton_steps))),
               ("int", K + "CRIT_STEPS", str(int(constants.crit_steps))))
    m = n - bottom
    closed = tuple(printer.doprint(v) for v in derivative_coefficients(n, m))
    solver = Solver(n, bottom, closed)
    if bernstein:
        # Newton starts at the zero of the root node's control polygon (the points
        # (w_i, b_i)), not at the secant of its ends: at degree 18 F is far steeper at one
        # end than near the root, and the secant starts next to the other end. Measured on
        # x^18 + y^18 + z^18 = 1 at 512^2: 6.3 -> 4.5 Newton steps a hit pixel, 7 % a frame.
        control_w = tuple(printer.float_literal(-1 + 2 * i / n) for i in range(n + 1))
        # S in Chebyshev's basis holds F where the chord's coefficients do not: Newton on it
        # throughout (T_16, T_18, T_20 at 256^2: 29, 300, 1,683 wrong roots with Estrin's
        # Newton and two polishing steps, 22, 115, 740 with Newton on S, at about the
        # same frame: 0.74 -> 0.65, 0.83 -> 0.79, 0.67 -> 0.71 of taylor's)
        robust_newton = n < ROBUST_NEWTON_BELOW or chebyshev is not None
        recenter = re_expands(expr, printer.precision)
        solver = Solver(n, bottom, closed, "bernstein", bernstein_lets(n, printer),
                        control_w, printer.float_literal(2 / n), robust_newton,
                        descent_levels(n),
                        printer.float_literal(NEXT_REACH / n),
                        printer.float_literal(1 / NEXT_FLOOR), NEXT_HALVINGS,
                        printer.float_literal(FIRST_REACH), FIRST_HALVINGS,
                        POLISH_STEPS if not robust_newton and printer.precision == "float"
                        else 0,
                        *((printer.float_literal(RECENTER_ERR),
                           printer.float_literal(RECENTER_AT)) if recenter
                          else ()), late_start=printer.precision == "double",
                        registers=walk_registers(printer.precision, printer.float_literal,
                                                  NEXT_FLOOR))
        if not robust_newton:
            value, powers = estrin(c, u)
            functions.append(ShaderFunction(
                "Fh", "F at u by Estrin's scheme alone: the Newton loop's value, inside a "
                f"bracket whose ends P{n} confirmed", (("Ray", "ray"), ("real", "u")), "real",
                tuple(printed_lets(powers, printer)), (printer.doprint(value),)))
        if recenter:
            printed += (("real", K + "RECENTER_ERR", solver.recenter_err),)
        printed += (("int", K + "MAX_NODES", str(BERNSTEIN_MAX_NODES)),
                    ("real", K + "MIN_WIDTH", printer.float_literal(2.0 ** -BERNSTEIN_DEPTH)))
    return Solving("ray-poly", tuple(functions), printed, ray_fields, ray, carried, solver)


def root_levels(n: int, bottom: int) -> range:
    """The levels k whose roots templates/solver/levels.j2 finds by a function root<k> (the levels
    strategy): above the closed-form one, up to n (F's pieces), or up to n - 2 where the
    levels n - 1 and n are solved in trace's one Newton loop (lazy: from degree 4)."""
    return range(bottom + 1, n - 1 if n - 1 > bottom else n + 1)


def descent_levels(n: int) -> tuple[tuple[int, tuple[int, ...]], ...]:
    """For L = 2..DESCENT_LEVELS, the pairs (b_(i-1), b_i) with i/n < 2^-L: a sign change
    there sends a descent L levels down (the deepest such L wins)."""
    return tuple((level, pairs) for level in range(2, DESCENT_LEVELS + 1)
                 if (pairs := tuple(i for i in range(1, n + 1) if i * 2 ** level < n)))


def bernstein_lets(n: int, printer) -> tuple[tuple[str, str, tuple[int, ...]], ...]:
    """b_0..b_n, the Bernstein coefficients of a node's polynomial sum_k e_k w^k on
    w in [-1, 1] (e_k: the Taylor coefficients about the node's middle, scaled to its half
    width): b_i = sum_k beta_ik e_k with beta_ik = sum_j C(i, j) C(n-i, k-j) (-1)^(k-j) /
    C(n, k), the blossom of w^k at i ones and n-i minus ones, so |beta_ik| <= 1 and the
    rounding of b is bounded by n eps sum |e_k| (about the node's start, as before, the
    bound grew like 3^n sum |e_k|: 57 wrong or missed pixels of 16,384 at degree 14).
    beta_(n-i),k = (-1)^k beta_ik: the even part (k even) and the odd part are summed once
    for i <= n/2 and give b_i and b_(n-i) by a sum and a difference; in double from the
    middle out (b_n, b_(n-1), read after the sums, are made last: 4 VGPRs fewer held
    through them). In double the odd part is summed negated (its first term, e_1's, is then
    positive; printed negative, it became a constant of its own, held in 2 SGPRs through
    the walk by AMD's compiler: 6 SGPRs spilled at degrees 12-13 on RDNA2/RDNA3), and
    b_i, b_(n-i) are its difference and sum: the same values, bit for bit. With each let,
    the pairs (b_(j-1), b_j) by j it completes."""
    lets: list[tuple[str, str, tuple[int, ...]]] = []
    known: set[int] = set()
    negated = printer.precision == "double"  # the odd part summed negated

    def coefficient(i: int, value: str) -> None:
        # after b_i, the pairs (b_(j-1), b_j) it completes, j in (i, i + 1)
        known.add(i)
        lets.append((f"b{i}", value, tuple(j for j in (i, i + 1)
                                            if j - 1 in known and j in known)))

    for i, even, odd in bernstein_sums(n)[::-1 if printer.precision == "double" else 1]:
        if odd is None:  # the middle coefficient
            coefficient(i, printer.doprint(even))
            continue
        lets += [(f"be{i}", printer.doprint(even), ()),
                 (f"bo{i}", printer.doprint(-odd if negated else odd), ())]
        coefficient(i, f"be{i} - bo{i}" if negated else f"be{i} + bo{i}")
        coefficient(n - i, f"be{i} + bo{i}" if negated else f"be{i} - bo{i}")
    return tuple(lets)


def bernstein_sums(n: int) -> list[tuple[int, sympy.Expr, sympy.Expr | None]]:
    """(i, even part, odd part) of b_i for i <= n/2 (bernstein_lets); the middle
    coefficient of an even degree has no odd part (None)."""
    e = [sym(f"e{k}") for k in range(n + 1)]

    def beta(i: int, k: int) -> sympy.Rational:
        return sympy.Rational(sum(comb(i, j) * comb(n - i, k - j) * (-1) ** (k - j)
                                  for j in range(k + 1)), comb(n, k))

    sums = []
    for i in range(n // 2 + 1):
        even = sympy.Add(*(beta(i, k) * e[k] for k in range(0, n + 1, 2)))
        odd = sympy.Add(*(beta(i, k) * e[k] for k in range(1, n + 1, 2)))
        sums.append((i, even, None if 2 * i == n else odd))
    return sums


@dataclass(frozen=True)
class WalkCost:
    """Operations of the Bernstein walk's parts (arithmetic only, as templates/solver/walk.j2
    prints them), for `implc show`'s per-ray estimate."""

    node: int  # Taylor shift, scaling, Bernstein sums, sign changes
    node_end: int  # F's robust value at a node's end: S at the point
    newton_step: int  # F (Estrin's, or S at the point below ROBUST_NEWTON_BELOW) and F'


def walk_cost(n: int, s_ops: int, chebyshev: bool = False) -> WalkCost:
    """WalkCost of a degree-n walk whose S costs `s_ops` at a point (`chebyshev`: S and
    the coefficients in Chebyshev's basis, where Newton reads S at the point)."""
    shift = n * (n + 1)  # n(n + 1)/2 multiply-adds
    scaling = 2 * n  # c_k nr^k (n products, n - 1 powers of nr) and nm/nr
    sums = sum(count_ops(even) + (count_ops(odd) + 2 if odd is not None else 0)
               for _, even, odd in bernstein_sums(n))
    signs = 2 * n  # a product and a comparison for each neighbouring pair
    at_point = s_ops + 6  # S at o + u d
    f = at_point if n < ROBUST_NEWTON_BELOW or chebyshev else estrin_derivative_ops(n, 0)
    return WalkCost(shift + scaling + sums + signs, at_point, f + estrin_derivative_ops(n, 1))
