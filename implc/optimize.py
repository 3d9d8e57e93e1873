"""Turn derived expressions into a straight-line `Program` a printer can emit.

Four passes, all deterministic:
1. joint CSE of every output of one shader function (sympy `cse`, canonical order,
   temporaries named t0, t1, ... in order of definition);
2. integer powers to products: x**4 becomes `x_2 = x*x; x_4 = x_2*x_2`, shared across the
   whole function (GLSL/WGSL `pow` is undefined or rejected for negative bases);
3. sums by depth: a sum of three or more terms is added up as a tree that combines the
   two earliest-ready terms first (depth counted in operations from the inputs), so a
   term computed late is added last and the sum's dependency chain is as short as the
   terms allow;
4. op counting with one cost model, before (each output alone, powers as repeated
   multiplication) and after (the optimized program), so `implc show` can report both.

In double (`by_axis`) a pass between 2 and 3 sums each output's terms per axis and puts
every statement after its axis's powers, so that x's powers are dead before y's are made
(`_by_axis`: a register-file's worth on a GPU, where a double takes two registers).
"""

from __future__ import annotations

import heapq
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import sympy


@dataclass(frozen=True)
class Program:
    """Straight-line code: assignments in order, then output expressions."""

    inputs: tuple[sympy.Symbol, ...]
    assignments: tuple[tuple[sympy.Symbol, sympy.Expr], ...]
    outputs: tuple[sympy.Expr, ...]
    ops_before: int
    ops_after: int


def optimize(outputs: Sequence[sympy.Expr], inputs: Sequence[sympy.Symbol],
             by_axis: bool = False) -> Program:
    """Jointly CSE `outputs`, rewrite integer powers as products and count operations;
    with `by_axis`, summed and ordered axis by axis (`_by_axis`)."""
    outputs = tuple(outputs)
    inputs = tuple(inputs)
    before = sum(count_ops(o) for o in outputs)
    temps = sympy.numbered_symbols("c", real=True)
    replacements, reduced = sympy.cse(list(outputs), symbols=temps, order="canonical")
    assignments, reduced, powers = _name_powers(list(replacements), list(reduced))
    assignments, reduced = _drop_aliases(assignments, reduced)
    assignments, reduced, powers = _renumber(assignments, reduced, powers)
    assignments = _insert_power_chains(assignments, powers, inputs)
    if by_axis:
        assignments, reduced = _by_axis(assignments, reduced, inputs)
    assignments, reduced = _sums_by_depth(assignments, reduced, inputs)
    after = sum(count_ops(v) for _, v in assignments) + sum(count_ops(o) for o in reduced)
    return Program(inputs, tuple(assignments), tuple(reduced), before, after)


def _power_symbol(base: sympy.Symbol, n: int) -> sympy.Symbol:
    # a uniform's name may be a field access (WGSL `u.u_param_R`): its powers are locals
    return sympy.Symbol(f"{re.sub(r'[^A-Za-z0-9_]', '_', base.name)}_{n}", real=True)


def _name_powers(assignments, outputs):
    """Replace every b**n (integer |n| >= 2) by a symbol b_n; say which powers are needed.

    A compound base that CSE left in place (used once) is first named itself (h0, h1, ...).
    """
    needed: dict[sympy.Symbol, set[int]] = {}
    hoisted: list[tuple[sympy.Symbol, sympy.Expr]] = []
    hoist_names = sympy.numbered_symbols("h", real=True)
    hoist_of: dict[sympy.Expr, sympy.Symbol] = {}

    def visit(node: sympy.Expr) -> sympy.Expr:
        if node.is_Pow and node.exp.is_Integer and abs(int(node.exp)) >= 2:
            n = int(node.exp)
            base = visit(node.base)
            if not base.is_Symbol:
                if base not in hoist_of:
                    hoist_of[base] = next(hoist_names)
                    hoisted.append((hoist_of[base], base))
                base = hoist_of[base]
            needed.setdefault(base, set()).add(abs(n))
            sym = _power_symbol(base, abs(n))
            return sym if n > 0 else sympy.Pow(sym, -1)
        if node.is_Atom or not node.args:
            return node
        return node.func(*(visit(a) for a in node.args))

    new_assignments = []
    for sym, value in assignments:
        value = visit(value)
        new_assignments.extend(hoisted)  # bases first found here are defined before use
        hoisted.clear()
        new_assignments.append((sym, value))
    new_outputs = [visit(o) for o in outputs]
    new_assignments.extend(hoisted)
    return new_assignments, new_outputs, needed


def _drop_aliases(assignments, outputs):
    """Remove copies such as `c0 = y_2` (CSE named a power the power pass also named)."""
    alias: dict[sympy.Symbol, sympy.Expr] = {}
    kept = []
    for sym, value in assignments:
        value = value.xreplace(alias) if alias else value
        if value.is_Symbol:
            alias[sym] = value
        else:
            kept.append((sym, value))
    return kept, [o.xreplace(alias) if alias else o for o in outputs]


def _renumber(assignments, outputs, powers):
    """Name temporaries t0, t1, ... in order of definition, and their powers t0_2, ..."""
    rename: dict[sympy.Symbol, sympy.Symbol] = {}
    for k, (sym, _) in enumerate(assignments):
        rename[sym] = sympy.Symbol(f"t{k}", real=True)
    for base, exps in powers.items():
        if base in rename:
            for n in exps:
                rename[_power_symbol(base, n)] = _power_symbol(rename[base], n)
    assignments = [(rename[s], v.xreplace(rename)) for s, v in assignments]
    outputs = [o.xreplace(rename) for o in outputs]
    powers = {rename.get(b, b): exps for b, exps in powers.items()}
    return assignments, outputs, powers


def _insert_power_chains(assignments, powers, inputs):
    """Define each needed b_n right after b: b_2 = b*b, b_3 = b*b_2, b_4 = b_2*b_2.

    Powers of a symbol that is neither an input nor a temporary (a parameter uniform,
    `--params uniform`) are defined first, like the inputs' (sorted by name)."""
    ordered = []
    defined = set(inputs) | {sym for sym, _ in assignments}
    free = sorted((b for b in powers if b not in defined), key=lambda b: b.name)
    for b in (*inputs, *free):
        ordered.extend(_power_chain(b, powers.get(b, set())))
    for sym, value in assignments:
        ordered.append((sym, value))
        ordered.extend(_power_chain(sym, powers.get(sym, set())))
    return ordered


def _power_chain(base: sympy.Symbol, exponents: set[int]):
    """Assignments computing base**n for each n by halving (unevaluated products)."""
    have: dict[int, sympy.Expr] = {1: base}
    chain: list[tuple[sympy.Symbol, sympy.Expr]] = []

    def build(n: int) -> sympy.Expr:
        if n not in have:
            half = n // 2
            lo, hi = build(half), build(n - half)
            sym = _power_symbol(base, n)
            chain.append((sym, sympy.Mul(lo, hi, evaluate=False)))
            have[n] = sym
        return have[n]

    for n in sorted(exponents):
        build(n)
    return chain


def _by_axis(assignments, outputs, inputs):
    """Each output's terms summed per axis, the statements ordered axis by axis.

    Input k is on axis k mod 3 (x, y, z, then dx, dy, dz); a statement or term is on the
    last axis it reads (-1: none). Each output that is a sum of terms on several axes
    becomes the sum of its parts, part<output>_<axis> (axis 1-3; each output of several,
    as grad's components on one axis each, is its parts too), and every statement
    moves, in its order, after those of lower axes: x's powers, what reads only x, then
    y's powers, ... A statement is never on a lower axis than one it reads, so this order
    keeps every definition before its uses. Written as a balanced sum of all terms, S of
    Chmutov's T_20 held the powers x^2..x^20 of all three axes at once, and in double
    RDNA3 spilled hessian's program at degree 18-20 (2-9 VGPRs; RDNA2 held 136-144, now
    96-104). The operations are the same."""
    key: dict[sympy.Symbol, int] = {s: k % 3 for k, s in enumerate(inputs)}

    def axis_of(expr: sympy.Expr) -> int:
        return max((key.get(s, -1) for s in expr.free_symbols), default=-1)

    for sym, value in assignments:
        key[sym] = axis_of(value)
    parts = []
    new_outputs = []
    for k, output in enumerate(outputs):
        groups: dict[int, list[sympy.Expr]] = {}
        for term in sympy.Add.make_args(output):
            groups.setdefault(axis_of(term), []).append(term)
        if len(groups) < 2 and len(outputs) < 2:  # nothing to order
            new_outputs.append(output)
            continue
        summed = []
        for axis, terms in sorted(groups.items()):
            if len(terms) == 1 and terms[0].is_Atom:
                summed.append(terms[0])
                continue
            part = sympy.Symbol(f"part{k}_{axis + 1}", real=True)
            key[part] = axis
            parts.append((part, sympy.Add(*terms)))
            summed.append(part)
        new_outputs.append(sympy.Add(*summed))
    lets = list(assignments) + parts
    order = sorted(range(len(lets)), key=lambda j: (key[lets[j][0]], j))
    return [lets[j] for j in order], new_outputs


def _sums_by_depth(assignments, outputs, inputs):
    """Pass 3: every sum of three or more terms as nested two-term sums (unevaluated, so
    the printers keep the grouping), the two shallowest terms first, as Huffman's code
    merges the two lightest. GPU compilers keep the order a sum is written in (floating
    point addition is not associative), and a march step is bound by its dependency
    chain (docs/journal/2026-12-01-marcher-and-forms.md): the Cross-Cap's S ends in `t0 + (x_2 +
    z)`, not
    `t0 + x_2 + z`. Ties keep sympy's canonical order, so the output stays
    deterministic."""
    return _arrange(assignments, outputs, dict.fromkeys(inputs, 0), products=False)


def arrange_by_depth(lets: Sequence[tuple[sympy.Symbol, sympy.Basic]], value: sympy.Basic,
                     depth: Mapping[sympy.Basic, int],
                     ) -> tuple[list[tuple[sympy.Symbol, sympy.Basic]], sympy.Basic]:
    """Straight-line code (`lets` in order, then `value`) with every sum and product of
    three or more operands nested so that the operands ready first (by `depth`, in
    operations; 0 if absent; a let as deep as its value) are combined first and the
    latest one last. For code whose inputs arrive at different times: in a march step's
    root test the end sample (F1, F1') comes last, so `F1' h/2 sign(F0)` is better
    written `(h/2 sign(F0)) F1'`, one product after F1', not three. Returns (lets, value)."""
    lets, (value,) = _arrange(lets, [value], dict(depth), products=True)
    return lets, value


def _arrange(lets, outputs, depth: dict, products: bool):
    """`lets` and `outputs` arranged by depth, each let given the depth of its value."""
    arranged = []
    for sym, expr in lets:
        expr, depth[sym] = _by_depth(expr, depth, products)
        arranged.append((sym, expr))
    return arranged, [_by_depth(o, depth, products)[0] for o in outputs]


def _by_depth(node, depth: dict, products: bool) -> tuple[sympy.Basic, int]:
    """(node arranged by depth, its depth); see `_sums_by_depth`, `arrange_by_depth`."""
    if node.is_Atom:
        return node, depth.get(node, 0)
    ordered_product = products and node.is_Mul and len(node.args) > 2
    if ordered_product and node.as_coeff_Mul()[0].is_negative:
        # the sign stays outside: -(a*(b*c)), one negation
        product, d = _by_depth(-node, depth, products)
        return sympy.Mul(sympy.S.NegativeOne, product, evaluate=False), d + 1
    parts = [_by_depth(a, depth, products) for a in node.args]
    if node.is_Add and len(parts) > 2:
        return _huffman(parts, sympy.Add)
    if ordered_product:
        return _huffman(parts, sympy.Mul)
    args = (e for e, _ in parts)
    # unevaluated: 4*(a + (b + c)) would distribute, a product would flatten a sum
    rebuilt = node.func(*args, evaluate=False) if node.is_Add or node.is_Mul \
        else node.func(*args)
    return rebuilt, max((d for _, d in parts), default=0) + 1


def _huffman(parts: list[tuple[sympy.Expr, int]], op) -> tuple[sympy.Expr, int]:
    """The operands combined by `op` (Add or Mul) as a tree merging the two shallowest
    first; (result, its depth)."""
    heap = [(d, k, e) for k, (e, d) in enumerate(parts)]
    heapq.heapify(heap)
    order = len(heap)
    while len(heap) > 1:
        da, _, a = heapq.heappop(heap)
        db, _, b = heapq.heappop(heap)
        heapq.heappush(heap, (max(da, db) + 1, order, op(a, b, evaluate=False)))
        order += 1
    depth, _, total = heap[0]
    return total, depth


def count_ops(expr: sympy.Expr) -> int:
    """Arithmetic operations to evaluate `expr` as a tree, b**n costing n-1 products.

    Add/Mul with k operands cost k-1, a negation or division 1, a function call 1.
    """
    if expr.is_Atom:
        return 0
    if expr.is_Pow:
        n = expr.exp
        inner = count_ops(expr.base)
        if n.is_Integer:
            k = abs(int(n))
            return inner + max(k - 1, 0) + (1 if int(n) < 0 else 0)
        return inner + count_ops(n) + 1
    if expr.is_Mul:
        args = expr.args
        cost = sum(count_ops(a) for a in args) + len(args) - 1
        if args[0] == -1:
            cost -= 1  # -1*x is a negation: one op, already counted as the product
        return cost
    if expr.is_Add:
        return sum(count_ops(a) for a in expr.args) + len(expr.args) - 1
    return sum(count_ops(a) for a in expr.args) + 1
