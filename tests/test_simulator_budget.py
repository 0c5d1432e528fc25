"""The simulator's work budget: hopeless settings are refused at once, a run stops when its budget is used up.

Each reproduction of issue 15 ran for minutes or forever; now each ends within a second with a message that
names the time scale at fault and what to change.
"""

from __future__ import annotations

import math
import time
from dataclasses import replace

import pytest

import collision_reflex as cr
from collision_reflex.errors import InvalidParameter, SimulationError
from collision_reflex.model.impulse import phase_impulses, series_stiffness, sprung_reaction
from collision_reflex.simulate import budget, integrator

BASE = cr.simulate.CollisionSetup(0.2, 1.0, 1000.0, 100.0, 10.0, 0.3, cr.simulate.Detection("force", 3.0))
IMPEDANCE = replace(BASE, drive="impedance")

# setting -> words the refusal must contain (the time scale at fault or the change to make)
HOPELESS = {
    "robot_mass=1e-9": (replace(BASE, m_r=1e-9), "raise m_r"),
    "control_rate=1e7": (replace(IMPEDANCE, control_rate=1e7), "lower control_rate"),
    "velocity=1e-9": (replace(IMPEDANCE, v0=1e-9), "raise v0"),
    "delay=1e9": (replace(IMPEDANCE, delay=1e9), "shorten the delay"),
    "viscous_friction=1e6": (replace(IMPEDANCE, viscous_friction=1e6), "lower viscous_friction"),
    "contact_stiffness=1e12": (replace(BASE, contact_stiffness=1e12), "lower contact_stiffness"),
}


@pytest.mark.parametrize("name", list(HOPELESS), ids=list(HOPELESS))
def test_hopeless_settings_are_refused_at_once(name: str) -> None:
    setup, hint = HOPELESS[name]
    start = time.perf_counter()
    with pytest.raises(SimulationError, match="integrator steps, beyond the budget max_steps") as error:
        cr.simulate.simulate(setup)
    assert time.perf_counter() - start < 1.0
    assert hint in str(error.value)
    assert "\n" not in str(error.value)


def test_ordinary_runs_stay_well_inside_the_budget() -> None:
    # These take ~150 steps (4000 with the compliant wall); the estimate must not refuse them, nor be vacuous.
    for setup in (
        BASE,
        IMPEDANCE,
        replace(IMPEDANCE, control_rate=1000.0),
        replace(BASE, contact_stiffness=1e6),
    ):
        steps = budget.estimated_steps(setup)
        assert 50 < steps < setup.max_steps / 10
        cr.simulate.simulate(setup)


def test_estimate_scales_with_span_over_time_scale() -> None:
    # A delay 10x longer in the delay-limited regime needs ~10x the steps: span / step, not a constant.
    long, longer = (budget.estimated_steps(replace(IMPEDANCE, delay=d)) for d in (100.0, 1000.0))
    assert longer / long == pytest.approx(10.0, rel=0.02)
    # The delay phase is stepped at a sixteenth of the robot's period on k_m + k_s.
    step = budget.phases(replace(IMPEDANCE, delay=100.0))[1].step
    assert step == pytest.approx(2 * math.pi * math.sqrt(1.0 / 1100.0) / 16, rel=1e-12)


def test_a_raised_budget_lets_a_long_run_through() -> None:
    setup = replace(IMPEDANCE, delay=50_000.0)
    with pytest.raises(SimulationError, match="shorten the delay"):
        budget.check_work(setup)
    budget.check_work(replace(setup, max_steps=10**6))


def test_the_run_stops_when_the_budget_is_used_up(monkeypatch: pytest.MonkeyPatch) -> None:
    # Without the up-front check the tiny robot mass would run for minutes; the step budget ends it.
    monkeypatch.setattr(integrator, "check_work", lambda setup: None)
    start = time.perf_counter()
    with pytest.raises(SimulationError, match="used up its budget of max_steps = 2000 integrator steps"):
        cr.simulate.simulate(replace(BASE, m_r=1e-9, max_steps=2000))
    assert time.perf_counter() - start < 3.0


def test_budget_counts_steps_of_an_ordinary_run() -> None:
    # The ordinary run needs ~140 steps: a budget of 20 stops it, one of 1000 does not.
    with pytest.raises(SimulationError, match="used up its budget"):
        integrator._Run(replace(BASE, max_steps=20)).run()
    integrator._Run(replace(BASE, max_steps=1000)).run()


@pytest.mark.parametrize("bad", [0, -1, 2.5, True, "100"])
def test_max_steps_is_a_whole_number(bad: object) -> None:
    with pytest.raises(InvalidParameter, match="max_steps"):
        replace(BASE, max_steps=bad)


def test_step_below_float_spacing_is_explained() -> None:
    with pytest.raises(SimulationError, match="below the resolution of double precision") as error:
        cr.simulate.simulate(replace(BASE, v0=1e-15))
    assert "raise v0" in str(error.value)


def test_the_paper_s_u8_soft_fit_runs_instead_of_being_refused() -> None:
    """A stiff sensor (k_m = 2e7 N/m) against a rigid wall: the finger is held there through the reaction, so
    its 28 us oscillation does not set the step; the ideal drive retreats from v0 k / k_m, not from v0. It was
    refused at 1.5e8 estimated steps; the estimate is now about 600 and the run takes a few hundred."""
    setup = cr.simulate.CollisionSetup(
        m_f=0.1,
        m_r=10.0,
        k_m=2e7,
        k_s=440.0,
        F_a=4.7e-4,
        v0=0.1,
        detection=cr.simulate.Detection("force", 3.0),
    )
    assert budget.estimated_steps(setup) < setup.max_steps / 10
    result = cr.simulate.simulate(setup)
    assert result.contact_end is not None and result.impulse > 0
    # Its phases are the closed forms': impact and sensing as the paper's, and, since F_s is 6,400 x F_a, the
    # reaction as the spring pushing the robot mass (sprung_reaction, from the ideal drive's v0 k / k_m), not the
    # paper's constant acceleration F_a / m_r, which is far slower. The integrator's rtol is 1e-10.
    k = series_stiffness(setup.k_m, setup.k_s)
    paper = phase_impulses(setup.m_f, k, setup.k_m, 3.0, setup.F_a / setup.m_r, setup.v0)
    assert result.impulse_to_detection == pytest.approx(paper.initial + paper.sensing, rel=1e-6)
    _, reaction = sprung_reaction(3.0, setup.k_m, setup.F_a, setup.m_r, setup.v0 * k / setup.k_m)
    assert result.impulse_reaction == pytest.approx(reaction, rel=1e-6)
    assert paper.reaction > 50 * reaction


CHEAP_BUT_REFUSED = {
    # F_a is far below the detection force: the spring pushes the robot mass back, not F_a alone (was 3.7e5 steps).
    "weak_actuator": cr.simulate.CollisionSetup(
        1.787,
        2.217,
        16654.0,
        86846.0,
        1.909e-4,
        0.07246,
        cr.simulate.Detection("position", 9.835e-4),
        "impedance",
    ),
    # The free drive never detects: no approach-until-detection phase, and the robot mass bounces off (1.9e5 steps).
    "free_heavy_robot": cr.simulate.CollisionSetup(
        3.822, 735.0, 101111.0, 73933.0, 0.3581, 1.533, cr.simulate.Detection("force", 0.813), "free"
    ),
    "free_slow_approach": cr.simulate.CollisionSetup(
        4.758, 0.2934, 2.304e7, 36.87, 236.2, 0.0012917, cr.simulate.Detection("position", 0.0029046), "free"
    ),
}


@pytest.mark.parametrize("name", list(CHEAP_BUT_REFUSED), ids=list(CHEAP_BUT_REFUSED))
def test_cheap_runs_with_a_weak_actuator_or_free_drive_are_not_refused(name: str) -> None:
    """Settings that run in a few hundred steps were refused up front at 5e4-4e5 estimated steps."""
    setup = CHEAP_BUT_REFUSED[name]
    assert budget.estimated_steps(setup) < setup.max_steps / 10
    assert cr.simulate.simulate(setup).impulse > 0


def test_a_setting_estimated_near_the_budget_runs_and_its_real_work_decides() -> None:
    """Estimated at 6.6e4 steps (1.3 budgets: the approach until a current detection, 0.39 s at the damped
    wall's 6 us) it was refused up front; its detector fires at the impact and the run takes under 300 points.
    A setting that really needs more than its budget still stops, with what to change."""
    setup = cr.simulate.CollisionSetup(
        1.4725e-3,
        45.152,
        3.5492e6,
        1349.7,
        0.021735,
        1.3697e-3,
        cr.simulate.Detection("current", 0.71625),
        contact_stiffness=2.7516e6,
        contact_damping=5.6409,
    )
    assert setup.max_steps < budget.estimated_steps(setup) < budget.REFUSED_BEYOND * setup.max_steps
    result = cr.simulate.simulate(setup)
    assert result.detection_time < 1e-3 and len(result.t) < 1000
    hopeless_near = replace(BASE, contact_stiffness=1e8, max_steps=5000)
    assert budget.estimated_steps(hopeless_near) < budget.REFUSED_BEYOND * hopeless_near.max_steps
    start = time.perf_counter()
    with pytest.raises(SimulationError, match="used up its budget of max_steps = 5000"):
        cr.simulate.simulate(hopeless_near)
    assert time.perf_counter() - start < 3.0
