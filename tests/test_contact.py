"""Transient contacts with a compliant body region (``collision_reflex.model.contact``): against a hand
calculation, an independent integration of two masses on a spring, and the project's time-domain simulator."""

from __future__ import annotations

import math

import numpy as np
import pytest

from collision_reflex.errors import InvalidParameter
from collision_reflex.model import (
    contact_robot_mass,
    iso_robot_mass,
    permissible_speed,
    rebound,
    reduced_mass,
    transient_contact,
)
from collision_reflex.simulate import CollisionSetup, Detection, simulate
from collision_reflex.study.body_regions import load_body_regions


def test_the_permissible_speed_of_a_hand_is_the_hand_calculation():
    # Worked by hand: a 10 kg robot mass against a hand (k = 75 N/mm, m_H = 0.6 kg) with a transient force
    # limit of 280 N: mu = 10 * 0.6 / 10.6 = 0.56604 kg, sqrt(mu k) = sqrt(0.56604 * 75,000) = 206.04 N s/m,
    # v = 280 / 206.04 = 1.3590 m/s.
    assert permissible_speed(280.0, 10.0, 75e3, 0.6) == pytest.approx(1.3590, rel=1e-4)
    hand = load_body_regions()["hand_finger"]  # the standard's figures, as packaged
    assert permissible_speed(hand.transient_force, 10.0, hand.stiffness, hand.mass) == pytest.approx(
        1.3590, rel=1e-4
    )
    assert reduced_mass(10.0, 0.6) == pytest.approx(0.56604, rel=1e-4)
    # A fixed object (no body mass) leaves the robot mass alone: v = 280 / sqrt(10 * 75,000) = 0.32332 m/s.
    assert permissible_speed(280.0, 10.0, 75e3) == pytest.approx(0.32332, rel=1e-4)
    # The standard's estimate without a dynamic model: half the moving mass plus the payload.
    assert iso_robot_mass(18.4, 5.0) == pytest.approx(14.2, rel=1e-12)


def _two_masses_on_a_spring(m_R: float, m_H: float, k: float, v: float) -> tuple[float, float]:
    """Peak force and contact time of two free masses meeting at ``v`` through a spring that cannot pull,
    integrated with SciPy (independent of the closed form)."""
    from scipy.integrate import solve_ivp

    def motion(_, y):  # y: compression, its rate
        return [y[1], -k * y[0] * (1 / m_R + 1 / m_H)]

    def separated(_, y):
        return y[0]

    separated.terminal, separated.direction = True, -1
    period = 2 * math.pi * math.sqrt(1 / (k * (1 / m_R + 1 / m_H)))
    # A tiny initial compression so that the separation event is not found at t = 0.
    start = [1e-15, v]
    solution = solve_ivp(
        motion, (0, period), start, rtol=1e-12, atol=1e-18, events=separated, dense_output=True
    )
    times = np.linspace(0, solution.t_events[0][0], 20001)
    compression = solution.sol(times)[0]
    # The peak where the rate crosses zero, bracketed by the largest sampled compression.
    from scipy.optimize import brentq

    i = int(np.argmax(compression))
    t_peak = brentq(lambda t: solution.sol(t)[1], times[i - 1], times[i + 1], xtol=1e-16)
    peak = solution.sol(t_peak)[0]
    return k * peak, float(solution.t_events[0][0])


@pytest.mark.parametrize(("m_R", "m_H", "k", "v"), [(2.5, 0.6, 75e3, 0.4), (14.2, 40.0, 25e3, 0.25)])
def test_the_peak_force_and_duration_are_those_of_two_masses_on_a_spring(m_R, m_H, k, v):
    peak, duration = _two_masses_on_a_spring(m_R, m_H, k, v)
    contact = transient_contact(v, m_R, k, m_H)
    assert contact.peak_force == pytest.approx(peak, rel=1e-6)
    assert contact.duration == pytest.approx(duration, rel=1e-6)
    assert contact.compression == pytest.approx(peak / k, rel=1e-6)
    # The permissible speed is the speed that gives the force limit.
    assert transient_contact(permissible_speed(peak, m_R, k, m_H), m_R, k, m_H).peak_force == pytest.approx(
        peak, rel=1e-12
    )


def _first_peak(m_f: float, m_r: float, k_m: float, k_c: float, v0: float) -> float:
    """The simulator's largest wall force during the first contact of an uncontrolled (free) collision."""
    setup = CollisionSetup(
        m_f=m_f,
        m_r=m_r,
        k_m=k_m,
        k_s=1e3,
        F_a=100.0,
        v0=v0,
        detection=Detection("force", 1.0),  # a free collision ignores detection
        drive="free",
        contact_stiffness=k_c,
    )
    result = simulate(setup)
    ends = [t for t, what in result.events if what == "finger leaves the wall"]
    first = result.t <= ends[0]
    return float(np.max(result.contact_force[first]))


M_F, M_R, K_M, V0 = 0.5, 2.0, 1e3, 0.3


@pytest.mark.parametrize("ratio", [1e-4, 1e-3, 1e-2, 1e2, 1e3, 1e4])
def test_the_contact_meets_the_finger_or_the_coupled_mass_as_the_stiffness_ratio_says(ratio):
    # A soft contact against ever stiffer joints, or ever stiffer contacts against the same joints.
    k_c, k_m = (1e3, 1e3 / ratio) if ratio < 1 else (ratio * K_M, K_M)
    mass, exact = contact_robot_mass(M_F, M_R, k_c, k_m)
    assert exact and mass == (M_F if ratio >= 100 else M_F + M_R)
    simulated = _first_peak(M_F, M_R, k_m, k_c, V0)
    assert simulated == pytest.approx(transient_contact(V0, mass, k_c).peak_force, rel=0.01)


@pytest.mark.parametrize("ratio", [0.1, 1.0, 10.0, 30.0])
def test_between_the_limits_the_coupled_mass_bounds_the_first_peak(ratio):
    k_c = ratio * K_M
    mass, exact = contact_robot_mass(M_F, M_R, k_c, K_M)
    assert not exact and mass == M_F + M_R
    simulated = _first_peak(M_F, M_R, K_M, k_c, V0)
    finger = transient_contact(V0, M_F, k_c).peak_force
    assert finger * (1 - 1e-3) <= simulated <= transient_contact(V0, mass, k_c).peak_force * (1 + 1e-3)


def test_arrays_broadcast_and_the_choice_is_per_element():
    mass, exact = contact_robot_mass(M_F, M_R, np.array([1.0, 1e3, 1e6]), K_M)
    assert mass.tolist() == [M_F + M_R, M_F + M_R, M_F] and exact.tolist() == [True, False, True]
    speeds = permissible_speed(np.array([140.0, 280.0]), 10.0, 75e3, 0.6)
    assert speeds[1] == pytest.approx(2 * speeds[0], rel=1e-12)


@pytest.mark.parametrize(
    ("call", "name"),
    [
        (lambda: permissible_speed(-1.0, 10.0, 75e3), "force_limit"),
        (lambda: permissible_speed(280.0, math.nan, 75e3), "robot_mass"),
        (lambda: permissible_speed(280.0, 10.0, math.inf), "contact_stiffness"),
        (lambda: transient_contact("fast", 10.0, 75e3), "velocity"),
        (lambda: transient_contact(0.3, 10.0, 75e3, 0.6 + 1j), "body_mass"),
        (lambda: reduced_mass(math.inf), "robot_mass"),
        (lambda: contact_robot_mass(0.5, -1.0, 1e3, 1e3), "rotor_mass"),
        (lambda: iso_robot_mass(18.4, -5.0), "payload"),
    ],
)
def test_bad_input_is_refused_with_its_name(call, name):
    with pytest.raises(InvalidParameter, match=name):
        call()


@pytest.mark.parametrize("e", [1e-300, 1e-100, 1e-17, 2.0**-53], ids=["1e-300", "1e-100", "1e-17", "2^-53"])
def test_rebound_below_float_resolution_is_the_small_e_limit(e: float) -> None:
    # 1 + e == 1: the flight cannot be solved for in float (a ZeroDivisionError before). The limit e -> 0 is one
    # flight s = sqrt(6 e); the solved flights just above float resolution follow it to 1e-12.
    got = rebound(e)
    assert got.impacts == 1
    assert got.settling == pytest.approx(math.sqrt(6 * e), rel=1e-15)
    for solved in (1e-14, 1e-12):
        assert rebound(solved).settling == pytest.approx(math.sqrt(6 * solved), rel=1e-12)


def test_contact_formulas_name_arguments_whose_shapes_do_not_fit():
    """Unbroadcastable arrays raised NumPy's unnamed ValueError from the contact formulas."""
    from collision_reflex.model import contact

    calls = [
        lambda: permissible_speed(np.ones((2, 2, 2)), 3.0, np.ones((3, 3))),
        lambda: contact_robot_mass(np.ones((3, 3)), np.eye(2) + 1, 1.0, 1.0),
        lambda: contact_robot_mass(1.0, 1.0, np.ones(2), np.ones(3)),
        lambda: transient_contact(np.ones(2), np.ones(3), 1.0),
        lambda: contact.settled_rebound_speed(10.0, np.ones(0) + 1, np.ones(2), 0.5),
        lambda: contact.rebound_impulse(np.ones((3, 3)), 3.0, np.ones(2), np.ones(4), 0.5),
    ]
    for call in calls:
        with pytest.raises(InvalidParameter, match="shapes that fit together"):
            call()


def test_normal_modes_and_first_crossing_refuse_what_is_not_their_input():
    """A scalar, a ragged list or a non-square matrix gave AttributeError, IndexError or SciPy's ValueError."""
    from collision_reflex.model import modal

    for mass, stiffness in [
        (-math.inf, 3),
        (np.float32(1e38), 0.5),
        ([[1, 2], [3]], np.ones(2)),
        (np.ones(2), 1.0),
    ]:
        with pytest.raises(InvalidParameter):
            modal.normal_modes(mass, stiffness)
    with pytest.raises(InvalidParameter, match="stiffness"):
        modal.normal_modes(np.eye(2), np.eye(3))
    with pytest.raises(InvalidParameter, match="modes"):
        modal.first_crossing(2.0, 1.0, 1.0, True, "the force")
