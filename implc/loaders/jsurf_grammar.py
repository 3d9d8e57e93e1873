"""A `.jsurf` file's equation: jsurf's own grammar (`AlgebraicExpression.g`), checked.

`+ - * / ^`, parentheses, numbers, identifiers, and one-argument functions
(`sin ... sqrt abs sign`); no implicit multiplication, no `=`, unary minus only before a
power; a polynomial in x, y, z whose coefficients may use functions of constants and
parameters; an exponent of x, y, z a whole number literal; division only by constants.
Every other identifier is a parameter with its value from `surface_parameter_NAME`. That
grammar is checked here token by token (errors point into the file at `file:line:col`);
the text that passes is a subset of implc's own input language with the same meaning, so
implc's parser reads it as it stands, with every character mapped to its place in the
file. Nothing is evaluated.
"""

from __future__ import annotations

import difflib
import re
from dataclasses import dataclass

from ..errors import InputError, Source

# jsurf's one-argument functions (DoubleUnaryOperation.Op) and what implc calls them;
# None: implc has no such function.
JSURF_FUNCTIONS: dict[str, str | None] = {
    "sin": "sin", "cos": "cos", "tan": "tan", "asin": "asin", "acos": "acos",
    "atan": "atan", "exp": "exp", "log": "log", "sqrt": "sqrt", "abs": "abs",
    "sign": "sign", "ceil": None, "floor": None, "neg": None,
}


_TOKEN = re.compile(r"(?P<num>\d+\.\d*(?:[eE][+-]?\d+)?|\.\d+(?:[eE][+-]?\d+)?|\d+[eE][+-]?\d+"
                    r"|0|[1-9]\d*)|(?P<id>[A-Za-z_][A-Za-z0-9_]*)|(?P<op>[-+*/^()])"
                    r"|(?P<ws>[ \t\r\n\f]+)", re.ASCII)


@dataclass(frozen=True)
class _Tok:
    kind: str  # num, int, id, op, end
    text: str
    start: int


@dataclass(frozen=True)
class _Node:
    poly: bool  # depends on x, y, z (jsurf's PolynomialOperation, not a DoubleOperation)
    integer: bool  # a whole-number literal (jsurf's DECIMAL_LITERAL), maybe in parentheses
    start: int
    end: int


class JsurfGrammar:
    """jsurf's parser and tree walker as checks: what they refuse is an InputError here,
    located in the file; what they accept is returned untouched, with its parameters."""

    def __init__(self, source: Source):
        self.source = source
        self.tokens = self.tokenize(source.text)
        self.i = 0
        self.params: dict[str, list[int]] = {}

    def error(self, message: str, start: int, length: int = 1) -> InputError:
        return InputError(message, self.source, start, length)

    def tokenize(self, text: str) -> list[_Tok]:
        tokens, pos = [], 0
        while pos < len(text):
            m = _TOKEN.match(text, pos)
            if m is None:
                ch = text[pos]
                hint = (": a .jsurf equation is S alone (drawn where S = 0), so write "
                        "'lhs - (rhs)'" if ch == "=" else "")
                raise self.error(f"jsurf's equations have no '{ch}'{hint}", pos)
            if m.lastgroup != "ws":
                kind = m.lastgroup
                if kind == "num" and re.fullmatch(r"\d+", m.group()):
                    kind = "int"
                tokens.append(_Tok(kind, m.group(), pos))
            pos = m.end()
        tokens.append(_Tok("end", "", len(text)))
        return tokens

    def peek(self) -> _Tok:
        return self.tokens[self.i]

    def take(self) -> _Tok:
        tok = self.tokens[self.i]
        self.i += 1
        return tok

    def check(self) -> dict[str, list[int]]:
        if self.peek().kind == "end":
            raise self.error("empty equation: surface_equation=... needs a polynomial in "
                             "x, y, z", 0, max(1, len(self.source.text)))
        self.add()
        tok = self.peek()
        if tok.kind != "end":
            hint = (": jsurf has no implicit multiplication; write '*'"
                    if tok.kind in ("int", "num", "id") or tok.text == "(" else "")
            raise self.error(f"unexpected '{tok.text}'{hint}", tok.start, len(tok.text))
        return self.params

    def add(self) -> _Node:
        node = self.mult()
        while self.peek().text in ("+", "-") and self.peek().kind == "op":
            self.take()
            right = self.mult()
            node = _Node(node.poly or right.poly, False, node.start, right.end)
        return node

    def mult(self) -> _Node:
        node = self.neg()
        while self.peek().kind == "op" and self.peek().text in ("*", "/"):
            op = self.take()
            right = self.neg()
            if op.text == "/" and right.poly:
                raise self.error("jsurf divides by constants only, not by x, y, z",
                                 right.start, right.end - right.start)
            node = _Node(node.poly or right.poly, False, node.start, right.end)
        return node

    def neg(self) -> _Node:
        if self.peek().kind == "op" and self.peek().text == "-":
            minus = self.take()
            node = self.power()
            return _Node(node.poly, False, minus.start, node.end)
        return self.power()

    def power(self) -> _Node:
        base = self.unary()
        if not (self.peek().kind == "op" and self.peek().text == "^"):
            return base
        self.take()
        exponent = self.power()
        if exponent.poly:
            raise self.error("an exponent cannot contain x, y or z", exponent.start,
                             exponent.end - exponent.start)
        if base.poly and not exponent.integer:
            raise self.error("a power of x, y, z needs a whole number literal as its exponent "
                             "(jsurf's rule)", exponent.start, exponent.end - exponent.start)
        return _Node(base.poly, False, base.start, exponent.end)

    def unary(self) -> _Node:
        tok = self.peek()
        if tok.kind == "id" and self.tokens[self.i + 1].text == "(":
            self.take()
            return self.call(tok)
        return self.primary()

    def call(self, name: _Tok) -> _Node:
        if name.text not in JSURF_FUNCTIONS:
            close = difflib.get_close_matches(name.text, JSURF_FUNCTIONS, n=1)
            hint = f"; did you mean '{close[0]}'?" if close else ""
            raise self.error(f"jsurf has no function '{name.text}'{hint}", name.start,
                             len(name.text))
        if JSURF_FUNCTIONS[name.text] is None:
            raise self.error(f"implc does not support jsurf's '{name.text}'", name.start,
                             len(name.text))
        self.take()  # (
        arg = self.add()
        close_tok = self.expect_close(name)
        if arg.poly:
            raise self.error(f"jsurf applies {name.text} to constants only, not to x, y, z",
                             arg.start, arg.end - arg.start)
        return _Node(False, False, name.start, close_tok.start + 1)

    def expect_close(self, opening: _Tok) -> _Tok:
        tok = self.peek()
        if not (tok.kind == "op" and tok.text == ")"):
            raise self.error(f"expected ')' to close the '(' at column "
                             f"{self.source.locate(opening.start)[1]}, found "
                             f"{repr(tok.text) if tok.text else 'the end'}", tok.start,
                             len(tok.text) or 1)
        return self.take()

    def primary(self) -> _Node:
        tok = self.take()
        if tok.kind in ("int", "num"):
            return _Node(False, tok.kind == "int", tok.start, tok.start + len(tok.text))
        if tok.kind == "id":
            if tok.text in ("x", "y", "z"):
                return _Node(True, False, tok.start, tok.start + 1)
            self.params.setdefault(tok.text, []).append(tok.start)
            return _Node(False, False, tok.start, tok.start + len(tok.text))
        if tok.kind == "op" and tok.text == "(":
            inner = self.add()
            close = self.expect_close(tok)
            return _Node(inner.poly, inner.integer, tok.start, close.start + 1)
        found = repr(tok.text) if tok.text else "the end of the equation"
        raise self.error(f"expected a number, a name or '(', found {found}", tok.start,
                         len(tok.text) or 1)
