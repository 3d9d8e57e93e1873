"""`implc corpus`: run implc over an independent corpus of equations and report.

The corpus (`../shared/corpus/implicit_surface_corpus.tsv`, or the permissive copy in
`tests/data/corpus_permissive.tsv`) holds equations exactly as other projects write them,
so it measures how much of the real world implc understands, and checks everything it
produces. Each row goes through what `implc compile -e EQUATION --param NAME=VALUE ...
-m hessian --emit program --validate` does, once per target:

1. load: parameters from the row's JSON as `--param NAME=repr(float)` (a name that
   breaks implc's rules, e.g. `e` or `xy`, is a rejection with that reason); the equation
   through the parser and its limits;
2. derive + optimize (bounded by `--max-derived`), then a numeric check at seeded random
   points: gradient, F' and F'' against finite differences, and every optimized shader
   function against the plain expressions it replaces;
3. emit the program for each target and validate it with the target's real compiler.

A row is *compiled* when every step passes on every target, *rejected* when implc refuses
it with an `ImplcError` (the message is the reason), and a *failure* (an implc bug) when a
shader fails validation, the numeric check fails or an unexpected exception escapes.
Rows are independent, so `jobs > 1` runs them in worker processes. What the run found is
reported by `corpus_report.py`.
"""

from __future__ import annotations

import csv
import json
import re
import time
import traceback
from collections.abc import Callable, Iterable, Sequence
from concurrent.futures import Executor
from dataclasses import dataclass, field
from pathlib import Path

from .errors import ImplcError, InputError, ToolError
from .executors import local_executor, stop_executor
from .fileio import read_input
from .targets import TARGETS as REGISTRY

TARGETS: tuple[str, ...] = tuple(REGISTRY)  # every target, in the registry's order
METHOD = "hessian"
COLUMNS = ("source", "name", "equation", "params", "degree", "note", "path")
TSV_NAME = "implicit_surface_corpus.tsv"
# Licences whose rows may be copied into implc's own test data (corpus README).
PERMISSIVE = ("CC-BY-4.0", "MIT", "Apache-2.0")

# Outcomes of a row.
COMPILED = "compiled"  # loaded, derived, checked, emitted and validated on every target
REJECTED = "rejected"  # implc refused it with a reason (ImplcError)
FAILED = "failed"  # an implc bug: invalid shader, wrong numbers or an unexpected exception


@dataclass(frozen=True)
class Row:
    """One corpus row; `number` is its 1-based data-row number in the shared TSV."""

    number: int
    source: str
    name: str
    equation: str
    params: dict[str, object]
    degree: int | None
    note: str
    path: str

    @property
    def licence(self) -> str:
        """The licence named in the source column, e.g. 'CC-BY-4.0' or 'GPL-2'."""
        match = re.search(r"(CC-BY-[\d.]+|MIT|Apache-[\d.]+|GPL-[\d.]+)", self.source)
        return match.group(1) if match else "unknown"

    @property
    def project(self) -> str:
        """The upstream repository, e.g. 'IMAGINARY/SURFER-Galleries'."""
        return self.source.split()[0]

    @property
    def free_params(self) -> tuple[str, ...]:
        """Names the note marks as free upstream (`free:R,r`): sliders without a value."""
        match = re.search(r"free:([\w,]+)", self.note)
        return tuple(match.group(1).split(",")) if match else ()


@dataclass
class RowResult:
    """What happened to one row (picklable: it comes back from worker processes)."""

    row: Row
    outcome: str = COMPILED
    reason: str = ""  # the ImplcError message, or the failure, without location
    location: str = ""  # the first line of the rendered diagnostic, when located
    targets: dict[str, str] = field(default_factory=dict)  # target -> ok|rejected|invalid|-
    numeric: str = ""  # "ok (N points)" or what disagreed
    seconds: float = 0.0
    detail: str = ""  # tool messages or a traceback for failures
    tool_missing: str = ""  # a ToolError message: the run cannot judge this target


# --------------------------------------------------------------------------- loading


def default_tsv() -> Path | None:
    """The shared corpus beside the checkout (`../shared/corpus/`), if it is there."""
    here = Path(__file__).resolve().parent.parent
    for base in (Path.cwd(), here):
        candidate = base.parent / "shared" / "corpus" / TSV_NAME
        if candidate.is_file():
            return candidate
    return None


def load_rows(path: Path) -> list[Row]:
    """Read a corpus TSV (the shared one, or a copy with an extra leading `row` column)."""
    try:
        text = read_input(path, "a corpus TSV").decode("utf-8")
    except UnicodeDecodeError as err:
        raise InputError(f"{path}: not UTF-8 text (byte {err.start})") from None
    reader = csv.DictReader(text.splitlines(), delimiter="\t")
    missing = [c for c in COLUMNS if c not in (reader.fieldnames or [])]
    if missing:
        raise InputError(f"{path}: not a corpus TSV (missing column {missing[0]!r})")
    rows = []
    for index, record in enumerate(reader, 1):
        number = int(record["row"]) if record.get("row") else index
        try:
            params = json.loads(record["params"]) if record["params"].strip() else {}
        except json.JSONDecodeError:
            params = {"<invalid JSON>": record["params"]}
        degree = record["degree"].strip()
        rows.append(Row(
            number=number,
            source=record["source"],
            name=record["name"],
            equation=record["equation"],
            params=params if isinstance(params, dict) else {"<not an object>": params},
            degree=int(degree) if degree.isdigit() else None,
            note=record["note"] or "",
            path=record["path"] or "",
        ))
    return rows


def row_surface(row: Row, limits=None):
    """The row as `implc compile -e EQUATION --param NAME=repr(float(VALUE)) ...` loads it,
    with the parameters its equation names (upstream rows may list more: a family's
    parameters that this member does not use, which `--param` refuses).

    Raises `InputError` with the reason when implc refuses the row.
    """
    from .loaders import load_surface
    from .loaders.common import equation_words

    args = []
    named = equation_words(row.equation)
    for name, value in row.params.items():
        if name not in named:
            continue
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise InputError(f"parameter '{name}' has no numeric value in the corpus")
        args.append(f"{name}={float(value)!r}")
    try:
        return load_surface(equation=row.equation, params=args, limits=limits)
    except InputError as err:
        names = re.findall(r"'(\w+)'", err.message)
        if (err.message.startswith("unknown name") and names
                and all(name in row.free_params for name in names)):
            what = "a free parameter" if len(names) == 1 else "free parameters"
            err.message = f"{err.message}: {what} upstream, with no value in the corpus"
            err.args = (err.message,)
        raise


# --------------------------------------------------------------------------- one row


def run_row(
    row: Row,
    targets: Sequence[str] = TARGETS,
    validate: bool = True,
    check: bool = True,
    limits=None,
) -> RowResult:
    """Load, derive, check, emit and validate one row; never raises (bugs are results)."""
    start = time.perf_counter()
    result = RowResult(row, targets={t: "-" for t in targets})
    try:
        _run_row(result, targets, validate, check, limits)
    except ToolError as err:
        result.tool_missing = str(err)
    except ImplcError as err:
        result.outcome = REJECTED
        result.reason = err.message if isinstance(err, InputError) else str(err)
        first = err.render().splitlines()[0]
        result.location = first if re.match(r"\S+:\d+:\d+: error: ", first) else ""
        for target, status in result.targets.items():
            if status == "-":
                result.targets[target] = "rejected"
    except Exception as err:  # an implc bug: report it with its traceback, keep going
        result.outcome = FAILED
        result.reason = f"internal error: {type(err).__name__}: {_first_line(err)}"
        result.detail = traceback.format_exc(limit=8)
    result.seconds = time.perf_counter() - start
    return result


def _run_row(result: RowResult, targets, validate: bool, check: bool, limits) -> None:
    from .emit import build_functions, emit
    from .methods import get_method
    from .validate import validate_text

    surface = row_surface(result.row, limits)
    # derive once; limits checked here
    build_functions(surface.expr, get_method(METHOD), surface.limits.max_derived)
    if check:
        result.numeric = numeric_check(surface.expr, seed=result.row.number)
        if not result.numeric.startswith("ok"):
            result.outcome = FAILED
            result.reason = f"numeric check: {result.numeric}"
    for target in targets:
        text = emit(surface, target, METHOD)
        if not validate:
            result.targets[target] = "emitted"
            continue
        verdict = validate_text(text, target, f"row{result.row.number}.{target}")
        result.targets[target] = "ok" if verdict.ok else "invalid"
        if not verdict.ok:
            result.outcome = FAILED
            result.reason = result.reason or f"{target} shader failed validation"
            result.detail += f"--- {target} ({verdict.tool})\n{verdict.messages}\n"


def _first_line(err: BaseException) -> str:
    text = str(err).strip().splitlines()
    return text[0][:200] if text else ""


# --------------------------------------------------------------------------- numbers


def numeric_check(expr, seed: int, n: int = 96) -> str:
    """Derivatives against finite differences and optimized programs against the plain
    expressions, at `n` seeded random points in [-1, 1]^3 with unit directions.

    Returns "ok (K of N points smooth)" or a description of the first disagreement.
    Points where S is not finite, or where two finite-difference steps disagree (a kink
    of abs/min/max/sign, a cusp of a real root: the derivative is taken by branch there),
    are not compared; everywhere else agreement is required.
    """
    import numpy as np

    from .derive import Derivatives
    from .emit import build_functions, function_quantities
    from .methods import get_method
    from .numeric import evaluate, evaluate_program
    from .symbols import DIRECTION, POINT

    rng = np.random.default_rng(seed)
    p = rng.uniform(-1.0, 1.0, (n, 3))
    u = rng.normal(size=(n, 3))
    u /= np.linalg.norm(u, axis=1, keepdims=True)

    def env(q):
        bound = {s: q[:, i] for i, s in enumerate(POINT)}
        bound.update({s: u[:, i] for i, s in enumerate(DIRECTION)})
        return bound

    def at(q):
        return evaluate(expr, env(q))

    d = Derivatives(expr)
    here = env(p)
    with np.errstate(all="ignore"):
        base = at(p)
        checks = []
        for k, axis in enumerate(np.eye(3)):
            checks.append((f"dS/d{'xyz'[k]}", evaluate(d.gradient[k], here),
                           *_central(at, p, axis)))
        checks.append(("F'", evaluate(d.directional, here), *_central(at, p, u)))
        checks.append(("F''", evaluate(d.second_directional, here), *_second(at, p, u)))
        smooth_all = np.isfinite(base)
        for label, exact, fd, fd_half, rtol in checks:
            smooth = (np.isfinite(exact) & np.isfinite(fd) & np.isfinite(fd_half)
                      & (np.abs(fd - fd_half) <= 1e-3 * (1.0 + np.abs(fd))) & np.isfinite(base))
            smooth_all &= smooth
            if not smooth.any():
                continue
            scale = 1.0 + np.abs(fd[smooth]).max()
            bad = smooth & ~(np.abs(exact - fd) <= rtol * np.abs(fd) + rtol * 1e-1 * scale)
            if bad.any():
                i = int(np.flatnonzero(bad)[0])
                return (f"{label} = {exact[i]:.6g} but finite differences give {fd[i]:.6g} "
                        f"at p = {tuple(round(float(c), 4) for c in p[i])} "
                        f"({int(bad.sum())} of {n} points)")
        method = get_method(METHOD)
        for name, program in build_functions(expr, method).items():
            original = [e for q in function_quantities(method)[name] for e in d.quantity(q)]
            got = evaluate_program(program.assignments, program.outputs, here)
            for k, (g, o) in enumerate(zip(got, original, strict=True)):
                want = np.broadcast_to(evaluate(o, here), (n,))
                g = np.broadcast_to(g, (n,))
                finite = np.isfinite(want)
                scale = 1.0 + (np.abs(want[finite]).max() if finite.any() else 0.0)
                bad = finite & ~(np.abs(g - want) <= 1e-9 * scale)
                if bad.any():
                    i = int(np.flatnonzero(bad)[0])
                    return (f"optimized {name}[{k}] = {g[i]:.12g} but the expression gives "
                            f"{want[i]:.12g} ({int(bad.sum())} of {n} points)")
    return f"ok ({int(smooth_all.sum())} of {n} points smooth)"


def _central(at, p, direction, h: float = 1e-5):
    """Central differences with steps h and h/2, and the tolerance they support."""
    fd = (at(p + h * direction) - at(p - h * direction)) / (2 * h)
    half = (at(p + h / 2 * direction) - at(p - h / 2 * direction)) / h
    return fd, half, 1e-4


def _second(at, p, direction, h: float = 1e-3):
    """Second differences with steps h and h/2 (a larger step: they divide by h^2)."""
    def second(step):
        return (at(p + step * direction) - 2 * at(p) + at(p - step * direction)) / step**2
    return second(h), second(h / 2), 1e-2


# --------------------------------------------------------------------------- many rows


def run_corpus(
    rows: Iterable[Row],
    targets: Sequence[str] = TARGETS,
    *,
    validate: bool = True,
    check: bool = True,
    jobs: int = 1,
    limits=None,
    progress: Callable[[RowResult], None] | None = None,
    targets_of: Callable[[Row], Sequence[str]] | None = None,
    executor: Executor | None = None,
) -> list[RowResult]:
    """`run_row` over every row, on `executor` (e.g. a Dask cluster's) or else in `jobs`
    local worker processes; results in row order.

    `targets_of(row)`, when given, chooses the targets row by row (e.g. a sample of rows
    on a slow validator) instead of `targets`.
    """
    rows = list(rows)

    def chosen(row: Row) -> tuple[str, ...]:
        return tuple(targets_of(row) if targets_of else targets)

    results: list[RowResult] = []
    if executor is None and (jobs <= 1 or len(rows) <= 1):
        for row in rows:
            results.append(run_row(row, chosen(row), validate, check, limits))
            if progress:
                progress(results[-1])
    else:
        pool = executor or local_executor(jobs)
        try:
            futures = [pool.submit(run_row, row, chosen(row), validate, check, limits)
                       for row in _costliest_first(rows)]
            for future in futures:
                results.append(future.result())
                if progress:
                    progress(results[-1])
        except BaseException:
            stop_executor(pool)
            raise
        if executor is None:
            pool.shutdown(wait=True)
    results.sort(key=lambda r: r.row.number)
    missing = next((r.tool_missing for r in results if r.tool_missing), "")
    if missing:
        raise ToolError(missing)
    return results


def _costliest_first(rows: list[Row]) -> list[Row]:
    """Long equations first, so two workers finish together (the slow rows are long)."""
    return sorted(rows, key=lambda r: -len(r.equation))


def permissive(rows: Iterable[Row]) -> list[Row]:
    """Rows whose licence lets implc copy them into its own test data."""
    return [r for r in rows if r.licence in PERMISSIVE]


__all__ = [
    "COMPILED", "FAILED", "REJECTED", "TARGETS", "Row", "RowResult", "default_tsv",
    "load_rows", "numeric_check", "permissive", "row_surface", "run_corpus",
    "run_row",
]
