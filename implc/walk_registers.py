"""The Bernstein walk's register switches (templates/solver/walk.j2, `exact` from
BERNSTEIN_FROM): in double a value takes two registers, and on RDNA3 (gfx1100, about 126
VGPRs a wave64 holds without spilling) the walk of Chmutov's T19-T20 spilled 5-9 VGPRs to
scratch until all of these held, and T12-T18 spilled 2-6 SGPRs into a VGPR's lanes
(tests/test_gpu_stats.py). Each keeps the program's values bit for bit but
inline_constants, whose node middle is exact where nm/nr rounded and whose `reach` is
compared as a product: exact's pictures in double (gl-double, cl-double) stayed
bit-identical in hit, t and steps. Float's programs take exit_code alone (4-5 % fewer
instructions on RDNA2/RDNA3 at T6-T20, the same pictures): the others need a double's
range (pos_unit's 2^-30 is beyond a float's 24 bits), F's values (float re-expands F
where its ends disagree with the coefficients) or late_start (control_index)."""

from __future__ import annotations

from dataclasses import dataclass

# the walk's node start, an int in units of 2^-POS_BITS: a width is at least 2^-WIDTH_BITS
# there (a descent stops at 2^-(BERNSTEIN_DEPTH + 3); only the next node's narrowing went
# further, on a ray that nearly touches the surface, and stops there)
POS_BITS = 30
WIDTH_BITS = 26


@dataclass(frozen=True)
class WalkRegisters:
    """Which of the walk's values the program holds in fewer registers, and how."""

    # S and its gradient at the chord's start before ray_of, not after it (F's n + 1
    # coefficients were held with the point's powers: T20 134 VGPRs on RDNA2)
    start_first: bool = False
    # the node's start an int ipos in units of pos_unit (2^-POS_BITS printed; pos_units,
    # its inverse, as a real and as an int), not a double pos and an int index; and a
    # descent's width shifted in those units, not scaled by a select of 2^-L's double
    # constants (one of which was held in a VGPR through the walk)
    pos_unit: str = ""
    pos_units: str = ""
    pos_units_int: str = ""
    width_floor: str = ""  # 2^-WIDTH_BITS printed
    # F at a node's ends carried as its sign (an int -1, 0, 1): the walk and Newton read
    # no more of it
    end_signs: bool = False
    # (late_start) the control polygon's pair with the sign change kept through the sums
    # by its index i, an int, and its w_(i-1) chosen after them
    control_index: bool = False
    # how the walk ended, an int `stop` (0 no root, 1 a root, 2 a leaf to test, 3 a touching
    # leaf; a root at a node's start is the one with fl = 0), not the bools found, leaf and
    # touch: set at the loops' breaks, each was a lane mask ACO carried through the walk's
    # loops in SGPRs (RDNA2/RDNA3, T14-T15: SGPRs spilled)
    exit_code: bool = False
    # (pos_unit) a descent's levels an int chosen right after the sums, not from
    # the cross_i at the descent: those were held as lane masks from the sums to it
    descent_int: bool = False
    # (pos_unit) no double constant in the walk's loop that AMD cannot encode inline (0.5,
    # 1, 2 and 4 it can): each such constant ACO held in 2 SGPRs through the walk (RDNA2/
    # RDNA3, T16-T18: SGPRs spilled). A division is AMD's software reciprocal, 4 constants:
    # the node's middle in half widths, nm/nr = (2 pos - 1 + width)/width (lo = -span/2),
    # is made exactly from ipos and 1/width, width's exponent bits negated (the language's
    # power_of_two_inverse: width is a power of two); `reach` is compared as a product;
    # 1/NEXT_FLOOR (0.25) is `floor_halvings` halvings.
    inline_constants: bool = False
    floor_halvings: int = 0


def walk_registers(precision: str, float_literal, next_floor: int) -> WalkRegisters:
    """All the switches in double, exit_code alone in float (double's F is expanded once,
    about the chord's middle: it never re-expands, so S at the chord's start can come
    first); `next_floor`: solver.NEXT_FLOOR, a power of two."""
    if next_floor & (next_floor - 1):
        raise ValueError(f"NEXT_FLOOR {next_floor} is not a power of two")
    if precision != "double":
        return WalkRegisters(exit_code=True)
    return WalkRegisters(start_first=True,
                         pos_unit=float_literal(2.0 ** -POS_BITS),
                         pos_units=float_literal(2.0 ** POS_BITS),
                         pos_units_int=str(2 ** POS_BITS),
                         width_floor=float_literal(2.0 ** -WIDTH_BITS),
                         end_signs=True, control_index=True, exit_code=True,
                         descent_int=True, inline_constants=True,
                         floor_halvings=next_floor.bit_length() - 1)
