"""The `Surface` record and where surfaces come from: TOML files, `-e`, bundled examples.

A surface file (see README "Surface files"):

    name = "Cross-Cap"
    equation = "4x^2(x^2 + y^2 + z^2 + z) + y^2(y^2 + z^2 - 1) = 0"
    [params]            # optional named constants
    a = 0.5
    [view]              # optional camera and clip sphere
    radius = 1.2        # clip sphere radius (centre: `center`, default the origin)
    eye = [3.0, 2.0, 4.0]
    target = [0.0, 0.0, 0.0]
    up = [0.0, 1.0, 0.0]
    fov = 30.0          # vertical, degrees

Errors point into the file: an equation inside a TOML string is located at its own
line and column, so a caret lands under the offending character of the file.
"""

from __future__ import annotations

import re
import sys
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import sympy

from .errors import InputError, Source
from .parse import Limits, check_param_name, parse_equation_with_params, parse_number
from .resources import data_dir
from .scene import View
from .textform import to_text

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib

MAX_FILE_BYTES = 1_000_000


@dataclass(frozen=True)
class Surface:
    name: str
    expr: sympy.Expr  # S(x, y, z); the surface is S = 0; parameters already substituted
    params: dict[str, sympy.Rational] = field(default_factory=dict)
    view: View = field(default_factory=View)
    origin: str = "<equation>"  # file path, example name or "<equation>"
    # S with the parameters as symbols (parse.param_symbol), for `--params uniform`;
    # None when the surface has no parameters (then it is `expr`)
    symbolic: sympy.Expr | None = None

    @property
    def equation(self) -> str:
        """The equation printed from the tree, in implc's own input language."""
        return to_text(self.expr)

    @property
    def symbolic_expr(self) -> sympy.Expr:
        return self.expr if self.symbolic is None else self.symbolic

    @property
    def symbolic_equation(self) -> str:
        """The equation with its parameters by name (what `--params uniform` compiles)."""
        return to_text(self.symbolic_expr)

    def uniform_params(self) -> list[str]:
        """The parameters that stay free with `--params uniform`, sorted by name: every
        parameter, less those that only appear in constant exponents (`x^n`)."""
        free = {s.name for s in self.symbolic_expr.free_symbols}
        return sorted(name for name in self.params if name in free)

    def params_json(self) -> dict[str, float]:
        return {k: float(v) for k, v in sorted(self.params.items())}


def example_paths() -> dict[str, Path]:
    """Bundled examples by name (file stem), e.g. `cross-cap`, `torus`."""
    root = data_dir("examples")
    return {p.stem: p for p in sorted(root.rglob("*.toml"))}


def load_surface(
    spec: str | None = None,
    equation: str | None = None,
    params: Sequence[str] = (),
    limits: Limits | None = None,
) -> Surface:
    """A surface from a TOML path, a bundled example name, or `-e` equation text.

    `params` are `name=value` overrides (from `--param`), applied over the file's [params].
    """
    if (spec is None) == (equation is None):
        raise InputError("give either a surface (file or example name) or -e EQUATION")
    limits = limits or Limits()
    overrides = _parse_param_args(params)
    if equation is not None:
        source = Source("<equation>", equation)
        values = dict(overrides)
        expr, symbolic = _parse(source, values, limits)
        return Surface("equation", expr, values, View(), symbolic=symbolic)
    path = Path(spec)
    if not path.suffix and not path.exists():
        examples = example_paths()
        if spec not in examples:
            raise InputError(
                f"no file or bundled example named '{spec}' (see `implc list`)"
            )
        path = examples[spec]
        return _load_toml(path, overrides, limits, origin=spec)
    return _load_toml(path, overrides, limits, origin=str(path))


def _parse_param_args(params: Sequence[str]) -> dict[str, sympy.Rational]:
    values: dict[str, sympy.Rational] = {}
    for arg in params:
        source = Source("--param", arg)
        name, sep, value = arg.partition("=")
        if not sep:
            raise InputError("expected NAME=VALUE", source, 0, len(arg))
        name = name.strip()
        check_param_name(name, Source("--param", arg))
        text = value.strip()
        values[name] = parse_number(text, Source("--param", text, 1, len(arg) - len(value) + 1 +
                                                 (len(value) - len(value.lstrip()))))
    return values


def _load_toml(
    path: Path, overrides: Mapping[str, sympy.Rational], limits: Limits, origin: str
) -> Surface:
    name = str(path)
    try:
        raw = path.read_bytes()
    except OSError as err:
        raise InputError(f"cannot read {name}: {err.strerror or err}") from None
    if len(raw) > MAX_FILE_BYTES:
        raise InputError(f"{name}: file is larger than {MAX_FILE_BYTES} bytes")
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as err:
        raise InputError(f"{name}: not UTF-8 text (byte {err.start})") from None
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as err:
        raise _toml_error(name, text, err) from None

    equation = data.get("equation")
    if not isinstance(equation, str):
        raise InputError(f"{name}: needs `equation = \"...\"` (a string)")
    values: dict[str, sympy.Rational] = {}
    table = data.get("params", {})
    if not isinstance(table, dict):
        raise InputError(f"{name}: [params] must be a table of numbers")
    for key, value in sorted(table.items()):
        src = Source(name, key, *_key_position(text, key))
        check_param_name(key, src)
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise InputError(f"parameter '{key}' must be a number", src, 0, len(key))
        values[key] = parse_number(repr(value), src)
    values.update(overrides)
    source = Source(name, equation, *_string_position(text, "equation", equation))
    expr, symbolic = _parse(source, values, limits)
    title = data.get("name", path.stem)
    if not isinstance(title, str):
        raise InputError(f"{name}: `name` must be a string")
    return Surface(title, expr, values, _view(name, data.get("view", {})), origin, symbolic)


def _parse(source: Source, values: Mapping[str, sympy.Rational], limits: Limits):
    """(expr with the values substituted, expr with parameter symbols or None)."""
    expr, symbolic = parse_equation_with_params(source, values, limits)
    return expr, (symbolic if values else None)


def _view(name: str, table) -> View:
    if not isinstance(table, dict):
        raise InputError(f"{name}: [view] must be a table")
    known = {"radius", "center", "eye", "target", "up", "fov"}
    unknown = sorted(set(table) - known)
    if unknown:
        choices = ", ".join(sorted(known))
        raise InputError(f"{name}: unknown [view] key '{unknown[0]}' (known: {choices})")
    default = View()

    def number(key: str, fallback: float, low: float, high: float) -> float:
        value = table.get(key, fallback)
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise InputError(f"{name}: [view] {key} must be a number")
        if not low < float(value) < high:
            raise InputError(f"{name}: [view] {key} must be between {low} and {high}")
        return float(value)

    def vector(key: str, fallback) -> tuple[float, float, float]:
        value = table.get(key, fallback)
        if (not isinstance(value, (list, tuple)) or len(value) != 3
                or any(isinstance(v, bool) or not isinstance(v, (int, float)) for v in value)):
            raise InputError(f"{name}: [view] {key} must be 3 numbers, like [0.0, 0.0, 0.0]")
        if any(abs(float(v)) > 1e6 for v in value):
            raise InputError(f"{name}: [view] {key} is too far from the origin")
        return (float(value[0]), float(value[1]), float(value[2]))

    view = View(
        eye=vector("eye", default.eye),
        target=vector("target", default.target),
        up=vector("up", default.up),
        fov_y_deg=number("fov", default.fov_y_deg, 0.0, 180.0),
        clip_center=vector("center", default.clip_center),
        clip_radius=number("radius", default.clip_radius, 0.0, 1e6),
    )
    if view.eye == view.target:
        raise InputError(f"{name}: [view] eye and target must differ")
    return view


def _toml_error(name: str, text: str, err: Exception) -> InputError:
    message = str(err)
    match = re.search(r"\(at line (\d+), column (\d+)\)", message)
    short = re.sub(r"\s*\(at .*\)$", "", message).strip()
    short = short[:1].lower() + short[1:]
    if not match:
        return InputError(f"{name}: invalid TOML: {short}")
    line, col = int(match.group(1)), int(match.group(2))
    lines = text.splitlines() or [""]
    line_text = lines[min(line, len(lines)) - 1]
    return InputError(f"invalid TOML: {short}", Source(name, line_text, line, 1), col - 1)


def _key_position(text: str, key: str) -> tuple[int, int]:
    for number, line in enumerate(text.splitlines(), 1):
        match = re.match(rf"\s*{re.escape(key)}\s*=", line)
        if match:
            return number, line.index(key) + 1
    return 1, 1


def _string_position(text: str, key: str, value: str) -> tuple[int, int]:
    """(line, col) of the first character of `key = "value"`'s string in the file.

    Exact for one-line basic or literal strings without escapes; otherwise the position
    of the key, so the line number is still right.
    """
    for number, line in enumerate(text.splitlines(), 1):
        match = re.match(rf"\s*{re.escape(key)}\s*=\s*(\"|')", line)
        if match:
            start = match.end()
            if line[start : start + len(value)] == value:
                return number, start + 1
            return number, 1
    return 1, 1
