"""The frame table for a machine with a real GPU (issue 49): every method (exact, taylor,
hessian, interval) over the degree sweep's Chmutov surfaces T_n, n = 2-20, and the
hand-written baselines beside their generated programs (Yuksel's solver beside exact at
T_4, T_10, T_16 and T_20), at 1024^2 and 2048^2, with the
device named. Every figure on docs/RESULTS.md is llvmpipe's, a CPU's; this is how to
check them on a GPU (`make gpu-bench`).

    python scripts/gpu_bench.py                      gl backend, 1024 and 2048, degree 2-20
    python scripts/gpu_bench.py --backend wgpu --sizes 1024 --degrees 4-12 --frames 20

Frames only, medians of --frames after a warm-up, taken in turns (implc's bench harness,
time_interleaved); no reference image (its certified CPU reference takes an hour a frame
at degree 20). Programs are float32, framed as implc frames them; the last column says
where float32 cannot hold the surface (Chmutov from degree 16: implc's compile warns, and
its pictures there are float32's, not the surface's; `make forms` times double there).
"""

from __future__ import annotations

import argparse
import statistics
import sys

from eval_forms import _degrees, float32_holds, sweep_equations

from implc.baseline import BASELINES, SOLVERS, open_baseline_runner, open_solver_runner
from implc.bench import time_interleaved
from implc.loaders import load_surface
from implc.methods import get_method
from implc.render.run import open_runner

METHODS = ("exact", "taylor", "hessian", "interval")
SOLVER_DEGREES = (4, 10, 16, 20)  # Chmutov T_n for the hand-written solvers (SOLVERS)
CPU_RENDERERS = ("llvmpipe", "lavapipe", "softpipe", "swiftshader")


def device_name(backend: str) -> str:
    """The renderer the backend draws on, as its driver names it."""
    if backend in ("gl", "hlsl-spirv"):
        from implc.render.gl import renderer_name

        return renderer_name()
    if backend == "wgpu":
        from implc.devices import wgpu_device

        info = wgpu_device().adapter.info
        return f"{info.get('device', '?')} ({info.get('backend_type', '?')})"
    if backend == "cl":
        from implc.devices import opencl_device

        return str(opencl_device().name)
    return backend


def median_ms(runners: list, frames: int) -> list[float]:
    """Each runner's median frame in ms, all timed in the same rounds; then released."""
    try:
        seconds, _, _ = time_interleaved(runners, frames)
    finally:
        for runner in runners:
            runner.release()
    return [1000 * statistics.median(s) for s in seconds]


def sweep(backend: str, size: int, degrees: list[int], frames: int) -> None:
    print(f"\n### Chmutov T_n at {size}², backend {backend}, median ms of {frames} frames\n")
    print("| degree | " + " | ".join(f"{m} ms" for m in METHODS)
          + " | exact / taylor | float32 holds S |")
    print("|---|" + "---|" * (len(METHODS) + 2))
    for degree in degrees:
        surface = load_surface(equation=sweep_equations(degree)["chmutov"])
        ms = median_ms([open_runner(surface, backend, m, get_method(m).defaults, size, size)
                        for m in METHODS], frames)
        print(f"| {degree} | " + " | ".join(f"{x:.2f}" for x in ms)
              + f" | {ms[0] / ms[1]:.2f} | {'yes' if float32_holds(surface) else 'no'} |",
              flush=True)


def baselines(size: int, frames: int) -> None:
    """Generated against hand-written (templates/baseline/, GLSL on gl), same constants."""
    print(f"\n### Generated against hand-written at {size}², backend gl\n")
    print("| surface | method | generated ms | hand-written ms | generated speed / hand-written |")
    print("|---|---|---|---|---|")
    for (key, method) in BASELINES:
        surface = load_surface(key)
        constants = get_method(method).defaults
        generated, written = median_ms(
            [open_runner(surface, "gl", method, constants, size, size),
             open_baseline_runner(key, method, constants, surface, size, size)], frames)
        print(f"| {key} | {method} | {generated:.2f} | {written:.2f} | "
              f"{written / generated:.2f} |", flush=True)
    for name, solver in SOLVERS.items():  # for any polynomial: Chmutov T_n (float32)
        constants = get_method(solver.method).defaults
        for degree in SOLVER_DEGREES:
            surface = load_surface(equation=sweep_equations(degree)["chmutov"])
            generated, written = median_ms(
                [open_runner(surface, "gl", solver.method, constants, size, size),
                 open_solver_runner(name, surface, constants, size, size)], frames)
            print(f"| Chmutov T{degree} | {solver.method} ({name}) | {generated:.2f} | "
                  f"{written:.2f} | {written / generated:.2f} |", flush=True)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--backend", default="gl", choices=("gl", "wgpu", "hlsl-spirv", "cl"))
    ap.add_argument("--sizes", default="1024,2048")
    ap.add_argument("--degrees", default="2-20")
    ap.add_argument("--frames", type=int, default=10)
    args = ap.parse_args()
    device = device_name(args.backend)
    print(f"## implc on {device} (backend {args.backend})")
    if any(name in device.lower() for name in CPU_RENDERERS):
        print(f"\nnote: {device} is a CPU renderer, not a GPU: these are CPU figures "
              "(on a machine with a GPU, check its driver is the one EGL/Vulkan picks)",
              file=sys.stderr)
    for size in (int(s) for s in args.sizes.split(",")):
        sweep(args.backend, size, _degrees(args.degrees), args.frames)
        if args.backend == "gl":
            baselines(size, args.frames)


if __name__ == "__main__":
    main()
