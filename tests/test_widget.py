"""`Surface.show()`, the notebook widget, on the kernel's side: its front end is the page's
own viewer script (one copy), its shaders are the page's, its `params` trait takes part of
the parameters and refuses what no slider has. The widget drawn in a real JupyterLab is
tests/test_jupyterlab.py's."""

from __future__ import annotations

import subprocess

import pytest
from conftest import IN_CI, require_tool

import implc
from implc.errors import OptionError
from implc.resources import data_dir
from implc.view import viewer_data

try:
    import anywidget  # noqa: F401
except ImportError:
    if IN_CI:
        raise  # the test extra has it: `make setup`
    pytest.skip("anywidget not installed (pip install -e '.[notebook]')",
                allow_module_level=True)


def test_front_end_is_the_viewer_script_then_the_widget_entry(tmp_path):
    """The widget's ES module is templates/view/viewer.js as it is, then widget.mjs; node
    parses the whole as a module (the form anywidget loads)."""
    w = implc.Surface.example("torus").show()
    view = data_dir("templates") / "view"
    script = (view / "viewer.js").read_text(encoding="utf-8")
    entry = (view / "widget.mjs").read_text(encoding="utf-8")
    assert w._esm == script + "\n" + entry
    assert "export default" in entry and "implcMount(shadow" in entry
    assert w._style.startswith((view / "viewer.css").read_text(encoding="utf-8"))
    assert w._markup == implc.Surface.example("torus").view_page().split("<body>\n", 1)[1] \
        .split('<script type="application/json"', 1)[0]
    module = tmp_path / "widget.mjs"
    module.write_text(w._esm, encoding="utf-8")
    node = require_tool("node")
    result = subprocess.run([node, "--check", str(module)], capture_output=True, text=True)
    assert result.returncode == 0, result.stderr


def test_widget_draws_the_pages_shaders():
    """The data the kernel sends is what `implc view` embeds: the same es300 and WGSL
    programs, camera and sliders (framed for the widget's square canvas)."""
    s = implc.Surface.example("torus")
    w = s.show()
    assert w._data == viewer_data(s.framed()[0])
    assert w._data["glsl"]["fragment"].startswith("#version 300 es")
    assert w.params == {"R": 1.0, "r": 0.35}
    assert w.size == 384 and w.backend == "webgl2" and w.error == ""
    taylor = s.show("taylor", step=0.02, webgpu=False)
    assert taylor._data["method"]["step"] == 0.02 and taylor._data["wgsl"]["program"] == ""


def test_params_take_some_and_refuse_what_no_slider_has():
    w = implc.Surface("x^2 + y^2 + z^2 = a + b", params={"a": 1, "b": 0.5}).show()
    assert w.params == {"a": 1.0, "b": 0.5}
    w.params = {"a": 0.3}
    assert w.params == {"a": 0.3, "b": 0.5}  # b kept
    with pytest.raises(OptionError, match="not a slider of this widget"):
        w.params = {"c": 1.0}
    for bad in (float("nan"), float("inf"), True, "0.5"):
        with pytest.raises(OptionError, match="expected a finite number"):
            w.params = {"a": bad}
    assert w.params == {"a": 0.3, "b": 0.5}
    assert implc.Surface("x^2 + y^2 + z^2 = 1").show().params == {}


def test_show_options_and_bad_input_are_errors():
    s = implc.Surface("x^2 + y^2 + z^2 = 1")
    with pytest.raises(OptionError, match="size"):
        s.show(size=10)
    with pytest.raises(OptionError, match="backend"):
        s.show(backend="vulkan")
    with pytest.raises(implc.InputError) as err:
        implc.Surface("x^2 + (y")
    # the caret text is in the message a notebook shows under the exception's name
    assert str(err.value) == "<equation>:1:7: error: unclosed '('\n  x^2 + (y\n        ^"
    assert err.value.message == "unclosed '('"
