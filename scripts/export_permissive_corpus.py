"""Copy the permissively licensed rows of the shared corpus into implc's test data.

    .venv/bin/python scripts/export_permissive_corpus.py [SHARED_TSV]

writes tests/data/corpus_permissive.tsv (the shared columns, unchanged, after a leading
`row` column with each row's number in the shared file) and
tests/data/CORPUS_ATTRIBUTION.md (source, licence and upstream path of every row). Only
CC-BY-4.0, MIT and Apache-2.0 rows are copied; the GPL rows stay in ../shared/corpus
(corpus README). Run it again when the shared corpus changes.
"""

from __future__ import annotations

import csv
import io
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from implc.corpus import COLUMNS, default_tsv, load_rows, permissive  # noqa: E402

OUT_TSV = ROOT / "tests" / "data" / "corpus_permissive.tsv"
OUT_ATTRIBUTION = ROOT / "tests" / "data" / "CORPUS_ATTRIBUTION.md"

NOTICES = {
    "IMAGINARY/SURFER-Galleries": (
        "CC-BY-4.0",
        "Equations from the `.jsurf` files of the SURFER galleries by IMAGINARY "
        "(https://github.com/IMAGINARY/SURFER-Galleries; authors listed in its AUTHORS "
        "file), licensed under the Creative Commons Attribution 4.0 International licence "
        "(https://creativecommons.org/licenses/by/4.0/). Changes: none to the equations "
        "or parameters; rows were selected and a `row` column added.",
    ),
    "hbatagelo/impvis": (
        "MIT",
        "Equations from the function catalogue of ImpVis (https://github.com/hbatagelo/"
        "impvis), under the MIT licence:\n\n"
        "> Copyright (c) 2022--2026 Harlen Batagelo\n>\n"
        "> Permission is hereby granted, free of charge, to any person obtaining a copy of "
        "this software and associated documentation files (the \"Software\"), to deal in the "
        "Software without restriction, including without limitation the rights to use, "
        "copy, modify, merge, publish, distribute, sublicense, and/or sell copies of the "
        "Software, and to permit persons to whom the Software is furnished to do so, subject "
        "to the following conditions:\n>\n"
        "> The above copyright notice and this permission notice shall be included in all "
        "copies or substantial portions of the Software.\n>\n"
        "> THE SOFTWARE IS PROVIDED \"AS IS\", WITHOUT WARRANTY OF ANY KIND, EXPRESS OR "
        "IMPLIED, INCLUDING BUT NOT LIMITED TO THE WARRANTIES OF MERCHANTABILITY, FITNESS "
        "FOR A PARTICULAR PURPOSE AND NONINFRINGEMENT. IN NO EVENT SHALL THE AUTHORS OR "
        "COPYRIGHT HOLDERS BE LIABLE FOR ANY CLAIM, DAMAGES OR OTHER LIABILITY, WHETHER IN "
        "AN ACTION OF CONTRACT, TORT OR OTHERWISE, ARISING FROM, OUT OF OR IN CONNECTION "
        "WITH THE SOFTWARE OR THE USE OR OTHER DEALINGS IN THE SOFTWARE.",
    ),
    "porst17/realsurf": (
        "Apache-2.0",
        "Equations from the surface list and benchmark set of realsurf "
        "(https://github.com/porst17/realsurf), licensed under the Apache License, "
        "Version 2.0 (https://www.apache.org/licenses/LICENSE-2.0). Changes: none to the "
        "equations; rows were selected and a `row` column added. Distributed on an \"AS "
        "IS\" basis, without warranties or conditions of any kind.",
    ),
}


def main(argv: list[str]) -> int:
    shared = Path(argv[1]) if len(argv) > 1 else default_tsv()
    if shared is None or not shared.is_file():
        print("no shared corpus found; pass its path", file=sys.stderr)
        return 1
    rows = permissive(load_rows(shared))
    with shared.open(encoding="utf-8", newline="") as handle:
        records = list(csv.DictReader(handle, delimiter="\t"))
    buffer = io.StringIO()
    writer = csv.writer(buffer, delimiter="\t", lineterminator="\n")
    writer.writerow(("row", *COLUMNS))
    for row in rows:
        record = records[row.number - 1]
        writer.writerow((row.number, *(record[c] for c in COLUMNS)))
    OUT_TSV.write_text(buffer.getvalue(), encoding="utf-8")

    lines = [
        "# Attribution of tests/data/corpus_permissive.tsv",
        "",
        "`corpus_permissive.tsv` copies the rows of the shared implicit-surface corpus "
        "(`../shared/corpus/implicit_surface_corpus.tsv`) whose upstream licence permits it "
        f"({len(rows)} rows; the GPL-2 rows are not copied and are used only from the shared "
        "folder). Its `row` column is the row's number in the shared file; the other columns "
        "are copied unchanged. Written by `scripts/export_permissive_corpus.py`.",
        "",
        "## Sources and licences",
        "",
    ]
    for project, (licence, notice) in NOTICES.items():
        count = sum(r.project == project for r in rows)
        lines += [f"### {project} ({licence}, {count} rows)", "", notice, ""]
    lines += ["## Rows", "", "| row | source | licence | upstream path | name |",
              "|---:|---|---|---|---|"]
    for row in rows:
        name = row.name.replace("|", "\\|")
        lines.append(f"| {row.number} | {row.project} | {row.licence} | `{row.path}` | "
                     f"{name} |")
    OUT_ATTRIBUTION.write_text("\n".join(lines) + "\n", encoding="utf-8")
    print(f"wrote {OUT_TSV} ({len(rows)} rows) and {OUT_ATTRIBUTION}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv))
