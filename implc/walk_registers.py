"""How the Bernstein walk (templates/solver/walk.j2, `exact` from BERNSTEIN_FROM) holds its
values in registers. In both precisions the node's start is an int in units of a power of
two and the walk's end an int `stop`. In double, where a value takes two registers, the
switches below hold more of them in fewer: on RDNA3 (gfx1100, about 126 VGPRs a wave64
holds without spilling) the walk of Chmutov's T19-T20 spilled 5-9 VGPRs to scratch until
all of them held, and T12-T18 spilled 2-6 SGPRs into a VGPR's lanes
(tests/test_gpu_stats.py). Each keeps the program's values bit for bit but
inline_constants, whose node middle is exact where nm/nr rounded and whose `reach` is
compared as a product: exact's pictures in double (gl-double, cl-double) stayed
bit-identical in hit, t and steps. Float takes none of the switches: F's values are read
where float re-expands F (end_signs, inline_constants), control_index adds instructions
without late_start, and S at the chord's start before ray_of would be computed again at
each re-expansion (start_first)."""

from __future__ import annotations

from dataclasses import dataclass, replace

# the walk's node start, an int in units of 2^-POS_BITS: a width is at least 2^-WIDTH_BITS
# there (a descent stops at 2^-(BERNSTEIN_DEPTH + 3); only the next node's narrowing went
# further, on a ray that nearly touches the surface, and stops there). Float's int start
# converts to a float exactly below 2^24.
POS_BITS = {"float": 24, "double": 30}
WIDTH_BITS = {"float": 20, "double": 26}


@dataclass(frozen=True)
class WalkRegisters:
    """Where the walk's node is (pos_unit: 2^-POS_BITS printed; pos_units, its inverse, as
    a real and as an int; width_floor: 2^-WIDTH_BITS printed), and which of its values the
    program holds in fewer registers, and how. The node's start is an int ipos in units of
    pos_unit, not a real pos and an int index, and a descent's width is shifted in those
    units (a select of 2^-L's double constants held one of them in a VGPR through the
    walk); the walk's end is an int `stop` (0 no root, 1 a root, 2 a leaf to test, 3 a
    touching leaf), not the bools found, leaf and touch, each a lane mask ACO carried
    through the walk's loops in SGPRs (RDNA2/RDNA3, double T14-T15: SGPRs spilled; float,
    with the int start: 6-11 % of exact's instructions at T6-T20)."""

    pos_unit: str = ""
    pos_units: str = ""
    pos_units_int: str = ""
    width_floor: str = ""
    # S and its gradient at the chord's start before ray_of, not after it (F's n + 1
    # coefficients were held with the point's powers: T20 134 VGPRs on RDNA2)
    start_first: bool = False
    # F at a node's ends carried as its sign (an int -1, 0, 1): the walk and Newton read
    # no more of it
    end_signs: bool = False
    # (late_start) the control polygon's pair with the sign change kept through the sums
    # by its index i, an int, and its w_(i-1) chosen after them
    control_index: bool = False
    # no double constant in the walk's loop that AMD cannot encode inline (0.5, 1, 2 and 4
    # it can): each such constant ACO held in 2 SGPRs through the walk (RDNA2/RDNA3,
    # T16-T18: SGPRs spilled). A division is AMD's software reciprocal, 4 constants: the
    # node's middle in half widths, nm/nr = (2 pos - 1 + width)/width (lo = -span/2), is
    # made exactly from ipos and 1/width, width's exponent bits negated (the language's
    # power_of_two_inverse: width is a power of two); `reach` is compared as a product;
    # 1/NEXT_FLOOR (0.25) is `floor_halvings` halvings.
    inline_constants: bool = False
    floor_halvings: int = 0


def walk_registers(precision: str, float_literal, next_floor: int) -> WalkRegisters:
    """The walk's registers in `precision`: every switch in double, none in float (double's
    F is expanded once, about the chord's middle: it never re-expands, so S at the chord's
    start can come first); `next_floor`: solver.NEXT_FLOOR, a power of two."""
    if next_floor & (next_floor - 1):
        raise ValueError(f"NEXT_FLOOR {next_floor} is not a power of two")
    bits, width_bits = POS_BITS[precision], WIDTH_BITS[precision]
    where = WalkRegisters(pos_unit=float_literal(2.0 ** -bits),
                          pos_units=float_literal(2.0 ** bits), pos_units_int=str(2 ** bits),
                          width_floor=float_literal(2.0 ** -width_bits))
    if precision != "double":
        return where
    return replace(where, start_first=True, end_signs=True, control_index=True,
                   inline_constants=True, floor_halvings=next_floor.bit_length() - 1)
