"""The equation parser: grammar, semantics, limits and robustness (implc/front/)."""

from __future__ import annotations

import csv
import json
import random
from pathlib import Path

import pytest
import sympy

from implc.errors import InputError, LimitError, Source
from implc.front import (
    Limits,
    check_param_name,
    fold_constants,
    param_symbol,
    parse_constant,
    parse_equation,
    parse_equation_with_params,
    parse_number,
)
from implc.front.build import FOLD_DIGITS, Builder
from implc.functions import USER_FUNCTIONS
from implc.symbols import X, Y, Z

CORPUS = Path(__file__).resolve().parents[2] / "shared" / "corpus" / "implicit_surface_corpus.tsv"


def parse(text: str, params: dict[str, sympy.Expr] | None = None, **limits: int) -> sympy.Expr:
    return parse_equation(Source("<equation>", text), params, Limits(**limits))


def same(text: str, expected: sympy.Expr, params: dict[str, sympy.Expr] | None = None) -> bool:
    """`text` parses to `expected` (its constants folded as the parser folds them)."""
    return sympy.expand(parse(text, params) - fold_constants(expected)) == 0


# --------------------------------------------------------------------------- the paper


def test_cross_cap() -> None:
    expected = 4 * X**2 * (X**2 + Y**2 + Z**2 + Z) + Y**2 * (Y**2 + Z**2 - 1)
    assert same("4x^2(x^2 + y^2 + z^2 + z) + y^2(y^2 + z^2 - 1) = 0", expected)


def test_steiner_as_printed() -> None:
    expected = X**2 * Y**2 - X**2 * Z**2 + Y**2 * Z**2 - X * Y * Z
    assert same("x^2y^2 - x^2z^2 + y^2z^2 - xyz = 0", expected)


def test_miter() -> None:
    expected = 4 * X**2 * (X**2 + Y**2 + Z**2) - Y**2 * (1 - Y**2 - Z**2)
    assert same("4x^2(x^2 + y^2 + z^2) - y^2(1 - y^2 - z^2) = 0", expected)


def test_cross_cap_keeps_its_factored_form() -> None:
    # the parser builds what was written; expanding is a later stage's choice
    result = parse("4x^2(x^2+y^2+z^2+z) + y^2(y^2+z^2-1)")
    assert result == 4 * X**2 * (X**2 + Y**2 + Z**2 + Z) + Y**2 * (Y**2 + Z**2 - 1)


# --------------------------------------------------------------------------- grammar


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("4x^2(x+1)", 4 * X**2 * (X + 1)),
        ("x^2y^2", X**2 * Y**2),
        ("xyz", X * Y * Z),
        ("xxy", X**2 * Y),
        ("xy^2", X * Y**2),
        ("(x+1)(x-1)", (X + 1) * (X - 1)),
        ("[x+1][x-1]", (X + 1) * (X - 1)),
        ("2 x y", 2 * X * Y),
        ("2(x+1)", 2 * (X + 1)),
        ("x(x+1)", X * (X + 1)),
        ("2x^2", 2 * X**2),
        ("x^2y", X**2 * Y),
        ("x/2y", X * Y / 2),
        ("sin(x)cos(y)", sympy.sin(X) * sympy.cos(Y)),
        ("2sin(x)", 2 * sympy.sin(X)),
        ("(x)y", X * Y),
        ("pi(x+1)", sympy.pi * (X + 1)),
        ("2pi x", 2 * sympy.pi * X),
        ("e(x+1)", sympy.E * (X + 1)),
    ],
)
def test_implicit_multiplication(text: str, expected: sympy.Expr) -> None:
    assert same(text, expected)


def test_parameter_followed_by_bracket_multiplies() -> None:
    assert same("a(x+1)", sympy.Rational(1, 2) * (X + 1), {"a": sympy.Rational(1, 2)})


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("x**2 - x^2 + y", Y),
        ("2^3^2 - x", 512 - X),  # right-associative: 2^(3^2)
        ("2**3**2 - x", 512 - X),
        ("2^3**2 - x", 512 - X),
        ("-x^2", -(X**2)),
        ("-2^2 + x", X - 4),
        ("(-2)^2 + x", X + 4),
        ("2^-1 + x", X + sympy.Rational(1, 2)),
        ("x^-2", X**-2),
        ("x**-1", 1 / X),
        ("2^-x^2", 2 ** (-(X**2))),
        ("--x", X),
        ("x - -y", X + Y),
        ("+x", X),
        ("x*-y", -X * Y),
        ("1 - x - y - z", 1 - X - Y - Z),
        ("x / y / z", X / (Y * Z)),
        ("x^2 / 2 * y", X**2 * Y / 2),
        ("[(x+1)^2 + y]^2", ((X + 1) ** 2 + Y) ** 2),
        ("([x])", X),
        ("x^2 +\n y^2", X**2 + Y**2),
        ("\tx  +  y\r\n", X + Y),
    ],
)
def test_operators(text: str, expected: sympy.Expr) -> None:
    assert same(text, expected)


@pytest.mark.parametrize(
    ("text", "value"),
    [
        ("2", 2),
        ("0.5", sympy.Rational(1, 2)),
        (".5", sympy.Rational(1, 2)),
        ("5.", 5),
        ("1e-3", sympy.Rational(1, 1000)),
        ("2E+4", 20000),
        ("1.5e2", 150),
        ("0.1", sympy.Rational(1, 10)),  # exact, not the binary float
        ("000.000", 0),
        ("0e99999999999999", 0),
        ("1e30", 10**30),
        ("1e-30", sympy.Rational(1, 10**30)),
        ("123456789.123456789", sympy.Rational(123456789123456789, 10**9)),
    ],
)
def test_numbers_are_exact(text: str, value: sympy.Expr) -> None:
    assert parse(f"x - {text}") == X - value


def test_e_is_scientific_notation_only_when_digits_follow() -> None:
    assert parse("x - 2e-3") == X - sympy.Rational(2, 1000)
    assert parse("2e x") == fold_constants(2 * sympy.E * X)
    assert parse("2e + x") == fold_constants(2 * sympy.E + X)
    with pytest.raises(InputError, match="unknown name 'ex'; did you mean 'e\\*x'"):
        parse("2ex")


def test_equation_sides() -> None:
    assert parse("x^2 + y^2 = 1") == X**2 + Y**2 - 1
    assert parse("x = y") == X - Y
    assert parse("x^2 + y^2 - 1") == X**2 + Y**2 - 1


def test_constants() -> None:
    assert parse("x - pi") == fold_constants(X - sympy.pi)
    assert parse("e^x - y") == sympy.exp(X) - Y
    assert parse("x - e") == fold_constants(X - sympy.E)


def test_parameters_are_substituted() -> None:
    params = {"a": sympy.Rational(3, 4), "phi": sympy.Rational(1618, 1000)}
    assert parse("x^2 + y^2 - a^2", params) == X**2 + Y**2 - sympy.Rational(9, 16)
    assert same("phi x - a", params["phi"] * X - params["a"], params)
    assert parse("x^a2", {"a2": sympy.Integer(3)}) == X**3  # a parameter as an exponent


def test_parameter_values_may_be_plain_rationals() -> None:
    from fractions import Fraction

    assert parse("a x", {"a": Fraction(1, 3)}) == X / 3  # type: ignore[dict-item]
    assert parse("a x", {"a": 2}) == 2 * X  # type: ignore[dict-item]


def test_bad_parameter_names_are_refused() -> None:
    with pytest.raises(InputError, match="shadows the function sin"):
        parse("x", {"sin": sympy.Integer(1)})
    with pytest.raises(InputError, match="read as a product"):
        parse("x", {"xy": sympy.Integer(1)})


def test_unknown_name_suggests_a_parameter() -> None:
    with pytest.raises(InputError, match="unknown name 'alpah'; did you mean 'alpha'"):
        parse("alpah x", {"alpha": sympy.Integer(1)})
    with pytest.raises(InputError, match="unknown name 'ax'; did you mean 'a\\*x'"):
        parse("ax + 1", {"a": sympy.Integer(1)})
    with pytest.raises(InputError, match="did you mean 'sin\\(x\\)'"):
        parse("sinx")


@pytest.mark.parametrize("name", sorted(USER_FUNCTIONS))
def test_every_user_function_parses_with_its_arity(name: str) -> None:
    function = USER_FUNCTIONS[name]
    args = ["x", "y", "z"][: function.arity]
    text = f"{name}({', '.join(args)})"
    result = parse(text)
    point = {X: 0.3, Y: 0.7, Z: 0.2}
    expected = function.numpy(*(point[s] for s in (X, Y, Z)[: function.arity]))
    assert float(result.subs(point).evalf()) == pytest.approx(float(expected))
    if function.variadic:
        with pytest.raises(InputError, match=f"{name} takes 2 or more arguments, got 1"):
            parse(f"{name}(x)")
    elif function.arity > 1:
        with pytest.raises(InputError, match=f"{name} takes {function.arity} arguments, got 1"):
            parse(f"{name}(x)")
    else:
        with pytest.raises(InputError, match=f"{name} takes 1 argument, got 2"):
            parse(f"{name}(x, y)")


def test_min_and_max_stay_as_written() -> None:
    result = parse("min(x, min(y, z))")
    assert isinstance(result, sympy.Min)
    assert result.args == (X, sympy.Min(Y, Z, evaluate=False))


@pytest.mark.parametrize("count", [3, 4, 7])
def test_min_and_max_take_more_arguments(count: int) -> None:
    """`max(abs(x), abs(y), abs(z))` was "max takes 2 arguments, got 3" (issue 23, point
    17): users write CSG so. Built as a balanced tree of two-argument calls (what printers
    fold them into; sympy differentiates a flat Max of n through Max of the n - 1 others,
    comparing them pairwise), printed flat again."""
    from implc.numeric import evaluate
    from implc.textform import to_text

    terms = [f"{k}x - y^2 + sin({k}z)" for k in range(1, count + 1)]
    for name, pick in (("max", max), ("min", min)):
        result = parse(f"{name}({', '.join(terms)})")
        calls = result.atoms(sympy.Max if name == "max" else sympy.Min)
        assert len(calls) == count - 1 and all(len(c.args) == 2 for c in calls)
        point = {X: 0.3, Y: -0.4, Z: 0.8}
        values = [float(evaluate(parse(t), point)) for t in terms]
        assert float(evaluate(result, point)) == pytest.approx(pick(values))
        printed = to_text(result)
        assert printed.startswith(f"{name}(") and printed.count(f"{name}(") == 1, printed
        assert same(printed, result)


def test_nested_min_is_built_unevaluated() -> None:
    """The bound on work: sympy compares every pair of a Min's flattened arguments when it
    evaluates one, which took minutes for this nesting. Built unevaluated, each Min keeps
    the two arguments it was written with (60 of them, none flattened)."""
    text = "min(" * 60 + "x" + "".join(f", sin({i}y))" for i in range(60))
    result = parse(text)
    mins = result.atoms(sympy.Min)
    assert len(mins) == 60 and all(len(m.args) == 2 for m in mins)


# --------------------------------------------------------------------------- semantics


def test_odd_root_is_the_real_root() -> None:
    cube_root = parse("x^(1/3)")
    assert cube_root == sympy.sign(X) * sympy.Abs(X) ** sympy.Rational(1, 3)
    assert cube_root.subs(X, -8) == -2
    assert parse("x^(2/3)") == sympy.Abs(X) ** sympy.Rational(2, 3)
    assert parse("x^(2/3)").subs(X, -8) == 4
    assert parse("x^(-1/3)").subs(X, -8) == -sympy.Rational(1, 2)
    assert parse("x^(5/3)").subs(X, -8) == -32


def test_cbrt_matches_the_odd_root() -> None:
    assert parse("cbrt(x)") == parse("x^(1/3)")


def test_even_root_is_an_ordinary_power() -> None:
    assert parse("x^0.5") == sympy.sqrt(X)
    assert parse("x^(3/4)") == X ** sympy.Rational(3, 4)
    assert parse("x^pi") == fold_constants(X**sympy.pi)


def test_constant_roots() -> None:
    assert parse("(-8)^(1/3) + x") == X - 2
    assert parse("8^(2/3) + x") == X + 4
    assert parse("4^(1/2) + x") == X + 2


def test_constant_base_may_have_a_variable_exponent() -> None:
    assert parse("2^x") == 2**X
    assert parse("e^(-x^2 - y^2)") == sympy.exp(-(X**2) - Y**2)


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("x^y", "exponent must not depend on x, y, z when the base does"),
        ("(x+1)^(2y)", "exponent must not depend on x, y, z when the base does"),
        ("(-2)^x", "negative base needs an integer exponent"),
        ("(-2)^0.5 + x", "negative base needs an integer exponent"),
        ("(-2)^pi + x", "negative base needs an integer exponent"),
        ("1/0 + x", "division by zero"),
        ("x/(pi - pi)", "division by zero"),
        ("x/sin(0)", "division by zero"),
        ("0^-1 + x", "division by zero"),
        ("sqrt(-1) + x", "value is not a real number"),
        ("asin(2) + x", "value is not a real number"),
        ("log(-1) + x", "value is not a real number"),
        ("log(0) + x", "value is infinite"),
        ("tan(pi/2) + x", "value is infinite"),
        ("atan2(0, 0) + x", "value is undefined"),
        ("2 = 2", "equation does not depend on x, y or z"),
        ("x - x", "equation does not depend on x, y or z"),
    ],
)
def test_semantic_errors(text: str, message: str) -> None:
    with pytest.raises(InputError, match=message):
        parse(text)


# --------------------------------------------------------------------------- limits


@pytest.mark.parametrize(
    ("text", "limits", "option"),
    [
        ("x+" * 10_000 + "x", {}, "--max-chars"),
        ("x + 1", {"max_chars": 3}, "--max-chars"),
        ("(" * 201 + "x" + ")" * 201, {}, "--max-depth"),
        ("-" * 201 + "x", {}, "--max-depth"),
        ("x" + "^1" * 201, {}, "--max-depth"),
        ("sin(" * 10 + "x" + ")" * 10, {"max_depth": 10}, "--max-depth"),
        ("x" * 10_001, {}, "--max-nodes"),
        ("x + y + z", {"max_nodes": 3}, "--max-nodes"),
        ("cbrt(" * 20 + "x + y" + ")" * 20, {}, "--max-nodes"),  # copies its argument
        ("(x+y+z)^100000", {}, "--max-exponent"),
        ("(x+y+z)^200", {}, "--max-exponent"),
        ("x^-65", {}, "--max-exponent"),
        ("pi^1000 + x", {}, "--max-exponent"),
        ("x^(1000/3)", {}, "--max-exponent"),
        ("x^4", {"max_exponent": 3}, "--max-exponent"),
        ("(x+y+z)^30 (x+y+z)^30", {}, "--max-degree"),
        ("x^41", {"max_exponent": 100}, "--max-degree"),
        ("(x^2 + 1)^3", {"max_degree": 5}, "--max-degree"),
        ("(sin(x)+sin(y)+sin(z)+cos(x)+cos(y)+cos(z)+x+y+z+1)^12", {}, "--max-terms"),
        ("(x + y + 1)^3", {"max_terms": 9}, "--max-terms"),
        ("x - 1e31", {}, "--max-literal-exponent"),
        ("x - 2e30", {}, "--max-literal-exponent"),
        ("x - 0.00000000000000000000000000000001", {}, "--max-literal-exponent"),
        ("x - 1e-99999999999999999999", {}, "--max-literal-exponent"),
        ("x - 1000", {"max_literal_exponent": 2}, "--max-literal-exponent"),
        ("9^9^9", {}, "--max-constant-digits"),
        ("2**10**10**10", {}, "--max-constant-digits"),
        ("x - 2^1000", {}, "--max-constant-digits"),
        ("x - 2^(1000.5)", {}, "--max-constant-digits"),
        ("x - 1." + "0" * 300 + "1", {}, "--max-constant-digits"),
        ("x - " + "/".join(["3"] * 700), {}, "--max-constant-digits"),
        ("x - 2^20", {"max_constant_digits": 5}, "--max-constant-digits"),
    ],
)
def test_each_limit_triggers(text: str, limits: dict[str, int], option: str) -> None:
    with pytest.raises(LimitError) as caught:
        parse(text, **limits)
    assert caught.value.message.startswith("too complex: ")
    assert caught.value.message.endswith(f"({option})")


def test_limit_message_names_the_limit_and_its_value() -> None:
    with pytest.raises(LimitError) as caught:
        parse("(x+y+z)^100000")
    assert caught.value.message == (
        "too complex: exponent 100000 exceeds the limit of 64 (--max-exponent)"
    )


@pytest.mark.parametrize(
    ("text", "limits", "expected"),
    [
        ("(x+y+z)^30 (x+y+z)^30", {"max_degree": 60}, (X + Y + Z) ** 60),
        ("x^100", {"max_exponent": 100, "max_degree": 100}, X**100),
        ("x - 2^1000", {"max_constant_digits": 400}, X - sympy.Integer(2) ** 1000),
        ("x - 1e40", {"max_literal_exponent": 40}, X - sympy.Integer(10) ** 40),
        ("x - 1e-40", {"max_literal_exponent": 40}, X - sympy.Rational(1, 10**40)),
        ("(" * 300 + "x" + ")" * 300, {"max_depth": 400}, X),
    ],
)
def test_raised_limits_accept_the_input(text: str, limits: dict[str, int],
                                        expected: sympy.Expr) -> None:
    """Raising a limit accepts the input and reads it exactly as it would without the
    limit: compared by exact evaluation at rational points (no expansion of degree 60)."""
    got = parse(text, **limits)
    assert got.free_symbols <= {X, Y, Z}
    for point in ((sympy.Rational(1, 3), sympy.Rational(-2, 7), sympy.Rational(5, 4)),
                  (sympy.Rational(7, 5), sympy.Rational(1, 2), sympy.Rational(-3, 11))):
        at = dict(zip((X, Y, Z), point, strict=True))
        assert got.subs(at) == expected.subs(at), (text, got)


def test_within_the_default_limits() -> None:
    assert parse("x^64 - 1", max_degree=64) == X**64 - 1
    assert parse("x - 2^996") == X - 2**996
    assert parse("x - 1e30 + 1e-30") == X - 10**30 + sympy.Rational(1, 10**30)
    assert parse("(x + y + z + 1)^20") == (X + Y + Z + 1) ** 20
    assert parse("(x+1)" * 40) == (X + 1) ** 40


@pytest.mark.parametrize("text", ["(x+y+z)^100000", "(x+y+z)^200", "9^9^9", "2**10**10**10"])
def test_huge_powers_are_refused_before_sympy(text: str, monkeypatch) -> None:
    """The bound on work: the limits refuse these on the AST, so sympy builds nothing
    (computing 9^9^9 or expanding (x+y+z)^100000 would not finish)."""
    def no_sympy(self, root):
        raise AssertionError(f"sympy was asked to build {text!r}")

    monkeypatch.setattr(Builder, "build", no_sympy)
    with pytest.raises(LimitError):
        parse(text)


def test_depth_beyond_the_interpreter_stack_is_a_limit_error() -> None:
    text = "(" * 5000 + "x" + ")" * 5000
    with pytest.raises(LimitError, match="--max-depth"):
        parse(text, max_depth=100_000)


# --------------------------------------------------------------------------- robustness


def _check_total(text: str) -> None:
    """Parsing `text` returns an expression or raises InputError; nothing else."""
    try:
        result = parse_equation(Source("<fuzz>", text))
    except InputError as error:
        assert error.message
        error.render()
    else:
        assert isinstance(result, sympy.Expr)


def test_random_printable_strings_are_parsed_or_rejected() -> None:
    rng = random.Random(20240611)
    printable = [chr(c) for c in range(32, 127)] + ["\t", "\n", "\0", "\u2212", "\u00b2", "\u0663"]
    for _ in range(2000):
        _check_total("".join(rng.choice(printable) for _ in range(rng.randint(0, 20))))


def test_random_strings_are_numbers_or_rejected() -> None:
    rng = random.Random(3)
    alphabet = list("0123456789.eE+-/ x") + ["nan", "inf", "\u0663"]
    for _ in range(2000):
        text = "".join(rng.choice(alphabet) for _ in range(rng.randint(0, 8)))
        try:
            assert isinstance(parse_number(text), sympy.Rational)
        except InputError as error:
            assert error.message


def test_random_token_soup_is_parsed_or_rejected() -> None:
    """2000 random token strings: each parses to an expression in x, y, z alone (the
    parameter substituted, no unknown function) whose printed form parses back to the
    same function, or is rejected with an InputError located inside the text. Both
    outcomes must occur, so neither branch is checked vacuously."""
    from implc.functions import BY_SYMPY_NAME
    from implc.numeric import evaluate
    from implc.textform import to_text

    rng = random.Random(7)
    pieces = [
        "x", "y", "z", "xy", "2", "0", "0.5", "1e3", "1e-40", "pi", "e", "a", "(", ")",
        "[", "]", "+", "-", "*", "/", "^", "**", "=", ",", " ", "sin(", "atan2(", "min(",
        "cbrt(", "sqrt(", "(1/3)", "foo", "9^9",
    ]  # fmt: skip
    params = {"a": sympy.Rational(1, 2)}
    points = {X: 0.3, Y: -0.45, Z: 0.7}
    parsed = rejected = 0
    for _ in range(2000):
        text = "".join(rng.choice(pieces) for _ in range(rng.randint(1, 12)))
        try:
            expr = parse_equation(Source("<fuzz>", text), params)
        except InputError as err:
            rejected += 1
            rendered = err.render()
            assert rendered.startswith("<fuzz>:1:"), rendered
            col = int(rendered.split(":")[2])
            assert 1 <= col <= len(text) + 1, (text, rendered)
            continue
        parsed += 1
        assert isinstance(expr, sympy.Expr), text
        assert expr.free_symbols and expr.free_symbols <= {X, Y, Z}, (text, expr)
        names = {type(f).__name__ for f in expr.atoms(sympy.Function)}
        assert names <= set(BY_SYMPY_NAME), (text, expr)
        again = parse_equation(Source("<printed>", to_text(expr)), limits=Limits(
            max_literal_exponent=330, max_constant_digits=3000, max_degree=10**4,
            max_exponent=10**4, max_terms=10**12))
        a, b = float(evaluate(expr, points)), float(evaluate(again, points))
        assert (a == b) or (abs(a - b) <= 1e-9 * (1 + abs(a))) or (a != a and b != b), (
            text, expr, to_text(expr))
    assert parsed >= 25 and rejected >= 1000, (parsed, rejected)  # 33 and 1967 (seed 7)


@pytest.mark.skipif(not CORPUS.exists(), reason="../shared/corpus is not present")
def test_corpus_rows_parse_or_are_rejected_cleanly() -> None:
    with CORPUS.open(encoding="utf-8") as handle:
        rows = list(csv.DictReader(handle, delimiter="\t"))
    parsed = 0
    for row in rows:
        try:
            raw = json.loads(row["params"]) if row["params"] else {}
            params = {name: parse_number(repr(float(v))) for name, v in raw.items()}
            parse_equation(Source(row["name"], row["equation"]), params)
            parsed += 1
        except InputError:
            pass
    assert parsed >= 0.8 * len(rows)


# --------------------------------------------------------------------------- parse_number


@pytest.mark.parametrize(
    ("text", "value"),
    [
        ("0.5", sympy.Rational(1, 2)),
        ("-1e-3", sympy.Rational(-1, 1000)),
        ("+.25", sympy.Rational(1, 4)),
        (" 2 ", sympy.Integer(2)),
        ("1/3", sympy.Rational(1, 3)),
        ("1 / -4", sympy.Rational(-1, 4)),
        ("0.1", sympy.Rational(1, 10)),
        (repr(0.5067166090011597), sympy.Rational(5067166090011597, 10**16)),
    ],
)
def test_parse_number(text: str, value: sympy.Rational) -> None:
    result = parse_number(text)
    assert isinstance(result, sympy.Rational)
    assert result == value


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("nan", "number must be finite, got 'nan'"),
        ("-inf", "number must be finite, got '-inf'"),
        ("Infinity", "number must be finite, got 'Infinity'"),
        ("abc", "invalid number 'abc'"),
        ("0x10", "invalid number '0x10'"),
        ("1,5", "invalid number '1,5'"),
        ("", "empty number"),
        ("2/0", "division by zero"),
        ("1e400", "too complex: number '1e400' exceeds the limit of 1e30"),
    ],
)
def test_parse_number_rejects(text: str, message: str) -> None:
    with pytest.raises(InputError) as caught:
        parse_number(text)
    assert caught.value.message.startswith(message)


def test_parse_number_points_into_its_source() -> None:
    with pytest.raises(InputError) as caught:
        parse_number(" 0.5.1", Source("--param", " 0.5.1", col=9))
    assert caught.value.render().startswith("--param:1:10: error: invalid number '0.5.1'")


# --------------------------------------------------------------------------- parse_constant


@pytest.mark.parametrize(
    ("text", "value"),
    [
        ("(1+sqrt(5))/2", (1 + sympy.sqrt(5)) / 2),
        ("2pi/3", 2 * sympy.pi / 3),
        ("0.1", sympy.Rational(1, 10)),
        (" -2 ", sympy.Integer(-2)),
        ("1 / -4", sympy.Rational(-1, 4)),
        ("2^-3", sympy.Rational(1, 8)),
        ("e^2", sympy.E**2),
        ("max(1, 2, 3/2)", sympy.Integer(2)),
        (repr(0.5067166090011597), sympy.Rational(5067166090011597, 10**16)),
    ],
)
def test_parse_constant(text: str, value: sympy.Expr) -> None:
    """A parameter's value may be a constant expression, read by the equation parser
    (`--param "phi=(1+sqrt(5))/2"` was "invalid number"; issue 23, point 12); exact."""
    result = parse_constant(Source("--param", text))
    assert sympy.simplify(result - value) == 0
    assert result.is_Rational == value.is_Rational


@pytest.mark.parametrize(
    ("text", "message", "column"),
    [
        ("x/2", "a value must not depend on x, y or z", 1),
        ("1 = 2", "a value has no '='", 3),
        ("sqrt(-1)", "value is not a real number", 1),
        ("log(0)", "value is infinite", 1),
        ("1/(2 - 2)", "division by zero", 3),
        ("(1+sqrt(5)/2", "unclosed '('", 1),
        ("nan", "number must be finite, got 'nan'", 1),
        ("-inf", "number must be finite, got '-inf'", 1),
        ("0x10", "invalid number '0x10'", 1),
        ("", "empty number", 1),
        ("abc", "unknown name 'abc'", 1),
        ("9^9^9", "too complex: constant power exceeds the limit of 300 digits", 1),
        ("1e400", "too complex: number '1e400' exceeds the limit of 1e30", 1),
        ("__import__('os')", "unknown function '__import__'", 1),
    ],
)
def test_parse_constant_rejects(text: str, message: str, column: int) -> None:
    with pytest.raises(InputError) as caught:
        parse_constant(Source("--param", text))
    assert caught.value.message.startswith(message)
    assert caught.value.render().startswith(f"--param:1:{column}: error: ")


# --------------------------------------------------------------------------- check_param_name


@pytest.mark.parametrize("name", ["a", "phi", "r_1", "_k", "A", "xa", "t"])
def test_good_parameter_names(name: str) -> None:
    check_param_name(name)


@pytest.mark.parametrize(
    ("name", "message"),
    [
        ("", "empty parameter name"),
        ("1a", "parameter name '1a' is not an identifier"),
        ("a-b", "parameter name 'a-b' is not an identifier"),
        ("a b", "parameter name 'a b' is not an identifier"),
        ("x", "parameter name 'x' shadows the variable x"),
        ("z", "parameter name 'z' shadows the variable z"),
        ("xyz", "parameter name 'xyz' would read as a product of x, y, z"),
        ("yy", "parameter name 'yy' would read as a product of x, y, z"),
        ("sin", "parameter name 'sin' shadows the function sin"),
        ("atan2", "parameter name 'atan2' shadows the function atan2"),
        ("pi", "parameter name 'pi' shadows the constant pi"),
        ("e", "parameter name 'e' shadows the constant e"),
    ],
)
def test_bad_parameter_names(name: str, message: str) -> None:
    source = Source("surface.toml", name, line=5, col=1)
    with pytest.raises(InputError) as caught:
        check_param_name(name, source)
    assert caught.value.message == message
    assert caught.value.render().startswith(f"surface.toml:5:1: error: {message}\n")


# --------------------------------------------------------------------------- constant folding

A = param_symbol("a")
FOLDED_CASES = [
    # pi written as SURFER writes it, inside cos and sin (corpus row 51, the Endrass octic)
    sympy.cos(sympy.Rational(314159265358979, 400000000000000)) * X
    + sympy.sin(3 * sympy.Rational(314159265358979, 400000000000000)) * Y - 1,
    sympy.sqrt(2) * X**2 + (1 - sympy.sqrt(2)) * Y * Z - sympy.Rational(1, 16),
    sympy.pi * X * Y + sympy.E * Z**3 + sympy.pi**2,
    sympy.exp(sympy.Rational(1, 3)) * X**3 + sympy.log(7) * Z - sympy.atan(2) * Y,
    sympy.Min(X, sympy.sqrt(3), evaluate=False) + sympy.Abs(Y - sympy.pi),
    X ** sympy.pi + sympy.Pow(2, sympy.Rational(1, 3)) * Y,
]


@pytest.mark.parametrize("expr", FOLDED_CASES, ids=range(len(FOLDED_CASES)))
def test_folded_constants_keep_the_value_to_float64(expr: sympy.Expr) -> None:
    """Every constant becomes a rational or a 30-digit Float; the folded form agrees with
    the original to 25 digits at seeded points (so to float64 after printing: a printer
    prints each Float as the float64 literal nearest its value)."""
    folded = fold_constants(expr)
    numbers = [n for n in sympy.preorder_traversal(folded) if not n.free_symbols]
    assert all(n.is_Rational or n.is_Float for n in numbers), numbers
    assert all(n._prec >= 3 * FOLD_DIGITS for n in numbers if n.is_Float)
    rng = random.Random(51)
    for _ in range(8):
        point = {v: sympy.Rational(rng.randint(1, 999), 1000) for v in (X, Y, Z)}
        want = expr.xreplace(point).evalf(40)
        got = folded.xreplace(point).evalf(40)
        assert abs(got - want) <= 1e-25 * (1 + abs(want)), (point, got, want)


def test_folding_keeps_unevaluated_min_and_uniform_parameters() -> None:
    folded = fold_constants(sympy.Min(X, sympy.sqrt(3) * A, sympy.cos(A), evaluate=False)
                            + sympy.sqrt(2) * A * X)
    assert sympy.cos(A) in folded.atoms(sympy.cos)  # a parameter kept as a symbol stays
    assert not folded.atoms(sympy.Pow) - {p for p in folded.atoms(sympy.Pow)
                                           if p.free_symbols}
    mins = folded.atoms(sympy.Min)
    assert len(mins) == 1 and len(next(iter(mins)).args) == 3


def test_endrass_octic_is_a_polynomial_over_the_reals() -> None:
    """The bound on work behind corpus row 51's 81 s compile: with pi written as
    3.14159265358979 inside cos and sin, every coefficient was an unevaluated cos(p/q),
    and sympy's Poly ran over its expression domain (66 s). Folded, the degree and the
    expansion run over the reals."""
    ray = "+".join(f"(cos({k}*3.14159265358979/4)*x+sin({k}*3.14159265358979/4)*y-1)"
                   for k in range(8)).replace(")+(", ")*(")
    expr = parse(f"(x^2+y^2-(1-sqrt(2))*z^2)^2 - {ray}")
    poly = sympy.Poly(expr, X, Y, Z)
    assert poly.domain.is_RR and poly.total_degree() == 8


def test_uniform_build_folds_what_holds_no_parameter() -> None:
    values = {"a": sympy.Rational(1, 2)}
    expr, symbolic = parse_equation_with_params(
        Source("<equation>", "cos(a) x + cos(pi/5) y - sqrt(2) z"), values)
    assert symbolic.atoms(sympy.cos) == {sympy.cos(A)}
    assert not expr.atoms(sympy.cos) and not expr.atoms(sympy.Pow)


@pytest.mark.parametrize(("text", "rewritten"), [
    ("x^2y^2 + y^2z^2 + z^2x^2 - xyz", "x^2y^2 + y^2z^2 + z^2x^2 - xyz + 0*x^3"),
    ("x^2y^2 + y^2z^2 + z^2x^2 - xyz", "(x*y)^2 + (y*z)^2 + (z*x)^2 - xyz"),
    ("4x^2(x^2 + y^2 + z^2 + z) + y^2(y^2 + z^2 - 1)",
     "4x^2(x^2 + y^2 + z^2 + z) + y^2(y^2 + z^2 - 1) + 0*x^3 - 0*(x*y)^2"),
    ("x*x*y + z", "x^2 y + z"),
])
def test_rewrites_the_parser_folds_give_the_same_tree(text: str, rewritten: str) -> None:
    """The same tree, so the same shader text and pixels: no render needed to know it
    (tests/test_metamorphic.py renders the rewrites that reach the shader as other text)."""
    assert parse(text) == parse(rewritten)


# The function table's `aliases` (implc/functions.py), read by the parser's hints: the test
# loops over the rows, not over names written here.

_ALIASES = [(alias, f.name) for f in USER_FUNCTIONS.values() for alias in f.aliases]


@pytest.mark.parametrize(("alias", "name"), _ALIASES)
def test_every_alias_in_the_table_names_its_row(alias: str, name: str) -> None:
    assert len(_ALIASES) >= 12
    args = ", ".join(["x"] * USER_FUNCTIONS[name].arity)
    with pytest.raises(InputError, match=rf"unknown function '{alias}'; did you mean '{name}'\?"):
        parse(f"{alias}({args}) - y")
