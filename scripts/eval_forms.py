"""Point versus ray-poly evaluation on named surfaces, and the degree sweep (exact against
taylor and hessian, degree 2-20): accuracy against the exact reference, frame time and
compile time (docs/RESULTS.md, "Evaluation forms" and "The degree sweep";
docs/cost-growth.png).

    python scripts/eval_forms.py accuracy --size 512 cross-cap miter ...   markdown table
    python scripts/eval_forms.py sweep --size 512 --plot docs/cost-growth.png
        each row solved in float32, or in double where float32 cannot hold S (the
        compile's warning for every method), exact / taylor in float32 beside
    python scripts/eval_forms.py gallery --size 512 barth-decic 163 285 ...  rows too
    python scripts/eval_forms.py precision --degrees 12-20 --families chmutov
        exact and taylor, each in float (gl) and in double (gl-double), with counts
        (--no-counts: frames only; --plot docs/precision.png: the ratios drawn)

Each surface's programs (one per form and method) are timed in turns in one GL context
(llvmpipe here), one warm-up frame then --frames frames, medians. The sweep's compile
times are implc's emit (in process) and the driver's (program build and first draw, with
Mesa's shader cache off).
"""

from __future__ import annotations

import argparse
import math
import os
import statistics
import sys
import time
from pathlib import Path
from typing import NamedTuple

os.environ.setdefault("MESA_SHADER_CACHE_DISABLE", "true")  # compile times are cold

from implc.bench import time_interleaved  # noqa: E402
from implc.derive import polynomial_degree  # noqa: E402
from implc.loaders import load_surface  # noqa: E402
from implc.marcher import choose_form  # noqa: E402
from implc.methods import get_method  # noqa: E402
from implc.metrics import compare  # noqa: E402
from implc.render.run import open_runner  # noqa: E402

FORMS = ("point", "ray-poly")
# The sweep compiles each program COPIES times and times them all in the same rounds,
# keeping the faster copy's median: llvmpipe at times runs one compiled program about
# 1.4x slower in every frame of a run (docs/journal/2026-12-05.md), a compile's lot, not
# the program's. The first copy's compile is the one reported (emit, driver).
COPIES = 2


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


SWEEP_RUNS = (("exact", "auto"), ("taylor", "point"), ("taylor", "ray-poly"),
              ("hessian", "auto"))


def float32_holds(surface) -> bool:
    """Whether float32 holds S in its view: the compile's warning for every method (a
    rounding of S moves its surface by more than T_TOL at 1 % of its sampled points,
    implc/conditioning.py) does not fire. Where it fires no method's float32 picture is
    right (Chmutov from degree 16: 52 % of the points at 18, 66 % at 20), so the sweep
    solves both methods in double there, as the warning advises."""
    from implc.float32 import float32_report

    degree = polynomial_degree(surface.expr)
    if degree is None:
        return True
    return not float32_report(surface.expr, surface.view, degree).point_warns


def measure_sweep(surface, size: int, frames: int, precision: str = "float") -> dict:
    """Per (method, form) of SWEEP_RUNS solved in `precision`, timed in the same rounds:
    median ms (the faster of COPIES compiles), the metrics against the reference, implc's
    emit seconds (in process, sympy included) and the driver's compile seconds (program
    build plus first draw, llvmpipe compiling there; the Mesa shader cache is off, see
    main). In double, exact and taylor (its `auto` form) in float32 too, in the same
    rounds, keyed (method, form, "float32")."""
    from implc.emit import emit

    reference = open_runner(surface, "reference", "", get_method("taylor").defaults,
                            size, size).frame()
    backend = "gl" if precision == "float" else "gl-double"
    keys = list(SWEEP_RUNS)
    if precision != "float":
        keys += [("exact", "auto", "float32"),
                 ("taylor", choose_form(get_method("taylor"), surface.expr), "float32")]
    runners, emits, builds = [], [], []
    try:
        for _copy in range(COPIES):
            for key in keys:
                method, form = key[:2]
                constants = get_method(method).constants(evaluation=form)
                start = time.perf_counter()
                emit(surface, "glsl", method, constants,
                     precision=precision if len(key) == 2 else "float")
                emits.append(time.perf_counter() - start)
                start = time.perf_counter()  # emit again (cached) and build the GL program
                runners.append(open_runner(surface, backend if len(key) == 2 else "gl",
                                           method, constants, size, size))
                builds.append(time.perf_counter() - start)
        seconds, last, first_use = time_interleaved(runners, frames)
    finally:
        for r in runners:
            r.release()
    results = {}
    for i, key in enumerate(keys):
        copies = [1000 * statistics.median(seconds[c * len(keys) + i]) for c in range(COPIES)]
        if max(copies) > 1.15 * min(copies):  # what the copies are for, seen
            print(f"note: {key}: copies {', '.join(f'{m:.1f}' for m in copies)} ms",
                  file=sys.stderr, flush=True)
        results[key] = {"ms": min(copies), "emit_s": emits[i],
                        "driver_s": builds[i] + first_use[i], **compare(last[i], reference)}
    return results


_HEADER = ("exact ms | taylor point ms | taylor ray-poly ms | hessian ms | exact / taylor | "
           "exact false / missed / wrong | taylor false / missed / wrong | "
           "hessian false / missed / wrong | exact emit s | exact driver compile s | "
           "solved in | exact / taylor, both in float32 |")
_MEASURED_COLUMNS = 12


class Row(NamedTuple):
    """One row of the sweep: exact / taylor (the form `--eval auto` picks) as measured in
    the precision `solved` (float or double), and as measured in float32."""

    family: str
    degree: int
    measured: dict
    ratio: float
    solved: str
    in_float32: float


def _measured_row(first: str, surface, size: int,
                  frames: int) -> tuple[dict, float, str, float]:
    """Measure `surface` (measure_sweep, in double where float32 does not hold it), print
    its table row after the cells `first`, and return the measurements, exact / taylor,
    the precision solved in and exact / taylor in float32."""
    precision = "float" if float32_holds(surface) else "double"
    r = measure_sweep(surface, size, frames, precision)
    form = choose_form(get_method("taylor"), surface.expr)
    taylor = r["taylor", form]
    exact = r["exact", "auto"]
    counts = [f"{c['false_hits']} / {c['missed_hits']} / {c['wrong_root']}"
              for c in (exact, taylor, r["hessian", "auto"])]
    in_float32 = (exact["ms"] / taylor["ms"] if precision == "float" else
                  r["exact", "auto", "float32"]["ms"] / r["taylor", form, "float32"]["ms"])
    print(f"| {first} | " + " | ".join(f"{r[k]['ms']:.1f}" for k in SWEEP_RUNS)
          + f" | {exact['ms'] / taylor['ms']:.2f} | " + " | ".join(counts)
          + f" | {exact['emit_s']:.2f} | {exact['driver_s']:.2f} | "
          + f"{'float32' if precision == 'float' else 'double'} | {in_float32:.2f} |",
          flush=True)
    return r, exact["ms"] / taylor["ms"], precision, in_float32


def sweep(degrees: list[int], size: int, frames: int, plot: str | None,
          families: list[str] | None = None) -> None:
    """The degree sweep (docs/RESULTS.md): exact against taylor (b = 0.01, both forms;
    `taylor` in the ratio is the form `auto` picks) and hessian, per family and degree
    (`families`: some of them only); each row solved in float32, or in double where
    float32 does not hold the surface (float32_holds), exact / taylor in float32 beside."""
    rows = []
    print(f"| family | degree | {_HEADER}")
    print("|---|---|" + "---|" * _MEASURED_COLUMNS)
    for degree in degrees:
        for family, equation in sweep_equations(degree).items():
            if families and family not in families:
                continue
            surface = load_surface(equation=equation)
            rows.append(Row(family, degree, *_measured_row(f"{family} | {degree}", surface,
                                                           size, frames)))
    if plot:
        _plot(rows, size, plot)


PRECISION_RUNS = (("gl", "exact"), ("gl-double", "exact"), ("gl", "taylor"),
                  ("gl-double", "taylor"))


def precision(degrees: list[int], size: int, frames: int,
              families: list[str] | None = None, counts: bool = True,
              plot: str | None = None) -> None:
    """exact and taylor (`--eval auto`), each in float (`gl`) and in double (`gl-double`),
    timed in the same rounds, with their counts against the reference unless `counts` is
    False (docs/journal/2026-12-04.md, "Double precision in GLSL", "Both methods in double");
    `plot`: exact / taylor in each precision against the degree, drawn there."""
    rows = []
    names = [f"{method} {'double' if backend.endswith('double') else 'float'}"
             for backend, method in PRECISION_RUNS]
    print("| family | degree | " + " | ".join(f"{n} ms" for n in names)
          + " | exact float / taylor float | exact double / taylor float | exact double / "
          "taylor double |" + ("".join(f" {n} false / missed / wrong |" for n in names)
                               if counts else ""))
    print("|---|---|" + "---|" * (7 + 4 * counts))
    for degree in degrees:
        for family, equation in sweep_equations(degree).items():
            if families and family not in families:
                continue
            surface = load_surface(equation=equation)
            constants = {"exact": get_method("exact").defaults,
                         "taylor": get_method("taylor").constants(
                             evaluation=choose_form(get_method("taylor"), surface.expr))}
            reference = (open_runner(surface, "reference", "", constants["taylor"], size,
                                     size).frame() if counts else None)
            runners = [open_runner(surface, backend, method, constants[method], size, size)
                       for backend, method in PRECISION_RUNS]
            try:
                seconds, last, _ = time_interleaved(runners, frames)
            finally:
                for r in runners:
                    r.release()
            ms = [1000 * statistics.median(s) for s in seconds]
            cells = [f"{m:.1f}" for m in ms] + [f"{ms[0] / ms[2]:.2f}", f"{ms[1] / ms[2]:.2f}",
                                                f"{ms[1] / ms[3]:.2f}"]
            if counts:
                cells += [f"{m['false_hits']} / {m['missed_hits']} / {m['wrong_root']}"
                          for m in (compare(result, reference) for result in last)]
            print(f"| {family} | {degree} | " + " | ".join(cells) + " |", flush=True)
            rows.append((family, degree, ms[0] / ms[2], ms[1] / ms[3]))
    if plot:
        _plot_precision(rows, size, plot)


def _plot_precision(rows, size: int, path: str) -> None:
    """exact / taylor against the degree, both methods in float32 and both in double."""
    fig, axes = _figure(1, (7, 4.2))
    ax = axes[0]
    for family, style in (("powers", "-"), ("chmutov", "--")):
        data = [r for r in rows if r[0] == family]
        for column, color, label in ((2, "tab:green", "float32"), (3, "tab:purple", "double")):
            ax.plot([r[1] for r in data], [r[column] for r in data], style, marker="o",
                    color=color, label=f"{family}, both in {label}")
    ax.axhline(0.67, color="grey", lw=1, ls=":", label="goal 0.67")
    ax.set_title(f"exact / taylor (b = 0.01) frame time, {size}x{size}, llvmpipe")
    _save(fig, axes, path)


def rows_from_table(path: str) -> list:
    """The sweep's rows back from its printed table (to redraw the plot unmeasured)."""
    rows = []
    for line in Path(path).read_text(encoding="utf-8").splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if len(cells) not in (12, 14) or not cells[1].isdigit():
            continue
        ms = [_number(c) for c in cells[2:6]]
        r = {key: {"ms": m} for key, m in zip(SWEEP_RUNS, ms, strict=True)}
        r["exact", "auto"].update(emit_s=_number(cells[10]), driver_s=_number(cells[11]))
        # tables before the precision columns were all solved in float32
        solved, in_float32 = (("double" if cells[12] == "double" else "float",
                               _number(cells[13])) if len(cells) == 14
                              else ("float", _number(cells[6])))
        rows.append(Row(cells[0], int(cells[1]), r, _number(cells[6]), solved, in_float32))
    return rows


def _number(cell: str) -> float:
    """A table cell's number; NaN (a gap in the plot) for one not measured, "–"."""
    return math.nan if cell in ("–", "-") else float(cell)


def gallery(names: list[str], size: int, frames: int) -> None:
    """The sweep's measurement on named surfaces: bundled examples, or corpus rows by
    number (the parameters as `implc corpus` gives them)."""
    from implc.corpus import default_tsv, load_rows, row_surface

    rows = {r.number: r for r in load_rows(default_tsv())} if any(
        n.isdigit() for n in names) else {}
    print(f"| surface | degree | {_HEADER}")
    print("|---|---|" + "---|" * _MEASURED_COLUMNS)
    for name in names:
        if name.isdigit():
            surface, label = row_surface(rows[int(name)]), f"{rows[int(name)].name} ({name})"
        else:
            surface, label = load_surface(name), name
        _measured_row(f"{label} | {polynomial_degree(surface.expr)}", surface, size, frames)


def _plot(rows: list[Row], size: int, path: str) -> None:
    """Frame times, exact / taylor and compile times against the degree; rows solved in
    double drawn hollow, with exact / taylor in float32 beside them (thin, dotted)."""
    fig, axes = _figure(3, (15, 4.2))
    colors = dict(zip(SWEEP_RUNS, ("tab:green", "tab:blue", "tab:orange", "tab:red"),
                      strict=True))
    for family, style in (("powers", "-"), ("chmutov", "--")):
        data = [r for r in rows if r.family == family]
        degrees = [r.degree for r in data]
        double = [r for r in data if r.solved == "double"]
        for key in SWEEP_RUNS:
            label = key[0] if key[1] == "auto" else f"{key[0]} {key[1]}"
            axes[0].plot(degrees, [r.measured[key]["ms"] for r in data], style, marker="o",
                         color=colors[key], label=f"{label}, {family}")
        axes[1].plot(degrees, [r.ratio for r in data], style, marker="o", color="tab:green",
                     label=f"exact / taylor, {family}")
        if double:
            axes[1].plot([r.degree for r in double], [r.ratio for r in double], "o",
                         mfc="white", color="tab:green",
                         label=f"{family}: both solved in double (float32 cannot hold S)")
            axes[1].plot([r.degree for r in double], [r.in_float32 for r in double], ":",
                         marker=".", color="tab:gray", lw=1,
                         label=f"{family}: both in float32 anyway (wrong pictures)")
        axes[2].plot(degrees, [r.measured["exact", "auto"]["driver_s"] for r in data], style,
                     marker="o", color="tab:green", label=f"exact, driver, {family}")
        axes[2].plot(degrees, [r.measured["exact", "auto"]["emit_s"] for r in data], style,
                     marker="o", color="tab:purple", label=f"exact, implc emit, {family}")
    axes[1].axhline(0.67, color="grey", lw=1, ls=":", label="goal 0.67")
    axes[0].set_title(f"frame time, {size}x{size}, llvmpipe (each row as solved)")
    axes[0].set_ylabel("ms per frame (median)")
    axes[0].set_yscale("log")
    axes[1].set_title("exact / taylor (b = 0.01) frame time")
    axes[2].set_title("compile (Mesa shader cache off)")
    axes[2].set_ylabel("seconds")
    _save(fig, axes, path)


def _figure(columns: int, size: tuple[float, float]):
    """A figure of `columns` plots side by side (matplotlib without a display)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, columns, figsize=size, dpi=110, squeeze=False)
    return fig, list(axes[0])


def _save(fig, axes, path: str) -> None:
    """Every plot against the degree, gridded, with its legend; written to `path`."""
    for ax in axes:
        ax.set_xlabel("degree of S")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path)
    print(f"wrote {path}")


def _degrees(text: str) -> list[int]:
    """--degrees: "2-20", or one degree, "16"."""
    lo, _, hi = text.partition("-")
    return list(range(int(lo), int(hi or lo) + 1))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("mode", choices=("accuracy", "sweep", "gallery", "precision"))
    ap.add_argument("surfaces", nargs="*")
    ap.add_argument("--size", type=int, default=512)
    ap.add_argument("--frames", type=int, default=3)
    ap.add_argument("--methods", nargs="+", default=["taylor", "hessian"])
    ap.add_argument("--degrees", default="2-20")
    ap.add_argument("--plot")
    ap.add_argument("--families", nargs="+", choices=("powers", "chmutov"),
                    help="sweep, precision: these families only (default both)")
    ap.add_argument("--no-counts", action="store_true",
                    help="precision: frames only, no reference (an hour a row at degree 20)")
    ap.add_argument("--from-table", help="sweep: redraw --plot from this printed table "
                    "instead of measuring")
    args = ap.parse_intermixed_args()
    if args.mode == "accuracy":
        accuracy(args.surfaces, args.methods, args.size, args.frames)
    elif args.mode == "gallery":
        gallery(args.surfaces, args.size, args.frames)
    elif args.mode == "precision":
        precision(_degrees(args.degrees), args.size, args.frames, args.families,
                  counts=not args.no_counts, plot=args.plot)
    else:
        if args.from_table:
            _plot(rows_from_table(args.from_table), args.size, args.plot)
            return
        sweep(_degrees(args.degrees), args.size, args.frames, args.plot, args.families)


if __name__ == "__main__":
    main()
