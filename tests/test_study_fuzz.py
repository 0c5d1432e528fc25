"""Fuzzing study files: random mutations of valid files give a valid study or the package's error with a line
number, never another exception."""

from __future__ import annotations

from pathlib import Path

import yaml
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from collision_reflex.errors import StudyFileError
from collision_reflex.study import parse_study, resolved_yaml

STUDIES = sorted((Path(__file__).resolve().parents[1] / "studies").glob("*.yaml"))
TEXTS = [path.read_text() for path in STUDIES]

# Pieces that matter to YAML, to units and to the schema: structure characters, anchors and tags, odd numbers,
# units of every dimension, and names of real keys put in the wrong place.
TOKENS = [
    ":",
    "-",
    "- ",
    "[",
    "]",
    "{",
    "}",
    ",",
    "'",
    '"',
    "\n",
    "  ",
    "\t",
    "#",
    "&a ",
    "*a",
    "!!str ",
    "!!binary ",
    "!!python/name:os.system ",
    "? ",
    "|",
    ">",
    "%",
    "@",
    "`",
    "~",
    "null",
    "yes",
    "1e999",
    "-1",
    "0",
    ".nan",
    "-.inf",
    "2001-02-30",
    "0x1F",
    "1_000",
    "3 kg",
    "60 mm",
    "1.3 N*m",
    "0.5 m/s",
    "1000 N*m/rad",
    "45 deg",
    "20 degC",
    "1/0 m",
    "kg**kg",
    "m^(1/0)",
    "\u00b5m",
    "name",
    "robot",
    "min",
    "max",
    "value",
    "joints",
    "circle",
    "sphere",
    "list",
    "random",
    "count",
    "seed",
    "kind",
    "actuator",
    "arm",
    "scheme",
    "current",
]


@st.composite
def mutated(draw: st.DrawFn) -> str:
    text = draw(st.sampled_from(TEXTS))
    for _ in range(draw(st.integers(1, 4))):
        if not text:
            break
        operation = draw(
            st.sampled_from(["delete", "insert", "replace_value", "swap_lines", "duplicate_line"])
        )
        lines = text.splitlines(keepends=True)
        if operation == "delete":
            start = draw(st.integers(0, len(text) - 1))
            text = text[:start] + text[start + draw(st.integers(1, 12)) :]
        elif operation == "insert":
            at = draw(st.integers(0, len(text)))
            piece = draw(st.one_of(st.sampled_from(TOKENS), st.text(max_size=6)))
            text = text[:at] + piece + text[at:]
        elif operation == "replace_value":
            index = draw(st.integers(0, len(lines) - 1))
            key, colon, _ = lines[index].partition(": ")
            if colon:
                value = draw(st.one_of(st.sampled_from(TOKENS), st.text(max_size=8), st.floats().map(repr)))
                lines[index] = f"{key}: {value}\n"
            text = "".join(lines)
        elif operation == "swap_lines" and len(lines) > 1:
            i, j = draw(st.integers(0, len(lines) - 1)), draw(st.integers(0, len(lines) - 1))
            lines[i], lines[j] = lines[j], lines[i]
            text = "".join(lines)
        elif operation == "duplicate_line":
            index = draw(st.integers(0, len(lines) - 1))
            lines.insert(index, lines[index])
            text = "".join(lines)
    return text


@settings(max_examples=400, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(mutated())
def test_mutated_study_files_are_valid_or_located(text):
    try:
        loaded = parse_study(text, "mutant.yaml", STUDIES[0].parent)
    except StudyFileError as error:
        n_lines = text.count("\n") + 1
        assert error.problems
        for problem in error.problems:
            # Every problem points into the file (1-based) and says what it found and what it expected.
            assert 1 <= problem.line <= n_lines, problem
            assert problem.column >= 1
            assert problem.found and problem.expected
            assert str(problem).startswith(f"mutant.yaml:{problem.line}:")
    else:
        # A mutant that is still valid resolves to a file that is valid too.
        yaml.safe_load(resolved_yaml(loaded))
