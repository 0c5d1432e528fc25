"""The design a run recommends, and why.

The best by the study's objective, or the lightest of those alike in it (:data:`RESOLUTION`).
"""

from __future__ import annotations

from collections.abc import Callable, Hashable, Iterable, Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, TypeVar, cast

from ..vocabulary import IMPULSE_OBJECTIVES
from .dominance import MERGE_TOLERANCE, same_point
from .objectives import OBJECTIVES

if TYPE_CHECKING:
    from .design_result import DesignResult
    from .pareto import ParetoSet


@dataclass(frozen=True)
class Recommendation:
    """The design a run recommends, and why.

    result: the design; pareto_index: its index on the front, or None for the single-objective optimum;
    reason: one sentence saying why it is this design and not another.
    """

    result: DesignResult
    pareto_index: int | None
    reason: str

    @property
    def source(self) -> str:
        """``"optimum"`` or ``"Pareto design <i>"``."""
        return "optimum" if self.pareto_index is None else f"Pareto design {self.pareto_index}"


RESOLUTION = 1e-3
"""Relative difference in an impulse objective below which the recommendation does not rank designs by it.

An objective as flat as the Panda study's mean impulse leaves the same multi-start's paths apart by more
than IPOPT's ``tol`` in the objective, whatever that ``tol``, and designs alike in impulse may differ much in
actuator mass. The closed form itself agrees with the time-domain simulation far less closely than 0.1 % (the
validity map, ``benchmarks/validity_map.py``), so such a difference is no reason to build a heavier arm."""


def recommend(optimum: DesignResult, front: ParetoSet | None, objective: Hashable) -> Recommendation:
    """The design a run recommends: the best by ``objective``, the lightest among those alike in it.

    The best design of every solve the run made (:func:`_best_design`), never dominated by a point of
    ``front``; then, when ``objective`` is an impulse, the lightest of the run's undominated designs within
    :data:`RESOLUTION` of the best impulse among them (:func:`_lightest_alike`).
    """
    return _lightest_alike(_best_design(optimum, front, objective), optimum, front, objective)


Alike = TypeVar("Alike")


def lightest_alike(
    candidates: Sequence[Alike],
    objectives: Callable[[Alike], Mapping[str, float]],
    objective: str,
    incumbent: Alike,
) -> Alike:
    """The lightest of ``candidates`` within :data:`RESOLUTION` of their least ``objective`` (an impulse).

    ``objectives`` gives a candidate's objective values [their units]. ``incumbent`` is kept unless that
    lightest candidate has less actuator mass by more than :data:`MERGE_TOLERANCE` (relative).
    """
    least = min(objectives(c)[objective] for c in candidates)
    alike = [c for c in candidates if objectives(c)[objective] <= least + RESOLUTION * abs(least)]
    lightest = min(alike, key=lambda c: objectives(c)["actuator_mass"])
    mass = objectives(lightest)["actuator_mass"]
    return incumbent if mass >= objectives(incumbent)["actuator_mass"] * (1 - MERGE_TOLERANCE) else lightest


def _lightest_alike(
    best: Recommendation, optimum: DesignResult, front: ParetoSet | None, objective: Hashable
) -> Recommendation:
    """``best``, or the run's lightest undominated design within :data:`RESOLUTION` of the best impulse."""
    if front is None or not front.points or objective not in IMPULSE_OBJECTIVES:
        return best
    judged = tuple(dict.fromkeys([*front.objectives, objective]))
    candidates: list[tuple[int | None, DesignResult]] = list(enumerate(front.points))
    if not front.all_dominating(optimum.numpy_objectives, MERGE_TOLERANCE, judged):
        candidates.append((None, optimum))
    incumbent = (best.pareto_index, best.result)
    chosen = lightest_alike(candidates, lambda c: c[1].numpy_objectives, str(objective), incumbent)
    if chosen[1] is best.result:
        return best
    index, lightest = chosen
    mine, theirs = best.result.numpy_objectives, lightest.numpy_objectives
    source = "the single-objective optimum" if index is None else f"Pareto design {index}"
    name, unit = str(objective).replace("_", " "), OBJECTIVES[str(objective)][1]
    return Recommendation(
        lightest,
        index,
        f"{best.reason}; but {source} is within {100 * RESOLUTION:g} % of it in {name} ({theirs[objective]:.6g} vs "
        f"{mine[objective]:.6g} {unit}) with {theirs['actuator_mass']:.4g} kg of actuators against "
        f"{mine['actuator_mass']:.4g} kg, and a difference below {100 * RESOLUTION:g} % ranks no design (it is within "
        "what the solver's tolerance moves a flat optimum, and far below the closed form's accuracy): the "
        "lighter design is recommended",
    )


def _best_design(optimum: DesignResult, front: ParetoSet | None, objective: Hashable) -> Recommendation:
    """The best design of every solve a run made for ``objective``, never dominated by a point of ``front``.

    ``objective``: the study's objective (a name, or a weighted one). When it is a name among the front's
    objectives, a front point better in it than ``optimum`` (by more than :data:`MERGE_TOLERANCE`) wins; when a
    front point dominates ``optimum`` (values within :data:`MERGE_TOLERANCE` counting as equal), the dominating
    point with the best ``objective`` is recommended. A front
    point equal to ``optimum`` within :data:`MERGE_TOLERANCE` is recommended as that point, so the
    recommendation is on the front whenever the front holds it.
    """
    if front is None or not front.points:
        return Recommendation(optimum, None, "the single-objective optimum (no Pareto front computed)")
    mine = optimum.numpy_objectives
    if isinstance(objective, str) and objective in front.objectives:
        sense, unit = OBJECTIVES[objective][0], OBJECTIVES[objective][1]
        best = min(
            range(len(front.points)), key=lambda i: sense * front.points[i].numpy_objectives[objective]
        )
        theirs = front.points[best].numpy_objectives[objective]
        if sense * (mine[objective] - theirs) > MERGE_TOLERANCE * max(abs(theirs), abs(mine[objective])):
            return Recommendation(
                front.points[best],
                best,
                f"Pareto design {best} has a better {objective.replace('_', ' ')} than the single-objective "
                f"optimum ({theirs:.6g} vs {mine[objective]:.6g} {unit}): the optimum stopped at a local optimum",
            )
    # Judged on the front's objectives and on the study objective's own: a front point that ties the optimum
    # on the front but is heavier, say, when the study also weighs mass, does not beat it.
    judged = tuple(dict.fromkeys([*front.objectives, *_components(objective)]))
    for index, point in enumerate(front.points):
        if same_point(point.numpy_objectives, mine, judged):
            return Recommendation(
                point,
                index,
                f"the single-objective optimum, which is Pareto design {index} (equal within the solver "
                f"tolerance, {MERGE_TOLERANCE:g} relative)",
            )
    beaten_by = front.all_dominating(mine, MERGE_TOLERANCE, judged)
    if beaten_by:
        if isinstance(objective, str) and objective in front.objectives:
            sense = OBJECTIVES[objective][0]
            beaten_by.sort(key=lambda i: sense * front.points[i].numpy_objectives[objective])
        index = beaten_by[0]
        gaps = ", ".join(
            f"{name.replace('_', ' ')} {front.points[index].numpy_objectives[name]:.6g} vs {mine[name]:.6g} "
            f"{OBJECTIVES[name][1]}"
            for name in judged
        )
        # The study objective's anchor minimises it, then the other objectives with it held: said so, as that
        # is the expected way a front's end beats a single-objective optimum (lighter at the same impulse).
        anchor = index < len(front.labels) and front.labels[index] == f"anchor: {objective}"
        words = str(objective).replace("_", " ")
        held = (
            f" (the anchor of {words}: it minimised, then the other objectives with it held)"
            if anchor
            else ""
        )
        return Recommendation(
            front.points[index],
            index,
            f"Pareto design {index}{held} dominates the single-objective optimum (within the solver "
            f"tolerance, {MERGE_TOLERANCE:g} relative: {gaps})",
        )
    return Recommendation(optimum, None, "the single-objective optimum; no Pareto design dominates it")


def _components(objective: Hashable) -> tuple[str, ...]:
    """The objective names a study objective weighs: itself, or each name of a weighted sum."""
    if isinstance(objective, str):
        return (objective,)
    pairs: Iterable[tuple[object, object]] = (
        objective.items()
        if isinstance(objective, Mapping)
        else cast("Iterable[tuple[object, object]]", objective)
    )
    return tuple(str(name) for name, _ in pairs)
