"""The effective-parameter formulas (model.effective) and the sensing schemes (model.sensing) on their own, against
explicit matrix algebra, the paper's published values and the CasADi backend.

Tolerances: 1e-12 relative where an explicit inverse replaces a solve on matrices of condition number below 1e2
(rounding only); the paper's table gives three significant figures, hence 5e-3 there.
"""

from __future__ import annotations

import casadi as ca
import numpy as np
import pytest

from collision_reflex.errors import InvalidParameter
from collision_reflex.hardware.motors import reference_motor
from collision_reflex.model import effective, sensing
from collision_reflex.vocabulary import SENSING_SCHEMES


@pytest.fixture
def system():
    """A random well-conditioned 4-joint system: SPD mass matrices, influence matrices, moment arms."""
    rng = np.random.default_rng(3)
    n, nv = 5, 4
    base = rng.standard_normal((n, nv, nv))
    mass = base @ np.swapaxes(base, 1, 2) + nv * np.eye(nv)
    arms = rng.standard_normal((n, nv, 3, nv)) * 0.3
    influence = np.swapaxes(arms, -1, -2) @ arms  # A_i = J_i^T J_i, positive semi-definite
    return mass, influence, rng.uniform(0.5, 2.0, nv), rng.standard_normal((n, nv)), rng.uniform(0.1, 1, nv)


def test_finger_mass_matrix_adds_motor_masses_and_finger_inertia(system):
    mass, influence, motor_mass, _, inertia = system
    got = effective.finger_mass_matrix(mass, influence, motor_mass, inertia)
    expected = mass + sum(motor_mass[i] * influence[:, i] for i in range(4)) + np.diag(inertia)
    np.testing.assert_allclose(got, expected, rtol=1e-14)


def test_finger_mass_is_the_inverse_of_the_inverse_inertia_along_w(system):
    mass, _, _, w, _ = system
    x = effective.finger_mass_direction(w, mass)
    np.testing.assert_allclose(np.einsum("si,si->s", w, x), 1.0, rtol=1e-12)
    explicit = 1 / np.einsum("si,sij,sj->s", w, np.linalg.inv(mass), w)
    np.testing.assert_allclose(effective.finger_mass(x, mass), explicit, rtol=1e-12)
    # Any other x with w^T x = 1 gives a larger x^T M x: the variational form the optimiser relies on.
    other = x + np.random.default_rng(0).standard_normal(x.shape) * 0.1
    other /= np.einsum("si,si->s", w, other)[:, None]
    assert np.all(effective.finger_mass(other, mass) > explicit)


def test_task_forms_match_explicit_matrices(system):
    mass, _, _, _, stiffness = system
    jacobian = np.random.default_rng(1).standard_normal((5, 3, 4))
    np.testing.assert_allclose(
        effective.task_compliance(jacobian, stiffness),
        jacobian @ np.diag(1 / stiffness) @ np.swapaxes(jacobian, 1, 2),
        rtol=1e-12,
    )
    np.testing.assert_allclose(
        effective.task_inverse_inertia(jacobian, mass),
        jacobian @ np.linalg.inv(mass) @ np.swapaxes(jacobian, 1, 2),
        rtol=1e-12,
    )
    # Infinite joint stiffness: that joint drops out of the compliance.
    rigid = np.array([np.inf, *stiffness[1:]])
    reduced = jacobian[..., 1:] @ np.diag(1 / stiffness[1:]) @ np.swapaxes(jacobian[..., 1:], 1, 2)
    np.testing.assert_allclose(effective.task_compliance(jacobian, rigid), reduced, rtol=1e-12)


def test_reaction_force_is_set_by_the_first_joint_to_saturate():
    w = np.array([[0.5, -0.2, 0.1], [0.0, 0.3, -0.6]])
    torque = np.array([10.0, 2.0, 3.0])
    compliance = effective.reaction_compliance(effective.torque_fractions(w, torque))
    # Contact forces at which each joint saturates: tau_i / |w_i|; F_a is the smallest.
    np.testing.assert_allclose(1 / compliance, [10.0, 5.0], rtol=1e-14)
    transposed = effective.torque_fractions(w.T, torque[:, None])
    np.testing.assert_allclose(effective.reaction_compliance(transposed, joint_axis=-2), compliance)
    robot = np.array([0.25, 0.5])  # 1 / m_r [1/kg]
    np.testing.assert_allclose(effective.reaction_acceleration(robot, compliance), [10.0 / 4, 5.0 / 2])


def test_reflected_inertia_reproduces_the_paper_m1_motor():
    """tab:motor_params, M1: the reference motor scaled to 10 mm (Haddadin) geared to 1.3 N m has
    N = 88.18 and N^2 J_m = 1.33e-4 kg m^2."""
    motor = reference_motor().scaled(stator_diameter=0.010, law="haddadin")
    ratio = 1.3 / motor.peak_torque
    assert ratio == pytest.approx(88.18, rel=5e-3)
    assert effective.reflected_inertia(ratio, motor.rotor_inertia) == pytest.approx(1.33e-4, rel=5e-3)


def test_finger_inertia_placement():
    inertia = np.array([0.1, 0.2])
    np.testing.assert_array_equal(effective.finger_inertia(inertia, 1.0), inertia)
    np.testing.assert_array_equal(effective.finger_inertia(inertia, 0.0), 0.0)
    np.testing.assert_array_equal(effective.finger_inertia(inertia, np.array([True, False])), [0.1, 0.0])


def test_casadi_backend_gives_the_numpy_values(system):
    """The same formulas on CasADi objects (one sample) give the NumPy numbers."""
    mass, influence, motor_mass, w, inertia = system
    m = ca.SX.sym("m", 4)
    matrix = effective.finger_mass_matrix(
        ca.DM(mass[0]), [ca.DM(influence[0, i]) for i in range(4)], m, ca.DM(inertia)
    )
    direction = effective.finger_mass_direction(ca.DM(w[0]), matrix)
    finger = ca.Function("finger", [m], [effective.finger_mass(direction, matrix)])
    numpy_matrix = effective.finger_mass_matrix(mass[:1], influence[:1], motor_mass, inertia)
    expected = 1 / (w[0] @ np.linalg.solve(numpy_matrix[0], w[0]))
    assert float(finger(motor_mass)) == pytest.approx(expected, rel=1e-12)
    compliance = effective.task_compliance(ca.DM(w[:1]), m)
    value = float(ca.Function("c", [m], [compliance])(inertia))
    assert value == pytest.approx(float(np.sum(w[0] ** 2 / inertia)), rel=1e-12)
    fractions = effective.torque_fractions(ca.DM(w[0]), m)
    torque = ca.Function("r", [m], [effective.reaction_compliance(fractions)])
    assert float(torque(inertia)) == pytest.approx(float(np.max(np.abs(w[0]) / inertia)), rel=1e-14)


def test_sensing_thresholds():
    k = np.array([100.0, 400.0])
    np.testing.assert_array_equal(sensing.threshold_force("force", 3.0, k), 3.0)
    np.testing.assert_allclose(sensing.threshold_force("position", 0.01, k), [1.0, 4.0])
    # The paper's A8 against the U8: a geared motor-current threshold is N times the motor-side one.
    assert sensing.current_threshold_torque(10.0, 0.3, 0.5) == pytest.approx(3.5)
    with pytest.raises(InvalidParameter, match="sensing"):
        sensing.threshold_force("current", 1.0, k)


def test_sensing_vocabulary():
    assert SENSING_SCHEMES == ("force", "position", "current")
    assert sensing.sensing_scheme("current") == "current"
    with pytest.raises(InvalidParameter, match="sensing"):
        sensing.sensing_scheme("joint_torque")  # the current scheme's name before the first release
    with pytest.raises(InvalidParameter, match="sensing"):
        sensing.sensing_scheme("current", ("force", "position"))


def test_the_formulas_refuse_what_numpy_would_fail_on_with_the_argument_named(system) -> None:
    """Shapes that do not fit, a singular mass matrix, zero moment arms, an overflow: one located error each."""
    mass, _, motor_mass, _, _ = system
    with pytest.raises(InvalidParameter, match=r"jacobian, mass_matrix .*shapes that fit together"):
        effective.task_inverse_inertia(np.ones((3, 5)), mass)  # 5 joints against 4
    with pytest.raises(InvalidParameter, match="non-singular matrices"):
        effective.task_inverse_inertia(np.ones((3, 4)), np.zeros((4, 4)))
    with pytest.raises(InvalidParameter, match="motor_mass_influence"):
        effective.finger_mass_matrix(mass, None, motor_mass)  # masses without their influence matrices
    with pytest.raises(InvalidParameter, match="not all zero"):
        effective.finger_mass_direction(np.zeros(4), mass[0])  # no joint moves the contact: 0/0
    with pytest.raises(InvalidParameter, match="float64 range"):
        effective.reflected_inertia(1e200, 1.0)
    with pytest.raises(InvalidParameter, match="in_finger"):
        effective.finger_inertia(1e-3, 2.0)  # a fraction of the rotor beyond the whole
    assert effective.finger_inertia(np.array([1e-3, 2e-3]), np.array([True, False])).tolist() == [1e-3, 0.0]


def test_casadi_arguments_pass_the_checks_unchanged() -> None:
    """The optimiser's symbols cannot be checked: the formulas build the same expressions as before."""
    w, m = ca.SX.sym("w", 2), ca.SX.sym("m", 2)
    fractions = effective.torque_fractions(w, ca.DM([10.0, 5.0]))
    value = ca.Function("f", [w], [effective.reaction_compliance(fractions)])(ca.DM([0.3, -0.4]))
    assert float(value) == pytest.approx(0.08, rel=1e-15)
    matrix = effective.finger_mass_matrix(ca.DM(np.eye(2)), [ca.DM(np.eye(2))] * 2, m)
    assert ca.Function("g", [m], [matrix])(ca.DM([1.0, 2.0])).full().tolist() == [[4.0, 0.0], [0.0, 4.0]]


def test_effective_formulas_refuse_no_joints_unfitting_shapes_and_overflow():
    """An empty joint axis, unbroadcastable arrays or an overflowing N tau_s were NumPy errors or a silent inf."""
    calls = {
        "fractions": lambda: effective.reaction_compliance(np.array([])),
        "joint_reflected_inertia, in_finger": lambda: effective.finger_inertia(np.eye(2), np.array([])),
        "robot_compliance, reaction_compliance_": lambda: effective.reaction_acceleration(
            np.ones((3, 3)), np.ones(2)
        ),
        "gear_ratio, motor_torque": lambda: sensing.current_threshold_torque(1e300, 2**62),
        "gear_ratio, motor_torque, friction_torque": lambda: sensing.current_threshold_torque(
            np.ones((3, 3)), np.ones(2)
        ),
    }
    for name, call in calls.items():
        with pytest.raises(InvalidParameter, match=f"^{name} ="):
            call()
