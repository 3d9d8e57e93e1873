"""Compiling needs only sympy and jinja2 (issue 43): loading a surface, deriving,
optimizing and emitting every target's shader never imports numpy, so that the compile
path runs where numpy cannot load (Pyodide). numpy belongs to rendering, the float32
report and measuring, which import it when they are asked for.

This file is also the child process of the test: run as a script, it blocks numpy with a
meta-path finder before importing implc, compiles `cases()` and prints each shader's sha256;
the test compiles the same in its own process, numpy loaded, and compares, so the
numpy-free path must give the same bytes, not merely run. That includes a float32 exact
program of degree 12 (`CHEBYSHEV`), whose S is written in Chebyshev's basis of a box
chosen by sampling S: in plain Python without numpy (issue 48)."""

from __future__ import annotations

import hashlib
import itertools
import json
import os
import subprocess
import sys
import traceback
from collections.abc import Iterator
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent

# name -> (example name, or None and an `-e` equation with its --param values)
SURFACES: dict[str, tuple[str | None, str | None, tuple[str, ...]]] = {
    "cross-cap": ("cross-cap", None, ()),
    "torus": ("torus", None, ()),  # has [params]: --params uniform has uniforms
    "param": (None, "x^2 + y^2/b + z^4 - a = 0", ("a=0.8", "b=2")),
    "sin": (None, "sin(3x) + cos(2y) + z^2 - 1 = 0", ()),  # not a polynomial
}
HAS_PARAMS = ("torus", "param")
# a float32 exact program whose S is in Chebyshev's basis of a sampled box: every target
CHEBYSHEV = 12  # Chmutov's T_n
METHODS = ("taylor", "interval", "exact")  # beside hessian
PARAM_MODES = ["constant", "uniform"]


def _load_surface():
    """`load_surface` from implc/loaders/, or from implc/surface.py where it was before."""
    try:
        from implc.loaders import load_surface
    except ImportError:
        from implc.surface import load_surface
    return load_surface


def cases() -> Iterator[tuple[str, str, str, str, str, str, str]]:
    """(surface, target, method, flavour, precision, emit form, params mode): hessian in
    every flavour, precision, emit form and --params mode of every target (all of them for
    the surface with parameters, the program with constants for the others), and the other
    methods with each target's defaults. A refused combination is a case too: its message
    is compared."""
    from implc.targets import TARGETS

    for surface, target in itertools.product(SURFACES, TARGETS.values()):
        full = surface == "param"
        for flavor, precision, form, params in itertools.product(
                target.flavors, target.precisions,
                target.templates if full else ["program"],
                PARAM_MODES if full else ["constant"]):
            yield surface, target.name, "hessian", flavor, precision, form, params
        modes = PARAM_MODES if surface in HAS_PARAMS else ["constant"]
        for method, params in itertools.product(METHODS, modes):
            yield surface, target.name, method, target.default_flavor, "float", "program", params


def digests() -> dict[str, str]:
    """sha256 of each case's shader text (or of the error refusing it)."""
    from implc.emit import emit
    from implc.errors import ImplcError
    from implc.targets import TARGETS

    load_surface = _load_surface()
    surfaces = {name: load_surface(spec, equation, params) if spec is None
                else load_surface(spec, params=params)
                for name, (spec, equation, params) in SURFACES.items()}
    result = {}
    for case in cases():
        surface, target, method, flavor, precision, form, params = case
        prefix = "lib_" if form == "library" else ""
        try:
            text = emit(surfaces[surface], target, method, flavor=flavor, emit_form=form,
                        prefix=prefix, precision=precision, params=params)
        except ImplcError as err:  # a refused combination: its message
            text = f"{type(err).__name__}: {err}"
        result["|".join(case)] = hashlib.sha256(text.encode()).hexdigest()
    from cases import chmutov

    chebyshev = load_surface(equation=chmutov(CHEBYSHEV))
    for target in TARGETS.values():
        if "float" in target.precisions:
            text = emit(chebyshev, target.name, "exact", flavor=target.default_flavor,
                        precision="float")
            result[f"chmutov{CHEBYSHEV}|{target.name}|exact|float"] = \
                hashlib.sha256(text.encode()).hexdigest()
    import implc  # the public API's compile, on examples whose files set their view

    for name, target in itertools.product(("cross-cap", "torus"), ("glsl", "wgsl", "hlsl")):
        shader = implc.Surface.example(name).compile(target, params="uniform")
        result[f"api|{name}|{target}"] = hashlib.sha256(shader.text.encode()).hexdigest()
    return result


def notes() -> tuple[str, ...]:
    """The API's notes on a float32 compile (without numpy: what was not measured)."""
    import implc

    return implc.Surface.example("cross-cap").compile("glsl").notes


class _NoNumpy:
    """A meta-path finder that refuses numpy, saying who asked for it."""

    def find_spec(self, name, path=None, target=None):
        if name == "numpy" or name.startswith("numpy."):
            stack = "".join(line for line in traceback.format_stack()
                            if "<frozen" not in line and "_NoNumpy" not in line)
            raise ImportError(f"numpy is blocked (the compile path needs none), "
                              f"imported from:\n{stack}")
        return None


def _child() -> None:
    sys.meta_path.insert(0, _NoNumpy())
    result = digests()
    print(json.dumps({"digests": result, "numpy": "numpy" in sys.modules, "notes": notes()}))


def test_compiling_imports_no_numpy_and_gives_the_same_bytes():
    child = subprocess.Popen(  # numpy blocked; runs beside this process's own compiles
        [sys.executable, __file__], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
        text=True, env={**os.environ, "PYTHONPATH": str(ROOT)}, cwd=ROOT)
    import numpy  # noqa: F401  here, numpy is loaded (as after a render) when compiling

    try:
        expected = digests()
        out, err = child.communicate(timeout=300)
    finally:
        child.kill()
    assert child.returncode == 0, f"the compile path failed without numpy:\n{err[-3000:]}"
    report = json.loads(out)
    assert not report["numpy"], "numpy was imported while compiling"
    assert report["digests"].keys() == expected.keys()
    different = [k for k, v in expected.items() if report["digests"][k] != v]
    assert not different, f"shaders differ without numpy: {different[:10]}"
    said = " ".join(report["notes"])  # what the compile could not do, it says
    assert "float32 not measured" in said and "may differ" not in said, report["notes"]
    assert len(expected) > 100
    chebyshev = [k for k in expected if k.startswith(f"chmutov{CHEBYSHEV}|")]
    assert len(chebyshev) >= 3, chebyshev  # and they are written in Chebyshev's basis:
    from cases import chmutov

    from implc.chebyshev import chebyshev_program
    from implc.loaders import load_surface

    assert chebyshev_program(load_surface(equation=chmutov(CHEBYSHEV)).expr) is not None


if __name__ == "__main__":
    _child()
