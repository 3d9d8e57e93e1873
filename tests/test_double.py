"""GLSL in double precision (`--precision double`, backend `gl-double`): the surface and
its solver in double where float32 cannot hold it, the camera and shading in float, and
clear refusals where GLSL has no double (GLSL ES, Shadertoy, sin, pow)."""

from __future__ import annotations

import pytest
import sympy
from conftest import require_backend, require_validator

from implc.backends.glsl import GlslPrinter
from implc.emit import emit
from implc.errors import InputError, OptionError
from implc.loaders import load_surface
from implc.methods import METHODS
from implc.metrics import compare
from implc.render.run import render
from implc.symbols import X

# Chmutov's T12(x) + T12(y) + T12(z) = 0, written out as users write it: coefficients up
# to 2^11, sheets a hundredth of the view apart near the cube's faces
CHMUTOV_12 = " + ".join(f"({c})*{v}^{k}" for k, c in ((12, 2048), (10, -6144), (8, 6912),
                                                      (6, -3584), (4, 840), (2, -72))
                        for v in "xyz") + " + 3"


def test_double_holds_where_float32_cannot():
    """At 128² float32's ray polynomial puts roots of Chmutov's T12 a wrong-root distance
    from their place (measured on gl: 0 false / 1 missed / 11 wrong); solved in double
    the picture is the reference's (measured: 0 / 0 / 0, and at 96² and 192² too). Fails
    on `gl`."""
    require_backend("gl-double")
    surface = load_surface(equation=CHMUTOV_12)
    size = 128
    reference = render(surface, "reference", "", METHODS["taylor"].defaults, size, size)
    result = render(surface, "gl-double", "exact", METHODS["exact"].defaults, size, size)
    m = compare(result, reference)
    assert reference.hit.sum() > 0.5 * size * size, "the surface should fill the view"
    assert m["false_hits"] == 0, m
    assert m["missed_hits"] + m["wrong_root"] <= 2, m


@pytest.mark.parametrize("kind", ["program", "library"])
@pytest.mark.parametrize("flavor", ["330", "450"])
def test_double_validates_in_both_desktop_flavours(flavor, kind):
    """The program (330 with GL_ARB_gpu_shader_fp64, 450 core) and the library (checked
    in a GLSL 400 frame) pass glslangValidator; only the surface is double."""
    validate = require_validator("glsl")
    text = emit(load_surface(equation=CHMUTOV_12), "glsl", "exact", flavor=flavor,
                emit_form=kind, prefix="d_" if kind == "library" else "", precision="double")
    assert ("#extension GL_ARB_gpu_shader_fp64 : require" in text) == (
        flavor == "330" and kind == "program")
    assert "double S(dvec3 p)" in text.replace("d_S", "S")
    assert "vec3 shade(vec3 g, vec3 rd)" in text.replace("d_shade", "shade")
    name = f"chmutov12.double.{kind}.{'frag' if kind == 'program' else 'glsl'}"
    verdict = validate(text, name)
    assert verdict.ok, verdict.render(name)


@pytest.mark.parametrize("flavor", ["es300", "shadertoy"])
def test_double_is_refused_where_glsl_has_none(flavor):
    with pytest.raises(OptionError, match=f"the glsl flavour {flavor} has no double precision: "
                                         "use --precision double with 330 or 450"):
        emit(load_surface("cross-cap"), "glsl", "exact", flavor=flavor, precision="double")


@pytest.mark.parametrize(("equation", "what"), [("sin(x) + y^2 + z^2 - 0.5", "sin"),
                                                 ("cbrt(x) + y^2 + z^2 - 1", "pow")])
def test_double_refuses_functions_glsl_lacks_in_double(equation, what):
    with pytest.raises(InputError, match=f"^GLSL has no double-precision {what}"):
        emit(load_surface(equation=equation), "glsl", "hessian", precision="double")


def test_half_integer_powers_print_as_products_with_sqrt_in_double():
    """A square root's derivatives (x^(3/2), x^(-5/2)) need no pow in double."""
    double, single = GlslPrinter("double"), GlslPrinter()
    assert double.doprint(X ** sympy.Rational(3, 2)) == "x*sqrt(x)"
    assert double.doprint(X ** sympy.Rational(-5, 2)) == "1.0lf/(x*x*sqrt(x))"
    assert double.doprint(sympy.sqrt(X) + 1) == "sqrt(x) + 1.0lf"
    assert single.doprint(X ** sympy.Rational(3, 2)) == "pow(x, 1.5)"
