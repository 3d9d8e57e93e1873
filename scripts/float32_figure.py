"""Why the sweep's Chmutov rows miss 0.67 in float32 from degree 17: a picture
(docs/float32-chmutov.png, docs/RESULTS.md, "The degree sweep").

    python scripts/float32_figure.py --degree 20 --size 384 -o docs/float32-chmutov.png \
        --before old.frag    (exact's float32 GLSL program from an earlier commit, drawn beside)

Chmutov's T_n + T_n + T_n = 0 as the sweep writes it (scripts/eval_forms.py), in the
sweep's view: exact in float32 (gl) and in double (gl-double) and taylor in float32,
shaded; the nodes each exact ray visits (the shader's `steps`); and where each float32
picture puts the root more than 1e-3 from exact's in double (the distance the counts
call a wrong root), or hits where it does not.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "scripts"))

from eval_forms import sweep_equations  # noqa: E402

from implc.loaders import load_surface  # noqa: E402
from implc.methods import get_method  # noqa: E402
from implc.render.run import render  # noqa: E402

WRONG = 1e-3  # a root this far from double's is wrong (implc.metrics' measure)


def disagreement(result, double) -> np.ndarray:
    """Pixels where `result` and exact in double disagree: a hit on one side only, or
    roots more than WRONG apart."""
    both = result.hit & double.hit
    return (result.hit != double.hit) | (both & (np.abs(result.t - double.t) > WRONG))


def _before(path: Path, surface, size: int):
    """An earlier commit's exact float32 GLSL program, rendered on gl in the same view."""
    from implc.emit import render_template
    from implc.render.gl import GlRunner

    vertex = render_template("glsl/fullscreen.vert.j2", version="330 core")
    runner = GlRunner(path.read_text(), vertex, surface.view, size, size)
    try:
        return runner.frame()
    finally:
        runner.release()


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--degree", type=int, default=20)
    ap.add_argument("--size", type=int, default=384)
    ap.add_argument("-o", "--output", default=str(ROOT / "docs" / "float32-chmutov.png"))
    ap.add_argument("--before", help="exact's float32 GLSL program (330) of an earlier "
                    "commit: drawn beside the current one")
    args = ap.parse_args()

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    surface = load_surface(equation=sweep_equations(args.degree)["chmutov"] + " = 0")
    exact, taylor = get_method("exact").defaults, get_method("taylor").defaults
    size = args.size
    runs = {"exact, float32": render(surface, "gl", "exact", exact, size, size),
            "exact, double": render(surface, "gl-double", "exact", exact, size, size),
            "taylor, float32": render(surface, "gl", "taylor", taylor, size, size)}
    if args.before:
        runs = {"exact, float32 before": _before(Path(args.before), surface, size), **runs}
    double = runs["exact, double"]
    columns = len(runs)
    fig, axes = plt.subplots(2, columns, figsize=(4 * columns, 8.6), dpi=80)
    for ax, (name, result) in zip(axes[0], runs.items(), strict=True):
        ax.imshow(np.clip(result.color, 0, 1))
        ax.set_title(f"T{args.degree}: {name}")
    top = max(float(np.percentile(r.steps[r.steps > 0], 99.5))
              for name, r in runs.items() if name.startswith("exact"))
    exacts = [name for name in runs if name.startswith("exact")]
    for ax, name in zip(axes[1][:len(exacts)], exacts, strict=True):
        steps = runs[name].steps
        shown = ax.imshow(steps, cmap="magma", vmin=0, vmax=top)
        block = steps[: size // 4 * 4, : size // 4 * 4].reshape(size // 4, 4, size // 4, 4)
        ax.set_title(f"{name}: nodes a ray {steps[steps > 0].mean():.2f},\n"
                     f"the 4x4 block's most {block.max(axis=(1, 3)).mean():.1f} on average",
                     fontsize=10)
        fig.colorbar(shown, ax=ax, fraction=0.046)
    by_exact = disagreement(runs["exact, float32"], double)
    by_taylor = disagreement(runs["taylor, float32"], double)
    wrong = np.zeros((size, size, 3))
    wrong[by_exact & ~by_taylor] = (1.0, 0.5, 0.0)
    wrong[by_taylor & ~by_exact] = (0.2, 0.4, 1.0)
    wrong[by_exact & by_taylor] = (1.0, 1.0, 1.0)
    axes[1][-1].imshow(wrong)
    shares = {name: disagreement(runs[name], double).mean()
              for name in runs if name != "exact, double"}
    before = (f"; before {100 * shares['exact, float32 before']:.1f} %"
              if "exact, float32 before" in shares else "")
    axes[1][-1].set_title(f"> {WRONG:g} from exact in double, or a hit on one side:\n"
                          f"exact float32 {100 * shares['exact, float32']:.2f} % (orange"
                          f"{before}),\ntaylor float32 "
                          f"{100 * shares['taylor, float32']:.0f} % (blue), both: white",
                          fontsize=9)
    for ax in axes.flat:
        ax.set_xticks([])
        ax.set_yticks([])
    fig.tight_layout()
    fig.savefig(args.output)
    print(f"wrote {args.output}")


if __name__ == "__main__":
    main()
