"""exact in float32 on every float32 renderer implc runs (issue 48): the pixels it gets
wrong (false hits + missed + wrong root) against the certified float64 reference, per
surface and renderer: llvmpipe (gl), lavapipe (wgpu), PoCL (cl), HLSL through SPIR-V on
llvmpipe (hlsl-spirv), and Chromium's WebGL2 and WebGPU on SwiftShader (webgl2, webgpu).

    python scripts/float32_renderers.py --size 512 --degrees 2-20
        Chmutov's T_n, n = 2..20 (the degree sweep's family whose monomials float32 cannot
        hold from degree 7), a row each
    python scripts/float32_renderers.py --size 512 --degrees 2-20 --gallery \\
        --write docs/results-float32.md
        and the gallery's rows (every bundled polynomial and corpus rows 137, 163, 285,
        244, 247), written into the page between its float32-renderers markers

The references do not depend on the programs, and Chmutov's take minutes each at 512^2
(T_16 about 6 CPU minutes): each is kept in results/reference-cache/ under a hash of S, the
view and the size, and read back by later runs.
"""

from __future__ import annotations

import argparse
import hashlib
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "scripts"))

from docs_section import commit, machine, replace_marked  # noqa: E402
from eval_forms import sweep_equations  # noqa: E402

from implc.derive import polynomial_degree  # noqa: E402
from implc.errors import ToolError  # noqa: E402
from implc.framing import frame  # noqa: E402
from implc.loaders import load_surface  # noqa: E402
from implc.methods import get_method  # noqa: E402
from implc.metrics import compare  # noqa: E402
from implc.render.result import RenderResult  # noqa: E402
from implc.render.run import open_runner  # noqa: E402

RENDERERS = ("gl", "wgpu", "cl", "hlsl-spirv", "webgl2", "webgpu")
# the gallery rows of docs/RESULTS.md's degree sweep section: bundled polynomials, then
# corpus rows by number
GALLERY = ("sphere", "cayley", "clebsch", "ding-dong", "whitney-umbrella", "roman", "steiner",
           "cross-cap", "miter", "tooth", "torus", "kummer", "barth-sextic", "heart",
           "barth-decic", "137", "163", "285", "244", "247")
BOUND = 1e-4  # the goal: at most 0.01 % of the pixels wrong
CACHE = ROOT / "results" / "reference-cache"
FIELDS = ("color", "hit", "t", "steps", "residual")


def reference(surface, size: int) -> RenderResult:
    """The certified reference of the framed `surface`, from the cache when it is there."""
    key = hashlib.sha256(f"{surface.expr!r}|{surface.view!r}|{size}".encode()).hexdigest()
    path = CACHE / f"{key[:24]}.npz"
    if path.exists():
        with np.load(path) as data:
            return RenderResult(**{f: data[f] for f in FIELDS})
    result = open_runner(surface, "reference", "", get_method("taylor").defaults,
                         size, size).frame()
    CACHE.mkdir(parents=True, exist_ok=True)
    partial = path.with_suffix(".partial.npz")
    np.savez_compressed(partial, **{f: getattr(result, f) for f in FIELDS})
    partial.replace(path)
    return result


def bad_pixels(surface, backend: str, size: int, ref: RenderResult) -> int | str:
    """exact's wrong pixels on `backend`, or "–" where the renderer cannot run here."""
    try:
        runner = open_runner(surface, backend, "exact", get_method("exact").defaults,
                             size, size)
    except ToolError as err:
        print(f"{backend}: {err}", file=sys.stderr)
        return "–"
    try:
        m = compare(runner.frame(), ref)
    finally:
        runner.release()
    return int(m["false_hits"] + m["missed_hits"] + m["wrong_root"])


def surfaces(degrees: list[int], gallery: bool):
    """(label, surface) of each row, framed as every command frames it."""
    for n in degrees:
        yield f"Chmutov T_{n}", load_surface(equation=sweep_equations(n)["chmutov"])
    if gallery:
        from implc.corpus import default_tsv, load_rows, row_surface

        rows = {r.number: r for r in load_rows(default_tsv())}
        for name in GALLERY:
            if name.isdigit():
                yield f"{rows[int(name)].name} ({name})", row_surface(rows[int(name)])
            else:
                yield name, load_surface(name)


def table(degrees: list[int], gallery: bool, size: int, renderers: list[str]) -> str:
    bound = BOUND * size * size
    lines = [f"| surface | degree | {' | '.join(renderers)} |",
             "|---|---|" + "---|" * len(renderers)]
    for label, surface in surfaces(degrees, gallery):
        surface, _ = frame(surface)
        ref = reference(surface, size)
        cells = [bad_pixels(surface, b, size, ref) for b in renderers]
        shown = [f"**{c}**" if isinstance(c, int) and c > bound else str(c) for c in cells]
        line = f"| {label} | {polynomial_degree(surface.expr)} | {' | '.join(shown)} |"
        print(line, file=sys.stderr, flush=True)
        lines.append(line)
    return "\n".join(lines) + "\n"


def _degrees(text: str) -> list[int]:
    if not text:
        return []
    lo, _, hi = text.partition("-")
    return list(range(int(lo), int(hi or lo) + 1))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--size", type=int, default=512)
    ap.add_argument("--degrees", default="2-20", help="Chmutov's degrees, e.g. 2-20 ('' none)")
    ap.add_argument("--gallery", action="store_true", help="the gallery's rows too")
    ap.add_argument("--renderers", default=",".join(RENDERERS))
    ap.add_argument("--write", type=Path, metavar="MARKDOWN",
                    help="rewrite the page's float32-renderers part with the table")
    args = ap.parse_args()
    renderers = args.renderers.split(",")
    text = table(_degrees(args.degrees), args.gallery, args.size, renderers)
    print(text)
    if args.write:
        command = " ".join(["python scripts/float32_renderers.py", *sys.argv[1:]])
        head = (f"Made by `{command}` at commit {commit()} on {machine()}: exact's wrong "
                f"pixels (false + missed + wrong root) of {args.size}² against the certified "
                f"reference; bold: over the issue's 0.01 % ({BOUND * args.size ** 2:.0f} "
                f"pixels); –: the renderer did not run.")
        replace_marked(args.write, "float32-renderers", head + "\n\n" + text)


if __name__ == "__main__":
    main()
