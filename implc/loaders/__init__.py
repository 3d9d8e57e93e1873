"""Where surfaces come from: `load_surface` reads a TOML file, a SURFER `.jsurf` file, a
bundled example or `-e` equation text into a `Surface`, choosing the reader by suffix.

The readers live beside this module (`toml_file`, `jsurf_read`; `jsurf_write` writes a
`.jsurf` file) and share `common`; none of them imports this module, and `Surface`
(implc/surface.py) imports none of them, so there is no import circle.
"""

from __future__ import annotations

import difflib
from collections.abc import Mapping, Sequence
from pathlib import Path

from ..errors import InputError, Source
from ..limits import Limits
from ..scene import View
from ..surface import Surface, example_paths
from .common import check_params_used, parse_param_args, parse_with_params
from .toml_file import load_toml

__all__ = ["load_surface", "to_jsurf"]


def load_surface(
    spec: str | None = None,
    equation: str | None = None,
    params: Sequence[str] = (),
    limits: Limits | None = None,
) -> Surface:
    """A surface from a TOML path, a `.jsurf` path, a bundled example name, or `-e`
    equation text.

    `params` are `name=value` overrides (from `--param`), applied over the file's [params].
    """
    if (spec is None) == (equation is None):
        raise InputError("give either a surface (file or example name) or -e EQUATION")
    limits = limits or Limits()
    overrides = parse_param_args(params, limits)
    if equation is not None:
        source = Source("<equation>", equation)
        values = dict(overrides)
        expr, symbolic = parse_with_params(source, values, limits)
        check_params_used(equation, overrides, params)
        return Surface("equation", expr, values, View(), symbolic=symbolic, limits=limits)
    path = Path(spec)
    if path.suffix.lower() == ".jsurf":  # SURFER's files
        from .jsurf_read import load_jsurf  # numpy: loaded only for a .jsurf file

        return load_jsurf(path, overrides, limits, params)
    if not path.suffix and not path.exists():
        examples = example_paths()
        if spec not in examples:
            raise InputError(f"no file or bundled example named '{spec}'"
                             f"{_example_hint(spec, examples)} (see `implc list`)")
        path = examples[spec]
        return load_toml(path, overrides, limits, origin=spec, params_args=params)
    return load_toml(path, overrides, limits, origin=str(path), params_args=params)


def to_jsurf(surface: Surface) -> str:
    """`surface` as a SURFER `.jsurf` file's text (`jsurf_write.to_jsurf`); the writer and
    numpy are imported on the first call, as the reader is."""
    from .jsurf_write import to_jsurf as write

    return write(surface)


def _example_hint(spec: str, examples: Mapping[str, Path]) -> str:
    """"; did you mean 'torus'?" for `Torus`, `tourus`; both Barths for `barth`."""
    by_lower = {name.lower(): name for name in examples}
    word = spec.lower()
    close = [by_lower[word]] if word in by_lower else sorted(
        {*(name for low, name in by_lower.items() if low.startswith(word) or
           low.replace("-", "") == word.replace("-", "")),
         *(by_lower[m] for m in difflib.get_close_matches(word, by_lower, n=3, cutoff=0.75))})
    if not close:
        return ""
    quoted = [f"'{name}'" for name in close[:3]]
    listed = quoted[0] if len(quoted) == 1 else ", ".join(quoted[:-1]) + " or " + quoted[-1]
    return f"; did you mean {listed}?"
