"""Start-up time of the commands a user types first (`make startup`; issue 23 point 20)
and of `import implc` (issue 43: the library is cheap to import; sympy, numpy and the GPU
stacks load on first use).

Each command runs in a fresh process, several times; the table shows the median and the
fastest wall-clock time, against bare Python (`python -c pass`) and the goal for
`import implc` and the commands that only print text (`--help`, `COMMAND --help`,
`--version`: no sympy, no numpy; tests/test_startup.py checks the imports, this script the
time). Bare Python, `import implc` and `implc --help` take turns run by run, so that a
change of the machine's load falls on the three alike, and a last line sets their medians
side by side. A benchmark, not a test: on a busy machine the times move, so it reports and
does not fail unless asked (`--check`).
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
GOAL = 0.15  # seconds: --help, COMMAND --help, --version
FAST = [["--help"], ["--version"], ["compile", "--help"], ["render", "--help"],
        ["show", "--help"], ["view", "--help"], ["bench", "--help"], ["list", "--help"]]
WORK = [["list"], ["show", "sphere"]]  # these load the parser (sympy): for comparison


def once(argv: list[str]) -> float:
    """Wall-clock seconds of one fresh process running `argv`."""
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    start = time.perf_counter()
    proc = subprocess.run(argv, capture_output=True, env=env, cwd=ROOT)
    elapsed = time.perf_counter() - start
    if proc.returncode != 0:
        raise SystemExit(f"{' '.join(argv)} failed ({proc.returncode}): "
                         f"{proc.stderr.decode(errors='replace')[:300]}")
    return elapsed


def wall(argv: list[str], runs: int) -> list[float]:
    return [once(argv) for _ in range(runs)]


def alternating(argvs: list[list[str]], runs: int) -> list[list[float]]:
    """`runs` times of each command, the commands taking turns (a, b, c, a, b, c, ...)."""
    times: list[list[float]] = [[] for _ in argvs]
    for _ in range(runs):
        for argv, column in zip(argvs, times, strict=True):
            column.append(once(argv))
    return times


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=7, help="runs per command (default 7)")
    parser.add_argument("--check", action="store_true",
                        help=f"exit 1 when a text-only command's median exceeds {GOAL} s")
    args = parser.parse_args()
    python = [sys.executable]
    bare, library, helping = alternating(
        [[*python, "-c", "pass"], [*python, "-c", "import implc"],
         [*python, "-m", "implc", "--help"]], args.runs)
    rows = [("python -c pass", bare, None), ("python -c 'import implc'", library, GOAL),
            ("implc --help", helping, GOAL)]
    rows += [("implc " + " ".join(a), wall([*python, "-m", "implc", *a], args.runs), GOAL)
             for a in FAST if a != ["--help"]]
    rows += [("implc " + " ".join(a), wall([*python, "-m", "implc", *a], max(3, args.runs // 2)),
              None) for a in WORK]
    over = []
    print(f"| command | median s | fastest s | goal s |  ({args.runs} runs each, "
          f"{os.cpu_count()} CPUs)")
    print("|---|---:|---:|---|")
    for name, times, goal in rows:
        median = statistics.median(times)
        verdict = "" if goal is None else f"{goal} {'ok' if median <= goal else 'OVER'}"
        if goal is not None and median > goal:
            over.append(name)
        print(f"| {name} | {median:.3f} | {min(times):.3f} | {verdict} |")
    print(f"median s: import implc {statistics.median(library):.3f}, implc --help "
          f"{statistics.median(helping):.3f}, python alone {statistics.median(bare):.3f}")
    if over:
        print(f"over the goal: {', '.join(over)}", file=sys.stderr)
    return 1 if args.check and over else 0


if __name__ == "__main__":
    sys.exit(main())
