"""Integrating a simulated arm collision phase by phase, and the time scales that bound the integration.

Impact and sensing until detection (through the blanking window after the impact), the delay, then the
reaction until the finger has left the wall for good; see :mod:`collision_reflex.simulate.arm` for the model.
SciPy's integrator is imported by the functions that run it: its import time is paid only by a simulation.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import SimulationError
from ..model.impulse import collision_times
from .arm_detection import detection_margin, next_sample
from .arm_dynamics import ArmDynamics
from .arm_inputs import ImpactClosedForm
from .budget import EVALUATIONS_PER_STEP, check_arm_work
from .setup import oscillation_period

_MAX_REBOUNDS = 50  # contacts after the reaction before the finger is taken to keep hitting the wall


@dataclass
class ArmTrace:
    """What the integration records: trace segments and the phase times [s], the impulse [N*s]."""

    times: list[np.ndarray]
    forces: list[np.ndarray]
    detection_time: float = math.nan
    detected_impulse: float = math.nan
    reaction_time: float = math.nan
    contact_end: float = math.nan
    impulse: float = math.nan

    def add(self, solution: Any, dynamics: ArmDynamics) -> None:
        """Record a solution's steps but the first (the previous segment's last) and the wall force at each."""
        self.times.append(solution.t[1:])
        self.forces.append(dynamics.wall_forces(solution))


def _time_scales(
    dynamics: ArmDynamics, closed: ImpactClosedForm, approach_velocity: float, threshold: float, delay: float
) -> tuple[float, float, float]:
    """Largest step, simulated time limit and the finger's period on the joint springs [s]."""
    eff = closed.effective
    finger_period = oscillation_period(eff["m_f"], eff["k_m"])
    periods = [
        oscillation_period(eff["m_f"], dynamics.contact_stiffness),
        finger_period,
        oscillation_period(eff["m_r"], eff["k_m"]),
        min(oscillation_period(b, k) for b, k in zip(dynamics.inertia, dynamics.k_m, strict=True)),
    ]
    if dynamics.drive == "impedance":  # the rotors on the software and joint springs
        periods.append(
            min(
                oscillation_period(b, k)
                for b, k in zip(dynamics.inertia, dynamics.k_s + dynamics.k_m, strict=True)
            )
        )
    if dynamics.detection == "observer":
        periods.append(2 * math.pi / dynamics.observer_gain)  # the observer's time constant, as a period
    max_step = min(periods) / 16  # a sixteenth of the shortest period in play
    # After the blanking (no detection can come sooner), fifty closed-form contacts (paper's reaction) and
    # delays, and twenty of the longest periods.
    _, t2 = collision_times(eff["m_f"], eff["k"], eff["k_m"], threshold, eff["a"], approach_velocity)
    duration = dynamics.blanking + 50 * (t2 + delay) + 20 * max(periods)
    return max_step, float(duration), finger_period


def _expected_span(
    closed: ImpactClosedForm, approach_velocity: float, threshold: float, delay: float, finger_period: float
) -> float:
    """The run's expected simulated time [s]: the closed form's contact, the delay and the watch after it."""
    eff = closed.effective
    _, t2 = collision_times(eff["m_f"], eff["k"], eff["k_m"], threshold, eff["a"], approach_velocity)
    return float(t2 + delay + 2 * finger_period)


def integrate_arm_collision(
    dynamics: ArmDynamics,
    closed: ImpactClosedForm,
    approach_velocity: float,
    threshold: float,
    delay: float,
    rtol: float,
    max_steps: float,
) -> ArmTrace:
    """Integrate the arm's collision, phase by phase.

    Impact and sensing until detection, the delay, then the reaction until the finger has left the wall for
    good.
    """
    from scipy.integrate import solve_ivp  # here: SciPy's import time is paid only by a simulation

    max_step, duration, finger_period = _time_scales(dynamics, closed, approach_velocity, threshold, delay)
    span = _expected_span(closed, approach_velocity, threshold, delay, finger_period)
    check_arm_work(span, max_step, max_steps)
    dynamics.max_evaluations = 4 * max_steps * EVALUATIONS_PER_STEP
    nv = dynamics.nv
    y = np.zeros(5 * nv + 1)
    y[:nv] = dynamics.q0
    y[nv : 2 * nv] = dynamics.v_ref  # the links move with the motors before the impact
    y[2 * nv : 3 * nv], y[3 * nv : 4 * nv] = dynamics.q0, dynamics.v_ref  # unloaded springs
    options: dict[str, Any] = {"method": "DOP853", "rtol": rtol, "atol": 1e-12, "max_step": max_step}
    trace = ArmTrace([np.array([0.0])], [np.array([0.0])])

    def detected(t: float, y: np.ndarray) -> float:
        return detection_margin(dynamics, t, y, threshold)

    detected.terminal, detected.direction = True, 1  # type: ignore[attr-defined]

    # 1. Impact and sensing until the estimated force reaches the threshold, once armed.
    t, y, armed = _blank(dynamics, trace, y, threshold, options)
    if armed and detection_margin(dynamics, t, y, threshold) < 0:  # at or above it: it fires at once
        solution = solve_ivp(dynamics.rhs, (t, duration), y, events=detected, **options)
        trace.add(solution, dynamics)
        if solution.status != 1:
            raise SimulationError(
                f"the detector never reached the threshold {threshold:g} N within {duration:.3g} s; lower it"
            )
        t = float(solution.t[-1])
        y = solution.y[:, -1].copy()
    # A sampled detector sees the crossing at its next sample.
    t, y = _advance(dynamics, trace, t, y, next_sample(t, dynamics.sample_rate) - t, options)
    trace.detection_time, trace.detected_impulse = t, float(y[-1])
    # 2. The delay, still tracking the reference.
    t, y = _advance(dynamics, trace, t, y, delay, options)
    trace.reaction_time = t
    # 3. The reaction: admittance off, the motors push at the force limit along -u.
    y = dynamics.start_reaction(t, y)
    _react(dynamics, trace, t, y, duration, 2 * finger_period, options)
    return trace


def _blank(
    dynamics: ArmDynamics, trace: ArmTrace, y: np.ndarray, threshold: float, options: dict[str, Any]
) -> tuple[float, np.ndarray, bool]:
    """Integrate through the blanking window after the impact.

    A rise above the threshold within the window is the impact pulse: the detector waits until the signal
    falls below again, and is armed from there. If it does not fall by the window's end, the force holds
    above the threshold and the detector fires there. A signal that stays below was armed all along (a first
    version waited for a fall in any case, and against a soft object, whose pulse never reaches the
    threshold, stayed blind for the whole window). Returns the time [s], the state then and whether the
    detector is armed (False: it fires at that time).
    """
    from scipy.integrate import solve_ivp

    window = dynamics.blanking
    if window <= 0:
        return 0.0, y, True

    def margin(t: float, y: np.ndarray) -> float:
        return detection_margin(dynamics, t, y, threshold)

    def rose(t: float, y: np.ndarray) -> float:
        return margin(t, y)

    def fell(t: float, y: np.ndarray) -> float:
        return margin(t, y)

    rose.terminal, rose.direction = True, 1  # type: ignore[attr-defined]
    fell.terminal, fell.direction = True, -1  # type: ignore[attr-defined]
    solution = solve_ivp(dynamics.rhs, (0.0, window), y, events=rose, **options)
    trace.add(solution, dynamics)
    t, y = float(solution.t[-1]), solution.y[:, -1].copy()
    if solution.status != 1:  # no rise within the window: armed all along, nothing crossed yet
        return t, y, True
    solution = solve_ivp(dynamics.rhs, (t, window), y, events=fell, **options)
    trace.add(solution, dynamics)
    t, y = float(solution.t[-1]), solution.y[:, -1].copy()
    return t, y, solution.status == 1


def _advance(
    dynamics: ArmDynamics,
    trace: ArmTrace,
    t: float,
    y: np.ndarray,
    span: float,
    options: dict[str, Any],
) -> tuple[float, np.ndarray]:
    """Integrate ``span`` [s] on from ``t`` [s] without a mode change; the new time and state."""
    from scipy.integrate import solve_ivp

    if span <= 0:
        return t, y
    solution = solve_ivp(dynamics.rhs, (t, t + span), y, **options)
    trace.add(solution, dynamics)
    return t + span, solution.y[:, -1].copy()


def _react(
    dynamics: ArmDynamics,
    trace: ArmTrace,
    t: float,
    y: np.ndarray,
    duration: float,
    watch: float,
    options: dict[str, Any],
) -> None:
    """Push until the finger leaves the wall; then the reflex is over: the motors brake to a stop.

    Watch ``watch`` [s] for a rebound into the wall before stopping (a constant torque kept on, or motors left to
    coast with the speed the push gave them, would swing the arm round into the wall again, which is no part of
    the reflex), and push again from the moment it touches again, until it leaves again.
    """
    from scipy.integrate import solve_ivp

    def separated(t: float, y: np.ndarray) -> float:
        return dynamics.penetration(y)

    def touched(t: float, y: np.ndarray) -> float:
        return dynamics.penetration(y)

    def retreated(t: float, y: np.ndarray) -> float:
        return dynamics.motor_approach(y) + dynamics.approach_velocity

    separated.terminal, separated.direction = True, -1  # type: ignore[attr-defined]
    touched.terminal, touched.direction = True, 1  # type: ignore[attr-defined]
    retreated.terminal, retreated.direction = True, -1  # type: ignore[attr-defined]

    in_contact = dynamics.penetration(y) > 0
    if not in_contact:
        # A rebound left the finger off the wall before detection: its contact is over once the motors retreat
        # as fast as they came (pushing on until the finger next leaves the wall would swing the arm round into
        # it again), unless it touches first.
        solution = solve_ivp(dynamics.rhs, (t, duration), y, events=[retreated, touched], **options)
        trace.add(solution, dynamics)
        y, t = solution.y[:, -1].copy(), float(solution.t[-1])
        if solution.status != 1:
            raise SimulationError(f"the motors had not retreated after {duration:.3g} s; lengthen it")
        in_contact = solution.t_events[1].size > 0
    for _ in range(_MAX_REBOUNDS):
        if in_contact:
            solution = solve_ivp(dynamics.rhs, (t, duration), y, events=separated, **options)
            trace.add(solution, dynamics)
            y, t = solution.y[:, -1].copy(), float(solution.t[-1])
            if solution.status != 1:
                raise SimulationError(f"the contact had not ended after {duration:.3g} s; lengthen it")
        in_contact = True
        trace.contact_end = t
        dynamics.brake(y)
        coast = solve_ivp(dynamics.rhs, (t, t + watch), y, events=touched, **options)
        trace.add(coast, dynamics)
        y, t = coast.y[:, -1].copy(), float(coast.t[-1])
        if coast.status != 1:  # no new touch within the watch
            break
        dynamics.brake(None)
    else:
        raise SimulationError(
            f"the finger kept hitting the wall again after the reaction ({_MAX_REBOUNDS} rebounds)"
        )
    trace.impulse = float(y[-1])
