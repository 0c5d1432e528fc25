"""An arm study's results as plain data (``designs.json``).

The record holds the chosen design (the single-objective optimum as solved), the recommended design and why,
the Pareto front as the optimiser decided it, the bounds the designs were solved within, the torque
requirement's kind, and where each contact sample comes from. With a duty cycle, the recommended design
also holds its torque-speed data (``recommended.torque_speed``, :func:`torque_speed_record`).
"""

from __future__ import annotations

import hashlib
import math
import threading
import time
from collections.abc import Callable, Mapping, Sequence
from concurrent.futures import Executor
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, NotRequired, TypedDict

import numpy as np

from ..optimize.dominance import MERGE_TOLERANCE
from ..optimize.duty import torque_speed_points
from ..optimize.pieces import built_problem
from ..optimize.recommend import recommend
from ..optimize.results import design_record, undecided_variables
from ..optimize.space import GLOBAL_VARIABLES, PER_JOINT_VARIABLES
from ..optimize.worst_case import SEARCH_TOLERANCE, WorstCase
from .arm_setup import ArmSetup, SampleLayout, StudyProblems, sample_layout
from .fresh import fresh_draw, fresh_impulses, fresh_record
from .schema import ArmStudy
from .worst_case import worst_case_record

if TYPE_CHECKING:
    from ..hardware.gearboxes import CatalogueGearbox
    from ..hardware.motors import Motor
    from ..optimize import DesignProblem, DesignResult, ParetoSet
    from ..optimize.candidates import CataloguePart
    from ..optimize.snap import CatalogueDesign
    from .load import LoadedStudy

SAVED_DIGITS = 7
"""Significant digits of the saved torque-speed data: compact, and within 5e-7 relative of the computed points."""


class ParetoRecord(TypedDict):
    """The Pareto front as plain data: objective names, designs on the front, failed points, dominated designs.

    Each design is a :func:`collision_reflex.optimize.results.design_record`; each failure a
    :meth:`collision_reflex.optimize.results.PointFailure.as_dict`; ``merged``: solved points dropped as
    repeats of a reported one (objectives equal within the solver tolerance).
    """

    objectives: list[str]
    points: list[dict[str, Any]]
    failed: list[dict[str, Any]]
    dominated: list[dict[str, Any]]
    merged: int


class ArmResults(TypedDict):
    """An arm study's own part of ``designs.json``.

    The samples and the contact domain they were drawn in, the chosen and recommended designs, the Pareto
    front, the bounds of the design variables
    (``{variable: {joint: [lower, upper]}}`` and ``{threshold|approach_velocity: [lower, upper]}``, SI units)
    the kind of torque requirement (:attr:`collision_reflex.optimize.Constraints.requirement`), with a duty
    cycle or a rated motion where the motors' speed limits come from, and what the transmissions are
    (:func:`transmissions`).
    """

    samples: SampleLayout
    domain: dict[str, Any]
    chosen: dict[str, Any]
    recommended: dict[str, Any]
    pareto: ParetoRecord
    bounds: dict[str, Any]
    requirement: str
    speed_limits: str | None
    transmissions: list[str]
    catalogue: NotRequired[CatalogueRecord]


class JointTorqueSpeed(TypedDict):
    """One joint's saved torque-speed data, motor side, named as :class:`~collision_reflex.plots.torque_speed.JointOperatingPoints`'s fields.

    ``speed`` [rad/s] and ``torque`` [N*m]: the duty cycle's motor speed ``N qd(t)`` and torque ``d(t) / N``
    (signed, no safety factor); ``approach_speed`` [rad/s]: the approach's motor speed at each contact sample;
    the envelope ``peak_torque`` and ``continuous_torque`` [N*m] and ``max_speed`` [rad/s] (None when the
    catalogue gives none); ``rms_torque`` [N*m]: the cycle's RMS motor torque. Rounded to
    :data:`SAVED_DIGITS` significant digits.
    """

    joint: str
    speed: list[float]
    torque: list[float]
    approach_speed: list[float]
    peak_torque: float
    continuous_torque: float
    max_speed: float | None
    rms_torque: float


def _rounded(values: Any) -> list[float]:
    """``values`` flattened to floats rounded to :data:`SAVED_DIGITS` significant digits."""
    return [float(f"{v:.{SAVED_DIGITS}g}") for v in np.asarray(values, dtype=float).ravel()]


def torque_speed_record(problem: DesignProblem, result: DesignResult) -> list[JointTorqueSpeed] | None:
    """Per joint, a design's motor-side torque-speed data for the report's figure; None without a duty cycle.

    The points are :func:`collision_reflex.optimize.duty.torque_speed_points`; the envelope is the scaled
    motor's (:func:`collision_reflex.hardware.motors.scaled_motor_quantities`); the RMS motor torque is the
    record's joint-side RMS divided by the gear ratio and the gearbox efficiency.
    """
    if problem.duty is None or result.required_rms_torque is None:
        return None
    design = result.design
    technology = problem.technology
    motor = technology.motor_quantities(design.stator_diameter, design.stack_length)
    n = len(design.joint_names)
    continuous = np.broadcast_to(np.asarray(motor.continuous_torque, dtype=float), (n,))
    max_speed = None if motor.max_speed is None else np.broadcast_to(np.asarray(motor.max_speed, float), (n,))
    rms_torque = np.asarray(result.required_rms_torque, dtype=float) / (
        design.gearbox_efficiency * design.gear_ratio
    )
    out: list[JointTorqueSpeed] = []
    for j, (name, points) in enumerate(
        zip(design.joint_names, torque_speed_points(problem, design), strict=True)
    ):
        out.append(
            {
                "joint": name,
                "speed": _rounded(points.cycle_speed),
                "torque": _rounded(points.cycle_torque),
                "approach_speed": _rounded(points.approach_speed),
                "peak_torque": _rounded(design.motor_peak_torque[j])[0],
                "continuous_torque": _rounded(continuous[j])[0],
                "max_speed": None if max_speed is None else _rounded(max_speed[j])[0],
                "rms_torque": _rounded(rms_torque[j])[0],
            }
        )
    return out


def design_bounds(setup: ArmSetup) -> dict[str, Any]:
    """The bounds every design of the study was solved within, as plain data [SI units].

    The design space's, as the optimiser lays it out: a joint's gear ratio within its gearbox's ratios, the force
    threshold above the noise floor.
    """
    from ..optimize.layout import design_layout

    joints = list(setup.arm.joint_names)
    layout = design_layout(setup.space, setup.technology, setup.constraints, len(joints), tuple(joints))
    out: dict[str, Any] = {}
    for name in PER_JOINT_VARIABLES:
        out[name] = {j: [b.lower, b.upper] for j, b in zip(joints, layout.bounds[name], strict=True)}
    for name in GLOBAL_VARIABLES:
        one = layout.bounds[name][0]
        out[name] = [one.lower, one.upper]
    return out


def arm_results(
    problems: StudyProblems,
    chosen: DesignResult,
    front: ParetoSet | None,
    catalogue: CatalogueRecord | None = None,
    searches: Mapping[str, WorstCase] | None = None,
    search_tolerance: float = SEARCH_TOLERANCE,
) -> ArmResults:
    """``samples``, ``chosen``, ``recommended``, ``pareto``, ``bounds`` and ``requirement`` of an arm study.

    The chosen design (the optimum of the study's objective, as solved) records ``dominated_by``: the index of
    a Pareto design that dominates it, or None. The recommended design
    (:func:`collision_reflex.optimize.pareto.recommend`) records ``source`` (``optimum`` or ``Pareto design
    <i>``), ``pareto_index``, ``reason``, ``undecided`` (its design variables that no objective decides,
    :func:`collision_reflex.optimize.results.undecided_variables`: ``{"variable", "joint"}`` each, the joint None
    for a global one), and with a duty cycle its ``torque_speed`` (:func:`torque_speed_record`). With
    ``catalogue`` (:func:`catalogue_results`), the results gain its ``catalogue`` entry and each Pareto design
    (the chosen one without a front) its quick snap, ``catalogue``, with ``catalogue_part`` per joint. Each
    design's ``worst_case`` says its worst case over the samples and over the contact domain as searched
    (``searches`` by label, :func:`.worst_case.worst_case_record`), its ``fresh`` what samples it was not
    optimised on say of it (:func:`.fresh.fresh_record`, the recommended design's with the bootstrap
    statistics; None without fresh samples); ``domain`` the domain itself.
    """
    setup = problems.setup
    # Every problem of a study shares its samples and technology: one of them evaluates every record.
    problem = built_problem(problems, problems.objective)
    draw = fresh_draw(setup)
    every = [chosen, *(front.points if front else ()), *(front.dominated if front else ())]
    fresh = (
        {}
        if draw is None
        else {
            id(result): found
            for result, found in zip(
                every, fresh_impulses(setup, draw, [r.design for r in every]), strict=True
            )
        }
    )

    def fresh_check(
        result: DesignResult, worst_case: float, statistics: bool = False
    ) -> dict[str, Any] | None:
        if draw is None:
            return None
        found = fresh.get(id(result)) or fresh_impulses(setup, draw, [result.design])[0]
        return fresh_record(found, worst_case, search_tolerance, statistics)

    def record(result: DesignResult, label: str) -> dict[str, Any]:
        out = design_record(problem, result, label, setup.catalogue)
        search = (searches or {}).get(label)
        out["worst_case"] = worst_case_record(result, search, search_tolerance)
        if search is not None:
            out["worst_case"]["pose"] = worst_pose(setup, search.q, search.direction)
        out["fresh"] = fresh_check(result, out["worst_case"]["domain"])
        return out

    pareto: ParetoRecord = {"objectives": [], "points": [], "failed": [], "dominated": [], "merged": 0}
    chosen_record = record(chosen, "optimum")
    chosen_record["dominated_by"] = None
    if front is not None:
        pareto = {
            "objectives": list(front.objectives),
            "points": [record(r, label) for r, label in zip(front.points, front.labels, strict=True)],
            "failed": [failure.as_dict() for failure in front.failed],
            "dominated": [
                record(r, label) for r, label in zip(front.dominated, front.dominated_labels, strict=True)
            ],
            "merged": front.merged,
        }
        # The recommendation's rule: values within the solver tolerance count as equal.
        chosen_record["dominated_by"] = front.dominating(chosen.numpy_objectives, MERGE_TOLERANCE)
    recommendation = recommend(chosen, front, problems.objective)
    recommended = (
        dict(pareto["points"][recommendation.pareto_index])
        if recommendation.pareto_index is not None
        else {k: v for k, v in chosen_record.items() if k != "dominated_by"}
    )
    recommended.update(
        source=recommendation.source,
        pareto_index=recommendation.pareto_index,
        reason=recommendation.reason,
        undecided=_undecided(problems, problem, recommendation.result),
        fresh=fresh_check(recommendation.result, recommended["worst_case"]["domain"], statistics=True),
    )
    torque_speed = torque_speed_record(problem, recommendation.result)
    if torque_speed is not None:
        recommended["torque_speed"] = torque_speed
    out: ArmResults = {
        "samples": sample_layout(setup),
        "domain": domain_record(problems),
        "chosen": chosen_record,
        "recommended": recommended,
        "pareto": pareto,
        "bounds": design_bounds(setup),
        "requirement": setup.constraints.requirement,
        "speed_limits": speed_limits(setup),
        "transmissions": transmissions(setup),
    }
    if catalogue is not None:
        rows = pareto["points"] or [chosen_record]
        for row, snapped in zip(rows, catalogue["pareto"], strict=True):
            row["catalogue"] = snapped
            for joint, part in zip(row["joints"], snapped["parts"], strict=True):
                joint["catalogue_part"] = part
        out["catalogue"] = catalogue
    return out


def worst_pose(setup: ArmSetup, q: np.ndarray, direction: np.ndarray) -> dict[str, Any]:
    """Where a worst case occurs, for the report's drawing.

    The joints' and the contact point's world positions [m] at configuration ``q``, and the contact direction
    in world axes.
    """
    kinematics = setup.arm.kinematics(np.asarray(q, dtype=float)[None])
    assert (
        kinematics.joint_positions is not None and kinematics.contact_position is not None
    )  # full kinematics
    plane = setup.arm.plane
    world = (
        np.asarray(direction, dtype=float) if plane is None else plane @ np.asarray(direction, dtype=float)
    )
    return {
        "joint_positions": kinematics.joint_positions[0].tolist(),
        "contact_position": kinematics.contact_position[0].tolist(),
        "direction": world.tolist(),
    }


def domain_record(problems: StudyProblems) -> dict[str, Any]:
    """The study's contact domain as plain data: its settings, how much of the box it keeps, searched samples.

    ``kept`` is the fraction of the joint-limit box's (configuration, direction) pairs inside the domain at
    ``sampling_velocity`` [m/s] (None when the configurations are listed); ``searched_samples`` the number of
    samples the worst-case searches added (the last of ``samples``) and ``searched`` those samples as the
    problems took them, ``[q, u]`` each (:meth:`~.arm_setup.StudyProblems.of_run` reads them back).
    """
    setup = problems.setup
    return {
        **setup.domain.to_json(),
        "kept": setup.domain_kept,
        "sampling_velocity": setup.sampling_velocity,
        "searched_samples": setup.searched,
        "searched": [[list(q), list(u)] for q, u in problems.extra],
    }


def _undecided(problems: StudyProblems, problem: DesignProblem, result: DesignResult) -> list[dict[str, Any]]:
    """The design variables of ``result`` (a solution of ``problem``) that no objective decides, as plain data.

    ``{"variable", "joint"}`` each, the joint's name, None for a global variable
    (:func:`collision_reflex.optimize.results.undecided_variables`).
    """
    names = problems.setup.arm.joint_names
    return [
        {"variable": name, "joint": None if joint is None else names[joint]}
        for name, joint in undecided_variables(problem, result.x)
    ]


def speed_limits(setup: ArmSetup) -> str | None:
    """Where the motors' speed limits come from, for the report (None without a duty cycle or a rated motion)."""
    from ..hardware.motors import scaling_law

    if not setup.constraints.moves:
        return None
    motor = setup.technology.motors[0]
    law = scaling_law(setup.technology.scaling_law).speed
    return (
        f"Speed limits: the reference motor {motor.name} turns at most {motor.max_speed:.4g} rad/s (its "
        f"catalogue entry's figure); a scaled motor's limit follows "
        f"omega_max ∝ (l/l0)^{law.length_exponent:g} (r/r0)^{law.diameter_exponent:g}. "
        f"{law.source}"
    )


def placement_sentences(setup: ArmSetup) -> list[str]:
    """Where each joint's reflected inertia acts in the impact, when the joints differ or a rule chose it."""
    from ..optimize.technology import PLACEMENT_STIFFNESS_RATIO

    joints = list(setup.arm.joint_names)
    in_finger = setup.technology.finger_joints(len(joints))
    ratios = setup.placement_ratios
    if ratios is None and len(set(in_finger)) < 2:
        return []
    named = [f"{joint}" + ("" if ratios is None else f" ({ratios[j]:.3g})") for j, joint in enumerate(joints)]
    finger = [n for n, f in zip(named, in_finger, strict=True) if f]
    robot = [n for n, f in zip(named, in_finger, strict=True) if not f]
    lines = [
        "Reflected inertia: "
        + (
            f"per joint from its transmission's stiffness against the contact's "
            f"({setup.study.reflected_inertia_in.contact_stiffness:.4g} N/m, seen at the joint through its "  # type: ignore[union-attr]
            "median squared moment arm; in brackets the contact's stiffness over the transmission's): "
            if ratios is not None
            else "per joint as the study gives it: "
        )
        + (
            f"in the impact (a stiff transmission) at {', '.join(finger)}"
            if finger
            else "in the impact nowhere"
        )
        + (f"; behind the joint spring (a compliant joint) at {', '.join(robot)}" if robot else "")
        + "."
    ]
    if ratios is not None and finger:
        lines.append(
            "Against an object softer than its transmission a joint's rotor moves with the links, but there the "
            "contact's own compliance spreads the impact, which the closed form (a rigid object) does not: the "
            'simulator finds it overestimates the impulse (documentation: Time-domain simulation, "Where the arm closed form holds"); treat the '
            "impulse as an upper estimate."
        )
    if ratios is not None:
        between = [
            joints[j]
            for j, r in enumerate(ratios)
            if 1 / PLACEMENT_STIFFNESS_RATIO < r < PLACEMENT_STIFFNESS_RATIO
        ]
        if between:
            lines.append(
                f"Warning: at {', '.join(between)} the contact and the transmission are of like stiffness "
                f"(within {PLACEMENT_STIFFNESS_RATIO:g}x): the simulator validates neither placement there "
                '(documentation: Time-domain simulation, "Where the arm closed form holds"); simulate the design before trusting its impulse.'
            )
    return lines


def transmissions(setup: ArmSetup) -> list[str]:
    """What the joints' transmissions are, for the report: scaled gearboxes, and geared joints without a model."""
    from ..hardware.gearbox_scaling import GEARBOX_SCALING
    from ..hardware.gearboxes import ScaledGearbox

    joints = list(setup.arm.joint_names)
    gearboxes = setup.technology.joint_gearboxes(len(joints))
    ratios = setup.space.per_joint("gear_ratio", len(joints))
    lines = []
    scaled: dict[ScaledGearbox, list[str]] = {}
    for joint, gearbox in zip(joints, gearboxes, strict=True):
        if isinstance(gearbox, ScaledGearbox):
            scaled.setdefault(gearbox, []).append(joint)
    for gearbox, named in scaled.items():
        mass, inertia, torque = (law.diameter for law in GEARBOX_SCALING[gearbox.kind])
        low, high = gearbox.ratio_range
        lines.append(
            f"Transmissions of {', '.join(named)}: a {gearbox.kind} gearbox scaled from {gearbox.reference.name} "
            f"to carry its motor's peak torque N tau_p (mass ∝ torque^{mass / torque:.3g}, input inertia ∝ "
            f"torque^{inertia / torque:.3g}: Saerens et al. 2019 at the reference's length), its mass in the "
            f"actuator mass and its input inertia in N^2 (J_m + J_g). Its ratios "
            f"({', '.join(f'{r:g}' for r in gearbox.ratios)}) are relaxed to the range {low:g} to {high:g} in the "
            "continuous designs; the catalogue design takes a unit of the catalogue at a ratio it is sold with."
        )
    lines += placement_sentences(setup)
    bare = [
        joint
        for joint, gearbox, bounds in zip(joints, gearboxes, ratios, strict=True)
        if gearbox is None and bounds.upper > 1
    ]
    if bare:
        lines.append(
            f"Warning: {', '.join(bare)} may be geared (N up to {max(b.upper for b in ratios):g}) but have no "
            "transmission model: their gearboxes weigh nothing and have no inertia, so a larger ratio costs "
            "nothing but the reflected rotor inertia. Give actuators.gearbox (a catalogue unit, its figures, or "
            "{scaled_from: ...}), or fix the gear ratio at 1 for direct drive."
        )
    return lines


class CatalogueRecord(TypedDict):
    """The catalogue snap of a study as plain data (``designs.json``: ``catalogue``).

    ``key``: a digest of the catalogue file and the snap settings, and of the searched samples when there are
    any (a resumed run reuses a saved snap only with the same key); ``snapped``: which design was snapped
    (``optimum`` or ``Pareto design <i>``); ``method``: how the answer was found; ``joints``: per joint the chosen part and its provenance, the candidates, and the
    nearest part with what it misses when none is within bounds; ``objectives``, ``continuous_objectives``,
    ``difference`` (catalogue minus continuous), ``relative_difference`` (over the continuous value; None where
    that is zero) [each objective's unit]; ``design``: the catalogue design's record (with its ``undecided``
    design variables, as the recommended design's), None when none was found;
    ``tried``: every combination re-solved; ``pareto``: the quick snap of every Pareto design (the chosen
    design's without a front), see :func:`quick_snap_record`; ``solve_time``: the snap's wall time [s] (in
    ``timings.json``, not ``designs.json``).
    """

    key: str
    snapped: str
    method: str
    candidates: int
    max_combinations: int
    warnings: list[str]
    joints: list[dict[str, Any]]
    objectives: dict[str, float]
    continuous_objectives: dict[str, float]
    difference: dict[str, float]
    relative_difference: dict[str, float | None]
    design: dict[str, Any] | None
    tried: list[dict[str, Any]]
    pareto: list[dict[str, Any]]
    solve_time: float


@dataclass(frozen=True)
class SnapCatalogue:
    """The catalogue a study snaps to, and its settings.

    motors, gearboxes: the catalogue's motors and gearboxes by name (no gearboxes when no joint has one);
    provenance: per part, each field's source or estimate (as :func:`collision_reflex.hardware.catalogue.
    read_entries` gives it); files: the catalogue files read; candidates, max_combinations, gearbox_kinds:
    :func:`collision_reflex.optimize.snap.snap_to_catalogue`'s settings.
    """

    motors: dict[str, Motor]
    gearboxes: dict[str, CatalogueGearbox]
    provenance: dict[str, dict[str, str]]
    files: tuple[Path, ...]
    candidates: int
    max_combinations: int
    gearbox_kinds: tuple[str, ...] | None = None

    @property
    def key(self) -> str:
        """A digest of the catalogue files' bytes and the settings."""
        digest = hashlib.sha256()
        for file in self.files:
            digest.update(file.read_bytes())
        digest.update(f"{self.candidates}/{self.max_combinations}/{self.gearbox_kinds}".encode())
        return digest.hexdigest()[:16]


def study_catalogue(loaded: LoadedStudy) -> SnapCatalogue | None:
    """The catalogue an arm study snaps to (None when its ``catalogue.snap`` is false).

    Raises
    ------
    CatalogueError: the catalogue file cannot be read or has a bad entry (file, line and field).
    """
    from ..hardware.catalogue import packaged_catalogue_path, read_entries
    from ..hardware.gearboxes import load_gearbox_catalogue
    from ..hardware.motors import Motor

    study = loaded.study
    assert isinstance(study, ArmStudy)
    spec = study.catalogue
    if not spec.snap:
        return None
    file = loaded.path(spec.motors) if spec.motors is not None else packaged_catalogue_path()
    entries = read_entries(file, "motors")
    motors = {
        name: Motor(name=name, **{k: v for k, v in e.fields.items() if k not in ("sources", "estimates")})
        for name, e in entries.items()
    }
    provenance = {name: dict(e.provenance) for name, e in entries.items()}
    files: tuple[Path, ...] = (file,)
    gearboxes: dict[str, CatalogueGearbox] = {}
    geared = study.actuators.gearbox is not None or any(
        j.gearbox is not None for j in study.actuators.joints.values()
    )
    if geared:  # read only when a joint has a gearbox to snap
        gearbox_file = (
            loaded.path(spec.gearboxes)
            if spec.gearboxes is not None
            else packaged_catalogue_path("gearboxes.yaml")
        )
        gearboxes = load_gearbox_catalogue(gearbox_file)
        provenance.update(
            {name: dict(e.provenance) for name, e in read_entries(gearbox_file, "gearboxes").items()}
        )
        files += (gearbox_file,)
    kinds = None if spec.gearbox_kinds is None else tuple(spec.gearbox_kinds)
    return SnapCatalogue(motors, gearboxes, provenance, files, spec.candidates, spec.max_combinations, kinds)


def catalogue_results(
    problems: StudyProblems,
    chosen: DesignResult,
    front: ParetoSet | None,
    catalogue: SnapCatalogue,
    progress: Callable[[int, int], None] | None = None,
    executor: Executor | None = None,
) -> CatalogueRecord:
    """The recommended design snapped to ``catalogue`` (re-solved), and every Pareto design's quick snap.

    The recommended design is snapped by :func:`collision_reflex.optimize.snap.snap_to_catalogue` (exact or
    heuristic), its combinations solved through ``executor`` (default in this process: the same numbers
    either way), on active sets of the samples as the study's ``optimizer.active_set`` says (the sweep's
    rule); each Pareto design (the chosen one without a front) by :func:`quick_snap_record`.
    """
    from ..optimize.parts import catalogue_problem
    from ..optimize.snap import snap_to_catalogue
    from .arm_setup import IPOPT_OPTIONS

    started = time.perf_counter()
    problem = built_problem(problems, problems.objective)
    recommendation = recommend(chosen, front, problems.objective)
    snap = snap_to_catalogue(
        problem,
        recommendation.result,
        catalogue.motors,
        arm=problems.setup.arm,
        gearboxes=catalogue.gearboxes or None,
        candidates=catalogue.candidates,
        gearbox_kinds=catalogue.gearbox_kinds,
        max_combinations=catalogue.max_combinations,
        ipopt_options=IPOPT_OPTIONS,
        progress=progress,
        solve_many=None if executor is None else _ThroughExecutor(problems, recommendation.result, executor),
        active_set=problems.active_set,
    )
    joints = [_joint_record(snap, j, catalogue) for j in range(len(snap.joints))]
    design = None
    if snap.result is not None and snap.parts is not None:
        design = design_record(problem, snap.result, "catalogue design", catalogue.motors)
        parts_problem = catalogue_problem(problem, snap.parts, problems.setup.arm)
        design["undecided"] = _undecided(problems, parts_problem, snap.result)
    results = front.points if front is not None and front.points else (chosen,)
    return {
        "key": catalogue.key,
        "snapped": recommendation.source,
        "method": snap.method,
        "candidates": catalogue.candidates,
        "max_combinations": catalogue.max_combinations,
        "warnings": list(snap.warnings),
        "joints": joints,
        "objectives": snap.objectives,
        "continuous_objectives": snap.continuous_objectives,
        "difference": snap.difference,
        "relative_difference": {k: _finite(v) for k, v in snap.relative_difference.items()},
        "design": design,
        "tried": [
            {"parts": list(t.parts), "objective": t.objective, "status": t.status, "iterations": t.iterations}
            for t in snap.tried
        ],
        "pareto": [quick_snap_record(problem, r, catalogue) for r in results],
        "solve_time": time.perf_counter() - started,
    }


_SNAP_LOCK = threading.RLock()
"""CasADi and IPOPT are not thread-safe: a process (a Dask worker with several threads) solves one combination
at a time; the snap runs after the sweep, so its pieces never meet the sweep's."""


@dataclass(frozen=True)
class _ThroughExecutor:
    """A :data:`collision_reflex.optimize.snap.PartsSolver` that solves each combination as a piece of work."""

    problems: StudyProblems
    optimum: DesignResult
    executor: Executor

    def __call__(
        self, combinations: Sequence[tuple[CataloguePart, ...]], warm: bool = True
    ) -> list[DesignResult | str]:
        futures = [
            self.executor.submit(solve_study_parts, self.problems, self.optimum, c, warm)
            for c in combinations
        ]
        try:
            return [future.result() for future in futures]
        except BaseException:
            for future in futures:
                future.cancel()
            raise


def solve_study_parts(
    problems: StudyProblems, optimum: DesignResult, parts: tuple[CataloguePart, ...], warm: bool = True
) -> DesignResult | str:
    """One combination of a study's catalogue snap, in any process (its problem built there once).

    ``warm``: as :func:`collision_reflex.optimize.snap.solve_parts` says.

    One solve at a time per process with single-threaded BLAS, as every piece of a sweep, so that the numbers
    are the same on every executor.
    """
    from ..optimize.blas import single_threaded_blas
    from ..optimize.catalogue_search import solved_or_status
    from .arm_setup import IPOPT_OPTIONS

    with _SNAP_LOCK, single_threaded_blas():
        problem = built_problem(problems, problems.objective)
        return solved_or_status(
            problem, optimum, parts, problems.setup.arm, IPOPT_OPTIONS, problems.active_set, warm
        )


def _joint_record(snap: CatalogueDesign, j: int, catalogue: SnapCatalogue) -> dict[str, Any]:
    """Joint ``j`` of a catalogue snap as plain data: its part and provenance, next to the continuous design."""
    candidates = snap.joints[j]
    part = snap.parts[j] if snap.parts is not None else None
    gearbox = None if part is None else part.gearbox
    continuous = snap.continuous.design
    return {
        "joint": candidates.joint,
        "part": None if part is None else part.label,
        "motor": None if part is None else part.motor.name,
        "gearbox": None if gearbox is None else gearbox.name,
        "gearbox_from_catalogue": None if part is None else part.gearbox_from_catalogue,
        "gearbox_source": None if gearbox is None else gearbox.source,
        "gearbox_estimates": {}
        if gearbox is None
        else _estimates(catalogue.provenance.get(gearbox.name, {})),
        "gear_ratio": None if snap.result is None else float(snap.result.design.gear_ratio[j]),
        "continuous_gear_ratio": float(continuous.gear_ratio[j]),
        "stator_diameter": None if part is None else part.motor.stator_diameter,
        "continuous_stator_diameter": float(continuous.stator_diameter[j]),
        **_provenance(part, catalogue),
        "candidates": [p.label for p in candidates.parts],
        "nearest": candidates.nearest,
        "misses": list(candidates.misses),
        "warning": candidates.warning,
    }


def quick_snap_record(
    problem: DesignProblem, result: DesignResult, catalogue: SnapCatalogue
) -> dict[str, Any]:
    """A design's quick catalogue snap: the nearest candidate per joint, evaluated without a re-solve.

    Each joint's nearest part within bounds (:func:`collision_reflex.optimize.snap.quick_parts`) at the
    gear ratio that keeps the joint's peak torque, raised where the parts' own masses need more
    (:func:`collision_reflex.optimize.snap.evaluate_parts`), the other variables the design's: far cheaper than
    re-solving it (build and IPOPT). ``parts``: the
    part per joint (None: no catalogue part within bounds, with ``missing``: the nearest part and what it
    misses); ``feasible`` and ``shortfalls``: whether it meets every torque and speed requirement as it is;
    ``objectives``, ``difference``, ``relative_difference``: as in :class:`CatalogueRecord` (empty without
    parts).
    """
    from ..optimize.candidates import joint_candidates
    from ..optimize.parts import evaluate_parts, quick_parts

    joints = joint_candidates(
        problem, result, catalogue.motors, 1, catalogue.gearboxes or None, 1, screen=False
    )
    missing = [
        {"joint": j.joint, "nearest": j.nearest, "misses": list(j.misses)} for j in joints if not j.parts
    ]
    parts = quick_parts(joints, result.design)
    record: dict[str, Any] = {
        "parts": [j.parts[0].label if j.parts else None for j in joints]
        if parts is None
        else [p.label for p in parts],
        "missing": missing,
        "feasible": False,
        "shortfalls": [],
        "objectives": {},
        "difference": {},
        "relative_difference": {},
    }
    if parts is None:
        return record
    evaluated = evaluate_parts(problem, result.design, parts)
    continuous = result.numpy_objectives
    difference = {k: v - continuous[k] for k, v in evaluated.objectives.items()}
    record.update(
        feasible=evaluated.feasible,
        shortfalls=list(evaluated.shortfalls),
        objectives=evaluated.objectives,
        difference=difference,
        relative_difference={
            k: _finite(d / continuous[k]) if continuous[k] != 0 else None for k, d in difference.items()
        },
    )
    return record


def _provenance(part: CataloguePart | None, catalogue: SnapCatalogue) -> dict[str, Any]:
    """A part's ``source`` (its entry's), the fields with another ``sources``, and its ``estimates`` (methods)."""
    if part is None:
        return {"source": None, "sources": {}, "estimates": {}}
    fields = catalogue.provenance.get(part.motor.name, {})
    default = f"source: {part.motor.source}"
    return {
        "source": part.motor.source,
        "sources": {
            k: v.removeprefix("source: ")
            for k, v in fields.items()
            if v.startswith("source: ") and v != default
        },
        "estimates": _estimates(fields),
    }


def _estimates(provenance: dict[str, str]) -> dict[str, str]:
    """The estimated fields of a part's provenance, with their methods."""
    return {k: v.removeprefix("ESTIMATE: ") for k, v in provenance.items() if v.startswith("ESTIMATE: ")}


def _finite(value: float) -> float | None:
    """``value``, or None where it is not finite (JSON has no inf)."""
    return float(value) if math.isfinite(value) else None
