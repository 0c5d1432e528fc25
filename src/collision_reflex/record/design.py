"""The record of one design, the optimiser's (``designs.json``: ``chosen``, ``recommended``, the Pareto designs).

:func:`collision_reflex.optimize.results.result_record` writes a solved design, :func:`~collision_reflex.optimize.
results.design_record` the design record the report reads; the study adds its worst case, its fresh samples'
check and, to the recommended design, why it is recommended. Plain JSON data, SI units. Wall times
(``solve_time``, ``build_time``, ``search_time``) are kept in ``timings.json``: their keys are optional.
"""

from __future__ import annotations

from typing_extensions import NotRequired, TypedDict

from .checked import Efficiency, NonNegative, Positive, checked


@checked
class Estimate(TypedDict):
    """An impulse statistic with its sampling interval [N*s]: :meth:`~collision_reflex.optimize.statistics.Estimate.to_json`.

    ``quantile``: the quantile estimated (``quantile_impulse`` only).
    """

    value: float
    low: float
    high: float
    relative_error: float
    configurations: int
    samples: int
    quantile: NotRequired[float]


@checked
class AttemptRecord(TypedDict):
    """One IPOPT run of a solve (retries included): its name, status, iterations and wall time [s]."""

    name: str
    status: str
    iterations: int
    solve_time: NotRequired[float | None]


@checked
class SolverRecord(TypedDict):
    """How a design was solved: IPOPT's status and iterations, the epsilon bounds, the attempts and the method.

    ``method``: ``full NLP`` or the active-set method; ``active_samples``: the samples of its last NLP. The wall
    times [s] are None where ``timings.json`` is gone.
    """

    status: str
    iterations: int
    solve_time: NotRequired[float | None]
    build_time: NotRequired[float | None]
    search_time: NotRequired[float | None]
    epsilon: dict[str, float]
    attempts: list[AttemptRecord]
    method: str
    active_samples: int


@checked
class SolvedJoint(TypedDict):
    """One joint of a solved design (:func:`~collision_reflex.optimize.results.result_record`), SI units.

    A margin without a requirement, and a duty cycle's quantities without one, are None.
    """

    joint: str
    stator_diameter: Positive
    stack_length: Positive
    gear_ratio: Positive
    rotor_inertia: NonNegative
    reflected_inertia: NonNegative
    motor_peak_torque: Positive
    peak_torque: Positive
    required_torque: NonNegative
    torque_margin: float | None
    mechanical_stiffness: Positive
    software_stiffness: Positive
    stiffness: Positive
    motor_mass: Positive
    gearbox: str
    gearbox_mass: NonNegative
    gearbox_inertia: NonNegative
    gearbox_efficiency: Efficiency
    actuator_mass: NonNegative
    required_rms_torque: float | None
    rms_margin: float | None
    max_motor_speed: float | None
    speed_limit: float | None
    speed_margin: float | None


@checked
class JointRecord(SolvedJoint):
    """One joint of a design record: what sets its required torque, its module, the nearest catalogue motor.

    ``required_by``: None where nothing is required; ``module``: the joints of its module (a module of one
    joint has none); ``catalogue_part``: its part in the design's quick snap (None: none within bounds).
    """

    required_by: str | None
    module: NotRequired[list[str]]
    nearest_catalogue_motor: str | None
    catalogue_part: NotRequired[str | None]


@checked
class _DesignFields(TypedDict):
    """What every design record holds beside its joints (objectives by name, in their units)."""

    label: str
    requirement: str
    objectives: dict[str, float]
    casadi_objectives: dict[str, float]
    threshold: float
    sensing: str
    approach_velocity: float
    impulses: list[float]
    solver: SolverRecord


@checked
class SolvedRecord(_DesignFields):
    """A design and its solve (:func:`~collision_reflex.optimize.results.result_record`)."""

    joints: list[SolvedJoint]


@checked
class Phases(TypedDict):
    """The impulse of each collision phase per sample [N*s]."""

    initial: list[float]
    sensing: list[float]
    reaction: list[float]


@checked
class SearchRecord(TypedDict):
    """A worst-case search's result: :meth:`~collision_reflex.optimize.worst_case.WorstCase.to_json`."""

    impulse: float
    q: list[float]
    direction: list[float]
    starts: int
    evaluations: int
    search_time: NotRequired[float | None]
    domain_kept: float | None


@checked
class WorstPose(TypedDict):
    """Where a worst case occurs: the joints' and the contact point's world positions [m], the direction."""

    joint_positions: list[list[float]]
    contact_position: list[float]
    direction: list[float]


@checked
class WorstCaseRecord(TypedDict):
    """A design's worst case over the samples and as searched: :func:`~collision_reflex.study.worst_case.worst_case_record`."""

    sampled: float
    searched: SearchRecord | None
    domain: float
    certified: bool
    tolerance: NotRequired[float]
    pose: NotRequired[WorstPose]


@checked
class FreshRecord(TypedDict):
    """What samples a design was not optimised on say of it: :func:`~collision_reflex.study.fresh.fresh_record`."""

    configurations: int
    samples: int
    largest: float | None
    q: list[float] | None
    direction: list[float] | None
    mean: float | None
    exceeds: bool
    statistics: NotRequired[dict[str, Estimate]]


@checked
class UndecidedVariable(TypedDict):
    """A design variable no objective decides, with its joint (None for a global variable)."""

    variable: str
    joint: str | None


@checked
class JointTorqueSpeed(TypedDict):
    """One joint's saved torque-speed data, motor side, named as :class:`~collision_reflex.plots.torque_speed.JointOperatingPoints`'s fields.

    ``speed`` [rad/s] and ``torque`` [N*m]: the duty cycle's motor speed ``N qd(t)`` and torque ``d(t) / N``
    (signed, no safety factor); ``approach_speed`` [rad/s]: the approach's motor speed at each contact sample;
    the envelope ``peak_torque`` and ``continuous_torque`` [N*m] and ``max_speed`` [rad/s] (None when the
    catalogue gives none); ``rms_torque`` [N*m]: the cycle's RMS motor torque. Rounded to
    :data:`~collision_reflex.study.arm_results.SAVED_DIGITS` significant digits.
    """

    joint: str
    speed: list[float]
    torque: list[float]
    approach_speed: list[float]
    peak_torque: float
    continuous_torque: float
    max_speed: float | None
    rms_torque: float


@checked
class MissingPart(TypedDict):
    """A joint without a catalogue part within bounds: its nearest part and what that part misses."""

    joint: str
    nearest: str | None
    misses: list[str]


@checked
class QuickSnap(TypedDict):
    """A design's quick catalogue snap: :func:`~collision_reflex.study.catalogue_snap.quick_snap_record`."""

    parts: list[str | None]
    missing: list[MissingPart]
    feasible: bool
    shortfalls: list[str]
    objectives: dict[str, float]
    difference: dict[str, float]
    relative_difference: dict[str, float | None]


@checked
class DesignRecord(_DesignFields):
    """A design as the report shows it: :func:`~collision_reflex.optimize.results.design_record`, with what the study adds.

    The study adds ``worst_case`` and ``fresh`` (not to the catalogue design), ``dominated_by`` (the chosen
    design), ``source``, ``pareto_index``, ``reason``, ``undecided`` and, with a duty cycle, ``torque_speed``
    (the recommended design), ``catalogue`` (each Pareto design's quick snap): see
    :func:`collision_reflex.study.arm_results.arm_results`.
    """

    joints: list[JointRecord]
    phases: Phases
    optimal_velocity: list[float]
    statistics: dict[str, Estimate]
    worst_case: NotRequired[WorstCaseRecord]
    fresh: NotRequired[FreshRecord | None]
    dominated_by: NotRequired[int | None]
    source: NotRequired[str]
    pareto_index: NotRequired[int | None]
    reason: NotRequired[str]
    undecided: NotRequired[list[UndecidedVariable]]
    torque_speed: NotRequired[list[JointTorqueSpeed]]
    catalogue: NotRequired[QuickSnap]


@checked
class PointFailureRecord(TypedDict):
    """A sweep's solve that failed: :meth:`~collision_reflex.optimize.results.PointFailure.as_dict`."""

    objective: str
    epsilon: dict[str, float]
    status: str
    message: str
