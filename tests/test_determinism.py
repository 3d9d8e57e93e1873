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
