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
from implc.front import Limits, parse_equation

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


# --------------------------------------------------------------------------- issue 23


def _caret_column(rendered: str) -> int:
    return rendered.split("\n")[2].index("^")


@pytest.mark.parametrize("at", [5, 30_000, 59_990])
def test_a_long_line_is_cut_to_a_window_around_the_caret(at: int) -> None:
    """A 60,000-character equation echoed whole was a 20,003-character caret line (issue
    23, point 10): the line is cut to about 100 columns around the caret, `...` where it
    was cut, and the header keeps the real column."""
    text = "x+" * 30_000
    text = text[:at] + "@" + text[at + 1:]
    with pytest.raises(InputError) as caught:
        parse_equation(Source("<equation>", text),
                       limits=Limits(max_chars=100_000, max_nodes=100_000))
    rendered = caught.value.render()
    header, shown, caret = rendered.split("\n")
    assert header == f"<equation>:1:{at + 1}: error: unexpected character '@'"
    assert len(shown) <= 2 + 100 and len(caret) <= 2 + 100, rendered
    assert shown[_caret_column(rendered)] == "@", rendered
    assert shown.startswith("  ...") == (at > 100)
    assert shown.endswith("...") == (at < 59_900)


def test_the_length_limit_shows_where_the_limit_falls() -> None:
    text = "x+" * 30_000 + "x"
    with pytest.raises(LimitError) as caught:
        parse_equation(Source("<equation>", text))
    rendered = caught.value.render()
    assert rendered.startswith("<equation>:1:20001: error: too complex: input length 60001 ")
    assert max(len(line) for line in rendered.split("\n")[1:]) <= 102, rendered
    shown = rendered.split("\n")[1]
    column = _caret_column(rendered)
    assert shown[column - 3:column + 3] == text[20_000 - 3:20_000 + 3]


def test_a_span_cut_by_the_window_ends_at_its_edge() -> None:
    text = "x + " + "y" * 500 + "(x)"  # 'yyy...y(' is an unknown function
    with pytest.raises(InputError) as caught:
        parse_equation(Source("<equation>", text))
    shown, caret = caught.value.render().split("\n")[1:]
    assert shown.endswith("...") and len(shown) <= 2 + 100
    assert caret == "  " + " " * 4 + "^" + "~" * (len(shown) - 3 - 2 - 5)  # to the cut


def test_wide_characters_take_two_columns() -> None:
    """A terminal shows a full-width character two columns wide: the caret after one
    moves right by two."""
    with pytest.raises(InputError) as caught:
        parse_equation(Source("<equation>", "x（ + @"))
    assert caught.value.render().split("\n")[2] == "   ^~"
