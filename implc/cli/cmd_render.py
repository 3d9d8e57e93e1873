"""`implc render`: a picture (PNG) or data (EXR), and a JSON sidecar."""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

from ..errors import EXIT_OK, InputError
from ..fileio import check_output
from ..options import MAX_IMAGE
from ..render.run import BACKENDS, REFERENCE, REFERENCE_ABOUT
from ..targets import TARGETS, backends_in, flavor_problem
from . import args as common
from .args import UsageError


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("render", help="render a surface to PNG or EXR (+ JSON sidecar)")
    common.surface_args(p)
    common.view_args(p)
    common.shader_args(p)
    p.add_argument("-b", "--backend", choices=[*BACKENDS, REFERENCE], default=None,
                   help="; ".join([*(f"{name}: {b.about}" for name, b in BACKENDS.items()),
                                   f"{REFERENCE}: {REFERENCE_ABOUT}"])
                   + " (default: the backend of -t, else gl)")
    p.add_argument("--size", type=common.int_between(1, MAX_IMAGE), metavar="N",
                   help=f"square image size in pixels, 1 to {MAX_IMAGE} (default 512)")
    p.add_argument("--width", type=common.int_between(1, MAX_IMAGE), metavar="W",
                   help="image width in pixels; alone, the image is square (W x W)")
    p.add_argument("--height", type=common.int_between(1, MAX_IMAGE), metavar="H",
                   help="image height in pixels; alone, the image is square (H x H)")
    p.add_argument("-o", "--output", type=Path, required=True,
                   help="out.png (for people) or out.exr (R G B A Z steps); out.json beside it")


def run(args: argparse.Namespace) -> int:
    from ..framing import check_frame

    width, height = _size(args)
    backend = _backend(args)
    check_output(args.output, (".png", ".exr"), what="a render",
                 sidecars=(".json",))
    surface = common.surface(args)
    record, _ = surface.framed()
    method = args.method or surface.default_method
    common.warn_ignored(args, method, reference=backend == REFERENCE)
    check_frame(record, width, height)
    start = time.perf_counter()
    constants = {} if backend == REFERENCE else common.constants_given(args)
    rendering = surface.render(width=width, height=height, backend=backend, method=method,
                               params=args.params, **constants)
    paths = rendering.save(args.output)
    elapsed = time.perf_counter() - start
    timing = rendering.timing
    for note in rendering.notes:
        print(note, file=sys.stderr)
    for path in paths:
        print(f"wrote {path}")
    what = backend if backend == REFERENCE else f"{backend}/{method}"
    phases = ", ".join(f"{name} {timing[name]:.3f} s" for name in ("setup", "compile", "frame")
                       if name in timing)
    print(f"rendered {width}x{height} with {what} in {elapsed:.2f} s ({phases}); "
          f"{_percent(rendering.hit_fraction)} of pixels hit", file=sys.stderr)
    for line in rendering.picture_warnings:
        print(line, file=sys.stderr)
    shader = rendering.shader
    if args.precision is None and shader is not None and shader.float32:
        common.warn(args, f"{shader.float32}; {_remedy(backend)}")
    return EXIT_OK


def _remedy(backend: str) -> str:
    from ..render.run import backend_for

    try:
        return f"try -b {backend_for(backend, 'double')}"
    except InputError:
        return f"double precision renders with -b {' or '.join(backends_in('double'))}"


def _percent(share: float) -> str:
    """`38.4 %`; a few hits are `< 0.1 %`, not `0.0 %`."""
    share = 100.0 * share
    return "< 0.1 %" if 0.0 < share < 0.1 else f"{share:.1f} %"


def _backend(args: argparse.Namespace) -> str:
    """-b, or the backend of -t's language (`-t wgsl` renders with wgpu), else gl; at
    --precision's backend (`-b cl --precision double` is cl-double). A contradiction
    (`-t wgsl -b gl`), or a --flavor the backend does not run, is a usage error."""
    from ..api.rendering import choose_backend

    backend = args.backend
    if args.target is not None:
        target = TARGETS[args.target]
        if backend is None:
            backend = next(iter(target.backends))
        elif backend not in target.backends:
            raise UsageError(f"-t {target.name} renders with -b "
                             f"{' or '.join(target.backends)}, not -b {backend}")
    backend = choose_backend(backend, args.precision)  # a precision is a backend of its own
    target = next((t for t in TARGETS.values() if backend in t.backends), None)
    if target is not None and args.flavor is not None:
        if problem := flavor_problem(target, args.flavor):
            raise UsageError(f"--flavor: {problem}")
        runs = BACKENDS[backend].flavor or target.default_flavor
        if args.flavor != runs:  # the program the backend runs
            raise UsageError(f"--flavor {args.flavor}: -b {backend} renders the "
                             f"{runs} program; the other flavours are for "
                             "`implc compile`")
    return backend


def _size(args: argparse.Namespace) -> tuple[int, int]:
    """--size N, or --width/--height (each defaults to the other, then to 512). The
    options' type refuses 0 (an error, not "not given")."""
    if args.size is not None and (args.width is not None or args.height is not None):
        raise UsageError("give --size or --width/--height, not both")
    from ..api.rendering import picture_size

    return picture_size(args.size, args.width, args.height)
