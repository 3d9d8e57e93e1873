"""Camera, clip sphere and shading shared by every runner, the CPU reference included.

This module is the single definition of a pixel's ray and of its colour. The shader
templates receive these same constants as printed literals, and the CPU reference uses
the numpy functions below, so a GPU image and the reference are directly comparable.

Pixel (i, j), column i from the left and row j from the top, is the ray from `eye`
through the image-plane point at distance 1 along the view direction:
    ndc_x = 2 (i + 0.5) / W - 1,   ndc_y = 1 - 2 (j + 0.5) / H,   m = min(W, H)
    dir   = normalize(forward + ndc_x * tan(fov/2) * (W/m) * right
                              + ndc_y * tan(fov/2) * (H/m) * up)
with forward = normalize(target - eye), right = normalize(forward x up_hint),
up = right x forward. `fov_y_deg` spans the SHORTER side (vertical unless portrait), so
what a square picture holds, every picture holds (issue 44: portraits lost the sides).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING

if TYPE_CHECKING:  # numpy loads with the CPU reference and framing, never to compile
    import numpy as np

Vec3 = tuple[float, float, float]


@dataclass(frozen=True)
class View:
    """Where the camera is and which part of space holds the surface."""

    eye: Vec3 = (3.0, 2.0, 4.0)
    target: Vec3 = (0.0, 0.0, 0.0)
    up: Vec3 = (0.0, 1.0, 0.0)
    fov_y_deg: float = 30.0  # across the shorter side of the picture (see above)
    clip_center: Vec3 = (0.0, 0.0, 0.0)
    clip_radius: float = 1.5
    # front and back colours (RGB in [0, 1]); None: SHADING's (a .jsurf file sets them)
    front: Vec3 | None = None
    back: Vec3 | None = None
    # the [view] keys its surface file sets (empty for `-e`): what `apply_view` may
    # choose instead (not part of the view's value)
    given: frozenset[str] = field(default=frozenset(), compare=False, repr=False)

    def camera_json(self, width: int, height: int) -> dict:
        return {
            "eye": list(self.eye),
            "target": list(self.target),
            "up": list(self.up),
            "fov_y_deg": self.fov_y_deg,
            "width": width,
            "height": height,
        }

    def clip_json(self) -> dict:
        return {"center": list(self.clip_center), "radius": self.clip_radius}


@dataclass(frozen=True)
class Light:
    """A directional light fixed to the camera of the surface's [view].

    `direction` points towards the light in camera space: x = right, y = up, z = back
    towards the viewer; `light_directions(view)` turns it into world space, once, so
    shaders receive constant world-space vectors (moving the camera at run time through
    the program's uniforms keeps the lights where the [view] put them).
    """

    direction: Vec3
    color: Vec3


@dataclass(frozen=True)
class Shading:
    """Two-sided Blinn-Phong; the side is chosen by the sign of grad(S) . D."""

    front: Vec3 = (0.90, 0.62, 0.25)
    back: Vec3 = (0.30, 0.55, 0.90)
    background: Vec3 = (0.08, 0.08, 0.10)
    ambient: float = 0.18
    specular: float = 0.35
    shininess: float = 48.0
    lights: tuple[Light, ...] = field(
        default=(
            Light((-0.45, 0.65, 0.60), (0.85, 0.85, 0.85)),  # key: upper left, in front
            Light((0.70, -0.25, 0.45), (0.35, 0.35, 0.40)),  # fill: lower right
        )
    )


SHADING = Shading()


def shading_for(view: View) -> Shading:
    """SHADING with the view's own front and back colours, where it has them."""
    if view.front is None and view.back is None:
        return SHADING
    return replace(SHADING, front=view.front or SHADING.front, back=view.back or SHADING.back)


# --------------------------------------------------------------------------- framing
#
# The command line's view options (`--radius --center --eye --look-at --up --fov`, the
# [view] keys; --look-at is `target`) override the file's values one by one. What neither sets is
# chosen (docs/guide/command-line.md "Framing"):
# - no `radius`: the clip sphere is the surface's, found by sampling S
#   (implc/extent.py), centred on it (or on `center`); when no surface is found the
#   default view is kept and the caller says so;
# - no `target`: the clip sphere's centre;
# - no `eye`: the eye looks at the target from FRAME_DIRECTION, turned so that +y goes
#   to `up`, at the distance where the clip sphere fills FRAME_FILL of the picture's
#   shorter side, wherever the radius came from (a file's `radius` without `eye` kept the
#   default eye (3, 2, 4) once: a close-up cut by the frame, issue 44).

FRAME_DIRECTION = (3.0, 2.0, 4.0)  # the default eye's direction, for up = +y
FRAME_FILL = 0.9


@dataclass(frozen=True)
class Extent:
    """Where a surface was found (implc/extent.py): a clip sphere that holds it, or for
    an unbounded surface the part near `center`."""

    center: Vec3
    radius: float
    bounded: bool
    period: float = 0.0  # an unbounded periodic surface's longest wavelength (its radius)


@dataclass(frozen=True)
class Framing:
    """What `apply_view` chose, for the one line the command line prints."""

    view: View
    framed_sphere: bool  # the clip sphere was searched for (no radius given)
    extent: Extent | None  # what the search found (None: nothing; see framed_sphere)
    placed_eye: bool
    searched: float  # the half-size of the largest cube searched

    def message(self) -> str:
        view = self.view
        if self.framed_sphere and self.extent is None:
            where = (f"|x|,|y|,|z| <= {self.searched:g}" if not any(view.clip_center) else
                     f"the cube of half-size {self.searched:g} around "
                     f"{point_text(view.clip_center)}")
            return (f"no surface found in {where} (S changes sign "
                    "nowhere on the search grids); keeping the default view (radius "
                    f"{view.clip_radius:g}; --radius, --center to set)")
        parts, options = [], []
        if self.framed_sphere:
            parts.append(f"center {point_text(view.clip_center)}, radius {view.clip_radius:g}")
            options += ["--radius", "--center"]
        if self.placed_eye:
            parts.append(f"eye {point_text(view.eye)}")
            options.append("--eye")
        text = f"framed: {', '.join(parts)} (auto; {', '.join(options)} to set)"
        if self.extent is not None and not self.extent.bounded:
            text += ("; the surface seems unbounded (it reaches the edge of every region "
                     "the search sampled): this is the part near the centre")
            if self.extent.period:
                text += f", a period ({self.extent.period:g}) each way"
        return text


@dataclass(frozen=True)
class ViewOptions:
    """The command line's view options; None: not given."""

    radius: float | None = None
    center: Vec3 | None = None
    eye: Vec3 | None = None
    target: Vec3 | None = None
    up: Vec3 | None = None
    fov: float | None = None

    def given(self) -> set[str]:
        return {key for key in VIEW_OPTION_KEYS if getattr(self, key) is not None}


VIEW_OPTION_KEYS = ("radius", "center", "eye", "target", "up", "fov")  # the [view] keys


def apply_view(
    view: View, options: ViewOptions, locate: Callable[[Vec3 | None], Extent | None],
    searched: float = 0.0,
) -> tuple[View, Framing | None]:
    """`view` with the command line's `options` and what neither sets chosen by the rule
    above; `locate(center or None)` finds the surface, called only when the clip sphere
    is chosen (`searched`: how far it looks, for the message). The Framing is None when
    nothing was chosen."""
    given = set(view.given) | options.given()

    def pick(option, value):
        return value if option is None else option

    center = pick(options.center, view.clip_center)
    radius = pick(options.radius, view.clip_radius)
    up = pick(options.up, view.up)
    fov = pick(options.fov, view.fov_y_deg)
    framed_sphere = "radius" not in given
    placed_eye = "eye" not in given
    extent = None
    if framed_sphere:
        extent = locate(center if "center" in given else None)
        if extent is None:
            placed_eye = False  # the default view, as it was
        else:
            center, radius = extent.center, extent.radius
    target = pick(options.target, view.target if "target" in given else center)
    eye = pick(options.eye, view.eye)
    if placed_eye:
        import numpy as np

        aim = np.asarray(target, dtype=np.float64)
        off_centre = float(np.linalg.norm(np.asarray(center) - aim))
        point = aim + (off_centre + fit_distance(radius, fov)) * frame_direction(up)
        eye = (float(point[0]), float(point[1]), float(point[2]))
    result = View(eye=eye, target=target, up=up, fov_y_deg=fov, clip_center=center,
                  clip_radius=radius, front=view.front, back=view.back, given=view.given)
    if not framed_sphere and not placed_eye:
        return result, None
    return result, Framing(result, framed_sphere, extent, placed_eye, searched)


def frame_direction(up: Vec3) -> np.ndarray:
    """FRAME_DIRECTION (unit) turned by the rotation that takes +y to `up`: the same
    three-quarter view, whichever way is up ((3, -4, 2) for up = +z)."""
    import numpy as np

    a = np.array([0.0, 1.0, 0.0])
    b = np.asarray(up, dtype=np.float64) / np.linalg.norm(up)
    d = np.asarray(FRAME_DIRECTION) / np.linalg.norm(FRAME_DIRECTION)
    c = float(a @ b)
    if c < -1.0 + 1e-12:  # up = -y: half a turn about x
        return d * np.array([1.0, -1.0, -1.0])
    v = np.cross(a, b)
    k = np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])
    rotation = np.eye(3) + k + k @ k / (1.0 + c)
    return rotation @ d


def fit_distance(radius: float, fov_y_deg: float) -> float:
    """How far from its centre a sphere of `radius` fills FRAME_FILL of the shorter side
    of a picture with this field of view (which spans that side: any aspect ratio)."""
    half = math.radians(fov_y_deg) / 2.0
    return radius / math.sin(math.atan(FRAME_FILL * math.tan(half)))


def frame_spans(width: float, height: float) -> tuple[float, float]:
    """(horizontal, vertical) half extents of a `width` x `height` picture on the image
    plane, in units of tan(fov/2): the shorter side spans 1 (W/H and 1 when landscape)."""
    short = min(width, height)
    return width / short, height / short


def point_text(v) -> str:
    return "(" + ", ".join(f"{float(x):.3g}" for x in v) + ")"


# --------------------------------------------------------------------------- view checks
#
# A view that cannot show anything is refused with a reason and a fix rather than
# rendered as a blank picture: the camera needs a direction (eye != target), an up hint
# that is not parallel to it (right = forward x up would be zero: every ray is NaN), a
# field of view inside (0, 180) degrees, a clip sphere of positive radius, and the clip
# sphere must be inside the view at least partly. `view_problems` checks what needs no
# image size: the plane of the eye, the top and bottom of a square picture (a portrait
# one sees more there, but such a [view] is refused when read); `frame_problem` adds the
# sides of a W x H frame, which widen with W/H.
# The sphere tests are plane tests (conservative: a sphere that grazes a frustum corner
# passes), so only a view that certainly shows nothing is refused.

PARALLEL_SINE = 1e-6  # |forward x up| / |up| below this: the up hint is parallel


def view_problems(view: View) -> list[tuple[str, str]]:
    """(key of [view], message with the fix) for each problem of `view`; empty when fine."""
    problems: list[tuple[str, str]] = []
    values = [*view.eye, *view.target, *view.up, *view.clip_center, view.fov_y_deg,
              view.clip_radius]
    if not all(math.isfinite(float(v)) for v in values):
        return [("view", "every [view] value must be a finite number (no nan or inf)")]
    if not 0.0 < view.fov_y_deg < 180.0:
        problems.append(("fov", f"fov = {view.fov_y_deg:g} is outside (0, 180) degrees; "
                                "a field of view like fov = 30 shows the picture"))
    if not view.clip_radius > 0.0:
        problems.append(("radius", f"radius = {view.clip_radius:g}: the clip sphere needs a "
                                   "positive radius, e.g. radius = 1.5"))
    eye, target, up = (_floats(v) for v in (view.eye, view.target, view.up))
    distance = _length(_sub(target, eye))
    if distance <= 1e-9 * max(1.0, *(abs(c) for c in eye)):
        problems.append(("target", f"eye and target are the same point {_vec(view.eye)}: the "
                                   "camera has no direction; move `target` to what it "
                                   "should look at (e.g. the clip sphere's centre)"))
        return problems
    forward = _over(_sub(target, eye), distance)
    up_length = _length(up)
    if up_length == 0.0:
        problems.append(("up", f"up = {_vec(view.up)} has no direction; use "
                               f"up = {_vec(suggest_up(forward))}"))
    elif _length(_cross(forward, _over(up, up_length))) < PARALLEL_SINE:
        problems.append(("up", f"up = {_vec(view.up)} is parallel to the view direction "
                               f"(eye {_vec(view.eye)} to target {_vec(view.target)}), so "
                               "the picture has no 'up'; choose an up perpendicular to "
                               f"it, e.g. up = {_vec(suggest_up(forward))}"))
    if problems:
        return problems
    outside = _sphere_outside(view, None)
    if outside:
        problems.append(("target", outside))
    return problems


def frame_problem(view: View, width: int, height: int) -> str | None:
    """Why a `width` x `height` frame of `view` would be blank for certain, or None."""
    problems = view_problems(view)
    if problems:
        return problems[0][1]
    return _sphere_outside(view, width / height)


def suggest_up(forward: Sequence[float]) -> Vec3:
    """The world axis least aligned with `forward` (positive direction): a usable up hint."""
    axis = min(range(3), key=lambda i: abs(forward[i]))  # the first, as numpy's argmin
    return tuple(1.0 if i == axis else 0.0 for i in range(3))  # type: ignore[return-value]


def _sphere_outside(view: View, aspect: float | None) -> str | None:
    """Where the clip sphere lies wholly outside the view (behind the eye, beyond one
    side of the frustum), as a message with a fix; None when part of it may be seen.

    aspect (width / height) None: behind, and above or below a square picture."""
    forward, right, up = camera_axes(view)
    offset = _sub(_floats(view.clip_center), _floats(view.eye))
    radius = view.clip_radius

    def tilt(angle: float, side: Vec3, sign: float) -> Vec3:
        """-sin(angle) forward +- cos(angle) side: the outward normal of a frustum plane."""
        return _add(_scale(-math.sin(angle), forward), _scale(sign * math.cos(angle), side))

    tan_half = math.tan(math.radians(view.fov_y_deg) / 2.0)
    span_x, span_y = frame_spans(1.0 if aspect is None else aspect, 1.0)
    half_v = math.atan(tan_half * span_y)
    planes = [("behind the camera", _scale(-1.0, forward)),
              ("above the picture", tilt(half_v, up, 1.0)),
              ("below the picture", tilt(half_v, up, -1.0))]
    if aspect is not None:
        half_h = math.atan(tan_half * span_x)
        planes += [("right of the picture", tilt(half_h, right, 1.0)),
                   ("left of the picture", tilt(half_h, right, -1.0))]
    for where, normal in planes:
        if _dot(normal, offset) > radius:
            return (f"the clip sphere (centre {_vec(view.clip_center)}, radius {radius:g}) is "
                    f"entirely {where}: the render would be blank; point `target` at it "
                    f"(e.g. target = {_vec(view.clip_center)}), move `eye`, or widen `fov`")
    return None


def _vec(v) -> str:
    return "[" + ", ".join(f"{float(x):g}" for x in v) + "]"


# 3-vector arithmetic in plain Python for what compiling reads (the camera, the lights, the
# view checks): the compile path imports no numpy (issue 43: Pyodide). Each operation
# rounds as numpy's elementwise one does, and `_length` sums x^2 + y^2 + z^2 left to right
# as numpy's `norm(v, axis=-1)` (`normalize`) does, so the shaders' literals are the bits
# the numpy version printed.

def _floats(v: Sequence[float]) -> Vec3:
    return (float(v[0]), float(v[1]), float(v[2]))


def _add(a: Vec3, b: Vec3) -> Vec3:
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


def _sub(a: Vec3, b: Vec3) -> Vec3:
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def _scale(k: float, a: Vec3) -> Vec3:
    return (k * a[0], k * a[1], k * a[2])


def _dot(a: Vec3, b: Vec3) -> float:
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def _length(a: Vec3) -> float:
    return math.sqrt(_dot(a, a))


def _cross(a: Vec3, b: Vec3) -> Vec3:
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def _over(a: Vec3, k: float) -> Vec3:
    return (a[0] / k, a[1] / k, a[2] / k)


def _unit(a: Vec3) -> Vec3:
    """a / |a|, and a zero vector unchanged (as `normalize`)."""
    n = _length(a)
    return _over(a, 1.0 if n == 0.0 else n)


def normalize(v: np.ndarray) -> np.ndarray:
    import numpy as np

    n = np.linalg.norm(v, axis=-1, keepdims=True)
    return v / np.where(n == 0.0, 1.0, n)


def camera_axes(view: View) -> tuple[Vec3, Vec3, Vec3]:
    """(forward, right, up) unit vectors of the camera, as plain floats."""
    forward = _unit(_sub(_floats(view.target), _floats(view.eye)))
    right = _unit(_cross(forward, _floats(view.up)))
    return forward, right, _cross(right, forward)


def camera_basis(view: View) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(forward, right, up) unit vectors of the camera, as numpy arrays (the reference)."""
    import numpy as np

    forward, right, up = camera_axes(view)
    return np.array(forward), np.array(right), np.array(up)


def light_directions(view: View, shading: Shading = SHADING) -> list[Vec3]:
    """World-space unit vectors towards each light of `shading` for this camera."""
    forward, right, up = camera_axes(view)
    result = []
    for light in shading.lights:
        x, y, z = (float(c) for c in light.direction)
        result.append(_unit(_sub(_add(_scale(x, right), _scale(y, up)), _scale(z, forward))))
    return result


def pixel_rays(view: View, width: int, height: int) -> tuple[np.ndarray, np.ndarray]:
    """Ray origins and unit directions, arrays of shape (height, width, 3), row 0 on top."""
    import numpy as np

    forward, right, up = camera_basis(view)
    tan_half = math.tan(math.radians(view.fov_y_deg) / 2.0)
    span_x, span_y = frame_spans(width, height)
    i = np.arange(width, dtype=np.float64)
    j = np.arange(height, dtype=np.float64)
    ndc_x = 2.0 * (i + 0.5) / width - 1.0
    ndc_y = 1.0 - 2.0 * (j + 0.5) / height
    sx = (ndc_x * tan_half * span_x)[None, :, None]
    sy = (ndc_y * tan_half * span_y)[:, None, None]
    dirs = normalize(forward[None, None, :] + sx * right[None, None, :] + sy * up[None, None, :])
    origins = np.broadcast_to(np.asarray(view.eye, dtype=np.float64), dirs.shape).copy()
    return origins, dirs


def clip_sphere(
    origins: np.ndarray, dirs: np.ndarray, center: Vec3, radius: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """[t_near, t_far] of each ray inside the sphere, and whether it meets it at all.

    t_near is clamped to 0 when the eye is inside the sphere.
    """
    import numpy as np

    oc = origins - np.asarray(center, dtype=np.float64)
    b = np.sum(oc * dirs, axis=-1)
    c = np.sum(oc * oc, axis=-1) - radius * radius
    disc = b * b - c
    hit = disc > 0.0
    root = np.sqrt(np.where(hit, disc, 0.0))
    t_near = np.maximum(-b - root, 0.0)
    t_far = -b + root
    hit &= t_far > t_near
    return t_near, t_far, hit


def shade(
    grad: np.ndarray, dirs: np.ndarray, hit: np.ndarray, view: View,
    shading: Shading = SHADING,
) -> np.ndarray:
    """Colour (H, W, 3) in [0, 1] from the surface gradient at each hit point."""
    import numpy as np

    n = normalize(grad)
    facing = np.sum(n * dirs, axis=-1, keepdims=True)
    base = np.where(facing < 0.0, np.asarray(shading.front), np.asarray(shading.back))
    n = np.where(facing < 0.0, n, -n)  # two-sided: the normal faces the viewer
    color = shading.ambient * base
    for light, ldir in zip(shading.lights, light_directions(view, shading), strict=True):
        ldir = np.asarray(ldir)
        diffuse = np.maximum(np.sum(n * ldir, axis=-1, keepdims=True), 0.0)
        half = normalize(ldir - dirs)
        spec = np.maximum(np.sum(n * half, axis=-1, keepdims=True), 0.0) ** shading.shininess
        color = color + np.asarray(light.color) * (diffuse * base + shading.specular * spec)
    color = np.clip(color, 0.0, 1.0)
    return np.where(hit[..., None], color, np.asarray(shading.background))
