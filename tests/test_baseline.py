"""The hand-written baseline (templates/baseline/, implc/baseline.py): the bar of
`implc bench --baseline` must compile and do the same work as the generated programs.

At 96x96 the hand-written and generated programs of one method agree on >= 99.9 % of the
hit mask (they differ only in float rounding: the hand-written F is Horner's about the
entry point), the second-order switch changes the test (Eq. 4 has none of Eq. 3's
false hits on the Cross-Cap's self-intersection), and the hand-written exact solver
(Barth's decic) agrees with the reference as the generated one does."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import require_gl, require_tool

from implc.baseline import BASELINES, baseline_program, open_baseline_runner
from implc.loaders import load_surface
from implc.methods import METHODS
from implc.metrics import compare
from implc.render.run import render
from implc.validate import validate_glsl

SIZE = 96


@pytest.mark.parametrize(("key", "method"), sorted(BASELINES))
def test_baseline_validates(key, method):
    require_tool("glslangValidator")
    text = baseline_program(key, method, METHODS[method].defaults, load_surface(key))
    verdict = validate_glsl(text, f"{key}.{method}.frag")
    assert verdict.ok, verdict.render(f"{key}.{method}.frag")


@pytest.mark.parametrize(("key", "method"), sorted(BASELINES))
def test_baseline_does_the_generated_programs_work(key, method):
    require_gl()
    surface = load_surface(key)
    constants = METHODS[method].defaults
    runner = open_baseline_runner(key, method, constants, surface, SIZE, SIZE)
    try:
        hand = runner.frame()
    finally:
        runner.release()
    generated = render(surface, "gl", method, constants, SIZE, SIZE)
    assert np.mean(hand.hit == generated.hit) >= 0.999
    reference = render(surface, "reference", "", constants, SIZE, SIZE)
    m = compare(hand, reference)
    if METHODS[method].solves:  # exact root isolation, as the generated program's
        assert m["false_hits"] <= 1 and m["missed_hits"] + m["wrong_root"] <= 2, m
        # the same walk: the same nodes a ray (both count them in aux.z)
        assert abs(hand.steps.mean() - generated.steps.mean()) <= 0.01 * generated.steps.mean()
    elif BASELINES[key, method]:  # Eq. 4: no false roots on the self-intersection
        assert m["false_hits"] <= 1, m
    else:  # Eq. 3 draws the false-root "stick"
        assert m["false_hits"] > 0, m
