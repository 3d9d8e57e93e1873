"""Rewrite a generated part of a docs page in place, between its markers (issue 47).

A table that a make target measures lives on the results page between
`<!-- NAME:begin -->` and `<!-- NAME:end -->`; the target rewrites only that part, so the
page's prose stays and the figures are always the last run's, with the command, the
commit and the machine named above them.

    python scripts/docs_section.py bench results/table.md --write docs/RESULTS.md

copies `implc bench`'s table.md (its headings one level down, its own title dropped) under
a line naming `make bench`, the commit and the machine (`make bench` runs it);
`forms-sweep` does the same for the degree sweep's table that `scripts/eval_forms.py
sweep` prints (`make forms`).
"""

from __future__ import annotations

import argparse
import re
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def replace_marked(path: Path, name: str, text: str) -> None:
    """Put `text` between the page's `name` markers; exit with a message if it has none."""
    begin, end = f"<!-- {name}:begin -->", f"<!-- {name}:end -->"
    page = path.read_text(encoding="utf-8")
    span = re.compile(re.escape(begin) + ".*?" + re.escape(end), re.S)
    if not span.search(page):
        sys.exit(f"{path} has no {begin} ... {end} part to replace")
    body = text if text.endswith("\n") else text + "\n"
    path.write_text(span.sub(lambda _: f"{begin}\n{body}{end}", page), encoding="utf-8")


def commit() -> str:
    """The checkout's commit (with `+` when the tree has changes), or `unknown`."""
    try:
        head = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT,
                              capture_output=True, text=True, check=True).stdout.strip()
        dirty = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no"],
                               cwd=ROOT, capture_output=True, text=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "unknown"
    return head + ("+" if dirty else "")


def machine() -> str:
    """This machine as a results table names it: its CPU model and core count."""
    import os
    import platform

    model = platform.processor() or platform.machine()
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                model = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    return f"{model}, {os.cpu_count()} cores"


def bench_section(table: str, command: str) -> str:
    """`implc bench`'s table.md as a part of the results page."""
    lines = table.strip().splitlines()
    if lines and lines[0].startswith("# "):
        lines = lines[1:]
    lines = [("#" + line) if line.startswith("## ") else line for line in lines]
    head = f"Made by `{command}` at commit {commit()} on {machine()}."
    return head + "\n\n" + "\n".join(lines).strip() + "\n"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("name", choices=["bench", "forms-sweep"],
                    help="the part of the page to rewrite")
    ap.add_argument("source", type=Path, help="the measured Markdown (results/table.md, "
                    "or eval_forms.py sweep's printed table)")
    ap.add_argument("--write", type=Path, required=True, metavar="MARKDOWN")
    ap.add_argument("--command", default="make bench", help="what made the source")
    args = ap.parse_args()
    text = bench_section(args.source.read_text(encoding="utf-8"), args.command)
    replace_marked(args.write, args.name, text)


if __name__ == "__main__":
    main()
