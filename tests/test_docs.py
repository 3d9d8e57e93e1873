"""The documentation site builds, strictly and offline (mkdocs.yml, pages under docs/).

`mkdocs build --strict` fails on a broken link or anchor, a page left out of the nav and a
missing included file, so a page moved or renamed without its links fails here, not in a
reader's browser. The built pages may not load anything from the network (no web font, no
CDN script): the site must read the same on a machine without one.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def build(tmp_path: Path) -> Path:
    """The site built into a temp dir; the test fails with mkdocs' own messages."""
    site = tmp_path / "site"
    env = dict(os.environ, NO_MKDOCS_2_WARNING="1")
    proc = subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "-f",
                           str(ROOT / "mkdocs.yml"), "-d", str(site)],
                          capture_output=True, text=True, env=env, timeout=300)
    assert proc.returncode == 0, proc.stderr[-4000:]
    return site


def test_the_site_builds_strictly_and_loads_nothing_from_the_network(tmp_path):
    site = build(tmp_path)
    pages = sorted(site.rglob("*.html"))
    assert (site / "index.html").is_file() and len(pages) > 3, pages
    remote = re.compile(r'<(?:script|link|img)\b[^>]*\b(?:src|href)="(?:https?:)?//', re.I)
    fetched = [str(p.relative_to(site)) for p in pages if remote.search(p.read_text("utf-8"))]
    assert not fetched, f"pages that load from the network: {fetched}"


def test_the_command_line_reference_is_the_parser_s():
    """docs/reference/cli.md is what scripts/cli_reference.py writes from build_parser():
    an option added, renamed or re-described without `make cli-reference` fails here."""
    sys.path.insert(0, str(ROOT / "scripts"))
    try:
        from cli_reference import page
    finally:
        sys.path.remove(str(ROOT / "scripts"))
    committed = (ROOT / "docs" / "reference" / "cli.md").read_text(encoding="utf-8")
    assert committed == page(), "docs/reference/cli.md is stale: run `make cli-reference`"
