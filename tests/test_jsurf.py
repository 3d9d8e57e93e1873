"""SURFER's .jsurf files: read (properties syntax, jsurf's grammar, view, colours), bad
input located in the file, written back (round trip), and `implc gallery`.

The framing against jsurf itself (hit-pixel fraction within 2 % of jsurf's own picture)
was measured once with jsurf built from its source (docs/guide/surfer-and-gallery.md "SURFER
files"); here the
orthographic sphere of kugel.jsurf is checked against its exact picture instead.
"""

from __future__ import annotations

import math
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import sympy

from implc.front import param_symbol
from implc.loaders import load_surface
from implc.loaders.jsurf_read import ORTHO_DISTANCE
from implc.loaders.jsurf_write import to_jsurf
from implc.scene import SHADING, camera_basis
from implc.symbols import X, Y, Z

DATA = Path(__file__).parent / "data" / "jsurf"
FILES = sorted(DATA.glob("*.jsurf"))
ROOT = Path(__file__).resolve().parents[1]


def run(*args: str, cwd: Path | None = None) -> subprocess.CompletedProcess:
    env = {**os.environ, "PYTHONPATH": str(ROOT), "IMPLC_NO_PROGRESS_BAR": "1"}
    return subprocess.run([sys.executable, "-m", "implc", *args], capture_output=True,
                          text=True, env=env, cwd=cwd, timeout=600)


def test_the_data_files_are_there():
    assert len(FILES) == 6


@pytest.mark.parametrize("path", FILES, ids=lambda p: p.stem)
def test_reads_gallery_file(path):
    surface = load_surface(str(path))
    assert surface.expr.is_polynomial(X, Y, Z)
    text = path.read_text()
    scale = float(text.split("scale_factor=")[1].split()[0])
    assert surface.view.clip_radius == pytest.approx(10.0 ** scale)
    assert surface.view.front is not None and surface.view.back is not None
    assert "light_*" in surface.notes[0]
    # cayley_cubic's perspective camera is one jsurf 0.4.1 draws off its axis
    assert len(surface.notes) == (2 if path.stem == "cayley_cubic" else 1)


def test_properties_syntax():
    """dingdong.jsurf: `!` comment, `:` separator, a continued line, a \\u escape."""
    surface = load_surface(str(DATA / "dingdong.jsurf"))
    assert sympy.expand(surface.expr - (X**2 + Y**2 + Z**3 - Z**2)) == 0


def test_parameters_and_ignored_parameter():
    surface = load_surface(str(DATA / "cayley_cubic.jsurf"))
    assert sorted(surface.params) == ["a", "b"]
    assert "surface_parameter_c (not in the equation)" in surface.notes[0]
    assert surface.uniform_params() == ["a", "b"]  # sliders in `implc view`


def test_param_override():
    base = load_surface(str(DATA / "kugel.jsurf"))
    bigger = load_surface(str(DATA / "kugel.jsurf"), params=["a=1.2"])
    assert bigger.params["a"] == sympy.Rational(6, 5) and bigger.expr != base.expr


def test_orthographic_sphere_framing():
    """kugel.jsurf: a unit sphere, clip radius s = 10^0.15, camera_height 2 (the view is
    s tall): its picture is a disc of diameter 1/s of the frame, pi/(4 s^2) of the
    pixels. The far perspective camera must give that within 2 %."""
    from implc.methods import get_method
    from implc.render.run import render

    surface = load_surface(str(DATA / "kugel.jsurf"))
    s = 10.0 ** 0.15
    result = render(surface, "reference", "exact", get_method("exact").defaults, 96, 96)
    expected = math.pi / (4.0 * s * s)
    assert float(result.hit.mean()) == pytest.approx(expected, rel=0.02)
    eye = np.asarray(surface.view.eye)
    assert np.linalg.norm(eye) == pytest.approx(ORTHO_DISTANCE * s, rel=1e-6)


def test_perspective_sphere_framing():
    """kugel_perspective.jsurf: the unit sphere seen from D = 2 clip radii (2 s) with a
    60 degree camera in the form jsurf 0.4.1 draws centred (camera_transform shears its
    off-axis window back onto the axis): a disc of radius tan(asin(1/D)) / tan(30 deg)
    of the half-height. Measured with jsurf 0.4.1 itself: 33.50 % at 256x256."""
    from implc.methods import get_method
    from implc.render.run import render

    surface = load_surface(str(DATA / "kugel_perspective.jsurf"))
    s = 10.0 ** 0.15
    rho = math.tan(math.asin(1.0 / (2.0 * s))) / math.tan(math.radians(30.0))
    result = render(surface, "reference", "exact", get_method("exact").defaults, 96, 96)
    assert float(result.hit.mean()) == pytest.approx(math.pi * rho * rho / 4.0, rel=0.02)
    assert np.linalg.norm(surface.view.eye) == pytest.approx(2.0 * s, rel=1e-6)  # 8 digits
    assert surface.view.fov_y_deg == 60.0
    assert len(surface.notes) == 1  # the lights; no off-axis note


def test_perspective_export_shears_the_window(tmp_path):
    """A perspective view is written in the form jsurf 0.4.1 draws centred: its
    camera_transform maps the window jsurf spans, (t, t, -1) to (3t, 3t, -1), onto the
    centred one, (-t, -t, -1) to (t, t, -1)."""
    from implc.loaders.jsurf_properties import Properties
    from implc.loaders.jsurf_read import _matrix
    from implc.loaders.jsurf_read import jsurf041_tan as _jsurf041_tan

    text = to_jsurf(load_surface("torus"))
    props = Properties("torus.jsurf", text)
    fov = float(props.entries["camera_fov_y"].value)
    t = _jsurf041_tan(fov)
    inverse = np.linalg.inv(_matrix(props, "camera_transform"))
    corner = inverse @ np.array([t, t, -1.0, 1.0]) - inverse @ np.array([0, 0, 0, 1.0])
    far = inverse @ np.array([3 * t, 3 * t, -1.0, 1.0]) - inverse @ np.array([0, 0, 0, 1.0])
    np.testing.assert_allclose(corner[:3], [-t, -t, -1.0], atol=1e-12)
    np.testing.assert_allclose(far[:3], [t, t, -1.0], atol=1e-12)


def _rays(view):
    """What decides every pixel's ray and colour (the target only gives a direction)."""
    forward, right, up = camera_basis(view)
    return (np.asarray(view.eye), forward, up, view.fov_y_deg, view.clip_radius,
            np.asarray(view.clip_center), view.front or SHADING.front,
            view.back or SHADING.back)


def _same_view(a, b):
    for u, v in zip(_rays(a), _rays(b), strict=True):
        np.testing.assert_allclose(np.asarray(u, dtype=float), np.asarray(v, dtype=float),
                                   rtol=1e-9, atol=1e-9)


def _same_surface(a, b):
    """S of both at seeded random points (parameters at their values), to float64:
    constants such as sqrt(5) are written as 17-digit decimals."""
    rng = np.random.default_rng(7)
    values = {param_symbol(k): v for k, v in a.params.items()}
    for point in rng.uniform(-1.5, 1.5, size=(12, 3)):
        at = {**values, X: point[0], Y: point[1], Z: point[2]}
        u = float(a.symbolic_expr.subs(at))
        v = float(b.symbolic_expr.subs(at))
        assert v == pytest.approx(u, rel=1e-12, abs=1e-12)


@pytest.mark.parametrize("path", FILES, ids=lambda p: p.stem)
def test_round_trip(path, tmp_path):
    """.jsurf -> implc -> .jsurf -> the same surface (symbolic, parameters) and view."""
    first = load_surface(str(path))
    written = tmp_path / path.name
    written.write_text(to_jsurf(first))
    second = load_surface(str(written))
    _same_surface(first, second)
    assert {k: float(v) for k, v in first.params.items() if k in first.uniform_params()} == \
        {k: float(v) for k, v in second.params.items()}
    _same_view(first.view, second.view)
    assert ("ORTHOGRAPHIC" in written.read_text()) == ("ORTHOGRAPHIC" in path.read_text())
    assert to_jsurf(first) == written.read_text()  # deterministic text


def test_export_of_a_toml_surface(tmp_path):
    """compile --emit jsurf of a bundled example (perspective, off-centre target)."""
    out = tmp_path / "torus.jsurf"
    proc = run("compile", "torus", "--emit", "jsurf", "-o", str(out))
    assert proc.returncode == 0, proc.stderr
    torus = load_surface("torus")
    back = load_surface(str(out))
    _same_surface(torus, back)
    _same_view(torus.view, back.view)


def test_export_refuses_a_non_polynomial(tmp_path):
    out = tmp_path / "g.jsurf"
    proc = run("compile", "gyroid", "--emit", "jsurf", "-o", str(out))
    assert proc.returncode == 1 and "polynomial surfaces only" in proc.stderr
    assert not out.exists()


BAD = [
    ("unknown key", "surface_equation=x^2+y^2+z^2-1\nscale_facter=0.5\n",
     "bad.jsurf:2:1: error: unknown key 'scale_facter'; did you mean 'scale_factor'?\n"
     "  scale_facter=0.5\n  ^~~~~~~~~~~~"),
    ("implicit product", "surface_equation=x^2+2y^2-1\n",
     "bad.jsurf:1:23: error: unexpected 'y': jsurf has no implicit multiplication; "
     "write '*'\n  surface_equation=x^2+2y^2-1\n                        ^\n"),
    ("equals sign", "surface_equation=x^2+y^2 = z\n",
     "bad.jsurf:1:26: error: jsurf's equations have no '=': a .jsurf equation is S alone "
     "(drawn where S = 0), so write 'lhs - (rhs)'"),
    ("no value", "surface_equation=x^2+y^2+z^2-r^2\n",
     "bad.jsurf:1:30: error: parameter 'r' has no value"),
    ("function of x", "surface_equation=sin(x)+y\n",
     "bad.jsurf:1:22: error: jsurf applies sin to constants only, not to x, y, z"),
    ("exponent", "surface_equation=x^2.5+y^2+z^2-1\n",
     "bad.jsurf:1:20: error: a power of x, y, z needs a whole number literal as its "
     "exponent (jsurf's rule)\n  surface_equation=x^2.5+y^2+z^2-1\n                     ^~~"),
    ("continued line", "surface_equation=x^2+\\\n    y^2+@\nscale_factor=0\n",
     "bad.jsurf:2:9: error: jsurf's equations have no '@'\n      y^2+@\n          ^"),
    ("bad matrix", "surface_equation=x\nrotation_matrix=1 0 0 0 0 1 0 0 0 0 1 0 0 0 0\n",
     "bad.jsurf:2:17: error: rotation_matrix must be 16 numbers (a 4x4 matrix, row by row), "
     "not 15"),
    ("bad escape", "surface_equation=x^2\\u00g1\n",
     "bad.jsurf:1:21: error: malformed \\uXXXX escape"),
    ("twice", "surface_equation=x\nsurface_equation=y\n",
     "bad.jsurf:2:1: error: 'surface_equation' is given twice (first at line 1)"),
    ("no equation", "# nothing\nscale_factor=0\n",
     "error: no surface_equation"),
    ("camera type", "surface_equation=x\ncamera_type=ORTHOGRAPHIC\n",
     "bad.jsurf:2:13: error: camera_type must be ORTHOGRAPHIC_CAMERA or PERSPECTIVE_CAMERA; "
     "did you mean 'ORTHOGRAPHIC_CAMERA'?"),
    ("unknown function", "surface_equation=sinh(2)*x\n",
     "bad.jsurf:1:18: error: jsurf has no function 'sinh'; did you mean 'sin'?"),
]


@pytest.mark.parametrize(("text", "message"), [b[1:] for b in BAD], ids=[b[0] for b in BAD])
def test_bad_input(tmp_path, text, message):
    (tmp_path / "bad.jsurf").write_text(text)
    proc = run("render", "bad.jsurf", "--size", "16", "-o", "out.png", cwd=tmp_path)
    assert proc.returncode == 1, proc.stderr
    assert message in proc.stderr
    assert "Traceback" not in proc.stderr
    assert not (tmp_path / "out.png").exists() and not (tmp_path / "out.json").exists()


def test_render_says_ignored_keys_once(tmp_path):
    out = tmp_path / "k.png"
    proc = run("render", str(DATA / "kummer_quartic.jsurf"), "--size", "64", "-o", str(out))
    assert proc.returncode == 0, proc.stderr
    notes = [line for line in proc.stderr.splitlines() if "ignored" in line]
    assert len(notes) == 1 and "light_*" in notes[0] and "*_material_shininess" in notes[0]
    assert out.exists()


def test_gallery(tmp_path):
    """Two surfaces and one that fails: its error in its cell, the run goes on."""
    bad = tmp_path / "broken.jsurf"
    bad.write_text("surface_equation=x^2+2y^2-1\n")
    out = tmp_path / "gal"
    proc = run("gallery", "torus", str(DATA / "kugel.jsurf"), str(bad), "--size", "64",
               "-o", str(out))
    # issue 44: a failed surface is exit 1 (it was 0), the sheet written all the same
    assert proc.returncode == 1, proc.stderr
    assert "1 failed" in proc.stdout
    assert "implc gallery: error: 1 of 3 surfaces failed" in proc.stderr
    page = (out / "index.html").read_text()
    for stem in ("torus", "kugel"):
        assert f'<a href="{stem}.html"' in page and (out / f"{stem}.png").stat().st_size > 0
        assert "implc view" in (out / f"{stem}.html").read_text()
    assert "jsurf has no implicit multiplication" in page and "broken" in page
    assert "degree 4 &middot; exact &middot; frame" in page
    assert not (out / "broken.png").exists()
    assert (out / "contact-sheet.png").stat().st_size > 0
    assert "[3/3]" in proc.stderr  # progress lines (a bar with ETA on a terminal)


def test_gallery_says_a_note_once(tmp_path):
    """The same note of several files (their ignored keys) is said once, naming them; one
    surface is "1 surface" (issue 44)."""
    files = [str(DATA / name)
             for name in ("kugel.jsurf", "dingdong.jsurf", "kummer_quartic.jsurf")]
    proc = run("gallery", *files, "--size", "16", "-o", str(tmp_path / "g"))
    assert proc.returncode == 0, proc.stderr
    ignored = [line for line in proc.stderr.splitlines() if "ignored (implc does not" in line]
    assert len(ignored) == 1 and ignored[0].startswith("implc: note: 3 files ("), ignored
    assert all(name in ignored[0] for name in files)
    proc = run("gallery", "torus", "--size", "16", "-o", str(tmp_path / "one"))
    assert proc.returncode == 0 and "(1 surface)" in proc.stdout, proc.stdout


def test_gallery_page_in_chromium(browser, tmp_path):
    """index.html as a browser shows it: every thumbnail loads at its size, every link
    points at a file the run wrote, and a thumbnail opens its `implc view` page."""
    from urllib.parse import unquote, urlparse

    from browser_support import file_url, open_page

    bad = tmp_path / "broken.jsurf"
    bad.write_text("surface_equation=x^2+2y^2-1\n")
    out = tmp_path / "gal"
    proc = run("gallery", "torus", str(DATA / "kugel_perspective.jsurf"), str(bad),
               "--size", "32", "-o", str(out))
    assert proc.returncode == 1, proc.stderr  # one cell fails by design (issue 44: exit 1)
    with open_page(browser, file_url(out / "index.html")) as (page, log):
        page.wait_for_load_state("load")
        images = page.eval_on_selector_all(
            "img", "els => els.map(e => [e.getAttribute('src'), e.complete, e.naturalWidth])")
        assert sorted(images) == [["kugel_perspective.png", True, 32], ["torus.png", True, 32]]
        links = page.eval_on_selector_all("a", "els => els.map(e => e.href)")
        assert len(links) == 4
        for link in links:
            assert link.startswith("file://"), link
            assert Path(unquote(urlparse(link).path)).is_file(), link
        page.click("#torus a >> nth=0")
        page.wait_for_load_state("load")
        assert page.url.endswith("/torus.html")
        assert page.title() == "Torus \u2014 implc view"
        assert not log.exceptions, log.exceptions
