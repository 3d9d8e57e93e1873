"""Output files: checked before any work starts, written atomically, never left partial.

`check_output` / `check_output_dir` are what the command line calls for every output
option (`compile -o`, `render -o`, `bench -o`, `corpus -o`, and `view -o`): the
directory must exist (or be creatable) and be writable, the extension must be one the
command writes, and nothing may sit in the way (a directory where a file should go).
They raise `OutputError` (exit code 1, one line) before a second is spent rendering.

`write_atomic` / `write_with` write through a temporary file in the same directory and a
rename, so a reader, an interrupted run or a full disk never leaves a partial output;
an `OSError` while writing (ENOSPC, EFBIG under RLIMIT_FSIZE, EIO) becomes an
`OutputError` naming the file.
"""

from __future__ import annotations

import contextlib
import errno
import itertools
import os
import shutil
import stat
import tempfile
from collections.abc import Callable, Iterator, Sequence
from pathlib import Path
from typing import TypeVar

from .errors import InputError, OutputError
from .interrupts import raise_dropped, signals_held

T = TypeVar("T")


def read_input(path: Path, kind: str) -> bytes:
    """The bytes of an input file, or an InputError saying in one line why it cannot be
    read; `kind` names what the file should be ("a surface file", "a corpus TSV"). The
    caller decodes and checks the size, with diagnostics of its own kind."""
    path = Path(path)
    if path.is_dir():
        raise InputError(f"cannot read {path}: it is a directory, not {kind}")
    try:
        return path.read_bytes()
    except FileNotFoundError:
        raise InputError(f"cannot read {path}: no such file") from None
    except OSError as err:
        raise InputError(f"cannot read {path}: {(err.strerror or str(err)).lower()}") from None

# errno values that mean "the disk (or the process's file-size limit) is full"
FULL_DISK = {errno.ENOSPC, errno.EFBIG, getattr(errno, "EDQUOT", errno.ENOSPC)}


def _describe(err: OSError) -> str:
    if err.errno == errno.EFBIG:
        return "file too large (disk full or file-size limit reached)"
    if err.errno == errno.ENOSPC:
        return "no space left on the device"
    return (err.strerror or str(err)).lower()


def check_output(
    path: Path | str,
    extensions: Sequence[str] | None = None,
    *,
    what: str = "output",
    companions: Sequence[Path] = (),
    sidecars: Sequence[str] = (),
) -> Path:
    """Check, before any work, that `path` can be written as a file.

    `extensions` (".png", ".exr", ...) are the ones this output may have (case-insensitive);
    `companions` are files written beside it, checked alike; `sidecars` the suffixes of
    files named after it (a render's `.json`), named once `path` is known to name a file.
    Probes the directory with a real temporary file (removed again), so a read-only
    file system or missing permissions show up even for root.
    """
    path = Path(path)
    if is_device(path):  # `-o /dev/null`, `-o /dev/stdout`: written as they are
        return path
    named = (path.with_suffix(suffix) for suffix in sidecars)  # after path: `-o .` has no name
    for target in itertools.chain((path, *companions), named):  # `-o adir`: a directory
        if target.is_dir():
            example = f"; name a file in it, e.g. {path / ('out' + extensions[0])}" if (
                extensions and target == path) else ""
            raise OutputError(f"cannot write {target}: it is a directory{example}")
    if extensions is not None and path.suffix.lower() not in {e.lower() for e in extensions}:
        known = " or ".join(extensions) if len(extensions) < 3 else (
            ", ".join(extensions[:-1]) + " or " + extensions[-1])
        shown = (f", not '{path.suffix}'" if path.suffix else
                 f"; '{path.name}' has no extension")
        raise OutputError(f"cannot write {path}: {what} needs {known}{shown}")
    directory = path.parent if str(path.parent) else Path(".")
    _check_writable_dir(directory, path)
    return path


def check_output_dir(path: Path | str, *, what: str = "output directory") -> Path:
    """Check, before any work, that `path` is (or can be created as) a writable directory."""
    path = Path(path)
    if path.exists() and not path.is_dir():
        raise OutputError(f"cannot write {path}: the {what} is a file, not a directory")
    existing = path
    while not existing.exists():
        parent = existing.parent
        if parent == existing:
            break
        existing = parent
    if not existing.is_dir():
        raise OutputError(f"cannot create {path}: {existing} is not a directory")
    _check_writable_dir(existing, path)
    return path


def _check_writable_dir(directory: Path, path: Path) -> None:
    if not directory.exists():
        raise OutputError(f"cannot write {path}: directory {directory} does not exist")
    if not directory.is_dir():
        raise OutputError(f"cannot write {path}: {directory} is not a directory")
    try:
        fd, probe = tempfile.mkstemp(prefix=".implc-probe-", dir=directory)
    except OSError as err:
        raise OutputError(f"cannot write {path}: directory {directory} is not writable "
                          f"({_describe(err)})") from None
    os.close(fd)
    os.unlink(probe)


def write_atomic(path: Path, data: str | bytes) -> None:
    """Write `data` to `path` through a temporary file in the same directory + rename."""
    payload = data.encode("utf-8") if isinstance(data, str) else data
    write_with(path, lambda tmp: Path(tmp).write_bytes(payload))


def write_with(path: Path, writer: Callable[[str], object], suffix: str = "") -> None:
    """Let `writer(temp_path)` produce the file, then rename it onto `path` atomically.

    The temporary keeps the target's extension (image writers choose the format by it;
    `suffix` names the format for a device, which has none).
    """
    if is_device(path):
        write_device(path, writer, suffix)
        return
    commit = prepare_with(path, writer)
    commit()


def is_device(path: Path | str) -> bool:
    """A character device (`/dev/null`, a terminal): written to, never replaced."""
    try:
        return stat.S_ISCHR(os.stat(path).st_mode)
    except OSError:
        return False


def write_device(path: Path | str, writer: Callable[[str], object], suffix: str = "") -> None:
    """`writer` makes the file in a scratch directory; its bytes go to the device (a
    rename would replace `/dev/null` itself)."""
    with tempfile.TemporaryDirectory(prefix="implc-") as scratch:
        staged = Path(scratch) / ("out" + (suffix or Path(path).suffix))
        writer(str(staged))
        try:
            with open(path, "wb") as device:
                device.write(staged.read_bytes())
        except OSError as err:
            raise OutputError(f"cannot write {path}: {_describe(err)}") from None


def prepare_with(path: Path, writer: Callable[[str], object]) -> Callable[[], None]:
    """Write the temporary of `path` now; return the rename that puts it in place.

    Several outputs that belong together (an image and its sidecar) are all prepared
    first, then committed, so an interruption leaves none or all of them.
    """
    path = Path(path)
    directory = path.parent if str(path.parent) else Path(".")
    if not directory.is_dir():
        raise OutputError(f"cannot write {path}: directory {directory} does not exist")
    try:
        tmp = _made_held(lambda: _temp_file(path, directory), _unlink)
    except OSError as err:
        raise OutputError(f"cannot write {path}: {_describe(err)}") from None
    try:
        writer(tmp)
        raise_dropped()  # an interrupted run puts no output in place
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)  # mkstemp makes 0600; outputs are ordinary files
    except OSError as err:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp)
        raise OutputError(f"cannot write {path}: {_describe(err)}") from None
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp)
        raise

    def commit() -> None:
        try:
            os.replace(tmp, path)
        except OSError as err:
            _unlink(tmp)
            raise OutputError(f"cannot write {path}: {_describe(err)}") from None
        except BaseException:
            _unlink(tmp)
            raise

    commit.discard = lambda: _unlink(tmp)  # type: ignore[attr-defined]
    return commit


def _made_held(make: Callable[[], T], remove: Callable[[T], object]) -> T:
    """make() (a temporary file or directory) with SIGINT and SIGTERM held: a signal
    between its making and the caller's cleanup would leave it behind
    (test_fault[gallery-SIGTERM] under load). The signal that waited removes it."""
    made = None
    try:
        with signals_held():
            made = make()
    except BaseException:
        if made is not None:
            remove(made)
        raise
    return made


def _temp_file(path: Path, directory: Path) -> str:
    fd, tmp = tempfile.mkstemp(prefix=f".{path.stem}.", suffix=path.suffix, dir=directory)
    os.close(fd)
    return tmp


def _unlink(path: str) -> None:
    with contextlib.suppress(FileNotFoundError):
        os.unlink(path)


@contextlib.contextmanager
def staged_directory(out_dir: Path | str) -> Iterator[Path]:
    """A temporary directory beside `out_dir` to write a run's many files into; when the
    block ends normally its contents move into `out_dir` (created if missing), and when
    it raises (an error, Ctrl-C, SIGTERM) it is removed: no partial run is left behind.
    """
    out_dir = Path(out_dir)
    parent = out_dir.parent if str(out_dir.parent) else Path(".")
    parent.mkdir(parents=True, exist_ok=True)
    try:
        stage = _made_held(
            lambda: Path(tempfile.mkdtemp(prefix=f".{out_dir.name}.partial-", dir=parent)),
            lambda made: shutil.rmtree(made, ignore_errors=True))
    except OSError as err:
        raise OutputError(f"cannot write {out_dir}: {_describe(err)}") from None
    try:
        try:
            yield stage
        except OutputError as err:  # name the file as the user will know it
            err.message = err.message.replace(str(stage), str(out_dir))
            err.args = (err.message,)
            raise
        raise_dropped()
        if not out_dir.exists():
            os.chmod(stage, 0o777 & ~_umask())
            os.replace(stage, out_dir)
            return
        for source in sorted(stage.rglob("*")):
            target = out_dir / source.relative_to(stage)
            if source.is_dir():
                target.mkdir(exist_ok=True)
            else:
                os.replace(source, target)
    except OSError as err:
        raise OutputError(f"cannot write {out_dir}: {_describe(err)}") from None
    finally:
        shutil.rmtree(stage, ignore_errors=True)


def _umask() -> int:
    umask = os.umask(0)
    os.umask(umask)
    return umask


def describe_os_error(err: OSError) -> str:
    """A short, lower-case reason for an OSError (used for standard output)."""
    return _describe(err)
