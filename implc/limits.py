"""The input limits (`Limits`): plain data, without sympy, so that the command line can
show their defaults in `--help` without loading the parser (implc/front/ checks them;
each field is a `--max-...` option)."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Limits:
    """Bounds that keep parsing and every later stage fast; each has a `--max-...` option."""

    # Input length in characters, checked first, on the raw string.
    max_chars: int = 20_000
    # Nesting of brackets and operators (parser recursion depth).
    max_depth: int = 200
    # AST nodes, and the estimated size of the sympy tree built from them.
    max_nodes: int = 10_000
    # |exponent| of a power whose base is not a rational number (x^n, sin(x)^n, pi^n).
    max_exponent: int = 64
    # Estimated total degree in x, y, z after expansion (non-polynomial parts count 1).
    max_degree: int = 40
    # Estimated number of monomials after full expansion.
    max_terms: int = 200_000
    # Decimal exponent bound of number literals: 10^-N <= |literal| <= 10^N unless zero.
    # float32 shaders cannot represent values far outside this range meaningfully.
    max_literal_exponent: int = 30
    # Decimal digits of the numerator or denominator of any rational constant computed
    # exactly while parsing (literals, folded constants such as 2^100 or 9^9^9); a root
    # of rational constants, r^(p/q), needs q x digits(r) <= 10 x this.
    max_constant_digits: int = 300
    # Estimated size (tree nodes) of the derivatives a marcher needs, before CSE, and for a
    # surface with functions also 160 per node of a partial derivative
    # (derive.FUNCTION_WEIGHT); checked by implc.derive before differentiating (derivation
    # and CSE time grow with it).
    max_derived: int = 500_000
