"""Point versus ray-poly evaluation: accuracy against the exact reference, frame time and
compile time, on named surfaces and on degree sweeps (docs/RESULTS.md, "Evaluation
forms", and docs/cost-growth.png).

    python scripts/eval_forms.py accuracy --size 512 cross-cap miter ...   markdown table
    python scripts/eval_forms.py sweep --size 256 --plot docs/cost-growth.png

Each surface's programs (one per form and method) are timed in turns in one GL context
(llvmpipe here), one warm-up frame then --frames frames, medians; compile time is a cold
`implc compile` subprocess (imports included), median of 3.
"""

from __future__ import annotations

import argparse
import statistics
import subprocess
import sys
import time

from implc.bench import time_interleaved
from implc.methods import get_method
from implc.metrics import compare
from implc.render.run import open_runner
from implc.surface import load_surface

FORMS = ("point", "ray-poly")


def sweep_equations(degree: int) -> dict[str, str]:
    """Two families of degree n: sums of n-th powers (small coefficients) and Chmutov
    surfaces T_n(x) + T_n(y) + T_n(z) = 0 (coefficients up to 2^(n-1), many sheets)."""
    import sympy

    x = sympy.Symbol("x")
    t = sympy.Poly(sympy.chebyshevt(degree, x), x)
    cheb = " + ".join(f"({c})*{v}^{k}" for (k,), c in t.terms() for v in "xyz" if c) \
        if degree else "3"
    return {"powers": f"x^{degree} + y^{degree} + z^{degree} - 1", "chmutov": cheb}


def measure(surface, methods: list[str], size: int, frames: int, exact: bool = False) -> dict:
    """Per (method, form): median ms and the metrics against the reference; with `exact`
    also ("exact", "ray-poly"), timed in the same rounds."""
    reference = open_runner(surface, "reference", "", get_method("taylor").defaults,
                            size, size).frame()
    keys, runners = [], []
    try:
        for method in methods:
            for form in FORMS:
                constants = get_method(method).constants(evaluation=form)
                runners.append(open_runner(surface, "gl", method, constants, size, size))
                keys.append((method, form))
        if exact:
            runners.append(open_runner(surface, "gl", "exact", get_method("exact").defaults,
                                       size, size))
            keys.append(("exact", "ray-poly"))
        seconds, last, _ = time_interleaved(runners, frames)
    finally:
        for r in runners:
            r.release()
    return {key: {"ms": 1000 * statistics.median(s), **compare(result, reference)}
            for key, s, result in zip(keys, seconds, last, strict=True)}


def compile_seconds(args: list[str], repeats: int = 3) -> float:
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        subprocess.run([sys.executable, "-m", "implc", "compile", *args],
                       check=True, capture_output=True)
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def accuracy(names: list[str], methods: list[str], size: int, frames: int) -> None:
    print(f"| surface | method | {' | '.join(f'{f} ms' for f in FORMS)} | "
          f"{' | '.join(f'{f} false / missed / wrong' for f in FORMS)} |")
    print("|---|---|" + "---|" * (2 * len(FORMS)))
    for name in names:
        results = measure(load_surface(name), methods, size, frames)
        for method in methods:
            cells = [results[method, f] for f in FORMS]
            times = " | ".join(f"{c['ms']:.1f}" for c in cells)
            counts = " | ".join(f"{c['false_hits']} / {c['missed_hits']} / {c['wrong_root']}"
                                for c in cells)
            print(f"| {name} | {method} | {times} | {counts} |", flush=True)


def sweep(degrees: list[int], method: str, size: int, frames: int, plot: str | None) -> None:
    rows = []
    print(f"| family | degree | {' | '.join(f'{method} {f} ms' for f in FORMS)} | exact ms | "
          f"{' | '.join(f'{f} compile s' for f in FORMS)} | exact compile s | "
          f"{' | '.join(f'{f} false / missed / wrong' for f in FORMS)} | "
          "exact false / missed / wrong |")
    print("|---|---|" + "---|" * (3 * len(FORMS) + 3))
    for degree in degrees:
        for family, equation in sweep_equations(degree).items():
            surface = load_surface(equation=equation)
            results = measure(surface, [method], size, frames, exact=True)
            compile_s = {f: compile_seconds(["-e", equation, "-m", method, "--eval", f])
                         for f in FORMS}
            compile_s["exact"] = compile_seconds(["-e", equation, "-m", "exact"])
            cells = [results[method, f] for f in FORMS] + [results["exact", "ray-poly"]]
            rows.append((family, degree, cells, compile_s))
            print(f"| {family} | {degree} | "
                  + " | ".join(f"{c['ms']:.1f}" for c in cells) + " | "
                  + " | ".join(f"{compile_s[f]:.2f}" for f in (*FORMS, "exact")) + " | "
                  + " | ".join(f"{c['false_hits']} / {c['missed_hits']} / {c['wrong_root']}"
                               for c in cells) + " |", flush=True)
    if plot:
        _plot(rows, method, size, plot)


def _plot(rows, method: str, size: int, path: str) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(10, 4), dpi=110)
    for family, style in (("powers", "-"), ("chmutov", "--")):
        data = [r for r in rows if r[0] == family]
        degrees = [r[1] for r in data]
        for k, form in enumerate((*FORMS, "exact")):
            color = ("tab:blue", "tab:orange", "tab:green")[k]
            label = f"{method} {form}" if form != "exact" else "exact"
            axes[0].plot(degrees, [r[2][k]["ms"] for r in data], style, marker="o",
                         color=color, label=f"{label}, {family}")
            axes[1].plot(degrees, [r[3][form] for r in data], style, marker="o",
                         color=color, label=f"{label}, {family}")
    axes[0].set_title(f"frame time, {size}x{size}, llvmpipe")
    axes[0].set_ylabel("ms per frame (median)")
    axes[1].set_title("compile time (cold `implc compile`)")
    axes[1].set_ylabel("seconds")
    for ax in axes:
        ax.set_xlabel("degree of S")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path)
    print(f"wrote {path}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("mode", choices=("accuracy", "sweep"))
    ap.add_argument("surfaces", nargs="*")
    ap.add_argument("--size", type=int, default=512)
    ap.add_argument("--frames", type=int, default=3)
    ap.add_argument("--methods", nargs="+", default=["taylor", "hessian"])
    ap.add_argument("--degrees", default="2-12")
    ap.add_argument("--plot")
    args = ap.parse_intermixed_args()
    if args.mode == "accuracy":
        accuracy(args.surfaces, args.methods, args.size, args.frames)
    else:
        lo, hi = (int(v) for v in args.degrees.split("-"))
        sweep(list(range(lo, hi + 1)), args.methods[0], args.size, args.frames, args.plot)


if __name__ == "__main__":
    main()
