"""The documentation site builds, strictly and offline (mkdocs.yml, pages under docs/).

`mkdocs build --strict` fails on a broken link or anchor, a page left out of the nav and a
missing included file, so a page moved or renamed without its links fails here, not in a
reader's browser. The built pages may not load anything from the network (no web font, no
CDN script): the site must read the same on a machine without one.
"""

from __future__ import annotations

import os
import re
import shlex
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
    """docs/reference/cli.md and cli/COMMAND.md are what scripts/cli_reference.py writes
    from build_parser(): an option or a command added, renamed or re-described without
    `make cli-reference` fails here."""
    sys.path.insert(0, str(ROOT / "scripts"))
    try:
        from cli_reference import pages
    finally:
        sys.path.remove(str(ROOT / "scripts"))
    reference = ROOT / "docs" / "reference"
    fresh = pages()
    committed = {"cli.md"} | {f"cli/{p.name}" for p in (reference / "cli").glob("*.md")}
    assert committed == set(fresh), "a command's page is missing or left over: run " \
                                    "`make cli-reference`"
    for name, text in fresh.items():
        assert (reference / name).read_text(encoding="utf-8") == text, \
            f"docs/reference/{name} is stale: run `make cli-reference`"


PAGE_LINES = 600


def test_no_page_is_longer_than_600_lines():
    """A page a reader can finish: the README at most 150 lines, every docs page 600."""
    assert len((ROOT / "README.md").read_text("utf-8").splitlines()) <= 150
    docs = ROOT / "docs"
    long = {str(p.relative_to(docs)): n for p in docs.rglob("*.md")
            if (n := len(p.read_text("utf-8").splitlines())) > PAGE_LINES}
    assert not long, long


def test_the_readme_s_first_commands_run(tmp_path):
    """Every line of the README's "First commands" block runs and exits 0, as a newcomer
    types it (`implc` is this checkout's, in a fresh directory)."""
    readme = (ROOT / "README.md").read_text("utf-8")
    block = readme.split("## First commands", 1)[1].split("```sh\n", 1)[1].split("```", 1)[0]
    commands = [line.split("#", 1)[0].strip() for line in block.splitlines()]
    commands = [c for c in commands if c]
    assert len(commands) >= 5 and all(c.startswith("implc ") for c in commands), commands
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    for command in commands:
        argv = [sys.executable, "-m", "implc", *shlex.split(command)[1:]]
        proc = subprocess.run(argv, cwd=tmp_path, capture_output=True, text=True, env=env,
                              timeout=300)
        assert proc.returncode == 0, (command, proc.stderr[-2000:])


FENCE = re.compile(r"^```(\w*)\n(.*?)^```", re.M | re.S)
GUIDE = [ROOT / "README.md", *sorted((ROOT / "docs" / "guide").glob("*.md")),
         ROOT / "docs" / "reference" / "input-language.md"]


def blocks(language: str) -> list[tuple[str, str]]:
    """(page, code) of every fenced block in `language` on the README and the guide."""
    return [(str(page.relative_to(ROOT)), match.group(2))
            for page in GUIDE for match in FENCE.finditer(page.read_text("utf-8"))
            if match.group(1) == language]


def run(argv: list[str], cwd: Path, where: str) -> None:
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    proc = subprocess.run(argv, cwd=cwd, capture_output=True, text=True, env=env, timeout=600)
    assert proc.returncode == 0, (where, argv[-1][:200], proc.stderr[-2000:])


def test_the_guide_s_code_blocks_run(tmp_path):
    """Every Python block of the README and the guide runs as a script, every `implc`
    line of their shell blocks runs, and every TOML block is a surface file `implc show`
    reads: an example that drifts from the program fails here. (The JavaScript, HTML and
    shader blocks are the drop-ins' own tests': tests/test_browser.py, tests/test_wgsl.py.)"""
    python, shell, toml = blocks("python"), blocks("sh"), blocks("toml")
    assert len(python) >= 4 and toml, (len(python), len(toml))
    for n, (page, code) in enumerate(python):
        work = tmp_path / f"py{n}"
        work.mkdir()
        run([sys.executable, "-c", code], work, page)
    for page, code in shell:  # the README's are test_the_readme_s_first_commands_run's
        for line in code.splitlines():
            command = line.split("#", 1)[0].strip()
            if command.startswith("implc ") and page != "README.md":
                run([sys.executable, "-m", "implc", *shlex.split(command)[1:]], tmp_path, page)
    for n, (page, code) in enumerate(toml):
        surface = tmp_path / f"surface{n}.toml"
        surface.write_text(code, encoding="utf-8")
        run([sys.executable, "-m", "implc", "show", str(surface)], tmp_path, page)


def test_the_python_reference_names_every_public_name():
    """docs/reference/python.md renders each name of `implc.__all__` from its docstring
    (mkdocstrings); a public name added without its entry fails here."""
    import implc

    page = (ROOT / "docs" / "reference" / "python.md").read_text("utf-8")
    listed = set(re.findall(r"^::: implc\.api\.(\w+)$", page, re.M))
    public = set(implc.__all__) - {"__version__"}
    assert listed == public, f"missing: {public - listed}, not public: {listed - public}"


def test_make_bench_rewrites_its_tables_in_place(tmp_path):
    """`make bench`'s second step: a real `implc bench` table goes between the results
    page's bench markers with the command and the commit above it, and not a character of
    the page outside them moves; a page without the markers is refused."""
    results = tmp_path / "results"
    run([sys.executable, "-m", "implc", "bench", "cross-cap", "--size", "32", "--frames", "1",
         "--configs", "paper", "-o", str(results)], tmp_path, "implc bench")
    page = tmp_path / "RESULTS.md"
    before = (ROOT / "docs" / "RESULTS.md").read_text("utf-8")
    page.write_text(before, encoding="utf-8")
    script = [sys.executable, str(ROOT / "scripts" / "docs_section.py"), "bench",
              str(results / "table.md"), "--write"]
    run([*script, str(page)], tmp_path, "docs_section.py")
    after = page.read_text("utf-8")
    span = re.compile(r"<!-- bench:begin -->.*?<!-- bench:end -->", re.S)
    assert span.sub("", after) == span.sub("", before)
    table = span.search(after).group(0)
    assert "Made by `make bench` at commit " in table and "32x32 pixels" in table, table[:400]
    assert "\n### paper: the paper's constants" in table and "\n# implc bench" not in table
    bare = tmp_path / "bare.md"
    bare.write_text("# no markers\n", encoding="utf-8")
    proc = subprocess.run([*script, str(bare)], capture_output=True, text=True, timeout=60)
    assert proc.returncode != 0 and "no <!-- bench:begin -->" in proc.stderr, proc.stderr


def test_make_forms_rewrites_its_sweep_table_in_place(tmp_path):
    """`make forms`: the degree sweep's printed table (a real one, at 32^2 and degree 2)
    goes between the results page's forms-sweep markers under the command and the commit,
    and nothing outside them moves."""
    sweep = tmp_path / "forms-sweep.md"
    proc = subprocess.run([sys.executable, str(ROOT / "scripts" / "eval_forms.py"), "sweep",
                           "--size", "32", "--frames", "1", "--degrees", "2-2"],
                          cwd=tmp_path, capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr[-2000:]
    sweep.write_text(proc.stdout, encoding="utf-8")
    page = tmp_path / "RESULTS.md"
    before = (ROOT / "docs" / "RESULTS.md").read_text("utf-8")
    page.write_text(before, encoding="utf-8")
    run([sys.executable, str(ROOT / "scripts" / "docs_section.py"), "forms-sweep", str(sweep),
         "--write", str(page), "--command", "make forms"], tmp_path, "docs_section.py")
    after = page.read_text("utf-8")
    span = re.compile(r"<!-- forms-sweep:begin -->.*?<!-- forms-sweep:end -->", re.S)
    assert span.sub("", after) == span.sub("", before)
    part = span.search(after).group(0)
    assert "Made by `make forms` at commit " in part and " cores." in part  # the machine
    assert "\n| chmutov | 2 | " in part and "\n| powers | 2 | " in part
    assert "| chmutov | 20 |" not in part  # the old run's rows are gone
