"""The target registry (implc/targets.py) against what it names: extensions, templates,
validators, runners, precisions, and every function of the table spelled by every
printer and accepted by every real compiler."""

from __future__ import annotations

import inspect

import numpy as np
import pytest
import sympy
from cases import PAPER
from conftest import IN_CI, require_backend, require_gl

from implc.backends.printing import SPELLED
from implc.emit import EMITS, emit
from implc.errors import InputError, ToolError
from implc.functions import BY_SYMPY_NAME, FUNCTIONS
from implc.loaders import load_surface
from implc.methods import METHODS
from implc.metrics import compare
from implc.render.run import BACKENDS, REFERENCE, backend_for, render
from implc.resources import data_dir
from implc.surface import Surface
from implc.symbols import X, Y, Z
from implc.targets import TARGETS, resolve, target_of_file
from implc.validate import validate_text

NAMES = list(TARGETS)


def printers(target):
    """One printer per precision of `target`, as emit makes them."""
    if len(target.precisions) == 1:
        return [target.printer()]
    return [target.printer(precision) for precision in target.precisions]


@pytest.mark.parametrize("name", NAMES)
def test_every_extension_maps_back_to_its_target(name):
    target = TARGETS[name]
    assert target.extensions, f"{name} has no file extension"
    for extension in target.extensions:
        assert extension.startswith(".")
        assert target_of_file(extension) is target, f"{extension} is read as another target"
    others = {e for t in TARGETS.values() if t is not target for e in t.extensions}
    assert not others & set(target.extensions), f"{name} shares an extension"


@pytest.mark.parametrize("name", NAMES)
def test_templates_cover_every_emit_form(name):
    target = TARGETS[name]
    assert set(target.templates) == set(EMITS)
    for path in target.templates.values():
        assert (data_dir("templates") / path).is_file(), path


@pytest.mark.parametrize("name", NAMES)
def test_validator_and_runners_resolve_with_their_signatures(name):
    """The lazy "module:function" references: each imports and takes the agreed arguments."""
    target = TARGETS[name]
    inspect.signature(resolve(target.validator)).bind("text", "name")
    assert target.backends, f"{name} has no render backend"
    for backend in target.backends.values():
        inspect.signature(resolve(backend.runner)).bind(
            "shader", "view", "width", "height")
        inspect.signature(resolve(backend.probe)).bind()  # tests open the runtime with it


@pytest.mark.parametrize("name", NAMES)
def test_every_precision_has_one_backend_and_flavours_have_a_default(name):
    """Backends sharing a runner (gl and gl-double) take one precision each; the target's
    first backend's runner runs every precision of the target; another runner (webgl2)
    may take fewer."""
    target = TARGETS[name]
    runners: dict[str, list[str]] = {}
    for backend in target.backends.values():
        runners.setdefault(backend.runner, []).append(backend.precision)
    first = next(iter(target.backends.values())).runner
    assert sorted(runners[first]) == sorted(target.precisions), name
    for precisions in runners.values():
        assert len(precisions) == len(set(precisions)) and set(precisions) <= set(
            target.precisions), name
    for backend_name, backend in target.backends.items():
        for precision in runners[backend.runner]:
            chosen = backend_for(backend_name, precision)
            assert target.backends[chosen].precision == precision
            assert target.backends[chosen].runner == backend.runner
    assert target.default_flavor in target.flavors


def test_backend_names_are_unique_and_not_the_reference():
    names = [n for t in TARGETS.values() for n in t.backends]
    assert len(names) == len(set(names)) == len(BACKENDS)
    assert REFERENCE not in names


@pytest.mark.parametrize("name", NAMES)
def test_every_table_function_has_a_spelling_or_a_rule(name):
    """Each row printed as a call (the table's `printed` column: "call" or "fold") is in
    the printer's `known_functions`; the rest are printed by the mixin's rules, or sugar
    built from other rows. Nothing else."""
    for printer in printers(TARGETS[name]):
        spelled = printer.known_functions
        for row in FUNCTIONS:
            if row.sympy_name is None:  # sugar: what it builds must be rows of the table
                built = row.build(*[X, Y][: row.arity])
                classes = {type(f).__name__ for f in built.atoms(sympy.Function)}
                assert classes <= set(BY_SYMPY_NAME), f"{row.name} builds {classes}"
            elif row.printed not in SPELLED:
                assert row.sympy_name not in spelled, f"{row.name}: a rule and a spelling"
            elif not spelled.get(row.sympy_name):
                # a precision may refuse a function, and say so (GLSL's double has no sin);
                # a spelling missing anywhere else fails here: that printer says otherwise
                with pytest.raises(InputError, match="no double-precision"):
                    printer.doprint(row.build(*[X, Y][: row.arity]))
        ruled = {r.sympy_name for r in FUNCTIONS if r.printed not in SPELLED}
        dead = set(spelled) - (set(BY_SYMPY_NAME) - ruled)
        assert not dead, f"{name} spells {dead}, which are not table functions"


def every_function_surface(interval: bool = False, printer=None) -> Surface:
    """Every user function of the table; its derivatives add the rows only derivatives
    use (step, delta). With `interval`: those with an interval rule, whose rules add the
    rows only rules use (floor). With `printer`: those it prints (a precision may refuse
    some: GLSL's double has no sin)."""
    args = (X / 2 + sympy.Rational(1, 4), Y / 3 - sympy.Rational(1, 5))

    def printed(f) -> bool:
        try:
            printer.doprint(f.build(*args[: f.arity]))
        except InputError:
            return False
        return True

    expr = sum((f.build(*args[: f.arity]) for f in FUNCTIONS
                if f.user and (not interval or f.interval or f.name in ("min", "max", "cbrt"))
                and (printer is None or printed(f))),
               sympy.Integer(0))
    return Surface("every function", expr + Z)


def validated(text: str, target: str, name: str):
    try:
        return validate_text(text, target, name)
    except ToolError as err:
        if IN_CI:
            pytest.fail(f"the {target} compiler is required under CI=true: {err}")
        pytest.skip(f"no {target} compiler: {err}")


@pytest.mark.parametrize("form", EMITS)
@pytest.mark.parametrize("name", NAMES)
def test_every_table_function_prints_and_validates(name, form):
    """What the printers spell, the real compiler of each language accepts, in every
    precision and emit form."""
    target = TARGETS[name]
    for precision, printer in zip(target.precisions, printers(target), strict=True):
        texts = {method: emit(every_function_surface(method == "interval", printer), name,
                              method, emit_form=form, precision=precision)
                 for method in ("hessian", "interval")}
        for spelling in set(printer.known_functions.values()):
            assert any(f"{spelling}(" in text for text in texts.values()), \
                f"{spelling} is not used: the test lost a function"
        for method, text in texts.items():
            file = f"functions.{method}.{precision}.{form}{target.extensions[0]}"
            verdict = validated(text, name, file)
            assert verdict.ok, verdict.render(file)


# --- every render backend against GL -----------------------------------------------------

RENDER_SIZE = 96
OTHER_BACKENDS = [name for t in TARGETS.values() for name, b in t.backends.items()
                  if name != "gl" and b.precision == "float"]


@pytest.mark.parametrize("method", list(METHODS))
@pytest.mark.parametrize("example", PAPER)
@pytest.mark.parametrize("backend", OTHER_BACKENDS)
def test_every_backend_renders_like_gl(backend, example, method):
    """Every method of every target's float backend at 96x96 against GLSL on GL (itself
    checked against the exact reference: tests/test_render_gl.py): the same float32
    algorithm, so the images agree to rounding.

    Measured (wgpu/lavapipe, cl/PoCL, vs llvmpipe): hit agreement 1.0 on every case; SSIM
    >= 0.998 (miter/curvature on cl the lowest); a pixel near a double line may take
    another root. Thresholds: hit agreement >= 0.999, SSIM >= 0.99, wrong roots (|dt| >
    1e-3) <= 0.1% of pixels."""
    require_gl()
    require_backend(backend)
    surface = load_surface(example)
    constants = METHODS[method].defaults
    gl = render(surface, "gl", method, constants, RENDER_SIZE, RENDER_SIZE)
    other = render(surface, backend, method, constants, RENDER_SIZE, RENDER_SIZE)
    m = compare(other, gl)
    assert gl.hit.mean() > 0.05, "the surface should cover the view"
    assert m["hit_agreement"] >= 0.999, m
    assert m["ssim"] >= 0.99, m
    assert m["wrong_root"] <= 0.001 * RENDER_SIZE * RENDER_SIZE, m
    assert other.color.dtype == np.float32 and other.color.shape == (RENDER_SIZE, RENDER_SIZE, 3)
