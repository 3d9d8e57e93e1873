"""A `.jsurf` file's syntax: a Java properties file (jsurf's `FileFormat.load`).

`key=value` lines, `#`/`!` comments, backslash escapes (`\\t`, `\\uXXXX`, `\\=`) and line
continuations (a line ending in an odd number of backslashes), read as
`java.util.Properties.load` reads them, keeping where each value character is written so
that an error in a value (the equation above all) points into the file.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

from ..errors import InputError, Source


@dataclass(frozen=True)
class Entry:
    """One property: its key, its value, and the file position of each value character."""

    key: str
    value: str
    line: int  # where the key starts
    col: int
    positions: tuple[tuple[int, int], ...]  # (line, col) of each value char, and the end


class Properties:
    """A .jsurf file's properties in file order, each with where it is written."""

    def __init__(self, name: str, text: str):
        self.name = name
        self.lines = tuple(re.split(r"\r\n|\r|\n", text))
        self.entries: dict[str, Entry] = {}
        for entry in _read_properties(text):
            if entry.key in self.entries:
                first = self.entries[entry.key]
                raise self.key_error(entry, f"'{entry.key}' is given twice (first at line "
                                            f"{first.line})")
            self.entries[entry.key] = entry

    def source(self, entry: Entry) -> Source:
        return Source(self.name, entry.value, entry.positions[0][0], entry.positions[0][1],
                      entry.positions, self.lines)

    def key_error(self, entry: Entry, message: str) -> InputError:
        positions = tuple((entry.line, entry.col + i) for i in range(len(entry.key) + 1))
        return InputError(message, Source(self.name, entry.key, entry.line, entry.col,
                                          positions, self.lines), 0, len(entry.key))

    def value_error(self, entry: Entry, message: str) -> InputError:
        lead = len(entry.value) - len(entry.value.lstrip())
        return InputError(message, self.source(entry), lead, len(entry.value.strip()) or 1)

    def file_error(self, message: str) -> InputError:
        return InputError(message, Source(self.name, self.lines[0] if self.lines else ""))


def _read_properties(text: str) -> list[Entry]:
    """java.util.Properties.load, keeping each character's (line, col)."""
    chars: list[tuple[str, int, int]] = []  # the logical line being read
    entries: list[Entry] = []
    natural = re.split(r"\r\n|\r|\n", text)
    continuing = False
    for number, line in enumerate(natural, start=1):
        start = len(line) - len(line.lstrip(" \t\f"))
        body = line[start:]
        if not continuing:
            if not body or body[0] in "#!":
                continue
            chars = []
        backslashes = len(body) - len(body.rstrip("\\"))
        continuing = backslashes % 2 == 1
        kept = body[:-1] if continuing else body
        chars.extend((ch, number, start + i + 1) for i, ch in enumerate(kept))
        if continuing and number < len(natural):
            continue
        continuing = False
        if chars:
            entries.append(_entry(chars, number))
    return entries


_ESCAPES = {"t": "\t", "n": "\n", "r": "\r", "f": "\f"}


def _entry(chars: list[tuple[str, int, int]], last_line: int) -> Entry:
    i = 0
    key = []

    def unescape(i: int) -> tuple[str, int]:
        """The character at i (an escape sequence decoded) and the index after it."""
        ch = chars[i][0]
        if ch != "\\" or i + 1 >= len(chars):
            return ch, i + 1
        nxt = chars[i + 1][0]
        if nxt == "u":
            digits = "".join(c for c, _, _ in chars[i + 2 : i + 6])
            if not re.fullmatch(r"[0-9a-fA-F]{4}", digits):
                raise MalformedEscape(chars[i][1], chars[i][2])
            return chr(int(digits, 16)), i + 6
        return _ESCAPES.get(nxt, nxt), i + 2

    while i < len(chars) and chars[i][0] not in "=: \t\f":
        ch, i = unescape(i)
        key.append(ch)
    while i < len(chars) and chars[i][0] in " \t\f":
        i += 1
    if i < len(chars) and chars[i][0] in "=:":
        i += 1
        while i < len(chars) and chars[i][0] in " \t\f":
            i += 1
    value, positions = [], []
    while i < len(chars):
        positions.append(chars[i][1:])
        ch, i = unescape(i)
        value.append(ch)
    end = (chars[-1][1], chars[-1][2] + 1) if chars else (last_line, 1)
    positions.append(end)
    return Entry("".join(key), "".join(value), chars[0][1], chars[0][2], tuple(positions))


class MalformedEscape(Exception):
    """A `\\u` escape without four hex digits after it, at (line, col) of the file."""

    def __init__(self, line: int, col: int):
        super().__init__(line, col)
        self.line, self.col = line, col
