"""Writing and reading render outputs: PNG to look at, EXR for data, JSON sidecar always.

The EXR holds float32 channels exactly `R G B A Z steps`: colour, A = hit (0/1), Z = t
along the unit ray direction from the eye (0 where no hit), and march steps. The JSON
beside it (`<stem>.json`) carries what is needed to recompute every pixel's ray (camera,
surface, method, parameters, timings). Every file is written atomically: a temp file in
the same directory, then os.replace, so a reader never sees a partial file
(implc.fileio).
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from ..errors import OutputError
from ..fileio import is_device, prepare_with, write_device
from ..interrupts import signals_held
from .result import RenderResult

with signals_held():  # a nanobind module: a signal inside its import aborts the process
    import OpenImageIO as oiio

EXR_CHANNELS = ("R", "G", "B", "A", "Z", "steps")


def write_render(result: RenderResult, path: Path, metadata: dict) -> list[Path]:
    """Write `path` (.png or .exr) and `<stem>.json` beside it; returns the paths written.

    The metadata is serialized first, so a bad value fails before any file is touched.
    """
    path = Path(path)
    if is_device(path):  # `-o /dev/null`: the PNG alone, no sidecar beside a device
        write_device(path, lambda tmp: _write_png(result, Path(tmp)), ".png")
        return [path]
    sidecar = path.with_suffix(".json")
    text = json.dumps(metadata, indent=2, sort_keys=True, default=_json_value) + "\n"
    suffix = path.suffix.lower()
    if suffix == ".png":
        write = _write_png
    elif suffix == ".exr":
        write = _write_exr
    else:
        raise OutputError(f"cannot write {path}: a render needs .png or .exr, not "
                          f"'{path.suffix}'")
    # both temporaries first, then both renames: an interruption leaves neither or both
    image = prepare_with(path, lambda tmp: write(result, tmp))
    try:
        side = prepare_with(sidecar, lambda tmp: Path(tmp).write_text(text, encoding="utf-8"))
    except BaseException:
        image.discard()
        raise
    try:
        image()
    except BaseException:
        side.discard()
        raise
    side()
    return [path, sidecar]


def read_render(path: Path) -> tuple[RenderResult, dict]:
    """Read an EXR written by `write_render` and its JSON sidecar.

    The EXR does not store |F| at the hit, so `residual` comes back as NaN; `timing` is the
    sidecar's "timing" table when it has one (as `implc render` writes it).
    """
    path = Path(path)
    image = oiio.ImageInput.open(str(path))
    if image is None:
        raise OSError(f"{path}: {oiio.geterror()}")
    try:
        names = tuple(image.spec().channelnames)
        if names != EXR_CHANNELS:
            raise ValueError(f"{path}: channels {names}, expected {EXR_CHANNELS}")
        pixels = image.read_image(format="float")
    finally:
        image.close()
    if pixels is None:
        raise OSError(f"{path}: {oiio.geterror()}")
    metadata = json.loads(path.with_suffix(".json").read_text(encoding="utf-8"))
    result = RenderResult(
        color=np.ascontiguousarray(pixels[..., :3], dtype=np.float32),
        hit=pixels[..., 3] > 0.5,
        t=np.ascontiguousarray(pixels[..., 4], dtype=np.float32),
        steps=np.ascontiguousarray(pixels[..., 5], dtype=np.float32),
        residual=np.full(pixels.shape[:2], np.nan, dtype=np.float32),
        timing={k: float(v) for k, v in dict(metadata.get("timing", {})).items()},
    )
    return result, metadata


def _write_png(result: RenderResult, path: Path) -> None:
    """8-bit PNG of the colour, values clipped to [0, 1] and rounded (no transfer curve)."""
    rgb = np.round(np.clip(result.color, 0.0, 1.0) * 255.0).astype(np.uint8)
    _write_image(path, oiio.ImageSpec(result.width, result.height, 3, "uint8"), rgb)


def _write_exr(result: RenderResult, path: Path) -> None:
    spec = oiio.ImageSpec(result.width, result.height, len(EXR_CHANNELS), "float")
    spec.channelnames = EXR_CHANNELS
    spec.alpha_channel = EXR_CHANNELS.index("A")
    spec.z_channel = EXR_CHANNELS.index("Z")
    planes = [
        *np.moveaxis(np.asarray(result.color, np.float32), -1, 0),
        result.hit.astype(np.float32),
        result.t,
        result.steps,
    ]
    _write_image(path, spec, np.stack(planes, axis=-1).astype(np.float32))


def _write_image(path: Path, spec: oiio.ImageSpec, pixels: np.ndarray) -> None:
    out = oiio.ImageOutput.create(str(path))
    if out is None:
        raise OSError(f"{path}: {oiio.geterror()}")
    try:
        if not (out.open(str(path), spec) and out.write_image(pixels)):
            raise OSError(f"{path}: {out.geterror()}")
    finally:
        out.close()


def _json_value(value: object) -> object:
    """numpy scalars and arrays in metadata become plain JSON values."""
    if isinstance(value, np.generic | np.ndarray):
        return value.tolist()
    raise TypeError(f"{type(value).__name__} is not JSON serializable")
