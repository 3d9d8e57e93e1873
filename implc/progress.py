"""Progress of long runs (`bench`, `corpus`, `make fuzz`): a bar with an ETA on a
terminal (tqdm), plain lines otherwise (a log file, CI, a pipe).

    progress = Progress(total=9, desc="bench", stream=sys.stderr)
    progress.step("cross-cap hessian paper: 12.3 fps")   # one unit done
    progress.note("reference cross-cap: 1.2 s")          # a line, no unit
    progress.close()

On a terminal `step` moves the bar (its text becomes the bar's postfix) and `note` prints
above it; elsewhere both print their line, `step` prefixed by `[k/total]`.
"""

from __future__ import annotations

import os
import sys
from typing import TextIO


def is_terminal(stream: TextIO | None) -> bool:
    if stream is None or os.environ.get("IMPLC_NO_PROGRESS_BAR"):
        return False
    try:
        return stream.isatty()
    except (AttributeError, ValueError):
        return False


class Progress:
    def __init__(self, total: int, desc: str, stream: TextIO | None = sys.stderr,
                 unit: str = "it", bar: bool | None = None):
        self.total, self.done, self.stream = total, 0, stream
        self.bar = None
        if bar if bar is not None else is_terminal(stream):
            from tqdm import tqdm

            self.bar = tqdm(total=total, desc=desc, file=stream, unit=unit, dynamic_ncols=True,
                            leave=True, smoothing=0.1)

    def step(self, line: str = "", count: int = 1) -> None:
        self.done += count
        if self.bar is not None:
            self.bar.update(count)
            if line:
                self.bar.set_postfix_str(line[:60], refresh=True)
        elif self.stream is not None and line:
            width = len(str(self.total))
            print(f"[{self.done:>{width}}/{self.total}] {line}", file=self.stream, flush=True)

    def note(self, line: str) -> None:
        if self.bar is not None:
            self.bar.write(line, file=self.stream)
        elif self.stream is not None:
            print(line, file=self.stream, flush=True)

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()
            self.bar = None

    def __enter__(self) -> Progress:
        return self

    def __exit__(self, *exc) -> None:
        self.close()
