"""`implc corpus`: implc over a corpus of equations, and a report."""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

from ..errors import EXIT_OK, InputError
from ..fileio import check_output, write_atomic
from ..targets import TARGETS
from . import args as common
from .args import UsageError


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("corpus", help="run implc over a corpus of equations and report",
                       description="Load, derive, numerically check, emit (-m hessian, "
                                   "program) and validate every row of a corpus TSV; "
                                   "report what compiled and why the rest was rejected.")
    p.add_argument("tsv", nargs="?", type=Path, metavar="TSV",
                   help="corpus TSV (default: ../shared/corpus/implicit_surface_corpus.tsv)")
    p.add_argument("-o", "--output", type=Path, help="write the Markdown report here")
    p.add_argument("-t", "--targets", nargs="+", choices=list(TARGETS), default=list(TARGETS),
                   help="targets to emit and validate (default: all)")
    common.executor_args(p, default_jobs=0)
    p.add_argument("--rows", help="only these data rows, e.g. 1-20,35")
    p.add_argument("--no-validate", action="store_true", help="emit only; skip the compilers")
    p.add_argument("--no-check", action="store_true", help="skip the numeric checks")
    common.limit_args(p)


def run(args: argparse.Namespace) -> int:
    from .. import corpus, corpus_report
    from ..api import check_corpus
    from ..executors import effective_jobs
    from ..progress import Progress

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
    jobs = effective_jobs(args.jobs)
    bar = Progress(len(rows), "corpus", sys.stderr, unit="row")

    def progress(result: corpus.RowResult) -> None:
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
        with common.executor(args) as executor:
            results = check_corpus(rows, args.targets, validate=not args.no_validate,
                                 check=not args.no_check, limits=common.limits(args),
                                 progress=progress, executor=executor)
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
