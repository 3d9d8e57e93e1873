"""The public API (re-exported by `implc`): surfaces, their shaders and renderings, the
batch runs, and the errors they raise."""

from ..errors import (
    ImplcError,
    InputError,
    LimitError,
    OptionError,
    ToolError,
    ValidationError,
)
from ..limits import Limits
from .batch import benchmark, check_corpus, gallery
from .records import Rendering, Shader
from .surface import Surface


def examples() -> list[str]:
    """The names of the bundled example surfaces (`Surface.example(name)`)."""
    from ..surface import example_paths

    return list(example_paths())


__all__ = [
    "ImplcError", "InputError", "LimitError", "Limits", "OptionError", "Rendering", "Shader",
    "Surface", "ToolError", "ValidationError", "benchmark", "check_corpus", "examples",
    "gallery",
]
