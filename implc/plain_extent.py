"""implc/extent.py's search for a polynomial surface in plain Python (floats and lists, no
numpy), for the box of Chebyshev's basis (implc/box_choice.py) where numpy cannot load
(issue 43: Pyodide), so that compile chooses the box numpy's does (issue 48).

It samples the same grids in the same order and finds the same sign changes: the steps
of `extent._locate` (growing cubes, the tight cube, the clip sphere) and
`numeric.evaluate_on_grid`'s polynomial routes, each rounding as numpy's does where
that can decide a sign: the walker's values (S's tree, left to right) wherever the
expanded form's rounding bound reaches |S|. The contraction's own sums round in another
order than numpy's einsum (its last bits differ): a sign change moves by an ulp, and the
box, rounded outwards to a dyadic grid, does not (tests/test_box_choice.py checks bundled
surfaces). Pure Python takes about half a second a 65^3 grid where numpy takes 0.05 s:
only the compile without numpy pays it, for a float32 exact program from degree 7."""

from __future__ import annotations

import math
from collections.abc import Sequence
from functools import lru_cache

import sympy

from .symbols import POINT

# extent.py's grid and search too (it imports them): one set of numbers for both
GRID = 64  # cells a side; (GRID + 1)^3 = 274,625 samples a cube
SHIFT = 0.2718  # of a cell: where the grid starts inside the cube
GROWING = (2.0, 8.0, 32.0, 128.0, 512.0, 2048.0)
SHRINKING = (0.5, 0.125, 0.03125)
MARGIN = 1.05  # the clip sphere is 5 % larger than the farthest sign change, plus a cell
SPHERE_SAMPLES = 8192  # points on the clip sphere for `crosses_sphere`
GROWTH = 1.25  # the clip sphere's step while the surface pierces it (`_clear_of_sphere`)
GROWTH_STEPS = 3  # ... at most (1.95 times): pierced beyond that, the surface is unbounded
EXPAND_UP_TO = 24  # degree: at most 2,925 monomials, expanded in 0.1 s (numeric.py's too)

Point = tuple[float, float, float]
Terms = dict[tuple[int, int, int], float]


def locate(expr: sympy.Expr) -> tuple[Point, float] | None:
    """(centre, radius) of `extent.locate_surface(expr)` (no centre given), or None."""
    origin = (0.0, 0.0, 0.0)
    first_found = None
    for half in GROWING:
        points, spacing, touching = sign_changes(expr, origin, half)
        if points and not touching:
            return _clear_of_sphere(expr, *_bounded(expr, points, spacing))
        if points and first_found is None:
            first_found = half
    if first_found is not None:  # unbounded (a polynomial has no period)
        return origin, first_found
    for half in SHRINKING:
        points, spacing, _ = sign_changes(expr, origin, half)
        if points:
            return _bounded(expr, points, spacing)
    return None


def _bounded(expr: sympy.Expr, points: list[Point], spacing: float) -> tuple[Point, float]:
    low = [min(p[a] for p in points) - 2 * spacing for a in range(3)]
    high = [max(p[a] for p in points) + 2 * spacing for a in range(3)]
    middle = tuple((lo + hi) / 2.0 for lo, hi in zip(low, high, strict=True))
    widest = max(hi - lo for lo, hi in zip(low, high, strict=True))
    fine, fine_spacing, _ = sign_changes(expr, middle, widest / 2.0)
    if fine:
        points, spacing = fine, fine_spacing
    middle = tuple((min(p[a] for p in points) + max(p[a] for p in points)) / 2.0
                   for a in range(3))
    quantum = length_quantum(_reach(points, middle))
    middle = tuple(round(m / quantum) * quantum + 0.0 for m in middle)
    radius = MARGIN * _reach(points, middle) + spacing
    quantum = length_quantum(radius)
    radius = math.ceil(radius / quantum - 1e-9) * quantum
    return tuple(_round12(m) + 0.0 for m in middle), round(radius, 12)


def _round12(v: float) -> float:
    """np.round(v, 12): v times 10^12 rounded to an integer (half to even), divided back."""
    return round(v * 1e12) / 1e12


def _reach(points: list[Point], middle: Sequence[float]) -> float:
    """The farthest point's distance (np.linalg.norm's sum of squares, left to right)."""
    return max(math.sqrt((p[0] - middle[0]) ** 2 + (p[1] - middle[1]) ** 2
                         + (p[2] - middle[2]) ** 2) for p in points)


def _clear_of_sphere(expr: sympy.Expr, center: Point, radius: float) -> tuple[Point, float]:
    grown = radius
    for _ in range(GROWTH_STEPS):
        if not crosses_sphere(expr, center, grown):
            break
        grown *= GROWTH
    else:
        if crosses_sphere(expr, center, grown):
            return center, radius
    if grown == radius:
        return center, radius
    grown *= MARGIN
    quantum = length_quantum(grown)
    return center, round(math.ceil(grown / quantum - 1e-9) * quantum, 12)


def length_quantum(length: float) -> float:
    """The rounding step of a length: two significant digits (extent.py's too)."""
    return 10.0 ** (math.floor(math.log10(max(length, 1e-12))) - 1)


def crosses_sphere(expr: sympy.Expr, center: Point, radius: float) -> bool:
    """extent.crosses_sphere: S takes both signs at SPHERE_SAMPLES points of the sphere."""
    positive = negative = False
    golden = math.pi * (1.0 + math.sqrt(5.0))
    for index in range(SPHERE_SAMPLES):
        k = index + 0.5
        polar = math.acos(1.0 - 2.0 * k / SPHERE_SAMPLES)
        azimuth = golden * k
        unit = (math.cos(azimuth) * math.sin(polar), math.sin(azimuth) * math.sin(polar),
                math.cos(polar))
        value = walk(expr, tuple(c + radius * u for c, u in zip(center, unit, strict=True)))
        positive, negative = positive or value > 0, negative or value < 0
        if positive and negative:
            return True
    return False


def sign_changes(expr: sympy.Expr, center: Sequence[float],
                 half: float) -> tuple[list[Point], float, bool]:
    """extent.sign_changes: the points where S changes sign along a grid edge (numpy's
    order: by axis, then the edge's grid index), the spacing, and whether any lies in
    the cube's outer layer of cells."""
    spacing = 2.0 * half / GRID
    axes = [[c - half + spacing * (SHIFT + i) for i in range(GRID + 1)] for c in center]
    values = grid_values(expr, axes)
    sign = [1 if v > 0 else -1 if v < 0 else 0 for v in values]  # NaN: 0, no change
    size = GRID + 1
    found: list[Point] = []
    touching = False
    for axis, step in enumerate((size * size, size, 1)):
        # the edges from grid point i to i + step (flat, C order: numpy's nonzero order)
        changes = [i for i, (sa, sb) in enumerate(zip(sign, sign[step:], strict=False))
                   if sa * sb < 0]
        for i in changes:
            index = (i // (size * size), i // size % size, i % size)
            if index[axis] == GRID:  # no edge: i is on the far face along this axis
                continue
            touching = touching or any(k == 0 or k >= GRID - 1 for k in index)
            fa, fb = values[i], values[i + step]
            coords = [axes[k][index[k]] for k in range(3)]
            coords[axis] = coords[axis] + spacing * (fa / (fa - fb))
            found.append((coords[0], coords[1], coords[2]))
    return found, spacing, touching


def grid_values(expr: sympy.Expr, axes: Sequence[Sequence[float]]) -> list[float]:
    """numeric.evaluate_on_grid(expr, axes) flattened in C order, for a polynomial: a sum
    of monomials contracted; an expanded form contracted and checked against its rounding
    bound (the walker's value where the bound reaches |S|, the walker everywhere where
    that is more than a tenth of the grid); else the walker."""
    terms = sum_of_monomials(expr)
    if terms is not None:
        return _contract(terms, axes)
    terms = float_terms(expr)
    if terms is not None:
        values = _contract(terms, axes)
        magnitudes = _contract({k: abs(c) for k, c in terms.items()},
                               [[abs(v) for v in a] for a in axes])
        units = (len(terms) + max(sum(k) for k in terms) + 8) * 2.0**-52
        unsure = [i for i, (v, m) in enumerate(zip(values, magnitudes, strict=True))
                  if not abs(v) > units * m]
        if len(unsure) <= len(values) // 10:
            for i in unsure:
                values[i] = walk(expr, _grid_point(axes, i))
            return values
    return [walk(expr, _grid_point(axes, i)) for i in range(math.prod(len(a) for a in axes))]


def _grid_point(axes: Sequence[Sequence[float]], flat: int) -> Point:
    rest, c = divmod(flat, len(axes[2]))
    a, b = divmod(rest, len(axes[1]))
    return axes[0][a], axes[1][b], axes[2][c]


def _contract(terms: Terms, axes: Sequence[Sequence[float]]) -> list[float]:
    """sum c x^i y^j z^k at every grid point: x's powers contracted first, then y's, then
    Horner's scheme in z along each line."""
    degrees = [max(m[axis] for m in terms) for axis in range(3)]
    in_z: dict[tuple[int, int], list[float]] = {}
    for (i, j, k), c in terms.items():
        in_z.setdefault((i, j), [0.0] * (degrees[2] + 1))[k] += c
    powers = [[_powers(v, degrees[axis]) for v in axes[axis]] for axis in range(2)]
    values: list[float] = []
    for px in powers[0]:
        in_yz: dict[int, list[float]] = {}
        for (i, j), row in in_z.items():
            f = px[i]
            acc = in_yz.setdefault(j, [0.0] * len(row))
            for k, c in enumerate(row):
                acc[k] += f * c
        for py in powers[1]:
            line = [0.0] * (degrees[2] + 1)
            for j, row in in_yz.items():
                f = py[j]
                for k, c in enumerate(row):
                    line[k] += f * c
            line.reverse()
            for z in axes[2]:
                v = 0.0
                for c in line:
                    v = v * z + c
                values.append(v)
    return values


def _powers(v: float, top: int) -> list[float]:
    row = [1.0] * (top + 1)
    for e in range(1, top + 1):
        row[e] = row[e - 1] * v
    return row


def walk(expr: sympy.Expr, point: Point) -> float:
    """S at a point as numeric.evaluate's walker rounds it: sums and products left to
    right, integer powers by halves (b^n = b^(n // 2) b^(n - n // 2)); from S's tape, so
    that the clip sphere's 8,192 points read S's tree once."""
    values: list[float] = []
    for op, arg in _tape(expr):
        if op == "var":
            value = point[arg]
        elif op == "const":
            value = arg
        elif op == "pow":
            value = _by_halves(values[arg[0]], arg[1])
        elif op == "sqrt":
            base = values[arg]
            value = math.sqrt(base) if base >= 0 else math.nan
        else:
            value = values[arg[0]]
            for k in arg[1:]:
                value = value + values[k] if op == "add" else value * values[k]
        values.append(value)
    return values[-1]


@lru_cache(maxsize=8)
def _tape(expr: sympy.Expr) -> tuple[tuple[str, object], ...]:
    """S's distinct sub-expressions in the order the walker evaluates them, each an
    operation on earlier ones (their indices), S last."""
    tape: list[tuple[str, object]] = []
    index: dict[sympy.Basic, int] = {}

    def visit(node: sympy.Basic) -> int:
        if node in index:
            return index[node]
        if node.is_Symbol and node in POINT:
            entry: tuple[str, object] = ("var", POINT.index(node))
        elif node.is_Number or node.is_NumberSymbol:
            entry = ("const", float(node))
        elif node.is_Add or node.is_Mul:
            entry = ("add" if node.is_Add else "mul", tuple(visit(a) for a in node.args))
        elif node.is_Pow and node.exp.is_Integer and node.exp >= 0:
            entry = ("pow", (visit(node.base), int(node.exp)))
        elif node.is_Pow and node.exp == sympy.Rational(1, 2):
            entry = ("sqrt", visit(node.base))
        elif not node.free_symbols:  # a constant such as cos(1): its correctly rounded value
            entry = ("const", float(node))
        else:
            raise NotImplementedError(f"no plain meaning for {type(node).__name__}")
        index[node] = len(tape)
        tape.append(entry)
        return index[node]

    visit(expr)
    return tuple(tape)


def _by_halves(base: float, n: int) -> float:
    have = {1: base}

    def build(k: int) -> float:
        if k not in have:
            have[k] = build(k // 2) * build(k - k // 2)
        return have[k]

    return 1.0 if n == 0 else build(n)


def sum_of_monomials(expr: sympy.Expr) -> Terms | None:
    """{(i, j, k): c} of a sum of monomials c x^i y^j z^k with numeric c, else None."""
    result: Terms = {}
    for term in sympy.Add.make_args(expr):
        coefficient, rest = term.as_coeff_Mul()
        if not coefficient.is_Number:
            return None
        exponents = [0, 0, 0]
        for factor in sympy.Mul.make_args(rest) if rest != 1 else ():
            base, exp = factor.as_base_exp()
            if base not in POINT or not exp.is_Integer or exp < 1:
                return None
            exponents[POINT.index(base)] += int(exp)
        key = (exponents[0], exponents[1], exponents[2])
        result[key] = result.get(key, 0.0) + float(coefficient)
    return result


@lru_cache(maxsize=8)
def float_terms(expr: sympy.Expr) -> Terms | None:
    """S's monomials with float coefficients, for a polynomial of degree at most
    EXPAND_UP_TO whose coefficients are numbers, else None. Cached (the search's cubes
    ask again); read, never changed."""
    from .derive import expanded_terms, polynomial_degree

    degree = polynomial_degree(expr)
    if degree is None or degree > EXPAND_UP_TO:
        return None
    terms = expanded_terms(expr)
    if not terms or any(not c.is_number for c in terms.values()):
        return None
    return {key: float(c) for key, c in terms.items()}
