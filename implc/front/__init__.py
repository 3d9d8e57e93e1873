"""Equation text -> sympy expression, safely: the front end, one stage per module.

`tokens` (characters -> tokens, number literals, names) -> `pratt` (tokens -> syntax
tree, in `tree`) -> `analyse` (limit checks on the tree) -> `build` (tree -> sympy); this
module runs them in that order and is the public API.

This package is the only place that reads user-written equations. It never hands user text
to `eval`, `exec`, `sympify`, `parse_expr` or `Rational(str)`: a hand-written tokenizer and
Pratt parser build a small AST, every limit is checked on that AST, and only then are
sympy nodes built directly (`Add`, `Mul`, `Pow`, `Rational(p, q)`, and the constructors in
`functions.USER_FUNCTIONS`). Every problem is an `InputError` (a `LimitError` for input
that is well formed but too large) located at the offending span; no other exception
escapes for any input string.

The language (docs/reference/input-language.md "The input language"):

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
  (`build._call_expr`).

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

import re
from collections.abc import Mapping

import sympy

from implc.errors import InputError, LimitError, Source
from implc.front.analyse import Analyzer
from implc.front.build import Builder, build_symbolic, fold_constants, param_symbol
from implc.front.pratt import Parser
from implc.front.tokens import (
    WHITESPACE,
    check_param_name,
    param_values,
    parse_number,
    quote,
    tokenize,
)
from implc.limits import Limits

__all__ = ["Limits", "check_param_name", "fold_constants", "param_symbol", "parse_constant",
           "parse_equation", "parse_equation_with_params", "parse_number"]


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
    stripped = text.strip(WHITESPACE)
    lead = len(text) - len(text.lstrip(WHITESPACE))
    if not stripped:
        raise InputError("empty number", source, 0, max(1, len(text)))
    if stripped.lstrip("+-").lower() in ("nan", "inf", "infinity"):
        raise InputError(f"number must be finite, got {quote(stripped)}", source, lead,
                         len(stripped))
    if re.fullmatch(r"[+-]?0[xXoObB]\w*", stripped):  # not 0 times the name x10
        raise InputError(f"invalid number {quote(stripped)}", source, lead, len(stripped))
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
    if not text.strip(WHITESPACE):
        raise InputError("empty equation", source, 0, 1)
    values = param_values(params or {})
    try:
        tokens = tokenize(text, values)
        root = Parser(source, tokens, values, limits, constant).parse()
        info = Analyzer(source, values, limits).analyze(root)
        builder = Builder(source, values, info, limits)
        expr = builder.build(root, constant)
        if constant:
            return expr, None
        folded = fold_constants(expr)
        if not keep_params:
            return folded, None
        return folded, fold_constants(build_symbolic(root, builder.built, info))
    except RecursionError:
        raise LimitError(
            f"too complex: nesting is too deep to parse with the limit of {limits.max_depth} "
            f"(--max-depth)",
            source,
            0,
            1,
        ) from None
