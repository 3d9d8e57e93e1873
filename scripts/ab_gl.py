"""Compare GLSL fragment programs side by side in one GL context (llvmpipe here).

    python scripts/ab_gl.py --size 96 --aux OLD.frag NEW.frag ...    aux identity, pairwise
    python scripts/ab_gl.py --size 512 --frames 5 A.frag B.frag ...   median ms per frame

Programs are implc GLSL 330 programs (uniforms u_resolution, u_eye, ...); the camera is
the surface's [view] (--surface, default cross-cap). Timed frames are interleaved (A, B,
C, A, B, C, ...) so that machine noise hits every program alike; each ends in glFinish.
Used for the old-versus-new measurements of issue 9 (docs/journal/2026-12-01-marcher-and-forms.md).
"""

from __future__ import annotations

import argparse
import statistics
import time
from pathlib import Path

from implc.emit import render_template
from implc.loaders import load_surface
from implc.render.gl import GlRunner


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("programs", nargs="+")
    ap.add_argument("--surface", default="cross-cap")
    ap.add_argument("--size", type=int, default=96)
    ap.add_argument("--frames", type=int, default=5)
    ap.add_argument("--aux", action="store_true", help="compare aux of consecutive pairs")
    args = ap.parse_args()
    view = load_surface(args.surface).view
    vertex = render_template("glsl/fullscreen.vert.j2", version="330 core")
    runners = [GlRunner(Path(p).read_text(), vertex, view, args.size, args.size)
               for p in args.programs]
    if args.aux:
        pairs = list(zip(args.programs, runners, strict=True))
        for (pa, a), (pb, b) in zip(pairs[::2], pairs[1::2], strict=True):
            ra, rb = a.frame(), b.frame()
            same = ((ra.hit == rb.hit) & (ra.t == rb.t) & (ra.steps == rb.steps))
            print(f"{int((~same).sum()):6d} of {same.size} pixels differ "
                  f"(hit {int((ra.hit != rb.hit).sum())}, t {int((ra.t != rb.t).sum())}, "
                  f"steps {int((ra.steps != rb.steps).sum())}): {pa} vs {pb}")
        return
    for r in runners:
        r.frame()  # warm-up
    times: list[list[float]] = [[] for _ in runners]
    for _ in range(args.frames):
        for k, r in enumerate(runners):
            start = time.perf_counter()
            r.draw()
            times[k].append(time.perf_counter() - start)
    base = statistics.median(times[0])
    for p, ts in zip(args.programs, times, strict=True):
        m = statistics.median(ts)
        print(f"{1000 * m:9.1f} ms  {base / m:5.2f}x of the first  {p}")


if __name__ == "__main__":
    main()
