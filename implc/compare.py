"""`implc compare A B`: the metrics of one saved render against another (usually the reference).

Renders are EXR files with their JSON sidecars (`image_io.read_render`). Two renders are
comparable only pixel for pixel, so their cameras (eye, target, up, fov, size) and clip
spheres must be the same; otherwise the comparison is refused rather than computed on
unrelated rays.
"""

from __future__ import annotations

import math
from pathlib import Path

from .errors import InputError
from .metrics import T_TOL, compare
from .render.result import RenderResult

# The sidecar blocks that fix every pixel's ray.
GEOMETRY_KEYS = ("camera", "clip")


def load_render(path: Path) -> tuple[RenderResult, dict]:
    """An EXR render and its sidecar, with input errors (not tracebacks) for bad files."""
    from .render.image_io import read_render

    path = Path(path)
    if path.suffix.lower() != ".exr":
        raise InputError(f"{path}: compare reads EXR renders (write them with "
                         "`implc render ... -o NAME.exr`)")
    if path.is_dir():
        raise InputError(f"{path}: is a directory, not an EXR render")
    if not path.is_file():
        raise InputError(f"{path}: no such file")
    if not path.with_suffix(".json").is_file():
        raise InputError(f"{path}: its JSON sidecar {path.with_suffix('.json').name} is missing")
    try:
        return read_render(path)
    except (OSError, ValueError) as err:
        raise InputError(f"cannot read {path}: {err}") from None


def geometry_difference(meta_a: dict, meta_b: dict) -> str | None:
    """The first camera/clip field that differs ('camera.width: 64 vs 48'), or None."""
    for key in GEOMETRY_KEYS:
        if key not in meta_a or key not in meta_b:
            return f"{key}: missing from a sidecar"
        found = _first_difference(meta_a[key], meta_b[key], key)
        if found:
            return found
    return None


def _first_difference(a: object, b: object, where: str) -> str | None:
    if isinstance(a, dict) and isinstance(b, dict):
        for key in sorted(set(a) | set(b)):
            if key not in a or key not in b:
                return f"{where}.{key}: only in one render"
            found = _first_difference(a[key], b[key], f"{where}.{key}")
            if found:
                return found
        return None
    if isinstance(a, list) and isinstance(b, list) and len(a) == len(b):
        for index, (x, y) in enumerate(zip(a, b, strict=True)):
            found = _first_difference(x, y, f"{where}[{index}]")
            if found:
                return found
        return None
    numbers = (int, float)
    if isinstance(a, numbers) and isinstance(b, numbers) and not isinstance(a, bool):
        same = math.isclose(float(a), float(b), rel_tol=1e-9, abs_tol=1e-12)
    else:
        same = a == b
    return None if same else f"{where}: {a} vs {b}"


def compare_files(path_a: Path, path_b: Path, t_tol: float = T_TOL) -> dict:
    """Metrics of render A against render B (B is typically the exact reference)."""
    a, meta_a = load_render(path_a)
    b, meta_b = load_render(path_b)
    difference = geometry_difference(meta_a, meta_b)
    if difference:
        raise InputError(f"{path_a} and {path_b} are renders of different cameras "
                         f"({difference}); compare needs the same camera, clip and size")
    metrics = compare(a, b, t_tol)
    metrics["a"] = {"path": str(path_a), **_describe(meta_a)}
    metrics["b"] = {"path": str(path_b), **_describe(meta_b)}
    return metrics


def _describe(meta: dict) -> dict:
    surface = meta.get("surface", {})
    method = meta.get("method", {})
    return {"surface": surface.get("name", "?"), "backend": meta.get("backend", "?"),
            "method": method.get("name", "?")}


def format_metrics(metrics: dict) -> str:
    """The metrics as aligned `name  value` lines for the terminal."""
    a, b = metrics["a"], metrics["b"]
    pixels = metrics["pixels"]
    rows = [
        ("A", f"{a['path']} ({a['surface']}, {a['backend']}/{a['method']})"),
        ("B", f"{b['path']} ({b['surface']}, {b['backend']}/{b['method']})"),
        ("ssim", f"{metrics['ssim']:.6f}"),
        ("non-finite", f"{metrics['nonfinite_a']} (A), {metrics['nonfinite_b']} (B)  (pixels "
                       "with a NaN or infinite colour, black in ssim)"),
        ("false hits", f"{metrics['false_hits']}  (A hit, B missed)"),
        ("missed hits", f"{metrics['missed_hits']}  (A missed, B hit)"),
        ("wrong root", f"{metrics['wrong_root']}  (both hit, |t_A - t_B| > {metrics['t_tol']:g})"),
        ("hit agreement", f"{metrics['hit_agreement']:.6f}  ({pixels} pixels)"),
        ("mean steps", f"{metrics['mean_steps']:.2f}  (A, per pixel)"),
        ("max steps", f"{metrics['max_steps']:.0f}  (A)"),
    ]
    width = max(len(name) for name, _ in rows)
    return "\n".join(f"{name:<{width}}  {value}" for name, value in rows)
