"""Malformed equations and the exact diagnostics users see for them.

The cases live in tests/data/malformed.txt (format described in its header), so the
messages can be read and reviewed as a list; each one is pinned byte for byte.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

import pytest
from cpu_bound import cpu_limit

from implc.errors import InputError, LimitError, Source
from implc.parse import parse_equation

DATA = Path(__file__).parent / "data" / "malformed.txt"
_ESCAPE = re.compile(r"\\(n|t|0|\\|u[0-9A-Fa-f]{4}|.)")
_SIMPLE_ESCAPES = {"n": "\n", "t": "\t", "0": "\0", "\\": "\\"}


@dataclass(frozen=True)
class Case:
    title: str
    text: str
    expected: str


def unescape(line: str) -> str:
    def replace(match: re.Match[str]) -> str:
        code = match.group(1)
        if code in _SIMPLE_ESCAPES:
            return _SIMPLE_ESCAPES[code]
        if code.startswith("u") and len(code) == 5:
            return chr(int(code[1:], 16))
        raise ValueError(f"unknown escape \\{code} in {DATA.name}: {line!r}")

    return _ESCAPE.sub(replace, line)


def load_cases() -> list[Case]:
    cases: list[Case] = []
    blocks = re.split(r"^=== ", DATA.read_text(encoding="utf-8"), flags=re.MULTILINE)[1:]
    for block in blocks:
        title, input_line, *expected = block.rstrip("\n").split("\n")
        assert input_line.startswith("input: "), f"case {title!r}: no input line"
        while expected and (not expected[-1] or expected[-1].startswith("#")):
            expected.pop()
        text = unescape(input_line[len("input: ") :])
        cases.append(Case(title, text, "\n".join(unescape(line) for line in expected)))
    return cases


CASES = load_cases()


def test_the_data_file_has_enough_cases() -> None:
    assert len(CASES) >= 30
    assert len({case.title for case in CASES}) == len(CASES), "titles must be unique"


@pytest.mark.parametrize("case", CASES, ids=[case.title for case in CASES])
def test_diagnostic_is_pinned(case: Case) -> None:
    # a hang guard in CPU time (tests/cpu_bound.py): a case takes 1 ms typically and 20 ms
    # at most, so 5 s is 250x the costliest and a busy machine cannot trip it
    with cpu_limit(5.0, f"rejecting {case.title!r}"), pytest.raises(InputError) as caught:
        parse_equation(Source("<equation>", case.text))
    assert caught.value.render() == case.expected


@pytest.mark.parametrize("case", CASES, ids=[case.title for case in CASES])
def test_messages_follow_the_style(case: Case) -> None:
    with pytest.raises(InputError) as caught:
        parse_equation(Source("<equation>", case.text))
    message = caught.value.message
    assert message == message.rstrip(". "), "no trailing period"
    assert message[0].islower() or message[0] in "'(", "messages start in lower case"
    if isinstance(caught.value, LimitError):
        assert message.startswith("too complex: ")
        assert re.search(r"\(--max-[a-z-]+\)$", message), "a limit names its option"


def test_position_inside_a_toml_string_is_shifted() -> None:
    # equation = "x^2 + @" with the string's first character on line 3, column 11
    source = Source("cross-cap.toml", "x^2 + @", line=3, col=11)
    with pytest.raises(InputError) as caught:
        parse_equation(source)
    assert caught.value.render() == (
        "cross-cap.toml:3:17: error: unexpected character '@'\n  x^2 + @\n        ^"
    )


def test_position_on_a_later_line_of_a_toml_string_restarts_at_column_one() -> None:
    # a multi-line TOML string: the second line of the equation is line 4 of the file
    source = Source("cross-cap.toml", "x^2 +\ny^2 + sinn(z)", line=3, col=11)
    with pytest.raises(InputError) as caught:
        parse_equation(source)
    assert caught.value.render() == (
        "cross-cap.toml:4:7: error: unknown function 'sinn'; did you mean 'sin'?\n"
        "  y^2 + sinn(z)\n"
        "        ^~~~"
    )
