"""`-m exact` over the corpus: every polynomial row that loads compiles and validates with
the exact method on glsl, wgsl and opencl, or is refused with the documented degree
reason (docs/journal/2026-12-01-exact-and-table-1.md, "Corpus").

    python scripts/corpus_exact.py [TSV] [-j 2]
"""

from __future__ import annotations

import argparse
import sys
from collections import Counter
from concurrent.futures import ProcessPoolExecutor
from multiprocessing import get_context

TARGETS = ("glsl", "wgsl", "opencl")


def check_row(row) -> tuple[int, str, str]:
    """(row number, outcome, detail): outcome is one of not-loaded, not-polynomial, ok,
    refused, invalid."""
    from implc.corpus import row_surface
    from implc.derive import polynomial_degree
    from implc.emit import emit
    from implc.errors import ImplcError
    from implc.validate import validate_text

    try:
        surface = row_surface(row, None)
    except ImplcError as err:
        return row.number, "not-loaded", str(err).splitlines()[0][:80]
    degree = polynomial_degree(surface.expr)
    if degree is None:
        return row.number, "not-polynomial", ""
    bad = []
    for target in TARGETS:
        try:
            text = emit(surface, target, "exact")
        except ImplcError as err:
            message = str(err).splitlines()[0]
            if "supports degree up to" in message:
                return row.number, "refused", f"degree {degree}"
            return row.number, "invalid", f"{target}: {message[:80]}"
        verdict = validate_text(text, target, f"row{row.number}.{target}")
        if not verdict.ok:
            bad.append(f"{target}: {verdict.messages.splitlines()[0][:80]}")
    return row.number, ("invalid" if bad else "ok"), "; ".join(bad) or f"degree {degree}"


def main() -> None:
    from implc.corpus import default_tsv, load_rows

    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("tsv", nargs="?")
    ap.add_argument("-j", type=int, default=2)
    args = ap.parse_args()
    tsv = args.tsv or default_tsv()
    if tsv is None:
        sys.exit("no corpus TSV found")
    rows = list(load_rows(tsv))
    with ProcessPoolExecutor(args.j, mp_context=get_context("spawn")) as pool:
        results = list(pool.map(check_row, rows))
    counts = Counter(outcome for _, outcome, _ in results)
    print(f"{len(rows)} rows of {tsv}: " + ", ".join(f"{k} {v}" for k, v in sorted(counts.items())))
    for number, outcome, detail in results:
        if outcome in ("invalid", "refused"):
            print(f"  row {number}: {outcome} ({detail})")


if __name__ == "__main__":
    main()
