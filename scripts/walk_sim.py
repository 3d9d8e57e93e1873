"""The exact method's Bernstein walk (templates/solver/walk.j2) re-run in float64 on a view's
pixel rays, to weigh its rules for the next node before building them: nodes a ray
(mean) and the mean over 4x4 pixel blocks of the most any pixel of the block took (what a
SIMD group pays), for the plain walk (one level a descent, the widest next node after a
skip, the chord's left half first), the shipped rules added one by one
(solver.DESCENT_LEVELS, NEXT_HALVINGS, FIRST_HALVINGS) and the lower bound: the fewest
nodes any rule could visit, the dyadic cover of the chord up to the first root by nodes
that Descartes' rule proves root-free, and the root's node (docs/journal/2026-12-04-night.md).

    python scripts/walk_sim.py "x^18 + y^18 + z^18 - 1 = 0" --size 64
"""

from __future__ import annotations

import argparse
import math

import numpy as np
from scipy.special import comb

from implc.conditioning import DIRECTION, POINT, clip_sphere, pixel_rays
from implc.loaders import load_surface
from implc.numeric import evaluate_program
from implc.raypoly import coefficient_program
from implc.solver import (
    BERNSTEIN_DEPTH,
    BERNSTEIN_MAX_NODES,
    DESCENT_LEVELS,
    FIRST_HALVINGS,
    FIRST_REACH,
    NEXT_FLOOR,
    NEXT_HALVINGS,
    NEXT_REACH,
    descent_levels,
)

MIN_WIDTH = 2.0 ** -BERNSTEIN_DEPTH


def chord_polynomials(equation: str, size: int) -> tuple[np.ndarray, np.ndarray]:
    """Per pixel ray: F's coefficients in w in [-1, 1] over the chord (columns; NaN
    outside the clip sphere), and whether the ray meets the clip sphere."""
    surface = load_surface(equation=equation)
    view = surface.view
    program = coefficient_program(surface.expr, "double")  # float64, as this simulation
    origins, dirs = (a.reshape(-1, 3) for a in pixel_rays(view, size, size))
    t0, t1, inside = clip_sphere(origins, dirs, view.clip_center, view.clip_radius)
    half = 0.5 * (t1 - t0)
    middle = origins + (t0 + half)[:, None] * dirs
    env = {**dict(zip(POINT, middle.T, strict=True)), **dict(zip(DIRECTION, dirs.T, strict=True))}
    c = np.array([np.broadcast_to(v, half.shape)
                  for v in evaluate_program(program.assignments, program.outputs, env)])
    return c * half[None, :] ** np.arange(len(c))[:, None], inside


def bernstein_matrix(n: int) -> np.ndarray:
    """b = M e: the Bernstein coefficients on [-1, 1] of sum e_k w^k."""
    m = np.zeros((n + 1, n + 1))
    for k in range(n + 1):
        p = np.polynomial.polynomial.polypow([-1.0, 2.0], k)  # w^k in s = (w + 1)/2
        for i in range(n + 1):
            m[i, k] = sum(p[j] * comb(i, j) / comb(n, j) for j in range(min(i, k) + 1))
    return m


class Ray:
    """One ray's F over the chord, w in [0, 1], and a node's verdict as the shader has it."""

    def __init__(self, c: np.ndarray, matrix: np.ndarray):
        self.f = np.polynomial.polynomial.Polynomial(c)
        self.n, self.matrix = len(c) - 1, matrix

    def value(self, w: float) -> float:
        return float(self.f(2 * w - 1))

    def bernstein(self, pos: float, width: float) -> np.ndarray:
        """The node's Bernstein coefficients b_0..b_n."""
        middle = 2 * (pos + width / 2) - 1
        e = np.array([self.f.deriv(k)(middle) / math.factorial(k) * width ** k
                      for k in range(self.n + 1)])
        return self.matrix @ e

    def crossings(self, pos: float, width: float) -> np.ndarray:
        """Which pairs (b_(i-1), b_i) of the node's coefficients change sign (0 counts)."""
        b = self.bernstein(pos, width)
        return b[:-1] * b[1:] <= 0

    def first_root(self) -> float:
        """The first sign change of F on the chord, to float64's resolution (2: none)."""
        grid = np.linspace(0.0, 1.0, 4001)
        values = self.f(2 * grid - 1)
        change = np.nonzero(np.signbit(values[:-1]) != np.signbit(values[1:]))[0]
        if not len(change):
            return 2.0
        lo, hi = grid[change[0]], grid[change[0] + 1]
        for _ in range(60):
            mid = 0.5 * (lo + hi)
            same = np.signbit(self.value(mid)) == np.signbit(self.value(lo))
            lo, hi = (mid, hi) if same else (lo, mid)
        return 0.5 * (lo + hi)


def narrowed(width: float, reach: float, halvings: int, least: float = 0.0) -> float:
    """`width` halved while wider than `reach` and `least`, at most `halvings` times (the
    template's `narrowed`)."""
    for _ in range(halvings):
        width = width / 2 if width > reach and width > least else width
    return width


def walk(ray: Ray, levels: int, halvings: int, first: int = 0) -> int:
    """Nodes the walk visits, a descent going down up to `levels` levels at once, the next
    node after a skip narrowed by up to `halvings` halvings, the first by up to `first`."""
    rule = descent_levels(ray.n) if levels > 1 else ()
    rule = tuple((level, pairs) for level, pairs in rule if level <= levels)
    pos, width, index, nodes = 0.0, 0.5, 0, 0
    left = ray.value(0.0)
    slope = 2 * ray.f.deriv()(-1.0)  # F' at the chord's start, in chord units
    if left * slope < 0:
        width = narrowed(width, FIRST_REACH * abs(left / slope), first)
    while nodes < BERNSTEIN_MAX_NODES:
        nodes += 1
        right = ray.value(pos + width)
        b = ray.bernstein(pos, width)
        cross = b[:-1] * b[1:] <= 0
        changes, change = int(cross.sum()), left * right < 0
        if change and (changes == 1 or width <= MIN_WIDTH):
            return nodes
        if change or changes > 0:
            if width <= MIN_WIDTH:
                return nodes  # a leaf: the shader's touch test decides after the walk
            down = max((level for level, pairs in rule if cross[[i - 1 for i in pairs]].any()),
                       default=1)
            width, index = width / 2 ** down, index << down
            continue
        toward = b[-1] * (b[-1] - b[-2]) < 0
        reach = NEXT_REACH / ray.n * abs(b[-1] / (b[-1] - b[-2])) * width if toward else 0.0
        least = width / NEXT_FLOOR
        left, pos = right, pos + width
        if pos >= 1.0:
            return nodes
        index += 1
        low = index & -index
        index, width = index // low, width * low
        if toward:
            width = narrowed(width, reach, halvings, least)
            index = int(pos / width)
    return nodes


def lower_bound(ray: Ray, root: float) -> int:
    """The fewest nodes any descent rule visits: dyadic nodes before the root that
    Descartes' rule proves root-free, and the root's node with one sign change."""
    def cover(pos: float, width: float) -> int:
        if pos >= root or width < MIN_WIDTH:
            return 0
        changes = int(ray.crossings(pos, width).sum())
        ends = ray.value(pos) * ray.value(pos + width) < 0
        if (pos + width <= root and changes == 0 and not ends) or (
                pos < root <= pos + width and changes == 1 and ends):
            return 1
        return cover(pos, width / 2) + cover(pos + width / 2, width / 2)

    return cover(0.0, 0.5) + cover(0.5, 0.5)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("equation")
    ap.add_argument("--size", type=int, default=64, help="pixels a side (a multiple of 4)")
    args = ap.parse_args()
    c, inside = chord_polynomials(args.equation, args.size)
    matrix = bernstein_matrix(len(c) - 1)
    rays = {j: Ray(c[:, j], matrix) for j in np.nonzero(inside)[0]}
    rules = {"plain": lambda ray: walk(ray, 1, 0),
             f"descent up to {DESCENT_LEVELS} levels": lambda ray: walk(ray, DESCENT_LEVELS, 0),
             "and the next node narrowed": lambda ray: walk(ray, DESCENT_LEVELS, NEXT_HALVINGS),
             "and the first node narrowed (shipped)":
                 lambda ray: walk(ray, DESCENT_LEVELS, NEXT_HALVINGS, FIRST_HALVINGS),
             "lower bound": lambda ray: lower_bound(ray, ray.first_root())}
    blocks = args.size // 4
    for name, count in rules.items():
        nodes = np.zeros(args.size * args.size)
        for j, ray in rays.items():
            nodes[j] = count(ray)
        block_max = nodes.reshape(blocks, 4, blocks, 4).max(axis=(1, 3)).mean()
        print(f"{name:38s} nodes a ray {nodes[list(rays)].mean():5.2f}, "
              f"4x4 block max {block_max:5.2f}", flush=True)


if __name__ == "__main__":
    main()
