"""The package's own fuzz test: seeded mutants of every shipped study and catalogue.

Every mutant must be a valid file or fail with the package's error: one printable line per problem, located
in the file, quoting at most an excerpt of what it found; no mutant may take more than a few seconds, and all
of them together no more than a few hundred MB. Mutants are made three ways:

- structure-aware: the file's data with one node replaced by a hostile value (extreme and unphysical numbers,
  expression towers, wrong units and types, paths of devices), deleted, renamed, or swapped with another;
- text-level: characters deleted, YAML and unit tokens inserted (anchors, aliases, tags, escapes), lines
  swapped, duplicated or cut;
- byte-level: bytes that are not UTF-8, read from a file as ``crx validate`` reads it.

Each mutant comes from its own seed (``SEED`` and its index), so a failure names the index that reproduces it:
``mutant(index)`` rebuilds it. ``benchmarks/fuzz_studies.py`` runs the next mutants, in larger numbers, to the same
check (:func:`check_fuzz_report`).
"""

from __future__ import annotations

import copy
import math
import random
import resource
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import yaml

from collision_reflex.errors import CatalogueError, StudyFileError
from collision_reflex.hardware.catalogue import read_entries
from collision_reflex.study import load_study, parse_study, resolved_yaml
from collision_reflex.study.prepare import describe_study

ROOT = Path(__file__).resolve().parents[1]
STUDIES = sorted((ROOT / "studies").glob("*.yaml"))
CATALOGUES = {ROOT / "designs" / "motors.yaml": "motors", ROOT / "designs" / "gearboxes.yaml": "gearboxes"}
SOURCES = [*STUDIES, *CATALOGUES]
TEXTS = {path: path.read_text(encoding="utf-8") for path in SOURCES}
_LOADER = getattr(yaml, "CSafeLoader", yaml.SafeLoader)
DATA = {path: yaml.load(text, Loader=_LOADER) for path, text in TEXTS.items()}

SEED = 15
N_MUTANTS = 1_500  # per test run, about 7 s on one core (benchmarks/fuzz_studies.py runs the ones after)
MAX_SECONDS = 3.0  # any one mutant: parse, validate, load the (cached) robot
MAX_PEAK_GROWTH_MB = 300  # the process's peak memory over the whole run
MAX_FOUND = 160  # characters of what a problem quotes from the file: an excerpt
MAX_MESSAGE = 2000  # characters of one problem's line, with what is expected (e.g. the robot's frame names)

# Values a hostile or careless author writes: extremes, non-numbers, expressions, wrong units and types.
HOSTILE_VALUES: list[Any] = [
    0,
    -1,
    1,
    2**63,
    10**30,
    1e-300,
    1e300,
    -1e300,
    math.inf,
    -math.inf,
    math.nan,
    True,
    None,
    "",
    " ",
    "yes",
    "9**9**9 m/s",
    "10**10**10",
    "1e-300 mm",
    "1e300 kg",
    "1e308 km",
    "-0 N",
    "1/0 m",
    "m^(1/0)",
    "kg**kg",
    "20 degC",
    "3000 rpm",
    "50 Hz",
    "1 m" + " * m/m" * 40,
    "1" * 300 + " m",
    "\u00b5m",
    "60 \u00b5m",
    "1.3 N\u00b7m",
    "0.25 kg*cm^2",
    "/proc/self/mem",
    "/dev/zero",
    "../designs/planar_two_link.urdf",
    "panda_hand_tcp",
    "joint1",
    "panda_joint1",
    "shoulder_pan_joint",
    "double_pendulum",
    "ur5",
    "OPN-060-013-A",
    "\ud800",
    "a\x00b",
    "line\nbreak",
    "\x1b[31mred",
    [],
    {},
    [1, 2, 3],
    [[0.1] * 7] * 3,
    {"min": 1e-300, "max": 1e300},
    {"min": "10 mm", "max": "1 mm"},
    {"value": "1e300"},
    {"count": 2_000_000_000, "seed": -1},
    [[[[[[[[[[1]]]]]]]]]],
    "x" * 5000,
]
UNITS = ["mm", "m", "kg", "g", "N", "N*m", "N*m/rad", "m/s", "deg", "rad", "s", "Hz", "kg*m^2", "N/m", "A"]
# Pieces that matter to YAML and to units, inserted anywhere in the text.
TOKENS = [
    ":", "-", "- ", "[", "]", "{", "}", ",", "'", '"', "\n", "  ", "\t", "#", "&a ", "*a", "&b [*a, *a, *a] ",
    "<<: *a\n", "!!str ", "!!binary ", "!!python/name:os.system ", "!!python/object/apply:os.system [ls] ",
    "!local ", "? ", "|", ">", "%YAML 1.1\n", "---\n", "...\n", "@", "`", "~", "null", "1e999", "-1", "0x1F",
    "1_000", "2001-02-30", ".nan", " mm", " kg", "**9**9", "^99", "\\ud800", "\\0", "\\x1b", "\u2028", "\ufeff",
    "\x85", "\u00e9", "name", "robot", "min", "max", "value", "joints", "count", "seed", "kind", "actuator",
    "motors", "gearboxes", "source", "estimates",
]  # fmt: skip


@dataclass(frozen=True)
class Mutant:
    """One mutant: where it came from, how it was made, and its text (or bytes, for byte-level mutants)."""

    index: int
    source: Path
    how: str
    text: str
    data: bytes | None = None


def mutant(index: int) -> Mutant:
    """The mutant of ``index``: the same on every run and machine."""
    rng = random.Random(SEED * 1_000_003 + index)
    source = SOURCES[index % len(SOURCES)]
    roll = rng.random()
    if roll < 0.5:
        return Mutant(index, source, "structure", _structure_mutant(rng, DATA[source]))
    if roll < 0.97:
        return Mutant(index, source, "text", _text_mutant(rng, TEXTS[source]))
    raw = bytearray(TEXTS[source].encode("utf-8"))
    for _ in range(rng.randint(1, 3)):
        raw.insert(rng.randrange(len(raw) + 1), rng.choice([0x80, 0xC3, 0xE2, 0xFF, 0xFE, 0xED]))
    return Mutant(index, source, "bytes", "", bytes(raw))


def _nodes(data: Any, path: tuple = ()) -> list[tuple]:
    """Paths of every node of plain data (mapping keys and list indices)."""
    out = [path]
    if isinstance(data, dict):
        for key, value in data.items():
            out += _nodes(value, (*path, key))
    elif isinstance(data, list):
        for index, value in enumerate(data):
            out += _nodes(value, (*path, index))
    return out


def _get(data: Any, path: tuple) -> Any:
    for key in path:
        data = data[key]
    return data


def _structure_mutant(rng: random.Random, original: Any) -> str:
    data = copy.deepcopy(original)
    for _ in range(rng.randint(1, 3)):
        paths = _nodes(data)[1:]
        if not paths:
            break
        path = rng.choice(paths)
        parent, key = _get(data, path[:-1]), path[-1]
        operation = rng.choice(
            ["replace", "replace", "scale", "unit", "delete", "rename", "swap", "add", "alias", "bomb"]
        )
        value = parent[key]
        if operation == "replace":
            parent[key] = copy.deepcopy(rng.choice(HOSTILE_VALUES))  # never the shared original
        elif operation == "scale" and isinstance(value, (int, float)) and not isinstance(value, bool):
            parent[key] = value * 10.0 ** rng.choice([-300, -30, -9, -3, 3, 9, 30, 300])
        elif operation == "unit" and isinstance(value, (int, float, str)) and not isinstance(value, bool):
            number = str(value).split()[0] if str(value).split() else "1"
            parent[key] = f"{number} {rng.choice(UNITS)}"
        elif operation == "delete":
            del parent[key]
        elif operation == "rename" and isinstance(parent, dict):
            parent[f"{key}_" if rng.random() < 0.5 else str(key)[:-1]] = parent.pop(key)
        elif operation == "swap":
            other = rng.choice(paths)
            parent[key] = copy.deepcopy(_get(data, other)) if other[: len(path)] != path else value
        elif operation == "alias":
            # The same object twice: the dump writes an anchor and an alias (a valid use of them).
            parent[key] = [value, value] if rng.random() < 0.5 else value
            if isinstance(parent, dict):
                parent[f"{key}_again"] = value
        elif operation == "bomb":
            # Shared lists nested ``depth`` deep: the dump is a few lines, the expansion 9**depth nodes.
            bomb: Any = value
            for _ in range(rng.randint(2, 8)):
                bomb = [bomb] * 9
            parent[key] = bomb
            break  # walking the data again would expand the bomb here
        elif operation == "add" and isinstance(parent, dict):
            parent[rng.choice(["colour", "count", "min", "joints", "value", key])] = copy.deepcopy(
                rng.choice(HOSTILE_VALUES)
            )
    return _dump(data)


def _dump(data: Any, flow: bool | None = None) -> str:
    """YAML of plain data, by libyaml's emitter where PyYAML has it (the Python one is 10x slower)."""
    try:
        return yaml.dump(data, Dumper=_DUMPER, sort_keys=False, allow_unicode=True, default_flow_style=flow)
    except (yaml.YAMLError, UnicodeEncodeError):  # libyaml refuses a lone surrogate; PyYAML escapes it
        return yaml.dump(data, Dumper=yaml.SafeDumper, sort_keys=False, default_flow_style=flow)


_DUMPER = getattr(yaml, "CSafeDumper", yaml.SafeDumper)


def _text_mutant(rng: random.Random, text: str) -> str:
    for _ in range(rng.randint(1, 4)):
        if not text:
            break
        lines = text.splitlines(keepends=True)
        operation = rng.choice(["delete", "insert", "insert", "value", "swap", "duplicate", "cut"])
        if operation == "delete":
            start = rng.randrange(len(text))
            text = text[:start] + text[start + rng.randint(1, 12) :]
        elif operation == "insert":
            at = rng.randrange(len(text) + 1)
            text = text[:at] + rng.choice(TOKENS) + text[at:]
        elif operation == "value":
            index = rng.randrange(len(lines))
            key, colon, _ = lines[index].partition(": ")
            if colon:
                value = rng.choice(HOSTILE_VALUES)
                shown = value if isinstance(value, str) else _dump(value, flow=True)
                lines[index] = f"{key}: {shown.strip()}\n"
            text = "".join(lines)
        elif operation == "swap" and len(lines) > 1:
            i, j = rng.randrange(len(lines)), rng.randrange(len(lines))
            lines[i], lines[j] = lines[j], lines[i]
            text = "".join(lines)
        elif operation == "duplicate":
            index = rng.randrange(len(lines))
            lines.insert(index, lines[index] * rng.choice([1, 2, 50]))
            text = "".join(lines)
        elif operation == "cut":
            text = text[: rng.randrange(len(text))]
    return text


# --- checking one mutant --------------------------------------------------------------------------------------


def _check_line(message: str, file: str, n_lines: int, line: int | None) -> None:
    assert "\n" not in message and message.isprintable(), repr(message)
    assert len(message) <= MAX_MESSAGE, message
    assert message.startswith(file), message
    if line is not None:
        assert 0 <= line <= n_lines + 1, (line, n_lines)


def check_mutant(item: Mutant, folder: Path) -> str:
    """Validate a mutant as ``crx validate`` does; return ``"valid"`` or ``"error"``, or fail the test."""
    if item.source in CATALOGUES:
        return _check_catalogue(item, folder)
    # YAML also breaks lines at \r, \x85, \u2028 and \u2029: count as splitlines() does (a superset).
    text = item.data.decode("utf-8", "replace") if item.data is not None else item.text
    n_lines = len(text.splitlines()) + 1
    file = str(folder / "mutant.yaml") if item.data is not None else "mutant.yaml"
    try:
        if item.data is not None:
            path = Path(file)
            path.write_bytes(item.data)
            loaded = load_study(path)
        else:
            loaded = parse_study(item.text, file, item.source.parent)
        describe_study(loaded)  # the robot, frames, joints, samples, duty cycle
    except StudyFileError as error:
        assert error.problems
        for problem in error.problems:
            _check_line(str(problem), file, n_lines, problem.line)
            assert problem.line >= 1 or item.data is not None, problem
            assert problem.found and problem.expected, problem
            assert len(problem.found) <= MAX_FOUND, problem
        return "error"
    yaml.load(resolved_yaml(loaded), Loader=_LOADER)  # what validates resolves to YAML that reads back
    return "valid"


def _check_catalogue(item: Mutant, folder: Path) -> str:
    path = folder / item.source.name
    if item.data is not None:
        path.write_bytes(item.data)
    else:
        path.write_text(item.text, encoding="utf-8", errors="surrogatepass")
    n_lines = (
        len((item.data.decode("utf-8", "replace") if item.data is not None else item.text).splitlines()) + 1
    )
    try:
        read_entries(path, CATALOGUES[item.source])
    except CatalogueError as error:
        _check_line(str(error), str(path), n_lines, error.line)
        return "error"
    return "valid"


@dataclass
class FuzzReport:
    """What a fuzz run found: counts by outcome and kind, the slowest mutant, the growth of peak memory."""

    counts: dict[str, int]
    slowest: tuple[float, int]
    peak_growth_mb: float
    seconds: float


def fuzz(
    n_mutants: int, folder: Path, first: int = 0, progress: Callable[[int], None] | None = None
) -> FuzzReport:
    """Check mutants ``first`` to ``first + n_mutants - 1``; a failing mutant's assertion names its index."""
    counts: dict[str, int] = {}
    slowest = (0.0, -1)
    peak_before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    start = time.perf_counter()
    for index in range(first, first + n_mutants):
        item = mutant(index)
        began = time.perf_counter()
        try:
            outcome = check_mutant(item, folder)
        except Exception as error:
            raise AssertionError(
                f"mutant {index} ({item.how} of {item.source.name}) gave {type(error).__name__}: {error}"
            ) from error
        elapsed = time.perf_counter() - began
        slowest = max(slowest, (elapsed, index))
        key = f"{item.how} {outcome}"
        counts[key] = counts.get(key, 0) + 1
        if progress is not None and (index - first + 1) % 1000 == 0:
            progress(index - first + 1)
    peak_after = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss  # kB on Linux
    return FuzzReport(counts, slowest, (peak_after - peak_before) / 1024, time.perf_counter() - start)


def check_fuzz_report(report: FuzzReport, n_mutants: int) -> None:
    """What a fuzz run of ``n_mutants`` must show (the test's and ``benchmarks/fuzz_studies.py``'s check)."""
    assert sum(report.counts.values()) == n_mutants
    # The mutants reach both outcomes and every kind: a mutator that broke everything would test little.
    assert report.counts.get("structure valid", 0) > 0.05 * n_mutants, report.counts
    assert report.counts.get("text error", 0) > 0.1 * n_mutants, report.counts
    assert report.counts.get("bytes error", 0) > 0, report.counts
    elapsed, index = report.slowest
    assert elapsed < MAX_SECONDS, f"mutant {index} took {elapsed:.1f} s"
    assert report.peak_growth_mb < MAX_PEAK_GROWTH_MB, report


def test_mutants_are_valid_or_located(tmp_path):
    check_fuzz_report(fuzz(N_MUTANTS, tmp_path), N_MUTANTS)


def test_the_mutants_are_reproducible():
    assert mutant(123) == mutant(123)
    assert mutant(123) != mutant(124)
