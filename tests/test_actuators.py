"""Actuator quantities and sensing schemes against hand computation and the paper's relations."""

from __future__ import annotations

import math

import numpy as np
import pytest

import collision_reflex as cr

MOTOR = cr.Motor("test", 0.05, 0.02, 2e-5, 1.5, 0.6, 0.4)


@pytest.mark.parametrize("gear", [1.0, 3.0, 9.0, 50.0], ids=["dd", "N3", "N9", "N50"])
def test_reflected_inertia_scales_with_n_squared(gear):
    actuator = cr.Actuator(MOTOR, gear_ratio=gear)
    assert actuator.reflected_inertia == pytest.approx(gear**2 * 2e-5, rel=1e-15)
    assert actuator.peak_torque == pytest.approx(gear * 1.5, rel=1e-15)
    assert actuator.continuous_torque == pytest.approx(gear * 0.6, rel=1e-15)


def test_gear_ratio_for():
    assert cr.hardware.gear_ratio_for(1.3, 0.65) == 2.0
    assert cr.hardware.gear_ratio_for(1.3, 2.6) == 1.0  # a motor strong enough is direct drive
    np.testing.assert_array_equal(
        cr.hardware.gear_ratio_for(1.0, np.array([0.1, 1.0, 4.0])), [10.0, 1.0, 1.0]
    )
    with pytest.raises(cr.InvalidParameter, match="peak_torque"):
        cr.hardware.gear_ratio_for(1.0, 0.0)


def test_stiffness_is_series_and_mass_adds_gearbox():
    actuator = cr.Actuator(MOTOR, mechanical_stiffness=300.0, software_stiffness=600.0)
    assert actuator.stiffness == pytest.approx(200.0, rel=1e-15)  # 1/(1/300 + 1/600)
    assert cr.Actuator(MOTOR).stiffness == math.inf
    gearbox = cr.hardware.Gearbox(
        "harmonic", diameter=0.05, length=0.03, mass=0.25, inertia=1e-6, rated_torque=20.0
    )
    geared = cr.Actuator(MOTOR, 30.0, gearbox=gearbox)
    assert geared.mass == pytest.approx(0.65, rel=1e-15)
    assert (
        geared.peak_torque == pytest.approx(45.0) and geared.torque_limit == 20.0
    )  # the gearbox's rating caps
    assert cr.Actuator(MOTOR, 10.0, gearbox=gearbox).torque_limit == pytest.approx(15.0)


def test_gearbox_inertia_is_optional():
    gearbox = cr.hardware.Gearbox("planetary", 2, 0.04, 0.03, 0.2, 3e-7, 10.0)
    off = cr.Actuator(MOTOR, 9.0, gearbox=gearbox)
    on = cr.Actuator(MOTOR, 9.0, gearbox=gearbox, gearbox_inertia=True)
    assert off.reflected_inertia == pytest.approx(81 * 2e-5, rel=1e-15)  # the paper's default: rotor only
    assert on.reflected_inertia == pytest.approx(81 * (2e-5 + 3e-7), rel=1e-15)


@pytest.mark.parametrize("gear", [0.5, 0.0, float("nan"), float("inf")], ids=["half", "zero", "nan", "inf"])
def test_gear_ratio_below_one_rejected(gear):
    with pytest.raises(cr.InvalidParameter, match="gear_ratio"):
        cr.Actuator(MOTOR, gear_ratio=gear)


def test_contact_parameters_map_through_the_lever():
    lever = 0.2
    actuator = cr.Actuator(MOTOR, 4.0, mechanical_stiffness=80.0, software_stiffness=40.0)
    robot = actuator.contact_parameters(lever, m_f=0.1)
    reflected = 16 * 2e-5 / 0.04  # N^2 J_m / L^2
    assert robot.m_f == pytest.approx(0.1, rel=1e-15)
    assert robot.m_r == pytest.approx(reflected, rel=1e-15)
    assert robot.k_m == pytest.approx(80.0 / 0.04, rel=1e-15)
    assert robot.k == pytest.approx((80 * 40 / 120) / 0.04, rel=1e-15)
    assert robot.F_a == pytest.approx(4 * 1.5 / 0.2, rel=1e-15)
    assert robot.a == pytest.approx(robot.F_a / reflected, rel=1e-15)
    assert robot.F_s == 3.0
    finger = actuator.contact_parameters(lever, m_f=0.1, reflected_inertia_in="finger")
    assert finger.m_f == pytest.approx(0.1 + reflected, rel=1e-15)
    assert finger.m_r == robot.m_r


def test_sensing_thresholds():
    lever = 0.1
    base = dict(motor=MOTOR, gear_ratio=10.0, mechanical_stiffness=50.0, software_stiffness=50.0)
    force = cr.Actuator(**base, sensing=cr.hardware.ForceThreshold(3.0)).contact_parameters(lever, 0.1)
    assert force.F_s == 3.0
    # position error 0.02 rad on a 25 N m/rad joint: 0.5 N m at the joint, 5 N at 0.1 m
    position = cr.Actuator(**base, sensing=cr.hardware.PositionThreshold(0.02)).contact_parameters(lever, 0.1)
    assert position.F_s == pytest.approx(25.0 * 0.02 / lever, rel=1e-15)
    # motor-side 0.01 N m through N = 10, plus 0.05 N m joint friction: 0.15 N m, 1.5 N at 0.1 m
    current = cr.Actuator(**base, sensing=cr.hardware.CurrentThreshold(0.01, 0.05)).contact_parameters(
        lever, 0.1
    )
    assert current.F_s == pytest.approx((10 * 0.01 + 0.05) / lever, rel=1e-15)


def test_contact_parameters_refuse_impossible_setups():
    rigid = cr.Actuator(MOTOR, sensing=cr.hardware.PositionThreshold(0.01))
    with pytest.raises(cr.InvalidParameter, match="mechanical_stiffness"):
        rigid.contact_parameters(0.1, m_f=0.1)  # rigid joint on a rigid constraint: infinite force
    with pytest.raises(cr.InvalidParameter, match="stiffness"):
        rigid.sensing.joint_threshold_torque(rigid)  # a rigid joint never builds a position error
    soft = cr.Actuator(MOTOR, mechanical_stiffness=10.0)
    with pytest.raises(cr.InvalidParameter, match="m_f"):
        soft.contact_parameters(0.1, m_f=0.0)  # nothing hits the constraint in the impact phase
    assert soft.contact_parameters(0.1, 0.0, reflected_inertia_in="finger").m_f == pytest.approx(2e-5 / 0.01)


def test_current_threshold_grows_with_gear_ratio():
    # The paper's A8 (U8 + 9:1) detects at ~40 N against ~3 N for the U8: a motor-side threshold is N times
    # larger at the joint. Same motor-side threshold, N = 1 vs 9: exactly 9x the contact force.
    sensing = cr.hardware.CurrentThreshold(3.0 * 0.1143)
    direct = cr.Actuator(MOTOR, 1.0, mechanical_stiffness=10.0, sensing=sensing).contact_parameters(
        0.1143, 0.1
    )
    geared = cr.Actuator(MOTOR, 9.0, mechanical_stiffness=10.0, sensing=sensing).contact_parameters(
        0.1143, 0.1
    )
    assert direct.F_s == pytest.approx(3.0, rel=1e-14)
    assert geared.F_s == pytest.approx(27.0, rel=1e-14)


def test_contact_parameters_keep_the_robot_mass():
    actuator = cr.Actuator(MOTOR, 4.0, mechanical_stiffness=80.0, software_stiffness=40.0)
    new = actuator.contact_parameters(0.2, m_f=0.1, m_r=0.3)
    assert new.m_r == pytest.approx(0.3 + 16 * 2e-5 / 0.04, rel=1e-15)  # the robot mass is not dropped


def test_gear_ratio_for_names_unfitting_shapes_and_overflow():
    """Unbroadcastable arrays were NumPy's unnamed ValueError; 4.6e18 / 1e-300 returned inf."""
    with pytest.raises(cr.InvalidParameter, match="torque_required, peak_torque"):
        cr.hardware.gear_ratio_for(np.ones((3, 3)), np.ones(2))
    with pytest.raises(cr.InvalidParameter, match="float64 range"):
        cr.hardware.gear_ratio_for(2**62, 1e-300)
