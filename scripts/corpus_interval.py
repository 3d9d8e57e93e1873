"""`-m interval` over the corpus: every non-polynomial row that loads and compiles with
`hessian` (the marchers' method, the default there before interval) is compiled
with the interval method on glsl, wgsl and opencl and validated by each target's real
compiler (implc/validate.py), or refused with the interval method's reason (a function
without an interval rule, e.g. atan2, or a power with a variable exponent).

    python scripts/corpus_interval.py [TSV] [-j 2] [-o FILE.md]

Polynomial rows are scripts/corpus_exact.py's. "Compiles today" means hessian emits
the program for every target (`implc compile -e ROW` without --validate;
`make corpus` validates those). Prints a summary table; `-o` writes it as Markdown.
"""

from __future__ import annotations

import argparse
import re
import sys
import time
from collections import Counter
from concurrent.futures import ProcessPoolExecutor
from multiprocessing import get_context

TARGETS = ("glsl", "wgsl", "opencl")
METHOD = "interval"


def check_row(row) -> tuple[int, str, str, str, dict[str, str]]:
    """(row number, name, outcome, detail, target -> ok|invalid|-): outcome is one of
    not-loaded, polynomial, default-fails, refused, ok, invalid, tool-missing, and error
    (an unexpected exception: an implc bug, reported with its first line)."""
    try:
        return _check_row(row)
    except Exception as err:
        return (row.number, row.name, "error", f"{type(err).__name__}: {_first(str(err))}",
                {t: "-" for t in TARGETS})


def _check_row(row) -> tuple[int, str, str, str, dict[str, str]]:
    from implc.corpus import row_surface
    from implc.derive import polynomial_degree
    from implc.emit import emit
    from implc.errors import ImplcError, ToolError
    from implc.validate import validate_text

    statuses = {t: "-" for t in TARGETS}
    try:
        surface = row_surface(row, None)
    except ImplcError as err:
        return row.number, row.name, "not-loaded", _first(str(err)), statuses
    if polynomial_degree(surface.expr) is not None:
        return row.number, row.name, "polynomial", "", statuses
    default = "hessian"  # what rendered these rows before interval (the marchers)
    for target in TARGETS:
        try:
            emit(surface, target, default)
        except ImplcError as err:
            return (row.number, row.name, "default-fails",
                    f"-m {default} on {target}: {_first(str(err))}", statuses)
    bad = []
    try:
        for target in TARGETS:
            try:
                text = emit(surface, target, METHOD)
            except ImplcError as err:
                return row.number, row.name, "refused", refusal(str(err)), statuses
            verdict = validate_text(text, target, f"row{row.number}.{target}")
            statuses[target] = "ok" if verdict.ok else "invalid"
            if not verdict.ok:
                bad.append(f"{target}: {_first_error(verdict.messages)}")
    except ToolError as err:
        return row.number, row.name, "tool-missing", _first(str(err)), statuses
    return row.number, row.name, ("invalid" if bad else "ok"), "; ".join(bad), statuses


def refusal(message: str) -> str:
    """The interval method's reason, without the advice: "no interval rule for 'atan2'"."""
    first = _first(message)
    if "variable exponent" in first:
        return "no interval rule for a power with a variable exponent"
    match = re.search(r"(no interval rule for '[^']+')", first)
    return match.group(1) if match else first


def _first(text: str) -> str:
    lines = text.strip().splitlines()
    return lines[0][:120] if lines else ""


def _first_error(messages: str) -> str:
    """The first line that says error (a build log may start with warnings)."""
    lines = [line.strip() for line in messages.splitlines() if line.strip()]
    for line in lines:
        if "error" in line.lower():
            return line[:120]
    return lines[0][:120] if lines else "(no message)"


def summary(results, tsv, seconds: float) -> str:
    """The summary as Markdown (printed as it is: the tables read as plain text too)."""
    counts = Counter(outcome for _, _, outcome, _, _ in results)
    tried = [r for r in results if r[2] in ("refused", "ok", "invalid")]
    compiled = [r for r in results if r[2] in ("ok", "invalid")]
    lines = [
        f"# -m interval on the corpus ({len(results)} rows of {tsv.name})",
        "",
        f"scripts/corpus_interval.py, {seconds:.0f} s. Each non-polynomial row that loads "
        "and compiles with `-m hessian` is compiled with `-m interval` for "
        f"{', '.join(TARGETS)} and validated by each target's compiler.",
        "",
        "| rows | count |",
        "|---|---|",
        f"| in the corpus | {len(results)} |",
        f"| not loaded (implc refuses the equation) | {counts['not-loaded']} |",
        f"| polynomial (scripts/corpus_exact.py) | {counts['polynomial']} |",
        f"| non-polynomial, hessian fails | {counts['default-fails']} |",
        f"| non-polynomial, compiled today: tried with -m interval | {len(tried)} |",
        f"| -m interval refused | {counts['refused']} |",
        f"| -m interval compiles on every target | {len(compiled)} |",
        f"| ... and validates on every target | {counts['ok']} |",
        f"| ... fails validation somewhere | {counts['invalid']} |",
    ]
    if counts["error"]:
        lines.append(f"| an unexpected exception (an implc bug) | {counts['error']} |")
    if counts["tool-missing"]:
        lines.append(f"| a validator is missing (not judged) | {counts['tool-missing']} |")
    lines += ["", "| target | validated | of compiled |", "|---|---|---|"]
    for target in TARGETS:
        ok = sum(1 for r in compiled if r[4][target] == "ok")
        lines.append(f"| {target} | {ok} | {len(compiled)} |")
    reasons = Counter(detail for _, _, outcome, detail, _ in results if outcome == "refused")
    if reasons:
        lines += ["", "| refused because | rows |", "|---|---|"]
        lines += [f"| {reason} | {n} |" for reason, n in reasons.most_common()]
    # every row tried, and every non-polynomial row that could not be
    listed = [r for r in results if r[2] not in ("not-loaded", "polynomial")]
    if listed:
        head = " | ".join(TARGETS)
        lines += ["", f"| row | name | outcome | {head} | detail |",
                  "|---|---|---|" + "---|" * len(TARGETS) + "---|"]
        lines += [f"| {number} | {_cell(name)} | {outcome} | "
                  + " | ".join(statuses[t] for t in TARGETS) + f" | {_cell(detail)} |"
                  for number, name, outcome, detail, statuses in listed]
    return "\n".join(lines) + "\n"


def _cell(text: str) -> str:
    return text.replace("|", "\\|")


def main() -> None:
    from pathlib import Path

    from implc.corpus import default_tsv, load_rows

    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("tsv", nargs="?")
    ap.add_argument("-j", type=int, default=2, choices=(1, 2),
                    help="worker processes (at most 2)")
    ap.add_argument("-o", "--output", help="also write the summary as Markdown")
    args = ap.parse_args()
    tsv = args.tsv or default_tsv()
    if tsv is None:
        sys.exit("no corpus TSV found")
    tsv = Path(tsv)
    rows = list(load_rows(tsv))
    start = time.perf_counter()
    with ProcessPoolExecutor(args.j, mp_context=get_context("spawn")) as pool:
        results = list(pool.map(check_row, rows))
    text = summary(results, tsv, time.perf_counter() - start)
    print(text, end="")
    if args.output:
        Path(args.output).write_text(text, encoding="utf-8")
    if any(outcome in ("invalid", "error", "tool-missing") for _, _, outcome, _, _ in results):
        sys.exit(1)


if __name__ == "__main__":
    main()
