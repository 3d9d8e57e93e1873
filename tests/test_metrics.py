"""compare(): SSIM and the hit-mask confusion counts on constructed renders."""

from __future__ import annotations

import numpy as np
import pytest

from implc.metrics import T_TOL, compare
from implc.render.result import RenderResult


def make_render(size: int = 32, seed: int = 0) -> RenderResult:
    """A render with a disc of hits, depth 4..5 and a few steps per pixel."""
    rng = np.random.default_rng(seed)
    j, i = np.mgrid[:size, :size]
    hit = (i - size / 2) ** 2 + (j - size / 2) ** 2 < (size / 3) ** 2
    color = np.where(hit[..., None], rng.uniform(0.2, 1.0, (size, size, 3)), 0.1)
    return RenderResult(
        color=color.astype(np.float32),
        hit=hit,
        t=np.where(hit, rng.uniform(4.0, 5.0, (size, size)), 0.0).astype(np.float32),
        steps=rng.integers(0, 50, (size, size)).astype(np.float32),
        residual=np.zeros((size, size), np.float32),
    )


def copy(render: RenderResult) -> RenderResult:
    return RenderResult(
        render.color.copy(), render.hit.copy(), render.t.copy(), render.steps.copy(),
        render.residual.copy(),
    )


def test_identical_renders_agree_fully():
    ref = make_render()
    m = compare(copy(ref), ref)
    assert m["ssim"] == pytest.approx(1.0)
    assert (m["false_hits"], m["missed_hits"], m["wrong_root"]) == (0, 0, 0)
    assert m["hit_agreement"] == 1.0
    assert m["pixels"] == 32 * 32
    assert m["mean_steps"] == pytest.approx(float(ref.steps.mean()))
    assert m["max_steps"] == float(ref.steps.max())
    assert m["t_tol"] == T_TOL


def test_constructed_differences_are_counted_exactly():
    ref = make_render()
    a = copy(ref)
    hits = np.argwhere(ref.hit)
    misses = np.argwhere(~ref.hit)
    for j, i in misses[:3]:  # 3 false hits
        a.hit[j, i], a.t[j, i] = True, 2.0
    for j, i in hits[:5]:  # 5 missed hits
        a.hit[j, i], a.t[j, i] = False, 0.0
    for j, i in hits[5:12]:  # 7 wrong roots
        a.t[j, i] += 0.05
    for j, i in hits[12:20]:  # within the tolerance: not wrong
        a.t[j, i] += 0.5 * T_TOL
    a.color[0, 0] = 1.0 - a.color[0, 0]
    m = compare(a, ref)
    assert (m["false_hits"], m["missed_hits"], m["wrong_root"]) == (3, 5, 7)
    assert m["hit_agreement"] == pytest.approx(1.0 - 8 / (32 * 32))
    assert m["ssim"] < 1.0


def test_tolerance_is_an_argument():
    ref = make_render()
    a = copy(ref)
    a.t[ref.hit] += 0.01
    assert compare(a, ref)["wrong_root"] == ref.hit.sum()
    assert compare(a, ref, t_tol=0.02)["wrong_root"] == 0


def test_sizes_must_match():
    with pytest.raises(ValueError, match="sizes differ"):
        compare(make_render(32), make_render(16))
