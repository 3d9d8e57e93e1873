"""What a real GPU's compiler makes of a program: RADV's ACO statistics (registers,
spills, scratch, waves per SIMD, instructions) for named AMD families, with no GPU.

llvmpipe, which times every frame here, is a CPU: it cannot show register pressure, the
cost that decides speed on a GPU at high degree (issue 49). RADV, Mesa's AMD Vulkan
driver, makes a "null" device for any family named by RADV_FORCE_FAMILY and compiles
pipelines with ACO, the compiler AMD GPUs run on Linux. A program reaches it as SPIR-V:
HLSL through glslang's HLSL front end (as `validate` and the hlsl-spirv runner do), GLSL
through glslang with -R (Vulkan's relaxed rules: the program's plain uniforms become one
uniform block at set 0, binding 0, as HLSL's $Globals does). The Vulkan client runs in a
child process (render/vulkan_stats.py says why), one per family.
"""

from __future__ import annotations

import functools
import json
import os
import re
import subprocess
import sys
import tempfile
from collections.abc import Sequence
from ctypes.util import find_library
from dataclasses import dataclass
from pathlib import Path

from ..emit import CompiledShader, render_template
from ..errors import OptionError, ToolError
from ..options import GPU_FAMILIES
from ..targets import TARGETS, get_target
from .hlsl_runner import _run

ICD_DIRS = ("/usr/share/vulkan/icd.d", "/etc/vulkan/icd.d", "/usr/local/share/vulkan/icd.d")
CLIENT = Path(__file__).with_name("vulkan_stats.py")  # imports nothing of implc
TIMEOUT = 600  # seconds for one family's pipelines (a degree-20 program compiles in ~1 s)


@dataclass(frozen=True)
class GpuStats:
    """ACO's figures for a program's fragment shader on one family (`device`: RADV's
    name for it). `waves`: waves per SIMD the registers allow; `scratch`: bytes."""

    family: str
    device: str
    vgprs: int
    sgprs: int
    spilled_vgprs: int
    spilled_sgprs: int
    scratch: int
    waves: int
    instructions: int

    @property
    def spills(self) -> bool:
        return bool(self.spilled_vgprs or self.spilled_sgprs or self.scratch)

    def line(self) -> str:
        """One line for a report."""
        spill = (f"SPILLS {self.spilled_vgprs} VGPRs, {self.spilled_sgprs} SGPRs, "
                 f"{self.scratch} B scratch" if self.spills else "no spills")
        return (f"{self.family} ({self.device}): {self.vgprs} VGPRs, {self.sgprs} SGPRs, "
                f"{self.waves} waves/SIMD, {self.instructions} instructions, {spill}")

    def as_dict(self) -> dict[str, int | str]:
        return {f: getattr(self, f) for f in self.__dataclass_fields__}


# RADV's statistic names -> GpuStats fields
NAMES = {"VGPRs": "vgprs", "SGPRs": "sgprs", "Spilled VGPRs": "spilled_vgprs",
         "Spilled SGPRs": "spilled_sgprs", "Scratch size": "scratch",
         "Subgroups per SIMD": "waves", "Instructions": "instructions"}


def spirv_problem(shader: CompiledShader) -> str | None:
    """Why this shader has no path to SPIR-V here (None: it has one): its target's record
    names the flavours glslang turns into Vulkan SPIR-V (Target.spirv_flags)."""
    if shader.emit != "program":
        return "only a program (not a library) is a whole pipeline stage"
    flags = get_target(shader.target).spirv_flags
    if shader.flavor in flags:
        return None
    if flags:
        return (f"the {shader.target} flavour {shader.flavor} has no Vulkan form here (use "
                f"--flavor {' or '.join(flags)})")
    able = [t.name for t in TARGETS.values() if t.spirv_flags]
    return f"{shader.target} has no path to SPIR-V here (targets {' and '.join(able)} do)"


def radv_problem() -> str | None:
    """Why RADV cannot be asked here (None: the loader and RADV's manifest are present)."""
    if find_library("vulkan") is None:
        return "no Vulkan loader (libvulkan.so.1; Debian: libvulkan1)"
    if radv_manifest() is None:
        return ("no RADV driver (radeon_icd.*.json in " + ", ".join(ICD_DIRS)
                + "; Debian: mesa-vulkan-drivers)")
    return None


def radv_manifest() -> str | None:
    for folder in ICD_DIRS:
        found = sorted(Path(folder).glob("radeon_icd.*.json")) if Path(folder).is_dir() else []
        if found:
            return str(found[0])
    return None


def _glslang(text: str, stage: str, flags: Sequence[str]) -> bytes:
    """SPIR-V of one stage by glslangValidator with the target's `flags`."""
    tool = "glslangValidator"
    with tempfile.TemporaryDirectory(prefix="implc-") as tmp:
        source, spirv = os.path.join(tmp, f"shader.{stage}"), os.path.join(tmp, "shader.spv")
        Path(source).write_text(text, encoding="utf-8")
        _run([tool, *flags, "-V", "-S", stage, "-o", spirv, source])
        return Path(spirv).read_bytes()


def _check_spirv(shader: CompiledShader) -> None:
    if problem := spirv_problem(shader):
        raise OptionError(f"GPU statistics: {problem}")


def fragment_spirv(shader: CompiledShader) -> bytes:
    """The program's fragment stage as SPIR-V (OptionError where it has no path there)."""
    _check_spirv(shader)
    return _glslang(shader.text, "frag",
                    get_target(shader.target).spirv_flags[shader.flavor])


@functools.cache
def vertex_spirv() -> bytes:
    """The full-screen triangle (templates/glsl/fullscreen.vert.j2) as SPIR-V."""
    return _glslang(render_template("glsl/fullscreen.vert.j2", version="450 core"), "vert",
                    get_target("glsl").spirv_flags["450"])


def check_family(family: str) -> str:
    """The family name, lower case; OptionError if it is not a plain name."""
    if not re.fullmatch(r"[a-z0-9_]{2,20}", family.lower()):
        raise OptionError(f"'{family}' is not a GPU family name (e.g. {', '.join(GPU_FAMILIES)}, "
                         "polaris10)")
    return family.lower()


def gpu_stats(shaders: Sequence[CompiledShader],
              families: Sequence[str] = GPU_FAMILIES) -> dict[str, list[GpuStats]]:
    """Each family -> the statistics of each shader's fragment stage, in order. ToolError
    where RADV or glslang is missing or a family is unknown to RADV."""
    names = [check_family(f) for f in families]
    for shader in shaders:  # an option's mistake before a tool's absence
        _check_spirv(shader)
    if problem := radv_problem():
        raise ToolError(f"GPU statistics need Mesa's RADV: {problem}")
    request = json.dumps({"vertex": vertex_spirv().hex(),
                          "fragments": [fragment_spirv(s).hex() for s in shaders]})
    return {family: _ask(family, request) for family in names}


def _ask(family: str, request: str) -> list[GpuStats]:
    """One child process: RADV's null device for `family`, every pipeline of `request`."""
    manifest = radv_manifest()
    env = {**os.environ, "RADV_FORCE_FAMILY": family, "VK_ICD_FILENAMES": str(manifest),
           "VK_DRIVER_FILES": str(manifest)}
    try:
        proc = subprocess.run([sys.executable, str(CLIENT)],
                              input=request, capture_output=True, text=True, env=env,
                              timeout=TIMEOUT)
    except subprocess.TimeoutExpired:
        raise ToolError(f"RADV ({family}) did not finish within {TIMEOUT} s") from None
    if "Unknown family" in proc.stderr:  # RADV aborts on a name it does not know
        raise OptionError(f"RADV knows no GPU family '{family}' (e.g. "
                          f"{', '.join(GPU_FAMILIES)}, polaris10)")
    try:
        answer = json.loads(proc.stdout)
    except json.JSONDecodeError:
        raise ToolError(f"the Vulkan client for {family} failed (exit {proc.returncode}):\n"
                        f"{proc.stderr.strip()[-2000:]}") from None
    if "error" in answer:
        hint = (f" (is '{family}' a family RADV knows? e.g. {', '.join(GPU_FAMILIES)}, polaris10)"
                if "no Vulkan device" in answer["error"] else "")
        raise ToolError(f"RADV ({family}): {answer['error']}{hint}")
    if "RADV" not in answer["device"]:
        raise ToolError(f"the device for {family} is {answer['device']!r}, not RADV's")
    missing = [name for name in NAMES if answer["stats"] and name not in answer["stats"][0]]
    if missing:  # another Mesa may name them otherwise: say so, never guess
        raise ToolError(f"RADV ({answer['device']}) reports no {', '.join(missing)} (it "
                        f"reports {', '.join(answer['stats'][0])})")
    return [GpuStats(family=family, device=answer["device"],
                     **{field: int(stats[name]) for name, field in NAMES.items()})
            for stats in answer["stats"]]
