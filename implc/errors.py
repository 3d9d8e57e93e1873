"""Error types and the diagnostic printer.

Every error a user can cause is an `ImplcError`; the CLI prints it with `render()` and
exits with its `exit_code`. Nothing else reaches the terminal: no tracebacks.
Located errors point into the user's own file (`file:line:col: error: ...`, the source
line and a caret under the span), even when the equation sits inside a TOML string.
"""

from __future__ import annotations

from dataclasses import dataclass

# Documented exit codes (README "Exit codes").
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
        self, message: str, source: Source | None = None, offset: int = 0, length: int = 1
    ):
        super().__init__(message)
        self.message = message
        self.source = source
        self.offset = offset
        self.length = max(1, length)

    def render(self) -> str:
        if self.source is None:
            return f"implc: error: {self.message}"
        line, col, line_text, col_in_line = self.source.locate(self.offset)
        shown = _printable(line_text)
        caret_len = max(1, min(self.length, len(shown) - col_in_line))
        caret = " " * col_in_line + "^" + "~" * (caret_len - 1)
        return f"{self.source.name}:{line}:{col}: error: {self.message}\n  {shown}\n  {caret}"


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


def _printable(text: str) -> str:
    """Show control characters as `?` so the caret stays under the right column."""
    return "".join(ch if ch.isprintable() else "?" for ch in text)
