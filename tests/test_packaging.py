"""The templates and examples are found from an installed wheel, not only from a checkout."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def test_wheel_finds_templates_and_examples(tmp_path):
    wheel_dir, site = tmp_path / "wheel", tmp_path / "site"
    subprocess.run(
        [sys.executable, "-m", "pip", "wheel", "-q", "--no-deps",
         "-w", str(wheel_dir), str(ROOT)],
        check=True, capture_output=True, timeout=300,
    )
    wheel = next(wheel_dir.glob("implc-*.whl"))
    subprocess.run(
        [sys.executable, "-m", "pip", "install", "-q", "--no-deps", "--target", str(site),
         str(wheel)],
        check=True, capture_output=True, timeout=300,
    )
    templates = site / "implc" / "templates"
    for name in ("marcher.j2", "glsl/lang.j2", "opencl/probe.cl", "baseline/cross-cap.frag.j2",
                 "view/viewer.html.j2", "view/viewer.js", "view/viewer.css",
                 "view/viewer-body.html.j2", "view/widget.mjs", "view/widget.css",
                 "notebook/figure.html.j2", "notebook/shader.html.j2"):
        assert (templates / name).is_file(), name
    # Run from an unrelated directory with only the installed copy on the path.
    env = {**os.environ, "PYTHONPATH": str(site)}
    proc = subprocess.run(
        [sys.executable, "-c",
         "import implc, sys; from implc.cli import main;"
         "assert 'site' in implc.__file__, implc.__file__;"
         "sys.exit(main(['compile', 'cross-cap', '-m', 'hessian']))"],
        capture_output=True, text=True, cwd=tmp_path, env=env, timeout=120,
    )
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.startswith("#version 330 core")
    assert "bool march(" in proc.stdout
