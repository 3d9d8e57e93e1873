"""Regenerate the README's gallery pictures (`make gallery-pictures`).

docs/gallery-examples.png: `implc gallery` of every bundled example; docs/gallery-corpus.png:
of the first 24 rows of the shared corpus (../shared/corpus) not from SURFER, each written
as a TOML surface file (name, equation, [params]) so that its cell shows the row's name.
Both at 96 pixels a thumbnail; each picture is the run's contact-sheet.png.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from implc.corpus import default_tsv, load_rows  # noqa: E402
from implc.surface import example_paths  # noqa: E402

SIZE = "96"
CORPUS_ROWS = 24


def gallery(surfaces: list[str], picture: Path, work: Path) -> None:
    out = work / picture.stem
    env = {**os.environ, "PYTHONPATH": str(ROOT), "IMPLC_NO_PROGRESS_BAR": "1"}
    subprocess.run([sys.executable, "-m", "implc", "gallery", *surfaces, "--size", SIZE,
                    "-o", str(out)], check=True, env=env)
    shutil.copyfile(out / "contact-sheet.png", picture)
    print(f"wrote {picture.relative_to(ROOT)}")


def toml(name: str, equation: str, params: dict[str, object]) -> str:
    """A surface file; json's string quoting is TOML's for these ASCII strings."""
    lines = [f"name = {json.dumps(name)}", f"equation = {json.dumps(equation)}"]
    if params:
        lines.append("[params]")
        lines += [f"{key} = {json.dumps(value)}" for key, value in params.items()]
    return "\n".join(lines) + "\n"


def main() -> int:
    tsv = default_tsv()
    if tsv is None:
        print("gallery_pictures: the shared corpus (../shared/corpus) is missing",
              file=sys.stderr)
        return 4
    rows = [r for r in load_rows(tsv) if not r.source.startswith("IMAGINARY/SURFER")]
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        gallery(list(example_paths()), ROOT / "docs" / "gallery-examples.png", work)
        files = []
        for i, row in enumerate(rows[:CORPUS_ROWS]):
            path = work / f"{i:02d}-{row.name.replace(' ', '_')}.toml"
            path.write_text(toml(row.name, row.equation, row.params))
            files.append(str(path))
        gallery(files, ROOT / "docs" / "gallery-corpus.png", work)
    return 0


if __name__ == "__main__":
    sys.exit(main())
