"""Output is byte-identical across runs and hash seeds (each run a fresh process)."""

from __future__ import annotations

import pytest
from test_cli import implc


@pytest.mark.parametrize("args", [
    ("compile", "cross-cap", "-m", "hessian"),
    ("compile", "barth-sextic", "-m", "curvature"),
    ("compile", "gyroid", "-m", "hessian-approx", "--flavor", "es300"),
    ("compile", "clebsch", "--emit", "library", "--prefix", "c_"),
])
def test_same_bytes_for_every_hash_seed(args):
    outputs = set()
    for seed in ("0", "1", "4242"):
        proc = implc(*args, env={"PYTHONHASHSEED": seed})
        assert proc.returncode == 0, proc.stderr
        outputs.add(proc.stdout)
    assert len(outputs) == 1


def test_the_template_cache_changes_no_byte(tmp_path):
    """Compiled templates are kept under the user's cache (jinja2's bytecode cache, 0.3 s
    of a cold compile, issue 44 point 9): a run that fills it, one that reads it, and one
    with caching off (IMPLC_CACHE_DIR empty) print the same shader, and the cache holds
    the compiled templates."""
    cache = tmp_path / "cache"
    args = ("compile", "torus", "-t", "wgsl")
    runs = [implc(*args, env={"IMPLC_CACHE_DIR": str(cache)}) for _ in range(2)]
    runs.append(implc(*args, env={"IMPLC_CACHE_DIR": ""}))
    assert all(run.returncode == 0 for run in runs), runs[-1].stderr
    assert len({run.stdout for run in runs}) == 1
    assert list((cache / "templates").glob("__jinja2_*.cache"))
