"""write_render / read_render: EXR channels, PNG, JSON sidecar, atomic writes."""

from __future__ import annotations

import json

import numpy as np
import OpenImageIO as oiio
import pytest

from implc.errors import OutputError
from implc.render.image_io import EXR_CHANNELS, read_render, write_render
from implc.render.result import RenderResult

METADATA = {
    "surface": "x^2 + y^2 + z^2 - 1",
    "camera": {"width": 5, "height": 4},
    "timing": {"total": 0.25},
}


def make_render() -> RenderResult:
    rng = np.random.default_rng(1)
    hit = rng.random((4, 5)) < 0.5
    return RenderResult(
        color=rng.random((4, 5, 3)).astype(np.float32),
        hit=hit,
        t=np.where(hit, rng.uniform(3.0, 6.0, (4, 5)), 0.0).astype(np.float32),
        steps=rng.integers(0, 300, (4, 5)).astype(np.float32),
        residual=np.zeros((4, 5), np.float32),
    )


def test_exr_round_trip(tmp_path):
    render = make_render()
    path = tmp_path / "out.exr"
    written = write_render(render, path, METADATA)
    assert written == [path, tmp_path / "out.json"]

    image = oiio.ImageInput.open(str(path))
    spec = image.spec()
    pixels = image.read_image(format="float")
    image.close()
    assert tuple(spec.channelnames) == EXR_CHANNELS == ("R", "G", "B", "A", "Z", "steps")
    assert spec.format == oiio.FLOAT
    assert pixels.shape == (4, 5, 6)
    np.testing.assert_array_equal(pixels[..., 3], render.hit.astype(np.float32))

    back, metadata = read_render(path)
    assert metadata == METADATA
    np.testing.assert_array_equal(back.color, render.color)
    np.testing.assert_array_equal(back.hit, render.hit)
    np.testing.assert_array_equal(back.t, render.t)
    np.testing.assert_array_equal(back.steps, render.steps)
    assert np.isnan(back.residual).all()  # not stored in the EXR
    assert back.timing == {"total": 0.25}


def test_json_sidecar_is_sorted_and_indented(tmp_path):
    write_render(make_render(), tmp_path / "cc.exr", {"z": 1, "a": np.float64(0.5)})
    text = (tmp_path / "cc.json").read_text()
    assert text == json.dumps({"a": 0.5, "z": 1}, indent=2, sort_keys=True) + "\n"


def test_png_is_8_bit_rgb(tmp_path):
    render = make_render()
    path = tmp_path / "out.png"
    assert write_render(render, path, METADATA) == [path, tmp_path / "out.json"]
    image = oiio.ImageInput.open(str(path))
    spec = image.spec()
    pixels = image.read_image(format="uint8")
    image.close()
    assert (spec.width, spec.height, spec.nchannels) == (5, 4, 3)
    assert spec.format == oiio.UINT8
    np.testing.assert_array_equal(pixels, np.round(render.color * 255.0).astype(np.uint8))


def test_writes_leave_no_temp_files(tmp_path):
    write_render(make_render(), tmp_path / "a.exr", METADATA)
    write_render(make_render(), tmp_path / "a.png", METADATA)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.exr", "a.json", "a.png"]


def test_failed_write_leaves_nothing(tmp_path):
    with pytest.raises(TypeError):
        write_render(make_render(), tmp_path / "bad.exr", {"x": object()})
    with pytest.raises(OutputError, match=r"needs \.png or \.exr, not '\.tiff'"):
        write_render(make_render(), tmp_path / "bad.tiff", METADATA)
    with pytest.raises(OutputError, match="does not exist"):
        write_render(make_render(), tmp_path / "missing" / "bad.exr", METADATA)
    assert list(tmp_path.iterdir()) == []


def test_failed_move_removes_the_written_temp_file(tmp_path):
    (tmp_path / "taken.exr").mkdir()  # os.replace of the finished temp file onto it fails
    with pytest.raises(OutputError, match="is a directory"):
        write_render(make_render(), tmp_path / "taken.exr", METADATA)
    assert [p.name for p in tmp_path.iterdir()] == ["taken.exr"]
    assert list((tmp_path / "taken.exr").iterdir()) == []
