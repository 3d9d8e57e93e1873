"""Run the real compiler of each shader language and return its verdict.

Which function validates which language, and which file extensions are which language,
is the target registry's (implc/targets.py); this module holds the validators.

GLSL: glslangValidator (Khronos reference front end). An implc library emit (its S, grad,
intersect and shade under one prefix) and a Shadertoy image shader have no
`#version`/`main`, so they are wrapped in templates/glsl/harness.glsl.j2 first; any other
GLSL file is compiled as it is, in the stage its extension names (or `stage`), as
`#version 330` when it has none (glslang's own default, ES 1.00, rejects `float` without
a precision). The tool's line numbers are mapped back into the user's file.

A file with no code (only whitespace and comments, which the three languages write
alike) is refused by `check_source` in every language alike, before any compiler runs.
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import tempfile
from dataclasses import dataclass
from pathlib import Path

from .devices import FP64, opencl_build, opencl_device, wgpu_device
from .errors import InputError, ToolError
from .targets import TARGETS, get_target, resolve, target_of_file

PLAIN_GLSL_VERSION = "330"  # for a plain GLSL file without #version


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
    """'program' (has #version), 'shadertoy' (has mainImage), 'library' (an implc
    library emit) or 'plain' (any other GLSL: compiled as it is)."""
    if re.search(r"^\s*#version\b", text, re.M):
        return "program"
    if re.search(r"\bvoid\s+mainImage\s*\(", text):
        return "shadertoy"
    if _library_prefix(text) is not None:
        return "library"
    return "plain"


def glsl_stage(name: str) -> str:
    """The stage of a GLSL file by its extension, named as the target record's stages
    (`x.vert`, `x.vert.glsl`); any other GLSL file (.frag, .glsl) is a fragment shader
    unless `--stage` says otherwise."""
    suffixes = Path(name).suffixes
    suffix = suffixes[-2] if len(suffixes) > 1 and suffixes[-1] == ".glsl" else Path(name).suffix
    stage = suffix[1:]
    return stage if stage in get_target("glsl").stages else "frag"


def check_source(text: str, name: str) -> None:
    """Refuse a shader file with no code: only whitespace and `//`, `/* */` comments
    (one rule for GLSL, WGSL and OpenCL C, whose compilers would disagree on it)."""
    code = re.sub(r"//[^\n]*|/\*.*?(\*/|\Z)", " ", text, flags=re.S)
    if not code.strip():
        raise InputError(f"{name}: empty file: no shader code to validate (only whitespace "
                         "or comments)")


def validate_glsl(text: str, name: str = "shader.frag", stage: str | None = None) -> Verdict:
    """Validate GLSL with glslangValidator; `name` is used in the reported messages and
    gives the stage (`glsl_stage`) unless `stage` does."""
    from .emit import render_template  # late: emit imports the whole pipeline

    tool = find_tool("glslangValidator")
    kind = glsl_kind(text)
    stage = stage or glsl_stage(name)
    prelude = 0
    source = text
    if kind in ("shadertoy", "library", "plain"):
        prefix = _library_prefix(text) or ""
        source = render_template("glsl/harness.glsl.j2", kind=kind, body=text, prefix=prefix,
                                 version=PLAIN_GLSL_VERSION,
                                 double=re.search(r"\bdvec3\b", text) is not None)
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
    tool = "glslangValidator"
    if stage != "frag" or kind == "plain":
        tool += f", {stage} stage"
    if kind == "plain":
        tool += f", no #version: checked as {PLAIN_GLSL_VERSION}"
    return Verdict(proc.returncode == 0, tool, output)


def validate_hlsl(text: str, name: str = "shader.hlsl") -> Verdict:
    """Validate HLSL with glslangValidator's HLSL front end, compiled to SPIR-V as a pixel
    shader with entry point main (`-D -S frag -e main -V`). A library emit has no entry
    point, so templates/hlsl/harness.hlsl.j2 appends one that calls its functions; the
    user's text comes first, so the tool's line numbers are the user's."""
    from .emit import render_template  # late: emit imports the whole pipeline

    tool = find_tool("glslangValidator")
    source = text
    if not re.search(r"\bmain\s*\(", text):
        match = re.search(r"\bbool\s+(\w*)intersect\s*\(", text)
        source = render_template("hlsl/harness.hlsl.j2", body=text,
                                 prefix=match.group(1) if match else "")
    with tempfile.TemporaryDirectory(prefix="implc-") as tmp:
        path = os.path.join(tmp, "shader.hlsl")
        Path(path).write_text(source, encoding="utf-8")
        try:
            proc = subprocess.run([tool, "-D", "-S", "frag", "-e", "main", "-V",
                                   "-o", os.path.join(tmp, "shader.spv"), path],
                                  capture_output=True, text=True, timeout=120)
        except subprocess.TimeoutExpired:
            raise ToolError("glslangValidator did not finish within 120 s") from None
    output = (proc.stdout + proc.stderr).replace(path, name).strip()
    output = "\n".join(line for line in output.splitlines() if line.strip() != name)
    return Verdict(proc.returncode == 0, "glslangValidator, HLSL to SPIR-V",
                   _locate(output, name, 0))


def _library_prefix(text: str) -> str | None:
    """The prefix of an implc library emit's entry points (what the harness calls), or
    None when `text` does not define them all (a user's own GLSL)."""
    for match in re.finditer(r"\bbool\s+(\w*)intersect\s*\(", text):
        prefix = re.escape(match.group(1))
        if all(re.search(pattern, text) for pattern in (
                rf"\bfloat\s+{prefix}S\s*\(", rf"\bvec3\s+{prefix}grad\s*\(",
                rf"\bvec3\s+{prefix}shade\s*\(")):
            return match.group(1)
    return None


def _locate(output: str, name: str, prelude: int) -> str:
    """`ERROR: 0:49: msg` -> `ERROR: name:LINE: msg`, LINE counted in the user's file."""

    def shift(match: re.Match) -> str:
        return f"{match.group(1)}{name}:{max(int(match.group(2)) - prelude, 1)}:"

    return re.sub(r"((?:ERROR|WARNING): )(?:0|" + re.escape(name) + r"):(\d+):", shift, output)


def validate_opencl(text: str, name: str = "shader.cl") -> Verdict:
    """Build OpenCL C with the OpenCL driver (PoCL here) through pyopencl.

    A program and a library emit both build as they are (a program needs no kernel), so
    line numbers are the user's. A double-precision source on a device without
    cl_khr_fp64 fails here, with the reason, rather than with the driver's type errors.
    """
    dev = opencl_device()
    tool = f"OpenCL build, {dev.name}"
    pragma = re.search(r"^[ \t]*#[ \t]*pragma[ \t]+OPENCL[ \t]+EXTENSION[ \t]+" + FP64, text, re.M)
    if pragma and not dev.has_fp64:
        line = text.count("\n", 0, pragma.start()) + 1
        message = (f"{name}:{line}:1: error: double precision needs {FP64}, which this "
                   "device does not support")
        return Verdict(False, tool, message)
    built = opencl_build(text)
    return Verdict(built.program is not None, tool, _locate_cl(built.log, name))


def _locate_cl(log: str, name: str) -> str:
    """`error: /tmp/.../tempfile_x.cl:5:25: msg` (PoCL) or `<source>:5:25: error: msg`
    (clang) -> `name:5:25: error: msg`."""
    log = re.sub(r"^(error|warning|note|remark): [^\s:]+:(\d+):(\d+): ",
                 lambda m: f"{name}:{m.group(2)}:{m.group(3)}: {m.group(1)}: ", log, flags=re.M)
    return re.sub(r"^(?:<source>|[^\s:]+\.cl):(\d+):(\d+): ", lambda m: f"{name}:{m.group(1)}:"
                  f"{m.group(2)}: ", log, flags=re.M)


WGSL_LABEL = "implc-shader.wgsl"  # the name naga sees; replaced by the user's in messages


def validate_wgsl(text: str, name: str = "shader.wgsl") -> Verdict:
    """Validate WGSL with naga: inside wgpu (the shader module an engine would create, on
    the software adapter) and with the `naga` CLI when it is on PATH; both must accept.
    A library emit needs no harness: naga validates a module without entry points.
    Messages are naga's own (`┌─ name:line:col` and a caret), pointing at `name`."""
    dev = wgpu_device()  # a missing wgpu or adapter is a ToolError (exit 4)
    import wgpu

    tools, failures = ["naga (wgpu)"], []
    try:
        dev.create_shader_module(code=text, label=WGSL_LABEL)
    except wgpu.GPUError as err:
        # drop wgpu's "Validation Error / Caused by / In wgpuDeviceCreateShaderModule" frame
        message = re.sub(r"(?s)^.*?In wgpuDeviceCreateShaderModule[^\n]*\n", "", str(err))
        # parse errors name the source `wgsl`, validation errors by its label
        failures.append(re.sub(r"(─ )wgsl:(?=\d)", rf"\g<1>{WGSL_LABEL}:", message).strip())
    naga = shutil.which("naga")
    if naga is not None:
        tools.append("naga CLI")
        try:
            proc = subprocess.run(
                [naga, "--input-kind", "wgsl", "--stdin-file-path", WGSL_LABEL],
                input=text, capture_output=True, text=True, timeout=120,
                env={**os.environ, "NO_COLOR": "1"},
            )
        except subprocess.TimeoutExpired:
            raise ToolError("naga did not finish within 120 s") from None
        if proc.returncode != 0:
            # one report is enough when both reject: the CLI's is the plainer text
            failures = [(proc.stdout + proc.stderr).strip()]
    messages = "\n".join(failures).replace(WGSL_LABEL, name)
    return Verdict(not failures, " + ".join(tools), messages)


def validate_file(path: Path) -> Verdict:
    """Validate a shader file, choosing the language by its extension."""
    target = target_of_file(path.suffix)
    if target is None:
        known = " ".join(sorted(ext for t in TARGETS.values() for ext in t.extensions))
        raise ToolError(f"{path}: unknown shader extension '{path.suffix}' (known: {known})")
    return validate_text(path.read_text(encoding="utf-8"), target.name, str(path))


def validate_text(text: str, target: str, name: str, stage: str | None = None) -> Verdict:
    """Validate `text` in the language of `target`; `name` is used in the messages;
    `stage` (GLSL only) overrides the stage `name`'s extension gives."""
    if target not in TARGETS:
        raise ToolError(f"no validator for target '{target}'")
    check_source(text, name)
    validator = resolve(TARGETS[target].validator)
    if stage is None:
        return validator(text, name)
    if stage not in TARGETS[target].stages:
        raise ValueError(f"a {target} shader has no stage '{stage}' to choose")
    return validator(text, name, stage=stage)
