"""The syntax tree the parser builds and the limit checks and the builder walk.

Plain dataclasses, one per construct; no sympy object exists at this stage.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from fractions import Fraction


@dataclass(eq=False)
class Node:
    """An AST node covering `text[start:end]` (brackets included)."""

    start: int
    end: int


@dataclass(eq=False)
class Num(Node):
    value: Fraction


@dataclass(eq=False)
class Var(Node):
    name: str


@dataclass(eq=False)
class Named(Node):
    """A constant (`pi`, `e`) or a parameter."""

    name: str
    is_param: bool


@dataclass(eq=False)
class Neg(Node):
    operand: Node


@dataclass(eq=False)
class Sum(Node):
    terms: list[Node]
    negative: list[bool]


@dataclass(eq=False)
class Product(Node):
    factors: list[Node]
    divide: list[bool]


@dataclass(eq=False)
class Power(Node):
    base: Node
    exponent: Node


@dataclass(eq=False)
class Call(Node):
    name: str
    args: list[Node] = field(default_factory=list)


def children(node: Node) -> list[Node]:
    if isinstance(node, Sum):
        return node.terms
    if isinstance(node, Product):
        return node.factors
    if isinstance(node, Neg):
        return [node.operand]
    if isinstance(node, Power):
        return [node.base, node.exponent]
    if isinstance(node, Call):
        return node.args
    return []


def postorder(root: Node) -> list[Node]:
    """Children before parents, left subtrees first; iterative, so depth cannot overflow."""
    order: list[Node] = []
    stack = [root]
    while stack:
        node = stack.pop()
        order.append(node)
        stack.extend(children(node))
    order.reverse()
    return order
