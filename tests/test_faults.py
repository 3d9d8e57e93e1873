"""Fault injection: every subcommand x every fault, through the real command line.

Faults: a missing input, an unreadable input, a directory where a file is expected, an
unwritable output, a full disk (RLIMIT_FSIZE), SIGINT and SIGTERM. Each must end with its
documented exit code (docs/reference/errors.md "Exit codes": 1 for the file faults, 130 for SIGINT,
143
for SIGTERM), one line on stderr without a traceback, and no partial output: no output
file, no temporary file, no staging directory.

Where a fault has no subject it is marked n/a in MATRIX (`list` reads no input). Commands
whose only output is standard output meet "unwritable output" as a read-only descriptor
and "full disk" as `> file` under the size limit (what is printed is then cut, and the
exit code says so). As root (CI here), permission bits do not stop reads or writes, so
the unreadable and unwritable cases run the command without CAP_DAC_OVERRIDE.

Signals arrive at a known point, not after a guess of wall time: commands that compute
before writing a file (compile -o, render, bench, corpus) get the signal once their
SIGTERM handler is installed and they have spent CPU time in the work (or made their
staging directory, or started their workers); the commands that print are given a
standard output pipe that is already full, and get the signal while blocked writing
to it (/proc/PID/syscall shows the write).
"""

from __future__ import annotations

import ctypes
import fcntl
import os
import resource
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import pytest
from conftest import require_gl, require_tool

ROOT = Path(__file__).resolve().parent.parent
FSIZE = 64  # bytes: under RLIMIT_FSIZE every output (and temp file) is larger
SLOW = "sin(" * 34 + "x*y*z" + ")" * 34  # ~2.6 s of CPU in derive + CSE

COMMANDS = ("list", "show", "compile", "validate", "render", "compare", "bench", "corpus",
            "view", "gallery", "export", "probe")
FAULTS = ("missing input", "unreadable input", "directory input", "directory output",
          "unwritable output", "full disk", "SIGINT", "SIGTERM")
STDOUT_ONLY = {"list", "show", "validate", "compare", "probe"}
NO_INPUT = {"list", "probe"}
# (command, fault) -> why it does not apply
NOT_APPLICABLE = {
    **{(c, f): f"{c} reads no input" for c in NO_INPUT for f in
       ("missing input", "unreadable input", "directory input")},
    **{(c, "directory output"): f"{c} writes standard output only" for c in STDOUT_ONLY},
    **{("gallery", f): "gallery shows a surface's input error in its cell and goes on "
       "(issue 25; tests/test_jsurf.py)" for f in
       ("missing input", "unreadable input", "directory input")},
}
EXIT = {"SIGINT": 130, "SIGTERM": 143}  # every other fault: 1


@pytest.fixture(scope="module")
def place():
    """A world-readable work area (nobody must reach it) with one good input of each kind."""
    base = Path(tempfile.mkdtemp(prefix="implc-faults-"))
    os.chmod(base, 0o755)
    inputs = base / "inputs"
    inputs.mkdir()
    os.chmod(inputs, 0o755)
    (inputs / "surface.toml").write_text(
        (ROOT / "examples" / "paper" / "cross-cap.toml").read_text())
    lines = (ROOT / "tests" / "data" / "corpus_permissive.tsv").read_text().splitlines()
    (inputs / "corpus.tsv").write_text("\n".join(lines[:41]) + "\n")
    run = implc_run(["compile", "sphere", "-o", str(inputs / "shader.frag")])
    assert run.returncode == 0, run.stderr
    run = implc_run(["render", "sphere", "-b", "reference", "--size", "16",
                     "-o", str(inputs / "render.exr")])
    assert run.returncode == 0, run.stderr
    for path in inputs.iterdir():
        os.chmod(path, 0o644)
    yield base
    shutil.rmtree(base, ignore_errors=True)


def environment(home: Path) -> dict:
    return {**os.environ, "PYTHONPATH": str(ROOT), "HOME": str(home),
            "MESA_SHADER_CACHE_DISABLE": "true", "IMPLC_NO_PROGRESS_BAR": "1"}


def implc_run(argv, **kwargs):
    return subprocess.run([sys.executable, "-m", "implc", *argv], capture_output=True,
                          text=True, cwd=ROOT, timeout=180,
                          env=environment(Path(tempfile.gettempdir())), **kwargs)


def good_input(cmd: str, place: Path) -> str:
    inputs = place / "inputs"
    return str({"show": inputs / "surface.toml", "compile": inputs / "surface.toml",
                "view": inputs / "surface.toml",
                "render": inputs / "surface.toml", "bench": inputs / "surface.toml",
                "validate": inputs / "shader.frag", "compare": inputs / "render.exr",
                "corpus": inputs / "corpus.tsv", "gallery": inputs / "surface.toml",
                "export": inputs / "surface.toml"}.get(cmd, ""))


def output_name(cmd: str) -> str:
    return {"compile": "out.frag", "render": "out.png", "bench": "bench-out", "view": "out.html",
            "corpus": "report.md", "gallery": "gallery-out", "export": "export-out"}.get(cmd, "")


def argv(cmd: str, inp: str, out: str, place: Path) -> list[str]:
    reference = str(place / "inputs" / "render.exr")
    return {
        "list": ["list"],
        "show": ["show", inp],
        "compile": ["compile", inp, "-o", out],
        "view": ["view", inp, "-o", out],
        "validate": ["validate", inp],
        "render": ["render", inp, "--size", "16", "-o", out],
        "compare": ["compare", inp, reference],
        "bench": ["bench", inp, "--size", "16", "--frames", "1", "--methods", "taylor",
                  "--configs", "paper", "-o", out],
        "corpus": ["corpus", inp, "--rows", "1-3", "-j", "1", "--no-validate", "-o", out],
        "gallery": ["gallery", inp, "--size", "16", "-o", out],
        "export": ["export", inp, "--host", "unity", "-o", out],
        "probe": ["probe", "-b", "gl"],
    }[cmd]


def default_interrupt() -> None:
    """preexec_fn: SIGINT at its default, as a terminal gives it. A shell without job
    control starts background jobs with SIGINT ignored (`make test &`, nohup, some CI
    runners), and a program that inherits an ignored SIGINT keeps ignoring it (Python
    then installs no KeyboardInterrupt handler), so Ctrl-C could not be tested there."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)


PR_CAPBSET_DROP = 24
CAP_DAC_OVERRIDE, CAP_DAC_READ_SEARCH = 1, 2


def without_override():
    """preexec_fn: as root, drop the capabilities that let root ignore permission bits
    (from the bounding set, so they stay dropped across exec); the files stay readable
    by their owner's bits only. Elsewhere permission bits apply anyway."""
    if os.geteuid() != 0:
        return
    libc = ctypes.CDLL(None, use_errno=True)
    for cap in (CAP_DAC_OVERRIDE, CAP_DAC_READ_SEARCH):
        if libc.prctl(PR_CAPBSET_DROP, cap, 0, 0, 0) != 0:
            os._exit(99)  # reported by the test as "cannot drop capabilities"


def limit_fsize():
    resource.setrlimit(resource.RLIMIT_FSIZE, (FSIZE, FSIZE))


def workdir(place: Path, name: str, mode: int = 0o777) -> Path:
    path = Path(tempfile.mkdtemp(prefix=f"{name}-", dir=place))
    os.chmod(path, mode)
    return path


def leftovers(directory: Path) -> list[str]:
    return sorted(p.name for p in directory.iterdir()) if directory.exists() else []


def check_one_line(proc_stderr: str, code: int, expected_code: int, needle: str) -> None:
    """The exit code, no traceback, and exactly one `implc:` line, the last one (bench
    prints progress lines before it)."""
    lines = proc_stderr.strip().splitlines()
    assert code == expected_code, proc_stderr
    assert "Traceback" not in proc_stderr, proc_stderr
    errors = [line for line in lines if line.startswith("implc:")]
    assert len(errors) == 1 and lines[-1] == errors[0], proc_stderr
    assert needle in errors[0], proc_stderr


def needs_tools(cmd: str) -> None:
    if cmd in ("render", "bench", "gallery", "probe"):
        require_gl()
    if cmd == "validate":
        require_tool("glslangValidator")


CASES = [(c, f) for c in COMMANDS for f in FAULTS]


@pytest.mark.parametrize(("cmd", "fault"), CASES, ids=[f"{c}-{f}" for c, f in CASES])
def test_fault(cmd, fault, place):
    if (cmd, fault) in NOT_APPLICABLE:
        pytest.skip(f"n/a: {NOT_APPLICABLE[cmd, fault]}")
    needs_tools(cmd)
    if fault in EXIT:
        return signal_case(cmd, fault, place)
    out_dir = workdir(place, "out")
    out = str(out_dir / output_name(cmd)) if output_name(cmd) else ""
    inp = good_input(cmd, place)
    kwargs: dict = {}
    needle = ""
    if fault == "missing input":
        inp = str(Path(inp).with_name("missing" + Path(inp).suffix))
        needle = "no such file"
    elif fault == "unreadable input":
        locked = workdir(place, "locked", 0o755) / Path(inp).name
        shutil.copy(inp, locked)
        if cmd == "compare":
            shutil.copy(Path(inp).with_suffix(".json"), locked.with_suffix(".json"))
        os.chmod(locked, 0)
        inp, kwargs["preexec_fn"], needle = str(locked), without_override, "cannot read"
    elif fault == "directory input":
        folder = workdir(place, "dir", 0o755) / Path(inp).name
        folder.mkdir()
        if cmd == "compare":
            shutil.copy(Path(good_input(cmd, place)).with_suffix(".json"),
                        folder.with_suffix(".json"))
        inp, needle = str(folder), "directory"
    elif fault == "directory output":
        if cmd in ("bench", "gallery", "export"):  # a directory: a file in its place is the fault
            Path(out).write_text("not a directory\n")
            needle = "is a file, not a directory"
        else:
            Path(out).mkdir()
            needle = "is a directory"
    elif fault == "unwritable output":
        kwargs["preexec_fn"] = without_override
        if cmd in STDOUT_ONLY:
            kwargs["stdout"] = os.open(os.devnull, os.O_RDONLY)
            needle = "cannot write to standard output"
        else:
            locked = workdir(place, "readonly", 0o555)
            out_dir, out = locked, str(locked / output_name(cmd))
            needle = "is not writable"
    elif fault == "full disk":
        kwargs["preexec_fn"] = limit_fsize
        needle = "file too large"
        if cmd in STDOUT_ONLY:
            kwargs["stdout"] = os.open(out_dir / "stdout.txt", os.O_WRONLY | os.O_CREAT, 0o644)
    home = workdir(place, "home")
    capture = {"stderr": subprocess.PIPE}
    if "stdout" not in kwargs:
        capture["stdout"] = subprocess.PIPE
    try:
        proc = subprocess.run([sys.executable, "-m", "implc", *argv(cmd, inp, out, place)],
                              text=True, cwd=ROOT, timeout=180, env=environment(home),
                              **capture, **kwargs)
    finally:
        if isinstance(kwargs.get("stdout"), int):
            os.close(kwargs["stdout"])
    if proc.returncode == 99 and "preexec_fn" in kwargs:
        pytest.skip("cannot drop CAP_DAC_OVERRIDE here")
    check_one_line(proc.stderr, proc.returncode, 1, needle)
    expected = {"stdout.txt"} if fault == "full disk" and cmd in STDOUT_ONLY else set()
    if fault == "directory output":
        expected = {output_name(cmd)}
    assert set(leftovers(out_dir)) == expected, leftovers(out_dir)
    if fault == "directory output" and cmd not in ("bench", "gallery", "export"):
        assert leftovers(Path(out)) == []


# --------------------------------------------------------------------------- signals


def _status(pid: int, field: str) -> str:
    for line in Path(f"/proc/{pid}/status").read_text().splitlines():
        if line.startswith(field + ":"):
            return line.split(":", 1)[1].strip()
    return ""


def handles_sigterm(pid: int) -> bool:
    """Python installed implc's SIGTERM handler (main() is running)."""
    try:
        return bool(int(_status(pid, "SigCgt"), 16) & (1 << (signal.SIGTERM - 1)))
    except (OSError, ValueError):
        return False


def cpu_seconds(pid: int) -> float:
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def blocked_writing(pid: int) -> bool:
    try:
        return Path(f"/proc/{pid}/syscall").read_text().split()[0] == "1"  # write(2)
    except (OSError, IndexError):
        return False


def children(pid: int) -> list[int]:
    found = []
    for task in Path(f"/proc/{pid}/task").iterdir():
        found += [int(c) for c in (task / "children").read_text().split()]
    return found


def full_pipe() -> tuple[int, int]:
    """A pipe whose buffer is already full: a write to it blocks until it is read."""
    read, write = os.pipe()
    fcntl.fcntl(write, fcntl.F_SETFL, os.O_NONBLOCK)
    try:
        while True:
            os.write(write, b"\0" * 65536)
    except BlockingIOError:
        pass
    fcntl.fcntl(write, fcntl.F_SETFL, 0)
    return read, write


def signal_case(cmd: str, fault: str, place: Path) -> None:
    sig = signal.SIGINT if fault == "SIGINT" else signal.SIGTERM
    out_dir = workdir(place, "out")
    out = str(out_dir / output_name(cmd)) if output_name(cmd) else ""
    inp = good_input(cmd, place)
    args = argv(cmd, inp, out, place)
    if cmd in ("compile", "view"):
        args = [cmd, "-e", SLOW, "-o", out]
    elif cmd == "export":
        args = ["export", "-e", SLOW, "--host", "unity", "-o", out]
    elif cmd == "render":
        args = ["render", inp, "-b", "reference", "--size", "1024", "-o", out]
    elif cmd == "bench":
        args = ["bench", inp, "--size", "384", "--frames", "2", "--methods", "taylor",
                "hessian", "--configs", "paper", "-o", out]
    elif cmd == "corpus":
        args = ["corpus", inp, "-j", "2", "-t", "glsl", "-o", out]
    elif cmd == "gallery":
        args = ["gallery", *[inp] * 40, "--size", "512", "-o", out]
    read = write = None
    stdout = subprocess.PIPE
    if cmd in STDOUT_ONLY:
        read, write = full_pipe()
        stdout = write
    proc = subprocess.Popen([sys.executable, "-m", "implc", *args], stdout=stdout,
                            stderr=subprocess.PIPE, text=True, cwd=ROOT,
                            env=environment(workdir(place, "home")),
                            preexec_fn=default_interrupt)
    if write is not None:
        os.close(write)
    ready = {
        "compile": lambda: cpu_seconds(proc.pid) > 1.0,
        "view": lambda: cpu_seconds(proc.pid) > 1.0,
        "export": lambda: cpu_seconds(proc.pid) > 1.0,
        "render": lambda: cpu_seconds(proc.pid) > 1.0,
        "bench": lambda: any(p.name.startswith(".bench-out.partial-")
                             for p in out_dir.iterdir()) and cpu_seconds(proc.pid) > 1.0,
        "corpus": lambda: len(children(proc.pid)) >= 2,
        "gallery": lambda: any(p.name.startswith(".gallery-out.partial-")
                               for p in out_dir.iterdir()) and cpu_seconds(proc.pid) > 1.0,
    }.get(cmd, lambda: blocked_writing(proc.pid))
    deadline = time.monotonic() + 90
    while proc.poll() is None and time.monotonic() < deadline:
        if handles_sigterm(proc.pid) and ready():
            break
        time.sleep(0.02)
    assert proc.poll() is None, f"{cmd} finished before it could be signalled: {proc.stderr}"
    workers = children(proc.pid)
    if cmd == "corpus":
        time.sleep(0.5)  # the workers are compiling rows
    proc.send_signal(sig)
    if read is not None:  # let the interrupted print's last flush through
        with os.fdopen(read, "rb") as drain:
            drain.read()
    _, stderr = proc.communicate(timeout=60)
    check_one_line(stderr, proc.returncode, EXIT[fault],
                   "interrupted" if sig == signal.SIGINT else "terminated")
    assert stderr.strip().splitlines()[-1] == (
        "implc: interrupted" if sig == signal.SIGINT else "implc: terminated")
    assert leftovers(out_dir) == [], leftovers(out_dir)
    for pid in workers:  # corpus: its workers (and multiprocessing's tracker) end too
        deadline = time.monotonic() + 10
        while time.monotonic() < deadline and Path(f"/proc/{pid}").exists() and not (
                _status(pid, "State").startswith("Z")):
            time.sleep(0.05)
        alive = Path(f"/proc/{pid}").exists() and not _status(pid, "State").startswith("Z")
        assert not alive, Path(f"/proc/{pid}/cmdline").read_bytes()


def test_matrix_is_complete():
    """Every subcommand of the parser is in the matrix, and every fault is either run or
    says why it does not apply."""
    from implc.cli import build_parser

    parser = build_parser()
    sub = next(a for a in parser._actions if a.dest == "command")
    assert set(sub.choices) == set(COMMANDS)
    applicable = [case for case in CASES if case not in NOT_APPLICABLE]
    assert len(applicable) == len(CASES) - len(NOT_APPLICABLE) == 82
