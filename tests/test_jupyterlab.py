"""The widget in a real front end: JupyterLab (from PyPI) started on localhost by the test,
opened in the headless Chromium the browser tests drive with Playwright. The tour
notebook's cells tagged `jupyterlab` run there; the test reads the widget's canvas back and
checks that the surface is drawn (not background), that moving a slider changes the
picture and reaches Python (`w.params`), that setting `w.params` in Python moves the
slider and the picture, and that the WebGPU button draws the same frame (SSIM >= 0.99
against WebGL2's; measured 1.0000 on SwiftShader); shown twice, the widget has two views
(each in its own shadow root) on one model, so a slider of one moves the other. Every
request the page makes after it opened goes to that server (or is data: or blob:): the
widget needs no network.

Bounds: a free port on 127.0.0.1, a random token, every Jupyter directory in the test's
temporary directory, the server's start within SERVER_START_S, each browser wait within
browser_support.TIMEOUT_MS; the server is stopped (its process group) whatever happens.

With IMPLC_SCREENSHOTS=DIR the widget's cell is saved as DIR/notebook-widget.png: the
docs/guide/python.md's figure is made by `make notebook-picture` (IMPLC_SCREENSHOTS=docs).
"""

from __future__ import annotations

import json
import os
import secrets
import signal
import socket
import subprocess
import sys
import time
import urllib.request
from contextlib import contextmanager
from pathlib import Path

import numpy as np
import pytest
from browser_support import background_mask, open_page, screenshot, ssim
from test_notebook import TOUR, require

from implc.scene import SHADING

ROOT = Path(__file__).resolve().parent.parent
SERVER_START_S = 90
SSIM_CHANGED = 0.95  # as tests/test_view.py: a frame that must differ scores below this
SSIM_SAME = 0.99  # as tests/test_view.py: WebGPU's frame is WebGL2's (both float32)
MIN_DRAWN = 0.05  # at least this share of the canvas shows the surface, not background


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@contextmanager
def jupyterlab(root: Path):
    """A JupyterLab server on 127.0.0.1 serving `root`; yields its base URL and token."""
    require("jupyterlab")
    require("anywidget")
    port, token = free_port(), secrets.token_hex(16)
    home = root / ".jupyter"
    env = {**os.environ,
           "PYTHONPATH": os.pathsep.join(filter(None, [str(ROOT), os.environ.get("PYTHONPATH")])),
           "JUPYTER_CONFIG_DIR": str(home / "config"), "JUPYTER_DATA_DIR": str(home / "data"),
           "JUPYTER_RUNTIME_DIR": str(home / "runtime"),
           "JUPYTERLAB_SETTINGS_DIR": str(home / "settings"),
           "JUPYTERLAB_WORKSPACES_DIR": str(home / "workspaces"),
           "IPYTHONDIR": str(home / "ipython")}
    # no "Would you like to get notified about official Jupyter news?" over the widget
    news = home / "settings" / "@jupyterlab" / "apputils-extension"
    news.mkdir(parents=True)
    (news / "notification.jupyterlab-settings").write_text('{"fetchNews": "false"}')
    log = (root / "jupyterlab.log").open("w")
    proc = subprocess.Popen(
        [sys.executable, "-m", "jupyterlab", "--no-browser", "--ip=127.0.0.1",
         f"--port={port}", "--port-retries=0", f"--IdentityProvider.token={token}",
         f"--ServerApp.root_dir={root}", "--LabApp.news_url=None",
         "--LabApp.check_for_updates_class=jupyterlab.NeverCheckForUpdate",
         "--LabApp.extension_manager=readonly", "--LabApp.expose_app_in_browser=True",
         "--allow-root"],
        cwd=root, env=env, stdout=log, stderr=subprocess.STDOUT, start_new_session=True)
    base = f"http://127.0.0.1:{port}"
    try:
        deadline = time.monotonic() + SERVER_START_S
        while True:
            try:
                with urllib.request.urlopen(f"{base}/api/status?token={token}", timeout=5):
                    break
            except OSError:
                if proc.poll() is not None or time.monotonic() > deadline:
                    log.flush()
                    pytest.fail("JupyterLab did not start:\n"
                                + (root / "jupyterlab.log").read_text()[-3000:])
                time.sleep(0.5)
        yield base, token
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGTERM)
            try:
                proc.wait(timeout=20)
            except subprocess.TimeoutExpired:
                os.killpg(proc.pid, signal.SIGKILL)
                proc.wait(timeout=20)
        log.close()


def tagged_cells(tag: str) -> list[dict]:
    """The tour's cells with `tag`, without outputs (as a new notebook's cells)."""
    tour = json.loads(TOUR.read_text(encoding="utf-8"))
    cells = [c for c in tour["cells"] if tag in c.get("metadata", {}).get("tags", [])]
    return [{**c, "outputs": [], "execution_count": None} for c in cells]


def write_notebook(path: Path) -> list[dict]:
    tour = json.loads(TOUR.read_text(encoding="utf-8"))
    cells = tagged_cells("jupyterlab")
    path.write_text(json.dumps({**tour, "cells": cells}, indent=1), encoding="utf-8")
    return cells


VIEWER = """() => {
  for (const el of document.querySelectorAll(".jp-OutputArea-output *"))
    if (el.implcViewer) return el;
  return null;
}"""


VIEWERS = """() => Array.from(document.querySelectorAll(".jp-OutputArea-output *"))
  .filter((el) => el.implcViewer).map((el) => el.implcViewer)"""


def viewer_state(page) -> dict:
    return page.evaluate(f"""() => {{
      const el = ({VIEWER})();
      if (!el) return null;
      const v = el.implcViewer;
      return {{frames: v.frames, idle: v.idle, error: v.error, params: v.params}};
    }}""")


def wait_drawn(page, after: int = 0) -> int:
    page.wait_for_function(f"""() => {{
      const el = ({VIEWER})();
      return el && (el.implcViewer.error ||
                    (el.implcViewer.frames > {after} && el.implcViewer.idle));
    }}""")
    state = viewer_state(page)
    assert not state["error"], f"the widget failed: {state['error']}"
    return state["frames"]


def run_cell(page, index: int) -> None:
    """Run the notebook's cell `index` as its Run button does (JupyterLab's own
    `notebook:run-cell` command, once the kernel is ready) and wait for its execution
    count."""
    page.evaluate("""async (index) => {
      const panel = window.jupyterapp.shell.currentWidget;
      await panel.sessionContext.ready;
      panel.content.activeCellIndex = index;
      await window.jupyterapp.commands.execute("notebook:run-cell");
    }""", index)
    page.wait_for_function(
        """(index) => {
          const cell = document.querySelectorAll(".jp-Notebook .jp-Cell")[index];
          return cell && /\\[\\d+\\]/.test(cell.querySelector(".jp-InputArea-prompt").textContent);
        }""", arg=index)


def ask_kernel(page, code: str) -> str:
    """What `code` prints in the notebook's kernel (sent beside the cells, as a console
    attached to the notebook would)."""
    return page.evaluate("""async (code) => {
      const kernel = window.jupyterapp.shell.currentWidget.sessionContext.session.kernel;
      let text = "";
      const future = kernel.requestExecute({ code });
      future.onIOPub = (msg) => { if (msg.header.msg_type === "stream") text += msg.content.text; };
      await future.done;
      return text;
    }""", code)


def test_widget_draws_and_syncs_in_jupyterlab(browser, tmp_path):
    notebook = tmp_path / "widget.ipynb"
    cells = write_notebook(notebook)
    widget_at = next(i for i, c in enumerate(cells) if "widget" in c["metadata"]["tags"])
    set_at = next(i for i, c in enumerate(cells) if "set-params" in c["metadata"]["tags"])
    assert set_at == widget_at + 1
    background = SHADING.background
    with jupyterlab(tmp_path) as (base, token), \
            open_page(browser, f"{base}/lab/tree/{notebook.name}?token={token}",
                      width=1200, height=900) as (page, log):
        requests: list[str] = []
        page.on("request", lambda request: requests.append(request.url))
        page.locator(".jp-Notebook .jp-Cell").first.wait_for()
        for index in range(widget_at + 1):
            run_cell(page, index)
        frames = wait_drawn(page)
        canvas = page.locator(".jp-OutputArea-output #gl-canvas")
        first = screenshot(canvas)
        drawn = 1.0 - background_mask(first, background).mean()
        keep = os.environ.get("IMPLC_SCREENSHOTS")
        if keep:
            Path(keep).mkdir(parents=True, exist_ok=True)
            page.locator(".jp-Notebook .jp-Cell").nth(widget_at).screenshot(
                path=str(Path(keep) / "notebook-widget.png"))
        # a slider moved in the browser: a new picture, and w.params in Python follows
        slider = page.locator(".jp-OutputArea-output #param-a")
        slider.fill("0.2")
        frames = wait_drawn(page, frames)
        moved = screenshot(canvas)
        page.wait_for_timeout(500)  # the model's message to the kernel
        after_slider = ask_kernel(page, "print(w.params)")
        # Python sets w.params: the slider and the picture follow
        run_cell(page, set_at)
        page.wait_for_function(f"""() => {{
          const el = ({VIEWER})();
          return el && el.implcViewer.params.a === 0.5 && el.implcViewer.idle &&
                 el.implcViewer.frames > {frames};
        }}""")
        from_python = screenshot(canvas)
        slider_value = float(slider.input_value())
        # WebGPU, where this Chromium has it (SwiftShader's Vulkan here): the same picture
        page.wait_for_function(f"() => ({VIEWER})().implcViewer.ready")
        webgpu = page.evaluate(f"() => ({VIEWER})().implcViewer.webgpu")
        if webgpu == "available":
            page.locator(".jp-OutputArea-output #use-webgpu").click()
            wait_drawn(page, viewer_state(page)["frames"])
            on_webgpu = screenshot(page.locator(".jp-OutputArea-output #gpu-canvas"))
            assert page.evaluate(f"() => ({VIEWER})().implcViewer.backend") == "webgpu"
        # the same widget shown again: a second view in its own shadow root (the same ids
        # twice in the page, no clash), one model: its slider moves the first view too
        page.evaluate("""async (index) => {
          const panel = window.jupyterapp.shell.currentWidget;
          panel.content.activeCellIndex = index;
          await window.jupyterapp.commands.execute("notebook:insert-cell-below");
          panel.content.activeCell.model.sharedModel.setSource("w");
        }""", set_at)
        run_cell(page, set_at + 1)
        page.wait_for_function(f"""() => {{
          const views = ({VIEWERS})();
          return views.length === 2 && views.every((v) => v.frames > 0 && v.idle);
        }}""")
        first_view_frames = page.evaluate(f"() => ({VIEWERS})()[0].frames")
        page.locator(".jp-OutputArea-output #param-a").nth(1).fill("0.8")
        page.wait_for_function(f"""() => {{
          const [one, two] = ({VIEWERS})();
          return one.params.a === two.params.a && two.params.a !== 0.5 && one.idle &&
                 one.frames > {first_view_frames};
        }}""")
        both = page.evaluate(f"() => ({VIEWERS})().map((v) => [v.params.a, v.error])")
        problems = [p for p in log.problems() if "favicon" not in p]
    print(f"JupyterLab widget: {100 * drawn:.1f} % of the canvas drawn; slider to a=0.2: "
          f"SSIM {ssim(first, moved):.3f} vs the first frame; w.params after it: "
          f"{after_slider.strip()}; w.params = 0.5 from Python: SSIM "
          f"{ssim(moved, from_python):.3f} vs a=0.2")
    assert drawn >= MIN_DRAWN, "the widget's canvas shows only background"
    assert ssim(first, moved) < SSIM_CHANGED, "moving the slider did not change the picture"
    assert after_slider.strip() == "{'a': 0.2}"
    assert slider_value == 0.5
    assert ssim(moved, from_python) < SSIM_CHANGED
    assert webgpu == "available", f"no WebGPU in the widget: {webgpu}"
    webgpu_ssim = ssim(on_webgpu, from_python)
    print(f"the same frame on WebGPU: SSIM {webgpu_ssim:.4f} vs WebGL2")
    assert webgpu_ssim >= SSIM_SAME
    assert np.abs(from_python - first).max() > 0
    assert [error for _, error in both] == ["", ""] and abs(both[0][0] - 0.8) < 0.01
    assert problems == []
    elsewhere = [u for u in requests if not u.startswith((base, "data:", "blob:"))]
    assert requests and elsewhere == [], f"requests off this server: {elsewhere}"
