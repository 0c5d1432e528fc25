"""The record of a run, the study's (``designs.json``): an arm study's designs and front, an actuator study's candidates.

:func:`collision_reflex.study.arm_results.arm_results` writes an arm study's own part, the run adds the study as
run and the verdict; an actuator study's record holds every candidate's collision. Plain JSON data, SI units.
"""

from __future__ import annotations

from typing import Any, Literal

from typing_extensions import NotRequired, TypedDict

from .checked import checked
from .design import DesignRecord, PointFailureRecord, QuickSnap


@checked
class ParetoRecord(TypedDict):
    """The Pareto front as plain data: objective names, designs on the front, failed points, dominated designs.

    ``merged``: solved points dropped as repeats of a reported one (objectives equal within the solver
    tolerance).
    """

    objectives: list[str]
    points: list[DesignRecord]
    failed: list[PointFailureRecord]
    dominated: list[DesignRecord]
    merged: int


@checked
class CatalogueJoint(TypedDict):
    """One joint of the catalogue design: its part and provenance, next to the continuous design's.

    None where no part was found; ``sources`` and ``estimates``: per field of the motor its source or how it
    was estimated (``gearbox_estimates`` the gearbox's); ``candidates`` the parts tried; ``nearest`` and
    ``misses`` the nearest part and what it misses when none is within bounds.
    """

    joint: str
    part: str | None
    motor: str | None
    gearbox: str | None
    gearbox_from_catalogue: bool | None
    gearbox_source: str | None
    gearbox_estimates: dict[str, str]
    gear_ratio: float | None
    continuous_gear_ratio: float
    stator_diameter: float | None
    continuous_stator_diameter: float
    source: str | None
    sources: dict[str, str]
    estimates: dict[str, str]
    candidates: list[str]
    nearest: str | None
    misses: list[str]
    warning: str | None


@checked
class TriedParts(TypedDict):
    """One combination of parts re-solved: a part per joint, its objective (None: no design), the solve."""

    parts: list[str]
    objective: float | None
    status: str
    iterations: int | None


@checked
class CatalogueRecord(TypedDict):
    """The catalogue snap of a study as plain data (``designs.json``: ``catalogue``).

    ``key``: a digest of the catalogue file and the snap settings, and of the searched samples when there are
    any (a resumed run reuses a saved snap only with the same key); ``snapped``: which design was snapped
    (``optimum`` or ``Pareto design <i>``); ``method``: how the answer was found; ``joints``: per joint the
    chosen part and its provenance; ``objectives``, ``continuous_objectives``, ``difference`` (catalogue minus
    continuous), ``relative_difference`` (over the continuous value; None where that is zero) [each objective's
    unit]; ``design``: the catalogue design's record (with its ``undecided`` design variables), None when none
    was found; ``tried``: every combination re-solved; ``pareto``: the quick snap of every Pareto design (the
    chosen design's without a front); ``solve_time``: the snap's wall time [s] (in ``timings.json``).
    """

    key: str
    snapped: str
    method: str
    candidates: int
    max_combinations: int
    warnings: list[str]
    joints: list[CatalogueJoint]
    objectives: dict[str, float]
    continuous_objectives: dict[str, float]
    difference: dict[str, float]
    relative_difference: dict[str, float | None]
    design: DesignRecord | None
    tried: list[TriedParts]
    pareto: list[QuickSnap]
    solve_time: NotRequired[float]


@checked
class SampleLayout(TypedDict):
    """Where each contact sample comes from (``designs.json``: ``samples``).

    ``configurations`` are joint positions [rad] (one row per configuration), ``directions`` unit contact
    directions; sample ``i`` is configuration ``config_index[i]`` hit along ``sample_directions[i]``.
    ``task_dim`` is the task-space dimension (2 for a planar arm, 3 otherwise).
    """

    configurations: list[list[float]]
    directions: list[list[float]]
    config_index: list[int]
    sample_directions: list[list[float]]
    joint_names: list[str]
    task_dim: int


@checked
class DomainRecord(TypedDict):
    """The contact domain: :func:`~collision_reflex.study.arm_results.domain_record`.

    A joint speed limit is None where there is none.
    """

    min_singular_value: float
    reach: float
    joint_speed_limit: list[float | None]
    joint_lower: list[float]
    joint_upper: list[float]
    kept: float | None
    sampling_velocity: float
    searched_samples: int
    searched: list[list[list[float]]]


@checked
class Bounds(TypedDict):
    """The bounds every design was solved within, ``[lower, upper]`` (SI units): per joint by its name, or global."""

    stator_diameter: dict[str, list[float]]
    stack_length: dict[str, list[float]]
    gear_ratio: dict[str, list[float]]
    software_stiffness: dict[str, list[float]]
    threshold: list[float]
    approach_velocity: list[float]


@checked
class ArmResults(TypedDict):
    """An arm study's own part of ``designs.json``: :func:`~collision_reflex.study.arm_results.arm_results`.

    The samples and the contact domain they were drawn in, the chosen and recommended designs, the Pareto
    front, the bounds of the design variables, the kind of torque requirement
    (:attr:`collision_reflex.optimize.Constraints.requirement`), with a duty cycle or a rated motion where the
    motors' speed limits come from, what the transmissions are, and the catalogue snap.
    """

    samples: SampleLayout
    domain: DomainRecord
    chosen: DesignRecord
    recommended: DesignRecord
    pareto: ParetoRecord
    bounds: Bounds
    requirement: str
    speed_limits: str | None
    transmissions: list[str]
    catalogue: NotRequired[CatalogueRecord]


@checked
class TransmissionTried(TypedDict):
    """A gearbox assignment tried: :func:`~collision_reflex.study.transmission_choice.choose_transmissions`."""

    assignment: dict[str, str]
    objective: float | None
    actuator_mass: float | None
    chosen: bool
    status: str


@checked
class SimulatedSample(TypedDict):
    """One contact sample of a design, closed form beside simulation (SI units).

    sample: its index among the study's samples; configuration: its configuration index; q [rad]; u: its unit
    direction; approach_velocity [m/s] and its ratio to the sample's ``v*``; contact_stiffness [N/m] of the
    simulated wall; closed_form and simulated impulses [N*s] (simulated None when the simulation was refused
    or failed, ``error`` says why); difference ``I_sim / I_closed - 1``; valid: within the tolerance.
    """

    sample: int
    configuration: int
    q: list[float]
    u: list[float]
    approach_velocity: float
    velocity_ratio: float
    contact_stiffness: float
    closed_form: float
    simulated: float | None
    difference: float | None
    valid: bool
    error: str


@checked
class DesignSimulation(TypedDict):
    """A design's simulated samples: which design, the detection scheme simulated, the tolerance, the rows."""

    design: str
    detection: str
    tolerance: float
    samples: list[SimulatedSample]


@checked
class SimulationRecord(TypedDict):
    """The simulated designs: the recommended one (None when not asked) and the Pareto designs."""

    recommended: DesignSimulation | None
    pareto: list[DesignSimulation]


@checked
class RegionSpeeds(TypedDict):
    """A design's permissible approach speeds against one body region over its run's contact samples (SI units).

    region: its name; stiffness [N/m], mass [kg] and transient_force [N]: the region's figures; slowest, median
    and fastest [m/s]: the permissible speeds; slowest_sample: where the slowest is; above_approach: the samples
    at which the design's approach speed exceeds it; bound_samples: those whose robot mass is the
    rotors-on-links bound; iso_speed [m/s]: the half-moving-mass-plus-payload estimate's.
    """

    region: str
    stiffness: float
    mass: float
    transient_force: float
    slowest: float
    median: float
    fastest: float
    slowest_sample: int
    above_approach: int
    bound_samples: int
    iso_speed: float


@checked
class HeldToRegion(TypedDict):
    """The region a study held its designs to, and whether the recommended design keeps it on fresh poses.

    region: its name; fresh_samples: the fresh configurations' pairs inside the design's domain, each with the
    study's directions and its heaviest one (0 without fresh configurations); slowest [m/s]: the least
    permissible speed among them (None without); below: how many are below the design's approach velocity;
    robot_mass, link_mass [kg] and links_speed [m/s]: at the slowest pose, the design's robot mass, the links'
    own, and the permissible speed with the links alone, which no actuators could exceed (None without).
    """

    region: str
    fresh_samples: int
    slowest: float | None
    below: int
    robot_mass: float | None
    link_mass: float | None
    links_speed: float | None


@checked
class HumanContactRecord(TypedDict):
    """The recommended design against the standard's body regions (:mod:`collision_reflex.study.safety`).

    design: which design; samples: how many contact samples; approach_velocity [m/s]: the design's; moving_mass
    and payload [kg]: what the ISO/TS 15066 estimate takes, iso_mass [kg] the estimate; regions: one row per
    region with a transient force; no_transient: the regions the standard permits no transient contact with;
    held_to: the region the study held its designs to (``constraints.body_region``), and the search's check.
    """

    design: str
    samples: int
    approach_velocity: float
    moving_mass: float
    payload: float
    iso_mass: float
    regions: list[RegionSpeeds]
    no_transient: list[str]
    held_to: NotRequired[HeldToRegion]


@checked
class ArmRunRecord(ArmResults):
    """An arm study's ``designs.json``: the study as run, its results, and the verdict the report opens with.

    ``transmission_choice``: the gearbox assignments tried (a study with gearbox options);
    ``simulation``: the simulated designs (a study that asks); ``human_contact``: the recommended design's
    permissible speeds against the standard's body regions.
    """

    kind: Literal["arm"]
    study: str
    description: str
    resolved: dict[str, Any]
    transmission_choice: NotRequired[list[TransmissionTried]]
    simulation: NotRequired[SimulationRecord]
    human_contact: NotRequired[HumanContactRecord]
    verdict: list[str]


@checked
class ContactRecord(TypedDict):
    """A candidate's 1D collision parameters (SI units): finger and reflected mass, stiffnesses, forces, ``a``."""

    m_f: float
    m_r: float
    k: float
    k_m: float
    F_s: float
    F_a: float
    a: float


@checked
class PhaseImpulses(TypedDict):
    """The impulse of each phase and their total [N*s] at the study's approach velocity."""

    initial: float
    sensing: float
    reaction: float
    total: float


@checked
class PhaseSweep(TypedDict):
    """The impulse of each phase and their total [N*s] at each of the study's velocities."""

    initial: list[float]
    sensing: list[float]
    reaction: list[float]
    total: list[float]


@checked
class ActuatorCandidate(TypedDict):
    """One candidate actuator of an actuator study and its collision (SI units)."""

    name: str
    motor: str
    stator_diameter: float
    gear_ratio: float
    gearbox: str
    reflected_inertia: float
    peak_torque: float
    mass: float
    mechanical_stiffness: float
    software_stiffness: float
    sensing: str
    reflected_inertia_in: str
    contact: ContactRecord
    impulse: PhaseImpulses
    optimal_velocity: float
    minimum_impulse: float
    sweep: PhaseSweep
    pareto_optimal: bool


@checked
class ActuatorRunRecord(TypedDict):
    """An actuator study's ``designs.json``: every candidate's collision at and around the approach velocity."""

    kind: Literal["actuator"]
    study: str
    description: str
    resolved: dict[str, Any]
    lever: float
    approach_velocity: float
    velocities: list[float]
    candidates: list[ActuatorCandidate]


RunRecord = ArmRunRecord | ActuatorRunRecord
"""A run's ``designs.json``, by its ``kind``."""
RUN_KINDS = ("arm", "actuator")
"""The kinds of results a run writes (one record type, and one report template, each)."""
