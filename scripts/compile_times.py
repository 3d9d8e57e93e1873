"""Compile time of every corpus row, as a user meets it: `implc compile -e ROW --param ...
-o FILE` in a fresh process (default method, GLSL), two rows at a time on this 2-core
machine. Prints the distribution over the rows that compile and the slowest ten
(docs/RESULTS.md, "Compile time on the corpus"); `make compile-times` runs it.

    python scripts/compile_times.py [TSV] [-j 2] [--rows 1-20,51] [-o TABLE.md]

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
from dataclasses import dataclass
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
    args = ap.parse_args()
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
