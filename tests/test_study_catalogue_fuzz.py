"""Seeded fuzz of the catalogues a study names (``catalogue.motors``, ``catalogue.gearboxes``).

A small arm study names a motor and a gearbox catalogue of its own. Each mutant changes one thing: an entry of
either catalogue (an empty source, a name or a field given twice, a wrong kind, huge numbers, text for numbers,
nested junk, unknown fields, negative figures, per-ratio figures that miss or add a ratio), or the study's
``catalogue`` section itself (a missing file, a folder, a number, a mapping). ``crx validate`` either accepts
the study, and then the packaged catalogues' loader accepts each named file too, or refuses it with exit status
2 and one line located in the study file (the catalogue's own file and line quoted in it); never a traceback,
never more than two seconds. A mutant known to be bad (all but a few) must be refused, a mutant known to be
good accepted: the expectation is written with the mutation, independent of the loader.
"""

from __future__ import annotations

import random
import re
import shutil
import time
from collections.abc import Callable
from pathlib import Path

import pytest

from collision_reflex.cli import main
from collision_reflex.errors import CatalogueError
from collision_reflex.hardware.catalogue import read_entries
from collision_reflex.study import load_study, parse_study, resolved_yaml

ROOT = Path(__file__).resolve().parents[1]
MUTANTS = 40  # per catalogue kind, and as many of the study's section

STUDY = """\
name: catalogue-fuzz
robot: {urdf: planar_two_link.urdf, contact_frame: tip}
actuators:
  motor: {reference: "OPN-060-013-A", scaling_law: haddadin, stator_diameter: 60 mm}
  gear_ratio: 10
  gearbox: {scaled_from: NPS015-MF-1}
  mechanical_stiffness: 1000 N*m/rad
  software_stiffness: 100 N*m/rad
sensing: {scheme: force, threshold: 3 N}
approach_velocity: 0.5 m/s
samples:
  configurations: {list: [[0 deg, 45 deg]]}
  directions: {circle: 4}
constraints: {torque_required: [1.3 N*m, 1.3 N*m]}
catalogue:
  motors: motors.yaml
  gearboxes: gearboxes.yaml
"""

# Entries as (name, [(field, YAML value)]) so that a name or a field can be written twice.
Entries = list[tuple[str, list[tuple[str, str]]]]
SOURCE = ("source", "a test datasheet")
CATALOGUES: dict[str, Entries] = {
    "motors": [
        (
            "M-60",
            [
                ("stator_diameter", "60 mm"),
                ("stack_length", "12.5 mm"),
                ("rotor_inertia", "2.2e-5 kg*m^2"),
                ("peak_torque", "1.3 N*m"),
                ("continuous_torque", "0.5 N*m"),
                ("mass", "0.2 kg"),
                SOURCE,
            ],
        ),
        (
            "M-85",
            [
                ("stator_diameter", "0.085"),
                ("stack_length", "0.03"),
                ("rotor_inertia", "1.1e-4"),
                ("peak_torque", "4.0"),
                ("continuous_torque", "1.5"),
                ("mass", "0.6"),
                ("max_speed", "3000 rpm"),
                SOURCE,
            ],
        ),
    ],
    "gearboxes": [
        (
            "PG-1",
            [
                ("kind", "planetary"),
                ("ratios", "[5, 10]"),
                ("rated_torque", "{5: 10 N*m, 10: 12 N*m}"),
                ("peak_torque", "20 N*m"),
                ("mass", "0.5 kg"),
                ("inertia", "{5: 0.2 kg*cm^2, 10: 0.1 kg*cm^2}"),
                SOURCE,
            ],
        ),
        (
            "HD-1",
            [
                ("kind", "harmonic"),
                ("ratio_range", "[50, 100]"),
                ("rated_torque", "5 N*m"),
                ("peak_torque", "15 N*m"),
                ("mass", "0.3"),
                ("inertia", "0.05 kg*cm^2"),
                SOURCE,
            ],
        ),
    ],
}
NUMBERS = {  # numeric fields of each kind, for the mutations of a figure
    "motors": [
        "stator_diameter",
        "stack_length",
        "rotor_inertia",
        "peak_torque",
        "continuous_torque",
        "mass",
    ],
    "gearboxes": ["rated_torque", "peak_torque", "mass", "inertia"],
}
BAD_FIGURES = [
    "-3",
    "0",
    "'-3 N*m'",
    ".nan",
    ".inf",
    "1e400",
    "heavy",
    "'12 apples'",
    "''",
    "'3 m/s'",
    "true",
    "[1, 2]",
    "{a: [1, {b: c}]}",
    "9" * 5000,
    "'9**9**9 N*m'",
    "2001-02-30",
    "!!binary aGVsbG8=",
    "[" * 200 + "]" * 200,
]


def _text(kind: str, entries: Entries) -> str:
    lines = [f"{kind}:"]
    for name, fields in entries:
        lines.append(f"  {name}:")
        lines += [f"    {field}: {value}" for field, value in fields]
    return "\n".join(lines) + "\n"


def _copy(entries: Entries) -> Entries:
    return [(name, list(fields)) for name, fields in entries]


def _set(fields: list[tuple[str, str]], field: str, value: str) -> None:
    index = next(i for i, (key, _) in enumerate(fields) if key == field)
    fields[index] = (field, value)


# A mutation takes the catalogue's kind, a copy of its entries and the generator; it changes the entries in place
# and returns whether the result must be refused (True), accepted (False) or may be either (None).
Mutation = Callable[[str, Entries, random.Random], bool | None]


def _empty_source(kind: str, entries: Entries, rng: random.Random) -> bool:
    _set(rng.choice(entries)[1], "source", rng.choice(["''", "'   '", "", "null", ">-\n      "]))
    return True


def _name_twice(kind: str, entries: Entries, rng: random.Random) -> bool:
    entries.append(_copy([rng.choice(entries)])[0])
    return True


def _field_twice(kind: str, entries: Entries, rng: random.Random) -> bool:
    fields = rng.choice(entries)[1]
    fields.insert(rng.randrange(len(fields) + 1), rng.choice(fields))
    return True


def _unknown_field(kind: str, entries: Entries, rng: random.Random) -> bool:
    fields = rng.choice(entries)[1]
    fields.insert(rng.randrange(len(fields) + 1), (rng.choice(["colour", "Mass", "ratio", "sorce"]), "red"))
    return True


def _missing_field(kind: str, entries: Entries, rng: random.Random) -> bool:
    fields = rng.choice(entries)[1]
    required = [i for i, (field, _) in enumerate(fields) if field != "max_speed"]
    fields.pop(rng.choice(required))
    return True


def _bad_figure(kind: str, entries: Entries, rng: random.Random) -> bool:
    _set(rng.choice(entries)[1], rng.choice(NUMBERS[kind]), rng.choice(BAD_FIGURES))
    return True


def _wrong_kind(kind: str, entries: Entries, rng: random.Random) -> bool:
    if kind == "gearboxes":
        _set(rng.choice(entries)[1], "kind", rng.choice(["worm", "5", "[planetary]", "Planetary", "''"]))
    else:  # a gearbox's fields in a motor catalogue
        rng.choice(entries)[1].append(("kind", "planetary"))
    return True


def _per_ratio(kind: str, entries: Entries, rng: random.Random) -> bool:
    if kind == "motors":  # a motor has no ratios
        _set(entries[0][1], "peak_torque", "{5: 1.3 N*m, 10: 1.3 N*m}")
        return True
    value = rng.choice(
        [
            "{5: 10 N*m}",  # a ratio missing
            "{5: 10 N*m, 10: 12 N*m, 20: 12 N*m}",  # a ratio that is not offered
            "{5: 10 N*m, 5.0: 11 N*m, 10: 12 N*m}",  # a ratio twice
            "{'5': 10 N*m, 10: 12 N*m}",  # a ratio as text
            "{0.5: 10 N*m, 10: 12 N*m}",  # not a ratio
            "{}",
        ]
    )
    _set(entries[0][1], "rated_torque", value)
    if rng.random() < 0.3:  # or figures per ratio over a range
        _set(entries[1][1], "peak_torque", "{50: 15 N*m, 100: 15 N*m}")
    return True


def _huge_but_consistent(kind: str, entries: Entries, rng: random.Random) -> bool | None:
    # Very large or small finite figures: physical nonsense maybe, but numbers the schema takes or refuses by
    # its cross-checks (peak above rated, inertia within the motor's mass): either is right.
    _set(rng.choice(entries)[1], rng.choice(NUMBERS[kind]), rng.choice(["1e300", "1e-300", "'1e30 kg'"]))
    return None


def _still_good(kind: str, entries: Entries, rng: random.Random) -> bool:
    # A figure changed to another valid one, with its unit written another way: must stay accepted.
    fields = rng.choice(entries)[1]
    _set(fields, "mass", rng.choice(["0.4 kg", "400 g", "0.4", "'0.4 kg'"]))
    fields.append(("maker", "Someone"))
    return False


MUTATIONS: list[Mutation] = [
    _empty_source,
    _name_twice,
    _field_twice,
    _unknown_field,
    _missing_field,
    _bad_figure,
    _bad_figure,
    _wrong_kind,
    _per_ratio,
    _huge_but_consistent,
    _still_good,
]


def _section_mutants(rng: random.Random) -> list[str]:
    """Mutants of the study's ``catalogue`` section: one of its two files named wrongly, or an unknown key."""
    values = [
        "missing.yaml",
        "''",
        ".",
        "5",
        "[motors.yaml]",
        "{file: motors.yaml}",
        "OTHER.yaml",  # the other kind's catalogue
        '"\\0"',  # a NUL in the name
        "x" * 300 + ".yaml",  # a name longer than the system allows
        "study.yaml",  # not a catalogue at all
        "planar_two_link.urdf",
    ]
    mutants = []
    for _ in range(MUTANTS):
        kind = rng.choice(["motors", "gearboxes"])
        other = "gearboxes" if kind == "motors" else "motors"
        value = rng.choice([*values, "COLOUR"]).replace("OTHER", other)
        line = f"  {kind}: {kind}.yaml"
        mutants.append(
            STUDY.replace(line, f"{line}\n  colour: red" if value == "COLOUR" else f"  {kind}: {value}")
        )
    return mutants


def _validate(study: Path, capsys: pytest.CaptureFixture[str]) -> tuple[int, str, float]:
    started = time.perf_counter()
    status = main(["validate", str(study)])
    elapsed = time.perf_counter() - started
    return status, capsys.readouterr().err, elapsed


def _check(status: int, err: str, elapsed: float, study: Path, must_refuse: bool | None, label: str) -> None:
    assert elapsed < 2.0, label
    assert status in (0, 2), label
    if status == 2:
        lines = err.strip().splitlines()
        assert len(lines) == 1, (label, err)
        assert re.match(rf"{re.escape(str(study))}:\d+:\d+: catalogue", lines[0]), (label, err)
        assert "Traceback" not in err
    if must_refuse is not None:
        assert status == (2 if must_refuse else 0), (label, err)
    if status == 0:  # what the study accepts, the packaged catalogues' loader accepts from its file
        for kind in ("motors", "gearboxes"):
            read_entries(study.parent / f"{kind}.yaml", kind)


@pytest.fixture
def folder(tmp_path: Path) -> Path:
    shutil.copy(ROOT / "designs" / "planar_two_link.urdf", tmp_path)
    for kind, entries in CATALOGUES.items():
        (tmp_path / f"{kind}.yaml").write_text(_text(kind, entries), encoding="utf-8")
    (tmp_path / "study.yaml").write_text(STUDY, encoding="utf-8")
    return tmp_path


def test_the_unmutated_study_and_its_catalogues_are_valid(folder, capsys) -> None:
    assert main(["validate", str(folder / "study.yaml")]) == 0, capsys.readouterr().err
    for kind in CATALOGUES:
        assert read_entries(folder / f"{kind}.yaml", kind)


def test_a_bad_entry_of_a_named_catalogue_is_refused_at_the_study_line(folder, capsys) -> None:
    # Found by the fuzz: crx validate never read the catalogues a study names, so an entry without a source
    # (or a missing file, a folder, the other kind's file) passed, to fail only when a run reached them.
    entries = _copy(CATALOGUES["gearboxes"])
    _set(entries[1][1], "source", "''")
    (folder / "gearboxes.yaml").write_text(_text("gearboxes", entries), encoding="utf-8")
    study = folder / "study.yaml"
    assert main(["validate", str(study)]) == 2
    assert capsys.readouterr().err == (
        f"{study}:17:3: catalogue.gearboxes: found gearboxes.yaml:17: gearboxes.HD-1.source: Value error, every "
        "entry must cite its source (datasheet, paper, or a stated assumption) (got ''); expected a gearboxes "
        "catalogue file like designs/gearboxes.yaml, relative to the study file's folder: fix it where quoted, "
        "or leave catalogue.gearboxes out for the packaged one\n"
    )


def test_the_resolved_study_names_its_catalogues_wherever_it_is_read(folder, tmp_path_factory) -> None:
    # The resolved study (a run folder's study.resolved.yaml) kept catalogue paths relative: read from the run
    # folder, it named catalogues beside it that are not there.
    loaded = load_study(folder / "study.yaml")
    elsewhere = tmp_path_factory.mktemp("run")
    again = parse_study(resolved_yaml(loaded), "study.resolved.yaml", elsewhere)
    assert again.study.catalogue.motors == str(folder / "motors.yaml")
    assert again.study.catalogue.gearboxes == str(folder / "gearboxes.yaml")


@pytest.mark.parametrize("kind", list(CATALOGUES))
def test_a_mutated_catalogue_entry_is_validated_or_refused_in_one_located_line(kind, folder, capsys) -> None:
    rng = random.Random(f"study-catalogue-{kind}")
    study, target = folder / "study.yaml", folder / f"{kind}.yaml"
    refused = 0
    for trial in range(MUTANTS):
        entries = _copy(CATALOGUES[kind])
        mutation = rng.choice(MUTATIONS)
        must_refuse = mutation(kind, entries, rng)
        text = _text(kind, entries)
        target.write_text(text, encoding="utf-8")
        status, err, elapsed = _validate(study, capsys)
        label = f"{kind} mutant {trial} ({mutation.__name__}):\n{text}"
        _check(status, err, elapsed, study, must_refuse, label)
        if status == 2:
            refused += 1
            # The catalogue's own file and line are quoted, as its loader reports them.
            with pytest.raises(CatalogueError) as caught:
                read_entries(target, kind)
            line = caught.value.line
            assert f"found {kind}.yaml{'' if line is None else f':{line}'}: " in err, (label, err)
    assert refused >= MUTANTS // 2  # the mutations are mostly of bad entries


def test_a_mutated_catalogue_section_is_refused_in_one_located_line(folder, capsys) -> None:
    study = folder / "study.yaml"
    for trial, text in enumerate(_section_mutants(random.Random("study-catalogue-section"))):
        study.write_text(text, encoding="utf-8")
        status, err, elapsed = _validate(study, capsys)
        _check(status, err, elapsed, study, True, f"section mutant {trial}:\n{text}")
