"""The rebound of a rigid object with restitution e: the closed form against a small-e expansion, a brute-force
integration, the project's simulator and MuJoCo (``tests/mujoco_rebound.py``), and ``crx impulse --restitution``.

The parameters are a 0.5 kg finger on a 1e4 N/m joint spring in series with a 3e3 N/m controller, a 10 N threshold
and a 100 m/s^2 reaction (an arm-sized joint along one direction; representative, not a maker's figures).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from collision_reflex.cli import main
from collision_reflex.errors import InvalidParameter
from collision_reflex.model import (
    phase_impulses,
    rebound,
    rebound_impulse,
    series_stiffness,
    settled_rebound_speed,
)
from collision_reflex.simulate import CollisionSetup, Detection, contact_damping_for_restitution, simulate
from collision_reflex.simulate.contact import damping_ratio_for_restitution

M_F, M_R, K_M, K_S, F_A, F_S = 0.5, 2.0, 1e4, 3e3, 200.0, 10.0
K = float(series_stiffness(K_M, K_S))
TOLERANCE = 0.02
"""What the issue asks of the closed form against the simulator and MuJoCo; the plastic form misses it by 2.3x
at e = 0.5 near the settled speed, so the test can fail."""


def plastic(v0: float) -> float:
    """The closed form of a plastic impact, with the reaction that is exact for the ideal drive."""
    return float(phase_impulses(M_F, K, K_M, F_S, F_A / M_R, v0, "moving", v0 * K / K_M).total)


def test_a_small_restitution_adds_one_and_a_half_e_squared():
    """For small e the finger's one flight lasts ``sqrt(6 e)`` (``s = (1 + e) sin s`` to third order) and adds
    ``e s^2 / 2 - s^4 / 24 = 1.5 e^2`` of ``m_f v0``; a plastic contact adds nothing."""
    e = 1e-5
    small = rebound(e)
    assert small.excess == pytest.approx(1.5 * e**2, rel=1e-3)
    assert small.settling == pytest.approx(math.sqrt(6 * e), rel=1e-3)
    assert rebound(0.0).excess == 0.0 and rebound(0.0).settling == 0.0


@pytest.mark.parametrize("e", [0.1, 0.5, 0.8])
def test_the_rebound_equals_a_brute_force_integration_of_the_bouncing_finger(e):
    """The scaled finger ``x'' = t - x`` (spring's far end at ``t``) integrated step by step with its impacts as
    events, until the bounces are below 1e-9: the extra stretch's integral and the settling time agree to 1e-5."""
    from scipy.integrate import solve_ivp

    def flight(t, y):  # y = (x, x', integral of -x)
        return [y[1], t - y[0], -y[0]]

    def landing(t, y):
        return y[0]

    landing.terminal, landing.direction = True, 1
    t, y = 0.0, [0.0, -e, 0.0]
    while abs(y[1]) > 1e-9:
        step = abs(y[1]) / (
            10 * max(t, 1.0)
        )  # a tenth of the flight (2 |x'| / t), so no landing is stepped over
        run = solve_ivp(
            flight, (t, t + 2 * math.pi), y, events=landing, rtol=1e-12, atol=1e-15, first_step=step
        )
        t, y = float(run.t_events[0][0]), list(run.y_events[0][0])
        y[0], y[1] = 0.0, -e * y[1]
    exact = rebound(e)
    assert exact.excess == pytest.approx(y[2], rel=1e-5)
    assert exact.settling == pytest.approx(t, rel=1e-5)


@pytest.mark.parametrize("e", [0.1, 0.3, 0.5])
@pytest.mark.parametrize("share", [0.3, 0.9])
def test_the_closed_form_with_the_rebound_matches_the_simulator(e, share):
    """The 1D simulator with a contact 1000 times stiffer than the spring, damped to restitution ``e``, at a
    share of the settled-rebound speed: within 2 % (0.94 % measured at most)."""
    v0 = share * settled_rebound_speed(M_F, K, F_S, e)
    k_c = 1e3 * K
    setup = CollisionSetup(
        M_F,
        M_R,
        K_M,
        K_S,
        F_A,
        v0,
        Detection("force", F_S),
        contact_stiffness=k_c,
        contact_damping=contact_damping_for_restitution(e, M_F, k_c),
    )
    simulated = simulate(setup).impulse
    closed = plastic(v0) + rebound_impulse(M_F, K, F_S, v0, e)
    assert simulated == pytest.approx(closed, rel=TOLERANCE)
    if e == 0.5 and share == 0.9:
        assert abs(simulated / plastic(v0) - 1) > TOLERANCE  # the rebound is what the plastic form misses


@pytest.mark.parametrize("target", [0.0, 0.1, 0.3, 0.5])
def test_the_closed_form_with_the_rebound_matches_mujoco(target):
    """MuJoCo's soft contact (time constant 0.5 ms, damping ratio for ``target``; 0 is the simulator's default
    ratio 2) with its restitution measured in MuJoCo, at 0.9 of the settled speed (capped at 0.3 m/s): within 2 %
    (0.74 % measured at most), where the plastic form is up to 5 % off."""
    mujoco_rebound = pytest.importorskip("mujoco_rebound", reason="needs the mujoco package")
    time_constant, timestep = 5e-4, 1e-5
    ratio = 2.0 if target == 0 else damping_ratio_for_restitution(target)
    e = mujoco_rebound.measured_restitution(M_F, 0.1, time_constant, ratio, timestep)
    assert e == pytest.approx(target or 0.048, abs=0.01)  # MuJoCo's contact rebounds as the Kelvin-Voigt one
    v0 = min(0.9 * settled_rebound_speed(M_F, K, F_S, e), 0.3)
    simulated = mujoco_rebound.collision_impulse(
        M_F, K, K_M, F_S, F_A / M_R, v0, time_constant, ratio, timestep
    )
    assert simulated == pytest.approx(plastic(v0) + rebound_impulse(M_F, K, F_S, v0, e), rel=TOLERANCE)


def test_crx_impulse_adds_the_rebound_where_it_settles_and_says_simulate_beyond(capsys):
    """The printed total is the plastic total plus ``G(e) m_f v0``; a sweep marks the speeds beyond the settled
    one; an approach beyond it is refused, naming the speed."""
    common = ["impulse", "--finger-mass", "0.5", "--stiffness", str(K), "--mech-stiffness", str(K_M)]
    common += ["--threshold", "10", "--accel", "100"]
    assert main([*common, "--velocity", "0.1", "--restitution", "0.3"]) == 0
    out = capsys.readouterr().out
    plain = float(phase_impulses(M_F, K, K_M, F_S, 100.0, 0.1).total)
    expected = plain + rebound(0.3).excess * M_F * 0.1
    assert f"{expected:.6g}" in out.split("total I")[1].split()[0]
    assert main([*common, "--velocity", "0.1", "--velocities", "0.1,1", "--restitution", "0.3"]) == 0
    assert "simulate" in capsys.readouterr().out
    assert main([*common, "--velocity", "1", "--restitution", "0.3"]) == 2
    assert "settled-rebound speed" in capsys.readouterr().err


@pytest.mark.parametrize("bad", [1.0, -0.1, float("nan"), "0.3", 0.3j, [0.1, 0.2]])
def test_a_restitution_outside_zero_to_one_is_refused(bad):
    with pytest.raises(InvalidParameter, match="restitution"):
        rebound(bad)


def test_arrays_of_speeds_broadcast_and_one_beyond_the_settled_speed_is_refused():
    speeds = np.array([0.05, 0.1])
    assert rebound_impulse(M_F, K, F_S, speeds, 0.3) == pytest.approx(rebound(0.3).excess * M_F * speeds)
    with pytest.raises(InvalidParameter, match="still rebounding"):
        rebound_impulse(M_F, K, F_S, [0.1, 10.0], 0.3)
    assert math.isinf(settled_rebound_speed(M_F, K, F_S, 0.0))
