"""The public Python API (`implc.Surface` and its records): the same pipeline, defaults and
messages as the command line, immutable surfaces, exceptions instead of exits, sympy input
through implc's own parser, and one framing for every command."""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest
import sympy
from conftest import require_gl

import implc
from implc.errors import InputError, LimitError, OptionError

ROOT = Path(__file__).resolve().parent.parent
CROSS_CAP = "4x^2(x^2+y^2+z^2+z) + y^2(y^2+z^2-1) = 0"


def cli(*args: str, cwd: Path | None = None) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "implc", *args], capture_output=True,
                          text=True, cwd=cwd or ROOT, timeout=300,
                          env={**os.environ, "PYTHONPATH": str(ROOT)})


def test_compile_is_the_command_lines_compile(tmp_path):
    """Same defaults (method by surface, framing) and the same bytes as `implc compile`."""
    surface = implc.Surface.example("cross-cap")
    shader = surface.compile("wgsl", emit="library", prefix="cc_")
    assert (shader.method, shader.target, shader.emit, shader.prefix) == (
        "exact", "wgsl", "library", "cc_")
    proc = cli("compile", "cross-cap", "-t", "wgsl", "--emit", "library", "--prefix", "cc_")
    assert proc.returncode == 0, proc.stderr
    assert shader.text == proc.stdout
    torus = implc.Surface.example("torus").compile(params="uniform")
    assert [u.name for u in torus.uniforms] == ["R", "r"]
    assert torus.form in ("point", "ray-poly")
    hessian = implc.Surface.example("cross-cap").compile(method="hessian", step=0.004)
    assert hessian.constants.step == 0.004 and not hessian.warnings
    assert "CONST float STEP" in hessian.text or "0.004" in hessian.text


def test_text_and_sympy_give_the_same_shader():
    x, y, z = sympy.symbols("x y z")
    expr = 4 * x**2 * (x**2 + y**2 + z**2 + z) + y**2 * (y**2 + z**2 - 1)
    text = implc.Surface(CROSS_CAP).compile().text
    assert implc.Surface(expr).compile().text == text
    assert implc.Surface(sympy.Eq(expr, 0)).compile().text == text

    class SageLike:  # SageMath's symbolic expressions convert themselves like this
        def _sympy_(self):
            return expr

    assert implc.Surface(SageLike()).compile().text == text


def test_sympy_input_meets_the_same_limits_and_function_table():
    x, y, z = sympy.symbols("x y z")
    with pytest.raises(InputError, match="unknown function 'besselj'") as err:
        implc.Surface(sympy.besselj(0, x) + y + z)
    assert "^" in err.value.render()  # the caret under the printed expression
    big = sum(x**i * y for i in range(3000))
    with pytest.raises(LimitError, match="--max-nodes"):
        implc.Surface(big)
    with pytest.raises(InputError, match="expected equation text, a sympy expression"):
        implc.Surface(3.5)
    a = sympy.Symbol("a")
    ball = implc.Surface(x**2 + y**2 + z**2 - a, params={"a": sympy.Rational(1, 4)})
    assert ball.params == {"a": 0.25}


def test_errors_are_exceptions_with_the_diagnostic():
    with pytest.raises(InputError) as err:
        implc.Surface("x^2 + * y")
    text = err.value.render()
    assert text.startswith("<equation>:1:") and "^" in text
    with pytest.raises(OptionError, match="unknown glsl flavour 'gles'"):
        implc.Surface(CROSS_CAP).compile(flavor="gles")
    with pytest.raises(OptionError, match="radius"):
        implc.Surface(CROSS_CAP).with_view(radius=-1)
    with pytest.raises(TypeError, match="stepp"):
        implc.Surface(CROSS_CAP).compile(method="hessian", stepp=0.1)
    with pytest.raises(InputError, match="no file or bundled example named 'tourus'.*torus"):
        implc.Surface.example("tourus")


def test_surfaces_are_immutable_records():
    torus = implc.Surface.example("torus")
    fatter = torus.with_params(r=0.5)
    assert torus.params["r"] != 0.5 and fatter.params["r"] == 0.5
    near = torus.with_view(radius=2, up="z")
    assert near.view.clip_radius == 2 and near.view.up == (0.0, 0.0, 1.0)
    assert torus.view.clip_radius != 2
    with pytest.raises(InputError, match="parameter 'q' is not in the equation"):
        torus.with_params(q=1)
    assert "torus" in implc.examples() and "Surface" in dir(implc)


def test_public_names_do_not_hide_modules():
    """A public name that is also a module's (implc.corpus) would be shadowed by the
    module once imported, or shadow it (`from implc import corpus`)."""
    for package in (ROOT / "implc", ROOT / "implc" / "api"):
        for name in implc.__all__:
            assert not (package / f"{name}.py").exists(), (package, name)
            assert not (package / name).is_dir(), (package, name)


def test_a_big_surface_is_framed_and_rendered():
    """The issue's case: a sphere of radius 3 from an equation renders, framed."""
    require_gl()
    sphere = implc.Surface("x^2 + y^2 + z^2 = 9")
    assert sphere.view.clip_radius > 3
    rendering = sphere.render(32)
    assert rendering.image.shape == (32, 32, 3) and rendering.image.dtype.name == "uint8"
    assert 0.2 < rendering.hit_fraction < 0.9
    assert rendering.method == "exact" and rendering.notes[0].startswith("framed:")
    assert set(rendering.aux) == {"hit", "t", "steps", "residual"}
    assert rendering._repr_png_().startswith(b"\x89PNG")
    inside = sphere.with_view(radius=1.0).render(32)  # a sphere the surface is outside of
    assert inside.hit_fraction == 0.0
    assert any("no pixel hits the surface" in w and "try --radius" in w
               for w in inside.warnings)


def test_one_framing_serves_render_gallery_bench_and_view(tmp_path):
    """A surface file without a view, through four commands: one camera."""
    require_gl()
    path = tmp_path / "ball.toml"
    path.write_text('name = "ball"\nequation = "x^2 + y^2 + z^2 = 9"\n')
    eyes = {}
    proc = cli("render", str(path), "--size", "24", "-o", str(tmp_path / "r.png"))
    assert proc.returncode == 0, proc.stderr
    eyes["render"] = json.loads((tmp_path / "r.json").read_text())["camera"]["eye"]
    proc = cli("gallery", str(path), "--size", "24", "-o", str(tmp_path / "g"))
    assert proc.returncode == 0, proc.stderr
    eyes["gallery"] = _page_eye(tmp_path / "g" / "ball.html")
    proc = cli("bench", str(path), "--size", "16", "--methods", "taylor", "--configs",
               "paper", "--frames", "1", "-o", str(tmp_path / "b"))
    assert proc.returncode == 0, proc.stderr
    sidecar = tmp_path / "b" / "renders" / "ball-taylor-paper.json"
    eyes["bench"] = json.loads(sidecar.read_text())["camera"]["eye"]
    proc = cli("view", str(path), "-o", str(tmp_path / "v.html"))
    assert proc.returncode == 0, proc.stderr
    eyes["view"] = _page_eye(tmp_path / "v.html")
    eyes["api"] = list(implc.Surface.load(path).view.eye)
    assert eyes["render"] != [3.0, 2.0, 4.0]  # framed: not the default eye
    assert all(eye == pytest.approx(eyes["render"], rel=1e-12) for eye in eyes.values()), eyes


def _page_eye(page: Path) -> list[float]:
    data = re.search(r'<script type="application/json" id="implc-data">(.*?)</script>',
                     page.read_text(), re.S)
    assert data, page
    return json.loads(data.group(1))["view"]["eye"]


def test_gallery_on_a_dask_cluster_matches_local_processes(tmp_path):
    """The same gallery, byte-identical thumbnails, on a real dask.distributed
    LocalCluster on localhost as with local worker processes."""
    require_gl()
    distributed = pytest.importorskip("distributed")
    from implc.executors import local_executor

    specs = ["torus", "cross-cap", str(tmp_path / "missing.toml")]
    with local_executor(2) as pool:
        local = implc.gallery(specs, tmp_path / "local", size=24, executor=pool,
                              progress=None)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  host="127.0.0.1", dashboard_address=None) as cluster, \
            distributed.Client(cluster) as client:
        remote = implc.gallery(specs, tmp_path / "dask", size=24,
                               executor=client.get_executor(), progress=None)
    assert [c.error == "" for c in local] == [True, True, False]
    assert [c.stem for c in remote] == [c.stem for c in local]
    for stem in ("torus", "cross-cap"):
        assert (tmp_path / "dask" / f"{stem}.png").read_bytes() == \
            (tmp_path / "local" / f"{stem}.png").read_bytes()
    assert "missing.toml" in remote[2].error


def test_the_scheduler_option_reaches_a_cluster(tmp_path):
    """`implc gallery --scheduler ADDRESS` on a LocalCluster; a wrong address is a
    missing tool (exit 4), said in one line."""
    require_gl()
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=True,
                                  host="127.0.0.1", dashboard_address=None) as cluster:
        proc = cli("gallery", "torus", "--size", "16", "--scheduler", cluster.scheduler_address,
                   "-o", str(tmp_path / "g"))
    assert proc.returncode == 0, proc.stderr
    assert (tmp_path / "g" / "torus.png").is_file()
    proc = cli("gallery", "torus", "--size", "16", "--scheduler", "tcp://127.0.0.1:9",
               "-o", str(tmp_path / "h"))
    assert proc.returncode == 4 and "cannot reach the Dask scheduler" in proc.stderr
    assert "Traceback" not in proc.stderr and not (tmp_path / "h").exists()
