"""implc: compile implicit-surface equations into robust GPU ray-marching shaders.

    >>> import implc
    >>> s = implc.Surface("4x^2(x^2+y^2+z^2+z) + y^2(y^2+z^2-1) = 0")
    >>> shader = s.compile("wgsl", emit="library", prefix="cc_")
    >>> shader.method, shader.target
    ('exact', 'wgsl')

The public names load on first use, so `import implc` costs no sympy, numpy or GPU
stack (docs/api.md documents them).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from .version import __version__

if TYPE_CHECKING:
    from .api import (
        ImplcError,
        InputError,
        LimitError,
        Limits,
        OptionError,
        Rendering,
        Shader,
        Surface,
        ToolError,
        ValidationError,
        benchmark,
        check_corpus,
        examples,
        gallery,
    )

__all__ = [
    "ImplcError", "InputError", "LimitError", "Limits", "OptionError", "Rendering", "Shader",
    "Surface", "ToolError", "ValidationError", "__version__", "benchmark", "check_corpus",
    "examples", "gallery",
]


def __getattr__(name: str) -> Any:
    """The public API, imported when first asked for (PEP 562)."""
    if name in __all__:
        from . import api

        value = getattr(api, name)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'implc' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(__all__)
