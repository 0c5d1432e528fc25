"""The joint-space collision (:mod:`collision_reflex.model.joint_space`) against independent references.

- its limits: one joint is the 1D model (``m_f v0 + F_s^2 / (2 k v0)`` and ``sprung_reaction``) to round-off;
  links without mass give the sprung reaction with the arm's effective ``m_r``, ``k_m``, ``F_a``; a push far
  above ``F_s`` gives the paper's constant-acceleration reaction;
- a numerical integration of the same constrained equations in joint coordinates (no modes), where the
  derivation's assumptions hold exactly;
- the time-domain arm simulator (nonlinear, compliant wall) at ``v*``, where the 1D closed form is 6-17 % off:
  the model within 2 %, and a wrong ``m_f`` (x1.1) or ``F_a`` (x2) fails that tolerance.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import collision_reflex as cr
from collision_reflex.errors import InvalidParameter
from collision_reflex.model.impulse import phase_impulses, sprung_reaction
from collision_reflex.model.joint_space import joint_space_collision

pytestmark = pytest.mark.xdist_group("test_arm_reaction")  # one pytest-xdist worker: set-ups made once

URDF = Path(__file__).resolve().parents[1] / "designs" / "planar_two_link.urdf"
K_M, ROTOR, TAU, F_S = 50.0, 2.2e-3, 1.3, 3.0


@pytest.fixture(scope="module")
def arm():
    return cr.Arm.from_urdf(URDF, "tip")


def _at(arm, q):
    samples = arm.kinematics(np.asarray(q, dtype=float)[None])
    return samples.mass_matrix[0], samples.jacobian[0]


# --- limits -------------------------------------------------------------------------------------------------


@pytest.mark.parametrize("v0", [0.05, 0.5, 5.0])
@pytest.mark.parametrize("k_s", [math.inf, 30.0])
def test_one_joint_is_the_1d_model(v0, k_s):
    """No direction along the wall: impact, sensing and the sprung reaction of the 1D model, to round-off."""
    lever, inertia = 0.4, 0.03
    result = joint_space_collision(
        [[inertia]], [[lever]], [1.0], K_M, ROTOR, TAU, F_S, v0, software_stiffness=k_s
    )
    m_f, m_r, k_m = inertia / lever**2, ROTOR / lever**2, K_M / lever**2
    k = k_m if math.isinf(k_s) else k_m * (k_s / lever**2) / (k_m + k_s / lever**2)
    share = 1.0 if math.isinf(k_s) else k_s / (k_s + K_M)
    expected = phase_impulses(m_f, k, k_m, F_S, 1.0, v0)
    _, reaction = sprung_reaction(F_S, k_m, TAU / lever, m_r, share * v0)
    assert result.phases.initial == pytest.approx(float(expected.initial), rel=1e-12)
    assert result.phases.sensing == pytest.approx(float(expected.sensing), rel=1e-10)
    assert result.phases.reaction == pytest.approx(reaction, rel=1e-10)
    assert result.detection_time == pytest.approx(F_S / (k * v0), rel=1e-12)
    assert math.isinf(result.threshold_margin) and not result.lifted_off


def test_massless_links_give_the_sprung_reaction(arm):
    """Links of vanishing mass follow the motors quasi-statically: the 1D sprung reaction along u.

    With ``M -> eps M`` the link modes' periods and the force's oscillation scale as ``sqrt(eps)`` (about
    ``v0 sqrt(eps m k)``, 2e-3 N at ``eps = 1e-6``): the reaction and the detection time are then within 0.3 %
    of ``sprung_reaction(F_s, k_m, F_a, m_r, v0)`` and ``F_s / (k v0)`` (measured 0.09 %), while at ``eps = 1``
    (the arm's links, elbow up) the reaction is 18 % away and the detection 66 % earlier.
    """
    mass, jac = _at(arm, [0.3, 1.2])
    u = np.array([1.0, 0.0])
    lever = jac.T @ u
    m_r = 1 / float(lever @ (lever / ROTOR))
    k_m = 1 / float(lever @ (lever / K_M))
    F_a = float(np.min(TAU / np.abs(lever)))
    v0 = 0.36
    _, expected = sprung_reaction(F_S, k_m, F_a, m_r, v0)
    light = joint_space_collision(1e-6 * mass, jac, u, K_M, ROTOR, TAU, F_S, v0)
    heavy = joint_space_collision(mass, jac, u, K_M, ROTOR, TAU, F_S, v0)
    assert light.phases.reaction == pytest.approx(expected, rel=3e-3)
    assert light.detection_time == pytest.approx(F_S / (k_m * v0), rel=3e-3)
    assert abs(heavy.phases.reaction / expected - 1) > 0.1


def test_a_strong_push_gives_the_constant_acceleration_reaction():
    """``F_s / F_a -> 0``: the spring's push on the rotor is negligible, the paper's reaction (moving robot)."""
    lever, v0 = 0.4, 0.5
    m_r, k_m = ROTOR / lever**2, K_M / lever**2
    for torque, tolerance in ((1e3, 2e-3), (1e5, 2e-5)):  # the difference is O(F_s / F_a)
        result = joint_space_collision([[0.03]], [[lever]], [1.0], K_M, ROTOR, torque, F_S, v0)
        a = torque / lever / m_r
        constant = phase_impulses(0.03 / lever**2, k_m, k_m, F_S, a, v0, "moving")
        assert result.phases.reaction == pytest.approx(float(constant.reaction), rel=tolerance)


# --- the same equations integrated numerically --------------------------------------------------------------


def _integrated(mass, jac, u, v0, retreat="along_u"):
    """Impact, sensing and reaction integrated in joint coordinates with the contact force as a multiplier.

    ``M xi'' = K (theta - q) - c f`` with ``f = m_f c^T M^-1 K (theta - q)`` (the contact point kept on the
    wall), ideal motors until detection, rotors integrated after it: DOP853 at rtol 1e-11, events for the
    threshold and the force's return to zero.
    """
    from scipy.integrate import solve_ivp

    nv = mass.shape[0]
    c = jac.T @ u
    m_inv = np.linalg.inv(mass)
    m_f = 1 / float(c @ m_inv @ c)
    v_ref = np.linalg.pinv(jac) @ u * v0
    k = np.full(nv, K_M)
    push = -float(np.min(TAU / np.abs(c))) * c if retreat == "along_u" else -TAU * np.sign(c)

    def force(xi, theta):
        return m_f * float(c @ m_inv @ (k * (theta - xi)))

    def sensing(t, y):
        xi, dxi = y[:nv], y[nv : 2 * nv]
        f = force(xi, v_ref * t)
        return np.concatenate([dxi, m_inv @ (k * (v_ref * t - xi) - c * f), [f]])

    def reaction(t, y):
        xi, dxi, theta, dtheta = y[:nv], y[nv : 2 * nv], y[2 * nv : 3 * nv], y[3 * nv : 4 * nv]
        f = force(xi, theta)
        spring = k * (theta - xi)
        return np.concatenate([dxi, m_inv @ (spring - c * f), dtheta, (push - spring) / ROTOR, [f]])

    detected = lambda t, y: force(y[:nv], v_ref * t) - F_S  # noqa: E731
    detected.terminal, detected.direction = True, 1
    released = lambda t, y: force(y[:nv], y[2 * nv : 3 * nv])  # noqa: E731
    released.terminal, released.direction = True, -1
    options = dict(method="DOP853", rtol=1e-11, atol=1e-14, max_step=1e-4)
    y0 = np.concatenate([np.zeros(nv), v_ref - m_inv @ c * m_f * v0, [0.0]])
    first = solve_ivp(sensing, (0, 10.0), y0, events=detected, **options)
    t_d, y = first.t[-1], first.y[:, -1]
    y1 = np.concatenate([y[: 2 * nv], v_ref * t_d, v_ref, [0.0]])
    second = solve_ivp(reaction, (0, 10.0), y1, events=released, **options)
    return m_f * v0, y[-1], second.y[-1, -1], t_d, second.t[-1]


@pytest.mark.parametrize(
    ("q", "angle", "ratio", "retreat"),
    [
        ([-0.5, 2.0], 0.0, 1.0, "along_u"),
        ([0.3, 1.2], 0.0, 3.0, "along_u"),
        ([0.3, 1.2], 2.0, 1.0, "saturated"),
    ],
)
def test_modes_match_a_numerical_integration(arm, q, angle, ratio, retreat):
    """The modal solution against a numerical integration of the same linear equations (independent method).

    Agreement to 1e-6 of each phase (the integration's tolerance and the events' location, measured 1e-8).
    """
    mass, jac = _at(arm, q)
    u = np.array([np.cos(angle), np.sin(angle)])
    v0 = ratio * 0.4
    impact, sensing, reaction, t_d, duration = _integrated(mass, jac, u, v0, retreat)
    result = joint_space_collision(mass, jac, u, K_M, ROTOR, TAU, F_S, v0, retreat=retreat)
    assert result.phases.initial == pytest.approx(impact, rel=1e-12)
    assert result.phases.sensing == pytest.approx(sensing, rel=1e-6)
    assert result.phases.reaction == pytest.approx(reaction, rel=1e-6)
    assert result.detection_time == pytest.approx(t_d, rel=1e-6)
    assert result.reaction_duration == pytest.approx(duration, rel=1e-6)


# --- bad input ----------------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("mass", "jac", "u", "match"),
    [
        ([[1.0, 0.2], [0.0, 1.0]], [[1.0, 0.0], [0.0, 1.0]], [1.0, 0.0], "symmetric"),
        ([[1.0, 2.0], [2.0, 1.0]], [[1.0, 0.0], [0.0, 1.0]], [1.0, 0.0], "positive definite"),
        ([[1.0, 0.0], [0.0, 1.0]], [[1.0, 1.0], [1.0, 1.0]], [1.0, -1.0], "can move along"),
        ([[1.0, 0.0], [0.0, 1.0]], [[1.0, 0.0], [0.0, 1.0]], [math.nan, 0.0], "nonzero vector"),
        ([[1.0, 0.0], [0.0, 1.0]], [[1.0, 0.0, 0.0]], [1.0], r"\(task_dim, 2\)"),
    ],
)
def test_bad_arm_is_refused(mass, jac, u, match):
    with pytest.raises(InvalidParameter, match=match):
        joint_space_collision(mass, jac, u, K_M, ROTOR, TAU, F_S, 0.3)


def test_widely_separated_time_scales_are_refused_at_once():
    """A sensing phase of 1e7 link periods (60 ns links, 0.6 s until detection) is refused at once."""
    with pytest.raises(InvalidParameter, match="too far apart"):
        joint_space_collision(1e-8 * np.eye(2), np.eye(2), [1.0, 1.0], 1e8, ROTOR, TAU, F_S, 1e-7)


# --- the time-domain arm simulation -------------------------------------------------------------------------

# Elbow-up and folded, along x, at v* (contact-force sensor): the 1D closed form is 17 % and 6 % below the
# simulation, its sprung reaction 9 % below and 5 % above; the joint-space model is within 0.2 % and 0.1 % once
# the sensor's lag is included (the simulator's sensor reads the wall's elastic force k_c d, which lags the
# contact force by c / k_c on a ramp: 0.9 ms here, 8 % of the impulse without it). Tolerance 2 %: 10x the
# measured difference, and a tenth of what a wrong m_f (x1.1) or F_a (x2) changes, which must fail it.
ARM_TOLERANCE = 0.02


@pytest.fixture(scope="module")
def simulated(arm):
    from collision_reflex.simulate import simulate_arm_collision
    from collision_reflex.simulate.contact import damping_from_ratio

    runs = {}
    for q in ([0.3, 1.2], [-0.5, 2.0]):
        u = np.array([1.0, 0.0])
        probe = simulate_arm_collision(
            arm,
            q,
            u,
            0.1,
            F_S,
            detection="force",
            mechanical_stiffness=K_M,
            reflected_inertia=ROTOR,
            torque_limit=TAU,
        ).effective
        v_star = float(cr.optimal_velocity(probe["m_f"], probe["k"], F_S))
        result = simulate_arm_collision(
            arm,
            q,
            u,
            v_star,
            F_S,
            detection="force",
            mechanical_stiffness=K_M,
            reflected_inertia=ROTOR,
            torque_limit=TAU,
        )
        lag = damping_from_ratio(2.0, probe["m_f"], 1e6) / 1e6  # the simulator's default wall
        runs[tuple(q)] = (u, v_star, lag, result)
    return runs


def _model(arm, q, u, v0, lag, mass_scale=1.0, torque_scale=1.0):
    mass, jac = _at(arm, q)
    return joint_space_collision(
        mass * mass_scale, jac, u, K_M, ROTOR, TAU * torque_scale, F_S, v0, delay=lag
    )


@pytest.mark.parametrize("q", [(0.3, 1.2), (-0.5, 2.0)])
def test_the_arm_simulation_at_v_star(arm, simulated, q):
    u, v_star, lag, result = simulated[q]
    model = _model(arm, q, u, v_star, lag)
    assert result.impulse / model.total - 1 == pytest.approx(0, abs=ARM_TOLERANCE)
    detected = model.phases.initial + model.phases.sensing
    assert result.detected_impulse / detected - 1 == pytest.approx(0, abs=ARM_TOLERANCE)
    simulated_reaction = result.impulse - result.detected_impulse
    assert simulated_reaction / model.phases.reaction - 1 == pytest.approx(0, abs=ARM_TOLERANCE)
    # The 1D closed form, with either reaction, misses the same simulation by more than the tolerance.
    assert abs(result.relative_difference) > 2 * ARM_TOLERANCE
    assert abs(result.impulse / result.closed_form_sprung - 1) > 2 * ARM_TOLERANCE


@pytest.mark.parametrize("q", [(0.3, 1.2), (-0.5, 2.0)])
@pytest.mark.parametrize(("mass_scale", "torque_scale"), [(1.1, 1.0), (1.0, 2.0)])
def test_a_wrong_model_fails(arm, simulated, q, mass_scale, torque_scale):
    """Mutations: the links 10 % heavier (m_f x1.1) or the motors' force doubled (F_a, a x2)."""
    u, v_star, lag, result = simulated[q]
    model = _model(arm, q, u, v_star, lag, mass_scale, torque_scale)
    detected = model.phases.initial + model.phases.sensing
    simulated_reaction = result.impulse - result.detected_impulse
    misses = (
        abs(result.impulse / model.total - 1) > ARM_TOLERANCE
        or abs(result.detected_impulse / detected - 1) > ARM_TOLERANCE
        or abs(simulated_reaction / model.phases.reaction - 1) > ARM_TOLERANCE
    )
    assert misses


def test_sliding_pull_is_the_curvature_of_the_contact_path(arm):
    """``sliding_pull`` at the impact is ``-m_f a_n / F_s``, ``a_n`` the normal acceleration of the contact point
    moving at the links' post-impact velocity: here from a second difference of its position (no Jacobian).

    Elbow up, oblique, 1.05 m/s: the links slide at 0.9 m/s and pull 14 % of ``F_s`` off the wall (the
    simulated finger leaves it for most of the sensing phase); H = 0 pulls nothing.
    """
    q, u, v0 = np.array([0.3, 1.2]), np.array([np.cos(2.0), np.sin(2.0)]), 1.05
    mass, jac = _at(arm, q)
    step = 1e-6
    hessian = np.array(
        [u @ (_at(arm, q + step * e)[1] - _at(arm, q - step * e)[1]) / (2 * step) for e in np.eye(2)]
    )
    result = joint_space_collision(mass, jac, u, K_M, ROTOR, TAU, F_S, v0, normal_curvature=hessian)
    c = jac.T @ u
    m_f = 1 / float(c @ np.linalg.solve(mass, c))
    rate = np.linalg.pinv(jac) @ u * v0 - np.linalg.solve(mass, c) * m_f * v0  # q' after the impact
    h = 1e-4

    def normal(s):
        position = arm.kinematics((q + s * rate)[None]).contact_position[0]
        return float(u @ (arm.plane.T @ position))

    accel = (normal(h) - 2 * normal(0.0) + normal(-h)) / h**2
    # The largest pull is at the impact here (the sliding slows down after it): equal to 0.2 %.
    assert result.sliding_pull == pytest.approx(-m_f * accel / F_S, rel=2e-3)
    assert result.sliding_pull == pytest.approx(0.145, abs=0.01)
    flat = joint_space_collision(mass, jac, u, K_M, ROTOR, TAU, F_S, v0, normal_curvature=np.zeros((2, 2)))
    assert flat.sliding_pull == 0.0
    assert joint_space_collision(mass, jac, u, K_M, ROTOR, TAU, F_S, v0).sliding_pull is None


def test_the_validity_map_evaluates_the_model(arm):
    """The map's ``joint_space`` reaction model is this model at the configuration, both placements alike."""
    from collision_reflex.simulate.design_closed_form import REACTION_MODELS, JointDesign, arm_closed_form

    assert "joint_space" in REACTION_MODELS
    joints = JointDesign(mechanical_stiffness=K_M, reflected_inertia=ROTOR, torque_limit=TAU, threshold=F_S)
    q, u = [0.3, 1.2], np.array([1.0, 0.0])
    mass, jac = _at(arm, q)
    expected = joint_space_collision(mass, jac, u, K_M, ROTOR, TAU, F_S, 0.5).total
    for placement in ("robot", "finger"):
        closed = arm_closed_form(arm, q, u, joints, placement)
        assert closed.impulse(0.5, "joint_space") == pytest.approx(expected, rel=1e-12)
    assert closed.impulse(0.5, "constant") != pytest.approx(expected, rel=0.05)


def test_detection_signals(arm):
    """The position error against a rigid wall is ``k v0 t``: detection at ``t1`` exactly, whatever the links do.

    The projected spring torque ``c . K (theta - q) / |c|^2`` misses the links' oscillation along the wall when
    the joints are equally stiff (``c^T K N = k c^T N = 0``): the same detection; with unequal joints it sees it.
    """
    mass, jac = _at(arm, [0.3, 1.2])
    u, v0 = np.array([1.0, 0.0]), 0.57

    def run(detection, stiffness=K_M):
        return joint_space_collision(mass, jac, u, stiffness, ROTOR, TAU, F_S, v0, detection=detection)

    force, position, torque = run("force"), run("position"), run("spring_torque")
    assert position.detection_time == pytest.approx(F_S / (position.k * v0), rel=1e-12)
    assert torque.detection_time == pytest.approx(position.detection_time, rel=1e-9)
    assert abs(force.detection_time / position.detection_time - 1) > 0.5  # elbow up: the force rises early
    unequal = [K_M, 3 * K_M]
    assert (
        abs(run("spring_torque", unequal).detection_time / run("position", unequal).detection_time - 1) > 0.01
    )
    with pytest.raises(InvalidParameter, match="detection"):
        run("observer")


@pytest.mark.parametrize("retreat", ["along_u", "saturated"])
def test_a_joint_without_lever_does_not_limit_the_push(retreat):
    """A joint that cannot move the contact along u (``(J^T u)_i = 0``), decoupled from the other: the collision
    of the other joint alone (a zero lever once made the push zero and the model refuse the arm)."""
    two = joint_space_collision(
        np.diag([0.03, 0.01]), np.eye(2), [1.0, 0.0], K_M, ROTOR, TAU, F_S, 0.3, retreat=retreat
    )
    one = joint_space_collision([[0.03]], [[1.0]], [1.0], K_M, ROTOR, TAU, F_S, 0.3, retreat=retreat)
    assert two.total == pytest.approx(one.total, rel=1e-9)
    assert two.phases.reaction == pytest.approx(one.phases.reaction, rel=1e-9)
