"""Event-driven integration of the hybrid collision: SciPy's ``solve_ivp`` between mode changes.

The control samples, the delayed reaction and the end of the watch are segment boundaries as well.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..errors import SimulationError
from ..model.impulse import collision_times
from .budget import EVALUATIONS_PER_STEP, SEGMENT_STEPS, WATCH_PERIODS, check_work, reference_force
from .dynamics import DEFL, ERR, IMP, LOSS, NSTATE, SURF, VF, VR, WORK, XF, HybridCollision
from .result import SimulationResult
from .setup import CollisionSetup, oscillation_period

_TRACE_POINTS = 40  # interpolated trace points per integration segment
_MAX_REPEATS = 20  # one event at one instant, again and again, before the run is taken to be stuck


def simulate(setup: CollisionSetup) -> SimulationResult:
    """Simulate one collision from the impact (``t = 0``) until the finger has left the wall for good.

    After the finger leaves the wall during the reaction (or at all, with ``drive="free"``), the simulation
    watches five periods of the finger on its spring for a new contact before it stops.

    Returns a :class:`~collision_reflex.simulate.SimulationResult` with the force trace, the phase times and
    impulses and the energy bookkeeping. Raises :class:`~collision_reflex.errors.SimulationError` if nothing
    is detected, or the contact does not end, within ``setup.duration``; at once if the run would need more
    than ``setup.max_steps`` integrator steps (:func:`~collision_reflex.simulate.budget.check_work`), and when
    it has used them up.
    """
    check_work(setup)
    return _Run(setup).run()


class _OutOfBudget(Exception):
    """The run has used up its budget of steps (evaluations and segments, :func:`_Run.work`)."""


def _default_duration(setup: CollisionSetup) -> float:
    """Simulated time limit when ``setup.duration`` is unset [s].

    It covers 20 generous contact times, twice the delay, the watch after the contact, and ten control
    periods.
    """
    F_ref = reference_force(setup)
    # The closed form's contact time with the robot still moving at v0, plus a period of both masses on the
    # spring and the time to take up the play.
    _, t2 = collision_times(
        setup.m_f, setup.lumped_stiffness, setup.k_m, F_ref, setup.acceleration, setup.v0, "moving", setup.v0
    )
    free = oscillation_period(setup.m_f + setup.m_r, setup.k_m)
    contact = t2 + free + setup.backlash / setup.v0
    duration = 20 * contact + 2 * setup.delay + _watch_time(setup)
    if setup.control_rate is not None:
        duration += 10 / setup.control_rate
    return float(duration)


def _watch_time(setup: CollisionSetup) -> float:
    return WATCH_PERIODS * oscillation_period(setup.m_f, setup.k_m)


def _absolute_tolerances(setup: CollisionSetup) -> np.ndarray:
    """Absolute tolerance of each state, from its scale."""
    F_ref, k, v0 = reference_force(setup), setup.lumped_stiffness, setup.v0
    deflection = F_ref / setup.k_m
    admittance_yield = F_ref / setup.k_s if math.isfinite(setup.k_s) else 0.0
    finger = deflection
    if math.isfinite(setup.contact_stiffness):
        finger = max(finger, v0 * math.sqrt(setup.m_f / setup.contact_stiffness))  # indentation of the wall
    impulse = setup.m_f * v0 + F_ref**2 / (k * v0)
    energy = 0.5 * (setup.m_f + setup.m_r) * v0**2 + F_ref * deflection
    scales = np.empty(NSTATE)
    scales[[XF, VF, DEFL, VR]] = finger, v0, deflection, v0
    scales[ERR] = max(admittance_yield, deflection)
    scales[[SURF, IMP, WORK, LOSS]] = finger, impulse, energy, energy
    return 1e-3 * setup.rtol * scales


def _integrator_failure(t: float, message: str) -> str:
    """The integrator's failure at ``t`` [s], with what SciPy's terse message means."""
    text = f"the integrator failed at t = {t:.6g} s: {message}"
    if "spacing between numbers" in message:
        spacing = np.spacing(t)
        text += (
            f" (the step it needs is below the resolution of double precision at this time, {spacing:.2g} s: "
            "the run is too long for its fastest time scale; raise v0, shorten the delay, or set a shorter "
            "duration)"
        )
    return text


class _Trace:
    """The force trace as it is integrated: times, resolved states and the contact mode of each point."""

    def __init__(self, y: np.ndarray, contact: str) -> None:
        self.times: list[np.ndarray] = [np.array([0.0])]
        self.states: list[np.ndarray] = [y[:, None]]
        self.modes: list[str] = [contact]

    def add(self, solution: Any, sim: HybridCollision) -> None:
        """Add the integrator's steps plus evenly spaced points from its interpolant to the trace.

        The evenly spaced points are there so that a segment covered in a few long steps (a linear ramp) is
        still drawn smoothly where it bends later.
        """
        t, y, sol = solution.t, solution.y, solution.sol
        trace_times = t[1:]
        if t.size > 1:
            extra = np.linspace(t[0], t[-1], _TRACE_POINTS)[1:-1]
            trace_times = np.union1d(trace_times, extra)
            trace_states = sol(trace_times)
            trace_states[:, -1] = y[:, -1]
            resolved = np.stack([sim.resolved(column) for column in trace_states.T], axis=1)
        else:
            resolved = np.zeros((NSTATE, 0))
        self.times.append(trace_times)
        self.states.append(resolved)
        self.modes.extend([sim.contact] * trace_times.size)

    def replace_last(self, y: np.ndarray) -> None:
        """The state after a jump replaces the segment's last point."""
        if self.states[-1].shape[1]:
            self.states[-1][:, -1] = y

    def forces(self, sim: HybridCollision, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Wall and spring force [N] at each trace point, of resolved states ``y`` (NSTATE, n)."""
        setup = sim.s
        modes = np.array(self.modes)
        spring = np.array([sim.spring(d) for d in y[DEFL]])
        pressed = (0.0 if sim.rigid else setup.contact_stiffness) * y[XF] + setup.contact_damping * y[VF]
        contact = np.where(modes == "held", spring, np.where(modes == "pressed", pressed, 0.0))
        return np.maximum(contact, 0.0), spring


class _Run:
    """One integration from the impact to the end of the watch, and what it records on the way."""

    def __init__(self, setup: CollisionSetup) -> None:
        self.setup = setup
        self.sim = HybridCollision(setup)
        self.duration = setup.duration if setup.duration is not None else _default_duration(setup)
        self.atol = _absolute_tolerances(setup)
        self.tiny = 1e-12 * self.duration
        self.detecting = setup.drive != "free"
        self.detection_time = self.reaction_time = math.inf
        self.impulse_at_detection = self.impulse_at_reaction = self.v_r_at_reaction = math.nan
        self.watch_end = math.inf
        self.contact_end = math.nan
        self.last_event: tuple[float, str] = (math.nan, "")
        self.repeats = 0
        self.evaluations = 0
        self.segments = 0
        self.samples = 0
        self.t = 0.0
        # The finger touches the wall at v0; the spring carries no force, with `play` still to take up.
        y = np.zeros(NSTATE)
        y[VF] = y[VR] = setup.v0
        y[DEFL] = self.sim.half_gap - setup.play
        if setup.drive == "impedance":
            y[ERR] = setup.approach_force / setup.k_s  # the steady lag that overcomes friction
        self.start = y.copy()
        self.initial_energy = self.sim.energy(y)
        self.y = self.sim.touch(0.0, y)
        self.sim.events.append((0.0, "impact"))
        if self.sim.sampled and setup.drive == "impedance":
            self.sim.held_force = self.sim.impedance_law(self.y)
        self.trace = _Trace(self.y, self.sim.contact)

    def run(self) -> SimulationResult:
        """Integrate segment by segment, applying each mode change, until the watch ends."""
        try:
            return self._segments()
        except _OutOfBudget:
            modes = len(self.sim.events)
            if modes > self.samples and SEGMENT_STEPS * modes > 0.2 * self.work():
                why = "the contact chatters (the finger bounces, or a mode is entered and left over and over)"
            elif SEGMENT_STEPS * self.samples > 0.2 * self.work():
                why = "mostly control samples: lower control_rate"
            else:
                why = "a time scale far shorter than the run is in play (a stiff or non-smooth force, e.g. a saturated controller)"
            raise SimulationError(
                f"the simulation used up its budget of max_steps = {self.setup.max_steps} integrator steps at "
                f"t = {self.t:.3g} s of {self.duration:.3g} s ({self.evaluations / EVALUATIONS_PER_STEP:.3g} "
                f"steps of integration, {modes} mode changes, {self.samples} control samples): {why}; raise "
                "max_steps, or see collision_reflex.simulate.budget for what sets the steps"
            ) from None

    def work(self) -> float:
        """Steps used so far: right-hand-side evaluations over 12, plus the cost of each segment started."""
        return self.evaluations / EVALUATIONS_PER_STEP + SEGMENT_STEPS * self.segments

    def _segments(self) -> SimulationResult:
        sim = self.sim
        while True:
            self._react_if_due()
            if self._finished():
                break
            self._release_stiction()
            sample_time = self._next_control_sample()
            pending_reaction = self.reaction_time if self._awaiting_reaction() else math.inf
            t_stop = min(self.duration, self.watch_end, sample_time, pending_reaction)
            events = sim.mode_events(self._watching_for_detection(), self.start, self.y)
            solution = self._integrate(t_stop, [event for event, _ in events])
            if solution.status == 1:
                hit = zip(events, solution.t_events, strict=True)
                self._on_event(next(name for (_, name), hits in hit if hits.size))
                continue
            if self.t >= sample_time - self.tiny:
                self._on_control_sample()
        return self._result()

    # -- what is due -----------------------------------------------------------------------------------------
    def _awaiting_reaction(self) -> bool:
        return self.detecting and self.sim.drive != "reaction"

    def _watching_for_detection(self) -> bool:
        return self.detecting and math.isinf(self.detection_time)

    def _react_if_due(self) -> None:
        """Start the reaction once the (delayed, sampled) reaction time is reached."""
        if self._awaiting_reaction() and self.t >= self.reaction_time - self.tiny:
            sim = self.sim
            sim.drive = "reaction"
            sim.robot_stuck = False
            self.impulse_at_reaction = float(self.y[IMP])
            self.v_r_at_reaction = float(self.y[VR])
            sim.events.append((self.t, "reaction"))
            if sim.contact == "free":
                self.watch_end = self.t + _watch_time(self.setup)

    def _finished(self) -> bool:
        """True at the end of the watch; an error at the time limit if the contact has not ended."""
        if self.t >= self.watch_end - self.tiny:
            return True
        if self.t < self.duration - self.tiny:
            return False
        if math.isfinite(self.watch_end):
            return True  # the contact has ended; the watch for a new one is cut short by the duration
        setup = self.setup
        kind, threshold = setup.detection.kind, setup.detection.threshold
        if self._watching_for_detection():
            limited = ""
            if setup.drive == "impedance" and kind != "position" and threshold >= setup.F_a:
                limited = f" (the impedance controller pushes with at most F_a = {setup.F_a:g} N)"
            raise SimulationError(
                f"nothing was detected within {self.duration:.3g} s: the {kind} threshold {threshold:g} is "
                f"never reached{limited}; lower the threshold or lengthen duration"
            )
        raise SimulationError(
            f"the contact had not ended after {self.duration:.3g} s (reaction at {self.reaction_time:.3g} s); "
            "lengthen duration, or check that the force limit can pull the robot away"
        )

    def _release_stiction(self) -> None:
        """A force that changed at a sample (or at the reaction) may now exceed stiction."""
        if self.sim.robot_stuck:
            f = self.sim.forces(self.t, self.y)
            if abs(f["actuator"] - f["spring"]) > self.setup.coulomb_friction:
                self.sim.robot_stuck = False

    def _next_control_sample(self) -> float:
        """The next control sample the run must stop at [s].

        The run stops at samples while the impedance law is sampled, or while a sampled detector watches.
        """
        sim = self.sim
        if (
            sim.sampled
            and sim.drive != "reaction"
            and (sim.drive == "impedance" or math.isinf(self.detection_time))
        ):
            return self._sample_at(self.t, strictly=True)
        return math.inf

    def _sample_at(self, after: float, strictly: bool = False) -> float:
        """First control sample at (or strictly after) ``after`` [s]."""
        rate, phase = self.setup.control_rate, self.setup.sample_phase
        if rate is None:
            return after
        position = after * rate - phase
        index = math.floor(position + 1e-9) + 1 if strictly else math.ceil(position - 1e-9)
        return (max(index, 0) + phase) / rate

    # -- one segment -----------------------------------------------------------------------------------------
    def _integrate(self, t_stop: float, events: list[Any]) -> Any:
        """Integrate the current mode up to ``t_stop`` or its first event; record the trace."""
        from scipy.integrate import solve_ivp  # here: SciPy's import time is paid only by a simulation

        sim = self.sim
        self.segments += 1
        if self.work() > self.setup.max_steps:
            raise _OutOfBudget

        def rhs(t: float, y: np.ndarray) -> np.ndarray:
            self.evaluations += 1
            if self.evaluations % EVALUATIONS_PER_STEP == 0 and self.work() > self.setup.max_steps:
                raise _OutOfBudget
            return sim.rhs(t, y)

        solution = solve_ivp(
            rhs,
            (self.t, t_stop),
            self.y,
            method="DOP853",
            events=events,
            rtol=self.setup.rtol,
            atol=self.atol,
            max_step=min(sim.max_step(), t_stop - self.t),
            dense_output=True,
        )
        if solution.status < 0:
            raise SimulationError(_integrator_failure(self.t, solution.message))
        self.trace.add(solution, sim)
        self.t = float(solution.t[-1])
        self.y = sim.resolved(solution.y[:, -1])
        if sim.drive == "kinematic":
            # The integrated robot velocity follows the ideal one between jumps; book the controller's
            # impulsive work at a jump (play taken up or opened).
            self.y[WORK] += 0.5 * self.setup.m_r * (self.y[VR] ** 2 - solution.y[VR, -1] ** 2)
        return solution

    def _on_event(self, name: str) -> None:
        """Apply the jump of the event ``name`` at the current time."""
        sim, t, y = self.sim, self.t, self.y
        sim.events.append((t, name))
        if name == "finger hits the wall":
            y = sim.touch(t, y)
            self.watch_end = math.inf
        elif name == "finger leaves the wall":
            y = sim.leave(y)
            self.contact_end = t
            if sim.drive in ("reaction", "none"):
                self.watch_end = t + _watch_time(self.setup)
        elif name == "detection":
            self._detect(y)
        elif name == "robot stops":
            y[VR] = 0.0  # exactly, so that the next segment starts from rest
            f = sim.forces(t, y)
            if abs(f["actuator"] - f["spring"]) <= self.setup.coulomb_friction:
                sim.robot_stuck = True
        elif name == "robot breaks away":
            sim.robot_stuck = False
        elif name in ("play taken up", "play opens"):
            # Snap the chain exactly onto the edge of the play: a rounding error on the gap side would
            # re-fire the same event at once.
            edge = sim.half_gap if y[DEFL] + y[ERR] > 0 else -sim.half_gap
            v_r_before = y[VR]
            y[DEFL], y[ERR] = edge, 0.0
            y = sim.resolved(y)
            y[WORK] += 0.5 * self.setup.m_r * (y[VR] ** 2 - v_r_before**2)  # the ideal controller's
        self.y = y
        self.repeats = self.repeats + 1 if (t, name) == self.last_event else 0
        self.last_event = (t, name)
        if self.repeats > _MAX_REPEATS:
            raise SimulationError(
                f"the event {name!r} keeps firing at t = {t:.9g} s without the simulation advancing; "
                "change rtol or the parameters slightly"
            )
        self.trace.replace_last(y)

    def _on_control_sample(self) -> None:
        """Update the held impedance force and check a sampled detector."""
        sim, setup = self.sim, self.setup
        self.samples += 1
        if sim.drive == "impedance":
            sim.held_force = sim.impedance_law(self.y)
        if (
            self._watching_for_detection()
            and sim.measurement(self.t, self.y, self.start) >= setup.detection.threshold
        ):
            self._detect(self.y)
            sim.events.append((self.t, "detection"))

    def _detect(self, y: np.ndarray) -> None:
        """Record the detection now and schedule the reaction after the delay, on the control grid."""
        self.detection_time = self.t
        self.impulse_at_detection = float(y[IMP])
        self.reaction_time = self._sample_at(self.t + self.setup.delay)

    # -- the record ------------------------------------------------------------------------------------------
    def _result(self) -> SimulationResult:
        sim, y = self.sim, self.y
        trace_t = np.concatenate(self.trace.times)
        trace_y = np.concatenate(self.trace.states, axis=1)
        contact, spring = self.trace.forces(sim, trace_y)
        total = float(y[IMP])
        detection_time, reaction_time = self.detection_time, self.reaction_time
        at_detection, at_reaction = self.impulse_at_detection, self.impulse_at_reaction
        if not self.detecting:
            detection_time = reaction_time = math.nan
            at_detection = at_reaction = total
        return SimulationResult(
            setup=self.setup,
            t=trace_t,
            contact_force=contact,
            spring_force=spring,
            finger_velocity=trace_y[VF],
            robot_velocity=trace_y[VR],
            impacts=tuple(sim.impacts),
            impulse=total,
            detection_time=detection_time,
            reaction_time=reaction_time,
            contact_end=self.contact_end,
            impulse_to_detection=at_detection,
            impulse_delay=at_reaction - at_detection,
            impulse_reaction=total - at_reaction,
            robot_velocity_at_reaction=self.v_r_at_reaction,
            actuator_work=float(y[WORK]),
            dissipated=float(y[LOSS]),
            initial_energy=self.initial_energy,
            final_energy=sim.energy(y),
            events=tuple(sim.events),
        )
