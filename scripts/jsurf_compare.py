"""implc's picture of a .jsurf file against jsurf's own (README "SURFER files").

jsurf is not a dependency (a Java program built from its source), so this is a
measurement, not a test: `--jsurf` is the command that runs it, e.g. a shell script
`java -cp ... de.mfo.jsurf.Main --quality 0 "$@"`. For each file it renders jsurf's
picture twice, on a black and on a white background (a pixel that does not change is a
hit: jsurf's shading is not implc's, its coverage must be), and implc's with the default
method on the GL backend, and prints both hit fractions and the share of pixels on
which they agree.

`--export` first runs each SURFACE (anything `implc render` takes) through
`implc compile --emit jsurf` and gives jsurf that file: implc's picture of the surface
against jsurf's of the export.
"""

from __future__ import annotations

import argparse
import re
import shlex
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
from PIL import Image

from implc.loaders import load_surface
from implc.loaders.jsurf_write import to_jsurf
from implc.marcher import default_method
from implc.methods import get_method
from implc.render.run import render


def jsurf_hits(jsurf: list[str], text: str, size: int, work: Path) -> np.ndarray:
    """jsurf's hit mask of a .jsurf file's text: pixels equal on black and white."""
    images = []
    for name, colour in (("black", "0.0 0.0 0.0"), ("white", "1.0 1.0 1.0")):
        body = re.sub(r"(?m)^background_color=.*$", "", text)
        path = work / f"{name}.jsurf"
        path.write_text(f"{body}\nbackground_color={colour}\n")
        png = work / f"{name}.png"
        subprocess.run([*jsurf, "-s", str(size), str(path), str(png)], check=True,
                       capture_output=True, timeout=1200)
        images.append(np.asarray(Image.open(png).convert("RGB")).astype(np.int16))
    return np.abs(images[0] - images[1]).max(axis=-1) < 128


def implc_hits(spec: str, size: int) -> np.ndarray:
    surface = load_surface(spec)
    method = default_method(surface.expr)
    result = render(surface, "gl", method, get_method(method).defaults, size, size)
    return np.asarray(result.hit).astype(bool)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--jsurf", required=True, help="command that runs jsurf")
    parser.add_argument("--size", type=int, default=256)
    parser.add_argument("--export", action="store_true",
                        help="SURFACES are implc surfaces: compare with jsurf's picture "
                             "of their --emit jsurf export")
    parser.add_argument("surfaces", nargs="+")
    args = parser.parse_args()
    jsurf = shlex.split(args.jsurf)
    worst = 0.0
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        for spec in args.surfaces:
            text = (to_jsurf(load_surface(spec)) if args.export
                    else Path(spec).read_text(encoding="latin-1"))
            js = jsurf_hits(jsurf, text, args.size, work)
            im = implc_hits(spec, args.size)
            diff = 100.0 * (im.mean() - js.mean())
            worst = max(worst, abs(diff))
            camera = re.search(r"(?m)^camera_type=\s*(\w+)", text)
            print(f"{Path(spec).name:34s} {camera.group(1) if camera else '?':20s} "
                  f"jsurf {100 * js.mean():6.2f} %  implc {100 * im.mean():6.2f} %  "
                  f"diff {diff:+6.2f} pts  agree {100 * (js == im).mean():6.2f} %",
                  flush=True)
    print(f"largest |diff| {worst:.2f} pts")
    return 0


if __name__ == "__main__":
    sys.exit(main())
