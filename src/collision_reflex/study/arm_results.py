"""An arm study's results as plain data (``designs.json``).

The record holds the chosen design (the single-objective optimum as solved), the recommended design and why,
the Pareto front as the optimiser decided it, the bounds the designs were solved within, the torque
requirement's kind, and where each contact sample comes from.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, TypedDict

from ..optimize.pareto import MERGE_TOLERANCE, built_problem, recommend
from ..optimize.results import design_record
from ..optimize.space import GLOBAL_VARIABLES, PER_JOINT_VARIABLES
from .arm_setup import ArmSetup, SampleLayout, StudyProblems, sample_layout

if TYPE_CHECKING:
    from ..optimize import DesignResult, ParetoSet

STATIC_REQUIREMENT = "static (gravity only)"
"""The torque requirement when the study gives no duty cycle: gravity (and payload) over the samples."""
DUTY_CYCLE_REQUIREMENT = "duty cycle"
"""The torque requirement when the study gives a duty cycle: the motion's peak, RMS and speed."""
GIVEN_REQUIREMENT = "given per joint"
"""The torque requirement when the study gives each joint's required torque (``constraints.torque_required``)."""


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

    The samples, the chosen and recommended designs, the Pareto front, the bounds of the design variables
    (``{variable: {joint: [lower, upper]}}`` and ``{threshold|approach_velocity: [lower, upper]}``, SI units)
    and the kind of torque requirement (:data:`STATIC_REQUIREMENT`, :data:`GIVEN_REQUIREMENT` or
    :data:`DUTY_CYCLE_REQUIREMENT`).
    """

    samples: SampleLayout
    chosen: dict[str, Any]
    recommended: dict[str, Any]
    pareto: ParetoRecord
    bounds: dict[str, Any]
    requirement: str


def design_bounds(setup: ArmSetup) -> dict[str, Any]:
    """The bounds every design of the study was solved within, as plain data [SI units]."""
    joints = list(setup.arm.joint_names)
    space = setup.space
    reference = setup.technology.reference_motor
    defaults = {"stack_length": reference.stack_length}
    out: dict[str, Any] = {}
    for name in PER_JOINT_VARIABLES:
        bounds = space.per_joint(name, len(joints), defaults.get(name))
        out[name] = {j: [b.lower, b.upper] for j, b in zip(joints, bounds, strict=True)}
    for name in GLOBAL_VARIABLES:
        one = space.global_bounds(name)
        out[name] = [one.lower, one.upper]
    return out


def requirement_kind(setup: ArmSetup) -> str:
    """What the torque requirement is made of: a duty cycle, torques given per joint, or gravity only."""
    if getattr(setup, "duty_cycle", None) is not None:
        return DUTY_CYCLE_REQUIREMENT
    if setup.constraints.torque_required is not None:
        return GIVEN_REQUIREMENT
    return STATIC_REQUIREMENT


def arm_results(problems: StudyProblems, chosen: DesignResult, front: ParetoSet | None) -> ArmResults:
    """``samples``, ``chosen``, ``recommended``, ``pareto``, ``bounds`` and ``requirement`` of an arm study.

    The chosen design (the optimum of the study's objective, as solved) records ``dominated_by``: the index of
    a Pareto design that dominates it, or None. The recommended design
    (:func:`collision_reflex.optimize.pareto.recommend`) records ``source`` (``optimum`` or ``Pareto design
    <i>``), ``pareto_index`` and ``reason``.
    """
    setup = problems.setup
    # Every problem of a study shares its samples and technology: one of them evaluates every record.
    problem = built_problem(problems, problems.objective)

    def record(result: DesignResult, label: str) -> dict[str, Any]:
        return design_record(problem, result, label, setup.catalogue)

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
        source=recommendation.source, pareto_index=recommendation.pareto_index, reason=recommendation.reason
    )
    return {
        "samples": sample_layout(setup),
        "chosen": chosen_record,
        "recommended": recommended,
        "pareto": pareto,
        "bounds": design_bounds(setup),
        "requirement": requirement_kind(setup),
    }
