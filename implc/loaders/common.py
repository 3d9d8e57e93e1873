"""What the surface readers share: the file size limit, the `--param` overrides and the
check that each parameter given is one the equation uses, and the "did you mean" hint.

Written once here so that the TOML reader, the `.jsurf` reader and `-e` text treat
parameters alike; this module imports neither reader.
"""

from __future__ import annotations

import difflib
import re
from collections.abc import Mapping, Sequence
from typing import Protocol

import sympy

from ..errors import InputError, Source
from ..front import check_param_name, parse_constant, parse_equation_with_params
from ..limits import Limits

MAX_FILE_BYTES = 1_000_000


class KeyErrors(Protocol):
    """What locates a key of a surface file for an error (the TOML reader's `TomlMap`)."""

    def error(self, path: tuple[str, ...], message: str) -> InputError: ...


def parse_param_args(params: Sequence[str], limits: Limits) -> dict[str, sympy.Expr]:
    """`--param NAME=VALUE`s; a value is a number or a constant expression
    (`phi=(1+sqrt(5))/2`), and its errors echo the whole argument with the caret under
    the fault."""
    values: dict[str, sympy.Expr] = {}
    for arg in params:
        source = Source("--param", arg)
        name, sep, value = arg.partition("=")
        if not sep:
            raise InputError("expected NAME=VALUE", source, 0, len(arg))
        name = name.strip()
        check_param_name(name, Source("--param", arg))
        start = len(arg) - len(value) + 1  # the value's column in the argument
        positions = tuple((1, start + i) for i in range(len(value) + 1))
        values[name] = parse_constant(Source("--param", value, 1, start, positions, (arg,)),
                                      limits)
    return values


# A number or a word, as the equation's tokenizer reads them (implc/front/tokens.py): `1e3` is a
# number, not the word `e3`; `2R` is 2 and `R`.
_NUMBER_OR_WORD = re.compile(r"(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?|([A-Za-z_][A-Za-z0-9_]*)",
                             re.ASCII)


def equation_words(equation: str) -> set[str]:
    """The names an equation's text mentions (parameters, functions, constants, words
    of x, y, z), read as its tokenizer reads them."""
    return {m.group(1) for m in _NUMBER_OR_WORD.finditer(equation) if m.group(1)}


def check_params_used(
    equation: str,
    overrides: Mapping[str, sympy.Expr],
    params_args: Sequence[str],
    where: KeyErrors | None = None,
    table: Mapping[str, object] | None = None,
) -> None:
    """Every `--param` and `[params]` entry must name a parameter the equation uses
    (after it parsed, so every word of it is a known name): a misspelled `--param q=0.6`
    would otherwise be ignored without a word. A parameter only inside a constant
    exponent (`x^n`) counts as used."""
    words = equation_words(equation)
    used = sorted(words & ({*overrides, *(table or {})}))
    its = f" (its parameters: {', '.join(used)})" if used else ", which has no parameters"
    for arg in params_args:
        name = arg.partition("=")[0].strip()
        if name in overrides and name not in words:
            close = closest_name(name, used)
            hint_text = f"; did you mean '{close}'?" if close else ""
            raise InputError(f"parameter '{name}' is not in the equation{hint_text}{its}",
                             Source("--param", arg), arg.index(name), len(name))
    for key in sorted(table or {}):
        if key not in words and where is not None:
            raise where.error(("params", key), f"[params] {key} is not in the equation"
                                               f"{its}: remove it, or use it")


def parse_with_params(
    source: Source, values: Mapping[str, sympy.Expr], limits: Limits
) -> tuple[sympy.Expr, sympy.Expr | None]:
    """(expr with the values substituted, expr with parameter symbols or None)."""
    expr, symbolic = parse_equation_with_params(source, values, limits)
    return expr, (symbolic if values else None)


def closest_name(word: str, choices: Sequence[str]) -> str | None:
    """The choice `word` is most likely a misspelling of, or None."""
    close = difflib.get_close_matches(word, list(choices), n=1, cutoff=0.6)
    if not close:
        lower = {c.lower(): c for c in choices}
        return lower.get(word.lower())
    return close[0]
