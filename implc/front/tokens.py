"""The lexical level of the equation language: tokens, number literals, names.

The tokenizer, the exact value of a number literal (range-checked before any big integer
is made), what a parameter may be called, and the quoting and sizing of values in
messages. Knows no grammar and builds no sympy expression but a parameter's value.
"""

from __future__ import annotations

import re
import unicodedata
from collections.abc import Mapping
from dataclasses import dataclass
from fractions import Fraction

import sympy

from implc.errors import InputError, LimitError, Source
from implc.functions import CONSTANTS, USER_FUNCTIONS
from implc.limits import Limits
from implc.symbols import X, Y, Z

WHITESPACE = " \t\n\r"
_OPERATORS = ("**", "==", "+", "-", "*", "/", "^", "=", "(", ")", "[", "]", ",")
_DIGITS = frozenset("0123456789")
_NUMBER_RE = re.compile(r"(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?", re.ASCII)
_NUMBER_PARTS_RE = re.compile(r"(\d*)(?:\.(\d*))?(?:[eE]([+-]?\d+))?", re.ASCII)
_MALFORMED_NUMBER_RE = re.compile(r"[0-9.]*")
_WORD_RE = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")
_IDENTIFIER_RE = re.compile(r"[A-Za-z_][A-Za-z0-9_]*\Z")
VARIABLES: dict[str, sympy.Symbol] = {"x": X, "y": Y, "z": Z}
CLOSING = {"(": ")", "[": "]"}

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


# Other spellings of the constants that real dialects use and that mean nothing else:
# surf and SURFER write `PI` (corpus: IMAGINARY/surfer-alggeo-gtk). Not `E`: it is a
# common parameter name. A parameter may not take an alias's name.
CONSTANT_ALIASES: dict[str, str] = {"PI": "pi"}
LOG10_2 = 30103  # log10(2) * 10^5, for exact integer comparisons of digit counts


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
    stripped = text.strip(WHITESPACE)
    lead = len(text) - len(text.lstrip(WHITESPACE))
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
            message = f"number must be finite, got {quote(stripped)}"
        else:
            message = f"invalid number {quote(stripped)}"
        raise InputError(message, source, lead, len(stripped))
    numerator = literal_value(match.group(2), source, lead + match.start(2), limits)
    if match.group(1) == "-":
        numerator = -numerator
    value = numerator
    if match.group(4) is not None:
        start = lead + match.start(4)
        denominator = literal_value(match.group(4), source, start, limits)
        if match.group(3) == "-":
            denominator = -denominator
        if denominator == 0:
            raise InputError("division by zero", source, start, len(match.group(4)))
        value = numerator / denominator
        if too_many_digits(value, limits.max_constant_digits):
            raise constant_digits_error("number", limits, source, lead, len(stripped))
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
        raise InputError(f"parameter name {quote(name)} is not an identifier", source, 0, length)
    if name in VARIABLES:
        raise InputError(f"parameter name '{name}' shadows the variable {name}", source, 0, 1)
    if set(name) <= set(VARIABLES):
        raise InputError(
            f"parameter name '{name}' would read as a product of x, y, z", source, 0, length
        )
    if name in USER_FUNCTIONS:
        raise InputError(f"parameter name '{name}' shadows the function {name}", source, 0, length)
    if name in CONSTANTS or name in CONSTANT_ALIASES:
        constant = CONSTANT_ALIASES.get(name, name)
        raise InputError(
            f"parameter name '{name}' shadows the constant {constant}", source, 0, length
        )


def quote(text: str, width: int = 24) -> str:
    """`'text'` for a message, shortened so a huge token cannot flood the terminal, with
    control characters escaped (U+0000 as a backslash-u escape) so none reaches the
    terminal raw."""
    if len(text) > width:
        text = text[: width - 3] + "..."
    text = "".join(ch if ch.isprintable() else f"\\u{ord(ch):04x}" for ch in text)
    return f"'{text}'"


def show_value(value: Fraction) -> str:
    """A rational for a message: exact when short, its order of magnitude otherwise."""
    text = str(value)
    if len(text) <= 20:
        return text
    magnitude = abs(value)
    exponent = magnitude.numerator.bit_length() - magnitude.denominator.bit_length()
    return f"{'-' if value < 0 else ''}about 2^{exponent}"


def too_many_digits(value: Fraction, max_digits: int) -> bool:
    """True when the numerator or denominator of `value` has more than `max_digits` digits."""
    bits = max(abs(value.numerator).bit_length(), value.denominator.bit_length())
    return (bits - 1) * LOG10_2 > max_digits * 100_000


def constant_digits_error(
    what: str, limits: Limits, source: Source | None, start: int, length: int
) -> LimitError:
    return LimitError(
        f"too complex: {what} exceeds the limit of {limits.max_constant_digits} digits "
        f"(--max-constant-digits)",
        source,
        start,
        length,
    )


def literal_value(text: str, source: Source | None, start: int, limits: Limits) -> Fraction:
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
            f"too complex: number {quote(text)} exceeds the limit of 1e{bound} "
            f"(--max-literal-exponent)",
            source,
            start,
            len(text),
        )
    if top < -bound:
        raise LimitError(
            f"too complex: nonzero number {quote(text)} is below the limit of 1e-{bound} "
            f"(--max-literal-exponent)",
            source,
            start,
            len(text),
        )
    if len(significant) > limits.max_constant_digits:
        raise constant_digits_error(f"number {quote(text)}", limits, source, start, len(text))
    if scale >= 0:
        return Fraction(int(significant) * 10**scale)
    return Fraction(int(significant), 10**-scale)


def param_values(
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


@dataclass(frozen=True)
class Token:
    """One token; `bad` tokens carry the error to report when the parser reaches them."""

    kind: str  # "num", "name", "var", "op", "bad", "end"
    text: str
    start: int
    end: int
    message: str = ""

    def is_op(self, *texts: str) -> bool:
        return self.kind == "op" and self.text in texts


def tokenize(text: str, params: Mapping[str, object]) -> list[Token]:
    """Split `text` into tokens, ending with an `end` token.

    Scanning stops at the first unusable character, which becomes a `bad` token: the
    parser reports errors in reading order, so nothing after it can matter.
    """
    tokens: list[Token] = []
    pos = 0
    while pos < len(text):
        ch = text[pos]
        if ch in WHITESPACE:
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
                    Token("bad", literal, pos, end, f"malformed number {quote(literal)}")
                )
                break
            tokens.append(Token("num", text[pos:end], pos, end))
            pos = end
            continue
        word = _WORD_RE.match(text, pos)
        if word is not None:
            name = word.group()
            if (
                name not in params
                and name not in CONSTANTS
                and name not in USER_FUNCTIONS
                and (set(name) <= set(VARIABLES))
            ):
                # `xyz` is x*y*z: one variable token per letter, each with its own column
                tokens.extend(
                    Token("var", letter, pos + i, pos + i + 1) for i, letter in enumerate(name)
                )
            else:
                tokens.append(Token("name", name, pos, word.end()))
            pos = word.end()
            continue
        operator = next((op for op in _OPERATORS if text.startswith(op, pos)), None)
        if operator == "==":
            tokens.append(Token("bad", "==", pos, pos + 2, "use a single '=' (not '==')"))
            break
        if operator is not None:
            tokens.append(Token("op", operator, pos, pos + len(operator)))
            pos += len(operator)
            continue
        tokens.append(Token("bad", ch, pos, pos + 1, _bad_character_message(text, pos)))
        break
    tokens.append(Token("end", "", len(text), len(text)))
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
                   f"{quote(f'abs({text[pos + 1:end]})', 40)}?"
        return f"unexpected character {shown}"
    if ch == "\ufeff":  # text saved by Notepad as "UTF-8 with BOM"
        return f"unexpected character {code} (a byte order mark); delete it"
    if not ch.isprintable() or ch.isspace():
        hint = "; use a plain space" if ch.isspace() else ""
        return f"unexpected character {code}{hint}"
    if unicodedata.category(ch).startswith("M"):  # shown alone it would sit on the quote
        return f"unexpected combining character {code}"
    meant = _LOOKALIKES.get(ch) or _compatible_ascii(text, pos)
    hint = f"; did you mean {quote(meant)}?" if meant else ""
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
