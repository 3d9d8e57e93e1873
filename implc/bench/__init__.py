"""The Table 1 harness: speed and accuracy of every marcher against the exact reference.

For each configuration x surface x method: one warm-up frame, then `frames` timed frames
(each `runner.draw()` renders and waits for completion; the read-back of the outputs is
not part of a frame, as it is not in an application that displays them; the methods of one
surface take their frames in turns, see `time_interleaved`), reported as the
median frames per second and as the ratio to `taylor`'s fps in the same run (absolute fps
depend on the machine; the ratio is what compares across machines). The last timed frame
is compared with the exact CPU reference (computed once per surface, same size and
camera): SSIM, false / missed hits, wrong-root pixels, mean march steps per pixel.

Configurations:
- `paper`: each method's defaults, the paper's Table 1 constants (b = 0.01; hessian
  b = 0.002; tau1 = tau2 = tau3 = 0.01);
- `equal`: the same base step for every method (`equal_step`, default 0.002 = the paper's
  hessian step), so accuracy differences come from the root test, not the step;
- `taylor2`: hessian and hessian-approx with `taylor2 = "consistent"` (h^2/8, F''(t1) in r)
  at the paper's constants, with taylor (which has no F'' term, so is unchanged) timed
  again beside them: a ratio is only fair between frames taken in turns, close in time;
- `extremum`: the same with `taylor2 = "extremum"`, implc's own test (docs/explanation/methods.md
"The methods").

Outputs in the directory: table.md, table.json, figure.png (the first configuration,
`paper` by default, laid out like the paper's Fig. 2), figure-<config>.png for the others,
and renders/<surface>-<method>-<config>.png (+ JSON sidecar; + EXR with `exr=True`) and
renders/<surface>-reference.png.

Three modules, imported one way only: `records` (what a run is: its configurations and
cells), `report` (a run's files, from the records) and `measure` (timing a run, then
writing its report). This package re-exports the names its clients use.
"""

from __future__ import annotations

from .measure import machine_info, run_bench, time_interleaved
from .records import (
    CONFIG_NAMES,
    DEFAULT_METHODS,
    EQUAL_STEP,
    BenchConfig,
    BenchRun,
    Cell,
    make_configs,
)
from .report import PAPER_TABLE1, format_markdown, table_json, write_outputs

__all__ = [
    "CONFIG_NAMES",
    "DEFAULT_METHODS",
    "EQUAL_STEP",
    "PAPER_TABLE1",
    "BenchConfig",
    "BenchRun",
    "Cell",
    "format_markdown",
    "machine_info",
    "make_configs",
    "run_bench",
    "table_json",
    "time_interleaved",
    "write_outputs",
]
