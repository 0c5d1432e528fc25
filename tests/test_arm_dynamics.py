"""Joint torques over a duty cycle: against the closed-form dynamics of the planar two-link arm, against
Pinocchio models with the motor masses actually added, and the statistics against direct evaluation."""

from __future__ import annotations

from pathlib import Path

import casadi as ca
import numpy as np
import pinocchio as pin
import pytest

from collision_reflex import _backend as backend
from collision_reflex.arm import Arm
from collision_reflex.arm.duty_cycle import DutyCycle, Payload
from collision_reflex.arm.dynamics import (
    cycle_torques,
    joint_side_torque,
    max_speed,
    peak,
    rms,
    time_weights,
)
from collision_reflex.errors import InvalidParameter

TWO_LINK = Path(__file__).resolve().parents[1] / "designs" / "planar_two_link.urdf"
GRAVITY = 9.81  # [m/s^2], turned into the arm's plane below so that the two-link arm has gravity torques


def _two_link_inertias() -> tuple[tuple[float, float, float], tuple[float, float, float]]:
    """(mass [kg], centre of mass [m], inertia about z at the CoM [kg m^2]) of both links, read from the URDF's
    Pinocchio model (an independent reading: the formulas below are written out by hand)."""
    model = pin.buildModelFromUrdf(str(TWO_LINK))
    links = []
    for joint in (1, 2):
        inertia = model.inertias[joint]
        links.append((float(inertia.mass), float(inertia.lever[0]), float(inertia.inertia[2, 2])))
    return links[0], links[1]


def _closed_form_torques(
    q: np.ndarray, qd: np.ndarray, qdd: np.ndarray, motor2: float, payload: float, payload_izz: float
) -> np.ndarray:
    """``M(q) qdd + C(q, qd) qd + g(q)`` of a planar 2R arm, gravity ``-GRAVITY`` along world y.

    Link 1 carries motor 2 (a point mass at joint 2, ``L1`` from joint 1); link 2 carries the payload (a point
    mass at the tip, ``L2`` from joint 2, plus its inertia about z). Motor 1 sits on the base: it adds nothing.
    """
    (m1, c1, i1), (m2, c2, i2) = _two_link_inertias()
    length1, length2 = 0.30, 0.25
    first1 = m1 * c1 + motor2 * length1  # first moment of link 1 about joint 1 [kg m]
    inertia1 = i1 + m1 * c1**2 + motor2 * length1**2  # about joint 1 [kg m^2]
    mass2 = m2 + payload
    first2 = m2 * c2 + payload * length2
    inertia2 = i2 + m2 * c2**2 + payload_izz + payload * length2**2  # about joint 2
    cos2, sin2 = np.cos(q[:, 1]), np.sin(q[:, 1])
    m11 = inertia1 + inertia2 + mass2 * length1**2 + 2 * length1 * first2 * cos2
    m12 = inertia2 + length1 * first2 * cos2
    h = length1 * first2 * sin2
    coriolis = np.column_stack([-h * (2 * qd[:, 0] * qd[:, 1] + qd[:, 1] ** 2), h * qd[:, 0] ** 2])
    cos1, cos12 = np.cos(q[:, 0]), np.cos(q[:, 0] + q[:, 1])
    gravity = GRAVITY * np.column_stack([(first1 + mass2 * length1) * cos1 + first2 * cos12, first2 * cos12])
    inertial = np.column_stack([m11 * qdd[:, 0] + m12 * qdd[:, 1], m12 * qdd[:, 0] + inertia2 * qdd[:, 1]])
    return inertial + coriolis + gravity


def _sine_cycle(names: tuple[str, ...], n: int = 400, payload: Payload | None = None) -> DutyCycle:
    """An analytic motion (positions, velocities, accelerations exact) over 2 s, one sine per joint."""
    t = np.linspace(0.0, 2.0, n)
    k = np.arange(len(names))
    amplitude, omega, phase = 0.4 + 0.1 * k, np.pi * (1 + 0.5 * k), 0.3 * k
    angle = omega * t[:, None] + phase
    return DutyCycle(
        names,
        t,
        amplitude * np.sin(angle) + 0.1,
        amplitude * omega * np.cos(angle),
        -amplitude * omega**2 * np.sin(angle),
        payload,
    )


@pytest.fixture(scope="module")
def two_link_vertical() -> Arm:
    model = pin.buildModelFromUrdf(str(TWO_LINK))
    model.gravity.linear = np.array([0.0, -GRAVITY, 0.0])  # in the arm's plane
    return Arm(model, "tip")


def test_two_link_torques_match_closed_form(two_link_vertical):
    payload = Payload(0.4, np.diag([1e-4, 2e-4, 3e-4]))
    cycle = _sine_cycle(two_link_vertical.joint_names, payload=payload)
    torques = cycle_torques(two_link_vertical, cycle)
    motor_mass = np.array([0.7, 0.3])
    expected = _closed_form_torques(cycle.q, cycle.qd, cycle.qdd, motor_mass[1], 0.4, 3e-4)
    # The same dynamics evaluated two ways in double precision: agreement to rounding of ~1 N m terms.
    np.testing.assert_allclose(torques.torque(motor_mass), expected, rtol=0, atol=1e-12)
    # Motor 1 sits on the base, which never moves: it needs no torque.
    np.testing.assert_array_equal(torques.per_motor_mass[0], 0.0)
    # Without motors and payload the torques differ by terms of order 0.1 N m: the test can see them.
    bare = _closed_form_torques(cycle.q, cycle.qd, cycle.qdd, 0.0, 0.0, 0.0)
    assert np.max(np.abs(bare - expected)) > 0.1


@pytest.mark.parametrize("name", ["ur5", "panda"])
def test_motor_mass_decomposition_matches_added_bodies(name):
    arm = Arm.from_example_robot_data(name)
    rng = np.random.default_rng(3)
    lower, upper = arm.joint_limits()
    via = rng.uniform(lower / 2, upper / 2, size=(3, arm.nv))
    cycle = DutyCycle.through_via_points(via, arm.joint_names, 2.0, 6.0, rate=100.0)
    torques = cycle_torques(arm, cycle)
    masses = rng.uniform(0.2, 3.0, arm.nv)
    model = arm.model.copy()
    model.armature = np.zeros(model.nv)
    for joint in range(1, model.njoints):  # motor i: a point mass on the parent link at joint i's origin
        point_mass = pin.Inertia(masses[joint - 1], np.zeros(3), np.zeros((3, 3)))
        model.appendBodyToJoint(model.parents[joint], point_mass, model.jointPlacements[joint])
    data = model.createData()
    q = arm.configuration(cycle.q)
    expected = np.array([pin.rnea(model, data, q[s], cycle.qd[s], cycle.qdd[s]) for s in range(len(q))])
    np.testing.assert_allclose(torques.torque(masses), expected, rtol=0, atol=1e-10)
    # The motors matter at this tolerance: several N m.
    assert np.max(np.abs(expected - torques.structure)) > 1.0


def test_payload_matches_added_body():
    arm = Arm.from_example_robot_data("ur5")
    payload = Payload(2.0, [[0.02, 0.001, 0.0], [0.001, 0.03, 0.0], [0.0, 0.0, 0.04]])
    cycle = _sine_cycle(arm.joint_names, n=50, payload=payload)
    with_payload = cycle_torques(arm, cycle).structure
    bare = cycle_torques(arm, _sine_cycle(arm.joint_names, n=50)).structure
    # Independent: the payload as a point mass (Pinocchio frame Jacobian at the contact point) plus its
    # rotational inertia through the contact frame's angular Jacobian and acceleration.
    model = arm.model.copy()
    model.armature = np.zeros(model.nv)
    data = model.createData()
    frame = model.getFrameId(arm.contact_frame)
    q = arm.configuration(cycle.q)
    gravity = np.asarray(model.gravity.linear)
    for s in range(len(q)):
        pin.forwardKinematics(model, data, q[s], cycle.qd[s], cycle.qdd[s])
        pin.updateFramePlacements(model, data)
        jac = pin.computeFrameJacobian(model, data, q[s], frame, pin.LOCAL)
        accel = pin.getFrameClassicalAcceleration(model, data, frame, pin.LOCAL)
        omega = pin.getFrameVelocity(model, data, frame, pin.LOCAL).angular
        rotation = data.oMf[frame].rotation
        force = payload.mass * (accel.linear - rotation.T @ gravity)
        inertia = payload.inertia
        moment = inertia @ accel.angular + np.cross(omega, inertia @ omega)
        expected = jac[:3].T @ force + jac[3:].T @ moment
        np.testing.assert_allclose(with_payload[s] - bare[s], expected, rtol=0, atol=1e-10)
    assert np.max(np.abs(with_payload - bare)) > 1.0  # 2 kg on a UR5: tens of N m


def test_rotor_term_and_statistics_against_direct_evaluation(two_link_vertical):
    cycle = _sine_cycle(two_link_vertical.joint_names)
    torques = cycle_torques(two_link_vertical, cycle)
    motor_mass, reflected = np.array([0.5, 0.25]), np.array([0.02, 0.005])
    demand = torques.demand(motor_mass, reflected)
    base = torques.torque(motor_mass)
    for s in range(cycle.t.size):  # sample by sample: tau + N^2 J_m qdd
        for j in range(2):
            assert demand[s, j] == pytest.approx(base[s, j] + reflected[j] * cycle.qdd[s, j], abs=1e-14)
    duration = cycle.duration
    direct = np.sqrt(np.trapezoid(demand**2, cycle.t, axis=0) / duration)
    np.testing.assert_allclose(rms(demand.T, cycle.t), direct, rtol=1e-13)
    np.testing.assert_allclose(peak(demand.T), np.max(np.abs(demand), axis=0), rtol=0)
    for j in range(2):
        x = np.concatenate([[1.0], motor_mass, [reflected[j]]])
        np.testing.assert_allclose(torques.demand_basis(j) @ x, demand[:, j], rtol=0, atol=1e-13)
        np.testing.assert_allclose(np.sqrt(x @ torques.rms_form(j) @ x), direct[j], rtol=1e-12)


def test_rms_of_a_sine_on_a_non_uniform_grid():
    amplitude, omega = 3.0, 2 * np.pi
    rng = np.random.default_rng(0)
    t = np.sort(np.concatenate([[0.0, 1.0], rng.uniform(0, 1, 300)]))
    h = np.max(np.diff(t))
    # Trapezoid rule on f^2 over one period: error <= T h^2 max|(f^2)''| / 12, (f^2)'' = 2 A^2 w^2 cos(2 w t),
    # so the mean square is within A^2 w^2 h^2 / 6 and the RMS within half that relative to A^2 / 2.
    tolerance = amplitude**2 * omega**2 * h**2 / 6 / amplitude**2
    got = rms(amplitude * np.sin(omega * t), t)
    assert got == pytest.approx(amplitude / np.sqrt(2), rel=tolerance)
    assert tolerance < 0.05  # a 10 % error would fail
    np.testing.assert_allclose(time_weights(t).sum(), 1.0, rtol=1e-14)


def test_statistics_accept_casadi(two_link_vertical):
    cycle = _sine_cycle(two_link_vertical.joint_names, n=60)
    torques = cycle_torques(two_link_vertical, cycle)
    x = ca.SX.sym("x", torques.nv + 2)
    demand = ca.mtimes(ca.DM(torques.demand_basis(1)), x)
    value = np.array([1.0, 0.5, 0.25, 0.005])
    functions = ca.Function("stats", [x], [peak(demand), rms(demand, cycle.t)])
    numeric_peak, numeric_rms = (float(v) for v in functions(value))
    exact = torques.demand([0.5, 0.25], [0.0, 0.005])[:, 1]
    assert numeric_peak == pytest.approx(np.max(np.abs(exact)), rel=1e-13)
    assert numeric_rms == pytest.approx(
        np.sqrt(backend.quadratic_form(torques.rms_form(1), value)), rel=1e-12
    )


def test_joint_side_torque_is_affine_in_reflected_inertia():
    assert joint_side_torque(2.0, 0.5, 4.0) == 4.0
    np.testing.assert_array_equal(
        joint_side_torque(np.ones((3, 2)), np.array([1.0, 2.0]), np.ones((3, 2))), np.full((3, 2), [2.0, 3.0])
    )


def test_max_speed_hand_case():
    # Joint 0 moves 1 rad, joint 1 0.5 rad, limits 1 rad/s and 2 rad/s^2: joint 0 limits, cruising at
    # 1 rad/s after 0.5 s; joint 1, synchronised, cruises at half that.
    cycle = DutyCycle.through_via_points([[0.0, 0.0], [1.0, 0.5]], ("a", "b"), 1.0, 2.0, rate=50.0)
    np.testing.assert_allclose(max_speed(cycle.qd), [1.0, 0.5], rtol=1e-14)
    assert cycle.duration == pytest.approx(1.5, rel=1e-14)


def test_cycle_must_cover_the_arm(two_link_vertical):
    cycle = _sine_cycle(("joint1", "elbow"))
    with pytest.raises(InvalidParameter, match="joint2"):
        cycle_torques(two_link_vertical, cycle)
    with pytest.raises(InvalidParameter, match="increasing"):
        time_weights([0.0, 0.0, 1.0])


def test_max_speed_refuses_a_nan_or_a_vector_instead_of_returning_nan():
    """max_speed([nan, 1]) returned an array(nan); complex values a bare TypeError."""
    from collision_reflex.arm.dynamics import max_speed
    from collision_reflex.errors import InvalidParameter

    for velocity in (np.array([[np.nan, 1.0], [0.0, 1.0]]), np.array([np.nan, 1.0]), 1 + 1j):
        with pytest.raises(InvalidParameter, match="velocity"):
            max_speed(velocity)
    assert max_speed(np.array([[1.0, -3.0], [-2.0, 0.5]])).tolist() == [2.0, 3.0]
