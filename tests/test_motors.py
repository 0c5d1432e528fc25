"""Motor scaling laws against the paper's tab:motor_params and hand computation; backends; the catalogue."""

from __future__ import annotations

import casadi as ca
import numpy as np
import pytest

import collision_reflex as cr
from collision_reflex.hardware.motors import SpeedScaling

# tab:motor_params of "Reacting to Contact: Transparency and Collision Reflex in Actuation": the reference M2
# scaled by the Haddadin law to 10 mm (M1) and 100 mm (M3), output torque held at 1.3 N m.
PAPER_ROWS = {
    "M1": dict(
        diameter=0.010, J_m=1.71e-8, tau_c=5.94e-3, tau_p=1.47e-2, N=88.18, reflected=1.33e-4, out=1.3
    ),
    "M3": dict(diameter=0.100, J_m=1.71e-4, tau_c=1.879, tau_p=4.661, N=1.0, reflected=1.71e-4, out=4.661),
}


@pytest.mark.parametrize("row", PAPER_ROWS.values(), ids=PAPER_ROWS.keys())
def test_tab_motor_params_reproduced(row):
    motor = cr.reference_motor().scaled(row["diameter"], law="haddadin")
    gear = cr.hardware.gear_ratio_for(1.3, motor.peak_torque)
    actuator = cr.Actuator(motor, gear_ratio=gear)
    # The paper prints 3-4 significant figures; 1% covers its rounding (the tolerance).
    got = {
        "J_m": motor.rotor_inertia,
        "tau_c": motor.continuous_torque,
        "tau_p": motor.peak_torque,
        "N": gear,
        "reflected": actuator.reflected_inertia,
        "out": actuator.peak_torque,
    }
    for key, value in got.items():
        assert value == pytest.approx(row[key], rel=0.01), key


def test_reference_motor_is_m2():
    motor = cr.reference_motor()
    assert (motor.stator_diameter, motor.stack_length) == (0.060, 0.0125)
    assert (motor.rotor_inertia, motor.peak_torque, motor.continuous_torque) == (2.21e-5, 1.3, 0.524)
    assert "assumption" in motor.source.lower()  # the mass is not a datasheet value and says so


LAW_EXPONENTS = {  # tab:scaling_laws: (mass, inertia, torque) exponents of r
    "isometric": (2, 4, 4),
    "empirical": (2, 4, 2.8),
    "quadruped": (1, 3, 2),
    "haddadin": (2, 4, 2.5),
}


@pytest.mark.parametrize("name", LAW_EXPONENTS, ids=LAW_EXPONENTS.keys())
def test_scaling_laws_against_hand_computation(name):
    reference = cr.Motor("ref", 0.05, 0.02, 1e-5, 2.0, 1.0, 0.3)
    mass_e, inertia_e, torque_e = LAW_EXPONENTS[name]
    law = cr.hardware.scaling_law(name)
    assert (law.mass_exponent, law.inertia_exponent, law.torque_exponent) == (mass_e, inertia_e, torque_e)
    # Twice the diameter, 1.5x the length: q = q0 * 1.5 * 2**e, written out by hand.
    scaled = reference.scaled(0.10, 0.03, law=name)
    assert scaled.mass == pytest.approx(0.3 * 1.5 * 2**mass_e, rel=1e-14)
    assert scaled.rotor_inertia == pytest.approx(1e-5 * 1.5 * 2**inertia_e, rel=1e-14)
    assert scaled.peak_torque == pytest.approx(2.0 * 1.5 * 2**torque_e, rel=1e-14)
    assert scaled.continuous_torque == pytest.approx(1.0 * 1.5 * 2**torque_e, rel=1e-14)


def test_paper_inertia_torque_exponents():
    # The paper's text: J ∝ tau (isometric), tau^1.6 (electrical & thermal), tau^1.5 (quadruped).
    assert cr.hardware.scaling_law("isometric").inertia_torque_exponent == 1.0
    assert cr.hardware.scaling_law("haddadin").inertia_torque_exponent == 1.6
    assert cr.hardware.scaling_law("quadruped").inertia_torque_exponent == 1.5


def test_scaled_quantities_backends_agree():
    reference = cr.reference_motor()
    diameters = np.array([0.01, 0.03, 0.1])
    lengths = np.array([0.01, 0.0125, 0.05])
    numeric = cr.hardware.scaled_motor_quantities(reference, diameters, lengths, "empirical")
    for sym_r, sym_l in ((ca.SX.sym("r", 3), ca.SX.sym("l", 3)), (ca.MX.sym("r", 3), ca.MX.sym("l", 3))):
        symbolic = cr.hardware.scaled_motor_quantities(reference, sym_r, sym_l, "empirical")
        f = ca.Function("f", [sym_r, sym_l], list(symbolic))
        for got, expected in zip(f(diameters, lengths), numeric, strict=True):
            np.testing.assert_allclose(np.asarray(got).ravel(), expected, rtol=1e-14)
    # One motor scaled at a time gives the same numbers as the array call.
    for i, diameter in enumerate(diameters):
        single = reference.scaled(diameter, lengths[i], law="empirical")
        assert single.peak_torque == pytest.approx(numeric.peak_torque[i], rel=1e-14)


def test_stack_length_defaults_to_reference():
    reference = cr.reference_motor()
    got = cr.hardware.scaled_motor_quantities(reference, 0.03)
    assert got.rotor_inertia == pytest.approx(2.21e-5 * 0.5**4, rel=1e-14)


@pytest.mark.parametrize(
    "kwargs, field",
    [
        (dict(stator_diameter=0.0), "stator_diameter"),
        (dict(stator_diameter=-0.01), "stator_diameter"),
        (dict(stator_diameter=float("nan")), "stator_diameter"),
        (dict(stack_length=0.0), "stack_length"),
    ],
    ids=["zero-diameter", "negative-diameter", "nan-diameter", "zero-length"],
)
def test_bad_sizes_rejected(kwargs, field):
    with pytest.raises(cr.InvalidParameter, match=field):
        cr.reference_motor().scaled(**kwargs)


def test_unknown_law_lists_laws():
    with pytest.raises(cr.InvalidParameter, match="haddadin") as info:
        cr.reference_motor().scaled(0.03, law="cubic")
    assert isinstance(info.value, ValueError)


def test_motor_validates_its_fields():
    with pytest.raises(cr.InvalidParameter, match=r"Motor\.mass"):
        cr.Motor("x", 0.05, 0.01, 1e-5, 1.0, 0.5, -1.0)
    with pytest.raises(cr.InvalidParameter, match="continuous_torque"):
        cr.Motor("x", 0.05, 0.01, 1e-5, 1.0, 2.0, 0.1)
    with pytest.raises(cr.InvalidParameter, match=r"Motor\.peak_torque"):
        cr.Motor("x", 0.05, 0.01, 1e-5, "1.0", 0.5, 0.1)  # type: ignore[arg-type]


def _fast_motor(max_speed=300.0):
    return cr.Motor("fast", 0.05, 0.02, 1e-5, 2.0, 1.0, 0.3, source="test", max_speed=max_speed)


@pytest.mark.parametrize("name", LAW_EXPONENTS, ids=LAW_EXPONENTS.keys())
def test_max_speed_keeps_the_rotor_surface_speed(name):
    reference = _fast_motor()
    # Twice the diameter, 1.5x the length: the tip speed omega * r stays 300 rad/s * 0.025 m = 7.5 m/s, so
    # omega halves; the stack length does not enter.
    scaled = reference.scaled(0.10, 0.03, law=name)
    assert scaled.max_speed == pytest.approx(150.0, rel=1e-14)
    assert scaled.max_speed * 0.10 / 2 == pytest.approx(300.0 * 0.05 / 2, rel=1e-14)
    # At the reference size the reference's own speed comes back.
    assert reference.scaled(0.05, 0.02, law=name).max_speed == pytest.approx(300.0, rel=1e-15)


def test_speed_scaling_both_exponents_against_hand_and_casadi():
    law = cr.hardware.ScalingLaw("test", 2.0, 4.0, 2.5, "test", speed=SpeedScaling(0.5, -1.5, "test law"))
    reference = _fast_motor()
    diameters, lengths = np.array([0.025, 0.05, 0.2]), np.array([0.08, 0.02, 0.005])
    # omega = 300 (l/l0)^0.5 (r/r0)^-1.5: (4^0.5 0.5^-1.5, 1, 0.25^0.5 4^-1.5) = (5.657, 1, 0.0625) x 300
    hand = 300.0 * np.array([2.0 * 2**1.5, 1.0, 0.5 / 8.0])
    numeric = cr.hardware.scaled_motor_quantities(reference, diameters, lengths, law)
    np.testing.assert_allclose(numeric.max_speed, hand, rtol=1e-14)
    for sym_r, sym_l in ((ca.SX.sym("r", 3), ca.SX.sym("l", 3)), (ca.MX.sym("r", 3), ca.MX.sym("l", 3))):
        symbolic = cr.hardware.scaled_motor_quantities(reference, sym_r, sym_l, law).max_speed
        got = ca.Function("f", [sym_r, sym_l], [symbolic])(diameters, lengths)
        np.testing.assert_allclose(np.asarray(got).ravel(), hand, rtol=1e-14)


def test_unknown_max_speed_stays_unknown():
    reference = _fast_motor(max_speed=None)
    assert reference.scaled(0.1, 0.03).max_speed is None
    assert cr.hardware.scaled_motor_quantities(reference, np.array([0.01, 0.1])).max_speed is None
    assert cr.hardware.scaled_motor_quantities(reference, ca.SX.sym("r")).max_speed is None
    with pytest.raises(cr.InvalidParameter, match="no speed limit known for motor 'fast'"):
        reference.speed_limit()
    assert _fast_motor().speed_limit() == 300.0


def test_reference_max_speed_is_a_marked_estimate():
    motor = cr.reference_motor()
    # The catalogue's estimate: 10 m/s at the 40.6 mm rotor OD of tab:motor_params, rounded to 4 figures.
    assert motor.max_speed == pytest.approx(10.0 / 0.0203, rel=1e-4)
    assert "estimate" in motor.source.lower()
    assert "surface speed" in cr.hardware.scaling_law("haddadin").speed.source


def test_max_speed_and_speed_scaling_validated():
    with pytest.raises(cr.InvalidParameter, match=r"Motor\.max_speed"):
        _fast_motor(max_speed=-1.0)
    with pytest.raises(cr.InvalidParameter, match=r"Motor\.max_speed"):
        _fast_motor(max_speed="3000 rpm")  # type: ignore[arg-type]
    with pytest.raises(cr.InvalidParameter, match="diameter_exponent"):
        SpeedScaling(0.0, float("nan"), "x")
    with pytest.raises(cr.InvalidParameter, match=r"ScalingLaw\.speed"):
        cr.hardware.ScalingLaw("x", 2.0, 4.0, 2.5, speed=-1.0)  # type: ignore[arg-type]
    with pytest.raises(cr.InvalidParameter, match=r"ScalingLaw\.torque_exponent"):
        cr.hardware.ScalingLaw("x", 2.0, 4.0, 0.0)  # a zero exponent divided J_m ~ tau**p by zero


def test_a_name_or_reference_of_the_wrong_kind_is_invalid_parameter():
    """get_motor([1, 2]) raised 'unhashable type'; scaled_motor_quantities(0.06, ...) an AttributeError."""
    with pytest.raises(cr.InvalidParameter, match=r"^name ="):
        cr.hardware.motors.get_motor(np.ones(2))
    with pytest.raises(cr.InvalidParameter, match=r"^reference ="):
        cr.hardware.motors.scaled_motor_quantities(0.06, 0.05)
