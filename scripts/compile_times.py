"""Compile time of every corpus row, as a user meets it: `implc compile -e ROW --param ...
-o FILE` in a fresh process (default method, GLSL), two rows at a time on this 2-core
machine. Prints the distribution over the rows that compile and the slowest ten
(docs/RESULTS.md, "Compile time on the corpus"); `make compile-times` runs it.

    python scripts/compile_times.py [TSV] [-j 2] [--rows 1-20,51] [-o TABLE.md]
    python scripts/compile_times.py --families       growing inputs with functions

`--families` compiles members of growing size of five shapes with functions (sums of
gaussians, of sines, of inverse squares, a min of distances, nested sines) and two
polynomial ones (sums of twelfth powers of planes, products of shells) the same way,
beside the bound's estimate (derive.estimate_derived_size, and weighed as
`--max-derived` counts it): what calibrates derive.FUNCTION_WEIGHT.

Each time is the child's wall time (what a user waits) and its CPU time (user + system,
from wait4: what the machine's load does not inflate). Exit 1 is a refusal (the row's
first error line is shown), any other nonzero exit a failure.
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path


@dataclass
class Timing:
    number: int
    name: str
    degree: int | None
    code: int
    wall: float
    cpu: float
    message: str


def command(row, out: Path) -> list[str]:
    """The row as a user types it (params as corpus.row_surface passes them)."""
    from implc.loaders.common import equation_words

    argv = [sys.executable, "-m", "implc", "compile", "-e", row.equation, "-o", str(out)]
    named = equation_words(row.equation)  # a family's parameters this member does not use
    for name, value in row.params.items():
        if name in named and isinstance(value, (int, float)) and not isinstance(value, bool):
            argv += ["--param", f"{name}={float(value)!r}"]
    return argv


def time_row(row, workdir: Path) -> Timing:
    out = workdir / f"row{row.number}.frag"
    start = time.perf_counter()
    child = subprocess.Popen(command(row, out), stdout=subprocess.DEVNULL,
                             stderr=subprocess.PIPE, env={**os.environ, "PYTHONHASHSEED": "0"})
    stderr = child.stderr.read().decode("utf-8", "replace") if child.stderr else ""
    _, status, usage = os.wait4(child.pid, 0)
    wall = time.perf_counter() - start
    child.returncode = os.waitstatus_to_exitcode(status)
    message = next((line for line in stderr.splitlines() if "error" in line), "")
    return Timing(row.number, row.name, row.degree, child.returncode, wall,
                  usage.ru_utime + usage.ru_stime, message.strip())


# name -> the member of size n (docs/reference/errors.md quotes what they measure)
FAMILIES = {
    "gaussians": lambda n: "+".join(f"exp(-((x-{i / 10})^2+(y-{i / 7})^2+z^2))"
                                    for i in range(n)) + "-0.5",
    "sines": lambda n: "+".join(f"sin({i + 1}*x+{i / 3})*cos({i % 5 + 1}*y)"
                                for i in range(n)) + "+z",
    "inverse-squares": lambda n: "+".join(f"1/((x-{i / 10})^2+(y-{i / 7})^2+z^2+0.1)"
                                          for i in range(n)) + "-3",
    "min-of-distances": lambda n: "min(" + ",".join(f"sqrt((x-{i / 9})^2+(y-{i / 11})^2+z^2)-0.3"
                                                    for i in range(n)) + ")",
    "nested-sines": lambda n: "sin(" * n + "x*y*z" + ")" * n + "+x^2+y^2+z^2-1",
    # polynomials: powers of planes (expanded for Horner's scheme), nested shells
    "powers-of-planes": lambda n: "+".join(f"({i % 5 - 2}*x+{i % 3 - 1}*y+{i % 7 - 3}*z+1)^12"
                                           for i in range(n)) + "-1",
    "shells": lambda n: "*".join(f"(x^2+y^2+z^2-{i}/{n})" for i in range(1, n + 1)) + "-0.001",
}
FAMILY_SIZES = {"gaussians": (20, 40, 60), "sines": (20, 40, 80),
                "inverse-squares": (20, 40, 80), "min-of-distances": (5, 10, 20),
                "nested-sines": (10, 20, 34, 40), "powers-of-planes": (20, 40, 60),
                "shells": (5, 10, 20)}


@dataclass
class Member:
    """A family's member, shaped as a corpus row for `time_row`."""

    number: int
    name: str
    equation: str
    degree: None = None
    params: dict = field(default_factory=dict)


def families(workdir: Path) -> str:
    """Each family member's estimate, weighed estimate (as --max-derived counts it),
    outcome and times."""
    from implc.derive import check_derived_size, estimate_derived_size
    from implc.errors import LimitError
    from implc.loaders import load_surface

    lines = ["| family | n | estimate | weighed | outcome | wall s | CPU s |",
             "|---|---:|---:|---:|---|---:|---:|"]
    for name, make in FAMILIES.items():
        for n in FAMILY_SIZES[name]:
            member = Member(n, name, make(n))
            expr = load_surface(equation=member.equation).expr
            estimate = estimate_derived_size(expr)
            try:
                weighed = check_derived_size(expr, 10**15)
            except LimitError:  # past even that bound
                weighed = -1
            t = time_row(member, workdir)
            outcome = {0: "compiled", 1: "refused"}.get(t.code, f"exit {t.code}")
            lines.append(f"| {name} | {n} | {estimate:,} | {weighed:,} | "
                         f"{outcome} | {t.wall:.2f} | {t.cpu:.2f} |")
            print(lines[-1], file=sys.stderr, flush=True)
    return "\n".join(lines) + "\n"


def quantile(values: list[float], q: float) -> float:
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, int(q * len(ordered)))]


def report(timings: list[Timing]) -> str:
    compiled = [t for t in timings if t.code == 0]
    refused = [t for t in timings if t.code == 1]
    failed = [t for t in timings if t.code not in (0, 1)]
    lines = [f"{len(timings)} rows: {len(compiled)} compiled, {len(refused)} refused "
             f"(exit 1), {len(failed)} failed", ""]
    if compiled:
        lines += ["| over the compiled rows | wall s | CPU s |", "|---|---:|---:|"]
        for label, pick in (("median", lambda v: statistics.median(v)),
                            ("p90", lambda v: quantile(v, 0.9)),
                            ("max", max)):
            lines.append(f"| {label} | {pick([t.wall for t in compiled]):.2f} | "
                         f"{pick([t.cpu for t in compiled]):.2f} |")
        lines += ["", "Slowest ten (compiled):", "",
                  "| row | name | degree | wall s | CPU s |", "|---:|---|---:|---:|---:|"]
        for t in sorted(compiled, key=lambda t: -t.wall)[:10]:
            lines.append(f"| {t.number} | {t.name} | {t.degree or '-'} | {t.wall:.2f} | "
                         f"{t.cpu:.2f} |")
    if refused:
        slow = sorted(refused, key=lambda t: -t.wall)[0]
        lines += ["", f"Slowest refusal: row {slow.number} ({slow.name}) in {slow.wall:.2f} s: "
                  f"{slow.message[:100]}"]
    for t in failed:
        lines.append(f"FAILED row {t.number} ({t.name}), exit {t.code}: {t.message[:120]}")
    return "\n".join(lines) + "\n"


def main() -> None:
    from implc.corpus import default_tsv, load_rows

    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("tsv", nargs="?", help="corpus TSV (default: ../shared/corpus/)")
    ap.add_argument("-j", type=int, default=2, help="rows at a time (default 2)")
    ap.add_argument("--rows", help="only these rows, e.g. 1-20,51")
    ap.add_argument("-o", type=Path, help="also write the table to this Markdown file")
    ap.add_argument("--families", action="store_true",
                    help="time growing inputs with functions instead of the corpus")
    args = ap.parse_args()
    if args.families:
        with tempfile.TemporaryDirectory() as tmp:
            text = families(Path(tmp))
        print(text, end="")
        if args.o:
            args.o.write_text(text)
        return
    tsv = args.tsv or default_tsv()
    if tsv is None:
        sys.exit("compile_times: no corpus TSV found (../shared/corpus/)")
    rows = load_rows(Path(tsv))
    if args.rows:
        wanted: set[int] = set()
        for part in args.rows.split(","):
            low, _, high = part.partition("-")
            wanted.update(range(int(low), int(high or low) + 1))
        rows = [r for r in rows if r.number in wanted]
    timings: list[Timing] = []
    with tempfile.TemporaryDirectory() as tmp, ThreadPoolExecutor(args.j) as pool:
        for done, timing in enumerate(pool.map(lambda r: time_row(r, Path(tmp)), rows), 1):
            timings.append(timing)
            if done % 20 == 0 or done == len(rows):
                print(f"compile-times: {done}/{len(rows)} rows", file=sys.stderr, flush=True)
    text = report(timings)
    print(text, end="")
    if args.o:
        args.o.write_text(text)


if __name__ == "__main__":
    main()
