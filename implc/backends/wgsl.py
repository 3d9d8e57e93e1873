"""WGSL target: a sympy CodePrinter with implc's shader rules, typed for f32.

sympy has no WGSL printer, so this one starts from the generic `CodePrinter` (whose
arithmetic printing is the same as the C family's) and adds only what WGSL needs:
every literal carries the `f` suffix, so no abstract-float inference is involved;
`Heaviside` prints as WGSL's `step(0.0f, x)`; names that WGSL reserves are refused in
implc instead of by naga. Functions are spelled by `known_functions` below.
"""

from __future__ import annotations

from sympy.printing.codeprinter import CodePrinter

from ..errors import ImplcError
from .printing import ShaderPrinterMixin

# WGSL keywords and reserved words (WGSL spec, "Keyword and Token Summary"). Every name
# implc writes (x y z dx dy dz, temporaries c0 h0 x_2, the marcher's functions, locals and
# constants) is checked against this set by tests/test_wgsl.py; `target` is why the
# program's locals say `look_at`.
KEYWORDS = frozenset((
    "alias", "break", "case", "const", "const_assert", "continue", "continuing", "default",
    "diagnostic", "discard", "else", "enable", "false", "fn", "for", "if", "let", "loop",
    "override", "requires", "return", "struct", "switch", "true", "var", "while",
))
RESERVED = frozenset((
    "NULL", "Self", "abstract", "active", "alignas", "alignof", "as", "asm", "asm_fragment",
    "async", "attribute", "auto", "await", "become", "binding_array", "cast", "catch", "class",
    "co_await", "co_return", "co_yield", "coherent", "column_major", "common", "compile",
    "compile_fragment", "concept", "const_cast", "consteval", "constexpr", "constinit", "crate",
    "debugger", "decltype", "delete", "demote", "demote_to_helper", "do", "dynamic_cast",
    "enum", "explicit", "export", "extends", "extern", "external", "fallthrough", "filter",
    "final", "finally", "friend", "from", "fxgroup", "get", "goto", "groupshared", "highp",
    "impl", "implements", "import", "inline", "instanceof", "interface", "layout", "lowp",
    "macro", "macro_rules", "match", "mediump", "meta", "mod", "module", "move", "mut",
    "mutable", "namespace", "new", "nil", "noexcept", "noinline", "nointerpolation",
    "noperspective", "null", "nullptr", "of", "operator", "package", "packoffset", "partition",
    "pass", "patch", "pixelfragment", "precise", "precision", "premerge", "priv", "protected",
    "pub", "public", "readonly", "ref", "regardless", "register", "reinterpret_cast", "require",
    "resource", "restrict", "self", "set", "shared", "sizeof", "smooth", "snorm", "static",
    "static_assert", "static_cast", "std", "subroutine", "super", "target", "template", "this",
    "thread_local", "throw", "trait", "try", "type", "typedef", "typeid", "typename", "typeof",
    "union", "unless", "unorm", "unsafe", "unsized", "use", "using", "varying", "virtual",
    "volatile", "wgsl", "where", "with", "writeonly", "yield",
))
RESERVED_WORDS = KEYWORDS | RESERVED

# sympy class name -> WGSL built-in, for every row of implc/functions.py that prints as a
# call (the others: the table's `printed` column).
known_functions = {
    "sin": "sin", "cos": "cos", "tan": "tan", "asin": "asin", "acos": "acos", "atan": "atan",
    "atan2": "atan2", "sinh": "sinh", "cosh": "cosh", "tanh": "tanh", "exp": "exp",
    "log": "log", "sqrt": "sqrt", "Abs": "abs", "sign": "sign", "Min": "min", "Max": "max",
    "floor": "floor",
}


class WgslPrinter(ShaderPrinterMixin, CodePrinter):
    """Expressions as WGSL f32 code: `2.0f*x*x_2 - sqrt(c0)`."""

    target = "wgsl"
    language = "WGSL"
    float_suffix = "f"
    reserved_words = RESERVED_WORDS
    _kf = known_functions

    def __init__(self) -> None:
        super().__init__({"strict": True})

    def _print_Symbol(self, expr) -> str:
        if expr.name in RESERVED_WORDS or expr.name.startswith("__"):
            raise ImplcError(f"'{expr.name}' is a reserved word in WGSL and cannot be a name")
        return expr.name

    def print_select(self, cond: str, if_true: str, if_false: str) -> str:
        """WGSL has no ?:, only select(false_value, true_value, cond) (both evaluated)."""
        return f"select({if_false}, {if_true}, {cond})"

    # CodePrinter's abstract hooks; implc prints single expressions, never statements.
    def _get_comment(self, text: str) -> str:
        return f"// {text}"

    def _get_statement(self, codestring: str) -> str:
        return f"{codestring};"

    def _declare_number_const(self, name: str, value) -> str:
        return f"const {name}: f32 = {self.float_literal(float(value))};"

    def _format_code(self, lines: list[str]) -> list[str]:
        return lines
