"""The `implc` command: argument parsing and exit codes only; the work is in the library.

Exit codes (README "Exit codes"): 0 ok; 1 bad input or output (equation, surface file,
parameter, a missing or unreadable input, an output that cannot be written, a full disk);
2 bad command line; 3 a shader failed validation; 4 a tool or runtime is missing or
failed; 70 internal error (a bug: rerun with IMPLC_DEBUG=1 for the traceback);
130 interrupted (SIGINT); 143 terminated (SIGTERM). Every output path is checked before
any work starts (implc.fileio.check_output).
"""

from __future__ import annotations

import argparse
import contextlib
import math
import os
import re
import signal
import sys
import time
import traceback
from pathlib import Path

from . import __version__
from .errors import (
    EXIT_INPUT,
    EXIT_INTERNAL,
    EXIT_INTERRUPTED,
    EXIT_INVALID,
    EXIT_OK,
    EXIT_TERMINATED,
    EXIT_USAGE,
    ImplcError,
    InputError,
    ValidationError,
)
from .fileio import (
    FULL_DISK,
    check_output,
    check_output_dir,
    describe_os_error,
    read_input,
    write_atomic,
)
from .interrupts import Terminated, dropped_signals_kept, raise_dropped
from .limits import Limits
from .options import (
    AUTO_RAY_POLY_MAX_DEGREE,
    EVAL_CHOICES,
    EXACT_MAX_DEGREE,
    METHOD_NAMES,
    TAYLOR2_CHOICES,
    Constants,
)
from .render.run import BACKENDS, REFERENCE, REFERENCE_ABOUT
from .targets import (
    TARGETS,
    Target,
    backends_in,
    flavor_problem,
    prefix_problem,
    target_of_file,
    where_precision,
)

EPILOG = """\
surfaces: a TOML file, a SURFER .jsurf file, a bundled example name (see `implc list`),
or -e "EQUATION".

examples:
  implc list
  implc show cross-cap
  implc compile cross-cap -t glsl -m hessian -o cross-cap.frag --validate
  implc compile -e "x^2 + y^2 + z^2 = 1" -m taylor --flavor shadertoy
  implc compile cross-cap --emit library --prefix cc_ -o cc.glsl
  implc validate cross-cap.frag
  implc render cross-cap -m hessian --size 512 -o cross-cap.png
  implc view torus -o torus.html
  implc compare cc-hessian.exr cc-reference.exr
  implc bench cross-cap miter steiner --size 512 -o results/

exit codes: 0 ok, 1 bad input or output (file missing, unreadable or unwritable,
            disk full), 2 bad command line, 3 validation failed, 4 tool or runtime
            missing, 70 internal error (IMPLC_DEBUG=1 shows the traceback),
            130 interrupted (SIGINT), 143 terminated (SIGTERM)
"""

DEBUG_ENV = "IMPLC_DEBUG"


class StdoutError(ImplcError):
    """Standard output cannot be written (a full disk under `> file`, a closed or
    read-only descriptor): exit code 1, like any output that cannot be written."""


class _GuardedStdout:
    """sys.stdout, with write errors turned into StdoutError (a closed pipe stays a
    BrokenPipeError: the reader left, which is not an error)."""

    def __init__(self, stream):
        self._stream = stream

    def _guard(self, call, *args):
        try:
            return call(*args)
        except BrokenPipeError:
            raise
        except OSError as err:
            raise StdoutError(f"cannot write to standard output: {describe_os_error(err)}"
                              ) from None

    def write(self, text):
        return self._guard(self._stream.write, text)

    def flush(self):
        return self._guard(self._stream.flush)

    def __getattr__(self, name):
        return getattr(self._stream, name)


class UsageError(ImplcError):
    """A bad command line: an unknown option or choice, a value out of range, options
    that contradict each other. Exit 2, one line naming the command and where its
    options are listed (not argparse's whole usage message)."""

    exit_code = EXIT_USAGE

    def __init__(self, message: str, command: str | None = None):
        super().__init__(message)
        self.message = message
        self.command = command  # "implc compile"; None: main fills it in

    def render(self) -> str:
        prog = self.command or "implc"
        return f"{prog}: error: {self.message}\nsee '{prog} --help' for the options"


class _Parser(argparse.ArgumentParser):
    """argparse, with its errors raised as UsageError (main prints them in one line)."""

    def error(self, message: str):
        raise UsageError(message, self.prog)


def _on_sigterm(signum, frame):
    raise Terminated()


def _install_signals() -> dict:
    """SIGTERM ends the run cleanly (exit 143); SIGXFSZ is ignored so that a file-size
    limit (RLIMIT_FSIZE) shows as an EFBIG write error instead of killing the process."""
    previous = {}
    for sig, handler in ((signal.SIGTERM, _on_sigterm), (signal.SIGXFSZ, signal.SIG_IGN)):
        with contextlib.suppress(ValueError, OSError):  # not the main thread
            previous[sig] = signal.signal(sig, handler)
    # Restart system calls the signal interrupts (SA_RESTART) instead of failing them
    # with EINTR, which C libraries may not retry: a Ctrl-C during moderngl's ctx.program
    # segfaulted (test_fault[gallery-SIGINT]: 2 runs of 6; 0 of 14 with this, but once
    # more in a loaded clean-clone run, so render/gl.py also holds the signals while the
    # driver works). Python still raises KeyboardInterrupt once the call returns.
    for sig in (signal.SIGINT, signal.SIGTERM):
        with contextlib.suppress(ValueError, OSError):
            signal.siginterrupt(sig, False)
    return previous


def main(argv: list[str] | None = None) -> int:
    with dropped_signals_kept():
        return _main(argv)


def _main(argv: list[str] | None) -> int:
    previous = _install_signals()
    command = "implc"
    stdout = sys.stdout
    sys.stdout = _GuardedStdout(stdout)
    try:
        raise_dropped()  # one that came while the modules loaded
        parser = build_parser()
        args = parser.parse_args(_join_equation_values(sys.argv[1:] if argv is None else argv))
        command = getattr(args, "command", None) or "implc"
        if getattr(args, "equation", None) == []:  # argparse drops a value that is exactly "--"
            args.equation = "--"
        if not getattr(args, "command", None):
            parser.print_help()
            return EXIT_OK
        from .derive import derive_limits

        _NOTES.clear()
        with derive_limits(getattr(args, "max_derived", None)):
            code = args.run(args)
        raise_dropped()
        _print_notes()  # what framing chose, once the command has done its work
        sys.stdout.flush()  # a full disk under `> file` is reported here, not at exit
        return code
    except ImplcError as err:
        if isinstance(err, UsageError) and err.command is None:
            err.command = "implc" if command == "implc" else f"implc {command}"
        if isinstance(err, StdoutError):
            _detach_stdout()  # what is still buffered would fail again at exit
        print(err.render(), file=sys.stderr)
        return err.exit_code
    except KeyboardInterrupt:
        print("implc: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    except Terminated:
        print("implc: terminated", file=sys.stderr)
        return EXIT_TERMINATED
    except BrokenPipeError:  # `implc show x | head`: the reader left; not an error
        _detach_stdout()
        return EXIT_OK
    except RecursionError:
        print("implc: error: too complex: expression nesting exceeds Python's limits",
              file=sys.stderr)
        return EXIT_INPUT
    except OSError as err:
        if err.errno not in FULL_DISK:
            return _internal_error(command, err)
        print(f"implc: error: cannot write the output: {describe_os_error(err)}",
              file=sys.stderr)
        return EXIT_INPUT
    except Exception as err:  # a bug: one line, the traceback on request
        return _internal_error(command, err)
    finally:
        sys.stdout = stdout
        for sig, handler in previous.items():
            signal.signal(sig, handler)


def _internal_error(command: str, err: BaseException) -> int:
    if os.environ.get(DEBUG_ENV):
        traceback.print_exc()
    first = (str(err).splitlines() or [""])[0][:300]
    what = f"{type(err).__name__}: {first}" if first else type(err).__name__
    where = f"'implc {command}'" if command != "implc" else "implc"
    print(f"implc: internal error in {where}: {what} (rerun with {DEBUG_ENV}=1 for the "
          "traceback, and please report it)", file=sys.stderr)
    return EXIT_INTERNAL


def _detach_stdout() -> None:
    """Point stdout at /dev/null so the interpreter's last flush has nowhere to fail."""
    with contextlib.suppress(OSError, ValueError):
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())


def _join_equation_values(argv: list[str]) -> list[str]:
    """`-e "-x^2 + z"` -> `--equation=-x^2 + z`.

    argparse reads a separate value that starts with '-' as an option and reports
    "expected one argument", but equations often start with a minus sign (a quarter of
    the MathMod rows do). A value that looks like a long option (`--help`) is left alone.
    """
    joined: list[str] = []
    i = 0
    while i < len(argv):
        arg = argv[i]
        value = argv[i + 1] if i + 1 < len(argv) else None
        if (arg in ("-e", "--equation") and value is not None and value.startswith("-")
                and not re.match(r"--[A-Za-z]", value)):
            joined.append(f"--equation={value}")
            i += 2
            continue
        if arg in VIEW_POINT_FLAGS and value is not None and re.match(r"-[\d.xyzXYZ]", value):
            joined.append(f"{arg}={value}")  # `--eye -3,0,0`, `--up -z`
            i += 2
            continue
        joined.append(arg)
        i += 1
    return joined


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(
        prog="implc",
        description="Compile implicit-surface equations into robust GPU ray-marching shaders.",
        epilog=EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("--version", action="version", version=f"implc {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")

    p = sub.add_parser("list", help="list the bundled example surfaces",
                       description="The bundled example surfaces (examples/): name, degree "
                                   "(or non-poly) and equation. Give a name wherever a "
                                   "SURFACE is asked, e.g. `implc render torus -o t.png`.")
    p.set_defaults(run=cmd_list)

    p = sub.add_parser("show", help="print the equation, degree, derivatives and op counts")
    _surface_args(p)
    p.add_argument("-m", "--method", choices=sorted(METHOD_NAMES), default=None,
                   help="method whose shader functions to count (default: exact for "
                        "polynomials, else interval where every function has an interval "
                        "rule, else hessian)")
    p.set_defaults(run=cmd_show)

    p = sub.add_parser("compile", help="emit a shader for a surface",
                       formatter_class=argparse.RawDescriptionHelpFormatter,
                       description="Emit a complete shader program or a drop-in library.")
    _surface_args(p)
    _view_args(p)
    _shader_args(p)
    p.add_argument("--emit", choices=("program", "library", "jsurf"), default="program",
                   help="program (default): a complete shader; library: the functions only; "
                        "jsurf: the surface and its view as a SURFER/jsurf .jsurf file")
    p.add_argument("--prefix", default="",
                   help="prefix for every global name (library drop-ins), e.g. cc_ "
                        "(default: none); an identifier start: no leading digit, no '__', "
                        "not gl_ for glsl")
    p.add_argument("-o", "--output", type=Path,
                   help="output file; its extension gives the target when -t is not given "
                        f"({_extension_list(lambda t: t.compile_extensions)}); - or none: "
                        "standard output")
    p.add_argument("--validate", action="store_true",
                   help="validate with the language's real compiler before writing")
    p.set_defaults(run=cmd_compile)

    p = sub.add_parser("validate", help="check shader files with their real compilers",
                       description="Compile each file with its language's real compiler, "
                                   "chosen by extension: "
                                   f"{_extension_list(lambda t: t.extensions)}. Every file "
                                   "is read before any compiler runs; exit 3 if one fails.")
    p.add_argument("files", nargs="+", type=Path, metavar="FILE")
    p.add_argument("--stage", choices=list(dict.fromkeys(
                       stage for t in TARGETS.values() for stage in t.stages)),
                   help="GLSL files only: the shader stage (default: from the extension, "
                        ".vert, .comp, ... or .vert.glsl; .frag and .glsl are frag)")
    p.set_defaults(run=cmd_validate)

    p = sub.add_parser("render", help="render a surface to PNG or EXR (+ JSON sidecar)")
    _surface_args(p)
    _view_args(p)
    _shader_args(p)
    p.add_argument("-b", "--backend", choices=[*BACKENDS, REFERENCE], default=None,
                   help="; ".join([*(f"{name}: {b.about}" for name, b in BACKENDS.items()),
                                   f"{REFERENCE}: {REFERENCE_ABOUT}"])
                   + " (default: the backend of -t, else gl)")
    p.add_argument("--size", type=_int_between(1, MAX_IMAGE), metavar="N",
                   help=f"square image size in pixels, 1 to {MAX_IMAGE} (default 512)")
    p.add_argument("--width", type=_int_between(1, MAX_IMAGE), metavar="W",
                   help="image width in pixels; alone, the image is square (W x W)")
    p.add_argument("--height", type=_int_between(1, MAX_IMAGE), metavar="H",
                   help="image height in pixels; alone, the image is square (H x H)")
    p.add_argument("-o", "--output", type=Path, required=True,
                   help="out.png (for people) or out.exr (R G B A Z steps); out.json beside it")
    p.set_defaults(run=cmd_render)

    p = sub.add_parser("view", help="write a self-contained HTML page that shows a surface live",
                       description="One HTML file, no network: the es300 program in WebGL2 "
                                   "(and the WGSL program on WebGPU where the browser has "
                                   "it), orbit/zoom/pan, a slider per parameter. Its first "
                                   "frame is the surface's [view] camera, like `implc render`.")
    _surface_args(p)
    _view_args(p)
    _method_args(p)
    p.add_argument("--no-webgpu", action="store_true",
                   help="leave the WGSL program out of the page (WebGL2 only)")
    p.add_argument("-o", "--output", type=Path, required=True, metavar="FILE.html",
                   help="the page to write")
    p.set_defaults(run=cmd_view)

    p = sub.add_parser("compare", help="metrics of one EXR render against another",
                       description="SSIM, false/missed hits, wrong-root pixels and steps of "
                                   "render A against render B (typically the reference).")
    p.add_argument("a", type=Path, metavar="A", help="render to judge (EXR + JSON sidecar)")
    p.add_argument("b", type=Path, metavar="B", help="render to judge it by, e.g. the reference")
    p.add_argument("--t-tol", type=_positive_number, default=None,
                   help="wrong-root tolerance on t, scene units (default 1e-3)")
    p.add_argument("--json", action="store_true", help="print the metrics as JSON")
    p.set_defaults(run=cmd_compare)

    p = sub.add_parser("bench", help="the paper's Table 1: fps and accuracy of every method",
                       description="Time every method on each surface and compare it with "
                                   "the exact reference; writes table.md, table.json, "
                                   "figure.png and renders/ into -o DIR.")
    p.add_argument("surfaces", nargs="+", metavar="SURFACE",
                   help="TOML files or bundled example names (e.g. cross-cap miter steiner)")
    p.add_argument("--size", type=_int_between(8, MAX_IMAGE), default=1024,
                   help="square image size in pixels (default 1024, the paper's)")
    p.add_argument("--methods", nargs="+", choices=list(METHOD_NAMES), metavar="METHOD",
                   help="methods to time (default: taylor curvature hessian-approx hessian sign)")
    p.add_argument("--frames", type=_int_between(1, 1000), default=3,
                   help="timed frames per cell after 1 warm-up; fps is their median (default 3)")
    p.add_argument("-b", "--backend", choices=list(BACKENDS),
                   default="gl", help="renderer to time (default gl)")
    p.add_argument("--configs", default="paper,equal,taylor2,extremum",
                   help="comma-separated: paper (Table 1 constants), equal (one step for "
                        "all), taylor2 (Eq. 4 consistent), extremum (implc's test); "
                        "default all four")
    p.add_argument("--equal-step", type=_positive_number, default=None,
                   help="base step of every method in the `equal` configuration (default 0.002)")
    p.add_argument("--exr", action="store_true",
                   help="also write each render as EXR (for `implc compare`; 24 MB at 1024²)")
    p.add_argument("--baseline", action="store_true",
                   help="also time the hand-written GLSL of templates/baseline/ (Cross-Cap, "
                        "taylor and hessian; gl) in turns with the generated programs and "
                        "report generated / hand-written speed")
    p.add_argument("-o", "--output", type=Path, required=True, metavar="DIR",
                   help="output directory (created if missing)")
    p.set_defaults(run=cmd_bench)

    p = sub.add_parser("corpus", help="run implc over a corpus of equations and report",
                       description="Load, derive, numerically check, emit (-m hessian, "
                                   "program) and validate every row of a corpus TSV; "
                                   "report what compiled and why the rest was rejected.")
    p.add_argument("tsv", nargs="?", type=Path, metavar="TSV",
                   help="corpus TSV (default: ../shared/corpus/implicit_surface_corpus.tsv)")
    p.add_argument("-o", "--output", type=Path, help="write the Markdown report here")
    p.add_argument("-t", "--targets", nargs="+", choices=list(TARGETS), default=list(TARGETS),
                   help="targets to emit and validate (default: all)")
    p.add_argument("-j", "--jobs", type=_int_between(0, 64), default=0,
                   help="worker processes (default 0: one per CPU, at most 4)")
    p.add_argument("--rows", help="only these data rows, e.g. 1-20,35")
    p.add_argument("--no-validate", action="store_true", help="emit only; skip the compilers")
    p.add_argument("--no-check", action="store_true", help="skip the numeric checks")
    _limit_args(p)
    p.set_defaults(run=cmd_corpus)

    p = sub.add_parser("gallery", help="a contact sheet of many surfaces (index.html)",
                       description="Render each surface as a thumbnail with its default "
                                   "method and write index.html (name, equation, degree, "
                                   "method, frame time; each thumbnail links to the "
                                   "surface's `implc view` page), contact-sheet.png and "
                                   "the pages into -o DIR. A surface that fails shows its "
                                   "error in its cell.")
    p.add_argument("surfaces", nargs="+", metavar="SURFACE",
                   help="TOML or .jsurf files or bundled example names")
    p.add_argument("--size", type=_int_between(8, 1024), default=160,
                   help="thumbnail side in pixels (default 160)")
    p.add_argument("-b", "--backend", choices=[b for b in BACKENDS if b != REFERENCE],
                   default="gl", help="renderer of the thumbnails (default gl)")
    p.add_argument("--webgpu", action="store_true",
                   help="give the view pages the WebGPU program too (slower to write)")
    p.add_argument("-o", "--output", type=Path, required=True, metavar="DIR",
                   help="output directory (created if missing)")
    p.set_defaults(run=cmd_gallery)
    return parser


def _surface_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("surface", nargs="?",
                   help="TOML file, SURFER .jsurf file or bundled example name")
    p.add_argument("-e", "--equation", help='equation text instead of a file, e.g. "x^2+y^2+z^2=1"')
    p.add_argument("--param", action="append", default=[], metavar="NAME=VALUE",
                   help="set a named parameter (repeatable)")
    _limit_args(p)


def _limit_args(p: argparse.ArgumentParser) -> None:
    limits = p.add_argument_group("limits (hostile-input guards; README \"Limits\")")
    for flag, text in LIMIT_FLAGS.items():
        default = getattr(_default_limits(), flag[2:].replace("-", "_"))
        limits.add_argument(flag, type=_positive_int, metavar="N",
                            help=f"{text} (default {default})")


VIEW_POINT_FLAGS = ("--center", "--eye", "--look-at", "--up")  # values may start with '-'
# [view] key -> its option (`target` is --look-at: -t/--target is the shader language)
VIEW_FLAGS = {"radius": "--radius", "center": "--center", "eye": "--eye",
              "target": "--look-at", "up": "--up", "fov": "--fov"}
VIEW_ABOUT = (
    "Each option overrides the surface file's [view] key of the same name (--look-at: "
    "`target`). Which way is "
    "up: +y is up in the picture (the default `up`) unless the file's [view] sets `up`; an "
    "equation written z-up, like Taubin's heart typed with -e, lies on its side: --up z "
    "stands it up. What neither the file nor an option sets is chosen and printed: "
    "without a radius (every -e) implc finds where S changes sign and puts the clip "
    "sphere around it; without an eye (unless the file sets radius) the camera goes where "
    "the sphere fills the picture (README \"Framing\").")


def _view_args(p: argparse.ArgumentParser) -> None:
    """The camera and clip sphere on the command line (`render`, `view`, `compile`)."""
    v = p.add_argument_group("view", VIEW_ABOUT)
    v.add_argument("--radius", type=_radius_arg, metavar="R",
                   help="clip sphere radius: only what lies inside is drawn (default: the "
                        "file's, else framed automatically)")
    v.add_argument("--center", type=_point_arg, metavar="X,Y,Z",
                   help="clip sphere centre (default: the file's, else the surface's middle "
                        "when framed automatically, else the origin)")
    v.add_argument("--eye", type=_point_arg, metavar="X,Y,Z",
                   help="camera position (default: the file's, else placed where the clip "
                        "sphere fills the picture)")
    v.add_argument("--look-at", type=_point_arg, metavar="X,Y,Z", dest="look_at",
                   help="the point the camera looks at, [view] `target` (default: the "
                        "clip sphere's centre)")
    v.add_argument("--up", type=_up_arg, metavar="x|y|z|X,Y,Z",
                   help="the world direction that is up in the picture (default y: +y is "
                        "up, or the file's `up`); --up z for equations written z-up; -x, "
                        "-y, -z turn it over")
    v.add_argument("--fov", type=_fov_arg, metavar="DEG",
                   help="vertical field of view in degrees (default: the file's, else 30)")
    p.set_defaults(view_options=True)


def _point_arg(text: str) -> tuple[float, float, float]:
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


def _up_arg(text: str) -> tuple[float, float, float]:
    """argparse type of --up: an axis (`z`, `-y`) or a direction `X,Y,Z`."""
    axis = text.strip().lower()
    sign = -1.0 if axis.startswith("-") else 1.0
    if axis.lstrip("+-") in ("x", "y", "z"):
        index = "xyz".index(axis.lstrip("+-"))
        return tuple(sign if i == index else 0.0 for i in range(3))  # type: ignore[return-value]
    if not re.match(r"[\s\[(]*[-+.\d]", text):
        raise argparse.ArgumentTypeError(f"expected x, y, z (or -x, -y, -z) or a direction "
                                         f"X,Y,Z, got {text!r}")
    value = _point_arg(text)
    if not any(value):
        raise argparse.ArgumentTypeError("the up direction must not be 0,0,0")
    return value


def _radius_arg(text: str) -> float:
    return _number_arg(text, 0.0, 1e6, "a clip sphere radius")


def _fov_arg(text: str) -> float:
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


def _extension_list(extensions) -> str:
    """`.frag/.glsl glsl, .wgsl wgsl, ...`: each target's extensions, for the help."""
    return ", ".join("/".join(extensions(t)) + " " + t.name for t in TARGETS.values())


def _shader_args(p: argparse.ArgumentParser) -> None:
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
    _method_args(p)


def _method_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("-m", "--method", choices=list(METHOD_NAMES), default=None,
                   help="root-finding method (default: exact for polynomial surfaces up to "
                        f"degree {EXACT_MAX_DEGREE}, else interval where every function has "
                        "an interval rule (not atan2), else hessian); see README \"The "
                        "methods\"")
    d = Constants()
    c = p.add_argument_group(
        "method constants (defaults: the paper's Table 1)",
        "One the method does not read (--step with exact, any with -b reference) is "
        "ignored with a warning.")
    c.add_argument("--step", type=_positive_number,
                   help="base step b (default 0.01; hessian 0.002)")
    c.add_argument("--tau1", type=_positive_number,
                   help=f"|F| <= tau1: near the surface (default {d.tau1})")
    c.add_argument("--tau2", type=_positive_number,
                   help=f"|F| > tau2: far from it (default {d.tau2})")
    c.add_argument("--tau3", type=_positive_number,
                   help=f"|F'| <= tau3: silhouette (default {d.tau3})")
    c.add_argument("--eps", type=_positive_number,
                   help=f"hessian-approx finite-difference step (default {d.eps})")
    c.add_argument("--taylor2", choices=TAYLOR2_CHOICES,
                   help="Eq. 4 as printed (paper, default), consistent (h^2/8, F''(t1)), or "
                        "extremum (consistent plus each end's extremum inside the step)")
    c.add_argument("--max-steps", type=_int_between(1, MAX_STEPS),
                   help=f"march step cap per ray (default {d.max_steps})")
    p.add_argument("--eval", choices=EVAL_CHOICES, help=(
        "how F, F', F'' are computed along a ray: point (3-D functions of p = o + s d), "
        "ray-poly (polynomial S: the ray polynomial's coefficients once per ray, then "
        "Estrin's scheme), auto (default: ray-poly up to degree "
        f"{AUTO_RAY_POLY_MAX_DEGREE} where its march step evaluates fewer operations, as "
        "`implc show` prints, else point); see README \"Evaluation forms\""))


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
    "--max-derived": "largest estimated size of the derivatives before CSE, in nodes",
}


def _default_limits() -> Limits:
    return Limits()


def _positive_int(text: str) -> int:
    """argparse type of the limit options: a limit of 0 or below is a usage error."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a positive integer, got {text!r}") from None
    if not 1 <= value <= 10**9:
        raise argparse.ArgumentTypeError(f"expected an integer from 1 to 10^9, got {text}")
    return value


MAX_IMAGE = 8192  # the largest image side, in pixels
MAX_STEPS = 10_000_000  # the largest --max-steps


def _int_between(low: int, high: int):
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


def _positive_number(text: str) -> float:
    """argparse type of the method constants and tolerances: 0 < value < 1e6."""
    try:
        value = float(text)
    except ValueError:
        value = float("nan")
    if not 0.0 < value < 1e6:  # also nan and inf
        raise argparse.ArgumentTypeError(f"expected a positive number below 1e6, got {text!r}")
    return value


def _limits(args) -> Limits:
    given = {flag[2:].replace("-", "_"): getattr(args, flag[2:].replace("-", "_"))
             for flag in LIMIT_FLAGS}
    return Limits(**{k: v for k, v in given.items() if v is not None})


def _surface(args, aspect: float = 1.0):
    """The surface; for `render`, `view` and `compile` with the view options applied and
    a view framed automatically where none is given (`aspect`: the frame's width /
    height, when known)."""
    from .surface import load_surface

    if (args.surface is None) == (args.equation is None):
        raise UsageError("give a surface (a file or a bundled example name) or -e EQUATION"
                         + (", not both" if args.surface is not None else ""))
    surface = load_surface(args.surface, args.equation, args.param, _limits(args))
    for note in surface.notes:  # a .jsurf file's keys implc does not use, said once
        print(note, file=sys.stderr)
    if getattr(args, "view_options", False):
        surface = _with_view(args, surface, aspect)
    return surface


_NOTES: list[str] = []  # stderr lines kept until the command succeeds (_print_notes)


def _print_notes() -> None:
    while _NOTES:
        print(_NOTES.pop(0), file=sys.stderr)


def _with_view(args, surface, aspect: float):
    """`surface` with the view the command line and automatic framing give it; what
    framing chose is printed when the command succeeds (a refused or interrupted one
    prints its error only)."""
    import dataclasses

    from .derive import check_derived_size
    from .extent import SEARCHED, locate_surface
    from .scene import ViewOptions, apply_view, view_problems

    check_derived_size(surface.expr)  # refuse a too complex surface before sampling it

    options = ViewOptions(radius=args.radius, center=args.center, eye=args.eye,
                          target=args.look_at, up=args.up, fov=args.fov)
    view, framing = apply_view(surface.view, options,
                               lambda center: locate_surface(surface.expr, center),
                               aspect, SEARCHED)
    problems = view_problems(view)
    if problems:
        flags = " ".join(VIEW_FLAGS[key] for key in sorted(options.given()))
        if flags:
            raise UsageError(f"{flags}: the view shows nothing: {problems[0][1]}")
        raise InputError(f"{surface.origin}: [view] {problems[0][1]}")
    if framing is not None:
        _NOTES.append(framing.message())
    return dataclasses.replace(surface, view=view)


# Constants field -> (argparse dest, the option that sets it); ranges are checked by the
# options' types (a bad value is a usage error)
CONSTANT_OPTIONS = {
    "step": ("step", "--step"), "tau1": ("tau1", "--tau1"), "tau2": ("tau2", "--tau2"),
    "tau3": ("tau3", "--tau3"), "eps": ("eps", "--eps"), "taylor2": ("taylor2", "--taylor2"),
    "max_steps": ("max_steps", "--max-steps"), "evaluation": ("eval", "--eval"),
}


def _constants(args) -> Constants:
    from .methods import METHODS

    values = {field: getattr(args, dest) for field, (dest, _) in CONSTANT_OPTIONS.items()}
    return METHODS[args.method].constants(**values)


def _warn(args, message: str) -> None:
    print(f"implc {args.command}: warning: {message}", file=sys.stderr)


def _spoken(flags: list[str]) -> str:
    """['--step', '--tau1'] -> '--step and --tau1 do'."""
    listed = flags[0] if len(flags) == 1 else ", ".join(flags[:-1]) + " and " + flags[-1]
    return listed + (" does" if len(flags) == 1 else " do")


def _warn_ignored(args, backend: str | None = None) -> None:
    """A method constant the method does not read (--step with exact), or any method
    option with the CPU reference, is said on stderr and ignored (exit 0), never dropped
    silently (README "Command line"). What a method reads comes from its data
    (`Method.reads`), not from a list here."""
    given = [(field, flag) for field, (dest, flag) in CONSTANT_OPTIONS.items()
             if getattr(args, dest) is not None]
    if backend == REFERENCE:
        flags = (["-m"] if args.method_given else []) + [flag for _, flag in given]
        if args.flavor is not None:
            flags.append("--flavor")
        if flags:
            _warn(args, f"{_spoken(flags)} not apply to -b reference (the exact CPU "
                        "reference runs no method and no shader): ignored")
        return
    from .methods import METHODS

    reads = METHODS[args.method].reads
    ignored = [flag for field, flag in given if field not in reads]
    if ignored:
        which = "" if args.method_given else " (the default for this surface)"
        used = [flag for field, (_, flag) in CONSTANT_OPTIONS.items() if field in reads]
        _warn(args, f"{_spoken(ignored)} not apply to method {args.method}{which}, which "
                    f"reads {', '.join(used) if used else 'none of the method constants'}: "
                    "ignored")


def cmd_list(args) -> int:
    from .derive import polynomial_degree
    from .surface import example_paths, load_surface

    for name in example_paths():
        surface = load_surface(name)
        degree = polynomial_degree(surface.expr)
        kind = f"deg {degree}" if degree else "non-poly"
        equation, *substituted = surface.equation_lines()  # names, then values if any
        print(f"{name:<18} {kind:<9} {equation}")
        for line in substituted:
            print(f"{'':<28} {line}")
    return EXIT_OK


def _resolve_method(args, surface) -> None:
    """-m's default depends on the surface (marcher.default_method)."""
    from .marcher import default_method

    args.method_given = args.method is not None
    if args.method is None:
        args.method = default_method(surface.expr)


def cmd_show(args) -> int:
    from .methods import METHODS
    from .show import describe

    surface = _surface(args)
    _resolve_method(args, surface)
    print(describe(surface, METHODS[args.method]))
    return EXIT_OK


def shader_extensions(target: str) -> tuple[str, ...]:
    """File extensions `compile -o` writes for `target` (its record's: what `implc
    validate` reads back as the same emit, a fragment shader or library for glsl)."""
    return TARGETS[target].compile_extensions


def _compile_target(args) -> str:
    """-t, else the language of -o's extension (read as `implc validate` reads it: `-o
    x.wgsl` is WGSL), else glsl."""
    if args.target is not None:
        return args.target
    if args.output is None:
        return "glsl"
    every = tuple(ext for name in TARGETS for ext in shader_extensions(name))
    check_output(args.output, every, what="a shader")  # a directory, or no language's
    return target_of_file(args.output.suffix.lower()).name


def _check_shader_options(args, target: Target) -> None:
    """--flavor, --precision and --prefix against the target: a usage error (exit 2),
    before any work."""
    if args.flavor is not None and (
            problem := flavor_problem(target, args.flavor, args.precision or "float")):
        raise UsageError(f"--flavor: {problem}")
    if args.precision is not None and args.precision not in target.precisions:
        others = [t.name for t in TARGETS.values() if args.precision in t.precisions]
        raise UsageError(f"--precision {args.precision}: {target.name} has "
                         f"{' or '.join(target.precisions)} only ({args.precision}: "
                         f"{', '.join(others)})")
    if problem := prefix_problem(args.prefix, target):
        raise UsageError(problem)


def cmd_compile(args) -> int:
    if args.output is not None and str(args.output) == "-":
        args.output = None  # `-o -`: standard output
    if args.emit == "jsurf":
        return _compile_jsurf(args)
    args.target = target = _compile_target(args)
    _check_shader_options(args, TARGETS[target])
    if args.output:
        check_output(args.output, shader_extensions(target), what=f"the {target} shader")
    from .emit import emit

    surface = _surface(args)
    _resolve_method(args, surface)
    constants = _constants(args)
    _warn_ignored(args)
    text = emit(surface, target, args.method, constants, args.flavor, args.emit,
                args.prefix, precision=args.precision, params=args.params)
    if args.validate:
        from .validate import validate_text

        name = str(args.output) if args.output else f"<stdout>.{args.target}"
        verdict = validate_text(text, args.target, name)
        if not verdict.ok:
            raise ValidationError(verdict.render(name))
        print(verdict.render(name), file=sys.stderr)
    warning = None
    if args.precision is None:
        target = TARGETS[args.target]
        flavor = args.flavor or target.default_flavor
        warning = _float32_warning(args, surface, "try --precision double"
                                   if "double" in target.precisions
                                   and flavor_problem(target, flavor, "double") is None
                                   else "--precision double is in "
                                   + where_precision("double"))
    if args.output:
        write_atomic(args.output, text)
    else:
        sys.stdout.write(text)
    if warning:
        _warn(args, warning)
    return EXIT_OK


def _float32_warning(args, surface, remedy: str) -> str | None:
    """The warning where float32, the default precision, cannot hold a polynomial surface
    for the method (show.Float32Report: `implc show` prints both measures), to print once
    the command has succeeded; it is measured before any output is written, so an
    interrupt there leaves none. An explicit --precision float says the user knows."""
    from .derive import polynomial_degree
    from .show import float32_report
    from .solver import ROBUST_NEWTON_BELOW

    degree = polynomial_degree(surface.expr)
    if degree is None:
        return None
    # exact's warning from degree 7 is its own coefficients' (the other measure, S's at
    # sampled points, costs 0.04-0.3 s more and speaks for every method)
    report = float32_report(surface.expr, surface.view, degree,
                            point=args.method != "exact" or degree < ROBUST_NEWTON_BELOW)
    message = report.warning(args.method)
    return f"{message}; {remedy}" if message else None


def _compile_jsurf(args) -> int:
    """`compile --emit jsurf`: the surface, its view and colours as a .jsurf file (the
    shader options do not apply)."""
    from .jsurf import to_jsurf

    if args.output:
        check_output(args.output, (".jsurf",), what="a .jsurf file")
    text = to_jsurf(_surface(args))
    if args.output:
        write_atomic(args.output, text)
    else:
        sys.stdout.write(text)
    return EXIT_OK


def cmd_gallery(args) -> int:
    from .gallery import run_gallery

    check_output_dir(args.output, what="gallery output directory")
    cells = run_gallery(args.surfaces, args.output, size=args.size, backend=args.backend,
                        webgpu=args.webgpu)
    failed = sum(1 for cell in cells if cell.error)
    print(f"wrote {args.output / 'index.html'} ({len(cells)} surfaces"
          + (f", {failed} failed: see their cells" if failed else "") + ")")
    return EXIT_OK


def cmd_validate(args) -> int:
    """Every file is checked (exists, readable, known extension, UTF-8) before any
    compiler runs: a bad input is exit 1, a shader its compiler rejects exit 3."""
    from .targets import target_of_file
    from .validate import check_source, validate_text

    sources = []
    for path in args.files:
        target = target_of_file(path.suffix)
        if target is None:
            known = " ".join(sorted(ext for t in TARGETS.values() for ext in t.extensions))
            raise InputError(f"{path}: unknown shader extension '{path.suffix}' "
                             f"(known: {known})")
        if args.stage and args.stage not in target.stages:
            raise UsageError(f"--stage applies to GLSL files only; {path} is {target.name}")
        text = read_input_text(path)
        check_source(text, str(path))
        sources.append((path, target.name, text))
    failed = 0
    for path, target, text in sources:
        verdict = validate_text(text, target, str(path), stage=args.stage)
        print(verdict.render(str(path)), file=sys.stdout if verdict.ok else sys.stderr)
        failed += not verdict.ok
    return EXIT_INVALID if failed else EXIT_OK


def read_input_text(path: Path, limit: int = 50_000_000) -> str:
    """A text input file, or an InputError saying in one line why it cannot be read."""
    data = read_input(path, "a shader file")
    if len(data) > limit:
        raise InputError(f"{path}: larger than {limit} bytes")
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as err:
        raise InputError(f"{path}: not UTF-8 text (byte {err.start})") from None


def _render_backend(args) -> str:
    """-b, or the backend of -t's language (`-t wgsl` renders with wgpu), else gl; at
    --precision's backend (`-b cl --precision double` is cl-double). A contradiction
    (`-t wgsl -b gl`), or a --flavor the backend does not run, is a usage error."""
    from .render.run import backend_for

    backend = args.backend
    if args.target is not None:
        target = TARGETS[args.target]
        if backend is None:
            backend = next(iter(target.backends))
        elif backend not in target.backends:
            raise UsageError(f"-t {target.name} renders with -b "
                             f"{' or '.join(target.backends)}, not -b {backend}")
    backend = backend or "gl"
    try:
        backend = backend_for(backend, args.precision)  # a precision is a backend of its own
    except InputError as err:
        raise UsageError(err.message) from None
    target = next((t for t in TARGETS.values() if backend in t.backends), None)
    if target is not None and args.flavor is not None:
        if problem := flavor_problem(target, args.flavor):
            raise UsageError(f"--flavor: {problem}")
        if args.flavor != target.default_flavor:  # the program every backend runs
            raise UsageError(f"--flavor {args.flavor}: -b {backend} renders the "
                             f"{target.default_flavor} program; the other flavours are for "
                             "`implc compile`")
    return backend


def cmd_render(args) -> int:
    from .render.run import render_surface

    width, height = _size(args)
    backend = _render_backend(args)
    check_output(args.output, (".png", ".exr"), what="a render",
                 companions=[args.output.with_suffix(".json")])
    surface = _surface(args, width / height)
    _resolve_method(args, surface)
    _warn_ignored(args, backend)
    _check_frame(surface, width, height)
    warning = None
    if args.precision is None and backend != REFERENCE and BACKENDS[backend].precision == "float":
        from .render.run import backend_for

        try:
            remedy = f"try -b {backend_for(backend, 'double')}"
        except InputError:
            remedy = f"double precision renders with -b {' or '.join(backends_in('double'))}"
        warning = _float32_warning(args, surface, remedy)
    start = time.perf_counter()
    paths, result = render_surface(surface, backend, args.method, _constants(args), width,
                                   height, args.output, params=args.params)
    elapsed = time.perf_counter() - start
    timing = result.timing
    _print_notes()
    for path in paths:
        print(f"wrote {path}")
    what = backend if backend == "reference" else f"{backend}/{args.method}"
    phases = ", ".join(f"{name} {timing[name]:.3f} s" for name in ("setup", "compile", "frame")
                       if name in timing)
    print(f"rendered {width}x{height} with {what} in {elapsed:.2f} s ({phases}); "
          f"{_percent(result.hit)} of pixels hit", file=sys.stderr)
    for line in _render_warnings(surface, result, given_radius=args.radius is not None):
        print(line, file=sys.stderr)
    if warning:
        _warn(args, warning)
    return EXIT_OK


def _percent(hit) -> str:
    """`38.4 %`; a few hits are `< 0.1 %`, not `0.0 %`."""
    share = 100.0 * float(hit.mean())
    return "< 0.1 %" if 0.0 < share < 0.1 else f"{share:.1f} %"


def _render_warnings(surface, result, given_radius: bool) -> list[str]:
    """What a user should know about a picture (exit 0): nothing hit, or the surface cut
    by a clip sphere the file or --radius gave (a framed one says so when it frames)."""
    from .extent import SEARCHED, crosses_sphere, locate_surface
    from .scene import point_text

    view = surface.view
    sphere = (f"the clip sphere (center {point_text(view.clip_center)}, radius "
              f"{view.clip_radius:g})")
    if not result.hit.any():
        extent = locate_surface(surface.expr)
        if extent is None:
            return [f"implc: warning: no pixel hits the surface, and S changes sign nowhere "
                    f"in |x|,|y|,|z| <= {SEARCHED:g}: the equation may have no real "
                    "points (S > 0 or S < 0 everywhere), or a part thinner than the search "
                    "grid; --radius, --center to look elsewhere"]
        where = f"--radius {extent.radius:g}"
        if extent.center != tuple(view.clip_center):
            where += f" --center {','.join(f'{c:g}' for c in extent.center)}"
        found = (f"is found within radius {extent.radius:g} of {point_text(extent.center)}"
                 if extent.bounded else f"passes near {point_text(extent.center)} (unbounded?)")
        return [f"implc: warning: no pixel hits the surface inside {sphere}; the surface "
                f"{found}: try {where}"]
    if not ("radius" in view.given or given_radius):
        return []
    if not crosses_sphere(surface.expr, view.clip_center, view.clip_radius):
        return []
    extent = locate_surface(surface.expr, view.clip_center)
    if extent is not None and not extent.bounded:
        return [f"implc: note: the surface reaches {sphere}, and past |x|,|y|,|z| <= "
                f"{SEARCHED:g} (unbounded?): the picture shows the part inside the sphere; "
                "--radius to show more"]
    hint = f"--radius {extent.radius:g} holds all of it" if extent else "--radius to widen it"
    return [f"implc: warning: the surface reaches {sphere}: the picture is clipped there; "
            f"{hint}"]


def cmd_view(args) -> int:
    from .view import viewer_page

    check_output(args.output, (".html", ".htm"), what="the viewer page")
    surface = _surface(args)
    _resolve_method(args, surface)
    _warn_ignored(args)
    page = viewer_page(surface, args.method, _constants(args), webgpu=not args.no_webgpu)
    warning = _float32_warning(args, surface, "WebGL2 and WebGPU have no double; for the "
                               "picture, `implc render -b "
                               + " or ".join(backends_in("double")) + "`")
    write_atomic(args.output, page)
    print(f"wrote {args.output}")
    print(f"open file://{args.output.resolve()} in a browser", file=sys.stderr)
    if warning:
        _warn(args, warning)
    return EXIT_OK


def cmd_compare(args) -> int:
    import json

    from .compare import compare_files, format_metrics
    from .options import T_TOL

    t_tol = T_TOL if args.t_tol is None else args.t_tol  # its type checks the range
    metrics = compare_files(args.a, args.b, t_tol)
    print(json.dumps(metrics, indent=2) if args.json else format_metrics(metrics))
    return EXIT_OK


def cmd_bench(args) -> int:
    from .bench import DEFAULT_METHODS, EQUAL_STEP, make_configs, run_bench
    from .surface import load_surface

    configs = [name.strip() for name in args.configs.split(",") if name.strip()]
    try:
        make_configs(configs)
    except InputError as err:
        raise UsageError(f"--configs: {err.message}") from None
    twice = [m for i, m in enumerate(args.methods or ()) if m in args.methods[:i]]
    if twice:
        raise UsageError(f"--methods: {twice[0]} is listed twice")
    check_output_dir(args.output, what="bench output directory")
    surfaces = {}
    for spec in args.surfaces:
        key = Path(spec).stem
        if key in surfaces:
            raise InputError(f"surface '{key}' is given twice")
        surfaces[key] = load_surface(spec)
        for note in surfaces[key].notes:
            print(note, file=sys.stderr)
    run_bench(
        surfaces, args.output, size=args.size, methods=args.methods or DEFAULT_METHODS,
        frames=args.frames, backend=args.backend, configs=configs,
        equal_step=EQUAL_STEP if args.equal_step is None else args.equal_step, exr=args.exr,
        baseline=args.baseline,
    )
    return EXIT_OK


def cmd_corpus(args) -> int:
    from . import corpus, corpus_report

    wanted = _row_numbers(args.rows) if args.rows else None  # a usage error first
    if args.output:
        check_output(args.output, (".md",), what="the corpus report (Markdown)")
    tsv = args.tsv or corpus.default_tsv()
    if tsv is None:
        raise InputError("no corpus found at ../shared/corpus/implicit_surface_corpus.tsv; "
                         "give the TSV path (tests/data/corpus_permissive.tsv is a copy of "
                         "its permissively licensed rows)")
    rows = corpus.load_rows(tsv)
    if wanted is not None:
        rows = [r for r in rows if r.number in wanted]
    jobs = corpus.effective_jobs(args.jobs)
    from .progress import Progress

    bar = Progress(len(rows), "corpus", sys.stderr, unit="row")

    def progress(result) -> None:
        line = None
        if result.outcome != corpus.COMPILED:
            line = (f"row {result.row.number} ({result.row.name}): {result.outcome}: "
                    f"{result.reason}")
        if bar.bar is not None:
            bar.step(f"row {result.row.number}")
            if line:
                bar.note(line)
        elif line:
            print(line, file=sys.stderr, flush=True)

    start = time.perf_counter()
    try:
        results = corpus.run_corpus(rows, args.targets, validate=not args.no_validate,
                                    check=not args.no_check, jobs=jobs, limits=_limits(args),
                                    progress=progress)
    finally:
        bar.close()
    wall = time.perf_counter() - start
    if args.output:
        report = corpus_report.render_report(results, os.path.relpath(tsv), args.targets, wall,
                                             jobs, validate=not args.no_validate)
        write_atomic(args.output, report)
        print(f"wrote {args.output}", file=sys.stderr)
    print(corpus_report.summary_line(results, args.targets) + f" ({wall:.0f} s)")
    return 3 if any(r.outcome == corpus.FAILED for r in results) else EXIT_OK


def _row_numbers(text: str) -> set[int]:
    """`1-20,35` -> {1, ..., 20, 35}."""
    numbers: set[int] = set()
    for part in text.split(","):
        low, _, high = part.strip().partition("-")
        try:
            first, last = int(low), int(high or low)
        except ValueError:
            raise UsageError(f"--rows: expected numbers like 1-20,35, got {text!r}") from None
        numbers.update(range(first, last + 1))
    return numbers


def _check_frame(surface, width: int, height: int) -> None:
    """A view that would render a blank frame at this size is an error, not a picture."""
    from .scene import frame_problem

    problem = frame_problem(surface.view, width, height)
    if problem:
        raise InputError(f"{surface.origin}: [view] {problem} ({width}x{height})")


def _size(args) -> tuple[int, int]:
    """--size N, or --width/--height (each defaults to the other, then to 512). The
    options' type refuses 0 (an error, not "not given")."""
    if args.size is not None and (args.width is not None or args.height is not None):
        raise UsageError("give --size or --width/--height, not both")
    width = next((v for v in (args.width, args.size, args.height) if v is not None), 512)
    height = next((v for v in (args.height, args.size, args.width) if v is not None), 512)
    return width, height
