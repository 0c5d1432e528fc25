"""An arm study's results as plain data (``designs.json``).

The record holds the chosen design (the single-objective optimum as solved), the recommended design and why,
the Pareto front as the optimiser decided it, the bounds the designs were solved within, the torque
requirement's kind, and where each contact sample comes from. With a duty cycle, the recommended design
also holds its torque-speed data (``recommended.torque_speed``, :func:`torque_speed_record`).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import TYPE_CHECKING, Any, cast

import numpy as np

from ..optimize.dominance import MERGE_TOLERANCE
from ..optimize.duty import torque_speed_points
from ..optimize.layout import design_layout
from ..optimize.pieces import built_problem
from ..optimize.recommend import recommend
from ..optimize.results import design_record, undecided_variables
from ..optimize.worst_case import SEARCH_TOLERANCE, WorstCase
from ..record.design import (
    DesignRecord,
    FreshRecord,
    JointTorqueSpeed,
    UndecidedVariable,
    WorstCaseRecord,
    WorstPose,
)
from ..record.run import ArmResults, Bounds, CatalogueRecord, DomainRecord, ParetoRecord, SampleLayout
from ..vocabulary import GLOBAL_VARIABLES, PER_JOINT_VARIABLES
from .arm_setup import ArmSetup
from .fresh import FreshImpulses, fresh_draw, fresh_impulses, fresh_record
from .problems import StudyProblems
from .setup_notes import speed_limits, transmissions
from .worst_case import worst_case_record

if TYPE_CHECKING:
    from ..optimize import DesignProblem, DesignResult, ParetoSet

SAVED_DIGITS = 7
"""Significant digits of the saved torque-speed data: compact, and within 5e-7 relative of the computed points."""


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


def design_bounds(setup: ArmSetup) -> Bounds:
    """The bounds every design of the study was solved within, as plain data [SI units].

    The design space's, as the optimiser lays it out: a joint's gear ratio within its gearbox's ratios, the force
    threshold above the noise floor.
    """
    joints = list(setup.arm.joint_names)
    layout = design_layout(setup.space, setup.technology, setup.constraints, len(joints), tuple(joints))
    out: dict[str, Any] = {}
    for name in PER_JOINT_VARIABLES:
        out[name] = {j: [b.lower, b.upper] for j, b in zip(joints, layout.bounds[name], strict=True)}
    for shared in GLOBAL_VARIABLES:
        one = layout.bounds[shared][0]
        out[shared] = [one.lower, one.upper]
    return cast("Bounds", out)  # the variables of PER_JOINT_VARIABLES and GLOBAL_VARIABLES


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
    (:func:`collision_reflex.optimize.recommend.recommend`) records ``source`` (``optimum`` or ``Pareto design
    <i>``), ``pareto_index``, ``reason``, ``undecided`` (its design variables that no objective decides,
    :func:`collision_reflex.optimize.results.undecided_variables`: ``{"variable", "joint"}`` each, the joint None
    for a global one), and with a duty cycle its ``torque_speed`` (:func:`torque_speed_record`). With
    ``catalogue`` (:func:`.catalogue_snap.catalogue_results`), the results gain its ``catalogue`` entry and each Pareto design
    (the chosen one without a front) its quick snap, ``catalogue``, with ``catalogue_part`` per joint. Each
    design's ``worst_case`` says its worst case over the samples and over the contact domain as searched
    (``searches`` by label, :func:`.worst_case.worst_case_record`), its ``fresh`` what samples it was not
    optimised on say of it (:func:`.fresh.fresh_record`, the recommended design's with the bootstrap
    statistics; None without fresh samples); ``domain`` the domain itself.
    """
    setup = problems.setup
    # Every problem of a study shares its samples and technology: one of them evaluates every record.
    problem = built_problem(problems, problems.objective)
    every = [chosen, *(front.points if front else ()), *(front.dominated if front else ())]
    records = _Records(setup, problem, every, searches or {}, search_tolerance)
    pareto: ParetoRecord = {"objectives": [], "points": [], "failed": [], "dominated": [], "merged": 0}
    chosen_record = records.record(chosen, "optimum")
    chosen_record["dominated_by"] = None
    if front is not None:
        pareto = {
            "objectives": list(front.objectives),
            "points": [records.record(r, label) for r, label in zip(front.points, front.labels, strict=True)],
            "failed": [failure.as_dict() for failure in front.failed],
            "dominated": [
                records.record(r, label)
                for r, label in zip(front.dominated, front.dominated_labels, strict=True)
            ],
            "merged": front.merged,
        }
        # The recommendation's rule: values within the solver tolerance count as equal.
        chosen_record["dominated_by"] = front.dominating(chosen.numpy_objectives, MERGE_TOLERANCE)
    out: ArmResults = {
        "samples": sample_layout(setup),
        "domain": domain_record(problems),
        "chosen": chosen_record,
        "recommended": _recommended(problems, problem, records, chosen, front, pareto, chosen_record),
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


class _Records:
    """The records of a study's designs: each one's worst case, its pose, and what the fresh samples say of it.

    The fresh samples' impulses of ``every`` design are found at once (one pass over their kinematics).
    """

    def __init__(
        self,
        setup: ArmSetup,
        problem: DesignProblem,
        every: list[DesignResult],
        searches: Mapping[str, WorstCase],
        tolerance: float,
    ) -> None:
        self.setup, self.problem, self.searches, self.tolerance = setup, problem, searches, tolerance
        self.draw = draw = fresh_draw(setup)
        self.fresh: dict[int, FreshImpulses] = (
            {}
            if draw is None
            else dict(
                zip(map(id, every), fresh_impulses(setup, draw, [r.design for r in every]), strict=True)
            )
        )

    def fresh_check(
        self, result: DesignResult, worst_case: float, statistics: bool = False
    ) -> FreshRecord | None:
        """What the fresh samples say of ``result`` (None without fresh samples)."""
        if self.draw is None:
            return None
        found = self.fresh.get(id(result)) or fresh_impulses(self.setup, self.draw, [result.design])[0]
        return cast("FreshRecord", fresh_record(found, worst_case, self.tolerance, statistics))

    def record(self, result: DesignResult, label: str) -> DesignRecord:
        """The record of the design ``label``."""
        out = design_record(self.problem, result, label, self.setup.catalogue)
        search = self.searches.get(label)
        out["worst_case"] = cast("WorstCaseRecord", worst_case_record(result, search, self.tolerance))
        if search is not None:
            out["worst_case"]["pose"] = worst_pose(self.setup, search.q, search.direction)
        out["fresh"] = self.fresh_check(result, out["worst_case"]["domain"])
        return out


def _recommended(
    problems: StudyProblems,
    problem: DesignProblem,
    records: _Records,
    chosen: DesignResult,
    front: ParetoSet | None,
    pareto: ParetoRecord,
    chosen_record: DesignRecord,
) -> DesignRecord:
    """The recommended design's record: the Pareto design's or the chosen one's, with why and what it leaves."""
    recommendation = recommend(chosen, front, problems.objective)
    if recommendation.pareto_index is not None:
        recommended = pareto["points"][recommendation.pareto_index].copy()
    else:
        recommended = chosen_record.copy()
        del recommended["dominated_by"]
    recommended["source"] = recommendation.source
    recommended["pareto_index"] = recommendation.pareto_index
    recommended["reason"] = recommendation.reason
    recommended["undecided"] = undecided(problems, problem, recommendation.result)
    recommended["fresh"] = records.fresh_check(
        recommendation.result, recommended["worst_case"]["domain"], statistics=True
    )
    torque_speed = torque_speed_record(problem, recommendation.result)
    if torque_speed is not None:
        recommended["torque_speed"] = torque_speed
    return recommended


def worst_pose(setup: ArmSetup, q: np.ndarray, direction: np.ndarray) -> WorstPose:
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


def domain_record(problems: StudyProblems) -> DomainRecord:
    """The study's contact domain as plain data: its settings, how much of the box it keeps, searched samples.

    ``kept`` is the fraction of the joint-limit box's (configuration, direction) pairs inside the domain at
    ``sampling_velocity`` [m/s] (None when the configurations are listed); ``searched_samples`` the number of
    samples the worst-case searches added (the last of ``samples``) and ``searched`` those samples as the
    problems took them, ``[q, u]`` each (:meth:`~.problems.StudyProblems.of_run` reads them back).
    """
    setup = problems.setup
    domain = {
        **setup.domain.to_json(),
        "kept": setup.domain_kept,
        "sampling_velocity": setup.sampling_velocity,
        "searched_samples": setup.searched,
        "searched": [[list(q), list(u)] for q, u in problems.extra],
    }
    return cast("DomainRecord", domain)  # the domain's own fields, as ContactDomain.to_json writes them


def undecided(
    problems: StudyProblems, problem: DesignProblem, result: DesignResult
) -> list[UndecidedVariable]:
    """The design variables of ``result`` (a solution of ``problem``) that no objective decides, as plain data.

    ``{"variable", "joint"}`` each, the joint's name, None for a global variable
    (:func:`collision_reflex.optimize.results.undecided_variables`).
    """
    names = problems.setup.arm.joint_names
    return [
        {"variable": name, "joint": None if joint is None else names[joint]}
        for name, joint in undecided_variables(problem, result.x)
    ]


def sample_layout(setup: ArmSetup) -> SampleLayout:
    """Where each sample comes from (for the report's surfaces): configuration index and direction per sample."""
    return {
        "configurations": setup.configurations.tolist(),
        "directions": setup.directions.tolist(),
        "config_index": setup.samples.config_index.tolist(),
        "sample_directions": setup.samples.directions.tolist(),
        "joint_names": list(setup.arm.joint_names),
        "task_dim": int(setup.arm.task_dim),
    }
