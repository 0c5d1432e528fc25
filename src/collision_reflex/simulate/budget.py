"""The work a simulated collision needs, estimated before it starts: its phases' spans over their time scales.

The run length comes from the slow time scales (the approach until detection, the delay, the watch after the
contact) and the step from the fast ones (the periods of the masses on their springs, friction and damping
time constants, the control period). Their ratio is the number of integrator steps; a setting that needs more
than :data:`REFUSED_BEYOND` times the budget ``setup.max_steps`` is refused at once with what to change, instead
of running for hours; below that the run tries, and the budget bounds its real work: it stops when the steps it
has taken use the budget up.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..errors import SimulationError
from ..model.impulse import collision_times, series_stiffness, sprung_reaction
from ..model.sensing import threshold_force
from .setup import CollisionSetup, oscillation_period

STEP_PER_PERIOD = 16
"""Integrator steps per period of the fastest oscillation in play (the default ``max_step`` rule)."""

EVALUATIONS_PER_STEP = 12
"""Right-hand-side evaluations of one DOP853 step: the run's budget counts steps as evaluations / 12."""

WATCH_PERIODS = 5
"""Periods of the finger on its spring watched for a new contact after it leaves the wall."""

SEGMENT_STEPS = 3
"""Steps' worth of work that each segment costs (a control sample or a mode change): a new solver, its first
step and its trace points cost more than a step does."""

REFUSED_BEYOND = 10
"""A collision estimated at more than this many budgets is refused at once. Near the budget the estimate can
be far too pessimistic (a current detector that fires at the impact, 250 times fewer steps than estimated in
one random setting): such a setting runs, and stops at the budget if it really needs more."""

_MIN_STEPS_PER_PHASE = 10  # a phase without a time scale of its own still takes a few steps

# What to change, for each time scale that can limit the step and each phase that can be long.
_SCALE_HINTS = {
    "the finger on the mechanical spring": "lower k_m or raise m_f",
    "the finger on the wall contact": "lower contact_stiffness or make the wall rigid (contact_stiffness=inf)",
    "the robot mass on its springs": "raise m_r (or lower k_m, k_s)",
    "viscous friction on the robot mass": "lower viscous_friction (its time constant is m_r / viscous_friction)",
    "the software damping": "lower software_damping (its time constant is m_r / software_damping)",
    "the control period": "lower control_rate, or use continuous control (control_rate=None)",
    "max_step": "raise max_step or leave it unset",
}
_PHASE_HINTS = {
    "approach until detection": "raise v0 or lower the detection threshold",
    "delay": "shorten the delay",
    "reaction and watch": "raise k_m or lower m_f (the watch lasts five periods of the finger on k_m)",
}


@dataclass(frozen=True)
class Phase:
    """One phase of the run and the time scale that limits its step.

    Attributes
    ----------
    name: ``"approach until detection"``, ``"delay"`` or ``"reaction and watch"`` (the watch for a new contact
        after it).
    span: its expected duration [s].
    step: the largest step its fastest time scale allows [s] (``inf`` if none).
    scale: that time scale's name (``""`` if none).
    samples: control samples the run stops at in this phase.
    """

    name: str
    span: float
    step: float
    scale: str
    samples: float

    @property
    def steps(self) -> float:
        """Estimated integrator steps of the phase, control samples included (each as a segment)."""
        if self.span <= 0:
            return 0.0
        return _MIN_STEPS_PER_PHASE + self.span / self.step + SEGMENT_STEPS * self.samples


def phases(setup: CollisionSetup) -> tuple[Phase, Phase, Phase]:
    """The three phases of ``setup``'s run with their spans and step-limiting time scales."""
    approach = _approach_scales(setup)
    reaction = _reaction_scales(setup)
    rate = setup.control_rate
    # The free drive never detects: its whole run is the bounce and the watch after it.
    free = setup.drive == "free"
    sensing_span = 0.0 if free else _sensing_time(setup)
    delay_span = 0.0 if free else setup.delay + (1 / rate if rate is not None else 0.0)
    watch = WATCH_PERIODS * oscillation_period(setup.m_f, setup.k_m)
    reaction_time = _reaction_time(setup)
    reaction_span = reaction_time + watch
    spans = [sensing_span, delay_span, reaction_span]
    if setup.duration is not None:  # the run stops at the duration at the latest
        left = setup.duration
        for i, span in enumerate(spans):
            spans[i], left = min(span, left), max(left - span, 0.0)
    # The run stops at every control sample while a sampled detector watches (until detection) or a
    # sampled controller acts (the impedance law until the reaction; the free drive never detects).
    active = (True, setup.drive != "ideal", setup.drive == "free")
    samples = [
        span * rate if rate is not None and on else 0.0 for span, on in zip(spans, active, strict=True)
    ]
    return (
        Phase("approach until detection", spans[0], *_fastest(setup, approach), samples[0]),
        Phase("delay", spans[1], *_fastest(setup, approach), samples[1]),
        Phase(
            "reaction and watch",
            spans[2],
            *_reaction_step(setup, reaction, reaction_time, spans[2]),
            samples[2],
        ),
    )


def _reaction_step(
    setup: CollisionSetup, scales: dict[str, float], reaction_time: float, span: float
) -> tuple[float, str]:
    """The reaction-and-watch phase's mean step [s] and the time scale that limits it.

    Against a rigid wall the finger is held there until the contact ends: its oscillation on ``k_m`` limits
    only the watch after it, while the reaction is stepped by the robot mass (the paper's U8 soft fit, 0.08 s
    of reaction at the finger's 28 us, was refused at 1.5e8 steps and runs in 215).
    """
    if math.isfinite(setup.contact_stiffness) or span <= 0:
        return _fastest(setup, scales)
    held = {name: value for name, value in scales.items() if name != "the finger on the mechanical spring"}
    step_held, name_held = _fastest(setup, held)
    step_free, name_free = _fastest(setup, scales)
    watch = max(span - reaction_time, 0.0)
    held_time = min(reaction_time, span)
    steps = held_time / step_held + watch / step_free
    name = name_held if held_time / step_held >= watch / step_free else name_free
    return (span / steps if steps > 0 else math.inf), name


def estimated_steps(setup: CollisionSetup) -> float:
    """Integrator steps the run of ``setup`` is expected to take."""
    return sum(phase.steps for phase in phases(setup))


def check_work(setup: CollisionSetup) -> None:
    """Raise :class:`SimulationError` if ``setup`` needs more than :data:`REFUSED_BEYOND` budgets, saying why."""
    run = phases(setup)
    total = sum(phase.steps for phase in run)
    # An inf or NaN estimate, from extreme settings, is refused.
    if total <= REFUSED_BEYOND * setup.max_steps:
        return
    worst = max(run, key=lambda phase: phase.steps)
    if SEGMENT_STEPS * worst.samples > worst.span / worst.step:
        why = (
            f"the {worst.name} phase lasts {worst.span:.3g} s and the run stops at each of its "
            f"{worst.samples:.3g} control samples (control_rate = {setup.control_rate:g} Hz; each costs "
            f"{SEGMENT_STEPS} steps)"
        )
        change = _SCALE_HINTS["the control period"]
    else:
        why = f"the {worst.name} phase lasts {worst.span:.3g} s while {worst.scale} limits the step to {worst.step:.3g} s"
        ratio_phase = worst.span / _typical_span(setup)
        change = _PHASE_HINTS[worst.name] if ratio_phase > 1e3 else _SCALE_HINTS[worst.scale]
    raise SimulationError(
        f"this collision needs about {total:.2g} integrator steps, beyond the budget max_steps = "
        f"{setup.max_steps:g} ({REFUSED_BEYOND} times it at most are tried): {why}; {change}, or raise max_steps"
    )


def _typical_span(setup: CollisionSetup) -> float:
    """A contact's natural duration, a period of the finger on its spring [s]: what a phase is long against."""
    return oscillation_period(setup.m_f, setup.k_m)


def reference_force(setup: CollisionSetup) -> float:
    """Spring force [N] at which the detector trips in the ideal limit, ignoring play and friction.

    It is the scale of the forces in the run.
    """
    if setup.detection.kind == "position":
        return float(threshold_force("position", setup.detection.threshold, setup.lumped_stiffness))
    return setup.detection.threshold


def _sensing_time(setup: CollisionSetup) -> float:
    """Time from the impact to detection in the ideal limit, the play taken up first [s]."""
    return reference_force(setup) / (setup.lumped_stiffness * setup.v0) + setup.play / setup.v0


def _reaction_time(setup: CollisionSetup) -> float:
    """The closed form's reaction time ``t2 - t1`` [s], the robot moving at detection.

    At ``v0 k / k_m`` for the ideal drive (what it moves at while the finger is held), at ``v0`` (the most it
    can) for the others; the shorter of the paper's (``F_a`` alone decelerates the robot mass) and
    :func:`~collision_reflex.model.impulse.sprung_reaction`'s (the compressed spring pushes it back too).
    """
    F_ref, k, a = reference_force(setup), setup.lumped_stiffness, setup.acceleration
    v_r = setup.detection_robot_velocity if setup.drive == "ideal" else setup.v0
    t1, t2 = collision_times(setup.m_f, k, setup.k_m, F_ref, a, setup.v0, "moving", v_r)
    # The compressed spring pushes the robot mass back too: far sooner than F_a alone where F_ref >> F_a.
    k_push = series_stiffness(setup.k_m, setup.contact_stiffness)
    sprung, _ = sprung_reaction(F_ref, k_push, setup.F_a, setup.m_r, max(v_r, 0.0))
    return min(float(t2 - t1), float(sprung))


def _approach_scales(setup: CollisionSetup) -> dict[str, float]:
    """Periods (``"period"`` keys) and time constants of the phases before the reaction [s]."""
    scales: dict[str, float] = {}
    if math.isfinite(setup.contact_stiffness):
        scales["the finger on the mechanical spring"] = oscillation_period(setup.m_f, setup.k_m)
    if setup.drive != "ideal":
        stiffness = setup.k_m + (setup.k_s if setup.drive == "impedance" else 0.0)
        scales["the robot mass on its springs"] = oscillation_period(setup.m_r, stiffness)
        _add_constants(setup, scales, impedance=setup.drive == "impedance")
    return scales


def _reaction_scales(setup: CollisionSetup) -> dict[str, float]:
    """Periods and time constants of the reaction and the watch after it [s]."""
    scales = {
        "the finger on the mechanical spring": oscillation_period(setup.m_f, setup.k_m),
        "the robot mass on its springs": oscillation_period(setup.m_r, setup.k_m),
    }
    _add_constants(setup, scales, impedance=False)
    return scales


def _add_constants(setup: CollisionSetup, scales: dict[str, float], impedance: bool) -> None:
    """Add the friction and damping time constants acting on the robot mass [s]."""
    # An explicit integrator is stable only for steps of about a time constant: 16 steps per "period" of
    # 16 time constants.
    if setup.viscous_friction > 0:
        scales["viscous friction on the robot mass"] = STEP_PER_PERIOD * setup.m_r / setup.viscous_friction
    if impedance and setup.software_damping > 0:
        scales["the software damping"] = STEP_PER_PERIOD * setup.m_r / setup.software_damping


def _fastest(setup: CollisionSetup, scales: dict[str, float]) -> tuple[float, str]:
    """The step [s] the fastest of ``scales`` (and the wall contact) allows, and that scale's name."""
    scales = dict(scales)
    if math.isfinite(setup.contact_stiffness):
        k_c = setup.contact_stiffness + setup.k_m
        scales["the finger on the wall contact"] = oscillation_period(setup.m_f, k_c)
    if setup.max_step is not None:
        # A given max_step replaces the period rule; the time constants still bound an explicit step.
        scales = {name: value for name, value in scales.items() if "friction" in name or "damping" in name}
        scales["max_step"] = STEP_PER_PERIOD * setup.max_step
    if not scales:
        return math.inf, ""
    name = min(scales, key=lambda key: scales[key])
    return scales[name] / STEP_PER_PERIOD, name


def check_arm_work(span: float, step: float, max_steps: float) -> None:
    """Refuse an arm collision expected to need more than ``max_steps`` integrator steps.

    Parameters
    ----------
    span: the expected simulated time [s] (the closed form's contact, the delay and the watch after it).
    step: the largest step the fastest time scale allows [s] (a sixteenth of the shortest period in play).
    max_steps: the budget [steps].
    """
    steps = _MIN_STEPS_PER_PHASE + span / step
    if steps <= max_steps:  # (an inf or NaN estimate, from extreme settings, is refused)
        return
    raise SimulationError(
        f"the arm collision would need about {steps:.3g} integrator steps ({span:.3g} s at steps of "
        f"{step:.3g} s), more than the budget of {max_steps:.3g}: lower contact_stiffness, raise the joints' "
        "reflected_inertia or the approach velocity, or raise max_steps"
    )
