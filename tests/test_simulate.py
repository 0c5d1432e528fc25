"""The time-domain simulator against the closed form in its ideal limit, momentum and energy balances,
analytic effects of delay, sampling and play, a brute-force contact model, and its input checks."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import collision_reflex as cr
from collision_reflex.errors import InvalidParameter, SimulationError
from collision_reflex.simulate import (
    CollisionSetup,
    Detection,
    contact_damping_for_restitution,
    contact_restitution,
    simulate,
)

M_F, F_S, A = 0.2, 3.0, 20.0
# A robot mass so large that the spring's push (at most ~60 N here) is < 3e-6 of the force limit m_r a: the
# closed form's constant reaction acceleration is then exact to that order.
HEAVY = 1e6

# (k_s, k_m, reaction, v_r): the closed form's two reaction variants are the two ends of the ideal model.
IDEAL_CASES = {
    # k_s << k_m: the robot moves at v0 k/k_m <= 5e-5 m/s at detection, against sqrt(2 a F_s/k_m) = 3.5e-3 m/s
    # needed to matter; the at-rest reaction then differs from the exact one by <= 8e-6 of I (closed forms).
    "at-rest": (100.0, 1e7, "at_rest", None),
    # k_s -> inf: an ideally velocity-controlled robot mass still moving at v0 at detection.
    "moving": (math.inf, 1000.0, "moving", None),
    # comparable springs: the moving variant with the robot's true velocity at detection, v0 k/k_m.
    "series": (100.0, 1000.0, "moving", "detection"),
}
IDEAL_TOLERANCE = {"at-rest": 2e-5, "moving": 1e-5, "series": 1e-5}


def ideal_setup(k_s: float, k_m: float, v0: float, **changes) -> CollisionSetup:
    setup = CollisionSetup(
        m_f=M_F,
        m_r=HEAVY,
        k_m=k_m,
        k_s=k_s,
        F_a=HEAVY * A,
        v0=v0,
        detection=Detection("force", F_S),
    )
    return replace(setup, **changes)


def v_star(k_s: float, k_m: float) -> float:
    return float(cr.optimal_velocity(M_F, cr.model.series_stiffness(k_m, k_s), F_S))


@pytest.mark.parametrize("case", list(IDEAL_CASES), ids=list(IDEAL_CASES))
@pytest.mark.parametrize("ratio", [0.1, 0.3, 1.0, 3.0, 10.0], ids=lambda r: f"v={r}v*")
def test_ideal_limit_reproduces_closed_form(case, ratio):
    k_s, k_m, reaction, v_r = IDEAL_CASES[case]
    setup = ideal_setup(k_s, k_m, ratio * v_star(k_s, k_m))
    result = simulate(setup)
    closed = setup.closed_form(reaction, setup.detection_robot_velocity if v_r == "detection" else v_r)
    # Tolerances: the spring's push F/F_a <= 3e-6 (moving, series), plus <= 8e-6 for the neglected robot
    # velocity (at-rest); the integration (rtol 1e-10) contributes < 1e-8.
    assert result.impulse == pytest.approx(closed.total, rel=IDEAL_TOLERANCE[case])
    # Phase by phase: the impact and sensing impulses up to detection are exact (plastic impact, linear ramp).
    assert result.impulse_to_detection == pytest.approx(closed.initial + closed.sensing, rel=1e-8)
    assert result.impacts[0] == (0.0, pytest.approx(M_F * setup.v0, rel=1e-14))
    t1, t2 = cr.model.collision_times(
        M_F,
        setup.lumped_stiffness,
        k_m,
        F_S,
        A,
        setup.v0,
        reaction,
        None
        if reaction == "at_rest"
        else (setup.detection_robot_velocity if v_r == "detection" else setup.v0),
    )
    assert result.detection_time == pytest.approx(t1, rel=1e-8)
    if case != "at-rest":
        assert result.contact_end == pytest.approx(t2, rel=IDEAL_TOLERANCE[case])


def test_ideal_limit_error_shrinks_with_the_force_limit():
    """The only idealisation left in the 'moving' case is the spring's push on the robot, F/F_a: ten times
    the robot mass (and force limit, a fixed) must cut the difference about ten times."""
    errors = []
    for m_r in (1e2, 1e3):
        setup = replace(
            ideal_setup(math.inf, 1000.0, 3 * v_star(math.inf, 1000.0)),
            m_r=m_r,
            F_a=m_r * A,
        )
        errors.append(abs(simulate(setup).impulse / setup.closed_form("moving").total - 1))
    assert errors[0] / errors[1] == pytest.approx(10.0, rel=0.05)  # first order in F/F_a


def soft_setup(**changes) -> CollisionSetup:
    """A light direct-drive robot where the spring does push the robot back (F_a = 10 N)."""
    k = cr.model.series_stiffness(1000.0, 100.0)
    base = CollisionSetup(
        m_f=M_F,
        m_r=0.5,
        k_m=1000.0,
        k_s=100.0,
        F_a=10.0,
        v0=float(cr.optimal_velocity(M_F, k, F_S)),
        detection=Detection("force", F_S),
    )
    return replace(base, **changes)


def test_free_elastic_collision_conserves_energy_and_balances_momentum():
    setup = soft_setup(drive="free", contact_stiffness=1e5)
    result = simulate(setup)
    # No damping, no actuator, no friction: nothing is lost, nothing is added.
    assert result.actuator_work == 0.0
    assert result.dissipated == pytest.approx(0.0, abs=1e-12)
    assert result.final_energy == pytest.approx(result.initial_energy, rel=1e-8)  # rtol 1e-10, ~900 steps
    # The wall's impulse is the momentum the two masses lost.
    v0 = setup.v0
    momentum_lost = M_F * (v0 - result.finger_velocity[-1]) + setup.m_r * (v0 - result.robot_velocity[-1])
    assert result.impulse == pytest.approx(momentum_lost, rel=1e-8)
    # The pair leaves with about its approach speed (some energy stays in the spring's vibration).
    assert result.impulse == pytest.approx(2 * (M_F + setup.m_r) * v0, rel=1e-3)


BOOKKEEPING_CASES = {
    "ideal-rigid": {},
    "impedance-sampled": dict(drive="impedance", software_damping=5.0, control_rate=1000.0),
    "friction": dict(drive="impedance", software_damping=5.0, coulomb_friction=1.0, viscous_friction=0.5),
    "restitution": dict(
        contact_stiffness=1e5, contact_damping=contact_damping_for_restitution(0.5, M_F, 1e5)
    ),
    "play": dict(backlash=0.004, delay=0.005),
    # Regressions: the play taken up exactly at a control sample; stiction released by a sampled force step;
    # a bouncing finger crossing the play.
    "play-on-sample": dict(backlash=0.003, control_rate=500.0, delay=0.004, v0=0.05),
    "stiction-sampled": dict(
        drive="impedance", software_damping=5.0, coulomb_friction=1.0, control_rate=500.0, v0=0.05
    ),
    "bounce-in-play": dict(
        contact_stiffness=1e5,
        contact_damping=contact_damping_for_restitution(0.3, M_F, 1e5),
        backlash=0.003,
        v0=1.0,
    ),
}


@pytest.mark.parametrize("changes", list(BOOKKEEPING_CASES.values()), ids=list(BOOKKEEPING_CASES))
def test_energy_bookkeeping_closes(changes):
    """Final energy = initial energy + actuator work - losses (damping, plastic impact, friction)."""
    result = simulate(soft_setup(**changes))
    scale = result.initial_energy + abs(result.actuator_work) + result.dissipated
    assert abs(result.energy_residual) <= 1e-7 * scale  # integration error at rtol 1e-10, with margin
    assert result.dissipated >= 0


def test_delay_acts_as_a_higher_threshold_in_the_ideal_limit():
    """With an ideal drive the force keeps ramping at k v0 during a delay d: the impulse is the closed form's
    with threshold F_s + k v0 d, and it grows with the delay."""
    k_s, k_m = 100.0, 1000.0
    base = ideal_setup(k_s, k_m, v_star(k_s, k_m))
    k, v0 = base.lumped_stiffness, base.v0
    impulses = []
    for delay in (0.0, 0.005, 0.02, 0.05):
        result = simulate(replace(base, delay=delay))
        F_late = F_S + k * v0 * delay
        closed = cr.total_impulse(M_F, k, k_m, F_late, A, v0, "moving", v0 * k / k_m)
        assert result.impulse == pytest.approx(closed, rel=1e-5)  # F/F_a < 3e-6, as above
        assert result.reaction_time - result.detection_time == pytest.approx(delay, abs=1e-12)
        impulses.append(result.impulse)
    assert np.all(np.diff(impulses) > 0)


def test_delay_increases_impulse_with_a_physical_controller():
    impulses = [
        simulate(soft_setup(drive="impedance", software_damping=5.0, delay=d)).impulse
        for d in (0.0, 0.002, 0.005, 0.01, 0.02)
    ]
    assert np.all(np.diff(impulses) > 0)


def test_sampled_detection_lands_on_the_next_sample():
    rate = 200.0
    continuous = simulate(soft_setup())
    sampled = simulate(soft_setup(control_rate=rate, sample_phase=0.25))
    t = sampled.detection_time
    assert (t * rate - 0.25) == pytest.approx(round(t * rate - 0.25), abs=1e-9)  # on the sample grid
    assert continuous.detection_time <= t < continuous.detection_time + 1 / rate
    assert sampled.impulse > continuous.impulse


def test_position_threshold_detects_at_k_times_the_error():
    """Ideal drive: the output lags the reference by F/k, so an error threshold e detects at F_s = k e."""
    force = simulate(soft_setup())
    setup = soft_setup(detection=Detection("position", F_S / soft_setup().lumped_stiffness))
    assert setup.equivalent_threshold == pytest.approx(F_S, rel=1e-14)
    position = simulate(setup)
    assert position.detection_time == pytest.approx(force.detection_time, rel=1e-8)
    assert position.impulse == pytest.approx(force.impulse, rel=1e-8)


def test_current_threshold_sees_friction_as_well():
    """The actuator also overcomes friction, so a current threshold trips when the spring carries the
    threshold less the friction force."""
    setup = soft_setup(coulomb_friction=0.5, viscous_friction=2.0, detection=Detection("current", F_S))
    result = simulate(setup)
    detected = result.spring_force[np.searchsorted(result.t, result.detection_time)]
    assert detected == pytest.approx(setup.equivalent_threshold, rel=1e-8)
    assert setup.equivalent_threshold == pytest.approx(F_S - 0.5 - 2.0 * setup.detection_robot_velocity)


def test_play_only_delays_a_plastic_collision():
    """The finger stops plastically, so with an ideal drive the play is taken up at v0 and everything after
    is the same collision shifted by play / v0."""
    plain = simulate(soft_setup())
    played = simulate(soft_setup(backlash=0.004, initial_play=0.003))
    shift = 0.003 / plain.setup.v0
    assert played.detection_time == pytest.approx(plain.detection_time + shift, rel=1e-8)
    assert played.impulse == pytest.approx(plain.impulse, rel=1e-7)


@pytest.mark.parametrize("zeta", [0.05, 0.4, 0.9, 1.0, 3.0], ids=lambda z: f"zeta={z}")
def test_restitution_matches_brute_force(zeta):
    def rhs(t, y):
        return [y[1], -y[0] - 2 * zeta * y[1]]

    def release(t, y):
        return y[0] + 2 * zeta * y[1]  # the contact force of a unit mass on a unit spring

    release.terminal, release.direction = True, -1
    solution = solve_ivp(rhs, (0, 50), [0.0, 1.0], events=release, rtol=1e-12, atol=1e-14, first_step=1e-6)
    assert contact_restitution(zeta) == pytest.approx(-solution.y_events[0][0][1], rel=1e-8)


def test_restitution_round_trip_and_limits():
    assert contact_restitution(0.0) == 1.0
    assert contact_restitution(1.0) == pytest.approx(math.exp(-2), rel=1e-10)
    damping = contact_damping_for_restitution(0.3, 0.2, 1e6)
    assert contact_restitution(damping / (2 * math.sqrt(0.2 * 1e6))) == pytest.approx(0.3, rel=1e-9)
    with pytest.raises(InvalidParameter, match="rigid wall"):
        contact_damping_for_restitution(0.0, 0.2, 1e6)


def test_stiff_plastic_contact_approaches_the_rigid_wall():
    rigid = simulate(soft_setup())
    stiff = simulate(
        soft_setup(contact_stiffness=1e7, contact_damping=contact_damping_for_restitution(0.01, M_F, 1e7))
    )
    # A 1% rebound of the finger's m_f v0 = 0.05 N*s is gathered back by the spring; what remains is the
    # few-percent change of the contact's timing.
    assert stiff.impulse == pytest.approx(rigid.impulse, rel=0.02)


@pytest.mark.parametrize(
    ("changes", "message"),
    [
        (dict(m_f=-0.1), "m_f = -0.1 is invalid"),
        (dict(m_r=0.0), "m_r = 0.0 is invalid"),
        (
            dict(delay=0.5, duration=0.2),
            "delay = 0.5 is invalid: expected shorter than the simulated duration",
        ),
        (dict(contact_stiffness=1e6, max_step=1e-3), "use max_step <= 0.000351 s"),
        (dict(drive="impedance", k_s=math.inf), "use drive='ideal'"),
        (dict(coulomb_friction=20.0), "below F_a = 10 N"),
        (dict(backlash=0.001, initial_play=0.002), "at most backlash"),
        (dict(detection=Detection("current", 0.5), coulomb_friction=1.0), "above the actuator force"),
        (dict(drive="teleport"), "one of 'ideal', 'impedance', 'free'"),
        (dict(software_damping=1.0), "drive='impedance'"),
    ],
    ids=[
        "negative-mass",
        "zero-robot-mass",
        "delay-beyond-duration",
        "coarse-step",
        "infinite-impedance",
        "friction-above-limit",
        "play-beyond-backlash",
        "current-below-friction",
        "unknown-drive",
        "damping-in-ideal",
    ],
)
def test_bad_parameters_are_refused_with_the_fix(changes, message):
    with pytest.raises(InvalidParameter) as caught:
        soft_setup(**changes)
    assert message in str(caught.value)


def test_a_play_beyond_the_position_threshold_says_so() -> None:
    """The play is taken up before the spring builds force: an e_th below it leaves no threshold force."""
    setup = soft_setup(detection=Detection("position", 0.001), backlash=0.004, initial_play=0.003)
    assert setup.equivalent_threshold == 0.0
    with pytest.raises(InvalidParameter, match="the play or the friction alone already reaches it"):
        setup.closed_form()


def test_undetectable_threshold_says_so():
    with pytest.raises(SimulationError, match="never reached"):
        simulate(soft_setup(drive="impedance", detection=Detection("current", 9.9), duration=0.2))
    with pytest.raises(SimulationError, match="pushes with at most F_a = 2 N"):
        simulate(soft_setup(drive="impedance", F_a=2.0, v0=0.01, duration=1.0))


def test_detection_kind_and_threshold_checked():
    with pytest.raises(InvalidParameter, match="detection kind"):
        Detection("smell", 1.0)
    with pytest.raises(InvalidParameter, match="detection threshold"):
        Detection("force", -1.0)


def test_time_scales_and_shares_against_their_textbook_forms():
    """The helpers the simulation takes its steps, watch and admittance from, against the plain formulas."""
    from collision_reflex.simulate.contact import damping_from_ratio
    from collision_reflex.simulate.dynamics import admittance_share
    from collision_reflex.simulate.setup import oscillation_period

    assert oscillation_period(0.2, 1000.0) == pytest.approx(2 * math.pi * math.sqrt(0.2 / 1000.0), rel=1e-15)
    # The admittance follows k_s / (k_s + k_m) of the reference: the series stiffness over k_m.
    share = admittance_share(np.array([1000.0, 1000.0]), np.array([100.0, math.inf]))
    np.testing.assert_allclose(share, [cr.model.series_stiffness(1000.0, 100.0) / 1000.0, 1.0], rtol=1e-15)
    assert damping_from_ratio(1.0, 0.2, 1e6) == pytest.approx(2 * math.sqrt(0.2e6), rel=1e-15)  # critical
    # An undamped contact lasts half a period of the finger on it.
    assert soft_setup(contact_stiffness=1e6).contact_time == pytest.approx(
        math.pi * math.sqrt(0.2e-6), rel=1e-15
    )
