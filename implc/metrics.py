"""How a render differs from the exact reference: image similarity and hit-mask confusion."""

from __future__ import annotations

import numpy as np
from skimage.metrics import structural_similarity

from .options import T_TOL
from .render.result import RenderResult


def compare(a: RenderResult, ref: RenderResult, t_tol: float = T_TOL) -> dict:
    """Metrics of render `a` against reference `ref` of the same size.

    - ssim: scikit-image SSIM of the colour images (channel_axis=-1, data_range=1.0), a
      pixel with a non-finite channel (NaN: a normal of 0/0 or inf/inf) taken as black
      there, so that one such pixel cannot make the score NaN;
    - nonfinite_a, nonfinite_b: the pixels of `a`, `ref` with a non-finite colour (said,
      since they are no colour at all);
    - false_hits: `a` hit where `ref` missed; missed_hits: `a` missed where `ref` hit;
    - wrong_root: both hit and |t - t_ref| > t_tol (a different root, see T_TOL);
    - hit_agreement: fraction of pixels whose hit flags agree;
    - mean_steps, max_steps: march steps of `a` over ALL pixels (background pixels count,
      with the steps they took, usually 0), i.e. cost per pixel of the frame;
    - pixels: width x height; t_tol: the tolerance used.
    """
    if a.hit.shape != ref.hit.shape:
        raise ValueError(f"render sizes differ: {a.hit.shape} vs {ref.hit.shape}")
    both = a.hit & ref.hit
    t_error = np.abs(a.t.astype(np.float64) - ref.t.astype(np.float64))
    colors = [r.color.astype(np.float64) for r in (a, ref)]
    finite = [np.isfinite(c) for c in colors]
    ssim = structural_similarity(
        *(np.where(ok, c, 0.0) for c, ok in zip(colors, finite, strict=True)),
        channel_axis=-1, data_range=1.0,
    )
    return {
        "ssim": float(ssim),
        "nonfinite_a": int(np.count_nonzero(~finite[0].all(axis=-1))),
        "nonfinite_b": int(np.count_nonzero(~finite[1].all(axis=-1))),
        "false_hits": int(np.count_nonzero(a.hit & ~ref.hit)),
        "missed_hits": int(np.count_nonzero(~a.hit & ref.hit)),
        "wrong_root": int(np.count_nonzero(both & (t_error > t_tol))),
        "hit_agreement": float(np.mean(a.hit == ref.hit)),
        "mean_steps": float(np.mean(a.steps)),
        "max_steps": float(np.max(a.steps)),
        "pixels": int(a.hit.size),
        "t_tol": float(t_tol),
    }
