"""The pieces of an epsilon-constraint sweep: its anchors, the grid of bounds between them, and its points.

Warm-start policy (one for every caller): each anchor's lexicographic steps start from the anchor found so
far; every epsilon point starts from the first objective's anchor as solved on the sweep's own problem, its
point and multipliers (:data:`collision_reflex.optimize.ipopt.WARM_START_OPTIONS`), or its point alone when
the approach velocity is bounded (:func:`warm_started_points`). A point's result is then a
pure function of the problem and its bounds, whatever the executor and the order in which the points finish;
the points run in parallel. Chaining each point from its neighbour instead leaves no parallelism and was not
faster even in series. On active sets of the samples (``active_set``, :func:`~.pieces.solve_with`) the same
holds: every epsilon point starts from the first anchor's active set and its last NLP (point and multipliers),
and each lexicographic step from its anchor's active set.

Barrier strategy per kind of solve, each the one that needed the fewest IPOPT iterations on the Panda
benchmark: a cold anchor with IPOPT's monotone barrier from ``mu = 1e-2`` (the adaptive barrier needs more
iterations, each dearer); an epsilon point warm-started from the anchor with the adaptive barrier (from the
point alone, monotone, it needs far more; on the UR5 study the point alone, its approach velocity raised to the
point's bound, with the monotone barrier from ``mu = 1e-4`` is the better start: :func:`warm_started_points`,
:data:`POINT_START_OPTIONS`); a lexicographic step with the adaptive barrier and at most
:data:`LEXICOGRAPHIC_MAX_ITER` iterations (monotone, it runs into the 500-iteration cap, its bound held within
:data:`ANCHOR_SLACK` being nearly degenerate).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING

import numpy as np

from ..errors import InvalidParameter, SolverFailed
from .active_set_result import ActiveSetResult
from .design_result import DesignResult
from .dominance import MERGE_TOLERANCE, same_point
from .ipopt import IpoptOptions
from .objectives import OBJECTIVES, objective_values
from .pieces import ProblemBuilder, built_problem, one_at_a_time, solve_with, solved_point, subset_problem
from .results import PointFailure, SweepPoint
from .solve import warm_start
from .subsets import sample_subset

if TYPE_CHECKING:
    from .problem import DesignProblem


ANCHOR_SLACK = 1e-6
"""Relative slack on the first objective when the second is minimised at an anchor (lexicographic step): small
enough not to move the anchor visibly, large enough for IPOPT to find an interior point."""


LEXICOGRAPHIC_MAX_ITER = 150
"""Iteration cap of an anchor's lexicographic step: a step that reaches it stops there, keeps the anchor found
so far and is recorded among the sweep's failures (status ``Maximum_Iterations_Exceeded``)."""
LEXICOGRAPHIC_OPTIONS: dict[str, str | float] = {
    "ipopt.mu_strategy": "adaptive",
    "ipopt.max_iter": LEXICOGRAPHIC_MAX_ITER,
}
"""IPOPT options of a lexicographic step, over the sweep's (module docstring)."""


POINT_START_OPTIONS: dict[str, str | float] = {"ipopt.mu_init": 1e-4}
"""IPOPT options, under the sweep's, of an epsilon point started from the anchor's point alone (monotone barrier
from a smaller ``mu`` than a cold solve's 1e-2: the anchor's point is near the front). On the UR5 study's
points, each started at the anchor's design with the approach velocity raised to its bound
(:func:`velocity_within_bound`), it needed fewer iterations than ``mu = 1e-2`` or 1e-3, and than 1e-6, with
which some points needed a retry; the objectives were the same."""


def warm_started_points(names: Sequence[str]) -> bool:
    """Whether a sweep of ``names`` starts its epsilon points from the anchor's multipliers (module docstring).

    Not when the approach velocity is bounded: on the UR5 study (impulse against approach velocity) the points
    warm-started from the anchor needed far more iterations, with either barrier, than from the anchor's point
    alone with the monotone barrier (and fewer still once the start meets the point's velocity bound, from
    ``mu = 1e-4``: :data:`POINT_START_OPTIONS`).
    """
    return "approach_velocity" not in names[1:]


def point_start(
    anchor: DesignResult, first: DesignResult | None, names: Sequence[str]
) -> tuple[np.ndarray | DesignResult, np.ndarray | None]:
    """Where every epsilon point of a sweep of ``names`` starts: ``(start, initial)`` of :func:`solve_point`.

    ``anchor``: the first objective's anchor; ``first``: its first solve on the sweep's own problem
    (``SweepPoint.start``). The points start from ``first``, point and multipliers, or, when there is none or
    the points are not warm-started (:func:`warm_started_points`), from ``anchor``'s point alone;
    ``initial``: that start's active samples, None off active sets (module docstring).
    """
    origin = first if first is not None and warm_started_points(names) else anchor
    start = origin if origin is first else origin.x
    initial = origin.active_samples if isinstance(origin, ActiveSetResult) else None
    return start, initial


def _others(names: Sequence[str], name: str) -> tuple[str, ...]:
    return tuple(other for other in names if other != name)


@one_at_a_time
def solve_anchor(
    build: ProblemBuilder,
    objective: str,
    objectives: tuple[str, ...],
    ipopt_options: IpoptOptions | None,
    starts: int = 1,
    active_set: str = "auto",
    known: DesignResult | None = None,
) -> SweepPoint:
    """A Pareto anchor: ``objective`` minimised, then each other objective with it held at its optimum.

    The first solve runs from ``starts`` start points, or is ``known``, an optimum of ``objective`` alone
    found beforehand (:func:`anchor_start`); the lexicographic steps make the anchor non-dominated.
    A lexicographic step runs without retries, within :data:`LEXICOGRAPHIC_MAX_ITER` iterations; one that
    fails or stops early keeps the anchor found so far and is recorded among the failures. The first
    objective's anchor keeps its first solve as the start of the epsilon points (``SweepPoint.start``). On
    active sets (``active_set``, :func:`~.pieces.solve_with`) each step starts from the active samples of
    the last.
    """
    label = f"anchor: {objective}"
    result = None if known is None else anchor_start(build, objective, _others(objectives, objective), known)
    if result is None:
        try:
            result = solve_with(
                build,
                objective,
                _others(objectives, objective),
                active_set,
                ipopt_options=ipopt_options,
                starts=starts,
            )
        except SolverFailed as error:
            return SweepPoint(label, None, (PointFailure(objective, {}, error.status, str(error.args[0])),))
    start = result if objective == objectives[0] else None
    held = {objective: anchor_bound(objective, result.objectives[objective])}
    failures = []
    for other in _others(objectives, objective):
        try:
            result = solve_with(
                build,
                other,
                _others(objectives, other),
                active_set,
                epsilon=held,
                x0=result.x,
                ipopt_options={**(ipopt_options or {}), **LEXICOGRAPHIC_OPTIONS},
                retry=False,
                initial=result.active_samples if isinstance(result, ActiveSetResult) else None,
            )
        except SolverFailed as error:
            failures.append(PointFailure(other, dict(held), error.status, str(error.args[0])))
    return SweepPoint(label, result, tuple(failures), start)


def anchor_start(
    build: ProblemBuilder, objective: str, bounded: tuple[str, ...], known: DesignResult
) -> DesignResult | None:
    """``known``, an optimum of ``build(objective, ())``, as a solution of ``build(objective, bounded)``.

    The anchor's problem is the same with rows that bound ``bounded`` (loose at the anchor), so the optimum is
    its optimum: its multipliers are carried by row label (:func:`collision_reflex.optimize.solve.warm_start`,
    a bound's at zero), on active sets those of its last NLP, for the epsilon points' warm starts. This saves
    the anchor's own solve and makes the front's end the multi-started optimum rather than a single start's.
    None when the two problems' variables differ (bounding the worst
    case adds its epigraph variable): the anchor is then solved.

    Raises
    ------
    InvalidParameter: ``known`` is not a point of this problem (its objectives there are not its own).
    """
    source, target = built_problem(build, objective, ()), built_problem(build, objective, bounded)
    if known.x.size != target.x0.size:
        return None
    evaluated = target.evaluate(target.exact_point(known.x))
    found = objective_values(evaluated[0], evaluated[1], evaluated[2], target.samples)
    if not same_point(found, known.objectives, tuple(OBJECTIVES)):  # the same model at the same point: ~1e-15
        raise InvalidParameter(
            f"known optimum of {objective}",
            {name: known.objectives[name] for name in OBJECTIVES},
            f"a result of this sweep's problem (its objectives at that point are {found})",
            "pass the optimum single_optimum found with the same builder",
        )
    if isinstance(known, ActiveSetResult):
        last = known.last_round
        if last is None or last.multipliers is None:
            return known
        subset = sample_subset(target.samples, known.active_samples)
        carried = warm_start(
            subset_problem(build, objective, (), subset),
            subset_problem(build, objective, bounded, subset),
            last,
            last.x,
        )
        return dataclasses.replace(known, last_round=carried)
    return known if known.multipliers is None else warm_start(source, target, known, known.x)


def anchor_bound(name: str, value: float) -> float:
    """The anchor's bound on ``name``: its optimum with a relative slack toward feasibility."""
    sense = OBJECTIVES[name][0]
    return value * (1 + sense * ANCHOR_SLACK) if value > 0 else value + sense * ANCHOR_SLACK


def epsilon_grid(
    anchors: Mapping[str, DesignResult], bounded: Sequence[str], count: int
) -> list[dict[str, float]]:
    """Bounds on the bounded objectives spread between their values at the anchors [their units].

    The points are ordered so that each is near the previous one (a snake through the grid for three
    objectives). An objective whose values at the anchors agree within :data:`MERGE_TOLERANCE` (relative) spans
    no front: it is left unbounded, and with no objective left there are no points (each would repeat an
    anchor; a duty cycle that fixes the motors collapses a front so).
    """
    ranges = {}
    for name in bounded:
        values = [anchor.numpy_objectives[name] for anchor in anchors.values()]
        if max(values) - min(values) > MERGE_TOLERANCE * max(abs(v) for v in values):
            ranges[name] = (
                (max(values), min(values)) if OBJECTIVES[name][0] > 0 else (min(values), max(values))
            )
    bounded = tuple(ranges)
    if count <= 0 or not bounded:
        return []
    if len(bounded) == 1:
        (name,) = bounded
        loose, tight = ranges[name]
        # Interior points only: the anchors already hold the ends.
        return [{name: float(value)} for value in np.linspace(loose, tight, count + 2)[1:-1]]
    per_axis = max(2, round(np.sqrt(count)))
    axes = [np.linspace(*ranges[name], per_axis + 2)[1:-1] for name in bounded]
    grid = []
    for i, first in enumerate(axes[0]):
        second = axes[1] if i % 2 == 0 else axes[1][::-1]
        grid += [{bounded[0]: float(first), bounded[1]: float(value)} for value in second]
    return grid


def velocity_within_bound(
    problem: DesignProblem, start: np.ndarray, epsilon: Mapping[str, float]
) -> np.ndarray:
    """``start`` (NLP variables) with its approach velocity raised to the point's lower bound in ``epsilon``.

    The anchor of the worst-case impulse sits at the slowest approach; an epsilon point demands a faster one,
    which the start then meets, its auxiliaries (epigraph, reaction) set at their exact values for it. On the
    UR5 study's points, with :data:`POINT_START_OPTIONS`, that takes fewer iterations than the anchor's point
    as it is, to the same objectives (from ``mu = 1e-2`` a point may stop at a worse design). A start without a
    velocity bound, or with a fixed velocity, is kept.
    """
    start = np.array(start, dtype=float)
    bound = epsilon.get("approach_velocity")
    slot = problem.layout.slices.get("approach_velocity", [None])[0]
    if bound is None or slot is None or bound <= 0 or start[slot] >= np.log(bound):
        return start
    start[slot] = min(np.log(bound) + 1e-6, problem.ubx[slot])  # 1 ppm inside the bound
    return problem.exact_point(start)


@one_at_a_time
def solve_point(
    build: ProblemBuilder,
    objectives: tuple[str, ...],
    epsilon: dict[str, float],
    start: np.ndarray | DesignResult,
    ipopt_options: IpoptOptions | None,
    active_set: str = "auto",
    initial: np.ndarray | None = None,
) -> SweepPoint:
    """One epsilon-constraint point: the first objective minimised with the others bounded by ``epsilon``.

    The bounds are in the objectives' units; the solve starts from ``start``: a point of the NLP's variables,
    or a result of the same problem, whose multipliers then warm-start IPOPT; a point alone starts at the point's
    velocity bound (:func:`velocity_within_bound`, :data:`POINT_START_OPTIONS`). On active sets
    (``active_set``, :func:`~.pieces.solve_with`) it starts from the samples ``initial``.
    """
    label = "epsilon: " + ", ".join(_bound_text(k, v) for k, v in epsilon.items())
    options = ipopt_options
    if isinstance(start, DesignResult):
        x0: np.ndarray | DesignResult = start
    else:
        x0 = velocity_within_bound(built_problem(build, objectives[0], objectives[1:]), start, epsilon)
        options = {**POINT_START_OPTIONS, **(ipopt_options or {})}
    return solved_point(
        label,
        build,
        objectives[0],
        objectives[1:],
        active_set,
        epsilon,
        x0=x0,
        ipopt_options=options,
        initial=initial,
    )


def _bound_text(name: str, value: float) -> str:
    """``mass <= 0.1`` for a minimised objective, ``approach_velocity >= 0.4`` for a maximised one."""
    return f"{name} {'<=' if OBJECTIVES[name][0] > 0 else '>='} {value:.4g}"
