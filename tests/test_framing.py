"""Issue 23, points 1-3: a render that shows the surface, or says why not.

A surface given without a view (`-e`, or a file whose [view] sets neither `radius` nor
`eye`) is framed automatically (implc/extent.py finds it, implc/scene.py `apply_view`
places the clip sphere and the camera); `--radius --center --eye --look-at --up
--fov` override the file's [view]; a render prints its hit fraction and warns when nothing is
hit or when the surface reaches the clip sphere. Renders here use the CPU reference at
a few dozen pixels (no GPU needed).
"""

from __future__ import annotations

import json
import math
import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import sympy

from implc.loaders import load_surface
from implc.scene import View, camera_basis
from implc.surface import example_paths

# the framing API (new with issue 23), imported per test so that the command-line tests
# below run, and fail, against a tree without it


def locate_surface(*args, **kwargs):
    from implc.extent import locate_surface

    return locate_surface(*args, **kwargs)


def crosses_sphere(*args, **kwargs):
    from implc.extent import crosses_sphere

    return crosses_sphere(*args, **kwargs)


def apply_view(*args, **kwargs):
    from implc.scene import apply_view

    return apply_view(*args, **kwargs)


def ViewOptions(**kwargs):  # noqa: N802 (the class, imported late)
    from implc.scene import ViewOptions

    return ViewOptions(**kwargs)


def frame_direction(up):
    from implc.scene import frame_direction

    return frame_direction(up)

ROOT = Path(__file__).resolve().parent.parent


def implc(*args: str):
    return subprocess.run(
        [sys.executable, "-m", "implc", *args], capture_output=True, text=True, cwd=ROOT,
        timeout=300, env={**os.environ, "PYTHONPATH": str(ROOT)},
    )


def render(tmp_path: Path, *args: str, size: int = 32):
    out = tmp_path / "a.png"
    proc = implc("render", *args, "-b", "reference", "--size", str(size), "-o", str(out))
    assert "Traceback" not in proc.stderr, proc.stderr
    sidecar = json.loads(out.with_suffix(".json").read_text()) if out.exists() else None
    return proc, sidecar


def hit_percent(stderr: str) -> float:
    match = re.search(r"rendered \d+x\d+ .*; ([\d.]+) % of pixels hit", stderr)
    assert match, stderr
    return float(match.group(1))


def expr(text: str) -> sympy.Expr:
    return load_surface(equation=text).expr


# --- point 1: the extent search ------------------------------------------------------------

def test_a_sphere_of_radius_3_is_found_with_a_margin():
    extent = locate_surface(expr("x^2+y^2+z^2-9"))
    assert extent is not None and extent.bounded
    assert extent.center == (0.0, 0.0, 0.0)
    assert extent.radius == pytest.approx(3.3)


def test_an_offset_small_surface_is_centred_on_itself():
    extent = locate_surface(expr("(x-5)^2 + y^2 + (z+2)^2 - 0.25"))
    assert extent is not None and extent.bounded
    assert extent.center == pytest.approx((5.0, 0.0, -2.0))
    assert 0.5 < extent.radius < 0.6


def test_a_tiny_surface_is_found_by_the_small_cubes():
    extent = locate_surface(expr("x^2+y^2+z^2-0.0001"))
    assert extent is not None and extent.bounded
    assert 0.01 < extent.radius <= 0.012


def test_an_unbounded_surface_shows_the_part_near_the_origin():
    extent = locate_surface(expr("z - x*y"))
    assert extent is not None and not extent.bounded
    assert extent.center == (0.0, 0.0, 0.0) and extent.radius == 2.0


def test_no_real_surface_is_no_extent():
    assert locate_surface(expr("x^2+y^2+z^2+1")) is None


def test_a_given_centre_keeps_its_place():
    extent = locate_surface(expr("x^2+y^2+z^2-1"), center=(0.5, 0.0, 0.0))
    assert extent is not None and extent.center == (0.5, 0.0, 0.0)
    assert 1.5 <= extent.radius <= 1.7


# --- point 1: the framing rule -------------------------------------------------------------

def test_bundled_examples_keep_their_views():
    """Every bundled file sets `radius`: nothing is searched, nothing moves (goldens)."""
    def locate(center):
        raise AssertionError("a bundled example is not searched")

    for name in example_paths():
        view = load_surface(name).view
        framed, framing = apply_view(view, ViewOptions(), locate)
        assert framed == view and framing is None, name


def test_a_view_without_radius_or_eye_is_framed():
    sphere = expr("x^2+y^2+z^2-9")
    framed, framing = apply_view(View(), ViewOptions(), lambda c: locate_surface(sphere))
    assert framing is not None and framing.placed_eye
    assert framed.clip_radius == pytest.approx(3.3) and framed.target == (0.0, 0.0, 0.0)
    forward = -np.asarray(framed.eye) / np.linalg.norm(framed.eye)
    assert np.allclose(-forward, np.array([3.0, 2.0, 4.0]) / math.sqrt(29.0))
    # the sphere fills 90 % of the picture's height
    half = math.asin(3.3 / np.linalg.norm(framed.eye))
    assert math.tan(half) == pytest.approx(0.9 * math.tan(math.radians(15.0)))


def test_command_line_radius_overrides_and_places_the_eye():
    framed, framing = apply_view(View(), ViewOptions(radius=4.0), lambda c: pytest.fail("searched"))
    assert framed.clip_radius == 4.0 and framing is not None and framing.placed_eye


def test_a_file_radius_without_eye_places_the_eye():
    """The eye follows the radius wherever it comes from (issue 44: a file's `radius = 3`
    without `eye` kept the default eye (3, 2, 4), a close-up cut by the frame, while the
    same radius from --radius was framed)."""
    view = View(clip_radius=3.0, given=frozenset({"radius"}))
    framed, framing = apply_view(view, ViewOptions(), lambda c: pytest.fail("searched"))
    same, _ = apply_view(View(), ViewOptions(radius=3.0), lambda c: pytest.fail("searched"))
    assert framing is not None and framing.placed_eye and not framing.framed_sphere
    assert framed.eye == same.eye and framed.eye != (3.0, 2.0, 4.0)


def test_a_file_radius_without_eye_renders_the_whole_sphere(tmp_path):
    """A sphere of radius 2.9 in a clip sphere of radius 3 from the file, no eye: the
    picture holds all of it (the default eye saw 74.5 % hits, a cropped close-up)."""
    surface = tmp_path / "s.toml"
    surface.write_text('equation = "x^2+y^2+z^2 = 2.9^2"\n[view]\nradius = 3\n')
    proc, car = render(tmp_path, str(surface))
    assert proc.returncode == 0, proc.stderr
    assert "framed: eye" in proc.stderr
    assert 45.0 < hit_percent(proc.stderr) < 65.0


def test_command_line_options_override_the_file(tmp_path):
    surface = tmp_path / "s.toml"
    surface.write_text('equation = "x^2+y^2+z^2-1"\n[view]\nradius = 0.1\neye = [3, 2, 4]\n')
    proc, car = render(tmp_path, str(surface), "--radius", "1.5", "--center=0,0,0",
                       "--eye", "0,-6,0", "--look-at", "0,0,0", "--up", "z", "--fov", "35")
    assert proc.returncode == 0, proc.stderr
    assert car["clip"] == {"center": [0.0, 0.0, 0.0], "radius": 1.5}
    cam = car["camera"]
    assert (cam["eye"], cam["up"], cam["fov_y_deg"]) == ([0.0, -6.0, 0.0], [0.0, 0.0, 1.0], 35.0)
    assert hit_percent(proc.stderr) > 10.0


def test_negative_coordinates_need_no_equals_sign(tmp_path):
    proc, car = render(tmp_path, "-e", "x^2+y^2+z^2-1", "--eye", "-5,-1,-2", "--up", "-y")
    assert proc.returncode == 0, proc.stderr
    assert car["camera"]["eye"] == [-5.0, -1.0, -2.0] and car["camera"]["up"] == [0, -1, 0]


@pytest.mark.parametrize("option", [
    ("--radius", "0"), ("--radius", "-2"), ("--radius", "nan"), ("--center", "1,2"),
    ("--eye", "1,2,x"), ("--look-at", "inf,0,0"), ("--up", "w"), ("--up", "0,0,0"),
    ("--fov", "180"), ("--fov", "0"), ("--eye", "1e7,0,0"),
])
def test_bad_view_options_are_usage_errors(option, tmp_path):
    proc = implc("render", "-e", "x^2+y^2+z^2-1", *option, "-o", str(tmp_path / "a.png"))
    assert proc.returncode == 2, proc.stderr
    assert option[0] in proc.stderr and "Traceback" not in proc.stderr
    assert list(tmp_path.iterdir()) == []


def test_a_view_the_options_break_is_a_usage_error(tmp_path):
    """The file's eye looks along -y... and --up y is parallel to it."""
    surface = tmp_path / "s.toml"
    surface.write_text('equation = "x^2+y^2+z^2-1"\n[view]\neye = [0, 5, 0]\nup = [0, 0, 1]\n')
    proc = implc("render", str(surface), "--up", "y", "-o", str(tmp_path / "a.png"))
    assert proc.returncode == 2
    assert "up = [0, 1, 0] is parallel to the view direction" in proc.stderr
    assert not (tmp_path / "a.png").exists()


def test_big_sphere_from_the_issue_is_framed_and_hit(tmp_path):
    proc, car = render(tmp_path, "-e", "x^2+y^2+z^2-9")
    assert proc.returncode == 0, proc.stderr
    assert "framed: center (0, 0, 0), radius 3.3" in proc.stderr
    assert car["clip"]["radius"] == pytest.approx(3.3)
    assert hit_percent(proc.stderr) > 30.0
    assert "warning" not in proc.stderr


def test_no_real_surface_says_so_and_warns(tmp_path):
    proc, car = render(tmp_path, "-e", "x^2+y^2+z^2+1")
    assert proc.returncode == 0
    assert "no surface found in |x|,|y|,|z| <= 2048" in proc.stderr
    assert car["clip"]["radius"] == 1.5  # the default view is kept
    assert hit_percent(proc.stderr) == 0.0
    assert "warning: no pixel hits the surface" in proc.stderr


def test_a_clip_sphere_too_small_warns_with_a_radius_that_works(tmp_path):
    surface = tmp_path / "s.toml"
    surface.write_text('equation = "x^2+y^2+z^2-1"\n[view]\nradius = 0.1\n')
    proc, _ = render(tmp_path, str(surface))
    assert proc.returncode == 0
    assert hit_percent(proc.stderr) == 0.0
    warning = [ln for ln in proc.stderr.splitlines() if "warning" in ln]
    assert len(warning) == 1, proc.stderr
    assert "no pixel hits the surface" in warning[0] and "--radius 1.1" in warning[0]


def test_compile_and_view_take_the_view_options(tmp_path):
    proc = implc("compile", "-e", "x^2+y^2+z^2-1", "--eye", "0,0,9", "--flavor", "shadertoy")
    assert proc.returncode == 0, proc.stderr
    assert "vec3 eye = vec3(0.0, 0.0, 9.0);" in proc.stdout
    page = tmp_path / "p.html"
    proc = implc("view", "-e", "x^2+y^2+z^2-9", "--no-webgpu", "-o", str(page))
    assert proc.returncode == 0, proc.stderr
    assert "framed: center (0, 0, 0), radius 3.3" in proc.stderr
    assert '"clip_radius": 3.3' in page.read_text()


# --- point 2: which way is up --------------------------------------------------------------

def test_help_says_which_way_is_up():
    for command in ("render", "view", "compile"):
        text = " ".join(implc(command, "--help").stdout.split())
        assert "--up" in text and "+y is up" in text and "--up z" in text, command


def test_frame_direction_turns_with_up():
    assert np.allclose(frame_direction((0.0, 1.0, 0.0)) * math.sqrt(29), (3, 2, 4))
    assert np.allclose(frame_direction((0.0, 0.0, 1.0)) * math.sqrt(29), (3, -4, 2))
    assert np.allclose(frame_direction((0.0, 0.0, 2.0)) * math.sqrt(29), (3, -4, 2))


def test_the_heart_stands_up_with_up_z(tmp_path):
    heart = "(x^2 + 9/4 y^2 + z^2 - 1)^3 - x^2z^3 - 9/80 y^2z^3"
    proc, car = render(tmp_path, "-e", heart, "--up", "z")
    assert proc.returncode == 0, proc.stderr
    view = View(eye=tuple(car["camera"]["eye"]), target=tuple(car["camera"]["target"]),
                up=tuple(car["camera"]["up"]))
    assert camera_basis(view)[2][2] > 0.8  # the picture's up is mostly +z
    assert hit_percent(proc.stderr) > 20.0


# --- point 3: a clipped surface is said to be clipped --------------------------------------

def test_crosses_sphere():
    sphere = expr("x^2+y^2+z^2-1")
    assert crosses_sphere(sphere, (0.0, 0.0, 0.0), 0.9) is False
    assert crosses_sphere(sphere, (0.0, 0.0, 0.0), 1.2) is False
    assert crosses_sphere(sphere, (1.0, 0.0, 0.0), 0.5) is True


def test_a_torus_cut_by_the_clip_sphere_warns(tmp_path):
    proc, _ = render(tmp_path, "torus", "--param", "r=0.6")
    assert proc.returncode == 0
    warning = [ln for ln in proc.stderr.splitlines() if "warning" in ln]
    assert len(warning) == 1, proc.stderr
    assert "reaches the clip sphere" in warning[0] and "radius 1.45" in warning[0]
    assert "--radius 1.8 holds all of it" in warning[0]


def test_the_bundled_torus_is_not_clipped(tmp_path):
    proc, _ = render(tmp_path, "torus")
    assert proc.returncode == 0
    assert "clip sphere" not in proc.stderr and "warning" not in proc.stderr
    assert hit_percent(proc.stderr) > 10.0


# --- issue 44, point 5: long or thin shapes, unbounded ones, the cut said always -----------

def test_a_long_thin_ellipsoid_is_framed_whole():
    """Its ends (x = +-10) are thinner than the grid's cells at the cube that holds it:
    the grid alone framed it at radius 8 and cut them flat."""
    extent = locate_surface(expr("x^2/100 + y^2 + z^2/0.01 = 1"))
    assert extent is not None and extent.bounded
    assert 10.0 < extent.radius <= 12.0


def test_arms_that_thin_out_are_unbounded_and_never_held():
    """6x^2 - 2x^4 = y^2 z^2 (SURFER's fantasy_helix) reaches every sphere along y and z;
    the grid took it for bounded at radius 11, and a cut render said '--radius 11 holds
    all of it'."""
    equation = "6x^2 - 2x^4 = y^2 z^2"
    extent = locate_surface(expr(equation))
    assert extent is not None and not extent.bounded
    cut = implc("render", "-e", equation, "--radius", "5", "-b", "reference", "--size", "32",
                "-o", "/dev/null")
    assert cut.returncode == 0, cut.stderr
    assert "holds all of it" not in cut.stderr
    assert "seems unbounded" in cut.stderr


def test_a_cut_by_an_automatic_sphere_is_said(tmp_path, monkeypatch):
    """The hits on the clip sphere (the aux buffer's t) are counted whoever chose the
    sphere: with the sphere's growth turned off (the grid's framing alone, radius 8), the
    ellipsoid's cut ends are said, where before only a --radius sphere was checked."""
    import implc
    import implc.extent

    monkeypatch.setattr(implc.extent, "_clear_of_sphere", lambda expr, extent: extent)
    implc.extent._locate.cache_clear()
    try:
        picture = implc.Surface("x^2/100 + y^2 + z^2/0.01 = 1").render(
            backend="reference", size=96)
    finally:
        implc.extent._locate.cache_clear()
    assert picture.view.clip_radius == 8.0
    cut = [w for w in picture.warnings if "reaches the clip sphere" in w]
    assert len(cut) == 1, picture.warnings
    assert re.search(r"on \d+ pixels?: the picture is cut there", cut[0])
    assert "--radius 16" in cut[0]


# --- issue 44, point 18: periodic surfaces -------------------------------------------------

def test_a_periodic_surface_is_framed_a_period_each_way():
    gyroid = "sin(x)cos(y) + sin(y)cos(z) + sin(z)cos(x)"
    extent = locate_surface(expr(gyroid))
    assert extent is not None and not extent.bounded
    assert extent.radius == pytest.approx(6.3) and extent.period == pytest.approx(6.3)
    scaled = locate_surface(expr(gyroid.replace("(x)", "(3x)").replace("(y)", "(3y)")
                                 .replace("(z)", "(3z)")))
    assert scaled.radius == pytest.approx(2.1)  # 2 pi / 3
    proc = implc("render", "-e", gyroid, "-b", "reference", "--size", "32", "-o", "/dev/null")
    assert "a period (6.3) each way" in proc.stderr, proc.stderr


# --- issue 44, point 9: framing samples an expanded polynomial by contraction ---------------

def test_a_sum_of_monomials_on_the_grid_is_the_walkers_value():
    """numeric.evaluate_on_grid contracts the coefficient tensor axis by axis (the corpus's
    degree-18 knot: 0.01 s against the walker's 0.5 s on the 65^3 grid); its values are
    the walker's to rounding, and every other tree goes to the walker itself."""
    from implc.numeric import evaluate, evaluate_on_grid
    from implc.symbols import POINT

    axes = [np.linspace(-2.0, 1.5, 17), np.linspace(-1.0, 2.0, 13), np.linspace(-3.0, 3.0, 11)]
    grid = np.meshgrid(*axes, indexing="ij")
    for text in ("x^18 + 9x^16 y^2 - 40x^14 y z/7 + 2y^10 z^8 + x y z - 3/10",
                 "x^3 y - 2 z^5 + 1e-3 x^2 z^2 + 4",
                 "(x^2 + y^2 + z^2 - 1)^2 - x",  # not expanded: the walker
                 "sin(3x) + y z^2"):
        e = expr(text)
        fast = evaluate_on_grid(e, axes)
        slow = np.broadcast_to(evaluate(e, dict(zip(POINT, grid, strict=True))), fast.shape)
        assert fast.shape == (17, 13, 11)
        assert np.allclose(fast, slow, rtol=1e-12, atol=1e-12 * np.abs(slow).max()), text


def test_an_expanded_polynomial_keeps_the_walkers_signs():
    """A polynomial written factored (degree <= EXPAND_UP_TO) is expanded and contracted
    too, and where the expanded form's rounding could decide a sign the walker's value is
    taken: Wilkinson's product (x-1)(x-2)...(x-16), whose expanded coefficients reach
    2e13 and cancel near its roots (18 of these grid points get the wrong sign from the
    expanded form alone), keeps the walker's sign at every point."""
    from implc.numeric import _checked_contraction, _expanded, evaluate, evaluate_on_grid
    from implc.symbols import POINT

    axes = [np.linspace(-120.0, 120.0, 801), np.linspace(-1.0, 1.0, 5),
            np.linspace(-1.0, 1.0, 3)]
    grid = np.meshgrid(*axes, indexing="ij")
    e = expr("*".join(f"(x-{i})" for i in range(1, 17)) + " + y^2 + z^2 - 1/100")
    assert _checked_contraction(e, _expanded(e), axes) is not None  # the expanded route
    fast = evaluate_on_grid(e, axes)
    slow = np.broadcast_to(evaluate(e, dict(zip(POINT, grid, strict=True))), fast.shape)
    assert (np.sign(fast) == np.sign(slow)).all()
