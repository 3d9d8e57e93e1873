"""SURFER's `.jsurf` files read into a `Surface`: the equation, its parameters, the view
and the front/back colours (the file's syntax: `jsurf_properties`; its equation's grammar:
`jsurf_grammar`; writing one: `jsurf_write`).

The view (docs/guide/surfer-and-gallery.md "SURFER files"): jsurf maps camera space to its clipping
space by
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
from pathlib import Path

import numpy as np
import sympy

from ..errors import InputError, Source
from ..fileio import read_input
from ..front import check_param_name, parse_number
from ..limits import Limits
from ..scene import View, view_problems
from ..surface import Surface
from .common import MAX_FILE_BYTES, parse_with_params
from .jsurf_grammar import JsurfGrammar
from .jsurf_properties import MalformedEscape, Properties

# an orthographic camera's eye, in clip radii from the target (at 1000 float32 shaders
# speckle: the eye is too far for the entry point's precision)
ORTHO_DISTANCE = 100.0
# the writer's orthographic cameras: an eye this many clip radii or more from the target
ORTHO_MIN_DISTANCE = ORTHO_DISTANCE / 2.0

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
    except MalformedEscape as err:
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
    used = JsurfGrammar(source).check()
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
    expr, symbolic = parse_with_params(source, values, limits)
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
                  "jsurf's code means it (the docs' \"SURFER files\")",)
    return Surface(path.stem, expr, values, view, str(path), symbolic, notes, limits)


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


def jsurf041_tan(fov_y: float) -> float:
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
    t = jsurf041_tan(fov_y)
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
