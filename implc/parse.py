"""Equation text -> sympy expression, safely.

This module is the only place that reads user-written equations. It never hands user text
to `eval`, `exec`, `sympify`, `parse_expr` or `Rational(str)`: a hand-written tokenizer and
Pratt parser build a small AST, every limit is checked on that AST, and only then are
sympy nodes built directly (`Add`, `Mul`, `Pow`, `Rational(p, q)`, and the constructors in
`functions.USER_FUNCTIONS`). Every problem is an `InputError` (a `LimitError` for input
that is well formed but too large) located at the offending span; no other exception
escapes for any input string.

The language (DESIGN.md section 3):

- numbers `2`, `0.5`, `.5`, `1e-3`, `2E+4`, read exactly (`0.1` is 1/10). A number followed
  by `e` and digits is scientific notation (`2e-3` is 0.002); otherwise `e` is the
  constant (`2e` is 2*e, `2e+x` is 2*e + x);
- variables `x y z`; constants `pi` (also spelled `PI`), `e`; named parameters
  (substituted by their values); function calls `name(arg, ...)` from the function
  table, with its arity (`min` and `max` take two or more arguments);
- `+ - * /`; powers `^` and `**`, right-associative and binding tighter than a unary
  sign (`-x^2` is `-(x^2)`, `2^3^2` is 512, `2^-1` is 1/2); `(...)` and `[...]`;
- implicit multiplication, binding like `*`: `4x^2(x+1)`, `x^2y^2`, `(x+1)(x-1)`,
  `2 x y`, `a(x+1)` for a parameter or constant `a` (a function name followed by `(` is a
  call). A word that is not a declared name and is made only of the letters x, y, z is a
  product of those variables (`xyz`, `xy^2` = x*y^2). A number needs an explicit operator
  before it (`x 2` is an error, `2x` is not);
- `lhs = rhs` gives `lhs - rhs`; a bare expression means `= 0`. The equation must
  depend on x, y or z.

Semantics:

- `b^(p/q)` with a non-integer rational exponent and odd q (`x^(1/3)`, `x^(2/3)`) is the
  real root, defined for negative b on every target: `sign(b) * |b|^(p/q)` for odd p,
  `|b|^(p/q)` for even p. Other non-integer exponents (`x^0.5`, `x^pi`) are an ordinary
  power, defined for b >= 0 only (like `pow` in GLSL). A negative rational base needs an
  integer exponent or a fraction with an odd denominator.
- Exponents of expressions that depend on x, y, z must be constant; a positive constant
  base may have a variable exponent (`2^x`, `e^(-x^2)`; not `0^x` or `(1-pi)^x`).
- Division by a constant zero is an error, and so is any sub-expression that sympy
  evaluates to a non-real, infinite or undefined value (`sqrt(-1)`, `log(0)`, `asin(2)`,
  `sqrt(-x^2)`). Constants sympy leaves unevaluated (`sqrt(1 - pi)`) are not evaluated
  numerically, except calls with rational arguments: they are NaN in a shader.
- `min` and `max` are built unevaluated: sympy compares every pair of (flattened)
  arguments symbolically when it evaluates them, which takes minutes for nested calls.
  With more than two arguments they are a balanced tree of two-argument calls
  (`_call_expr`).

Errors name every unknown name at once (each use marked, with a `help:` line saying how
to give values), and common notations from print get their implc spelling as a hint
(`sin^2(x)`, `|x|`, full-width letters).

Limits (`Limits`, each a command-line option named after its field) are checked on the
AST before sympy builds anything: input length first, on the raw string; then nesting
depth and node count while parsing; then, bottom-up, literal magnitude, integer exponent
size, size of exactly computed constants (`9^9^9` is refused, never computed), estimated
polynomial degree and estimated number of monomials after expansion.
"""

from __future__ import annotations

import difflib
import math
import re
import unicodedata
from collections.abc import Mapping
from dataclasses import dataclass, field
from fractions import Fraction
from functools import cache

import sympy

from implc.errors import InputError, LimitError, Source
from implc.functions import CONSTANTS, USER_FUNCTIONS, Function
from implc.limits import Limits
from implc.symbols import X, Y, Z

__all__ = ["Limits", "check_param_name", "fold_constants", "param_symbol", "parse_constant",
           "parse_equation", "parse_equation_with_params", "parse_number"]


_WHITESPACE = " \t\n\r"
_OPERATORS = ("**", "==", "+", "-", "*", "/", "^", "=", "(", ")", "[", "]", ",")
_DIGITS = frozenset("0123456789")
_NUMBER_RE = re.compile(r"(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?", re.ASCII)
_NUMBER_PARTS_RE = re.compile(r"(\d*)(?:\.(\d*))?(?:[eE]([+-]?\d+))?", re.ASCII)
_MALFORMED_NUMBER_RE = re.compile(r"[0-9.]*")
_WORD_RE = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")
_IDENTIFIER_RE = re.compile(r"[A-Za-z_][A-Za-z0-9_]*\Z")
_VARIABLES: dict[str, sympy.Symbol] = {"x": X, "y": Y, "z": Z}
_CLOSING = {"(": ")", "[": "]"}

# Binding powers (left, right) of the infix operators; right < left is right-associative.
_INFIX_BP: dict[str, tuple[int, int]] = {
    "+": (10, 11),
    "-": (10, 11),
    "*": (20, 21),
    "/": (20, 21),
    "^": (31, 30),
    "**": (31, 30),
}
_IMPLICIT_BP = (20, 21)  # implicit multiplication binds like `*`
_PREFIX_BP = 25  # unary sign: tighter than `*`, looser than `^`

# Characters people paste from papers and word processors, and what they meant.
_LOOKALIKES: dict[str, str] = {
    "\u2212": "-",  # minus sign
    "\u2010": "-",  # hyphen
    "\u2013": "-",  # en dash
    "\u2014": "-",  # em dash
    "\u00d7": "*",  # multiplication sign
    "\u00b7": "*",  # middle dot
    "\u22c5": "*",  # dot operator
    "\u2217": "*",  # asterisk operator
    "\u00f7": "/",  # division sign
    "\u2215": "/",  # division slash
    "\u2044": "/",  # fraction slash
    "\u00b2": "^2",
    "\u00b3": "^3",
    "\u00b9": "^1",
    "\u2070": "^0",
    "\u2074": "^4",
    "\u2075": "^5",
    "\u2076": "^6",
    "\u2077": "^7",
    "\u2078": "^8",
    "\u2079": "^9",
    "\u03c0": "pi",
    "\uff08": "(",
    "\uff09": ")",
    "\uff1d": "=",
}

# Names from other languages, with the hint to give when they are called.
_FUNCTION_ALIASES: dict[str, str] = {
    "ln": "log",
    "arcsin": "asin",
    "arccos": "acos",
    "arctan": "atan",
    "arctan2": "atan2",
    "sgn": "sign",
    "fabs": "abs",
    "fmin": "min",
    "fmax": "max",
    "sh": "sinh",
    "ch": "cosh",
    "th": "tanh",
}
_POWER_FUNCTIONS = ("pow", "power", "powf")
_MAX_NAMES_SHOWN = 5  # unknown names listed in one message
_MAX_MARKS = 50  # their uses marked under the echoed line

# Other spellings of the constants that real dialects use and that mean nothing else:
# surf and SURFER write `PI` (corpus: IMAGINARY/surfer-alggeo-gtk). Not `E`: it is a
# common parameter name. A parameter may not take an alias's name.
_CONSTANT_ALIASES: dict[str, str] = {"PI": "pi"}

# sympy classes that compare all their arguments pairwise when evaluated (see docstring).
_UNEVALUATED = frozenset({"Min", "Max"})

_LOG10_2 = 30103  # log10(2) * 10^5, for exact integer comparisons of digit counts
_RADICAL_CAP = 10**12  # root degrees saturate here (see _Analyzer.check_radicals)
_ROOT_FUNCTIONS = {"sqrt": 2, "cbrt": 3}  # table functions that take a root of their argument
_GROWING = frozenset({"exp", "sinh", "cosh"})  # |f(a)| is about e^|a|: checked when constant
_NON_REAL_MESSAGES: tuple[tuple[sympy.Basic, str], ...] = (
    (sympy.nan, "value is undefined"),
    (sympy.zoo, "value is infinite"),
    (sympy.oo, "value is infinite"),
    (-sympy.oo, "value is infinite"),
    (sympy.I, "value is not a real number"),
)


# --------------------------------------------------------------------------- public API


def parse_equation(
    source: Source,
    params: Mapping[str, sympy.Expr] | None = None,
    limits: Limits = Limits(),  # noqa: B008 - frozen, so a shared default is safe
) -> sympy.Expr:
    """Parse `source.text` into the sympy expression `lhs - rhs`, parameters substituted.

    Raises `InputError` (or `LimitError`) located in `source`; nothing else for any text.
    `params` maps parameter names to their (rational) values; names are checked with
    `check_param_name`.
    """
    return _parse(source, params, limits, keep_params=False)[0]


def parse_equation_with_params(
    source: Source,
    params: Mapping[str, sympy.Expr],
    limits: Limits = Limits(),  # noqa: B008 - frozen, so a shared default is safe
) -> tuple[sympy.Expr, sympy.Expr]:
    """`parse_equation`'s expression, and the same equation with every parameter kept as
    a real symbol (`param_symbol(name)`) instead of its value, for `--params uniform`.

    Every check runs on the substituted expression (with the parameters' values); the
    symbolic one is then built from the same tree: a sub-expression without parameters
    is the substituted build's own node, so both fold constants alike. One exception: a
    parameter inside a constant exponent (`x^n`, `r^(1/k)`) keeps its value there (its
    value decides what the power means: an integer power, a real odd root, or pow), so a
    parameter that only appears in constant exponents is not free in the symbolic
    expression. In an exponent that depends on x, y, z (`e^(-a x^2)`) it stays a symbol.
    """
    return _parse(source, params, limits, keep_params=True)


def param_symbol(name: str) -> sympy.Symbol:
    """The symbol of parameter `name` in a symbolic (`--params uniform`) expression."""
    return sympy.Symbol(name, real=True)


def parse_constant(
    source: Source,
    limits: Limits = Limits(),  # noqa: B008 - frozen, so a shared default is safe
) -> sympy.Expr:
    """A parameter's value (`--param phi=(1+sqrt(5))/2`): a number or a constant
    expression of the equation language, read by the same parser with the same checks.

    Exact: a rational stays a `Rational` (`0.1` is 1/10), anything else the sympy
    expression as written (`1/2 + sqrt(5)/2`; the equation folds it like an inline
    constant). Raises `InputError` located in `source` for x, y, z, `=`, a non-real or
    non-finite value and everything `parse_equation` refuses.
    """
    text = source.text
    stripped = text.strip(_WHITESPACE)
    lead = len(text) - len(text.lstrip(_WHITESPACE))
    if not stripped:
        raise InputError("empty number", source, 0, max(1, len(text)))
    if stripped.lstrip("+-").lower() in ("nan", "inf", "infinity"):
        raise InputError(f"number must be finite, got {_quote(stripped)}", source, lead,
                         len(stripped))
    if re.fullmatch(r"[+-]?0[xXoObB]\w*", stripped):  # not 0 times the name x10
        raise InputError(f"invalid number {_quote(stripped)}", source, lead, len(stripped))
    value = _parse(source, None, limits, keep_params=False, constant=True)[0]
    if value.has(sympy.Min, sympy.Max):  # built unevaluated; of numbers, cheap to evaluate
        value = value.doit()
    return value


def _parse(
    source: Source, params: Mapping[str, sympy.Expr] | None, limits: Limits, keep_params: bool,
    constant: bool = False,
) -> tuple[sympy.Expr, sympy.Expr | None]:
    text = source.text
    if len(text) > limits.max_chars:
        raise LimitError(
            f"too complex: input length {len(text)} exceeds the limit of "
            f"{limits.max_chars} characters (--max-chars)",
            source,
            limits.max_chars,
            1,
        )
    if not text.strip(_WHITESPACE):
        raise InputError("empty equation", source, 0, 1)
    values = _param_values(params or {})
    try:
        tokens = _tokenize(text, values)
        root = _Parser(source, tokens, values, limits, constant).parse()
        info = _Analyzer(source, values, limits).analyze(root)
        builder = _Builder(source, values, info, limits)
        expr = builder.build(root, constant)
        if constant:
            return expr, None
        folded = fold_constants(expr)
        if not keep_params:
            return folded, None
        return folded, fold_constants(_build_symbolic(root, builder.built, info))
    except RecursionError:
        raise LimitError(
            f"too complex: nesting is too deep to parse with the limit of {limits.max_depth} "
            f"(--max-depth)",
            source,
            0,
            1,
        ) from None


def parse_number(
    text: str,
    source: Source | None = None,
    limits: Limits = Limits(),  # noqa: B008 - frozen, so a shared default is safe
) -> sympy.Rational:
    """Read a parameter value (`--param a=0.5`, a TOML value) exactly.

    Accepts an optional sign, a number literal as in equations, and an optional
    `/ denominator` (`1/3`). Rejects nan, inf and anything else with `InputError`.
    Error offsets index `text`: pass a `source` whose text is `text`.
    """
    stripped = text.strip(_WHITESPACE)
    lead = len(text) - len(text.lstrip(_WHITESPACE))
    if not stripped:
        raise InputError("empty number", source, 0, max(1, len(text)))
    match = re.fullmatch(
        r"([+-]?)("
        + _NUMBER_RE.pattern
        + r")(?:[ \t]*/[ \t]*([+-]?)("
        + _NUMBER_RE.pattern
        + r"))?",
        stripped,
        re.ASCII,
    )
    if match is None:
        if stripped.lstrip("+-").lower() in ("nan", "inf", "infinity"):
            message = f"number must be finite, got {_quote(stripped)}"
        else:
            message = f"invalid number {_quote(stripped)}"
        raise InputError(message, source, lead, len(stripped))
    numerator = _literal_value(match.group(2), source, lead + match.start(2), limits)
    if match.group(1) == "-":
        numerator = -numerator
    value = numerator
    if match.group(4) is not None:
        start = lead + match.start(4)
        denominator = _literal_value(match.group(4), source, start, limits)
        if match.group(3) == "-":
            denominator = -denominator
        if denominator == 0:
            raise InputError("division by zero", source, start, len(match.group(4)))
        value = numerator / denominator
        if _too_many_digits(value, limits.max_constant_digits):
            raise _constant_digits_error("number", limits, source, lead, len(stripped))
    return sympy.Rational(value.numerator, value.denominator)


def check_param_name(name: str, source: Source | None = None) -> None:
    """Raise `InputError` unless `name` can be a parameter of an equation.

    A parameter must be an identifier that does not shadow x, y, z, a function or a
    constant, and is not made only of x, y, z (it would read as a product). The error
    spans `name` from offset 0 of `source`.
    """
    length = max(1, len(name))
    if not name:
        raise InputError("empty parameter name", source, 0, 1)
    if not _IDENTIFIER_RE.match(name):
        raise InputError(f"parameter name {_quote(name)} is not an identifier", source, 0, length)
    if name in _VARIABLES:
        raise InputError(f"parameter name '{name}' shadows the variable {name}", source, 0, 1)
    if set(name) <= set(_VARIABLES):
        raise InputError(
            f"parameter name '{name}' would read as a product of x, y, z", source, 0, length
        )
    if name in USER_FUNCTIONS:
        raise InputError(f"parameter name '{name}' shadows the function {name}", source, 0, length)
    if name in CONSTANTS or name in _CONSTANT_ALIASES:
        constant = _CONSTANT_ALIASES.get(name, name)
        raise InputError(
            f"parameter name '{name}' shadows the constant {constant}", source, 0, length
        )


# Digits a folded constant keeps (`fold_constants`): far past float64's 17, so the float
# literal printed from it is the correctly rounded value of the constant as written.
FOLD_DIGITS = 30


def fold_constants(expr: sympy.Expr) -> sympy.Expr:
    """`expr` with every maximal sub-expression free of symbols made a number: rationals
    stay exact, anything else (`pi`, `sqrt(2)`, `cos(314159265358979/400000000000000)`)
    becomes a `FOLD_DIGITS`-digit Float, evaluated once.

    Why: sympy keeps such constants as expressions, and every polynomial operation then
    runs over its expression domain (`Poly` of the Endrass octic with `cos(pi/4)` written
    as SURFER writes pi took 66 s; over the reals it takes milliseconds). A parameter kept
    as a symbol (`--params uniform`) is not folded, nor anything holding it. Runs after
    every check of the builder (they need the exact forms); the value printed in a shader
    is the same float64 literal as before, since printers print each constant's value.
    Iterative, so a deep tree (up to --max-depth) cannot exhaust Python's stack."""
    folded: dict[sympy.Basic, sympy.Basic] = {}
    stack: list[tuple[sympy.Basic, bool]] = [(expr, False)]
    while stack:
        node, ready = stack.pop()
        if node in folded:
            continue
        if not node.free_symbols:
            folded[node] = node if node.is_Rational else _number(node)
            continue
        if not ready and node.args:
            stack.append((node, True))
            stack.extend((a, False) for a in node.args if a not in folded)
            continue
        args = tuple(folded.get(a, a) for a in node.args)
        if args == node.args:
            folded[node] = node
        elif type(node).__name__ in _UNEVALUATED:
            folded[node] = node.func(*args, evaluate=False)
        else:
            folded[node] = node.func(*args)
    return folded[expr]


def _number(constant: sympy.Expr) -> sympy.Expr:
    """A constant the builder checked (finite and real) as a FOLD_DIGITS-digit Float."""
    return constant.evalf(FOLD_DIGITS)


def _build_symbolic(
    root: _Node, numeric: Mapping[_Node, sympy.Expr], info: Mapping[_Node, _Info]
) -> sympy.Expr:
    """The tree rebuilt with parameters as symbols (see `parse_equation_with_params`).

    Nodes without a parameter below them are taken from the checked numeric build;
    the others are rebuilt the way `_Builder` builds them, without the value checks
    (they ran on the values already)."""
    built: dict[_Node, sympy.Expr] = {}
    symbolic: set[_Node] = set()
    for node in _postorder(root):
        if (isinstance(node, _Named) and node.is_param) or any(
                c in symbolic for c in _children(node)):
            symbolic.add(node)
        if node not in symbolic:
            built[node] = numeric[node]
        elif isinstance(node, _Named):
            built[node] = param_symbol(node.name)
        elif isinstance(node, _Neg):
            built[node] = -built[node.operand]
        elif isinstance(node, _Sum):
            built[node] = sympy.Add(*(-built[t] if neg else built[t]
                                      for t, neg in zip(node.terms, node.negative, strict=True)))
        elif isinstance(node, _Product):
            built[node] = sympy.Mul(*(sympy.Pow(built[f], -1) if divide else built[f]
                                      for f, divide in zip(node.factors, node.divide,
                                                           strict=True)))
        elif isinstance(node, _Power):
            power = info[node.exponent].value
            exponent = built[node.exponent] if power is None else numeric[node.exponent]
            built[node] = _symbolic_power(built[node.base], exponent, power)
        elif isinstance(node, _Call):
            expr = _call_expr(USER_FUNCTIONS[node.name], [built[a] for a in node.args])
            if expr.has(sympy.cot):
                expr = expr.replace(sympy.cot, lambda u: 1 / sympy.tan(u))
            built[node] = expr
        else:  # pragma: no cover - numbers and variables hold no parameter
            raise AssertionError(f"unexpected node {node!r}")
    return built[root]


def _call_expr(function: Function, args: list[sympy.Expr]) -> sympy.Expr:
    """A table function applied to built arguments. min and max are built unevaluated (see
    the module docstring), and with more than two arguments as a balanced tree of
    two-argument calls, the tree the printers fold them into anyway: sympy differentiates
    an n-ary Max through an evaluated Max of the other arguments, which compares them
    pairwise (max of 8 trigonometric terms: 23 s for the Hessian, 1.1 s as a tree)."""
    if function.sympy_name not in _UNEVALUATED:
        return function.build(*args)
    if len(args) <= 2:
        return function.build(*args, evaluate=False)
    half = (len(args) + 1) // 2
    return function.build(_call_expr(function, args[:half]), _call_expr(function, args[half:]),
                          evaluate=False)


def _symbolic_power(base: sympy.Expr, exponent: sympy.Expr, power: Fraction | None) -> sympy.Expr:
    """`_Builder.make_power`'s result when base or exponent holds parameters; a constant
    exponent (`power` is its exact value) comes from the numeric build."""
    if power is None:
        return sympy.Pow(base, exponent)
    if power.denominator == 1:
        return sympy.Pow(base, sympy.Integer(power.numerator))
    rational = sympy.Rational(power.numerator, power.denominator)
    if power.denominator % 2 == 0:
        return sympy.Pow(base, rational)
    magnitude = sympy.Pow(sympy.Abs(base), rational)
    return sympy.sign(base) * magnitude if power.numerator % 2 else magnitude


# --------------------------------------------------------------------------- helpers


def _quote(text: str, width: int = 24) -> str:
    """`'text'` for a message, shortened so a huge token cannot flood the terminal, with
    control characters escaped (U+0000 as a backslash-u escape) so none reaches the
    terminal raw."""
    if len(text) > width:
        text = text[: width - 3] + "..."
    text = "".join(ch if ch.isprintable() else f"\\u{ord(ch):04x}" for ch in text)
    return f"'{text}'"


def _show(value: Fraction) -> str:
    """A rational for a message: exact when short, its order of magnitude otherwise."""
    text = str(value)
    if len(text) <= 20:
        return text
    magnitude = abs(value)
    exponent = magnitude.numerator.bit_length() - magnitude.denominator.bit_length()
    return f"{'-' if value < 0 else ''}about 2^{exponent}"


def _too_many_digits(value: Fraction, max_digits: int) -> bool:
    """True when the numerator or denominator of `value` has more than `max_digits` digits."""
    bits = max(abs(value.numerator).bit_length(), value.denominator.bit_length())
    return (bits - 1) * _LOG10_2 > max_digits * 100_000


def _constant_digits_error(
    what: str, limits: Limits, source: Source | None, start: int, length: int
) -> LimitError:
    return LimitError(
        f"too complex: {what} exceeds the limit of {limits.max_constant_digits} digits "
        f"(--max-constant-digits)",
        source,
        start,
        length,
    )


def _literal_value(text: str, source: Source | None, start: int, limits: Limits) -> Fraction:
    """The exact value of a number literal, range-checked before any big integer is made."""
    match = _NUMBER_PARTS_RE.fullmatch(text)
    assert match is not None  # the tokenizer only produces well-formed literals
    int_part, frac_part = match.group(1), match.group(2) or ""
    exp_text = match.group(3) or "0"
    digits = (int_part + frac_part).lstrip("0")
    if not digits:
        return Fraction(0)
    significant = digits.rstrip("0")
    bound = limits.max_literal_exponent
    # |exponent| >= 10^9 is far outside any range: clamp it rather than build a huge int.
    exp_digits = exp_text.lstrip("+-").lstrip("0") or "0"
    if len(exp_digits) <= 9:
        exponent = int(exp_text)
    else:
        exponent = -(10**10) if exp_text.startswith("-") else 10**10
    # value = significant * 10^scale; top = floor(log10(value))
    scale = exponent - len(frac_part) + len(digits) - len(significant)
    top = len(significant) - 1 + scale
    if top > bound or (top == bound and significant != "1"):
        raise LimitError(
            f"too complex: number {_quote(text)} exceeds the limit of 1e{bound} "
            f"(--max-literal-exponent)",
            source,
            start,
            len(text),
        )
    if top < -bound:
        raise LimitError(
            f"too complex: nonzero number {_quote(text)} is below the limit of 1e-{bound} "
            f"(--max-literal-exponent)",
            source,
            start,
            len(text),
        )
    if len(significant) > limits.max_constant_digits:
        raise _constant_digits_error(f"number {_quote(text)}", limits, source, start, len(text))
    if scale >= 0:
        return Fraction(int(significant) * 10**scale)
    return Fraction(int(significant), 10**-scale)


def _param_values(
    params: Mapping[str, sympy.Expr],
) -> dict[str, tuple[sympy.Expr, Fraction | None]]:
    """Check parameter names; keep each value with its exact rational form when it has one."""
    values: dict[str, tuple[sympy.Expr, Fraction | None]] = {}
    for name, value in params.items():
        check_param_name(name)
        if isinstance(value, (int, Fraction)):
            value = sympy.Rational(value.numerator, value.denominator)
        if not isinstance(value, sympy.Expr) or not value.is_number:
            raise TypeError(f"parameter {name!r} must be a sympy number, got {value!r}")
        exact = Fraction(int(value.p), int(value.q)) if isinstance(value, sympy.Rational) else None
        values[name] = (value, exact)
    return values


# --------------------------------------------------------------------------- tokens


@dataclass(frozen=True)
class _Token:
    """One token; `bad` tokens carry the error to report when the parser reaches them."""

    kind: str  # "num", "name", "var", "op", "bad", "end"
    text: str
    start: int
    end: int
    message: str = ""

    def is_op(self, *texts: str) -> bool:
        return self.kind == "op" and self.text in texts


def _tokenize(text: str, params: Mapping[str, object]) -> list[_Token]:
    """Split `text` into tokens, ending with an `end` token.

    Scanning stops at the first unusable character, which becomes a `bad` token: the
    parser reports errors in reading order, so nothing after it can matter.
    """
    tokens: list[_Token] = []
    pos = 0
    while pos < len(text):
        ch = text[pos]
        if ch in _WHITESPACE:
            pos += 1
            continue
        if ch in _DIGITS or (ch == "." and text[pos + 1 : pos + 2] in _DIGITS):
            match = _NUMBER_RE.match(text, pos)
            assert match is not None
            end = match.end()
            if text[end : end + 1] == ".":
                end = _MALFORMED_NUMBER_RE.match(text, end).end()
                literal = text[pos:end]
                tokens.append(
                    _Token("bad", literal, pos, end, f"malformed number {_quote(literal)}")
                )
                break
            tokens.append(_Token("num", text[pos:end], pos, end))
            pos = end
            continue
        word = _WORD_RE.match(text, pos)
        if word is not None:
            name = word.group()
            if (
                name not in params
                and name not in CONSTANTS
                and name not in USER_FUNCTIONS
                and (set(name) <= set(_VARIABLES))
            ):
                # `xyz` is x*y*z: one variable token per letter, each with its own column
                tokens.extend(
                    _Token("var", letter, pos + i, pos + i + 1) for i, letter in enumerate(name)
                )
            else:
                tokens.append(_Token("name", name, pos, word.end()))
            pos = word.end()
            continue
        operator = next((op for op in _OPERATORS if text.startswith(op, pos)), None)
        if operator == "==":
            tokens.append(_Token("bad", "==", pos, pos + 2, "use a single '=' (not '==')"))
            break
        if operator is not None:
            tokens.append(_Token("op", operator, pos, pos + len(operator)))
            pos += len(operator)
            continue
        tokens.append(_Token("bad", ch, pos, pos + 1, _bad_character_message(text, pos)))
        break
    tokens.append(_Token("end", "", len(text), len(text)))
    return tokens


def _bad_character_message(text: str, pos: int) -> str:
    ch = text[pos]
    code = f"U+{ord(ch):04X}"
    if ch.isascii():
        if not ch.isprintable():
            return f"unexpected control character {code}"
        shown = f'"{ch}"' if ch == "'" else f"'{ch}'"
        if ch == "|":  # |x|, as printed
            end = text.find("|", pos + 1)
            if end < 0 or "\n" in text[pos:end]:
                return f"unexpected character {shown}; use abs(...) for an absolute value"
            return f"unexpected character {shown}; did you mean " \
                   f"{_quote(f'abs({text[pos + 1:end]})', 40)}?"
        return f"unexpected character {shown}"
    if ch == "\ufeff":  # text saved by Notepad as "UTF-8 with BOM"
        return f"unexpected character {code} (a byte order mark); delete it"
    if not ch.isprintable() or ch.isspace():
        hint = "; use a plain space" if ch.isspace() else ""
        return f"unexpected character {code}{hint}"
    if unicodedata.category(ch).startswith("M"):  # shown alone it would sit on the quote
        return f"unexpected combining character {code}"
    meant = _LOOKALIKES.get(ch) or _compatible_ascii(text, pos)
    hint = f"; did you mean {_quote(meant)}?" if meant else ""
    return f"unexpected character '{ch}' ({code}){hint}"


def _compatible_ascii(text: str, pos: int) -> str:
    """The ASCII that the run of characters at `pos` stands for, by Unicode's
    compatibility mapping: full-width `ｓｉｎ` (an input method left in full-width mode) is
    `sin`, the mathematical italic `𝑥` is `x`. '' when the character has none."""
    end = pos
    while end < len(text) and end - pos < 24 and not text[end].isascii():
        meant = unicodedata.normalize("NFKC", text[end])
        if text[end] in _LOOKALIKES or not (meant.isascii() and meant.isprintable()
                                            and meant.strip()):
            break
        end += 1
    return unicodedata.normalize("NFKC", text[pos:end])


# --------------------------------------------------------------------------- AST


@dataclass(eq=False)
class _Node:
    """An AST node covering `text[start:end]` (brackets included)."""

    start: int
    end: int


@dataclass(eq=False)
class _Num(_Node):
    value: Fraction


@dataclass(eq=False)
class _Var(_Node):
    name: str


@dataclass(eq=False)
class _Named(_Node):
    """A constant (`pi`, `e`) or a parameter."""

    name: str
    is_param: bool


@dataclass(eq=False)
class _Neg(_Node):
    operand: _Node


@dataclass(eq=False)
class _Sum(_Node):
    terms: list[_Node]
    negative: list[bool]


@dataclass(eq=False)
class _Product(_Node):
    factors: list[_Node]
    divide: list[bool]


@dataclass(eq=False)
class _Power(_Node):
    base: _Node
    exponent: _Node


@dataclass(eq=False)
class _Call(_Node):
    name: str
    args: list[_Node] = field(default_factory=list)


def _children(node: _Node) -> list[_Node]:
    if isinstance(node, _Sum):
        return node.terms
    if isinstance(node, _Product):
        return node.factors
    if isinstance(node, _Neg):
        return [node.operand]
    if isinstance(node, _Power):
        return [node.base, node.exponent]
    if isinstance(node, _Call):
        return node.args
    return []


def _postorder(root: _Node) -> list[_Node]:
    """Children before parents, left subtrees first; iterative, so depth cannot overflow."""
    order: list[_Node] = []
    stack = [root]
    while stack:
        node = stack.pop()
        order.append(node)
        stack.extend(_children(node))
    order.reverse()
    return order


# --------------------------------------------------------------------------- parser


class _Parser:
    """Pratt parser over the token list.

    Each nesting level (bracket, call, sign, operator operand) costs two or three Python
    frames, so `max_depth` keeps recursion well inside the interpreter's limit.
    """

    def __init__(
        self,
        source: Source,
        tokens: list[_Token],
        params: Mapping[str, object],
        limits: Limits,
        constant: bool = False,
    ):
        self.source = source
        self.tokens = tokens
        self.params = params
        self.limits = limits
        self.constant = constant  # a parameter's value (parse_constant), not an equation
        self.pos = 0
        self.prev: _Token | None = None
        self.depth = 0
        self.nodes = 0
        self.seen_equals = False
        self.contexts: list[str] = []  # "call" or "group", innermost last

    # -- token access

    def peek(self) -> _Token:
        return self.tokens[self.pos]

    def advance(self) -> _Token:
        token = self.tokens[self.pos]
        if token.kind != "end":
            self.pos += 1
        self.prev = token
        return token

    def error(self, message: str, start: int, end: int) -> InputError:
        return InputError(message, self.source, start, end - start)

    def error_at(self, message: str, token: _Token) -> InputError:
        return InputError(message, self.source, token.start, max(1, token.end - token.start))

    def new(self, node: _Node) -> _Node:
        self.nodes += 1
        if self.nodes > self.limits.max_nodes:
            raise LimitError(
                f"too complex: expression size exceeds the limit of {self.limits.max_nodes} "
                f"nodes (--max-nodes)",
                self.source,
                node.start,
                node.end - node.start,
            )
        return node

    # -- grammar

    def parse(self) -> _Node:
        """equation := expression ['=' expression]; returns the node of lhs - rhs."""
        lhs = self.expression(0)
        token = self.peek()
        if not token.is_op("="):
            self.expect_end(token)
            return lhs
        if self.constant:
            raise self.error_at("a value has no '='", token)
        equals = self.advance()
        self.seen_equals = True
        if self.peek().kind == "end":
            raise self.error_at("missing right-hand side after '='", equals)
        rhs = self.expression(0)
        token = self.peek()
        if token.is_op("="):
            raise self.error_at("only one '=' is allowed", token)
        self.expect_end(token)
        return self.new(_Sum(lhs.start, rhs.end, [lhs, rhs], [False, True]))

    def expect_end(self, token: _Token) -> None:
        if token.kind == "end":
            return
        if token.is_op(")", "]"):
            raise self.error_at(f"unmatched '{token.text}'", token)
        if token.is_op(","):
            raise self.error_at("',' is only allowed between function arguments", token)
        raise self.error_at(f"unexpected {_quote(token.text)}", token)  # pragma: no cover

    def expression(self, min_bp: int) -> _Node:
        """Parse operators binding tighter than `min_bp` (Pratt loop)."""
        self.depth += 1
        if self.depth > self.limits.max_depth:
            raise LimitError(
                f"too complex: nesting depth exceeds the limit of {self.limits.max_depth} "
                f"(--max-depth)",
                self.source,
                self.peek().start,
                max(1, self.peek().end - self.peek().start),
            )
        left = self.prefix()
        while True:
            token = self.peek()
            if token.kind == "op" and token.text in _INFIX_BP:
                left_bp, right_bp = _INFIX_BP[token.text]
                if left_bp < min_bp:
                    break
                self.advance()
                right = self.expression(right_bp)
                if token.text in ("^", "**"):
                    left = self.new(_Power(left.start, right.end, left, right))
                else:
                    left = self.combine(token.text, left, right)
            elif token.kind in ("name", "var") or token.is_op("(", "["):
                if _IMPLICIT_BP[0] < min_bp:
                    break
                right = self.expression(_IMPLICIT_BP[1])
                left = self.combine("*", left, right)
            elif token.kind == "num":
                raise self.error_at(f"missing operator before {_quote(token.text)}", token)
            elif token.kind == "bad":
                raise self.error_at(token.message, token)
            else:  # ) ] , = end: the caller decides
                break
        self.depth -= 1
        return left

    def combine(self, op: str, left: _Node, right: _Node) -> _Node:
        """Append to a left-hand sum or product (flat n-ary nodes keep the tree shallow)."""
        if op in ("+", "-"):
            if isinstance(left, _Sum):
                left.terms.append(right)
                left.negative.append(op == "-")
                left.end = right.end
                return left
            return self.new(_Sum(left.start, right.end, [left, right], [False, op == "-"]))
        if isinstance(left, _Product):
            left.factors.append(right)
            left.divide.append(op == "/")
            left.end = right.end
            return left
        return self.new(_Product(left.start, right.end, [left, right], [False, op == "/"]))

    def prefix(self) -> _Node:
        """An operand: number, name, call, bracketed group or signed operand."""
        token = self.peek()
        if token.kind == "num":
            self.advance()
            value = _literal_value(token.text, self.source, token.start, self.limits)
            return self.new(_Num(token.start, token.end, value))
        if token.kind == "var":
            self.advance()
            return self.new(_Var(token.start, token.end, token.text))
        if token.kind == "name":
            self.advance()
            return self.name(token)
        if token.kind == "bad":
            raise self.error_at(token.message, token)
        if token.is_op("(", "["):
            self.advance()
            return self.group(token)
        if token.is_op("-", "+"):
            self.advance()
            operand = self.expression(_PREFIX_BP)
            if token.text == "+":
                operand.start = token.start
                return operand
            return self.new(_Neg(token.start, operand.end, operand))
        raise self.missing_operand(token)

    def missing_operand(self, token: _Token) -> InputError:
        """The error for `token` standing where an operand should be."""
        prev = self.prev
        if token.is_op("*", "/", "^", "**"):
            return self.error_at(f"missing operand before '{token.text}'", token)
        if token.is_op("="):
            if self.seen_equals:
                return self.error_at("only one '=' is allowed", token)
            if prev is None:
                return self.error_at("missing left-hand side before '='", token)
        if token.is_op(","):
            if self.contexts and self.contexts[-1] == "call":
                return self.error_at("missing argument before ','", token)
            return self.error_at("',' is only allowed between function arguments", token)
        if prev is None:  # a closing bracket first
            return self.error_at(f"unmatched '{token.text}'", token)
        if prev.is_op("(", "["):
            if token.is_op(")", "]"):
                return self.error("empty brackets", prev.start, token.end)
            before = " before '='" if token.is_op("=") else ""
            return self.error_at(f"unclosed '{prev.text}'{before}", prev)
        if prev.is_op("^", "**"):
            return self.error_at(f"missing exponent after '{prev.text}'", prev)
        if prev.is_op("="):
            return self.error_at("missing right-hand side after '='", prev)
        if prev.is_op(","):
            return self.error_at("missing argument after ','", prev)
        return self.error_at(f"missing operand after '{prev.text}'", prev)

    def group(self, opening: _Token) -> _Node:
        self.contexts.append("group")
        inner = self.expression(0)
        closing = self.closing(opening)
        self.contexts.pop()
        inner.start, inner.end = opening.start, closing.end
        return inner

    def closing(self, opening: _Token) -> _Token:
        """Consume the bracket that closes `opening`, or explain why it is missing."""
        token = self.peek()
        if token.is_op(_CLOSING[opening.text]):
            return self.advance()
        if token.is_op(")", "]"):
            raise self.error_at(f"'{token.text}' does not match '{opening.text}'", token)
        if token.is_op("="):
            raise self.error_at(f"unclosed '{opening.text}' before '='", opening)
        if token.is_op(","):
            raise self.error_at("',' is only allowed between function arguments", token)
        raise self.error_at(f"unclosed '{opening.text}'", opening)

    def name(self, token: _Token) -> _Node:
        word = token.text
        if word in self.params or word in CONSTANTS:
            return self.new(_Named(token.start, token.end, word, word in self.params))
        if word in _CONSTANT_ALIASES:
            return self.new(_Named(token.start, token.end, _CONSTANT_ALIASES[word], False))
        followed_by_call = self.peek().is_op("(")
        if word in USER_FUNCTIONS:
            if followed_by_call:
                return self.call(token)
            if self.peek().kind == "bad":  # `sin（x）`: the look-alike bracket is the problem
                raise self.error_at(self.peek().message, self.peek())
            raise self.power_of_function(token)
        if followed_by_call:
            raise self.error_at(_unknown_name_message(word, True, self.params), token)
        raise self.unknown_names(token)

    def power_of_function(self, name: _Token) -> InputError:
        """`sin x` needs brackets; `sin^2(x)` and `tan^-1(x)`, as printed in books, get
        the spelling implc reads: `sin(x)^2`, `atan(x)`."""
        message = f"function '{name.text}' needs arguments in parentheses"
        tokens, at = self.tokens, self.pos
        if not tokens[at].is_op("^", "**"):
            return self.error_at(message, name)
        at += 1
        sign = "-" if tokens[at].is_op("-") else ""
        at += bool(sign)
        power, opening = tokens[at], tokens[at + 1] if tokens[at].kind == "num" else None
        if power.kind != "num" or opening is None or not opening.is_op("(", "["):
            return self.error_at(f"{message}; write {name.text}(...)^n for a power of it",
                                 name)
        closing = _matching(tokens, at + 1)
        if closing is None:
            return self.error_at(message, name)
        args = self.source.text[opening.start + 1 : closing.start]
        written = f"{name.text}({args})^{sign}{power.text}"
        inverse = "a" + name.text
        if sign and power.text == "1" and inverse in USER_FUNCTIONS:
            hint = f"did you mean {_quote(f'{inverse}({args})', 40)} (or {_quote(written, 40)})?"
        else:
            hint = f"did you mean {_quote(written, 40)}?"
        return self.error(f"{message}; {hint}", name.start, closing.end)

    def unknown_names(self, first: _Token) -> InputError:
        """Every unknown name of the equation at once, each use marked, with how to give
        them values: a paper's torus has R and r, and one error per run is slow going.
        Names with a likely intended spelling (`Y`, `x2`) get their hint instead."""
        uses: dict[str, list[_Token]] = {}
        for index in range(self.pos - 1, len(self.tokens) - 1):
            token = self.tokens[index]
            if (token.kind == "name" and not self.tokens[index + 1].is_op("(")
                    and token.text not in self.params and token.text not in CONSTANTS
                    and token.text not in _CONSTANT_ALIASES
                    and token.text not in USER_FUNCTIONS):
                uses.setdefault(token.text, []).append(token)
        names = list(uses)[:_MAX_NAMES_SHOWN]
        hints = {name: _unknown_name_hint(name, False, self.params) for name in names}
        free = [name for name in names if not hints[name] and len(_quote(name)) == len(name) + 2
                and name.lower() not in ("nan", "inf", "infinity")]
        if len(uses) == 1:
            hint = hints[first.text]
            message = f"unknown name {_quote(first.text)}" + (f"; {hint}" if hint else "")
        else:
            shown = [_quote(name) + (f" ({hints[name]})" if hints[name] else "")
                     for name in names]
            if len(uses) > len(names):
                shown.append(f"{len(uses) - len(names)} more")
            message = f"unknown names {', '.join(shown[:-1])} and {shown[-1]}"
        help_text = None
        if self.constant:
            help_text = ("a parameter's value is a number or a constant expression, like "
                         "(1 + sqrt(5))/2")
        elif free:
            given = " ".join(f"--param {name}=VALUE" for name in free)
            help_text = (f"give {'its value' if len(free) == 1 else 'their values'} with "
                         f"{given} (in a surface file: under [params])")
        also = tuple((t.start, t.end - t.start) for name in names for t in uses[name]
                     if t is not first)[:_MAX_MARKS]
        return InputError(message, self.source, first.start, first.end - first.start,
                          also=also, help=help_text)

    def call(self, name: _Token) -> _Node:
        opening = self.advance()
        self.contexts.append("call")
        args: list[_Node] = []
        if self.peek().is_op(")", "]"):
            closing = self.closing(opening)
        else:
            while True:
                args.append(self.expression(0))
                if self.peek().is_op(","):
                    self.advance()
                    continue
                closing = self.closing(opening)
                break
        self.contexts.pop()
        function = USER_FUNCTIONS[name.text]
        arity = function.arity
        if len(args) != arity and not (function.variadic and len(args) > arity):
            noun = "argument" if arity == 1 else "arguments"
            more = " or more" if function.variadic else ""
            raise self.error(
                f"{name.text} takes {arity}{more} {noun}, got {len(args)}", name.start,
                closing.end,
            )
        return self.new(_Call(name.start, closing.end, name.text, args))


def _unknown_name_message(word: str, followed_by_call: bool, params: Mapping[str, object]) -> str:
    """`unknown name 'foo'` plus a hint when a likely intended spelling is cheap to find."""
    message = f"unknown {'function' if followed_by_call else 'name'} {_quote(word)}"
    hint = _unknown_name_hint(word, followed_by_call, params)
    return f"{message}; {hint}" if hint else message


def _unknown_name_hint(word: str, followed_by_call: bool, params: Mapping[str, object]) -> str:
    """A likely intended spelling of an unknown name (`did you mean ...?`), or ''."""
    if followed_by_call:
        lower = word.lower()
        if lower in USER_FUNCTIONS:
            return f"did you mean '{lower}'?"
        if lower in _FUNCTION_ALIASES and _FUNCTION_ALIASES[lower] in USER_FUNCTIONS:
            return f"did you mean '{_FUNCTION_ALIASES[lower]}'?"
        if lower in _POWER_FUNCTIONS:
            return "use '^' for powers"
        close = difflib.get_close_matches(word, sorted(USER_FUNCTIONS), n=1)
        return f"did you mean '{close[0]}'?" if close else ""
    if len(word) > 32:  # the hints below cost O(len(word)^2)
        return ""
    known = [*_VARIABLES, *params, *CONSTANTS]
    lower = word.lower()
    if lower in known or lower in USER_FUNCTIONS:
        return f"did you mean '{lower}'?"
    digits = re.fullmatch(r"([xyz]+)([0-9]+)", word)
    if digits:
        return f"did you mean '{digits.group(1)}^{digits.group(2)}'?"
    for cut in range(1, len(word)):
        head, tail = word[:cut], word[cut:]
        if set(tail) <= set(_VARIABLES):
            if head in USER_FUNCTIONS:
                return f"did you mean '{head}({tail})'?"
            if head in params or head in CONSTANTS:
                return f"did you mean '{head}*{tail}'?"
        if set(head) <= set(_VARIABLES) and (tail in params or tail in CONSTANTS):
            return f"did you mean '{head}*{tail}'?"
    close = difflib.get_close_matches(word, sorted(params), n=1)
    return f"did you mean '{close[0]}'?" if close else ""


def _matching(tokens: list[_Token], at: int) -> _Token | None:
    """The token closing the bracket `tokens[at]` (either kind), or None."""
    depth = 0
    for token in tokens[at:]:
        if token.is_op("(", "["):
            depth += 1
        elif token.is_op(")", "]"):
            depth -= 1
            if depth == 0:
                return token
    return None


# --------------------------------------------------------------------------- analysis


@dataclass(frozen=True)
class _Info:
    """What the limit checks know about a node before any sympy object exists."""

    constant: bool  # does not depend on x, y, z
    value: Fraction | None  # its exact value, when it is a rational constant
    degree: int  # estimated total degree in x, y, z (opaque parts count 1)
    terms: int  # estimated monomials after expansion, capped at max_terms + 1
    polynomial: bool  # a polynomial in x, y, z with rational coefficients
    size: int  # estimated sympy tree size (the real-root rule copies its base)


@cache
def _argument_copies(name: str) -> tuple[int, ...]:
    """How many times a table function's sympy form repeats each argument (cbrt: twice)."""
    function = USER_FUNCTIONS[name]
    dummies = [sympy.Dummy(real=True) for _ in range(function.arity)]
    built = function.build(*dummies)
    return tuple(max(1, built.count(d)) for d in dummies)


class _Analyzer:
    """Bottom-up limit checks and exact folding of rational constants."""

    def __init__(
        self,
        source: Source,
        params: Mapping[str, tuple[sympy.Expr, Fraction | None]],
        limits: Limits,
    ):
        self.source = source
        self.params = params
        self.limits = limits

    def analyze(self, root: _Node) -> dict[_Node, _Info]:
        info: dict[_Node, _Info] = {}
        radicals: dict[_Node, tuple[int, int]] = {}
        for node in _postorder(root):
            result = self.visit(node, info)
            self.check_growth(node, result)
            info[node] = result
            radicals[node] = self.check_radicals(node, info, radicals)
        return info

    def check_radicals(
        self,
        node: _Node,
        info: Mapping[_Node, _Info],
        radicals: Mapping[_Node, tuple[int, int]],
    ) -> tuple[int, int]:
        """(root, digits) of `node`: the root degree under which sympy may combine
        rational constants in it (`(4/10^21)^(1/10^4)`, `(2^(1/64))^(1/64)`,
        `sqrt(r^(1/q))`, `(2x)^(1/q)` = 2^(1/q) |x|^(1/q)), and the most digits of a
        rational constant that would take part.

        sympy evaluates a rational to a rational power by factoring and builds integers
        of about root x digits decimal digits: 10^4 x 22 hangs or fails (Python refuses to
        print integers over 4300 digits; found by tests/test_fuzz.py). So root x digits
        is bounded by ten times `max_constant_digits`. Only products, powers and roots
        combine; a sum, or a function other than sqrt and cbrt, keeps its parts apart.
        """
        parts = [radicals[c] for c in _children(node)]
        value = info[node].value
        if value is not None:
            if value in (0, 1, -1):
                return 1, 0
            bits = max(abs(value.numerator).bit_length(), value.denominator.bit_length())
            return 1, bits * _LOG10_2 // 100_000 + 1
        if isinstance(node, _Neg) or (isinstance(node, _Call) and node.name == "abs"):
            return parts[0]  # |9e28 y| is 9e28 |y| to sympy
        if isinstance(node, _Product):
            root, digits = 1, 0
            for r, d in parts:
                root, digits = min(math.lcm(root, r), _RADICAL_CAP), max(digits, d)
        elif isinstance(node, _Power):  # the exponent's own radicals were checked at its nodes
            root, digits = radicals[node.base]
            power = info[node.exponent].value
            if digits and power is not None and power.denominator != 1:
                root = min(root * power.denominator, _RADICAL_CAP)
        elif isinstance(node, _Call) and node.name in _ROOT_FUNCTIONS:
            root, digits = parts[0]
            if digits:
                root = min(root * _ROOT_FUNCTIONS[node.name], _RADICAL_CAP)
        else:  # atoms, sums and other calls: nothing combines across them
            return 1, 0
        if root > 1 and digits and root * digits > 10 * self.limits.max_constant_digits:
            raise _constant_digits_error(
                "root of a constant", self.limits, self.source, node.start, node.end - node.start
            )
        return root, digits

    def fail(self, message: str, node: _Node) -> InputError:
        return InputError(message, self.source, node.start, node.end - node.start)

    def limit(self, message: str, node: _Node) -> LimitError:
        return LimitError(f"too complex: {message}", self.source, node.start, node.end - node.start)

    def check_growth(self, node: _Node, info: _Info) -> None:
        limits = self.limits
        if info.size > limits.max_nodes:
            raise self.limit(
                f"expression size exceeds the limit of {limits.max_nodes} nodes (--max-nodes)",
                node,
            )
        if info.degree > limits.max_degree:
            raise self.limit(
                f"degree {info.degree} exceeds the limit of {limits.max_degree} (--max-degree)",
                node,
            )
        if info.terms > limits.max_terms:
            raise self.limit(
                f"expansion would exceed the limit of {limits.max_terms} terms (--max-terms)",
                node,
            )

    def checked_value(self, value: Fraction, node: _Node) -> Fraction:
        if _too_many_digits(value, self.limits.max_constant_digits):
            raise _constant_digits_error(
                "constant value", self.limits, self.source, node.start, node.end - node.start
            )
        return value

    def cap_terms(self, terms: int, degree: int, polynomial: bool) -> int:
        """Cap a term estimate: at max_terms + 1, and for a polynomial in x, y, z at the
        number of monomials of its degree, C(degree + 3, 3)."""
        if polynomial:
            terms = min(terms, math.comb(degree + 3, 3))
        return min(terms, self.limits.max_terms + 1)

    def visit(self, node: _Node, info: Mapping[_Node, _Info]) -> _Info:
        if isinstance(node, _Num):
            return _Info(True, node.value, 0, 1, True, 1)
        if isinstance(node, _Var):
            return _Info(False, None, 1, 1, True, 1)
        if isinstance(node, _Named):
            exact = self.params[node.name][1] if node.is_param else None
            return _Info(True, exact, 0, 1, exact is not None, 1)
        if isinstance(node, _Neg):
            inner = info[node.operand]
            value = None if inner.value is None else -inner.value
            return _Info(
                inner.constant, value, inner.degree, inner.terms, inner.polynomial, inner.size + 1
            )
        if isinstance(node, _Sum):
            return self.visit_sum(node, [info[t] for t in node.terms])
        if isinstance(node, _Product):
            return self.visit_product(node, [info[f] for f in node.factors])
        if isinstance(node, _Power):
            return self.visit_power(node, info[node.base], info[node.exponent])
        if isinstance(node, _Call):
            return self.visit_call(node, [info[a] for a in node.args])
        raise AssertionError(f"unknown node {node!r}")  # pragma: no cover

    def visit_sum(self, node: _Sum, parts: list[_Info]) -> _Info:
        value: Fraction | None = Fraction(0)
        for part, negative in zip(parts, node.negative, strict=True):
            if value is None or part.value is None:
                value = None
                continue
            value = self.checked_value(value - part.value if negative else value + part.value, node)
        degree = max(p.degree for p in parts)
        polynomial = all(p.polynomial for p in parts)
        terms = self.cap_terms(sum(p.terms for p in parts), degree, polynomial)
        return _Info(
            all(p.constant for p in parts),
            value,
            degree,
            terms,
            polynomial,
            1 + sum(p.size for p in parts),
        )

    def visit_product(self, node: _Product, parts: list[_Info]) -> _Info:
        value: Fraction | None = Fraction(1)
        terms = 1
        for factor, part, divide in zip(node.factors, parts, node.divide, strict=True):
            if divide and part.value == 0:
                raise self.fail("division by zero", factor)
            terms = min(terms * part.terms, self.limits.max_terms + 1)
            if value is None or part.value is None:
                value = None
                continue
            value = self.checked_value(value / part.value if divide else value * part.value, node)
        degree = sum(p.degree for p in parts)
        polynomial = all(
            p.polynomial and (not divide or p.constant)
            for p, divide in zip(parts, node.divide, strict=True)
        )
        return _Info(
            all(p.constant for p in parts),
            value,
            degree,
            self.cap_terms(terms, degree, polynomial),
            polynomial,
            1 + sum(p.size for p in parts),
        )

    def visit_power(self, node: _Power, base: _Info, exponent: _Info) -> _Info:
        size = 1 + base.size + exponent.size
        negative_base = base.value is not None and base.value < 0
        real_base_message = (
            "negative base needs an integer exponent or a fraction with an odd denominator"
        )
        if exponent.value is None:
            if not exponent.constant and not base.constant:
                raise self.fail(
                    "exponent must not depend on x, y, z when the base does", node.exponent
                )
            if negative_base:
                raise self.fail(real_base_message, node)
            constant = base.constant and exponent.constant
            return _Info(constant, None, 0 if constant else 1, 1, False, size)
        power = exponent.value
        if power.denominator % 2 == 0 and negative_base:
            raise self.fail(real_base_message, node)
        if base.value is not None:
            return self.fold_power(node, base.value, power, size)
        if abs(power) > self.limits.max_exponent:
            raise self.limit(
                f"exponent {_show(power)} exceeds the limit of {self.limits.max_exponent} "
                f"(--max-exponent)",
                node.exponent,
            )
        if power.denominator != 1:
            if power.denominator % 2:  # real root: sign(b) * |b|^(p/q) repeats b
                size = 4 + 2 * base.size + exponent.size
            constant = base.constant
            return _Info(constant, None, 0 if constant else 1, 1, False, size)
        n = abs(power.numerator)
        degree = n * base.degree
        polynomial = base.polynomial and power >= 0
        terms = self.cap_terms(
            _power_terms(base.terms, n, self.limits.max_terms), degree, polynomial
        )
        return _Info(base.constant, None, degree, terms, polynomial, size)

    def fold_power(self, node: _Power, base: Fraction, power: Fraction, size: int) -> _Info:
        """A rational constant to a rational power: bound the result's size, then fold."""
        if base not in (0, 1, -1):
            bits = max(abs(base.numerator).bit_length(), base.denominator.bit_length())
            # an integer power is computed and checked exactly below, so a lower bound on
            # log2(base) does; a root is not, so it needs the upper one (3^647.1 is 1e308:
            # it reached the printer as inf; found by tests/test_fuzz.py)
            bits -= power.denominator == 1
            digits_bound = self.limits.max_constant_digits * 100_000 * power.denominator
            if abs(power.numerator) * bits * _LOG10_2 > digits_bound:
                raise _constant_digits_error(
                    "constant power", self.limits, self.source, node.start, node.end - node.start
                )
        if power.denominator != 1:  # e.g. 2^(1/3): sympy keeps it exact
            return _Info(True, None, 0, 1, False, size)
        if base == 0 and power < 0:
            raise self.fail("division by zero", node)
        value = self.checked_value(base**power.numerator, node)
        return _Info(True, value, 0, 1, True, size)

    def visit_call(self, node: _Call, args: list[_Info]) -> _Info:
        constant = all(a.constant for a in args)
        copies = _argument_copies(node.name)
        copies += copies[-1:] * (len(args) - len(copies))  # min and max take more
        calls = max(1, len(args) - 1)  # max(a, b, c) is two calls (`_call_expr`)
        size = calls + sum(n * a.size for n, a in zip(copies, args, strict=True))
        return _Info(constant, None, 0 if constant else 1, 1, False, size)


def _approx(expr: sympy.Expr) -> sympy.Expr:
    """`expr.evalf(15)`, or the imaginary unit when sympy cannot evaluate it: it raises
    when it compares a non-real value inside min/max (`max(2, cos(2)^0.5)`, found by
    tests/test_fuzz.py), and every caller then reports "not a real number"."""
    try:
        return expr.evalf(15)
    except (TypeError, ValueError, ArithmeticError):
        return sympy.I


def _power_terms(terms: int, n: int, max_terms: int) -> int:
    """Monomials of (t terms)^n, C(t + n - 1, n), stopping as soon as it passes max_terms."""
    result = 1
    for i in range(1, n + 1):
        result = result * (terms + i - 1) // i
        if result > max_terms:
            return max_terms + 1
    return result


# --------------------------------------------------------------------------- sympy


class _Builder:
    """Build the sympy expression bottom-up from a checked AST."""

    def __init__(
        self,
        source: Source,
        params: Mapping[str, tuple[sympy.Expr, Fraction | None]],
        info: Mapping[_Node, _Info],
        limits: Limits = Limits(),  # noqa: B008 - frozen, so a shared default is safe
    ):
        self.source = source
        self.params = params
        self.info = info
        self.limits = limits
        self.analyzer = _Analyzer(source, params, limits)
        # nodes holding a rational only sympy found (abs(9e28)): the analysis' radical
        # bound did not see it, so make_power checks powers of them again
        self.late: set[_Node] = set()

    def fail(self, message: str, node: _Node) -> InputError:
        return InputError(message, self.source, node.start, node.end - node.start)

    def build(self, root: _Node, constant: bool = False) -> sympy.Expr:
        """The expression of `root`; with `constant`, of a value (no x, y, z)."""
        built: dict[_Node, sympy.Expr] = {}
        self.built = built  # every node's expression (the symbolic build reuses them)
        order = _postorder(root)
        variable = next((n for n in order if isinstance(n, _Var)), None)
        if constant and variable is not None:
            raise self.fail("a value must not depend on x, y or z", variable)
        for node in order:
            built[node] = self.make(node, built)
            info = self.info[node]
            if info.constant and info.value is None and built[node].is_Rational:
                # sympy found an exact value the analysis could not (abs(7e23), sin(0),
                # exp(2 log 3)): bound it like every other exact constant
                self.analyzer.checked_value(Fraction(built[node].p, built[node].q), node)
                self.late.add(node)
            elif any(c in self.late for c in _children(node)):
                self.late.add(node)
        self.check_constants(order, built)
        result = built[root]
        if result.has(*(atom for atom, _ in _NON_REAL_MESSAGES)):
            raise self.locate_non_real(order, built)
        self.check_numbers(order, built)
        if not constant and not result.free_symbols & {X, Y, Z}:
            raise self.fail("equation does not depend on x, y or z", root)
        return result

    def check_constants(self, order: list[_Node], built: Mapping[_Node, sympy.Expr]) -> None:
        """Every maximal constant sub-expression must be a finite real number of at most
        `max_constant_digits` digits (and within float range): printers fold each one to
        a float literal. Catches what only sympy can evaluate: `cos(-5/2)^(3/4)` is not
        real, `pi^64 * 10^290 * e^64` overflows (both found by tests/test_fuzz.py).
        Each constant sub-tree is evaluated once, at its top."""
        inside: set[_Node] = set()
        for node in order:
            if not self.info[node].constant:
                inside.update(c for c in _children(node) if self.info[c].constant)
        exponent = min(self.limits.max_constant_digits, 300)
        for node in order:
            if node not in inside or self.info[node].value is not None:
                continue
            approx = _approx(built[node])
            if approx.has(sympy.nan):
                raise self.fail("value is undefined", node)
            if approx.has(sympy.zoo, sympy.oo, -sympy.oo):
                raise self.fail("value is infinite", node)
            if approx.is_real is False or not approx.is_number:
                raise self.fail("value is not a real number", node)
            if approx.is_real and abs(approx) >= sympy.Float(10) ** exponent:
                raise _constant_digits_error(
                    "constant value", self.limits, self.source, node.start,
                    node.end - node.start,
                )

    def check_numbers(self, order: list[_Node], built: Mapping[_Node, sympy.Expr]) -> None:
        """Every constant factor sympy split off must be real too: sqrt(tan(phi) x^2) is
        sqrt(tan(phi)) |x| to sympy, and tan(phi) < 0 (found by tests/test_fuzz.py).
        Walks the finished expression once; located at the innermost node holding it."""
        stack, seen = [built[order[-1]]], set()
        while stack:
            expr = stack.pop()
            if expr in seen:
                continue
            seen.add(expr)
            if expr.is_Rational:  # (1e30 x)^11 is 10^330 x^11: a float literal would be inf
                if _too_many_digits(Fraction(expr.p, expr.q), self.limits.max_constant_digits):
                    node = next(n for n in order if built[n].has(expr))
                    raise _constant_digits_error(
                        "constant value", self.limits, self.source, node.start,
                        node.end - node.start,
                    )
                continue
            if expr.is_Atom:
                continue
            if not expr.is_number:
                stack.extend(expr.args)
                continue
            approx = _approx(expr)
            if approx.is_real is not False and not approx.has(sympy.nan, sympy.zoo, sympy.oo):
                continue
            node = next(n for n in order if built[n].has(expr))
            raise self.fail("value is not a real number", node)

    def locate_non_real(self, order: list[_Node], built: Mapping[_Node, sympy.Expr]) -> InputError:
        """The innermost node whose value is not a finite real number."""
        for node in order:
            for atom, message in _NON_REAL_MESSAGES:
                if built[node].has(atom):
                    return self.fail(message, node)
        raise AssertionError("no node holds the non-real value")  # pragma: no cover

    def make(self, node: _Node, built: Mapping[_Node, sympy.Expr]) -> sympy.Expr:
        value = self.info[node].value
        if value is not None:
            return sympy.Rational(value.numerator, value.denominator)
        if isinstance(node, _Var):
            return _VARIABLES[node.name]
        if isinstance(node, _Named):
            return self.params[node.name][0] if node.is_param else CONSTANTS[node.name]
        if isinstance(node, _Neg):
            return -built[node.operand]
        if isinstance(node, _Sum):
            return sympy.Add(
                *(
                    -built[t] if neg else built[t]
                    for t, neg in zip(node.terms, node.negative, strict=True)
                )
            )
        if isinstance(node, _Product):
            return self.make_product(node, built)
        if isinstance(node, _Power):
            return self.make_power(node, built)
        if isinstance(node, _Call):
            return self.make_call(node, built)
        raise AssertionError(f"unknown node {node!r}")  # pragma: no cover

    def make_product(self, node: _Product, built: Mapping[_Node, sympy.Expr]) -> sympy.Expr:
        factors = []
        for factor, divide in zip(node.factors, node.divide, strict=True):
            expr = built[factor]
            if divide:
                if expr == 0:
                    raise self.fail("division by zero", factor)
                expr = sympy.Pow(expr, -1)
            factors.append(expr)
        return sympy.Mul(*factors)

    def make_power(self, node: _Power, built: Mapping[_Node, sympy.Expr]) -> sympy.Expr:
        base = built[node.base]
        power = self.info[node.exponent].value
        exponent = built[node.exponent]
        if power is None and exponent.is_Rational:  # sympy evaluated it (2^abs(7e23))
            power = Fraction(exponent.p, exponent.q)
            self.check_late_power(node, base, power)
        elif power is not None and node.base in self.late:  # abs(9e28)^(4000000/3381921)
            self.check_late_power(node, base, power)
        if (power is not None and self.info[node.base].constant and not base.is_Rational
                and power.denominator == 1):  # pi^64 is fine; (1e20 pi)^64 is 10^1280 pi^64
            self.check_magnitude(node, exponent * sympy.log(sympy.Abs(base)), "constant power")
        if base == sympy.E or isinstance(base, sympy.exp):  # sympy makes it exp(...)
            inner = exponent if base == sympy.E else base.args[0] * exponent
            self.check_exp_argument(node, inner)
        if power is None and not self.info[node.base].constant:  # x^(1e26^6.1) is x^4e158
            approx = abs(_approx(exponent))
            if approx.is_real and approx > self.limits.max_exponent:
                raise self.analyzer.limit(
                    f"exponent about {float(approx):.3g} exceeds the limit of "
                    f"{self.limits.max_exponent} (--max-exponent)",
                    node.exponent,
                )
        if power is None:
            if self.info[node.base].constant and not self.info[node.exponent].constant:
                # b^x = exp(x log b): its derivatives need log b, so b must be positive
                # (`0^x` and `(1-pi)^x` reached the printer as nan; found by test_fuzz.py)
                approx = _approx(base)
                if not (approx.is_real and approx.is_positive):
                    raise self.fail("the base of a variable exponent must be positive", node)
                if base != 1 and abs(_approx(sympy.log(base))) < 1e-15:
                    # sympy cannot decide the sign of log(b) at working precision and
                    # raises while differentiating (tanh(32)^x; found by test_fuzz.py)
                    raise self.fail(
                        "the base of a variable exponent is 1 to 15 digits (write 1)", node
                    )
            if self.info[node.base].constant and self.info[node.exponent].constant:
                self.check_magnitude(
                    node, exponent * sympy.log(sympy.Abs(base)), "constant power"
                )
            return sympy.Pow(base, exponent)
        if power.denominator == 1:
            return sympy.Pow(base, sympy.Integer(power.numerator))
        exponent = sympy.Rational(power.numerator, power.denominator)
        if power.denominator % 2 == 0:
            return sympy.Pow(base, exponent)
        magnitude = sympy.Pow(sympy.Abs(base), exponent)
        return sympy.sign(base) * magnitude if power.numerator % 2 else magnitude

    def check_late_power(self, node: _Power, base: sympy.Expr, power: Fraction) -> None:
        """The limits of `_Analyzer.visit_power` for a base or exponent only sympy could
        evaluate (`x^(sin(pi) + 1000)`, `2^abs(7e23)`, `abs(9e28)^(4000000/3381921)`),
        before sympy computes the power."""
        if power.denominator != 1 and not base.is_Rational:
            # rationals inside the base combine under the root (`(abs(4e-21) x)^(1/q)`)
            roots = [a.exp.q for a in base.atoms(sympy.Pow) if a.exp.is_Rational]
            digits = max((len(str(max(abs(r.p), r.q))) for r in base.atoms(sympy.Rational)
                          if r not in (0, 1, -1)), default=0)
            if digits and power.denominator * max(roots, default=1) * digits > (
                    10 * self.limits.max_constant_digits):
                raise _constant_digits_error(
                    "root of a constant", self.limits, self.source, node.start,
                    node.end - node.start,
                )
        if base.is_Rational:
            self.analyzer.fold_power(node, Fraction(base.p, base.q), power, 0)
            if power.denominator != 1:
                bits = max(abs(base.p).bit_length(), base.q.bit_length())
                digits = bits * _LOG10_2 // 100_000 + 1
                if power.denominator * digits > 10 * self.limits.max_constant_digits:
                    raise _constant_digits_error(
                        "root of a constant", self.limits, self.source, node.start,
                        node.end - node.start,
                    )
            return
        if abs(power) > self.limits.max_exponent:
            raise self.analyzer.limit(
                f"exponent {_show(power)} exceeds the limit of {self.limits.max_exponent} "
                f"(--max-exponent)",
                node.exponent,
            )
        degree = abs(power.numerator) * self.info[node.base].degree
        if power.denominator == 1 and degree > self.limits.max_degree:
            raise self.analyzer.limit(
                f"degree {degree} exceeds the limit of {self.limits.max_degree} (--max-degree)",
                node,
            )

    def check_magnitude(self, node: _Node, log_value: sympy.Expr, what: str) -> None:
        """Refuse a constant whose natural log is `log_value` when it has more than
        `max_constant_digits` digits: sympy may compute it exactly (`e^(1e20 log 2)`
        becomes 2^(10^20)). The estimate is numeric and cheap."""
        try:
            estimate = abs(complex(_approx(log_value)))
        except (TypeError, ValueError):  # not a plain number (nan, zoo): found later
            return
        if estimate / math.log(10) > self.limits.max_constant_digits:
            raise _constant_digits_error(
                what, self.limits, self.source, node.start, node.end - node.start
            )

    def check_exp_argument(self, node: _Node, arg: sympy.Expr) -> None:
        """sympy rewrites exp(a + k log(u)) as e^a u^k on construction, for any numeric k
        (`e^(10^20 log(2x))` computed 2^(10^20) and hung; found by tests/test_fuzz.py;
        `exp(100 log(x))` would be x^100, past --max-exponent). Bound k as an exponent of
        u before sympy sees it: |k| <= max_exponent when u depends on x, y, z, and the
        magnitude of u^k when it does not."""
        for term in sympy.Add.make_args(arg):
            coeff, rest = term.as_coeff_Mul()
            logs = [f for f in sympy.Mul.make_args(rest) if isinstance(f, sympy.log)]
            others = [f for f in sympy.Mul.make_args(rest) if not isinstance(f, sympy.log)]
            if len(logs) != 1 or not all(f.is_comparable for f in others):
                continue
            k, u = coeff * sympy.Mul(*others), logs[0].args[0]
            if not u.free_symbols & {X, Y, Z}:
                self.check_magnitude(node, k * sympy.log(sympy.Abs(u)), "constant power")
                continue
            try:
                magnitude = abs(float(k))
            except (TypeError, ValueError, OverflowError):
                magnitude = math.inf
            if magnitude > self.limits.max_exponent:
                raise self.analyzer.limit(
                    f"exponent about {magnitude:.3g} (exp(k log u) is u^k) exceeds the "
                    f"limit of {self.limits.max_exponent} (--max-exponent)",
                    node,
                )

    def make_call(self, node: _Call, built: Mapping[_Node, sympy.Expr]) -> sympy.Expr:
        function = USER_FUNCTIONS[node.name]
        args = [built[a] for a in node.args]
        if node.name == "exp":
            self.check_exp_argument(node, args[0])
        if node.name in _GROWING and self.info[node.args[0]].constant:
            self.check_magnitude(node, args[0], "constant value")  # exp(k log r) is r^k
        expr = _call_expr(function, args)
        if expr.has(sympy.cot):  # tan(x + 3pi/4) is -cot(x + pi/4) to sympy; no target has cot
            expr = expr.replace(sympy.cot, lambda u: 1 / sympy.tan(u))
        if all(self.info[a].constant for a in node.args):
            # Constant arguments are bounded (every check above ran on them), so evalf is
            # cheap; it finds asin(2) or acos(pi), which sympy leaves unevaluated although
            # they are not real (found by tests/test_fuzz.py: `acos(pi) x` reached the
            # printer).
            approx = _approx(expr)
            if approx.has(sympy.nan):
                raise self.fail("value is undefined", node)
            if approx.has(sympy.zoo, sympy.oo, -sympy.oo):
                raise self.fail("value is infinite", node)
            if approx.is_real is False:
                raise self.fail("value is not a real number", node)
        return expr
