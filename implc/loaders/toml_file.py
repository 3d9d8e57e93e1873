"""Surface files in TOML (docs/reference/input-language.md "Surface files"), and where each error
in one points.

A surface file:

    name = "Cross-Cap"
    equation = "4x^2(x^2 + y^2 + z^2 + z) + y^2(y^2 + z^2 - 1) = 0"
    [params]            # optional named constants
    a = 0.5
    [view]              # optional camera and clip sphere
    radius = 1.2        # clip sphere radius (centre: `center`, default the origin)
    eye = [3.0, 2.0, 4.0]
    target = [0.0, 0.0, 0.0]
    up = [0.0, 1.0, 0.0]
    fov = 30.0          # degrees, across the picture's shorter side

Errors point into the file: an equation inside a TOML string is located at its own
line and column, so a caret lands under the offending character of the file.
"""

from __future__ import annotations

import bisect
import math
import re
import sys
from collections.abc import Mapping, Sequence
from pathlib import Path

import sympy

from ..errors import InputError, Source
from ..fileio import read_input
from ..front import check_param_name, parse_constant, parse_number
from ..limits import Limits
from ..scene import View, view_problems
from ..surface import Surface
from .common import MAX_FILE_BYTES, check_params_used, closest_name, parse_with_params

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib

TOP_KEYS = ("name", "equation", "params", "view")  # what a surface file may hold
VIEW_KEYS = ("radius", "center", "eye", "target", "up", "fov")


def load_toml(
    path: Path, overrides: Mapping[str, sympy.Expr], limits: Limits, origin: str,
    params_args: Sequence[str] = (),
) -> Surface:
    """The surface of a TOML file; `overrides` (from `--param`) replace its [params]."""
    name = str(path)
    raw = read_input(path, "a surface file")
    if len(raw) > MAX_FILE_BYTES:
        first = raw[:200].split(b"\n")[0].decode("utf-8", "replace")
        raise InputError(f"file is larger than {MAX_FILE_BYTES} bytes",
                         Source(name, first, 1, 1), 0, 1)
    if raw.startswith((b"\xff\xfe", b"\xfe\xff")):
        raise InputError("not UTF-8 text: the file is UTF-16 (it starts with a byte order "
                         "mark); save it as UTF-8", Source(name, "", 1, 1))
    kind = _binary_kind(raw)
    if kind:  # named, not echoed: its bytes mean nothing on a terminal
        raise InputError(f"{name}: {kind}, not a surface file; {READS}")
    try:
        # a byte order mark (Notepad's "UTF-8 with BOM") is not part of the text
        text = raw.decode("utf-8").removeprefix("\ufeff")
    except UnicodeDecodeError as err:
        before = raw[: err.start]
        line = before.count(b"\n") + 1
        start = before.rfind(b"\n") + 1
        line_text = raw[start:].split(b"\n")[0].decode("utf-8", "replace")
        col = len(raw[start : err.start].decode("utf-8", "replace"))
        raise InputError(f"not UTF-8 text (byte 0x{raw[err.start]:02x})",
                         Source(name, line_text, line, 1), col) from None
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as err:
        error = _toml_error(name, text, err)
        error.help = _looks_like(text)
        raise error from None
    where = _TomlMap(name, text)
    where.check_keys(data)

    equation = data.get("equation")
    if equation is None:
        raise where.error(("",), "no equation: add a line like "
                                 "equation = \"x^2 + y^2 + z^2 = 1\"", whole_file=True)
    if not isinstance(equation, str):
        raise where.error(("equation",), "equation must be a string, like "
                                         "equation = \"x^2 + y^2 + z^2 = 1\"", value=True)
    values: dict[str, sympy.Expr] = {}
    table = data.get("params", {})
    if not isinstance(table, dict):
        raise where.error(("params",), "params must be a table ([params], then name = number)",
                          value=True)
    for key, value in sorted(table.items()):
        src = where.key_source(("params", key))
        check_param_name(key, src)
        if isinstance(value, str):  # a constant expression, as --param takes it
            values[key] = parse_constant(where.string_source(("params", key), value), limits)
            continue
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise where.error(("params", key), f"parameter '{key}' must be a number or a "
                                              "constant expression in quotes, not "
                                              f"{_toml_type(value)}", value=True)
        values[key] = parse_number(repr(value), src)
    values.update(overrides)
    source = where.string_source(("equation",), equation)
    expr, symbolic = parse_with_params(source, values, limits)
    check_params_used(equation, overrides, params_args, where, table)
    title = data.get("name", path.stem)
    if not isinstance(title, str):
        raise where.error(("name",), f"name must be a string, not {_toml_type(title)}",
                          value=True)
    return Surface(title, expr, values, _view(where, data.get("view", {})), origin, symbolic,
                   limits=limits)


def _view(where: _TomlMap, table) -> View:
    if not isinstance(table, dict):
        raise where.error(("view",), "view must be a table ([view], then key = value)",
                          value=True)
    default = View()

    def number(key: str, fallback: float, low: float, high: float) -> float:
        value = table.get(key, fallback)
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise where.error(("view", key), f"[view] {key} must be a number, not "
                                             f"{_toml_type(value)}", value=True)
        if not low < float(value) < high:
            raise where.error(("view", key), f"[view] {key} = {value} must be between {low:g} "
                                             f"and {high:g} (exclusive)", value=True)
        return float(value)

    def vector(key: str, fallback) -> tuple[float, float, float]:
        value = table.get(key, fallback)
        if (not isinstance(value, (list, tuple)) or len(value) != 3
                or any(isinstance(v, bool) or not isinstance(v, (int, float)) for v in value)):
            raise where.error(("view", key), f"[view] {key} must be 3 numbers, like "
                                             "[0.0, 0.0, 0.0]", value=True)
        if not all(math.isfinite(float(v)) for v in value):
            raise where.error(("view", key), f"[view] {key} must be finite (no nan or inf)",
                              value=True)
        if any(abs(float(v)) > 1e6 for v in value):
            raise where.error(("view", key), f"[view] {key} is too far from the origin "
                                             "(each coordinate within 1e6)", value=True)
        return (float(value[0]), float(value[1]), float(value[2]))

    center = vector("center", default.clip_center)
    view = View(
        eye=vector("eye", default.eye),
        target=vector("target", center),  # what it looks at: the clip sphere's centre
        up=vector("up", default.up),
        fov_y_deg=number("fov", default.fov_y_deg, 0.0, 180.0),
        clip_center=center,
        clip_radius=number("radius", default.clip_radius, 0.0, 1e6),
        given=frozenset(table),  # what the command line's framing leaves alone
    )
    for key, message in view_problems(view):
        # a default value is not in the file: point at the value that makes it wrong
        fallbacks = {"up": ("up", "eye", "target"), "target": ("target", "eye", "center")}
        chosen = next((k for k in fallbacks.get(key, (key,)) if k in table), None)
        path = ("view", chosen) if chosen else ("view",)
        raise where.error(path, f"[view] {message}", value=chosen is not None)
    return view


def _toml_type(value) -> str:
    if isinstance(value, bool):
        return "a boolean"
    if isinstance(value, str):
        return "a string"
    if isinstance(value, (int, float)):
        return "a number"
    if isinstance(value, list):
        return "an array"
    if isinstance(value, dict):
        return "a table"
    return f"a {type(value).__name__}"


_KEY_PART = r"""(?:[A-Za-z0-9_-]+|"(?:[^"\\]|\\.)*"|'[^']*')"""
_KEY_RE = re.compile(rf"\s*({_KEY_PART}(?:\s*\.\s*{_KEY_PART})*)\s*=\s*")
_HEADER_RE = re.compile(rf"\s*(\[\[?)\s*({_KEY_PART}(?:\s*\.\s*{_KEY_PART})*)\s*\]")


class _TomlMap:
    """Where every key, table header and string value of a surface file sits.

    tomllib gives values but no positions; this scanner reads the file's lines once for
    `key = value` lines and `[table]` headers (skipping the inside of multi-line
    strings), and decodes string values itself to map every character to its line and
    column, escapes and multi-line strings included. A key it cannot place (an inline
    table) falls back to its nearest placed ancestor, so the line is still right.
    """

    def __init__(self, name: str, text: str):
        self.name = name
        self.text = text
        self.lines = tuple(line.rstrip("\r") for line in text.split("\n"))
        self.starts = [0]
        for index, char in enumerate(text):
            if char == "\n":
                self.starts.append(index + 1)
        self.keys: dict[tuple[str, ...], tuple[int, int, int]] = {}  # line, key col, value col
        self.tables: dict[tuple[str, ...], tuple[int, int]] = {}  # line, name col
        self._scan()

    def _scan(self) -> None:
        table: tuple[str, ...] = ()
        number = 0
        while number < len(self.lines):
            line = self.lines[number]
            number += 1
            stripped = line.lstrip()
            if not stripped or stripped.startswith("#"):
                continue
            header = _HEADER_RE.match(line)
            if stripped.startswith("[") and header:
                table = _key_path(header.group(2))
                self.tables.setdefault(table, (number, header.start(2) + 1))
                continue
            match = _KEY_RE.match(line)
            if not match:
                continue
            key = table + _key_path(match.group(1))
            self.keys.setdefault(key, (number, match.start(1) + 1, match.end() + 1))
            rest = line[match.end():]
            if rest.startswith(('"""', "'''")):
                decoded = self._decode(self.starts[number - 1] + match.end())
                if decoded is not None:  # continue after the string's last line
                    number = bisect.bisect_right(self.starts, decoded[2] - 1)

    def check_keys(self, data: dict) -> None:
        """Unknown keys and sections are errors with a "did you mean" hint."""
        for key in data:
            if key in TOP_KEYS:
                continue
            is_table = isinstance(data[key], dict)
            hint = closest_name(key, [*TOP_KEYS, *VIEW_KEYS])
            if hint in VIEW_KEYS:
                hint_text = f"; did you mean '{hint}' (under [view])?"
            elif hint:
                hint_text = f"; did you mean [{hint}]?" if is_table and hint in (
                    "params", "view") else f"; did you mean '{hint}'?"
            else:
                hint_text = ""
            what = f"unknown section [{key}]" if is_table else f"unknown key '{key}'"
            known = "name, equation, [params], [view]"
            raise self.error((key,), f"{what} in a surface file{hint_text} (known: {known})")
        view = data.get("view")
        if isinstance(view, dict):
            for key in view:
                if key not in VIEW_KEYS:
                    hint = closest_name(key, VIEW_KEYS)
                    hint_text = f"; did you mean '{hint}'?" if hint else ""
                    raise self.error(("view", key), f"unknown key '{key}' in [view]{hint_text} "
                                                    f"(known: {', '.join(VIEW_KEYS)})")

    def _place(self, path: tuple[str, ...], value: bool) -> tuple[int, int, int] | None:
        """(line, col, length) of `path`'s key (or value), or of its nearest ancestor."""
        for end in range(len(path), 0, -1):
            prefix = path[:end]
            if prefix in self.keys:
                line, key_col, value_col = self.keys[prefix]
                if value and end == len(path):
                    rest = self.lines[line - 1][value_col - 1:]
                    length = len(rest.split("#")[0].rstrip()) or 1
                    return line, value_col, length
                return line, key_col, len(prefix[-1])
            if prefix in self.tables:
                line, col = self.tables[prefix]
                return line, col, len(".".join(prefix))
        return None

    def error(self, path: tuple[str, ...], message: str, *, value: bool = False,
              whole_file: bool = False) -> InputError:
        place = None if whole_file else self._place(path, value)
        line, col, length = place or (1, 1, 1)
        line_text = self.lines[line - 1] if self.lines else ""
        return InputError(message, Source(self.name, line_text, line, 1), col - 1, length)

    def key_source(self, path: tuple[str, ...]) -> Source:
        """A Source whose text is the key's own name, at its place in the file."""
        line, col = self.keys[path][:2] if path in self.keys else (1, 1)
        return Source(self.name, path[-1], line, col)

    def string_source(self, path: tuple[str, ...], value: str) -> Source:
        """The Source of a string value, every character mapped to the file."""
        if path in self.keys:
            line, _, value_col = self.keys[path]
            decoded = self._decode(self.starts[line - 1] + value_col - 1)
            if decoded is not None and decoded[0] == value:
                positions = tuple(self._position(k) for k in decoded[1])
                first = positions[0]
                return Source(self.name, value, first[0], first[1], positions, self.lines)
            return Source(self.name, value, line, 1)  # unknown layout: the line is right
        return Source(self.name, value)

    def _position(self, index: int) -> tuple[int, int]:
        line = bisect.bisect_right(self.starts, index)
        return line, index - self.starts[line - 1] + 1

    def _decode(self, k: int) -> tuple[str, list[int], int] | None:
        """The TOML string starting at text[k]: (value, file index of each character and
        of the closing quote, index after the string); None if it is not one."""
        text = self.text
        for quote in ('"""', "'''", '"', "'"):
            if text.startswith(quote, k):
                break
        else:
            return None
        multi, basic = len(quote) == 3, quote[0] == '"'
        j = k + len(quote)
        if multi and text.startswith("\r\n", j):
            j += 2
        elif multi and text.startswith("\n", j):
            j += 1  # a newline right after the opening quotes is not part of the value
        chars: list[str] = []
        where: list[int] = []
        escapes = {"b": "\b", "t": "\t", "n": "\n", "f": "\f", "r": "\r", '"': '"',
                   "\\": "\\", "e": "\x1b"}
        while j < len(text):
            if text.startswith(quote, j):
                run = len(quote)
                if multi:  # up to two quotes may sit right before the closing ones
                    while text.startswith(quote[0], j + run) and run < 5:
                        run += 1
                    for extra in range(run - 3):
                        chars.append(quote[0])
                        where.append(j + extra)
                    j += run - 3
                where.append(j)
                return "".join(chars), where, j + len(quote)
            char = text[j]
            if not multi and char == "\n":
                return None
            if basic and char == "\\":
                nxt = text[j + 1 : j + 2]
                if multi and nxt in (" ", "\t", "\r", "\n"):
                    m = re.compile(r"[ \t]*\r?\n[ \t\r\n]*").match(text, j + 1)
                    if m:  # a line-ending backslash eats the newline and what follows
                        j = m.end()
                        continue
                if nxt in escapes:
                    chars.append(escapes[nxt])
                    where.append(j)
                    j += 2
                    continue
                width = {"u": 4, "U": 8, "x": 2}.get(nxt)
                digits = text[j + 2 : j + 2 + width] if width else ""
                if width and re.fullmatch(r"[0-9A-Fa-f]+", digits) and len(digits) == width:
                    chars.append(chr(int(digits, 16)))
                    where.append(j)
                    j += 2 + width
                    continue
                return None
            chars.append(char)
            where.append(j)
            j += 1
        return None


def _key_path(text: str) -> tuple[str, ...]:
    parts = re.findall(_KEY_PART, text)
    return tuple(p[1:-1] if p[:1] in ('"', "'") else p for p in parts)


READS = ("implc reads surfaces from TOML files (.toml), SURFER files (.jsurf), bundled "
         "example names (`implc list`) and -e EQUATION")

# the first bytes of files a user may give by mistake, and what they are
_MAGIC = ((b"\x89PNG\r\n\x1a\n", "a PNG image"), (b"\x76\x2f\x31\x01", "an OpenEXR image"),
          (b"\xff\xd8\xff", "a JPEG image"), (b"\x03\x02\x23\x07", "a SPIR-V module"),
          (b"%PDF", "a PDF document"), (b"PK\x03\x04", "a zip archive"))
_SHADER = re.compile(r"^\s*#version\b|\bvoid\s+main\s*\(|@(compute|fragment|vertex)\b|"
                     r"__kernel\b|\bfn\s+\w+\s*\(", re.M)
_JSURF = re.compile(r"^\s*surface_equation\s*=", re.M)


def _binary_kind(raw: bytes) -> str | None:
    """What a binary file is (an image, a module), or None for text."""
    for magic, kind in _MAGIC:
        if raw.startswith(magic):
            return kind
    return "a binary file" if b"\0" in raw[:8192] else None


def _looks_like(text: str) -> str | None:
    """A hint for a text that is not TOML but another kind of file implc knows."""
    if _JSURF.search(text):
        return ("this looks like a SURFER file (surface_equation=...): name it .jsurf and "
                "implc reads it as one")
    if _SHADER.search(text):
        return (f"this looks like a shader, not a surface file (`implc validate` checks "
                f"shaders); {READS}")
    return None


def _toml_error(name: str, text: str, err: Exception) -> InputError:
    message = str(err)
    match = re.search(r"\(at line (\d+), column (\d+)\)", message)
    short = re.sub(r"\s*\(at .*\)$", "", message).strip()
    short = short[:1].lower() + short[1:]
    if not match:
        match = re.search(r"\(at end of document\)", message)
        lines = text.split("\n")
        line_text = lines[-1].rstrip("\r")
        return InputError(f"invalid TOML: {short}", Source(name, line_text, len(lines), 1),
                          len(line_text))
    line, col = int(match.group(1)), int(match.group(2))
    lines = text.splitlines() or [""]
    line_text = lines[min(line, len(lines)) - 1]
    return InputError(f"invalid TOML: {short}", Source(name, line_text, line, 1), col - 1)
