"""Fuzzing the front end and the whole compile path.

Two generators feed the same properties:

- grammar-based: hypothesis strategies that write equations the way people do (numbers
  in every notation, x y z, parameters, constants, every user function with its arity
  and sometimes a wrong one, `+ - * / ^ **`, implicit products such as `2x`, `x y`,
  `(x+1)(y-1)`, `( )` and `[ ]`, signs, `=`);
- mutation-based: corpus equations, malformed.txt and hostile.txt inputs with bytes,
  characters and tokens inserted, deleted, replaced, duplicated and spliced.

Properties, each under a per-case CPU-time bound (a hang fails the case; a busy machine
does not):

1. the parser raises `InputError` (located, rendered without error) or returns a sympy
   expression in x, y, z and nothing else; its printed form (`Surface.equation`, the
   shader header) parses back to the same function;
2. the whole path (parse -> derive -> optimize -> emit) gives a shader for every
   target of the registry, or stops with "too complex" (`--max-derived`); any other
   error means the parser accepted something a later stage cannot handle (a printer
   meeting inf or a non-real constant);
3. every shader of a random sample of each target validates with its real compiler
   (each target's validator).

`make test` runs a short derandomized pass (1,230 examples: ~4,000 parser and ~300
whole-path cases counted, ~20 s); `make fuzz` sets IMPLC_FUZZ_SCALE (see the Makefile)
for 100,000+ cases with a fresh seed each run. A summary of case counts goes to the
terminal at the end (`-s` shows it under pytest -q).
Findings are pinned in test_fuzz_regressions below or in tests/data/malformed.txt.
"""

from __future__ import annotations

import os
import random
import re
import sys
import time
from collections import Counter
from contextlib import contextmanager
from pathlib import Path

import numpy as np
import pytest
import sympy
from cpu_bound import cpu_limit, cpu_seconds
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

from implc.errors import ImplcError, InputError, LimitError, Source
from implc.front import Limits, parse_equation
from implc.functions import BY_SYMPY_NAME, USER_FUNCTIONS
from implc.symbols import X, Y, Z
from implc.targets import TARGETS

DATA = Path(__file__).parent / "data"
SCALE = float(os.environ.get("IMPLC_FUZZ_SCALE", "1"))
PATH_SCALE = float(os.environ.get("IMPLC_FUZZ_PATH_SCALE", str(SCALE)))
LONG = SCALE > 1
PARAMS = {"a": sympy.Rational(3, 4), "b": sympy.Rational(-5, 2), "phi": sympy.Rational(
    1618033988749895, 10**15), "R": sympy.Integer(2)}
# Hang guards, CPU seconds per case (tests/cpu_bound.py). Measured on the make-test pass
# (3,782 cases in 22 s; the summary line prints the costliest of each kind): a parser
# case takes 0.02 s at most, a whole-path case 0.07 s typically and 0.67 s at most (at
# IMPLC_FUZZ_SCALE=20, 34,976 cases: 0.46 s and 0.72 s at most, the parse one re-reading
# a long printed equation), so each bound is 10x or more of the costliest case and 70x or
# more of the typical one, and a busy machine cannot trip it; a real hang (the Endrass
# octic's mutation, 81 s before front.build.fold_constants) still fails.
PARSE_SECONDS = 5.0  # per parser case
PATH_SECONDS = 30.0  # per whole-path case (derive + CSE + print)
PATH_MAX_DERIVED = 60_000  # the bound on work that keeps a whole-path case small
SLOWEST: dict[str, tuple[float, str]] = {}  # kind -> (CPU seconds, case) of the costliest
STATS: Counter = Counter()


def examples(short: int, scale: float = SCALE) -> int:
    return max(1, int(short * scale))


def profile(short: int, scale: float = SCALE):
    """Settings of one fuzz test: `short` cases in make test, `scale` times more in make
    fuzz (IMPLC_FUZZ_SCALE, and IMPLC_FUZZ_PATH_SCALE for the slower whole-path tests)."""
    return settings(
        max_examples=examples(short, scale),
        deadline=None,  # the per-case timer below is the bound; hypothesis' deadline is noisy
        derandomize=not LONG,
        database=None,
        suppress_health_check=list(HealthCheck),
        print_blob=True,
    )


@contextmanager
def bounded(seconds: float, kind: str, what: str):
    """Run one case under a CPU-time hang guard (tests/cpu_bound.py: a busy machine does
    not trip it) and keep the costliest case of each kind for the summary line, which is
    how the bounds below were chosen."""
    start = cpu_seconds()
    with cpu_limit(seconds, what):
        yield
    spent = cpu_seconds() - start
    if spent > SLOWEST.get(kind, (0.0, ""))[0]:
        SLOWEST[kind] = (spent, what[:60])


# --------------------------------------------------------------------------- grammar


def _number() -> st.SearchStrategy[str]:
    digits = st.text("0123456789", min_size=1, max_size=4)
    return st.one_of(
        st.integers(0, 99).map(str),
        st.tuples(digits, digits).map(lambda t: f"{t[0]}.{t[1]}"),
        digits.map(lambda d: f".{d}"),
        st.tuples(st.integers(1, 9), st.sampled_from("eE"), st.sampled_from(["", "+", "-"]),
                  st.integers(0, 40)).map(lambda t: f"{t[0]}{t[1]}{t[2]}{t[3]}"),
        st.sampled_from(["0", "1", "2", "0.5", "1e-3", "2E+4", "1e30", "1e-30", "3.0"]),
    )


VARIABLES = st.sampled_from(["x", "y", "z"])
ATOMS = st.one_of(
    VARIABLES, VARIABLES, VARIABLES,  # weighted: most equations should depend on x, y, z
    st.sampled_from(["xy", "xyz", "zx", "yy", "xz"]),  # words of x, y, z: products
    st.sampled_from(["a", "b", "phi", "R", "pi", "e", "PI"]),
    _number(),
)
SPACE = st.sampled_from(["", "", "", " ", "  "])
FUNCTIONS = sorted(USER_FUNCTIONS)


def _juxtapose(parts: tuple[str, str, str]) -> str:
    """An implicit product as people write one: `2x`, `x y`, `xy`, `(x+1)(x-1)`, `2 (x)`.

    A number on the right needs brackets (`x 2` is an error by design); two words are
    glued only when both are made of x, y, z (`x` `y` -> `xy`), else spaced (`a x`)."""
    left, glue, right = parts
    if right[:1].isdigit() or right[:1] == ".":
        right = f"({right})"
    word = re.compile(r"[A-Za-z_0-9]")
    if word.match(left[-1:]) and word.match(right[:1]):
        tail = re.search(r"[A-Za-z_0-9.]*$", left).group()
        head = re.match(r"[A-Za-z_0-9]*", right).group()
        if not (set(tail) <= set("xyz") and set(head) <= set("xyz")):
            glue = " "
    return f"{left}{glue}{right}"


def _extend(inner: st.SearchStrategy[str]) -> st.SearchStrategy[str]:
    binary = st.tuples(inner, SPACE, st.sampled_from(["+", "-", "*", "/", "^", "**", "+", "*"]),
                       SPACE, inner).map(lambda t: "".join(t))
    implicit = st.tuples(inner, st.sampled_from(["", " "]), inner).map(_juxtapose)
    power = st.tuples(inner, st.sampled_from(["^", "**"]), st.one_of(
        st.integers(-4, 12).map(lambda n: f"({n})" if n < 0 else str(n)),
        st.sampled_from(["(1/3)", "(2/3)", "0.5", "(-1/3)", "(1/2)", "x", "2"]),
        inner)).map(lambda t: "".join(t))
    group = st.tuples(st.sampled_from(["()", "[]", "()"]), inner).map(
        lambda t: f"{t[0][0]}{t[1]}{t[0][1]}")
    sign = st.tuples(st.sampled_from(["-", "+", "-"]), inner).map(lambda t: "".join(t))

    @st.composite
    def call(draw) -> str:
        name = draw(st.sampled_from(FUNCTIONS))
        arity = USER_FUNCTIONS[name].arity
        if draw(st.integers(0, 19)) == 0:
            arity = draw(st.integers(0, 3))  # a wrong arity now and then
        args = [draw(inner) for _ in range(arity)]
        return f"{name}({', '.join(args)})"

    return st.one_of(binary, implicit, power, group, sign, call())


EXPRESSIONS = st.tuples(st.recursive(ATOMS, _extend, max_leaves=24), VARIABLES,
                        st.integers(0, 19)).map(
    # most random trees are constant; add a variable to 19 of 20 of those
    lambda t: t[0] if re.search("[xyz]", t[0]) or t[2] == 0 else f"{t[0]} + {t[1]}")
EQUATIONS = st.one_of(
    EXPRESSIONS,
    st.tuples(EXPRESSIONS, SPACE, SPACE, st.one_of(_number(), EXPRESSIONS))
    .filter(lambda t: t[0] != t[3])
    .map(lambda t: f"{t[0]}{t[1]}={t[2]}{t[3]}"),
)


# --------------------------------------------------------------------------- mutation


def _seeds() -> list[str]:
    """Corpus equations (the permissive copy), malformed.txt and short hostile.txt inputs."""
    import csv

    seeds: list[str] = []
    with (DATA / "corpus_permissive.tsv").open(encoding="utf-8") as handle:
        seeds += [row["equation"] for row in csv.DictReader(handle, delimiter="\t")]
    for line in (DATA / "malformed.txt").read_text(encoding="utf-8").splitlines():
        if line.startswith("input: "):
            seeds.append(line[len("input: "):])
    for line in (DATA / "hostile.txt").read_text(encoding="utf-8").splitlines():
        if line.startswith("-e: ") and "\\*" not in line:
            seeds.append(line[len("-e: "):])
    return seeds


SEEDS = _seeds()
ALPHABET = list("xyz0123456789.eE+-*/^()[],= abcpiqsnt_") + [
    "**", "sin(", "sqrt(", "max(", "^-", "1e308", "0.0", "/0", "\0", "\t", "\n", "\u2212",
    "\u00b2", "\u0445", "\ufeff", "PI", "xyz", "((", "))", "^2^2^2", "9^9", "e^", "=0",
]
TOKEN = re.compile(r"\d+\.?\d*(?:[eE][+-]?\d+)?|\.\d+|[A-Za-z_]\w*|\*\*|\S")


@st.composite
def mutants(draw) -> str:
    text = draw(st.sampled_from(SEEDS))
    if draw(st.booleans()):
        other = draw(st.sampled_from(SEEDS))  # splice two seeds
        cut_a = draw(st.integers(0, len(text)))
        cut_b = draw(st.integers(0, len(other)))
        text = text[:cut_a] + other[cut_b:]
    for _ in range(draw(st.integers(1, 6))):
        kind = draw(st.integers(0, 6))
        pos = draw(st.integers(0, len(text)))
        if kind == 0:  # insert a character or a fragment
            text = text[:pos] + draw(st.sampled_from(ALPHABET)) + text[pos:]
        elif kind == 1 and text:  # delete a run of characters
            text = text[:pos] + text[pos + draw(st.integers(1, 4)):]
        elif kind == 2 and text:  # replace one character by any code point
            char = chr(draw(st.integers(0, 0x10FFFF).filter(lambda c: not 0xD800 <= c < 0xE000)))
            text = text[:pos] + char + text[pos + 1:]
        elif kind in (3, 4, 5):  # token level: duplicate, delete or swap tokens
            tokens = TOKEN.findall(text)
            if len(tokens) >= 2:
                i = draw(st.integers(0, len(tokens) - 1))
                j = draw(st.integers(0, len(tokens) - 1))
                if kind == 3:
                    tokens.insert(i, tokens[j])
                elif kind == 4:
                    del tokens[i]
                else:
                    tokens[i], tokens[j] = tokens[j], tokens[i]
                glue = draw(st.sampled_from(["", " "]))
                text = glue.join(tokens)
        else:  # flip one byte of the UTF-8 encoding
            data = bytearray(text.encode("utf-8"))
            if data:
                k = min(pos, len(data) - 1)
                data[k] ^= 1 << draw(st.integers(0, 7))
            text = data.decode("utf-8", "replace")
    return text


# --------------------------------------------------------------------------- properties


def check_parse(text: str) -> sympy.Expr | None:
    """Property 1 on one input; returns the expression when it parses."""
    STATS["parser"] += 1
    source = Source("<equation>", text)
    try:
        with bounded(PARSE_SECONDS, "parse", f"parsing {text[:80]!r}"):
            expr = parse_equation(source, PARAMS)
    except InputError as err:
        STATS["parser rejected"] += 1
        rendered = err.render()
        assert rendered.startswith("<equation>:"), rendered
        assert err.message and "Traceback" not in rendered
        return None
    assert isinstance(expr, sympy.Expr)
    assert expr.free_symbols <= {X, Y, Z} and expr.free_symbols
    functions = {type(f).__name__ for f in expr.atoms(sympy.Function)}
    assert functions <= set(BY_SYMPY_NAME), f"{expr} holds {functions - set(BY_SYMPY_NAME)}"
    STATS["parser accepted"] += 1
    check_roundtrip(expr)
    return expr


_POINTS = np.random.default_rng(5).uniform(-0.9, 0.9, (3, 8))
ROOMY = Limits(max_chars=10**7, max_depth=10**4, max_nodes=10**7, max_exponent=10**4,
               max_degree=10**5, max_terms=10**12, max_literal_exponent=330,
               max_constant_digits=3000)


def check_roundtrip(expr: sympy.Expr) -> None:
    """The printed equation (shader headers, `implc show`) parses back to the same S."""
    from implc.numeric import evaluate
    from implc.textform import to_text

    text = to_text(expr)
    try:
        with bounded(PARSE_SECONDS, "parse", f"re-parsing {text[:80]!r}"):
            # the printed form states folded constants (1e-16 * 1e-16 = 1e-32) outside
            # the literal range and spells real roots out: parse it with room
            again = parse_equation(Source("<printed>", text), limits=ROOMY)
    except LimitError:
        # textform prints a rational with a denominator over 1000 as a float's decimal
        # (2^(1/1200) as 2^0.0008333333333333334): exact again only with a huge root
        STATS["printed form over the roomy limits"] += 1
        return
    env = dict(zip((X, Y, Z), _POINTS, strict=True))
    a, b = evaluate(expr, env), evaluate(again, env)
    a, b = np.broadcast_to(a, (8,)), np.broadcast_to(b, (8,))
    # Compared where S is defined: the printed form of a pow-semantics power with an odd
    # denominator (y^0.0072 * y^0.0072 = y^(9/625), NaN for y < 0) reads back as a real
    # root, defined there (textform, reported in docs/CORPUS.md).
    defined = np.isfinite(a)
    assert np.isfinite(b[defined]).all(), f"{expr} printed as {text}: {a} {b}"
    both = defined
    scale = 1.0 + np.abs(a[both]).max(initial=0.0)
    np.testing.assert_allclose(b[both], a[both], rtol=1e-9, atol=1e-9 * scale,
                               err_msg=f"{expr} printed as {text}")


TARGET_NAMES = tuple(TARGETS)  # every target of the registry
# reservoirs of emitted shaders per target, validated by test_sampled_shaders_validate
_SHADERS: dict[str, list[str]] = {target: [] for target in TARGET_NAMES}
# shaders validated per target by one run of test_sampled_shaders_validate: 25 where the
# validator takes a few ms (glslangValidator, naga), fewer where it is slow (PoCL builds
# take ~0.5 s each)
SAMPLE = {target: 25 for target in TARGET_NAMES} | {"opencl": 6}


def check_path(expr: sympy.Expr, rng: random.Random, keep: float = 0.25) -> None:
    """Property 2 (and a sample for property 3) on a parsed expression: the whole path
    to every target's printer; each shader is kept for
    validation with probability `keep`."""
    from implc.emit import emit
    from implc.limits import Limits
    from implc.surface import Surface

    STATS["path"] += 1
    surface = Surface("fuzz", expr, limits=Limits(max_derived=PATH_MAX_DERIVED))
    method = rng.choice(["hessian", "taylor", "curvature"])
    texts = {}
    try:
        with bounded(PATH_SECONDS, "path", f"compiling {expr}"):
            for target in TARGET_NAMES:
                texts[target] = emit(surface, target, method)
    except ImplcError as err:
        STATS["path rejected"] += 1
        assert str(err).startswith(("too complex: ", "too large for float32: ")), err
        return
    STATS["path emitted"] += 1
    for target, text in texts.items():
        STATS[f"emitted {target}"] += 1
        if rng.random() < keep:
            _SHADERS[target].append(text)


def _fill_pools(wanted: dict[str, int]) -> None:
    """Top the pools up from the seeds (corpus rows, mutated), so the sample is never
    empty: when this test runs alone, with -k, or before the whole-path tests."""
    rng = random.Random(13)
    attempts = 0
    while any(len(_SHADERS[t]) < n for t, n in wanted.items()) and attempts < 2000:
        attempts += 1
        text = rng.choice(SEEDS)
        expr = check_parse(text)
        if expr is not None:
            check_path(expr, rng, keep=1.0)


def validate_sample(scale: float) -> Counter:
    """Property 3: a sample of every target's shaders passes its real compiler, then the
    pools are emptied (a missing compiler skips, and fails under CI=true)."""
    from conftest import require_validator

    wanted = {t: examples(n, scale) for t, n in SAMPLE.items()}
    _fill_pools(wanted)
    validated: Counter = Counter()
    for target in TARGET_NAMES:
        pool, _SHADERS[target][:] = list(_SHADERS[target]), []
        sample = random.Random(len(pool)).sample(pool, min(wanted[target], len(pool)))
        validate = require_validator(target)
        for text in sample:
            verdict = validate(text, f"fuzz.{target}")
            STATS["validated"] += 1
            STATS[f"validated {target}"] += 1
            validated[target] += 1
            assert verdict.ok, f"{verdict.messages}\n--- shader header:\n{text[:600]}"
    return validated


@pytest.fixture(scope="module", autouse=True)
def summary():
    start = time.perf_counter()
    yield
    elapsed = time.perf_counter() - start
    line = (f"fuzz: {STATS['parser']} parser cases ({STATS['parser accepted']} parsed, "
            f"{STATS['parser rejected']} rejected), {STATS['path']} whole-path cases "
            f"({STATS['path emitted']} x {len(TARGET_NAMES)} targets emitted, "
            f"{STATS['path rejected']} over the bound), {STATS['validated']} validated ("
            + ", ".join(f"{t} {STATS[f'validated {t}']}" for t in TARGET_NAMES) + "); "
            f"{STATS['parser'] + STATS['path']} cases in "
            f"{elapsed:.0f} s")
    for kind, (seconds, case) in sorted(SLOWEST.items()):
        line += f"; costliest {kind} case {seconds:.2f} s CPU ({case})"
    print("\n" + line)
    out = os.environ.get("IMPLC_FUZZ_SUMMARY")
    if out:
        Path(out).write_text(line + "\n", encoding="utf-8")


_BAR = None  # make fuzz: a progress bar with an ETA per fuzz test (on a terminal)


@pytest.fixture(autouse=True)
def fuzz_progress(request):
    """On a terminal under `make fuzz` (-s), a tqdm bar per test over its max_examples;
    plain pytest output otherwise (the bar is off in the short pass)."""
    global _BAR
    chosen = getattr(request.function, "_hypothesis_internal_use_settings", None)
    if LONG and chosen is not None:
        from implc.progress import Progress

        _BAR = Progress(chosen.max_examples, request.node.name, sys.stderr, unit="case")
    yield
    if _BAR is not None:
        _BAR.close()
        _BAR = None


def tick() -> None:
    if _BAR is not None:
        _BAR.step()


@profile(600)
@given(EQUATIONS)
def test_grammar_parser(text):
    tick()
    check_parse(text)


@profile(400)
@given(mutants())
def test_mutation_parser(text):
    tick()
    check_parse(text)


@profile(150, PATH_SCALE)
@given(EQUATIONS, st.randoms(use_true_random=False))
def test_grammar_whole_path(text, rng):
    tick()
    expr = check_parse(text)
    assume(expr is not None)
    check_path(expr, rng)


@profile(80, PATH_SCALE)
@given(mutants(), st.randoms(use_true_random=False))
def test_mutation_whole_path(text, rng):
    tick()
    expr = check_parse(text)
    assume(expr is not None)
    check_path(expr, rng)


def test_sampled_shaders_validate():
    """Validates the shaders the whole-path tests kept (they run first in file order) and,
    when there are too few (run alone, with -k, in another order), shaders it makes from
    the seeds: every target's full sample is validated, whatever ran before."""
    validated = validate_sample(PATH_SCALE)
    assert validated == Counter({t: examples(n, PATH_SCALE) for t, n in SAMPLE.items()})


# --------------------------------------------------------------------------- findings

# Inputs the fuzzers found, each fixed; pinned here with the outcome they must have
# ("ok": parses, compiles and validates on every target; else the start of the parser's
# message). Diagnostics found by fuzzing are pinned in tests/data/malformed.txt too.
REGRESSIONS: list[tuple[str, str]] = [
    # sympy left d|acos(x)|/dx as re/im terms and d sign(acos(x))/dx as an unevaluated
    # Derivative: the printer raised (implc.derive.branch_diff)
    ("acos(x)^(1/3) + y", "ok"),
    ("abs(log(x)) + y^2 + z", "ok"),
    ("sign(sqrt(x)) + abs(asin(y)) + z - 1", "ok"),
    ("x^(1/3) + acos(y/2)^(2/3) + z", "ok"),
    # a non-real constant reached the printer ("the constant acos(pi) is not ...")
    ("acos(pi) x", "value is not a real number"),
    # hangs in sympy's exact arithmetic, now bounded before sympy starts
    ("1 ** 4E-21^1e-30 x", "too complex: root of a constant"),
    ("R^abs(7e23) * (pi) + x", "too complex: constant power"),
    ("e^(10^20*log(2)) + x", "too complex: constant power"),
    ("x^(sin(pi) + 1000)", "too complex: exponent 1000"),
    # folded constants outside the literal range still print and re-parse (roundtrip)
    ("x(1e-15)(1e-16)", "ok"),
    ("x(2)(1e30)", "ok"),
    ("y^0.0072*y^0.0072 + x", "ok"),
    # a constant base <= 0 with a variable exponent: log(b) in the derivatives was nan
    ("0^x", "the base of a variable exponent must be positive"),
    ("(1-pi)^x + y", "the base of a variable exponent must be positive"),
    ("sin(0)^x + y", "the base of a variable exponent must be positive"),
    # constants only sympy could evaluate reached the printer as non-real or inf
    ("x cos(-5/2)^(3/4)", "value is not a real number"),
    ("x+3.0^647.1", "too complex: constant power"),
    ("x + (1e20 pi)^64", "too complex: constant power"),
    ("pi^64 * 10^290 * e^64 + x", "too complex: constant value"),
    ("x + 2^0.5 + cos(1)^0.5 y", "ok"),
    # exp(k log u) becomes u^k inside sympy: 2^(10^20) hung; x^100 passed --max-exponent
    ("e ^ ( 10 ^ 20 * log ( 2 x ) + 8)", "too complex: exponent about 1e+20"),
    ("exp(100*log(x))", "too complex: exponent about 100"),
    ("exp(3*log(x)) + y + exp(pi*log(z^2+1))", "ok"),
    # printed forms that need a huge root to be exact again (skipped by the roundtrip)
    ("(2^(3/60))^(1/60) + x", "ok"),
    ("x^a^10.0004", "ok"),
    ("2e-2^(8(.0002)) + x", "ok"),
    # a base only sympy evaluates to a rational, under a root with a huge denominator
    ("abs(9E28)^.9195**(-2) abs(9E28) + z = 2", "too complex: root of a constant"),
    ("(abs(4e-21) x)^(1/10000)", "too complex: root of a constant"),
    ("abs(9E28y)^.9195**(-2) + z", "too complex: root of a constant"),
    # sympy splits sqrt(c x^2) into sqrt(c) |x|: a negative c reached the printer
    ("sqrt(tan(phi)xx)", "value is not a real number"),
    ("sqrt(cos(3) x^2) + y", "value is not a real number"),
    # sympy rewrites tan(x + 3pi/4) as -cot(x + pi/4); no target prints cot
    ("x=tan(x+a pi)", "ok"),
    ("tan(pi/2 - x) + y", "ok"),
    # an irrational constant exponent of a variable: x^4e158 reached the printer as inf
    ("x^1e26^6.1", "too complex: exponent about 3.98e+158"),
    # sympy raised while comparing a non-real argument of max
    ("max(a, cos(2.0)^0.5)", "value is not a real number"),
    # sympy raised in its assumptions on log(tanh(32)) = -2.5e-28 while differentiating
    ("tanh(32)^(x y)", "the base of a variable exponent is 1 to 15 digits"),
    ("2^x + tanh(3)^y", "ok"),
    # sympy expands (1e30 x)^11 to 10^330 x^11: the coefficient printed as inf
    ("x(1e30 x)^11", "too complex: constant value"),
]


@pytest.mark.parametrize(("text", "outcome"), REGRESSIONS)
def test_fuzz_regressions(text, outcome):
    from conftest import require_validator

    from implc.emit import emit
    from implc.surface import Surface

    if outcome != "ok":
        with pytest.raises(InputError) as caught:  # the bare message (str() adds the caret)
            parse_equation(Source("<equation>", text), PARAMS)
        assert caught.value.message.startswith(outcome), caught.value.message
        return
    expr = check_parse(text)
    assert expr is not None
    for target in TARGETS:
        shader = emit(Surface("regression", expr), target, "hessian")
        verdict = require_validator(target)(shader, f"regression.{target}")
        assert verdict.ok, verdict.messages


@pytest.mark.parametrize("target", TARGET_NAMES)
def test_constants_beyond_float32_are_refused(target):
    """Found by the fuzzer: a folded constant past float32's range (7e24 * 5e23) printed
    as a literal WGSL refuses (GLSL makes it inf). Every float32 shader refuses it with a
    message; OpenCL in double precision prints and builds it."""
    from conftest import require_validator

    from implc.emit import emit
    from implc.surface import Surface
    from implc.targets import get_target

    expr = check_parse("x(7e24)(5e23) z + y")
    with pytest.raises(InputError, match="^too large for float32: the constant 3.5e\\+48"):
        emit(Surface("fuzz", expr), target, "taylor")
    if "double" in get_target(target).precisions:
        shader = emit(Surface("fuzz", expr), target, "taylor", precision="double")
        verdict = require_validator(target)(shader, f"fuzz.{target}")
        assert verdict.ok, verdict.messages
