"""`Surface.show()`: implc's live viewer as a notebook widget (anywidget).

The kernel compiles the shaders (view.viewer_data, the data `implc view` embeds in its
page) and sends them as traitlets; the browser draws them with the page's own script,
templates/view/viewer.js, followed by widget.mjs (the anywidget entry) as one ES module:
one viewer, two hosts. `params` is synchronised both ways: setting it in Python moves the
picture and the sliders, moving a slider sets it. Everything ships in the package (no
network): anywidget's front end is in its wheel, implc's in templates/view/.
"""

from __future__ import annotations

import math
from functools import cache
from typing import Any

import anywidget
import traitlets

from ..emit import render_template
from ..errors import OptionError
from ..resources import data_dir

DEFAULT_SIZE = 384  # the square canvas, in CSS pixels: a notebook cell's width holds it


@cache
def front_end() -> tuple[str, str]:
    """(the ES module, the style sheet): viewer.js then widget.mjs; viewer.css then
    widget.css (read once a process)."""
    view = data_dir("templates") / "view"

    def text(name: str) -> str:
        return (view / name).read_text(encoding="utf-8")

    return text("viewer.js") + "\n" + text("widget.mjs"), text("viewer.css") + text("widget.css")


class Viewer(anywidget.AnyWidget):
    """A surface, live: orbit (drag), pan (right-drag), zoom (wheel), a slider per
    parameter, WebGL2 and WebGPU where the browser has it. `params` holds the sliders'
    values (assign a dict of some of them to move them); `error` is what the browser
    reported if it could not draw."""

    _esm = traitlets.Unicode(front_end()[0]).tag(sync=True)
    _style = traitlets.Unicode(front_end()[1]).tag(sync=True)
    _markup = traitlets.Unicode().tag(sync=True)
    _data = traitlets.Dict().tag(sync=True)
    params = traitlets.Dict().tag(sync=True)
    size = traitlets.Int(DEFAULT_SIZE).tag(sync=True)
    backend = traitlets.Unicode("webgl2").tag(sync=True)
    error = traitlets.Unicode("").tag(sync=True)

    def __init__(self, data: dict[str, Any], *, size: int = DEFAULT_SIZE,
                 backend: str = "webgl2") -> None:
        if isinstance(size, bool) or not isinstance(size, int) or not 64 <= size <= 2048:
            raise OptionError(f"size must be a whole number of pixels from 64 to 2048, "
                              f"got {size!r}")
        if backend not in ("webgl2", "webgpu"):
            raise OptionError(f"backend must be webgl2 or webgpu, got {backend!r}")
        super().__init__(_data=data, _markup=render_template("view/viewer-body.html.j2"),
                         size=size, backend=backend)
        self.params = {p["name"]: p["value"] for p in data["params"]}

    @traitlets.validate("params")
    def _merge_params(self, proposal: dict[str, Any]) -> dict[str, float]:
        """A dict of some parameters updates those (the others keep their values); a name
        without a slider or a value that is not a finite number is an OptionError."""
        known = [p["name"] for p in self._data.get("params", [])]
        merged = dict(self.params)
        for name, value in dict(proposal["value"]).items():
            if name not in known:
                names = ", ".join(known) or "none"
                raise OptionError(f"parameter {name!r}: not a slider of this widget "
                                  f"(its parameters: {names})")
            if isinstance(value, bool) or not isinstance(value, (int, float)) or \
                    not math.isfinite(value):
                raise OptionError(f"parameter {name}: expected a finite number, got {value!r}")
            merged[name] = float(value)
        return merged
