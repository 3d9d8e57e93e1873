"""Run the real compiler of each shader language and return its verdict.

GLSL: glslangValidator (Khronos reference front end). A shadertoy or library emit has no
`#version`/`main`, so it is wrapped in templates/glsl/harness.glsl.j2 first and the
tool's line numbers are mapped back into the user's file.
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import tempfile
from dataclasses import dataclass
from pathlib import Path

from .errors import ToolError

GLSL_STAGES = {".frag": "frag", ".vert": "vert", ".comp": "comp", ".glsl": "frag"}


@dataclass(frozen=True)
class Verdict:
    ok: bool
    tool: str
    messages: str  # the tool's own output, with file names and lines pointing at `name`

    def render(self, name: str) -> str:
        status = "ok" if self.ok else "FAILED"
        text = f"{name}: {status} ({self.tool})"
        return text + ("\n" + self.messages if self.messages and not self.ok else "")


def find_tool(name: str) -> str:
    path = shutil.which(name)
    if path is None:
        raise ToolError(f"{name} not found on PATH (run `make setup`, or install it)")
    return path


def glsl_kind(text: str) -> str:
    """'program' (has #version), 'shadertoy' (has mainImage) or 'library'."""
    if re.search(r"^\s*#version\b", text, re.M):
        return "program"
    if re.search(r"\bvoid\s+mainImage\s*\(", text):
        return "shadertoy"
    return "library"


def validate_glsl(text: str, name: str = "shader.frag", stage: str | None = None) -> Verdict:
    """Validate GLSL with glslangValidator; `name` is used in the reported messages."""
    from .emit import render_template  # late: emit imports the whole pipeline

    tool = find_tool("glslangValidator")
    kind = glsl_kind(text)
    stage = stage or GLSL_STAGES.get(Path(name).suffix, "frag")
    prelude = 0
    source = text
    if kind != "program":
        prefix = _library_prefix(text) if kind == "library" else ""
        source = render_template("glsl/harness.glsl.j2", kind=kind, body=text, prefix=prefix)
        prelude = source[: source.index(text)].count("\n")
    with tempfile.TemporaryDirectory(prefix="implc-") as tmp:
        path = os.path.join(tmp, f"shader.{stage}")
        Path(path).write_text(source, encoding="utf-8")
        try:
            proc = subprocess.run([tool, path], capture_output=True, text=True, timeout=120)
        except subprocess.TimeoutExpired:
            raise ToolError("glslangValidator did not finish within 120 s") from None
    output = (proc.stdout + proc.stderr).replace(path, name).strip()
    output = "\n".join(line for line in output.splitlines() if line.strip() != name)
    output = _locate(output, name, prelude)
    return Verdict(proc.returncode == 0, "glslangValidator", output)


def _library_prefix(text: str) -> str:
    match = re.search(r"\bbool\s+(\w*)intersect\s*\(", text)
    return match.group(1) if match else ""


def _locate(output: str, name: str, prelude: int) -> str:
    """`ERROR: 0:49: msg` -> `ERROR: name:LINE: msg`, LINE counted in the user's file."""

    def shift(match: re.Match) -> str:
        return f"{match.group(1)}{name}:{max(int(match.group(2)) - prelude, 1)}:"

    return re.sub(r"((?:ERROR|WARNING): )(?:0|" + re.escape(name) + r"):(\d+):", shift, output)


def validate_file(path: Path) -> Verdict:
    """Validate a shader file by its extension."""
    text = path.read_text(encoding="utf-8")
    suffix = path.suffix
    if suffix in GLSL_STAGES:
        return validate_glsl(text, str(path))
    raise ToolError(f"{path}: unknown shader extension '{suffix}' (known: .frag .vert .glsl)")


def validate_text(text: str, target: str, name: str) -> Verdict:
    if target == "glsl":
        return validate_glsl(text, name)
    raise ToolError(f"no validator for target '{target}'")
