"""An arm study's results as plain data (``designs.json``).

The record holds the chosen design, the Pareto front as the optimiser decided it, and where each contact
sample comes from.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, TypedDict

from ..optimize.pareto import built_problem
from ..optimize.results import design_record
from .arm_setup import SampleLayout, StudyProblems, sample_layout

if TYPE_CHECKING:
    from ..optimize import DesignResult, ParetoSet


class ParetoRecord(TypedDict):
    """The Pareto front as plain data: objective names, designs on the front, failed points, dominated designs.

    Each design is a :func:`collision_reflex.optimize.results.design_record`; each failure a
    :meth:`collision_reflex.optimize.results.PointFailure.as_dict`.
    """

    objectives: list[str]
    points: list[dict[str, Any]]
    failed: list[dict[str, Any]]
    dominated: list[dict[str, Any]]


class ArmResults(TypedDict):
    """An arm study's own part of ``designs.json``: the samples, the chosen design and the Pareto front."""

    samples: SampleLayout
    chosen: dict[str, Any]
    pareto: ParetoRecord


def arm_results(problems: StudyProblems, chosen: DesignResult, front: ParetoSet | None) -> ArmResults:
    """``samples``, ``chosen`` and ``pareto`` of an arm study's results.

    The chosen design (the optimum of the study's objective) records ``dominated_by``: the index of a Pareto
    design that dominates it, or None (a local optimum the sweep beat, or no front computed).
    """
    setup = problems.setup
    # Every problem of a study shares its samples and technology: one of them evaluates every record.
    problem = built_problem(problems, problems.objective)

    def record(result: DesignResult, label: str) -> dict[str, Any]:
        return design_record(problem, result, label, setup.catalogue)

    pareto: ParetoRecord = {"objectives": [], "points": [], "failed": [], "dominated": []}
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
        }
        chosen_record["dominated_by"] = front.dominating(chosen.numpy_objectives)
    return {"samples": sample_layout(setup), "chosen": chosen_record, "pareto": pareto}
