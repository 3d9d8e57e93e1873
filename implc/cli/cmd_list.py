"""`implc list`: the bundled example surfaces."""

from __future__ import annotations

import argparse

from ..errors import EXIT_OK


def add_parser(sub: argparse._SubParsersAction) -> None:
    sub.add_parser("list", help="list the bundled example surfaces",
                       description="The bundled example surfaces (examples/): name, degree "
                                   "(or non-poly) and equation. Give a name wherever a "
                                   "SURFACE is asked, e.g. `implc render torus -o t.png`.")


def run(args: argparse.Namespace) -> int:
    from ..api import Surface, examples

    for name in examples():
        surface = Surface.example(name)
        degree = surface.degree
        kind = f"deg {degree}" if degree else "non-poly"
        equation, *substituted = surface.record.equation_lines()  # names, then values
        print(f"{name:<18} {kind:<9} {equation}")
        for line in substituted:
            print(f"{'':<28} {line}")
    return EXIT_OK
