"""Error types and the diagnostic printer.

Every error a user can cause is an `ImplcError`; the CLI prints it with `render()` and
exits with its `exit_code`. Nothing else reaches the terminal: no tracebacks.
Located errors point into the user's own file (`file:line:col: error: ...`, the source
line and a caret under the span), even when the equation sits inside a TOML string.
"""

from __future__ import annotations

import unicodedata
from dataclasses import dataclass

# Documented exit codes (docs/reference/errors.md "Exit codes").
EXIT_OK = 0
EXIT_INPUT = 1  # the equation, a surface file or a parameter is wrong
EXIT_USAGE = 2  # the command line is wrong (argparse uses 2 as well)
EXIT_INVALID = 3  # a shader failed validation by its real compiler
EXIT_TOOL = 4  # a required tool or runtime is missing or failed
EXIT_INTERNAL = 70  # a bug in implc: an unexpected exception (sysexits EX_SOFTWARE)
EXIT_INTERRUPTED = 130  # SIGINT (Ctrl-C): 128 + 2
EXIT_TERMINATED = 143  # SIGTERM: 128 + 15


@dataclass(frozen=True)
class Source:
    """Text that a user wrote, and where it sits in its file.

    `text` is the equation itself; `line`/`col` (1-based) give where its first character
    sits in the file called `name`. An equation read from a TOML string starts mid-line.
    """

    name: str
    text: str
    line: int = 1
    col: int = 1
    # For text decoded from a quoted string (escapes, multi-line strings): the file's
    # (line, col) of every character of `text` and of the position after it, and the
    # file's lines, so a caret lands under the character as the user wrote it.
    positions: tuple[tuple[int, int], ...] | None = None
    file_lines: tuple[str, ...] | None = None

    def locate(self, offset: int) -> tuple[int, int, str, int]:
        """Map an offset into `text` to (file line, file col, line text, col in line text)."""
        offset = max(0, min(offset, len(self.text)))
        if self.positions and self.file_lines is not None:
            line, col = self.positions[min(offset, len(self.positions) - 1)]
            line_text = self.file_lines[line - 1] if 0 < line <= len(self.file_lines) else ""
            return line, col, line_text, col - 1
        before = self.text[:offset]
        line_in_text = before.count("\n")
        line_start = before.rfind("\n") + 1
        line_end = self.text.find("\n", offset)
        line_text = self.text[line_start : len(self.text) if line_end < 0 else line_end]
        col_in_line = offset - line_start
        if line_in_text == 0:
            return self.line, self.col + col_in_line, line_text, col_in_line
        return self.line + line_in_text, 1 + col_in_line, line_text, col_in_line


class ImplcError(Exception):
    """Base of every error implc reports to a user."""

    exit_code = EXIT_INPUT

    def render(self) -> str:
        return f"implc: error: {self}"


class InputError(ImplcError):
    """A mistake in user input, located at a span of its source when one is known."""

    def __init__(
        self,
        message: str,
        source: Source | None = None,
        offset: int = 0,
        length: int = 1,
        *,
        also: tuple[tuple[int, int], ...] = (),
        help: str | None = None,  # noqa: A002 - the word the printed line starts with
    ):
        super().__init__(message)
        self.message = message
        self.source = source
        self.offset = offset
        self.length = max(1, length)
        # more (offset, length) spans of the same problem (every use of an unknown name):
        # marked on the echoed line when they sit on it
        self.also = also
        # what to do about it, printed as a last line `help: ...`
        self.help = help

    def __str__(self) -> str:
        """The whole diagnostic (place, source line, caret, help): what Python and a
        notebook print after the exception's name, so a user of the API sees the caret
        too; `message` is the bare message."""
        if self.source is None:
            return self.message + (f"\n  help: {self.help}" if self.help else "")
        return self.render()

    def render(self) -> str:
        tail = f"\n  help: {self.help}" if self.help else ""
        if self.source is None:
            return f"implc: error: {self.message}{tail}"
        line, col, line_text, col_in_line = self.source.locate(self.offset)
        spans = [(col_in_line, self.length)]
        for offset, length in self.also:
            other = self.source.locate(offset)
            if other[0] == line and other[2] == line_text:
                spans.append((other[3], length))
        shown, marks = _excerpt(line_text, spans)
        return (f"{self.source.name}:{line}:{col}: error: {self.message}\n  {shown}\n  {marks}"
                f"{tail}")


class OptionError(ImplcError):
    """An option that does not fit: a choice a target does not have, contradicting
    options, a view that shows nothing (exit 2 on the command line, which names its
    flag; a keyword argument of the Python API). Distinct from InputError, which is
    about what the user wrote as a surface."""

    exit_code = EXIT_USAGE

    def __init__(self, message: str):
        super().__init__(message)
        self.message = message


class OutputError(InputError):
    """An output that cannot be written: a missing or read-only directory, an unknown
    extension, a directory where a file should go, a full disk (exit code 1)."""


class LimitError(InputError):
    """Input that is well formed but too large or too complex to compile safely."""


class ValidationError(ImplcError):
    """A generated shader that its language's real compiler rejects."""

    exit_code = EXIT_INVALID


class ToolError(ImplcError):
    """A required external tool or runtime is missing or failed."""

    exit_code = EXIT_TOOL


# Widest echoed source line, in terminal columns: a longer line is cut to a window around
# the caret, with `...` where it was cut (a 60,000-character -e stays a few lines).
WINDOW = 100
_CUT = "..."
_TAB = "    "  # a tab, shown as spaces (its width in a terminal depends on the column)


def _cell(ch: str) -> str:
    """How one character of an echoed line is shown: a tab as spaces, other control
    characters as `?`, so that the caret line can be counted in characters."""
    if ch == "\t":
        return _TAB
    return ch if ch.isprintable() else "?"


def _width(shown: str) -> int:
    """Terminal columns of a shown cell: 2 for wide (CJK, full-width) characters."""
    if len(shown) == 1 and unicodedata.east_asian_width(shown) in ("W", "F"):
        return 2
    return len(shown)


def _excerpt(text: str, spans: list[tuple[int, int]]) -> tuple[str, str]:
    """The echoed line and the caret line under it (`^~~~` under each span), cut to a
    window of about WINDOW columns around the first span when the line is longer."""
    cells = [_cell(ch) for ch in text]
    starts = [0]  # the column where each character starts, then the line's width
    for cell in cells:
        starts.append(starts[-1] + _width(cell))
    total = starts[-1]

    def columns(offset: int, length: int) -> tuple[int, int]:
        offset = max(0, min(offset, len(text)))
        end = min(offset + max(1, length), len(text))
        return starts[offset], max(starts[offset] + 1, starts[end])

    marked = [columns(offset, length) for offset, length in spans]
    left, right = 0, total
    if total > WINDOW:  # a third of the window before the caret, the rest after it
        room = WINDOW - 2 * len(_CUT)
        left = max(0, min(marked[0][0] - room // 3, total - room))
        right = left + room
    first = next(i for i, s in enumerate(starts) if s >= left)
    last = max(i for i, s in enumerate(starts) if s <= right)
    prefix = _CUT if first > 0 else ""
    suffix = _CUT if last < len(text) else ""
    shift = len(prefix) - starts[first]
    text_end = len(prefix) + starts[last] - starts[first]
    marks: list[str] = []
    for start, end in reversed(marked):  # the first span last: it wins where they meet
        start = start + shift  # a caret right after the text is fine: "missing ')'"
        end = max(start + 1, min(end + shift, text_end))
        if start < len(prefix) or start > text_end or (start == text_end and suffix):
            continue  # outside the window
        marks += [" "] * (end - len(marks))
        marks[start:end] = ["^"] + ["~"] * (end - start - 1)
    return prefix + "".join(cells[first:last]) + suffix, "".join(marks)
