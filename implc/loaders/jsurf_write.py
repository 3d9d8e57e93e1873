"""A `Surface` written as a SURFER `.jsurf` file (`implc compile --emit jsurf`): its
equation in jsurf's grammar, its parameters, view and colours, and jsurf's own lights and
materials. The cameras are the reader's in reverse (implc/loaders/jsurf_read.py): a
narrow view becomes an orthographic camera, any other a perspective one in the sheared
form jsurf 0.4.1 draws centred.
"""

from __future__ import annotations

import math

import numpy as np
import sympy

from ..errors import InputError
from ..scene import SHADING
from ..surface import Surface
from ..symbols import X, Y, Z
from ..textform import EquationPrinter
from .jsurf_read import ORTHO_MIN_DISTANCE, PARAMETER_PREFIX, jsurf041_tan


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
        # shear jsurf 0.4.1's off-axis window onto the axis (jsurf_read._jsurf041_window)
        t = jsurf041_tan(float(props["camera_fov_y"]))
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
