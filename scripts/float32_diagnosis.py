"""Where exact's float32 program goes wrong on Chmutov's T_n (issue 48): the program with
one part computed in the other precision, rendered on gl (llvmpipe, double through
GL_ARB_gpu_shader_fp64) and counted against the certified float64 reference.

    python scripts/float32_diagnosis.py --size 256 12 16 20
    python scripts/float32_diagnosis.py --size 256 --backends gl,wgpu,cl,hlsl-spirv 14 16 20
        exact in float32 as compiled, on each backend, instead of the variants
    python scripts/float32_diagnosis.py --size 512 --time 5 --before old/ 7-20
        exact against taylor, both in float32 on gl, in turns (one warm-up frame, medians
        of 5); with --before, also the programs old/T<n>.frag (exact's float32 GLSL
        program compiled by an earlier commit)

Variants (docs/journal/2026-12-05-float32.md has the numbers):
- float, double: the programs as compiled (`-t glsl`, `--precision double`);
- double, S float: the double program with S at the point (node ends, Newton's last
  steps) computed by the float32 program's S;
- float, S double: the float32 program with S at the point in double (S as written);
- double, coefficients float: the double program with the ray's coefficients computed in
  float32 (then widened);
- float, coefficients double: the float32 program with the ray's coefficients computed in
  double (then rounded to float32);
- float, S + coefficients double: both.
The splices are templates/diagnosis/mixed.glsl.j2; the programs' own text is renamed
(S -> S_inner, ray_of -> ray_of_inner, Ray -> RayInner) where a part moves across.
"""

from __future__ import annotations

import argparse
import re
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "scripts"))

from eval_forms import sweep_equations  # noqa: E402
from float32_renderers import reference as cached_reference  # noqa: E402

from implc.emit import compile_shader, render_template  # noqa: E402
from implc.framing import frame  # noqa: E402
from implc.loaders import load_surface  # noqa: E402
from implc.methods import get_method  # noqa: E402
from implc.metrics import compare  # noqa: E402
from implc.render.gl import GlRunner  # noqa: E402

TYPES = {"float": ("float", "vec3"), "double": ("double", "dvec3")}


def span(text: str, header: str) -> tuple[int, int]:
    """Where the function whose first line matches `header` starts and ends."""
    start = re.search(header, text, re.M).start()
    return start, text.index("\n}\n", start) + 3


def with_extension(text: str) -> str:
    if "GL_ARB_gpu_shader_fp64" in text:
        return text
    line = render_template("diagnosis/mixed.glsl.j2", part="extension").strip() + "\n"
    return text.replace("#version 330 core\n", "#version 330 core\n" + line, 1)


def swap_s(outer: str, inner_text: str, inner: str, text: str) -> str:
    """`text` (in precision `outer`) with S computed by `inner_text`'s S."""
    o_type, o_vec = TYPES[outer]
    i_type, i_vec = TYPES[inner]
    a, b = span(inner_text, rf"^{i_type} S\({i_vec} p\)")
    s_inner = inner_text[a:b].replace(f"{i_type} S(", f"{i_type} S_inner(", 1)
    wrapper = render_template("diagnosis/mixed.glsl.j2", part="s", outer=o_type,
                              outer_vec=o_vec, inner=i_type, inner_vec=i_vec,
                              inner_name="S_inner")
    a, b = span(text, rf"^{o_type} S\({o_vec} p\)")
    return with_extension(text[:a] + s_inner + wrapper + text[b:])


def swap_ray(outer: str, inner_text: str, inner: str, text: str, n: int) -> str:
    """`text` with the ray's coefficients computed by `inner_text`'s ray_of."""
    o_type, o_vec = TYPES[outer]
    i_type, i_vec = TYPES[inner]
    a, b = span(inner_text, r"^Ray ray_of\(")
    body = inner_text[a:b].replace("Ray ray_of(", "RayInner ray_of_inner(", 1)
    body = body.replace("return Ray(", "return RayInner(", 1)
    record = re.search(r"struct Ray \{.*?\n\};\n", inner_text, re.S).group(0)
    record = record.replace("struct Ray {", "struct RayInner {", 1)
    wrapper = render_template("diagnosis/mixed.glsl.j2", part="ray", outer=o_type,
                              outer_vec=o_vec, inner=i_type, inner_vec=i_vec,
                              inner_ray="RayInner", n=n,
                              size=f"{o_type} size;" in text)
    a, b = span(text, r"^Ray ray_of\(")
    return with_extension(text[:a] + record + body + wrapper + text[b:])


def chmutov(n: int):
    """Chmutov's T_n framed as every command frames it (float32_renderers' view, whose
    certified references are cached)."""
    return frame(load_surface(equation=sweep_equations(n)["chmutov"]))[0]


def variants(n: int) -> tuple[object, dict[str, str]]:
    surface = chmutov(n)
    constants = get_method("exact").defaults
    f = compile_shader(surface, "glsl", "exact", constants, "330", precision="float").text
    d = compile_shader(surface, "glsl", "exact", constants, "330", precision="double").text
    float_coefficients_double = swap_ray("float", d, "double", f, n)
    return surface, {
        "float": f,
        "double": d,
        "double, S float": swap_s("double", f, "float", d),
        "float, S double": swap_s("float", d, "double", f),
        "double, coefficients float": swap_ray("double", f, "float", d, n),
        "float, coefficients double": float_coefficients_double,
        "float, S + coefficients double": swap_s("float", d, "double",
                                                 float_coefficients_double),
    }


def backends(degrees: list[int], size: int, names: list[str]) -> None:
    """exact as compiled (float32 on each float32 backend) against the reference."""
    from implc.render.run import open_runner

    print("| degree | backend | false / missed / wrong | bad pixels |")
    print("|---|---|---|---|")
    for n in degrees:
        surface = chmutov(n)
        reference = cached_reference(surface, size)
        for backend in names:
            runner = open_runner(surface, backend, "exact", get_method("exact").defaults,
                                 size, size)
            try:
                m = compare(runner.frame(), reference)
            finally:
                runner.release()
            print(_counts_row(n, backend, m, 4), flush=True)


def _counts_row(n: int, label: str, m: dict, digits: int) -> str:
    """A table row: false / missed / wrong pixels and their share of the picture."""
    bad = m["false_hits"] + m["missed_hits"] + m["wrong_root"]
    return (f"| T_{n} | {label} | {m['false_hits']} / {m['missed_hits']} / "
            f"{m['wrong_root']} | {bad} ({100 * bad / m['pixels']:.{digits}f} %) |")


def _degrees(text: str) -> list[int]:
    low, _, high = text.partition("-")
    return list(range(int(low), int(high or low) + 1))


def timing(degrees: list[int], size: int, frames: int, before: str | None) -> None:
    """exact (and the --before programs) against taylor, float32 on gl, in turns."""
    from gpu_bench import median_ms

    from implc.marcher import choose_form
    from implc.render.run import open_runner

    vertex = render_template("glsl/fullscreen.vert.j2", version="330 core")
    print("| degree | exact ms | taylor ms | exact / taylor | before ms | before / taylor |")
    print("|---|---|---|---|---|---|")
    for n in degrees:
        surface = chmutov(n)
        taylor = get_method("taylor").constants(
            evaluation=choose_form(get_method("taylor"), surface.expr))
        runners = [open_runner(surface, "gl", "exact", get_method("exact").defaults,
                               size, size),
                   open_runner(surface, "gl", "taylor", taylor, size, size)]
        if before:
            text = (Path(before) / f"T{n}.frag").read_text()
            runners.append(GlRunner(text, vertex, surface.view, size, size))
        ms = median_ms(runners, frames)
        old = f"{ms[2]:.1f} | {ms[2] / ms[1]:.2f}" if before else "| "
        print(f"| T_{n} | {ms[0]:.1f} | {ms[1]:.1f} | {ms[0] / ms[1]:.2f} | {old} |",
              flush=True)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("degrees", nargs="+", help="degrees, or ranges a-b")
    ap.add_argument("--size", type=int, default=256)
    ap.add_argument("--backends", help="comma-separated: exact as compiled on each")
    ap.add_argument("--time", type=int, metavar="FRAMES", help="time exact against taylor")
    ap.add_argument("--before", help="a directory of T<n>.frag programs to time beside")
    args = ap.parse_args()
    args.degrees = [n for part in args.degrees for n in _degrees(part)]
    if args.time:
        timing(args.degrees, args.size, args.time, args.before)
        return
    if args.backends:
        backends(args.degrees, args.size, args.backends.split(","))
        return
    vertex = render_template("glsl/fullscreen.vert.j2", version="330 core")
    print("| degree | variant | false / missed / wrong | bad pixels |")
    print("|---|---|---|---|")
    for n in args.degrees:
        surface, programs = variants(n)
        reference = cached_reference(surface, args.size)
        for name, text in programs.items():
            runner = GlRunner(text, vertex, surface.view, args.size, args.size)
            try:
                m = compare(runner.frame(), reference)
            finally:
                runner.release()
            print(_counts_row(n, name, m, 3), flush=True)


if __name__ == "__main__":
    main()
