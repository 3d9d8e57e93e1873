"""SURFER's `.jsurf` files: read them into a `Surface`, write a `Surface` back as one.

A `.jsurf` file is a Java properties file (jsurf's `FileFormat.load`): `key=value` lines,
`#`/`!` comments, backslash escapes (`\\t`, `\\uXXXX`, `\\=`) and line continuations (a
line ending in an odd number of backslashes). Its equation is written in jsurf's own
grammar (`AlgebraicExpression.g`): `+ - * / ^`, parentheses, numbers, identifiers, and
one-argument functions (`sin ... sqrt abs sign`); no implicit multiplication, no `=`,
unary minus only before a power; a polynomial in x, y, z whose coefficients may use
functions of constants and parameters; an exponent of x, y, z a whole number literal;
division only by constants. Every other identifier is a parameter with its value from
`surface_parameter_NAME`. That grammar is checked here token by token (errors point into
the file at `file:line:col`); the text that passes is a subset of implc's own input
language with the same meaning, so implc's parser reads it as it stands, with every
character mapped to its place in the file. Nothing is evaluated.

The view (README "SURFER files"): jsurf maps camera space to its clipping space by
`transform_matrix * rotation_matrix * camera_transform^-1` and clipping space to the
surface's by `surface_transform_matrix * 10^scale_factor`; the clip sphere is the unit
sphere of clipping space. A perspective camera (`PERSPECTIVE_CAMERA`) is implc's camera
(eye at the camera's origin, `camera_fov_y`), looking where jsurf 0.4.1 draws when that
is a centred frustum (`_jsurf041_window`: jsurf's window is off-axis, a sheared
`camera_transform` centres it, and the writer writes that), else down -z. An orthographic one
(`ORTHOGRAPHIC_CAMERA`, `camera_height` tall) has no implc counterpart: it becomes a
perspective camera ORTHO_DISTANCE clip radii away whose field of view is that height at
the clip sphere's centre (picture scale within 1/ORTHO_DISTANCE across the sphere); the
writer turns a view whose eye is ORTHO_MIN_DISTANCE clip radii or more from its target
back into an orthographic camera.
"""

from __future__ import annotations

import difflib
import math
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import sympy

from .errors import InputError, Source
from .fileio import read_input
from .front import check_param_name, parse_equation_with_params, parse_number
from .limits import Limits
from .scene import SHADING, View, view_problems
from .surface import MAX_FILE_BYTES, Surface
from .symbols import X, Y, Z
from .textform import EquationPrinter

# an orthographic camera's eye, in clip radii from the target (at 1000 float32 shaders
# speckle: the eye is too far for the entry point's precision)
ORTHO_DISTANCE = 100.0
# the writer's orthographic cameras: an eye this many clip radii or more from the target
ORTHO_MIN_DISTANCE = ORTHO_DISTANCE / 2.0

# jsurf's one-argument functions (DoubleUnaryOperation.Op) and what implc calls them;
# None: implc has no such function.
JSURF_FUNCTIONS: dict[str, str | None] = {
    "sin": "sin", "cos": "cos", "tan": "tan", "asin": "asin", "acos": "acos",
    "atan": "atan", "exp": "exp", "log": "log", "sqrt": "sqrt", "abs": "abs",
    "sign": "sign", "ceil": None, "floor": None, "neg": None,
}
CAMERA_TYPES = ("ORTHOGRAPHIC_CAMERA", "PERSPECTIVE_CAMERA")
MATERIAL_KEYS = ("color", "ambient_intensity", "diffuse_intensity", "specular_intensity",
                 "specular_iIntensity", "shininess")  # iIntensity: as SURFER writes it
LIGHTS = 8  # AlgebraicSurfaceRenderer.MAX_LIGHTS
LIGHT_KEYS = ("status", "position", "color", "intensity")
USED_KEYS = ("surface_equation", "scale_factor", "rotation_matrix", "transform_matrix",
             "surface_transform_matrix", "camera_type", "camera_fov_y", "camera_height",
             "camera_transform", "front_material_color", "back_material_color")
KNOWN_KEYS = (*USED_KEYS, "background_color",
              *(f"{side}_material_{k}" for side in ("front", "back") for k in MATERIAL_KEYS),
              *(f"light_{k}_{i}" for i in range(LIGHTS) for k in LIGHT_KEYS))
PARAMETER_PREFIX = "surface_parameter_"


# --------------------------------------------------------------------------- properties

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
                raise _MalformedEscape(chars[i][1], chars[i][2])
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


class _MalformedEscape(Exception):
    def __init__(self, line: int, col: int):
        super().__init__(line, col)
        self.line, self.col = line, col


# --------------------------------------------------------------------------- equation

_TOKEN = re.compile(r"(?P<num>\d+\.\d*(?:[eE][+-]?\d+)?|\.\d+(?:[eE][+-]?\d+)?|\d+[eE][+-]?\d+"
                    r"|0|[1-9]\d*)|(?P<id>[A-Za-z_][A-Za-z0-9_]*)|(?P<op>[-+*/^()])"
                    r"|(?P<ws>[ \t\r\n\f]+)", re.ASCII)


@dataclass(frozen=True)
class _Tok:
    kind: str  # num, int, id, op, end
    text: str
    start: int


@dataclass(frozen=True)
class _Node:
    poly: bool  # depends on x, y, z (jsurf's PolynomialOperation, not a DoubleOperation)
    integer: bool  # a whole-number literal (jsurf's DECIMAL_LITERAL), maybe in parentheses
    start: int
    end: int


class _JsurfGrammar:
    """jsurf's parser and tree walker as checks: what they refuse is an InputError here,
    located in the file; what they accept is returned untouched, with its parameters."""

    def __init__(self, source: Source):
        self.source = source
        self.tokens = self.tokenize(source.text)
        self.i = 0
        self.params: dict[str, list[int]] = {}

    def error(self, message: str, start: int, length: int = 1) -> InputError:
        return InputError(message, self.source, start, length)

    def tokenize(self, text: str) -> list[_Tok]:
        tokens, pos = [], 0
        while pos < len(text):
            m = _TOKEN.match(text, pos)
            if m is None:
                ch = text[pos]
                hint = (": a .jsurf equation is S alone (drawn where S = 0), so write "
                        "'lhs - (rhs)'" if ch == "=" else "")
                raise self.error(f"jsurf's equations have no '{ch}'{hint}", pos)
            if m.lastgroup != "ws":
                kind = m.lastgroup
                if kind == "num" and re.fullmatch(r"\d+", m.group()):
                    kind = "int"
                tokens.append(_Tok(kind, m.group(), pos))
            pos = m.end()
        tokens.append(_Tok("end", "", len(text)))
        return tokens

    def peek(self) -> _Tok:
        return self.tokens[self.i]

    def take(self) -> _Tok:
        tok = self.tokens[self.i]
        self.i += 1
        return tok

    def check(self) -> dict[str, list[int]]:
        if self.peek().kind == "end":
            raise self.error("empty equation: surface_equation=... needs a polynomial in "
                             "x, y, z", 0, max(1, len(self.source.text)))
        self.add()
        tok = self.peek()
        if tok.kind != "end":
            hint = (": jsurf has no implicit multiplication; write '*'"
                    if tok.kind in ("int", "num", "id") or tok.text == "(" else "")
            raise self.error(f"unexpected '{tok.text}'{hint}", tok.start, len(tok.text))
        return self.params

    def add(self) -> _Node:
        node = self.mult()
        while self.peek().text in ("+", "-") and self.peek().kind == "op":
            self.take()
            right = self.mult()
            node = _Node(node.poly or right.poly, False, node.start, right.end)
        return node

    def mult(self) -> _Node:
        node = self.neg()
        while self.peek().kind == "op" and self.peek().text in ("*", "/"):
            op = self.take()
            right = self.neg()
            if op.text == "/" and right.poly:
                raise self.error("jsurf divides by constants only, not by x, y, z",
                                 right.start, right.end - right.start)
            node = _Node(node.poly or right.poly, False, node.start, right.end)
        return node

    def neg(self) -> _Node:
        if self.peek().kind == "op" and self.peek().text == "-":
            minus = self.take()
            node = self.power()
            return _Node(node.poly, False, minus.start, node.end)
        return self.power()

    def power(self) -> _Node:
        base = self.unary()
        if not (self.peek().kind == "op" and self.peek().text == "^"):
            return base
        self.take()
        exponent = self.power()
        if exponent.poly:
            raise self.error("an exponent cannot contain x, y or z", exponent.start,
                             exponent.end - exponent.start)
        if base.poly and not exponent.integer:
            raise self.error("a power of x, y, z needs a whole number literal as its exponent "
                             "(jsurf's rule)", exponent.start, exponent.end - exponent.start)
        return _Node(base.poly, False, base.start, exponent.end)

    def unary(self) -> _Node:
        tok = self.peek()
        if tok.kind == "id" and self.tokens[self.i + 1].text == "(":
            self.take()
            return self.call(tok)
        return self.primary()

    def call(self, name: _Tok) -> _Node:
        if name.text not in JSURF_FUNCTIONS:
            close = difflib.get_close_matches(name.text, JSURF_FUNCTIONS, n=1)
            hint = f"; did you mean '{close[0]}'?" if close else ""
            raise self.error(f"jsurf has no function '{name.text}'{hint}", name.start,
                             len(name.text))
        if JSURF_FUNCTIONS[name.text] is None:
            raise self.error(f"implc does not support jsurf's '{name.text}'", name.start,
                             len(name.text))
        self.take()  # (
        arg = self.add()
        close_tok = self.expect_close(name)
        if arg.poly:
            raise self.error(f"jsurf applies {name.text} to constants only, not to x, y, z",
                             arg.start, arg.end - arg.start)
        return _Node(False, False, name.start, close_tok.start + 1)

    def expect_close(self, opening: _Tok) -> _Tok:
        tok = self.peek()
        if not (tok.kind == "op" and tok.text == ")"):
            raise self.error(f"expected ')' to close the '(' at column "
                             f"{self.source.locate(opening.start)[1]}, found "
                             f"{repr(tok.text) if tok.text else 'the end'}", tok.start,
                             len(tok.text) or 1)
        return self.take()

    def primary(self) -> _Node:
        tok = self.take()
        if tok.kind in ("int", "num"):
            return _Node(False, tok.kind == "int", tok.start, tok.start + len(tok.text))
        if tok.kind == "id":
            if tok.text in ("x", "y", "z"):
                return _Node(True, False, tok.start, tok.start + 1)
            self.params.setdefault(tok.text, []).append(tok.start)
            return _Node(False, False, tok.start, tok.start + len(tok.text))
        if tok.kind == "op" and tok.text == "(":
            inner = self.add()
            close = self.expect_close(tok)
            return _Node(inner.poly, inner.integer, tok.start, close.start + 1)
        found = repr(tok.text) if tok.text else "the end of the equation"
        raise self.error(f"expected a number, a name or '(', found {found}", tok.start,
                         len(tok.text) or 1)


# --------------------------------------------------------------------------- reading

def load_jsurf(path: Path, overrides: Mapping[str, sympy.Expr], limits: Limits,
               params_args: Sequence[str] = ()) -> Surface:
    """The surface, parameters, view and colours of a .jsurf file; `overrides` from
    `--param` replace the file's `surface_parameter_*` values."""
    name = str(path)
    raw = read_input(path, "a .jsurf file")
    if len(raw) > MAX_FILE_BYTES:
        raise InputError(f"{name}: file is larger than {MAX_FILE_BYTES} bytes")
    try:
        text = raw.decode("utf-8").removeprefix("\ufeff")
    except UnicodeDecodeError:
        text = raw.decode("latin-1")  # java.util.Properties' own encoding
    try:
        props = Properties(name, text)
    except _MalformedEscape as err:
        lines = tuple(re.split(r"\r\n|\r|\n", text))
        line_text = lines[err.line - 1]
        raise InputError("malformed \\uXXXX escape: four hex digits must follow \\u",
                         Source(name, line_text, err.line, 1), err.col - 1, 2) from None
    return _surface(props, path, overrides, limits, params_args)


def _surface(props: Properties, path: Path, overrides: Mapping[str, sympy.Expr],
             limits: Limits, params_args: Sequence[str]) -> Surface:
    entries = props.entries
    for key, entry in entries.items():
        if key.startswith(PARAMETER_PREFIX) or key in KNOWN_KEYS:
            continue
        close = difflib.get_close_matches(key, [*KNOWN_KEYS, PARAMETER_PREFIX + "a"], n=1,
                                          cutoff=0.7)
        hint = f"; did you mean '{close[0]}'?" if close else ""
        raise props.key_error(entry, f"unknown key '{key}'{hint}")
    equation = entries.get("surface_equation")
    if equation is None:
        raise props.file_error("no surface_equation: a .jsurf file needs a line like "
                               "surface_equation=x^2+y^2+z^2-1")
    source = props.source(equation)
    used = _JsurfGrammar(source).check()
    values: dict[str, sympy.Expr] = {}
    ignored: list[str] = []
    for key, entry in entries.items():
        if not key.startswith(PARAMETER_PREFIX):
            continue
        pname = key[len(PARAMETER_PREFIX):]
        if pname not in used:
            ignored.append(f"{key} (not in the equation)")
            continue
        values[pname] = parse_number(entry.value, props.source(entry), limits)
    for pname, offsets in used.items():
        check_param_name(pname, Source(source.name, pname, *source.locate(offsets[0])[:2]))
        if pname not in values and pname not in overrides:
            raise InputError(f"parameter '{pname}' has no value", source, offsets[0],
                             len(pname), also=tuple((o, len(pname)) for o in offsets[1:]),
                             help=f"add a line {PARAMETER_PREFIX}{pname}=VALUE, or give "
                                  f"--param {pname}=VALUE")
    for arg in params_args:
        pname = arg.partition("=")[0].strip()
        if pname not in used:
            listed = ", ".join(sorted(used)) or "none"
            raise InputError(f"parameter '{pname}' is not in the equation (its parameters: "
                             f"{listed})", Source("--param", arg), 0, len(pname))
    values.update(overrides)
    expr, symbolic = parse_equation_with_params(source, values, limits)
    view, off_axis = _view(props)
    problems = view_problems(view)
    if problems:
        raise props.file_error(f"the view shows nothing: {problems[0][1]}")
    ignored += sorted({_ignored_name(k) for k in entries
                       if k in KNOWN_KEYS and k not in USED_KEYS})
    notes = (f"implc: note: {props.name}: ignored (implc does not use them): "
             f"{', '.join(ignored)}",) if ignored else ()
    if off_axis:
        notes += (f"implc: note: {props.name}: jsurf 0.4.1 draws this PERSPECTIVE_CAMERA "
                  "beside what it looks at (its window spans 1 to 3 times tan(fov/2) up "
                  "and right of the axis); implc draws the camera's centred view, as "
                  "jsurf's code means it (README \"SURFER files\")",)
    return Surface(path.stem, expr, values, view, str(path),
                   symbolic if values else None, notes)


def _ignored_name(key: str) -> str:
    """One name for a group: `light_*`, `*_material_shininess` for front and back."""
    if key.startswith("light_"):
        return "light_*"
    return re.sub(r"^(front|back)_material_", "*_material_", key)


def _floats(props: Properties, key: str, count: int) -> list[float] | None:
    """`count` numbers of `key`'s value (Java's Scanner over whitespace), None when absent."""
    entry = props.entries.get(key)
    if entry is None:
        return None
    words = entry.value.split()
    numbers = []
    for word in words:
        m = re.fullmatch(r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?[fFdD]?", word)
        if m is None:
            raise props.value_error(entry, f"{key}: '{word}' is not a number")
        numbers.append(float(word.rstrip("fFdD")))
    if len(numbers) != count:
        what = {1: "a number", 3: "3 numbers", 16: "16 numbers (a 4x4 matrix, row by row)"}
        raise props.value_error(entry, f"{key} must be {what[count]}, not {len(numbers)}")
    if not all(math.isfinite(v) for v in numbers):
        raise props.value_error(entry, f"{key}: every number must be finite")
    return numbers


def _matrix(props: Properties, key: str) -> np.ndarray:
    values = _floats(props, key, 16)
    if values is None:
        return np.eye(4)
    m = np.asarray(values).reshape(4, 4)
    if not np.allclose(m[3], [0, 0, 0, 1]) or abs(np.linalg.det(m[:3, :3])) < 1e-12:
        raise props.value_error(props.entries[key], f"{key} must be an invertible affine "
                                                    "matrix (last row 0 0 0 1)")
    return m


def _color(props: Properties, key: str) -> tuple[float, float, float] | None:
    values = _floats(props, key, 3)
    if values is None:
        return None
    if not all(0.0 <= v <= 1.0 for v in values):
        raise props.value_error(props.entries[key], f"{key}: each colour channel must be "
                                                    "between 0 and 1")
    return (values[0], values[1], values[2])


def _view(props: Properties) -> tuple[View, bool]:
    """The view, and whether it is a perspective camera jsurf 0.4.1 draws off its axis."""
    scale = _floats(props, "scale_factor", 1)
    surface_m = _matrix(props, "surface_transform_matrix") @ np.diag(
        [10.0 ** (scale[0] if scale else 0.0)] * 3 + [1.0])
    linear = surface_m[:3, :3]
    k = abs(np.linalg.det(linear)) ** (1.0 / 3.0)
    if not np.allclose(linear, k * np.eye(3), rtol=1e-6, atol=1e-9 * k):
        entry = props.entries["surface_transform_matrix"]
        raise props.value_error(entry, "surface_transform_matrix: implc supports a uniform "
                                       "scale and a translation only (its clip is a sphere)")
    camera_m = _matrix(props, "transform_matrix") @ _matrix(props, "rotation_matrix") @ \
        np.linalg.inv(_matrix(props, "camera_transform"))
    to_surface = surface_m @ camera_m
    eye = to_surface[:3, 3]
    forward = to_surface[:3, :3] @ np.array([0.0, 0.0, -1.0])
    up = to_surface[:3, :3] @ np.array([0.0, 1.0, 0.0])
    center = surface_m[:3, 3]
    radius = float(k)
    fwd = forward / np.linalg.norm(forward)
    type_entry = props.entries.get("camera_type")
    camera_type = type_entry.value.strip() if type_entry else CAMERA_TYPES[0]
    if camera_type not in CAMERA_TYPES:
        close = difflib.get_close_matches(camera_type, CAMERA_TYPES, n=1, cutoff=0.5)
        hint = f"; did you mean '{close[0]}'?" if close else ""
        raise props.value_error(type_entry, f"camera_type must be ORTHOGRAPHIC_CAMERA or "
                                            f"PERSPECTIVE_CAMERA{hint}")
    off_axis = False
    if camera_type == "PERSPECTIVE_CAMERA":
        fov = _floats(props, "camera_fov_y", 1)
        fov_y = fov[0] if fov else 60.0
        window = _jsurf041_window(to_surface[:3, :3], fov_y)
        if window is None:
            off_axis = True  # draw the camera's own centred frustum (jsurf's intent)
        else:
            forward, up, fov_y = window
            fwd = forward / np.linalg.norm(forward)
        ahead = float(np.dot(center - eye, fwd))
        target = eye + fwd * ahead if ahead > 1e-9 * radius else eye + fwd * radius
    else:
        # the point of the camera's axis nearest the clip sphere's centre
        axis_point = eye + fwd * float(np.dot(center - eye, fwd))
        height = _floats(props, "camera_height", 1)
        half = (height[0] if height else 2.0) / 2.0 * float(np.linalg.norm(up))
        if not half > 0.0:
            raise props.value_error(props.entries["camera_height"],
                                    "camera_height must be positive")
        distance = ORTHO_DISTANCE * radius
        eye = axis_point - fwd * distance
        target = axis_point
        fov_y = math.degrees(2.0 * math.atan(half / distance))
    view = View(eye=_vec(eye), target=_vec(target), up=_vec(up / np.linalg.norm(up)),
                fov_y_deg=fov_y, clip_center=_vec(center), clip_radius=radius,
                front=_color(props, "front_material_color"),
                back=_color(props, "back_material_color"),
                given=frozenset(("radius", "center", "eye", "target", "up", "fov")))
    return view, off_axis


def _jsurf041_tan(fov_y: float) -> float:
    """tan(fov_y/2) as jsurf computes it (a float)."""
    return float(np.float32(math.tan(math.radians(fov_y) / 2.0)))


def _jsurf041_window(linear: np.ndarray, fov_y: float) -> tuple[np.ndarray, np.ndarray,
                                                                 float] | None:
    """The frustum jsurf 0.4.1 draws for a perspective camera (square picture, as jsurf
    and SURFER draw), as (forward, up, fov_y) in surface space, when it is a centred one;
    None when it is not (then jsurf draws beside what the camera looks at).

    jsurf's PerspectiveCameraRayCreator spans its picture from (t, t, -1) to (3t, 3t, -1)
    in camera space (t = tan(fov_y/2); its corner should be (-t, -t, -1)), so its
    picture is centred only when `camera_transform` shears that window back onto the
    axis, as `to_jsurf` writes it. `linear`: camera space to surface space.
    """
    t = _jsurf041_tan(fov_y)
    centre = linear @ np.array([2.0 * t, 2.0 * t, -1.0])
    across = linear @ np.array([2.0 * t, 0.0, 0.0])
    up = linear @ np.array([0.0, 2.0 * t, 0.0])
    width, height = float(np.linalg.norm(across)), float(np.linalg.norm(up))
    # the centre ray's offset from the window's middle, in half-windows (0 when
    # centred, 2 for an unsheared camera; SURFER's float rotations leave ~1e-5)
    offset = max(abs(2.0 * float(np.dot(centre, across))) / width ** 2,
                 abs(2.0 * float(np.dot(centre, up))) / height ** 2)
    square = abs(float(np.dot(across, up))) / (width * height) < 1e-3 and \
        abs(width / height - 1.0) < 1e-3
    if offset > 1e-2 or not square:
        return None
    drawn = math.degrees(2.0 * math.atan(height / 2.0 / float(np.linalg.norm(centre))))
    # camera_fov_y itself when the window is its own (float rotations aside)
    return centre, up, fov_y if abs(drawn / fov_y - 1.0) < 1e-4 else drawn


def _vec(v) -> tuple[float, float, float]:
    return (float(v[0]), float(v[1]), float(v[2]))


# --------------------------------------------------------------------------- writing

class _JsurfPrinter(EquationPrinter):
    """sympy -> jsurf's grammar: implc's equation text (its decimals and fractions) with
    explicit `*`, `^` with whole-number exponents on x, y, z, functions only of constants
    (the caller checks the surface is a polynomial)."""

    _FUNCTIONS = {"sin", "cos", "tan", "asin", "acos", "atan", "exp", "log", "Abs", "sign"}

    def _print_Function(self, expr):
        name = type(expr).__name__
        if name not in self._FUNCTIONS:
            raise InputError(f"jsurf has no '{name.lower()}': this surface cannot be "
                             "written as a .jsurf file")
        spelled = "abs" if name == "Abs" else name
        return f"{spelled}({self._print(expr.args[0])})"

    _print_Abs = _print_Function

    _print_Min = _print_Max = _print_Function  # not in jsurf's grammar: refused

    def _print_Pi(self, expr):
        return repr(math.pi)

    def _print_Exp1(self, expr):
        return "exp(1)"

    def _print_Pow(self, expr, rational=False):
        base, exponent = expr.args
        if exponent == sympy.Rational(1, 2):
            return f"sqrt({self._print(base)})"
        b = self.parenthesize(base, 60, strict=True)  # parenthesize anything but atoms
        if exponent.is_Integer and exponent < 0:
            return f"1/{b}^{-int(exponent)}" if exponent != -1 else f"1/{b}"
        e = self._print(exponent)
        if not (exponent.is_Integer or exponent.is_Symbol):
            e = f"({e})"
        return f"{b}^{e}"


def to_jsurf(surface: Surface) -> str:
    """`surface` as a .jsurf file jsurf (and SURFER) read: its equation, parameters, view
    and front/back colours, and jsurf's own lights and materials (deterministic text)."""
    expr = surface.symbolic_expr
    if not expr.is_polynomial(X, Y, Z):
        raise InputError(f"{surface.origin}: jsurf draws polynomial surfaces only; this one "
                         "is not a polynomial in x, y, z")
    equation = _JsurfPrinter({"order": "lex"}).doprint(expr)
    view = surface.view
    radius = view.clip_radius
    eye, target, up_hint = (np.asarray(v, dtype=np.float64) for v in
                            (view.eye, view.target, view.up))
    forward = (target - eye) / np.linalg.norm(target - eye)
    right = np.cross(forward, up_hint)
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    basis = np.column_stack([right, up, -forward])  # camera x, y, z in the world
    center = np.asarray(view.clip_center, dtype=np.float64)
    props: dict[str, str] = {}
    if float(np.linalg.norm(target - eye)) >= ORTHO_MIN_DISTANCE * radius:
        # a narrow view is the reader's orthographic camera: eye on the axis one clip
        # radius from the axis point nearest the centre, as SURFER writes it
        axis_point = eye + forward * float(np.dot(center - eye, forward))
        camera_eye = (axis_point - forward * radius - center) / radius
        half = math.tan(math.radians(view.fov_y_deg) / 2.0) * float(
            np.linalg.norm(target - eye))
        props["camera_type"] = "ORTHOGRAPHIC_CAMERA"
        props["camera_height"] = _num(2.0 * half / radius)
        props["camera_fov_y"] = "60.0"
    else:
        camera_eye = (eye - center) / radius
        props["camera_type"] = "PERSPECTIVE_CAMERA"
        props["camera_fov_y"] = _num(view.fov_y_deg)
        props["camera_height"] = "2.0"
    rotation = np.eye(4)
    rotation[:3, :3] = basis
    camera = np.eye(4)
    camera[:3, 3] = -(basis.T @ camera_eye)
    if props["camera_type"] == "PERSPECTIVE_CAMERA":
        # shear jsurf 0.4.1's off-axis window onto the axis (_jsurf041_window)
        t = _jsurf041_tan(float(props["camera_fov_y"]))
        shear = np.eye(4)
        shear[0, 2] = shear[1, 2] = -2.0 * t
        camera = shear @ camera
    translate = np.eye(4)
    translate[:3, 3] = center
    props["surface_equation"] = equation
    for name in surface.uniform_params():
        props[PARAMETER_PREFIX + name] = _num(float(surface.params[name]))
    props["rotation_matrix"] = _matrix_text(rotation)
    props["camera_transform"] = _matrix_text(camera)
    props["scale_factor"] = _num(math.log10(radius))
    if center.any():
        props["surface_transform_matrix"] = _matrix_text(translate)
    for side, colour in (("front", view.front or SHADING.front),
                         ("back", view.back or SHADING.back)):
        props[f"{side}_material_color"] = " ".join(_num(c) for c in colour)
        props[f"{side}_material_ambient_intensity"] = "0.4"
        props[f"{side}_material_diffuse_intensity"] = "0.8"
        props[f"{side}_material_specular_intensity"] = "0.5"
        props[f"{side}_material_shininess"] = "30.0"
    props["background_color"] = "1.0 1.0 1.0"
    for i, (status, position, intensity) in enumerate(_SURFER_LIGHTS):
        props[f"light_status_{i}"] = status
        props[f"light_position_{i}"] = position
        props[f"light_color_{i}"] = "1.0 1.0 1.0"
        props[f"light_intensity_{i}"] = intensity
    lines = ["#jSurfer surface description", f"#written by implc from {surface.name}"]
    lines += [f"{key}={_escape(value)}" for key, value in props.items()]
    return "\n".join(lines) + "\n"


# SURFER's default lights (status, position, intensity), as its gallery files have them
_SURFER_LIGHTS = (("ON", "-100.0 100.0 100.0", "0.5"), ("ON", "100.0 100.0 100.0", "0.7"),
                  ("ON", "0.0 -100.0 100.0", "0.3"),
                  *((("OFF", "0.0 0.0 0.0", "1.0"),) * 5))


def _num(value: float) -> str:
    """15 significant digits (what survives a round trip through the matrices), and a
    rounding residue below 1e-12 as 0."""
    value = float(f"{float(value):.15g}")
    return "0.0" if abs(value) < 1e-12 else repr(value)


def _matrix_text(m: np.ndarray) -> str:
    return " ".join(_num(v) for v in m.reshape(-1))


def _escape(value: str) -> str:
    """A property value as java.util.Properties stores it (non-ASCII as \\uXXXX)."""
    out = []
    for i, ch in enumerate(value):
        if ch == "\\":
            out.append("\\\\")
        elif ch == " " and i == 0:
            out.append("\\ ")
        elif ch in "#!=:" and i == 0:
            out.append("\\" + ch)
        elif not 0x20 <= ord(ch) < 0x7F:
            out.append(f"\\u{ord(ch):04x}")
        else:
            out.append(ch)
    return "".join(out)

