"""Reflex surfaces of the planar two-link arm: the paper's qualitative findings (``fig:two_link``)."""

from __future__ import annotations

import itertools
from pathlib import Path

import numpy as np
import pytest

from collision_reflex.arm import Arm, JointParameters
from collision_reflex.arm.surfaces import reflex_surface
from collision_reflex.errors import InvalidParameter

TWO_LINK = Path(__file__).resolve().parents[1] / "designs" / "planar_two_link.urdf"
# Direct-drive Omni+ OPN-060-013-A at both joints (tab:motor_params, M2): J_m [kg m^2], peak torque [N m];
# joint springs of 250 N m/rad (about 1000 N/m at the 0.5 m reach, the paper's 1D mechanical stiffness) and a
# 100 N/m Cartesian controller with a 3 N force threshold (fig:motor_scale_modeling).
J_M, TAU_P, K_JOINT, K_TASK, F_S = 2.21e-5, 1.3, 250.0, 100.0, 3.0


def _arm(reflected=(J_M, J_M), torque=(TAU_P, TAU_P), motor_mass=(0.0, 0.0)) -> Arm:
    params = JointParameters(np.array(reflected), np.array(torque), K_JOINT, K_JOINT, np.array(motor_mass))
    return Arm.from_urdf(TWO_LINK, "tip", actuators=params)


@pytest.fixture(scope="module")
def arm() -> Arm:
    return _arm()


def _surface(arm: Arm, q2_deg: float = 45.0, v0: float = 0.5, directions=None):
    return reflex_surface(
        arm, [0.0, np.radians(q2_deg)], v0, F_S, task_stiffness=K_TASK, directions=directions
    )


def _aspect(surface) -> float:
    return float(surface.impulse.max() / surface.impulse.min())


def test_surface_elongates_toward_the_singularity(arm):
    angles = [90.0, 45.0, 20.0, 5.0, 1.0]
    surfaces = [_surface(arm, q2) for q2 in angles]
    aspects = [_aspect(s) for s in surfaces]
    assert all(later > earlier for earlier, later in itertools.pairwise(aspects)), aspects
    # The long axis turns toward the arm's line, the singular direction at q2 = 0.
    offsets = []
    for s in surfaces:
        radial = s.contact_position[:2] / np.linalg.norm(s.contact_position[:2])
        offsets.append(np.degrees(np.arccos(abs(s.extremes()[1] @ radial))))
    assert offsets[-1] < 1.0 and offsets == sorted(offsets, reverse=True)
    stretched = _surface(arm, 0.0)
    assert np.isinf(stretched.impulse.max()) and np.isfinite(stretched.impulse.min())
    assert stretched.parameters.singular.sum() == 2  # both senses of the arm's line (one per degree swept)


def test_low_velocity_approaches_a_circle(arm):
    aspects = {v: _aspect(_surface(arm, v0=v)) for v in (0.5, 0.005)}
    assert aspects[0.005] < 0.6 * aspects[0.5]
    # As v0 -> 0 the sensing phase F_s^2 / (2 k v0) dominates: the aspect ratio tends to that of 1/k, which the
    # 100 N/m Cartesian spring in series with ~1000 N/m joint springs keeps within ~10 % of a circle.
    slow = _surface(arm, v0=0.005)
    compliance = 1 / slow.parameters.k
    # At 5 mm/s the impact and reaction phases add about 1e-4 of the sensing phase (m_f v0 = 2.5e-4 N s
    # against F_s^2 / (2 k v0) = 10 N s; I3 ~ 1e-3 N s): 1e-3 tolerance.
    assert aspects[0.005] == pytest.approx(compliance.max() / compliance.min(), rel=1e-3)
    assert aspects[0.005] < 1.15


def test_high_velocity_takes_the_shape_of_the_effective_mass(arm):
    """Fast impacts are dominated by the impact phase m_f v0: the surface tends to the effective-mass
    surface, whatever the actuators."""
    fast = _surface(arm, v0=50.0)
    mass = fast.parameters.m_f
    # At 50 m/s the sensing and reaction phases (about 1e-3 N s) are below 1e-3 of the impact phase (m_f v0,
    # several N s): 5e-3 tolerance.
    np.testing.assert_allclose(fast.impulse / fast.impulse.max(), mass / mass.max(), atol=5e-3)
    assert _aspect(fast) == pytest.approx(mass.max() / mass.min(), rel=5e-3)


def _two_link_kinematics(q) -> np.ndarray:
    l1, l2 = 0.30, 0.25
    s1, c1, s12, c12 = np.sin(q[0]), np.cos(q[0]), np.sin(q[0] + q[1]), np.cos(q[0] + q[1])
    return np.array([[-l1 * s1 - l2 * s12, -l2 * s12], [l1 * c1 + l2 * c12, l2 * c12]])


@pytest.mark.parametrize("joint", [0, 1], ids=["motor-1", "motor-2"])
def test_motor_scaling_changes_only_directions_the_actuator_reaches(joint):
    """A bigger (geared) motor at one joint: more reflected inertia and torque. The impulse changes wherever
    that joint takes part in the motion along u, and not at all along the direction where (J^T u)_joint = 0."""
    q = [0.0, np.radians(45.0)]
    jac = _two_link_kinematics(q)
    column = jac[:, joint]
    unmoved = np.array([column[1], -column[0]]) / np.linalg.norm(column)  # u with (J^T u)_joint = 0
    directions = np.vstack([unmoved, -unmoved, [[1.0, 0.0], [0.0, 1.0], [-0.6, 0.8]]])
    reflected, torque = [J_M, J_M], [TAU_P, TAU_P]
    reflected[joint], torque[joint] = 0.05, 20.0  # a geared actuator at that joint: heavier, stronger
    base = _surface(_arm(), directions=directions)
    scaled = _surface(_arm(tuple(reflected), tuple(torque)), directions=directions)
    # Same arithmetic on identical inputs along the unmoved direction: equal to rounding.
    np.testing.assert_allclose(scaled.impulse[:2], base.impulse[:2], rtol=1e-12)
    # Elsewhere the reaction phase changes (a small part of the total here): far beyond rounding.
    assert np.all(np.abs(scaled.impulse[2:] / base.impulse[2:] - 1) > 1e-4)


def test_surface_inputs_are_checked(arm):
    with pytest.raises(InvalidParameter, match="one configuration"):
        reflex_surface(arm, [0.0, 0.1, 0.2], 0.5, F_S)
    with pytest.raises(InvalidParameter, match="v0"):
        reflex_surface(arm, [0.0, 0.1], -1.0, F_S)


def test_spatial_surface_on_the_sphere():
    ur5 = Arm.from_example_robot_data(
        "ur5", actuators=JointParameters(0.05, [150, 150, 150, 28, 28, 28], 800.0, 3000.0, 0.0)
    )
    q = ur5.sample_configurations(1, np.random.default_rng(4))[0]
    surface = reflex_surface(ur5, q, 0.2, 5.0, directions=200)
    assert surface.directions.shape == (200, 3) and np.all(np.isfinite(surface.impulse))
    # Opposite directions give equal impulses: every effective parameter is even in u.
    flipped = reflex_surface(ur5, q, 0.2, 5.0, directions=-surface.directions)
    np.testing.assert_allclose(flipped.impulse, surface.impulse, rtol=1e-12)  # rounding only


# Table tab:motor_params: the Omni+ scaled to 10 mm and 100 mm stator diameter with 1.3 N m required.
@pytest.mark.parametrize(
    "diameter, ratio, reflected",
    [(0.010, 88.18, 1.33e-4), (0.060, 1.0, 2.21e-5), (0.100, 1.0, 1.71e-4)],
    ids=["M1", "M2", "M3"],
)
def test_scaled_motors_reproduce_the_paper_table(arm, diameter, ratio, reflected):
    scaled = arm.with_scaled_motors(diameter, 1.3, mechanical_stiffness=K_JOINT)
    assert scaled.actuators[0].gear_ratio == pytest.approx(ratio, rel=1e-3)  # table rounds to 4 digits
    np.testing.assert_allclose(scaled.model.armature, reflected, rtol=5e-3)  # the table prints 3 digits
    np.testing.assert_allclose(
        scaled.torque_limit, max(1.3, scaled.actuators[0].motor.peak_torque), rtol=1e-12
    )


def test_scaling_the_base_motor_leaves_the_radial_direction_unchanged(arm):
    """With real scaled motors (masses included): joint 1's motor sits on the fixed base, so a different
    motor there changes the impulse only where joint 1 moves the contact, never along the radial line."""
    reference = arm.with_scaled_motors(0.060, 1.3, mechanical_stiffness=K_JOINT)
    small = arm.with_scaled_motors(0.010, 1.3, mechanical_stiffness=K_JOINT)
    mixed = arm.with_actuators([small.actuators[0], reference.actuators[1]])
    q = [0.0, np.radians(45.0)]
    jac = _two_link_kinematics(q)
    radial = np.array([0.30 + 0.25 * np.cos(q[1]), 0.25 * np.sin(q[1])])
    radial /= np.linalg.norm(radial)
    assert abs(radial @ jac[:, 0]) < 1e-12  # (J^T u)_1 = 0 along the radial line
    directions = np.vstack([radial, [[0.0, 1.0], [1.0, 0.0]]])
    before = reflex_surface(reference, q, 0.5, F_S, task_stiffness=K_TASK, directions=directions)
    after = reflex_surface(mixed, q, 0.5, F_S, task_stiffness=K_TASK, directions=directions)
    np.testing.assert_allclose(after.impulse[0], before.impulse[0], rtol=1e-12)  # identical inputs: rounding
    assert np.all(np.abs(after.impulse[1:] / before.impulse[1:] - 1) > 1e-6)  # far beyond rounding


def test_surface_uses_the_actuators_sensing(arm):
    from collision_reflex.hardware.actuators import CurrentThreshold, ForceThreshold

    forced = arm.with_scaled_motors(0.060, 1.3, mechanical_stiffness=K_JOINT, sensing=ForceThreshold(4.0))
    surface = reflex_surface(forced, [0.0, 1.0], 0.5, directions=8)
    np.testing.assert_allclose(surface.impulses.threshold, 4.0)
    current = arm.with_scaled_motors(0.010, 1.3, mechanical_stiffness=K_JOINT, sensing=CurrentThreshold(0.01))
    surface = reflex_surface(current, [0.0, 1.0], 0.5, directions=8)
    # The first joint to reach N tau_s detects: F_s = min_i N tau_s / |(J^T u)_i|.
    moments = np.abs(surface.directions @ _two_link_kinematics([0.0, 1.0]))
    ratio = current.actuators[0].gear_ratio
    np.testing.assert_allclose(
        surface.impulses.threshold, (ratio * 0.01) / moments.max(axis=1), rtol=1e-12
    )  # rounding


def test_rescaling_starts_from_the_urdf_torques(arm):
    """The torque requirement defaults to the URDF's effort limits, not to the current actuators' torque."""
    big = arm.with_scaled_motors(0.100)  # torque 4.661 N m, more than the 1.3 N m the URDF asks for
    small = big.with_scaled_motors(0.010)
    assert small.actuators[0].gear_ratio == pytest.approx(88.18, rel=1e-3)  # tab:motor_params, M1
