"""`implc show`: what implc understood and what it will compute (and, with --gpu-stats,
what AMD's compiler makes of the program: registers, spills, occupancy)."""

from __future__ import annotations

import argparse

from ..errors import EXIT_OK, OptionError
from ..options import METHOD_NAMES
from . import args as common

# the programs that reach SPIR-V, per precision: (target, flavour)
SPIRV_PROGRAMS = {"float": (("hlsl", None), ("glsl", "450")), "double": (("glsl", "450"),)}


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("show", help="print the equation, degree, derivatives and op counts")
    common.surface_args(p)
    p.add_argument("-m", "--method", choices=sorted(METHOD_NAMES), default=None,
                   help="method whose shader functions to count (default: exact for "
                        "polynomials, else interval where every function has an interval "
                        "rule, else hessian)")
    g = p.add_argument_group("GPU statistics (Mesa's RADV on a null device: no GPU needed)")
    g.add_argument("--gpu-stats", action="store_true", dest="gpu_stats",
                   help="also print what AMD's compiler (ACO) makes of the method's program "
                        "for each family: VGPRs, SGPRs, spills, scratch, waves per SIMD, "
                        "instructions (HLSL and GLSL 450 programs through SPIR-V)")
    common.gpu_family_arg(g)
    g.add_argument("--precision", choices=sorted(SPIRV_PROGRAMS), default=None,
                   help="precision of the programs measured (double: GLSL 450 only, HLSL "
                        "has float only; default float)")


def run(args: argparse.Namespace) -> int:
    if not args.gpu_stats and (args.gpu_family or args.precision):
        raise OptionError("--gpu-family and --precision apply with --gpu-stats only")
    families = common.gpu_families(args)
    precision = args.precision or "float"
    surface = common.surface(args)
    print(surface.describe(args.method))
    if args.gpu_stats:
        for target, flavor in SPIRV_PROGRAMS[precision]:
            shader = surface.compile(target, args.method, flavor=flavor, precision=precision)
            name = f"{target}{' ' + flavor if flavor else ''}"
            print(f"\nGPU statistics of the {shader.method} program, {name}, "
                  f"{precision} (RADV/ACO, fragment stage):")
            for stats in shader.gpu_stats(families):
                print(f"  {stats.line()}")
    return EXIT_OK
