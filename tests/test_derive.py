"""Mathematics checked numerically: derivatives against finite differences, and every
optimized shader function against the plain expressions it replaces."""

from __future__ import annotations

import numpy as np
import pytest
import sympy
from cases import EXAMPLES, chmutov

from implc.derive import DEFAULT_MAX_DERIVED, Derivatives
from implc.emit import build_functions, emit, function_quantities
from implc.functions import FUNCTIONS
from implc.loaders import load_surface
from implc.marcher import point_sets
from implc.methods import METHODS
from implc.numeric import evaluate, evaluate_program
from implc.optimize import _sums_by_depth, arrange_by_depth
from implc.pieces import build_programs
from implc.raypoly import estrin, estrin_derivative, weighted_coefficients
from implc.symbols import DIRECTION, POINT
from implc.targets import get_target

N = 128  # random points per example


def _points(example: str, seed: int = 7):
    """Seeded random points inside the example's clip sphere and unit directions."""
    rng = np.random.default_rng(seed)
    view = load_surface(example).view
    p = rng.uniform(-1, 1, (N, 3)) * view.clip_radius / np.sqrt(3) + view.clip_center
    d = rng.normal(size=(N, 3))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    return p, d


def _env(p, d):
    env = {s: p[:, i] for i, s in enumerate(POINT)}
    env.update({s: d[:, i] for i, s in enumerate(DIRECTION)})
    return env


@pytest.mark.parametrize("example", EXAMPLES)
def test_derivatives_match_finite_differences(example):
    surface = load_surface(example)
    d = Derivatives(surface.expr)
    p, u = _points(example)
    h = 1e-5
    env = _env(p, u)

    def S_at(q):
        return evaluate(surface.expr, _env(q, u))

    grad = np.stack([evaluate(g, env) for g in d.gradient], axis=1)
    fd_grad = np.stack(
        [(S_at(p + h * e) - S_at(p - h * e)) / (2 * h) for e in np.eye(3)], axis=1
    )
    scale = 1.0 + np.abs(fd_grad).max()
    np.testing.assert_allclose(grad, fd_grad, rtol=1e-5, atol=1e-6 * scale)

    # F'(t) and F''(t) along the ray through p in direction u
    f1 = evaluate(d.directional, env)
    f2 = evaluate(d.second_directional, env)
    fd1 = (S_at(p + h * u) - S_at(p - h * u)) / (2 * h)
    h2 = 1e-4
    fd2 = (S_at(p + h2 * u) - 2 * S_at(p) + S_at(p - h2 * u)) / (h2 * h2)
    np.testing.assert_allclose(f1, fd1, rtol=1e-5, atol=1e-6 * scale)
    np.testing.assert_allclose(f2, fd2, rtol=1e-3, atol=1e-4 * (1 + np.abs(fd2).max()))

    lap = evaluate(d.laplacian, env)
    hess_trace = sum(evaluate(d.hessian[i][i], env) for i in range(3))
    np.testing.assert_allclose(lap, hess_trace, rtol=1e-12, atol=1e-12)


@pytest.mark.parametrize("example", EXAMPLES)
@pytest.mark.parametrize("method", ["hessian", "curvature", "sign"])
def test_optimized_program_equals_original(example, method):
    surface = load_surface(example)
    d = Derivatives(surface.expr)
    p, u = _points(example, seed=11)
    env = _env(p, u)
    for name, program in build_functions(surface.expr, METHODS[method]).items():
        quantities = function_quantities(METHODS[method])[name]
        original = [e for q in quantities for e in d.quantity(q)]
        got = evaluate_program(program.assignments, program.outputs, env)
        for g, o in zip(got, original, strict=True):
            want = evaluate(o, env)
            np.testing.assert_allclose(g, want, rtol=1e-9, atol=1e-9 * (1 + np.abs(want).max()),
                                       err_msg=f"{example}/{name}")
        assert program.ops_after <= program.ops_before, (name, program.ops_before,
                                                         program.ops_after)


def test_sums_add_the_latest_term_last():
    """The Cross-Cap's t0 + x^2 + z, with t0 = y^2 + z^2 two operations deep: x^2 + z is
    summed while t0 is computed, and t0 comes last (3 operations on the path, not 4)."""
    x, y, z, t0 = sympy.symbols("x y z t0", real=True)
    assignments, (out,) = _sums_by_depth([(t0, y * y + z * z)], [t0 + x * x + z], (x, y, z))
    assert assignments == [(t0, y * y + z * z)]
    assert len(out.args) == 2 and t0 in out.args, out
    for target in ("glsl", "wgsl", "opencl"):
        text = emit(load_surface("cross-cap"), target, "taylor", METHODS["taylor"].defaults)
        assert "*(t0 + (x_2 + z))" in text, target


def test_products_take_the_latest_factor_last():
    """arrange_by_depth: F1' h/2 sign(F0) with F1' ready last is (h/2 sign(F0)) F1', one
    product after F1'; a negative coefficient stays outside; the value is unchanged."""
    a, b, late = sympy.symbols("a b late", real=True)
    sign = sympy.sign(a)
    for expr in (sympy.Rational(1, 2) * b * late * sign, -b * late * sign):
        out = arrange_by_depth([], expr, {late: 1000})[1]
        product = out.args[1] if out.args[0] == -1 else out
        assert product.is_Mul and len(product.args) == 2 and late in product.args, out
        env = {a: np.array([-2.0, 3.0]), b: np.array([0.5, -7.0]), late: np.array([3.0, 5.0])}
        np.testing.assert_array_equal(evaluate(out, env), evaluate(expr, env))
    text = get_target("glsl").printer().doprint(
        arrange_by_depth([], sympy.Rational(1, 2) * b * late * sign, {late: 1000, b: 10})[1])
    assert text.endswith("*late") and text.count("late") == 1, text


@pytest.mark.parametrize("method", ["hessian", "taylor"])
def test_double_programs_sum_axis_by_axis(method):
    """In double each point function reads an axis's powers (x_2.., dx_2..) only before
    the next axis's are made (optimize._by_axis: a register file's worth of doubles on
    RDNA3 at degree 18-20), with the same values and the same operations as the float
    programs. Chmutov's T_8 is a sum of one-axis terms."""
    surface = load_surface(equation=chmutov(8))
    sets = (*point_sets(METHODS[method]), ("S",), ("grad",))  # and exact's
    floats = build_programs(surface.expr, sets, DEFAULT_MAX_DERIVED, "float")
    doubles = build_programs(surface.expr, sets, DEFAULT_MAX_DERIVED, "double")
    env = _env(*_points("sphere", seed=5))
    for name, program in doubles.items():
        assert program.ops_after == floats[name].ops_after, name
        for got, want in zip(evaluate_program(program.assignments, program.outputs, env),
                             evaluate_program(floats[name].assignments,
                                              floats[name].outputs, env), strict=True):
            np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-9 * np.abs(want).max())
        axis_of = {v.name: k % 3 for k, v in enumerate(POINT + DIRECTION)}
        made = -1  # the highest axis whose powers were made so far
        for value in (*(v for _, v in program.assignments), *program.outputs):
            powers = {s.name.partition("_")[0] for s in value.free_symbols if "_" in s.name}
            axes = {axis_of[p] for p in powers if p in axis_of}
            assert not axes or min(axes) >= made, (name, value)
            made = max(made, *axes) if axes else made


@pytest.mark.parametrize("example", EXAMPLES)
def test_no_sum_of_three_terms_is_printed_flat(example):
    """Every optimized sum is a tree of two-term sums (the pass of optimize.py that
    shortens a march step's dependency chain)."""
    surface = load_surface(example)
    for name, program in build_functions(surface.expr, METHODS["hessian"]).items():
        for expr in (*(v for _, v in program.assignments), *program.outputs):
            flat = [n for n in sympy.preorder_traversal(expr) if n.is_Add and len(n.args) > 2]
            assert not flat, (example, name, flat[:1])


@pytest.mark.parametrize("weighted", [False, True])
@pytest.mark.parametrize("degree", [0, 1, 2, 3, 4, 5, 8, 12])
def test_estrin_evaluates_the_polynomial(degree, weighted):
    """The marcher's F', F'' by Estrin's scheme (its powers s^2, s^4, ... as lets) are
    the polynomial sum w_k c_k s^k: against numpy's Horner on random coefficients and
    integer weights."""
    rng = np.random.default_rng(degree)
    c = rng.normal(size=degree + 1)
    w = [int(v) for v in rng.integers(1, 40, size=degree + 1)] if weighted else None
    s = sympy.Symbol("s", real=True)
    value, powers = estrin([sympy.Float(v) for v in c], s, w)
    x = rng.uniform(-1.5, 1.5, 64)
    scope = evaluate_program(powers, [value], {s: x})[0]
    expected = np.polyval((c * (np.array(w) if w else 1))[::-1], x)
    np.testing.assert_allclose(scope, expected, rtol=1e-12, atol=1e-12)
    assert len(powers) == max(0, (degree).bit_length() - 1)


def _invariants(expr: sympy.Basic, varying: set) -> set:
    """The largest subexpressions of `expr` free of the `varying` symbols (what a compiler
    hoists out of a loop and keeps in registers), numbers and ray fields left out."""
    if not expr.free_symbols & varying:
        return set() if expr.is_Number or expr.is_Symbol else {expr}
    return set().union(*(_invariants(a, varying) for a in expr.args))


@pytest.mark.parametrize("degree", [2, 3, 4, 5, 6, 8])
def test_second_derivative_reads_the_first_derivatives_invariants(degree):
    """F'' at a march point multiplies the coefficient products F' holds already (k c_k),
    its integer factors on the powers of s: up to degree 4 no loop invariant of its own
    (measured 1.2-1.5 % a frame on the Steiner surface, raypoly.weighted_coefficients),
    above it fewer than F'' over its own coefficients k(k-1) c_k; and it is F''."""
    s = sympy.Symbol("s", real=True)
    d1, p1 = _weighted_estrin(degree, 1, s)
    d2, p2 = _weighted_estrin(degree, 2, s)
    own, p3 = estrin_derivative(degree, 2, s)
    varying = {s, *(k for k, _ in p1 + p2 + p3)}
    first = _invariants(d1, varying)
    extra = _invariants(d2, varying) - first
    if degree <= 4:
        assert not extra, extra
    else:
        assert len(extra) < len(_invariants(own, varying) - first)
    d2f = sum(sympy.ff(k, 2) * sympy.Symbol(f"ray.c{k}", real=True) * s ** (k - 2)
              for k in range(2, degree + 1))
    for square, value in reversed(p2):
        d2 = d2.subs(square, value)
    assert sympy.expand(d2 - d2f) == 0


def _weighted_estrin(n: int, m: int, s: sympy.Symbol):
    """F^(m) at s as the march evaluates it (raypoly.estrin_function)."""
    coefficients, weights = weighted_coefficients(n, m)
    return estrin(coefficients, s, weights)


def test_degree_is_computed_once_per_compile():
    """`polynomial_degree` expands S (the costliest question a compile asks of it): the
    default method, the evaluation form, exact's check and the ray coefficients all ask
    it, and one compile computes it once."""
    from implc.derive import polynomial_degree
    from implc.marcher import default_method

    surface = load_surface(equation="x^4 + y^4 + z^4 - 1 + x y z/7")  # fresh: not cached
    before = polynomial_degree.cache_info()
    emit(surface, "glsl", default_method(surface.expr))
    after = polynomial_degree.cache_info()
    assert after.misses - before.misses == 1 and after.hits > before.hits


@pytest.mark.parametrize("seed", range(20))
def test_expanded_polynomials_differentiate_as_sympy_does(seed):
    """branch_diff's Poly path for an expanded rational polynomial gives sympy.diff's own
    expression (the same tree, so the same shader), only faster."""
    from implc.derive import _is_expanded_rational_polynomial, branch_diff

    rng = np.random.default_rng(seed)
    x, y, z = POINT
    terms = [sympy.Rational(int(rng.integers(-40, 40)), int(rng.integers(1, 9)))
             * x ** int(rng.integers(0, 7)) * y ** int(rng.integers(0, 7))
             * z ** int(rng.integers(0, 7)) for _ in range(30)]
    expr = sympy.Add(*terms)
    assert _is_expanded_rational_polynomial(expr)
    for v in POINT:
        assert branch_diff(expr, v) == sympy.diff(expr, v)
        assert branch_diff(branch_diff(expr, v), x) == sympy.diff(sympy.diff(expr, v), x)
    for other in ((x + 1) ** 2 * y, sympy.sqrt(2) * x**2, x**2 * sympy.sin(y), x ** -1):
        assert not _is_expanded_rational_polynomial(other)


@pytest.mark.parametrize("row", [f for f in FUNCTIONS if f.branch_derivative is not None],
                         ids=lambda f: f.name)
def test_branch_derivative_column_drives_branch_diff(row):
    """A row with `branch_derivative` (abs, sign) is differentiated by it whatever its
    argument: of acos(x), which sympy cannot prove real, plain sympy.diff gives re/im terms
    or an unevaluated Derivative that no target prints; twice, so F'' branches too."""
    from implc.derive import branch_diff

    x = POINT[0]
    inner = sympy.acos(x)
    expr = row.build(inner)
    assert sympy.diff(expr, x).has(sympy.re, sympy.im, sympy.Derivative)  # why the column
    first = branch_diff(expr, x)
    assert first == row.branch_derivative(inner) * sympy.diff(inner, x)
    second = branch_diff(first, x)
    assert not second.has(sympy.re, sympy.im, sympy.Derivative), second


# An expanded degree-9 polynomial, longer than HORNER_ABOVE as written (corpus row 163's
# shape: many monomials in all three variables), and the bundled examples.
_EXPANDED = ("x^9 - 3x^7y^2 + 5x^5y^2z^2 - 7x^3y^4z + 2x y^8 - 4y^6z^3 + 6z^9 - 8x^2y^2z^5"
             " + 9x^4z^4 - y^3z^3 + 2x^6y z - 3x y z^7 + 5y^5 - 2z^4x + x^2 - y + 0.5"
             " + 4x^3y^3z^3 - 6x^5y^4 + 7y^2z^7 - 5x^7z^2 + 3x^2y^6z - 9x^4y z^4 + 2y^7z^2")


# A sum of univariate polynomials with a few mixed terms: x^e, y^e and z^e alone take
# the Taylor shift (raypoly._shifted), the mixed ones Horner's loop.
_SUMS = ("7x^11 - 3x^9 + 2x^4 - x + y^10 - 5y^7 + 2y^3 + 7z^12 - 4z^8 + z^2 + 3x y z"
         " - 2x^2y^3 + z^5x + 1.5")


@pytest.mark.parametrize("precision", ["float", "double"])
@pytest.mark.parametrize("example", ["cross-cap", "steiner", "clebsch", "barth-decic",
                                     "expanded", "sums"])
def test_both_routes_to_the_ray_coefficients_agree(example, precision):
    """Horner's nested scheme (raypoly.horner_program, whose powers standing alone are
    shifted one way for float32 and another for double) and the tree's truncated
    arithmetic (derive.ray_coefficients) give the same c_0..c_n at random (o, d); an
    equation written out at length takes Horner's route."""
    from implc.derive import ray_coefficients
    from implc.optimize import count_ops
    from implc.raypoly import HORNER_ABOVE, coefficient_program, horner_program

    if example in ("expanded", "sums"):
        expr = load_surface(equation=_EXPANDED if example == "expanded" else _SUMS).expr
        if example == "expanded":
            assert count_ops(expr) > HORNER_ABOVE
            assert coefficient_program(expr, precision) == horner_program(expr, precision)
        p, d = _points("cross-cap")
    else:
        expr = load_surface(example).expr
        p, d = _points(example)
    program = horner_program(expr, precision)
    got = evaluate_program(program.assignments, program.outputs, _env(p, d))
    want = [evaluate(c, _env(p, d)) for c in ray_coefficients(expr)]
    for k, (g, w) in enumerate(zip(got, want, strict=True)):
        np.testing.assert_allclose(g, w, rtol=1e-9, atol=1e-9 * np.max(np.abs(w)),
                                   err_msg=f"{example}: c{k}")


# --- the degree, without expanding (issue 44, point 9) ------------------------------------

@pytest.mark.parametrize(("equation", "degree"), [
    ("(x + 1)^2 - x^2", 1),  # cancellation: the tree says 2
    ("(x^2 + y)^3 - x^6", 5),
    ("x*y - y*x + z", 1),
    ("(x^2+y^2+z^2+x*y+y*z+z*x+x+y+z+1)^15 - 2", 30),
    ("x^2 - x^2 + y", 1),
])
def test_degree_is_exact_without_expanding(equation, degree, monkeypatch):
    from implc.derive import polynomial_degree

    expr = load_surface(equation=equation).expr
    monkeypatch.setattr(sympy, "Poly", lambda *a, **k: pytest.fail("expanded with Poly"))
    monkeypatch.setattr(sympy, "expand", lambda *a, **k: pytest.fail("expanded"))
    assert polynomial_degree(expr) == degree


def test_degree_agrees_with_sympy_on_every_example_and_corpus_row():
    """Poly's total degree (which expands) on the bundled examples, with their parameters
    as values and as symbols, and on the permissive corpus rows."""
    from pathlib import Path

    from implc import corpus
    from implc.derive import polynomial_degree
    from implc.surface import example_paths
    from implc.symbols import POINT

    exprs = []
    for name in example_paths():
        surface = load_surface(name)
        exprs += [surface.expr, surface.symbolic_expr]
    rows = corpus.load_rows(Path(__file__).parent / "data" / "corpus_permissive.tsv")
    for row in rows:
        try:
            exprs.append(corpus.row_surface(row).expr)
        except Exception:  # noqa: BLE001 - a row implc refuses has no degree to compare
            continue
    polynomials = [e for e in exprs if e.is_polynomial(*POINT)]
    assert len(polynomials) > 60
    for expr in polynomials:
        assert polynomial_degree(expr) == sympy.Poly(expr, *POINT).total_degree(), expr


# --- issue 44 point 9: expansion without sympy's general expand -------------------------

@pytest.mark.parametrize("text", [
    "x^18 + 9x^16 y^2 - 40x^14 y z/7 + 2y^10 z^8 + x y z - 3/10",
    "4x^2(x^2 + y^2 + z^2 + z) + y^2(y^2 + z^2 - 1)",
    "(x^2 + y^2 + z^2 + x y + 1)^5 - (x - y)^3 z + 1/7",
    "(x - 1)(x - 2)(x - 3)(x - 4) + y^2 + z^2",
    "(x^2 + y^2 + z^2 - sqrt(5))^2 - 2x",  # the parser folds sqrt(5) to a 30-digit float
])
def test_expanded_terms_are_sympys_monomials(text):
    """derive.expanded_terms (Horner's route reads it) gives Poly(S).terms() exactly."""
    from implc.derive import expanded_terms

    expr = load_surface(equation=text).expr
    expected = dict(sympy.Poly(expr, *POINT).terms())
    got = expanded_terms(expr)
    assert got.keys() == expected.keys()
    for m, c in got.items():  # exact where Poly is (its float domain rounds: 30 digits)
        if c.is_Rational and expected[m].is_Rational:
            assert c == expected[m], (text, m)
        else:
            assert abs(float(c - expected[m])) <= 1e-25 * max(1.0, abs(float(c))), (text, m)
