"""What several commands share: their argument groups and value types, and the reading of
parsed arguments into the API's values (never by changing `args`)."""

from __future__ import annotations

import argparse
import contextlib
import math
import re
import sys
from collections.abc import Iterator
from typing import TYPE_CHECKING, Any

from ..errors import OptionError
from ..limits import Limits
from ..options import (
    AUTO_RAY_POLY_MAX_DEGREE,
    EVAL_CHOICES,
    EXACT_MAX_DEGREE,
    GPU_FAMILIES,
    METHOD_NAMES,
    TAYLOR2_CHOICES,
    Constants,
)
from ..targets import TARGETS

if TYPE_CHECKING:
    from concurrent.futures import Executor

    from ..api.surface import Surface
    from ..scene import ViewOptions

MAX_STEPS = 10_000_000  # the largest --max-steps


class UsageError(OptionError):
    """A bad command line: an unknown option or choice, a value out of range, options
    that contradict each other. Exit 2, one line naming the command and where its
    options are listed (not argparse's whole usage message)."""

    def __init__(self, message: str, command: str | None = None):
        super().__init__(message)
        self.command = command  # "implc compile"; None: main fills it in

    def render(self) -> str:
        prog = self.command or "implc"
        return f"{prog}: error: {self.message}\nsee '{prog} --help' for the options"


# Every field of implc.limits.Limits, as the option its error messages name.
LIMIT_FLAGS = {
    "--max-chars": "longest equation, in characters",
    "--max-depth": "deepest nesting of brackets and operators",
    "--max-nodes": "largest expression size, in nodes",
    "--max-exponent": "largest |integer exponent| of a non-constant base",
    "--max-degree": "largest total degree in x, y, z",
    "--max-terms": "most monomials after expansion",
    "--max-literal-exponent": "number literals must lie within 1e-N .. 1e+N",
    "--max-constant-digits": "most digits of an exactly computed constant",
    "--max-derived": "largest estimated size of the derivatives before CSE, in nodes (a "
                     "surface with functions: also 160 per node of a partial derivative)",
}

# [view] key -> its option (`target` is --look-at: -t/--target is the shader language)
VIEW_ABOUT = (
    "Each option overrides the surface file's [view] key of the same name (--look-at: "
    "`target`). Which way is "
    "up: +y is up in the picture (the default `up`) unless the file's [view] sets `up`; an "
    "equation written z-up, like Taubin's heart typed with -e, lies on its side: --up z "
    "stands it up. What neither the file nor an option sets is chosen and printed: "
    "without a radius (every -e) implc finds where S changes sign and puts the clip "
    "sphere around it; without an eye (unless the file sets radius) the camera goes where "
    "the sphere fills the picture (the docs' \"Framing\").")

# Constants field -> (argparse dest, the option that sets it); ranges are checked by the
# options' types (a bad value is a usage error)
CONSTANT_OPTIONS = {
    "step": ("step", "--step"), "tau1": ("tau1", "--tau1"), "tau2": ("tau2", "--tau2"),
    "tau3": ("tau3", "--tau3"), "eps": ("eps", "--eps"), "taylor2": ("taylor2", "--taylor2"),
    "max_steps": ("max_steps", "--max-steps"), "evaluation": ("eval", "--eval"),
}


# --- argument groups -------------------------------------------------------------------

def surface_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("surface", nargs="?",
                   help="TOML file, SURFER .jsurf file or bundled example name")
    p.add_argument("-e", "--equation", help='equation text instead of a file, e.g. "x^2+y^2+z^2=1"')
    p.add_argument("--param", action="append", default=[], metavar="NAME=VALUE",
                   help="set a named parameter (repeatable)")
    limit_args(p)


def limit_args(p: argparse.ArgumentParser) -> None:
    limits = p.add_argument_group("limits (hostile-input guards; the docs' \"Limits\")")
    defaults = Limits()
    for flag, text in LIMIT_FLAGS.items():
        default = getattr(defaults, flag[2:].replace("-", "_"))
        limits.add_argument(flag, type=positive_int, metavar="N",
                            help=f"{text} (default {default})")


def view_args(p: argparse.ArgumentParser) -> None:
    """The camera and clip sphere on the command line (`render`, `view`, `compile`)."""
    v = p.add_argument_group("view", VIEW_ABOUT)
    v.add_argument("--radius", type=radius_arg, metavar="R",
                   help="clip sphere radius: only what lies inside is drawn (default: the "
                        "file's, else framed automatically)")
    v.add_argument("--center", type=point_arg, metavar="X,Y,Z",
                   help="clip sphere centre (default: the file's, else the surface's middle "
                        "when framed automatically, else the origin)")
    v.add_argument("--eye", type=point_arg, metavar="X,Y,Z",
                   help="camera position (default: the file's, else placed where the clip "
                        "sphere fills the picture)")
    v.add_argument("--look-at", type=point_arg, metavar="X,Y,Z", dest="look_at",
                   help="the point the camera looks at, [view] `target` (default: the "
                        "clip sphere's centre)")
    v.add_argument("--up", type=up_arg, metavar="x|y|z|X,Y,Z",
                   help="the world direction that is up in the picture (default y: +y is "
                        "up, or the file's `up`); --up z for equations written z-up; -x, "
                        "-y, -z turn it over")
    v.add_argument("--fov", type=fov_arg, metavar="DEG",
                   help="field of view across the picture's shorter side, in degrees "
                        "(default: the file's, else 30)")
    p.set_defaults(view_options=True)


def extension_list(extensions: Any) -> str:
    """`.frag/.glsl glsl, .wgsl wgsl, ...`: each target's extensions, for the help."""
    return ", ".join("/".join(extensions(t)) + " " + t.name for t in TARGETS.values())


def shader_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("-t", "--target", choices=list(TARGETS), default=None,
                   help="shader language (default: glsl; compile: from -o's extension; "
                        "render: the language of -b)")
    p.add_argument("--flavor", help="; ".join(
        f"{t.name}: {', '.join(t.flavors)} (default {t.default_flavor})"
        for t in TARGETS.values() if len(t.flavors) > 1) + " (the other targets have none)")
    precisions = dict.fromkeys(x for t in TARGETS.values() for x in t.precisions)
    p.add_argument("--precision", choices=list(precisions), help="; ".join(
        f"{t.name}: {' or '.join(t.precisions)} (default {t.precisions[0]})"
        for t in TARGETS.values() if len(t.precisions) > 1) + ". At the default, a "
        "warning says where float32 cannot hold a polynomial surface (`implc show` "
        "measures it); --precision float silences it")
    p.add_argument("--params", choices=("constant", "uniform"), default="constant",
                   help="constant (default): parameter values baked into the shader; "
                        "uniform: parameters are uniforms the host sets at run time")
    method_args(p)


def method_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("-m", "--method", choices=list(METHOD_NAMES), default=None,
                   help="root-finding method (default: exact for polynomial surfaces up to "
                        f"degree {EXACT_MAX_DEGREE}, else interval where every function has "
                        "an interval rule (not atan2), else hessian); see the docs' \"The "
                        "methods\"")
    d = Constants()
    c = p.add_argument_group(
        "method constants (defaults: the paper's Table 1)",
        "One the method does not read (--step with exact, any with -b reference) is "
        "ignored with a warning.")
    c.add_argument("--step", type=positive_number,
                   help="base step b (default 0.01; hessian 0.002)")
    c.add_argument("--tau1", type=positive_number,
                   help=f"|F| <= tau1: near the surface (default {d.tau1})")
    c.add_argument("--tau2", type=positive_number,
                   help=f"|F| > tau2: far from it (default {d.tau2})")
    c.add_argument("--tau3", type=positive_number,
                   help=f"|F'| <= tau3: silhouette (default {d.tau3})")
    c.add_argument("--eps", type=positive_number,
                   help=f"hessian-approx finite-difference step (default {d.eps})")
    c.add_argument("--taylor2", choices=TAYLOR2_CHOICES,
                   help="Eq. 4 as printed (paper, default), consistent (h^2/8, F''(t1)), or "
                        "extremum (consistent plus each end's extremum inside the step)")
    c.add_argument("--max-steps", type=int_between(1, MAX_STEPS),
                   help=f"march step cap per ray (default {d.max_steps})")
    p.add_argument("--eval", choices=EVAL_CHOICES, help=(
        "how F, F', F'' are computed along a ray: point (3-D functions of p = o + s d), "
        "ray-poly (polynomial S: the ray polynomial's coefficients once per ray, then "
        "Estrin's scheme), auto (default: ray-poly up to degree "
        f"{AUTO_RAY_POLY_MAX_DEGREE} where its march step evaluates fewer operations, as "
        "`implc show` prints, else point); see the docs' \"Evaluation forms\""))


# --- value types -----------------------------------------------------------------------

def point_arg(text: str) -> tuple[float, float, float]:
    """argparse type of --center, --eye, --look-at: `X,Y,Z` (brackets allowed)."""
    parts = text.strip().strip("[]()").split(",")
    try:
        values = tuple(float(part) for part in parts)
    except ValueError:
        values = ()
    if len(values) != 3:
        raise argparse.ArgumentTypeError(f"expected three numbers X,Y,Z, got {text!r}")
    if not all(math.isfinite(v) and abs(v) <= 1e6 for v in values):
        raise argparse.ArgumentTypeError(f"each coordinate must be a finite number within "
                                         f"1e6 of the origin, got {text!r}")
    return values  # type: ignore[return-value]


def up_arg(text: str) -> tuple[float, float, float]:
    """argparse type of --up: an axis (`z`, `-y`) or a direction `X,Y,Z`."""
    axis = text.strip().lower()
    sign = -1.0 if axis.startswith("-") else 1.0
    if axis.lstrip("+-") in ("x", "y", "z"):
        index = "xyz".index(axis.lstrip("+-"))
        return tuple(sign if i == index else 0.0 for i in range(3))  # type: ignore[return-value]
    if not re.match(r"[\s\[(]*[-+.\d]", text):
        raise argparse.ArgumentTypeError(f"expected x, y, z (or -x, -y, -z) or a direction "
                                         f"X,Y,Z, got {text!r}")
    value = point_arg(text)
    if not any(value):
        raise argparse.ArgumentTypeError("the up direction must not be 0,0,0")
    return value


def radius_arg(text: str) -> float:
    return _number_arg(text, 0.0, 1e6, "a clip sphere radius")


def fov_arg(text: str) -> float:
    return _number_arg(text, 0.0, 180.0, "a field of view in degrees")


def _number_arg(text: str, low: float, high: float, what: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number, got {text!r}") from None
    if not low < value < high:
        raise argparse.ArgumentTypeError(f"{what} must be between {low:g} and {high:g} "
                                         f"(exclusive), got {text}")
    return value


def positive_int(text: str) -> int:
    """argparse type of the limit options: a limit of 0 or below is a usage error."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a positive integer, got {text!r}") from None
    if not 1 <= value <= 10**9:
        raise argparse.ArgumentTypeError(f"expected an integer from 1 to 10^9, got {text}")
    return value


def int_between(low: int, high: int) -> Any:
    """argparse type: an integer from `low` to `high` (a value outside is a usage error,
    exit 2; `--size 0` is not "the default")."""

    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected an integer, got {text!r}") from None
        if not low <= value <= high:
            raise argparse.ArgumentTypeError(
                f"expected an integer from {low} to {high}, got {value}")
        return value

    return parse


def positive_number(text: str) -> float:
    """argparse type of the method constants and tolerances: 0 < value < 1e6."""
    try:
        value = float(text)
    except ValueError:
        value = float("nan")
    if not 0.0 < value < 1e6:  # also nan and inf
        raise argparse.ArgumentTypeError(f"expected a positive number below 1e6, got {text!r}")
    return value


# --- parsed arguments -> the API's values ----------------------------------------------

def limits(args: argparse.Namespace) -> Limits:
    given = {flag[2:].replace("-", "_"): getattr(args, flag[2:].replace("-", "_"))
             for flag in LIMIT_FLAGS}
    return Limits(**{k: v for k, v in given.items() if v is not None})


def view_options(args: argparse.Namespace) -> ViewOptions:
    from ..scene import ViewOptions

    if not getattr(args, "view_options", False):
        return ViewOptions()
    return ViewOptions(radius=args.radius, center=args.center, eye=args.eye,
                       target=args.look_at, up=args.up, fov=args.fov)


def equation_arg(args: argparse.Namespace) -> str | None:
    """-e's text; argparse drops a value that is exactly "--" (it reads it as [])."""
    return "--" if args.equation == [] else args.equation


def surface(args: argparse.Namespace) -> Surface:
    """The surface the command line names, loaded (its load notes said once), with the
    view options given; framed when a command compiles or renders it."""
    from ..api.surface import Surface

    equation = equation_arg(args)
    if (args.surface is None) == (equation is None):
        raise UsageError("give a surface (a file or a bundled example name) or -e EQUATION"
                         + (", not both" if args.surface is not None else ""))
    loaded = Surface.from_args(args.surface, equation, tuple(args.param), limits(args),
                               view_options(args))
    for note in loaded.notes:  # a .jsurf file's keys implc does not use, said once
        print(note, file=sys.stderr)
    return loaded


def constants_given(args: argparse.Namespace) -> dict[str, Any]:
    """The method constants the command line sets (Constants field -> value)."""
    return {field: getattr(args, dest) for field, (dest, _) in CONSTANT_OPTIONS.items()
            if getattr(args, dest) is not None}


def warn(args: argparse.Namespace, message: str) -> None:
    print(f"implc {args.command}: warning: {message}", file=sys.stderr)


def _spoken(flags: list[str]) -> str:
    """['--step', '--tau1'] -> '--step and --tau1 do'."""
    listed = flags[0] if len(flags) == 1 else ", ".join(flags[:-1]) + " and " + flags[-1]
    return listed + (" does" if len(flags) == 1 else " do")


def warn_ignored(args: argparse.Namespace, method: str, reference: bool = False) -> None:
    """A method constant the method does not read (--step with exact), or any method
    option with the CPU reference, is said on stderr and ignored (exit 0), never dropped
    silently (docs/guide/command-line.md "Command line"). What a method reads comes from its data
    (`Method.reads`), not from a list here."""
    given = constants_given(args)
    if reference:
        flags = (["-m"] if args.method is not None else []) + [
            CONSTANT_OPTIONS[field][1] for field in given]
        if args.flavor is not None:
            flags.append("--flavor")
        if flags:
            warn(args, f"{_spoken(flags)} not apply to -b reference (the exact CPU "
                       "reference runs no method and no shader): ignored")
        return
    from ..api.compiling import ignored_constants
    from ..methods import METHODS

    ignored = [CONSTANT_OPTIONS[field][1] for field in ignored_constants(method, given)]
    if ignored:
        reads = METHODS[method].reads
        which = "" if args.method is not None else " (the default for this surface)"
        used = [flag for field, (_, flag) in CONSTANT_OPTIONS.items() if field in reads]
        warn(args, f"{_spoken(ignored)} not apply to method {method}{which}, which "
                   f"reads {', '.join(used) if used else 'none of the method constants'}: "
                   "ignored")


def gpu_family_arg(g: Any) -> None:
    """--gpu-family, shared by `show --gpu-stats` and `bench --gpu-stats`."""
    g.add_argument("--gpu-family", default=None, dest="gpu_family", metavar="F1,F2",
                   help=f"RADV family names (default {','.join(GPU_FAMILIES)}: RDNA2, RDNA3; "
                        "e.g. polaris10 for GCN)")


def gpu_families(args: argparse.Namespace) -> tuple[str, ...]:
    """The families asked for with --gpu-stats (OptionError: a family option without it,
    or a name that is not one)."""
    if not args.gpu_stats:
        if args.gpu_family:
            raise OptionError("--gpu-family applies with --gpu-stats only")
        return ()
    from ..render.gpu_stats import check_family

    named = (args.gpu_family or ",".join(GPU_FAMILIES)).split(",")
    families = tuple(check_family(f.strip()) for f in named if f.strip())
    if not families:
        raise OptionError("--gpu-family: name at least one family, e.g. navi21")
    return families


def executor_args(p: argparse.ArgumentParser, default_jobs: int) -> None:
    """-j and --scheduler: where a batch command's work runs."""
    p.add_argument("-j", "--jobs", type=int_between(0, 64), default=default_jobs,
                   help=f"worker processes (0: one per CPU, at most 4; default "
                        f"{default_jobs}{': this process' if default_jobs == 1 else ''})")
    p.add_argument("--scheduler", metavar="ADDRESS",
                   help="run the work on a Dask distributed cluster, e.g. "
                        "tcp://10.0.0.5:8786 (needs pip install 'implc[dask]'); -j is "
                        "then ignored")


@contextlib.contextmanager
def executor(args: argparse.Namespace) -> Iterator[Executor | None]:
    """The executor -j or --scheduler asks for (None: this process), shut down after."""
    from ..executors import dask_executor, effective_jobs, local_executor, stop_executor

    if args.scheduler:
        pool = dask_executor(args.scheduler)
    else:
        jobs = effective_jobs(args.jobs)
        if jobs <= 1:
            yield None
            return
        pool = local_executor(jobs)
    try:
        yield pool
    except BaseException:
        stop_executor(pool)
        raise
    pool.shutdown(wait=True)
