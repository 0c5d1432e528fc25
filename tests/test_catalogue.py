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
    motor = cr.load_catalogue(_write(tmp_path, GOOD))["small"]
    assert motor.stator_diameter == pytest.approx(0.030, rel=1e-12)
    assert motor.rotor_inertia == pytest.approx(12e-3 * 1e-4, rel=1e-12)  # 12 g cm^2 = 1.2e-6 kg m^2
    assert motor.mass == pytest.approx(0.080, rel=1e-12)
    assert motor.stack_length == 0.01 and motor.continuous_torque == 0.2


def test_plain_exponent_numbers_are_si(tmp_path):
    # YAML 1.1 reads 1e-6 (no dot) as text; it must still be the SI number, not a unit error.
    motor = cr.load_catalogue(_write(tmp_path, GOOD.replace("12 g*cm^2", "1e-6")))["small"]
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
    motor = cr.load_catalogue(_write(tmp_path, entry))["small"]
    assert motor.max_speed == pytest.approx(rad_per_s, rel=1e-12)


def test_max_speed_optional(tmp_path):
    motor = cr.load_catalogue(_write(tmp_path, GOOD))["small"]
    assert motor.max_speed is None
    with pytest.raises(cr.InvalidParameter, match="no speed limit known for motor 'small'"):
        motor.speed_limit()


def test_packaged_catalogue_cites_sources():
    catalogue = cr.load_catalogue()
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
    "bad-yaml": ("motors:\n  small: [1,\n", 3, "", "YAML"),
    "no-motors-key": ("engines: {}\n", 1, "motors", "missing"),
}


@pytest.mark.parametrize("text, line, field, words", BAD.values(), ids=BAD.keys())
def test_bad_catalogue_names_field_and_line(tmp_path, text, line, field, words):
    path = _write(tmp_path, text)
    with pytest.raises(cr.CatalogueError) as info:
        cr.load_catalogue(path)
    error = info.value
    assert isinstance(error, ValueError)
    assert error.line == line
    assert field in error.field
    assert f"{path}:{line}" in str(error)
    assert words in str(error)


def test_unknown_motor_lists_the_catalogue():
    from collision_reflex.hardware.motors import get_motor

    with pytest.raises(cr.UnknownMotor, match="OPN-060-013-A"):
        get_motor("OPN-999")
