"""Motor catalogue files: units, and errors that name the field and the line."""

from __future__ import annotations

import math
import textwrap

import pytest

import collision_reflex as cr

GOOD = """\
motors:
  small:
    stator_diameter: 30 mm
    stack_length: 0.01
    rotor_inertia: 12 g*cm^2
    peak_torque: 0.4 N*m
    continuous_torque: 0.2
    mass: 80 g
    source: a test entry
"""


def _write(tmp_path, text):
    path = tmp_path / "motors.yaml"
    path.write_text(textwrap.dedent(text))
    return path


def test_units_converted_to_si(tmp_path):
    motor = cr.hardware.load_catalogue(_write(tmp_path, GOOD))["small"]
    assert motor.stator_diameter == pytest.approx(0.030, rel=1e-12)
    assert motor.rotor_inertia == pytest.approx(12e-3 * 1e-4, rel=1e-12)  # 12 g cm^2 = 1.2e-6 kg m^2
    assert motor.mass == pytest.approx(0.080, rel=1e-12)
    assert motor.stack_length == 0.01 and motor.continuous_torque == 0.2


def test_plain_exponent_numbers_are_si(tmp_path):
    # YAML 1.1 reads 1e-6 (no dot) as text; it must still be the SI number, not a unit error.
    motor = cr.hardware.load_catalogue(_write(tmp_path, GOOD.replace("12 g*cm^2", "1e-6")))["small"]
    assert motor.rotor_inertia == 1e-6


@pytest.mark.parametrize(
    "text, rad_per_s",
    [
        ("3000 rpm", 3000 * 2 * math.pi / 60),
        ("314 rad/s", 314.0),
        ("360 deg/s", 2 * math.pi),
        ("314", 314.0),  # a plain number is SI: rad/s
        ("2e3", 2000.0),
    ],
)
def test_max_speed_read_with_units(tmp_path, text, rad_per_s):
    entry = GOOD.replace("    source:", f"    max_speed: {text}\n    source:")
    motor = cr.hardware.load_catalogue(_write(tmp_path, entry))["small"]
    assert motor.max_speed == pytest.approx(rad_per_s, rel=1e-12)


def test_max_speed_optional(tmp_path):
    motor = cr.hardware.load_catalogue(_write(tmp_path, GOOD))["small"]
    assert motor.max_speed is None
    with pytest.raises(cr.InvalidParameter, match="no speed limit known for motor 'small'"):
        motor.speed_limit()


def test_packaged_catalogue_cites_sources():
    catalogue = cr.hardware.load_catalogue()
    assert "OPN-060-013-A" in catalogue
    assert all(motor.source for motor in catalogue.values())


BAD = {
    "missing-field": (GOOD.replace("    mass: 80 g\n", ""), 2, "motors.small.mass", "missing"),
    "wrong-type": (
        GOOD.replace("peak_torque: 0.4 N*m", "peak_torque: [1, 2]"),
        6,
        "motors.small.peak_torque",
        "",
    ),
    "wrong-unit": (GOOD.replace("30 mm", "30 kg"), 3, "motors.small.stator_diameter", "cannot be converted"),
    "negative": (GOOD.replace("mass: 80 g", "mass: -1"), 8, "motors.small.mass", "> 0"),
    "unknown-field": (
        GOOD.replace("    source:", "    colour: red\n    source:"),
        9,
        "motors.small.colour",
        "unknown",
    ),
    "no-source": (GOOD.replace("a test entry", "''"), 9, "motors.small.source", "cite"),
    "cont-above-peak": (
        GOOD.replace("continuous_torque: 0.2", "continuous_torque: 0.5"),
        7,
        "continuous_torque",
        "peak",
    ),
    "speed-wrong-unit": (
        GOOD.replace("    source:", "    max_speed: 3000 kg\n    source:"),
        9,
        "motors.small.max_speed",
        "cannot be converted to rad/s",
    ),
    "speed-without-angle": (
        GOOD.replace("    source:", "    max_speed: 50 Hz\n    source:"),
        9,
        "motors.small.max_speed",
        "no angle unit",
    ),
    "speed-negative": (
        GOOD.replace("    source:", "    max_speed: -3000 rpm\n    source:"),
        9,
        "motors.small.max_speed",
        "> 0",
    ),
    "zero-inertia": (GOOD.replace("12 g*cm^2", "0"), 5, "motors.small.rotor_inertia", "> 0"),
    "nan-mass": (GOOD.replace("mass: 80 g", "mass: .nan"), 8, "motors.small.mass", "> 0"),
    # 12 kg cm^2 on a 30 mm, 80 g motor: 8 times the inertia of its whole mass at 2 x its stator radius.
    "inertia-unit-slip": (
        GOOD.replace("12 g*cm^2", "12 kg*cm^2"),
        5,
        "motors.small.rotor_inertia",
        "check the unit",
    ),
    "unknown-construction": (
        GOOD.replace("    source:", "    construction: geared\n    source:"),
        9,
        "motors.small.construction",
        "'frameless' or 'housed'",
    ),
    "empty-maker": (
        GOOD.replace("    source:", "    maker: ''\n    source:"),
        9,
        "motors.small.maker",
        "empty",
    ),
    "duplicate-part": (
        GOOD + GOOD.replace("motors:\n", ""),
        10,
        "motors.small",
        "given twice (first on line 2)",
    ),
    "duplicate-field": (
        GOOD.replace("    source:", "    mass: 0.5 kg\n    source:"),
        9,
        "motors.small.mass",
        "given twice (first on line 8)",
    ),
    "duplicate-estimate": (
        GOOD.replace("    source:", "    estimates:\n      mass: a\n      mass: b\n    source:"),
        11,
        "motors.small.estimates.mass",
        "given twice",
    ),
    "bad-yaml": ("motors:\n  small: [1,\n", 3, "", "YAML"),
    "no-motors-key": ("engines: {}\n", 1, "motors", "missing"),
}


@pytest.mark.parametrize("text, line, field, words", BAD.values(), ids=BAD.keys())
def test_bad_catalogue_names_field_and_line(tmp_path, text, line, field, words):
    path = _write(tmp_path, text)
    with pytest.raises(cr.errors.CatalogueError) as info:
        cr.hardware.load_catalogue(path)
    error = info.value
    assert isinstance(error, ValueError)
    assert error.line == line
    assert field in error.field
    assert f"{path}:{line}" in str(error)
    assert words in str(error)


def test_unknown_motor_lists_the_catalogue():
    from collision_reflex.hardware.motors import get_motor

    with pytest.raises(cr.errors.UnknownMotor, match="OPN-060-013-A"):
        get_motor("OPN-999")


def _given_fields(path, kind):
    """Field names written in each entry of a catalogue file (provenance keys excluded), read independently."""
    import yaml

    entries = yaml.safe_load(path.read_text())[kind]
    text_only = {"source", "sources", "estimates", "maker", "construction"}
    return {name: set(entry) - text_only for name, entry in entries.items()}


@pytest.mark.parametrize("kind, file", [("motors", "motors.yaml"), ("gearboxes", "gearboxes.yaml")])
def test_every_packaged_field_has_a_source_or_an_estimate(kind, file):
    from collision_reflex.hardware.catalogue import packaged_catalogue_path, read_entries

    path = packaged_catalogue_path(file)
    entries = read_entries(path, kind)
    given = _given_fields(path, kind)
    assert entries and set(entries) == set(given)
    for name, entry in entries.items():
        assert set(entry.provenance) == given[name], name
        for field, text in entry.provenance.items():
            origin, _, detail = text.partition(": ")
            assert origin in ("source", "ESTIMATE") and len(detail.strip()) > 10, (name, field, text)


def test_reference_motor_estimates_are_marked():
    from collision_reflex.hardware.catalogue import packaged_catalogue_path, read_entries

    provenance = read_entries(packaged_catalogue_path(), "motors")["OPN-060-013-A"].provenance
    assert provenance["mass"].startswith("ESTIMATE: active-part volume")
    assert provenance["max_speed"].startswith("ESTIMATE: a 10 m/s rotor surface speed")
    assert provenance["rotor_inertia"].startswith("source: Bhatia, Mason, Johnson")


def test_reference_motor_unchanged():
    motor = cr.hardware.load_catalogue()["OPN-060-013-A"]
    expected = (0.060, 0.0125, 2.21e-5, 1.3, 0.524, 0.195, 492.6)
    got = (
        motor.stator_diameter,
        motor.stack_length,
        motor.rotor_inertia,
        motor.peak_torque,
        motor.continuous_torque,
        motor.mass,
        motor.max_speed,
    )
    assert got == pytest.approx(expected, rel=1e-12)


def test_torque_constant_read_with_units(tmp_path):
    entry = GOOD.replace("    source:", "    torque_constant: 75 mN*m/A\n    source:")
    assert cr.hardware.load_catalogue(_write(tmp_path, entry))["small"].torque_constant == pytest.approx(
        0.075, rel=1e-12
    )
    assert cr.hardware.load_catalogue(_write(tmp_path, GOOD))["small"].torque_constant is None


PROVENANCE_BAD = {
    "source-of-absent-field": (
        GOOD.replace("    source:", "    sources:\n      max_speed: a datasheet\n    source:"),
        10,
        "motors.small.sources.max_speed",
        "names no field",
    ),
    "empty-estimate": (
        GOOD.replace("    source:", "    estimates:\n      mass: ''\n    source:"),
        10,
        "motors.small.estimates.mass",
        "empty",
    ),
    "sourced-and-estimated": (
        GOOD.replace(
            "    source:", "    sources:\n      mass: sheet\n    estimates:\n      mass: guess\n    source:"
        ),
        12,
        "motors.small.estimates.mass",
        "sourced or estimated",
    ),
    "no-source-key": (GOOD.replace("    source: a test entry\n", ""), 2, "motors.small.source", "missing"),
    "torque-constant-wrong-unit": (
        GOOD.replace("    source:", "    torque_constant: 3 N*m\n    source:"),
        9,
        "motors.small.torque_constant",
        "cannot be converted",
    ),
}


@pytest.mark.parametrize("text, line, field, words", PROVENANCE_BAD.values(), ids=PROVENANCE_BAD.keys())
def test_bad_provenance_names_field_and_line(tmp_path, text, line, field, words):
    path = _write(tmp_path, text)
    with pytest.raises(cr.errors.CatalogueError) as info:
        cr.hardware.load_catalogue(path)
    assert info.value.line == line and info.value.field == field
    assert f"{path}:{line}" in str(info.value) and words in str(info.value)


def test_descriptive_fields_are_text_apart_from_the_numbers(tmp_path):
    from collision_reflex.hardware.catalogue import read_entries

    text = GOOD.replace("    source:", "    maker: Acme\n    construction: frameless\n    source:")
    entry = read_entries(_write(tmp_path, text), "motors")["small"]
    assert entry.description == {"maker": "Acme", "construction": "frameless"}
    assert "maker" not in entry.provenance and "construction" not in entry.fields
    assert cr.hardware.load_catalogue(_write(tmp_path, text))["small"].mass == pytest.approx(0.080, rel=1e-12)
    assert read_entries(_write(tmp_path, GOOD), "motors")["small"].description == {}
