"""Check that a compile without numpy chooses the box of Chebyshev's basis numpy's does
(issue 48): for every bundled surface, Chmutov's T_n and polynomial corpus row of degree
>= --min-degree that chebyshev.py would convert (numeric coefficients, at most
MAX_MONOMIALS monomials), numpy's box (box_numpy.py) against the plain-Python one
(box_choice.py on plain_extent.py's sampling), with both times.

    python scripts/box_choice_check.py [--min-degree 7] [--corpus TSV]

Prints one line a surface and a summary; exits 1 when a box differs.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tests"))  # cases.chmutov


def surfaces(corpus: Path | None) -> list[tuple[str, object]]:
    """(label, S) of the bundled examples, Chmutov's T_7..T_20 and the corpus's rows."""
    from cases import chmutov

    import implc
    from implc.corpus import default_tsv, load_rows, row_surface
    from implc.errors import ImplcError
    from implc.loaders import load_surface

    found = [(f"example:{name}", load_surface(name).expr) for name in implc.examples()]
    found += [(f"chmutov{n}", load_surface(equation=chmutov(n)).expr) for n in range(7, 21)]
    path = corpus or default_tsv()
    for row in load_rows(path) if path else []:
        try:
            found.append((f"row{row.number}:{row.name}", row_surface(row).expr))
        except ImplcError:
            continue
    return found


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--min-degree", type=int, default=7)
    ap.add_argument("--corpus", type=Path, default=None)
    args = ap.parse_args()

    from implc import box_numpy, chebyshev
    from implc.derive import expanded_terms, polynomial_degree

    checked = boxes = 0
    differ = []
    for label, expr in surfaces(args.corpus):
        degree = polynomial_degree(expr)
        if degree is None or degree < args.min_degree:
            continue
        terms = expanded_terms(expr)
        if (not terms or len(terms) > chebyshev.MAX_MONOMIALS
                or not all(c.is_number for c in terms.values())):
            continue
        start = time.perf_counter()
        numpy_box = box_numpy.surface_box(expr)
        middle = time.perf_counter()
        plain_box = chebyshev._plain_box(expr)
        end = time.perf_counter()
        checked += 1
        boxes += numpy_box is not None
        if plain_box != numpy_box:
            differ.append(label)
        print(f"{label}: degree {degree}, {len(terms)} monomials, numpy {middle - start:.2f} s,"
              f" plain {end - middle:.2f} s, {'same' if plain_box == numpy_box else 'DIFFERS'}"
              f" ({'a box' if numpy_box else 'monomials kept'})", flush=True)
    print(f"{checked} surfaces, {boxes} with a box, {checked - len(differ)} the same box")
    if differ:
        print("differ:", ", ".join(differ))
        sys.exit(1)


if __name__ == "__main__":
    main()
