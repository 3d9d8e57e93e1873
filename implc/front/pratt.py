"""Tokens -> syntax tree: the Pratt parser of the equation language.

Checks nesting depth and node count while parsing, and says what was probably meant
when a name is unknown (`sin^2(x)`, `|x|`, `ln`). Builds no sympy expression.
"""

from __future__ import annotations

import difflib
import re
from collections.abc import Mapping

from implc.errors import InputError, LimitError, Source
from implc.front.tokens import CLOSING, CONSTANT_ALIASES, VARIABLES, Token, literal_value, quote
from implc.front.tree import Call, Named, Neg, Node, Num, Power, Product, Sum, Var
from implc.functions import CONSTANTS, FUNCTIONS, USER_FUNCTIONS
from implc.limits import Limits

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

# Names from other languages (the table's `aliases`), with the hint to give when they are
# called.
_FUNCTION_ALIASES: dict[str, str] = {alias: f.name for f in FUNCTIONS for alias in f.aliases}
_POWER_FUNCTIONS = ("pow", "power", "powf")
_MAX_NAMES_SHOWN = 5  # unknown names listed in one message
_MAX_MARKS = 50  # their uses marked under the echoed line


class Parser:
    """Pratt parser over the token list.

    Each nesting level (bracket, call, sign, operator operand) costs two or three Python
    frames, so `max_depth` keeps recursion well inside the interpreter's limit.
    """

    def __init__(
        self,
        source: Source,
        tokens: list[Token],
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
        self.prev: Token | None = None
        self.depth = 0
        self.nodes = 0
        self.seen_equals = False
        self.contexts: list[str] = []  # "call" or "group", innermost last

    # -- token access

    def peek(self) -> Token:
        return self.tokens[self.pos]

    def advance(self) -> Token:
        token = self.tokens[self.pos]
        if token.kind != "end":
            self.pos += 1
        self.prev = token
        return token

    def error(self, message: str, start: int, end: int) -> InputError:
        return InputError(message, self.source, start, end - start)

    def error_at(self, message: str, token: Token) -> InputError:
        return InputError(message, self.source, token.start, max(1, token.end - token.start))

    def new(self, node: Node) -> Node:
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

    def parse(self) -> Node:
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
        return self.new(Sum(lhs.start, rhs.end, [lhs, rhs], [False, True]))

    def expect_end(self, token: Token) -> None:
        if token.kind == "end":
            return
        if token.is_op(")", "]"):
            raise self.error_at(f"unmatched '{token.text}'", token)
        if token.is_op(","):
            raise self.error_at("',' is only allowed between function arguments", token)
        raise self.error_at(f"unexpected {quote(token.text)}", token)  # pragma: no cover

    def expression(self, min_bp: int) -> Node:
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
                    left = self.new(Power(left.start, right.end, left, right))
                else:
                    left = self.combine(token.text, left, right)
            elif token.kind in ("name", "var") or token.is_op("(", "["):
                if _IMPLICIT_BP[0] < min_bp:
                    break
                right = self.expression(_IMPLICIT_BP[1])
                left = self.combine("*", left, right)
            elif token.kind == "num":
                raise self.error_at(f"missing operator before {quote(token.text)}", token)
            elif token.kind == "bad":
                raise self.error_at(token.message, token)
            else:  # ) ] , = end: the caller decides
                break
        self.depth -= 1
        return left

    def combine(self, op: str, left: Node, right: Node) -> Node:
        """Append to a left-hand sum or product (flat n-ary nodes keep the tree shallow)."""
        if op in ("+", "-"):
            if isinstance(left, Sum):
                left.terms.append(right)
                left.negative.append(op == "-")
                left.end = right.end
                return left
            return self.new(Sum(left.start, right.end, [left, right], [False, op == "-"]))
        if isinstance(left, Product):
            left.factors.append(right)
            left.divide.append(op == "/")
            left.end = right.end
            return left
        return self.new(Product(left.start, right.end, [left, right], [False, op == "/"]))

    def prefix(self) -> Node:
        """An operand: number, name, call, bracketed group or signed operand."""
        token = self.peek()
        if token.kind == "num":
            self.advance()
            value = literal_value(token.text, self.source, token.start, self.limits)
            return self.new(Num(token.start, token.end, value))
        if token.kind == "var":
            self.advance()
            return self.new(Var(token.start, token.end, token.text))
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
            return self.new(Neg(token.start, operand.end, operand))
        raise self.missing_operand(token)

    def missing_operand(self, token: Token) -> InputError:
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

    def group(self, opening: Token) -> Node:
        self.contexts.append("group")
        inner = self.expression(0)
        closing = self.closing(opening)
        self.contexts.pop()
        inner.start, inner.end = opening.start, closing.end
        return inner

    def closing(self, opening: Token) -> Token:
        """Consume the bracket that closes `opening`, or explain why it is missing."""
        token = self.peek()
        if token.is_op(CLOSING[opening.text]):
            return self.advance()
        if token.is_op(")", "]"):
            raise self.error_at(f"'{token.text}' does not match '{opening.text}'", token)
        if token.is_op("="):
            raise self.error_at(f"unclosed '{opening.text}' before '='", opening)
        if token.is_op(","):
            raise self.error_at("',' is only allowed between function arguments", token)
        raise self.error_at(f"unclosed '{opening.text}'", opening)

    def name(self, token: Token) -> Node:
        word = token.text
        if word in self.params or word in CONSTANTS:
            return self.new(Named(token.start, token.end, word, word in self.params))
        if word in CONSTANT_ALIASES:
            return self.new(Named(token.start, token.end, CONSTANT_ALIASES[word], False))
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

    def power_of_function(self, name: Token) -> InputError:
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
            hint = f"did you mean {quote(f'{inverse}({args})', 40)} (or {quote(written, 40)})?"
        else:
            hint = f"did you mean {quote(written, 40)}?"
        return self.error(f"{message}; {hint}", name.start, closing.end)

    def unknown_names(self, first: Token) -> InputError:
        """Every unknown name of the equation at once, each use marked, with how to give
        them values: a paper's torus has R and r, and one error per run is slow going.
        Names with a likely intended spelling (`Y`, `x2`) get their hint instead."""
        uses: dict[str, list[Token]] = {}
        for index in range(self.pos - 1, len(self.tokens) - 1):
            token = self.tokens[index]
            if (token.kind == "name" and not self.tokens[index + 1].is_op("(")
                    and token.text not in self.params and token.text not in CONSTANTS
                    and token.text not in CONSTANT_ALIASES
                    and token.text not in USER_FUNCTIONS):
                uses.setdefault(token.text, []).append(token)
        names = list(uses)[:_MAX_NAMES_SHOWN]
        hints = {name: _unknown_name_hint(name, False, self.params) for name in names}
        free = [name for name in names if not hints[name] and len(quote(name)) == len(name) + 2
                and name.lower() not in ("nan", "inf", "infinity")]
        if len(uses) == 1:
            hint = hints[first.text]
            message = f"unknown name {quote(first.text)}" + (f"; {hint}" if hint else "")
        else:
            shown = [quote(name) + (f" ({hints[name]})" if hints[name] else "")
                     for name in names]
            if len(uses) > len(names):
                shown.append(f"{len(uses) - len(names)} more")
            message = f"unknown names {', '.join(shown[:-1])} and {shown[-1]}"
        help_text = None
        if self.constant:
            help_text = ("a parameter's value is a number or a constant expression, like "
                         "(1 + sqrt(5))/2; it cannot name another parameter (each is set on "
                         "its own: by --param, a viewer's slider, a shader's uniform)")
        elif free:
            given = " ".join(f"--param {name}=VALUE" for name in free)
            help_text = (f"give {'its value' if len(free) == 1 else 'their values'} with "
                         f"{given} (in a surface file: under [params])")
        also = tuple((t.start, t.end - t.start) for name in names for t in uses[name]
                     if t is not first)[:_MAX_MARKS]
        return InputError(message, self.source, first.start, first.end - first.start,
                          also=also, help=help_text)

    def call(self, name: Token) -> Node:
        opening = self.advance()
        self.contexts.append("call")
        args: list[Node] = []
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
        return self.new(Call(name.start, closing.end, name.text, args))


def _unknown_name_message(word: str, followed_by_call: bool, params: Mapping[str, object]) -> str:
    """`unknown name 'foo'` plus a hint when a likely intended spelling is cheap to find."""
    message = f"unknown {'function' if followed_by_call else 'name'} {quote(word)}"
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
    known = [*VARIABLES, *params, *CONSTANTS]
    lower = word.lower()
    if lower in known or lower in USER_FUNCTIONS:
        return f"did you mean '{lower}'?"
    digits = re.fullmatch(r"([xyz]+)([0-9]+)", word)
    if digits:
        return f"did you mean '{digits.group(1)}^{digits.group(2)}'?"
    for cut in range(1, len(word)):
        head, tail = word[:cut], word[cut:]
        if set(tail) <= set(VARIABLES):
            if head in USER_FUNCTIONS:
                return f"did you mean '{head}({tail})'?"
            if head in params or head in CONSTANTS:
                return f"did you mean '{head}*{tail}'?"
        if set(head) <= set(VARIABLES) and (tail in params or tail in CONSTANTS):
            return f"did you mean '{head}*{tail}'?"
    close = difflib.get_close_matches(word, sorted(params), n=1)
    return f"did you mean '{close[0]}'?" if close else ""


def _matching(tokens: list[Token], at: int) -> Token | None:
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
