"""S's scale for float32 (implc/scaling.py, issue 44 point 1): where the shader's S is
the equation times a power of two, the shader and `implc show` say so; where S's
magnitude is ordinary (every bundled example), the shader is S as written. The pictures
are pinned in tests/test_metamorphic.py (c*S draws as S for c = 1e25, 1e-25, 1e20)."""

from __future__ import annotations

import subprocess
import sys

import pytest

from implc.emit import emit
from implc.loaders import load_surface
from implc.scaling import SCALE_BEYOND, magnitude_log2, scale_exponent
from implc.surface import example_paths


@pytest.mark.parametrize(("equation", "k"), [
    ("1e-25*(x^2+y^2+z^2) - 1e-25", 83),
    ("(x^2+y^2+z^2)^4 = 1e24", -80),  # a sphere of radius 1000
    ("1e20*x^2 + 1e20*y^2 + 1e20*z^2 - 1e20", -66),
    ("sin(3x) + 1e-30*y - z^2", 0),  # its largest term is 1: nothing to bring near 1
])
def test_the_factor_brings_the_largest_term_near_one(equation, k):
    assert scale_exponent(load_surface(equation=equation).expr) == k


def test_ordinary_surfaces_are_compiled_as_written():
    for name in example_paths():
        surface = load_surface(name)
        assert abs(magnitude_log2(surface.expr)) < SCALE_BEYOND, name
        assert "times 2^" not in emit(surface, "glsl", "hessian")


def test_the_shader_and_show_say_the_factor():
    equation = "1e-25*(x^2+y^2+z^2) - 1e-25"
    shader = emit(load_surface(equation=equation), "glsl", "exact")
    header = next(line for line in shader.splitlines() if line.startswith("// Equation:"))
    assert "the shader's S is the equation times 2^83" in header
    assert "e-25*" not in shader.split("// Method:")[1]  # the constants themselves moved
    show = subprocess.run([sys.executable, "-m", "implc", "show", "-e", equation],
                          capture_output=True, text=True, timeout=120)
    assert show.returncode == 0, show.stderr
    assert "measured as the shader computes S: the shader's S is the equation times 2^83" \
        in show.stdout
