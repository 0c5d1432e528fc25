"""Solving combinations of catalogue parts, and the search over them.

Each combination is solved on all samples or on an active set of them by the sweep's rule (``active_set``,
:func:`collision_reflex.optimize.active_set.uses_active_set`), the first round on the continuous optimum's active
samples. Each re-solve on all samples starts from the continuous optimum's values with the gear ratios raised
to cover the parts' own torque requirements (:func:`collision_reflex.optimize.parts.covering_gear_ratios`),
IPOPT warm-started from the continuous optimum's multipliers (:func:`collision_reflex.optimize.solve.warm_start`),
in fewer IPOPT iterations than a cold start from the matched gear ratios. A combination may have more than one
local optimum (the warm and the cold start may reach different ones, either of them the better); which one is
found depends on its start, so the start is the same for every combination (never another combination's
solution: the result does not depend on the order of the search), and the best combination is re-solved cold
as well, from the matched gear ratios, keeping the better (:meth:`PartsSearch.confirm`). On an active set every
re-solve is cold from the matched gear ratios (the continuous optimum's multipliers are its subset's).

:class:`PartsSearch` solves combinations once each, in batches (:data:`PartsSolver`), enumerates them or descends
coordinate by coordinate, and chooses the best by the problem's objective (:func:`objective_value`).
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Any

import numpy as np

from .._interrupt import interruptible
from ..errors import InvalidParameter, SolverFailed
from ..vocabulary import IMPULSE_OBJECTIVES
from .active_set import solve_active_set, uses_active_set
from .active_set_result import ActiveSetResult
from .build import build_problem
from .candidates import CataloguePart
from .design import Design
from .design_result import DesignResult
from .dominance import MERGE_TOLERANCE
from .ipopt import IpoptOptions
from .objectives import objective_expression
from .parts import (
    REQUIREMENT_PASSES,
    catalogue_problem,
    covering_gear_ratios,
    evaluate_parts,
    matched_gear_ratio,
)
from .problem import DesignProblem
from .recommend import lightest_alike
from .solve import solve, warm_start
from .subsets import kept_problem, sample_subset

if TYPE_CHECKING:
    from ..arm.robot import Arm
    from .samples import ContactSamples

__all__ = [
    "InProcessSolver",
    "PartsSearch",
    "PartsSolver",
    "Trial",
    "impulse_objective",
    "objective_value",
    "solve_parts",
    "solved_or_status",
    "warm_startable",
]

PartsSolver = Callable[..., list["DesignResult | str"]]
"""``solve_many(combinations, warm=True)``: each combination (one part per joint) re-optimised, in any order or
place (an executor's workers), as its :class:`DesignResult`, or the status that says why it has none (IPOPT's,
or ``"refused: ..."`` for a problem refused before solving); ``warm``: as :func:`solve_parts` says. Default:
:func:`solve_parts` in this process."""


@dataclass(frozen=True)
class Trial:
    """One combination tried: a part label per joint, its objective value (None: no feasible design) and status.

    The status is IPOPT's, or ``"refused: ..."`` when the problem of these parts was refused before solving;
    iterations: IPOPT's iterations of the design found (None without one).
    """

    parts: tuple[str, ...]
    objective: float | None
    status: str
    iterations: int | None = None


@interruptible()
def solve_parts(
    problem: DesignProblem,
    optimum: DesignResult,
    parts: Sequence[CataloguePart],
    arm: Arm,
    ipopt_options: IpoptOptions | None = None,
    active_set: str = "auto",
    warm: bool = True,
) -> DesignResult:
    """The design of ``parts`` with the remaining continuous variables re-optimised.

    Started from ``optimum``'s values of those variables (clipped to their bounds). ``warm`` (solved on all
    samples, ``optimum`` of ``problem`` itself): the gear ratios at :func:`covering_gear_ratios` (a start that
    meets the parts' torque requirements) and IPOPT warm-started from ``optimum``'s multipliers
    (:func:`warm_start`); otherwise cold, the gear ratios at :func:`matched_gear_ratio`. ``active_set`` (one of
    :data:`collision_reflex.optimize.active_set.ACTIVE_SET_CHOICES`) says whether the samples are solved on an
    active set, by the sweep's rule (:func:`collision_reflex.optimize.active_set.uses_active_set`); on an
    active set the first round holds ``optimum``'s last active samples when it has them (the samples that bound
    the continuous optimum, most likely those that bound a catalogue design near it).

    Raises
    ------
    SolverFailed: no design of these parts meets the constraints (or the solver did not converge).
    InvalidParameter: the problem of these parts is refused before solving (a duty-cycle requirement or a
        gearbox rating that no design within the bounds can meet).
    """
    built = catalogue_problem(problem, parts, arm)
    full = not uses_active_set(built.samples.size, active_set)
    warm = warm and warm_startable(problem, optimum, active_set)
    x0 = _parts_start(problem, optimum, parts, built, raised=warm)
    if full:
        return solve(
            built, x0=warm_start(problem, built, optimum, x0) if warm else x0, ipopt_options=ipopt_options
        )
    initial = None
    if (
        isinstance(optimum, ActiveSetResult)
        and optimum.active_samples.size
        and optimum.impulses.size == built.samples.size
    ):
        initial = optimum.active_samples
    first: ActiveSetResult | None = None
    if warm and isinstance(optimum, ActiveSetResult):
        first = _warm_round(problem, optimum, parts, arm, x0)
    return solve_active_set(
        functools.partial(_catalogue_on, problem, parts, arm),
        built.samples,
        ipopt_options=ipopt_options,
        initial=initial,
        x0=x0,
        full=built,
        warm=first,
    )


def warm_startable(problem: DesignProblem, optimum: DesignResult, active_set: str) -> bool:
    """Whether a combination of parts is re-solved warm from ``optimum`` (:func:`solve_parts`).

    From a solution of ``problem`` itself with its multipliers: on all samples, ``optimum``'s own (a catalogue
    problem has the same samples, so the same auxiliaries); on active sets, those of ``optimum``'s last NLP
    (``last_round``), whose samples the combination's first round then holds.
    """
    if not uses_active_set(problem.samples.size, active_set):
        return optimum.multipliers is not None and optimum.x.size == problem.x0.size
    last = optimum.last_round if isinstance(optimum, ActiveSetResult) else None
    return (
        last is not None
        and last.multipliers is not None
        and optimum.impulses.size == problem.samples.size
        and optimum.x.size == problem.x0.size
    )


def _warm_round(
    problem: DesignProblem, optimum: ActiveSetResult, parts: Sequence[CataloguePart], arm: Arm, x0: np.ndarray
) -> ActiveSetResult:
    """``optimum`` as the warm start of ``parts``' active-set solve from ``x0`` (a point of the full problem).

    Its last NLP's point and multipliers are carried (:func:`warm_start`) to the parts' problem on the same
    samples (the solve's first round, :func:`_catalogue_on`), started at ``x0``'s design with those samples'
    auxiliaries at their exact values.
    """
    subset = sample_subset(problem.samples, optimum.active_samples)
    solved_on = _subset_problem(problem, arm, subset)
    built = _catalogue_on(problem, parts, arm, subset)
    n_design = built.layout.size
    start = built.exact_point(np.concatenate([x0[:n_design], built.x0[n_design:]]))
    assert optimum.last_round is not None  # warm_startable
    return replace(optimum, x=x0, last_round=warm_start(solved_on, built, optimum.last_round, start))


def _subset_problem(problem: DesignProblem, arm: Arm, subset: ContactSamples) -> DesignProblem:
    """``problem`` on the samples ``subset`` (its other inputs the same), built once per process and subset.

    The same for every combination of one snap: one build serves all of them.
    """

    def build() -> DesignProblem:
        return build_problem(
            arm,
            subset,
            problem.space,
            problem.technology,
            problem.objective,
            problem.constraints,
            problem.bounded_objectives,
        )

    return kept_problem(("continuous", id(problem)), subset, build, holds=problem)


def _catalogue_on(
    problem: DesignProblem, parts: Sequence[CataloguePart], arm: Arm, samples: ContactSamples
) -> DesignProblem:
    """:func:`catalogue_problem` on ``samples`` (an active set's round), built once per process.

    The warm start's first round (:func:`_warm_round`) is then the solve's own, not built twice.
    """
    key = ("catalogue", id(problem), *((p.label, p.gear_ratio.lower, p.gear_ratio.upper) for p in parts))
    return kept_problem(key, samples, lambda: catalogue_problem(problem, parts, arm, samples), holds=problem)


def _parts_start(
    problem: DesignProblem,
    optimum: DesignResult,
    parts: Sequence[CataloguePart],
    built: DesignProblem,
    raised: bool,
) -> np.ndarray:
    """The start of ``parts``' problem ``built``: ``optimum``'s values, gear ratios matched (or ``raised``).

    Clipped to ``built``'s bounds, the auxiliaries at their exact values; ``raised``: the gear ratios at
    :func:`covering_gear_ratios`, else at :func:`matched_gear_ratio`.
    """
    design = optimum.design
    gear = (
        covering_gear_ratios(problem, design, parts)
        if raised
        else np.array([matched_gear_ratio(p, design, j) for j, p in enumerate(parts)])
    )
    known: dict[str, np.ndarray] = {
        "gear_ratio": gear,
        "software_stiffness": design.software_stiffness,
        "threshold": np.array([design.threshold]),
        "approach_velocity": np.array([design.approach_velocity]),
    }
    start = built.x0.copy()
    for name, values in known.items():
        for i, b, value in zip(built.layout.slices[name], built.layout.bounds[name], values, strict=True):
            if i is not None:
                start[i] = math.log(min(max(float(value), b.lower), b.upper))
    return built.exact_point(start)


def solved_or_status(
    problem: DesignProblem,
    optimum: DesignResult,
    parts: Sequence[CataloguePart],
    arm: Arm,
    ipopt_options: IpoptOptions | None = None,
    active_set: str = "auto",
    warm: bool = True,
) -> DesignResult | str:
    """:func:`solve_parts`, or the status that says why these parts have no design (see :data:`PartsSolver`)."""
    try:
        return solve_parts(problem, optimum, parts, arm, ipopt_options, active_set, warm)
    except SolverFailed as error:
        # What the parts miss at the ratios that cover their own masses says why, where anything does.
        shortfalls = evaluate_parts(problem, optimum.design, parts).shortfalls
        return error.status + (f" ({'; '.join(shortfalls)})" if shortfalls else "")
    except InvalidParameter as error:  # refused before solving: no design of these parts can meet it
        return f"refused: {error}"


@dataclass(frozen=True)
class InProcessSolver:
    """The default :data:`PartsSolver`: :func:`solve_parts` for each combination, here, one after the other."""

    problem: DesignProblem
    optimum: DesignResult
    arm: Arm
    ipopt_options: IpoptOptions | None
    active_set: str = "auto"

    def __call__(
        self, combinations: Sequence[tuple[CataloguePart, ...]], warm: bool = True
    ) -> list[DesignResult | str]:
        """Each combination's :func:`solved_or_status`."""
        return [
            solved_or_status(
                self.problem, self.optimum, parts, self.arm, self.ipopt_options, self.active_set, warm
            )
            for parts in combinations
        ]


class PartsSearch:
    """Solves combinations of candidate parts (by index per joint) once each, and keeps their values."""

    def __init__(
        self,
        problem: DesignProblem,
        design: Design,
        parts: list[tuple[CataloguePart, ...]],
        solve_many: PartsSolver,
        progress: Callable[[int, int], None] | None,
        owner: Sequence[int] | None = None,
    ) -> None:
        self.problem, self.design, self.parts = problem, design, parts
        self.solve_many, self.progress = solve_many, progress
        # Per joint the joint whose part it takes (a module's first joint): combinations keep modules whole.
        self.owner = list(range(len(parts))) if owner is None else list(owner)
        self.values: dict[tuple[int, ...], float] = {}
        self.results: dict[tuple[int, ...], DesignResult] = {}
        self.tried: dict[tuple[int, ...], Trial] = {}
        self.total = 0

    def tied(self, combinations: Iterable[Sequence[int]]) -> list[tuple[int, ...]]:
        """The distinct ``combinations`` with every module's joints at its first joint's part."""
        return list(dict.fromkeys(tuple(c[o] for o in self.owner) for c in combinations))

    def values_of(self, combinations: list[tuple[int, ...]]) -> list[float]:
        """The problem's objective of each combination re-optimised (inf: no feasible design); new ones solved."""
        new = [c for c in dict.fromkeys(combinations) if c not in self.values]
        chosen = [tuple(self.parts[j][i] for j, i in enumerate(c)) for c in new]
        for combination, parts, solved in zip(new, chosen, self.solve_many(chosen), strict=True):
            labels = tuple(p.label for p in parts)
            if isinstance(solved, str):
                self.values[combination] = math.inf
                self.tried[combination] = Trial(labels, None, solved)
            else:
                value = objective_value(self.problem, solved.numpy_objectives)
                self.values[combination], self.results[combination] = value, solved
                self.tried[combination] = Trial(labels, value, solved.status, solved.iterations)
        if new and self.progress is not None:
            self.progress(len(self.tried), max(self.total, len(self.tried)))
        return [self.values[c] for c in combinations]

    def confirm(self, combination: tuple[int, ...]) -> None:
        """Solve ``combination`` again from the continuous optimum's values alone (cold) and keep the better.

        The warm start may lead a combination to another of its local optima than the cold start from the same
        values does, either of them the better; the chosen parts' design is then never worse than the cold
        start's.
        """
        parts = tuple(self.parts[j][i] for j, i in enumerate(combination))
        (solved,) = self.solve_many([parts], warm=False)
        if isinstance(solved, str):
            return
        value = objective_value(self.problem, solved.numpy_objectives)
        if value < self.values[combination]:
            self.values[combination], self.results[combination] = value, solved
            labels = tuple(p.label for p in parts)
            self.tried[combination] = Trial(labels, value, solved.status, solved.iterations)

    def descend(self) -> int:
        """Coordinate descent from the nearest parts until a pass improves nothing; the number of passes.

        A step solves every candidate of one joint with the others held (one batch) and moves to the best, if
        it is better than the current design by more than :data:`collision_reflex.optimize.dominance.MERGE_TOLERANCE`
        (relative): a smaller difference is within what re-solving repeats, and chasing it costs whole passes of
        re-solves for nothing a design would show. The best combination tried is kept either way
        (:meth:`best`).
        """
        current = self.start()
        (value,) = self.values_of([current])
        passes, improved = 0, True
        while improved:
            improved, passes = False, passes + 1
            for j, joint_parts in enumerate(self.parts):
                if self.owner[j] != j:  # moved with its module's first joint
                    continue
                options = self.tied((*current[:j], c, *current[j + 1 :]) for c in range(len(joint_parts)))
                values = self.values_of(options)
                best = min(range(len(options)), key=lambda i: values[i])
                # From an infeasible design (inf) any feasible one is a move.
                if values[best] < value and (
                    math.isinf(value) or value - values[best] > MERGE_TOLERANCE * abs(value)
                ):
                    current, value, improved = options[best], values[best], True
        return passes

    def start(self) -> tuple[int, ...]:
        """The nearest parts, each joint that misses its own requirement moved to its nearest part that meets it.

        The requirement is of the chosen parts' masses (:func:`evaluate_parts`, no solve), which the continuous
        optimum's lighter ones understate: from a start where two joints miss theirs, no step of the descent,
        which changes one joint, reaches a feasible design.
        """
        current = [0] * len(self.parts)

        def misses(combination: list[int], j: int) -> bool:
            parts = [self.parts[k][i] for k, i in enumerate(combination)]
            prefixes = tuple(
                f"{name}:" for name, o in zip(self.problem.joint_names, self.owner, strict=True) if o == j
            )
            shortfalls = evaluate_parts(self.problem, self.design, parts).shortfalls
            return any(s.startswith(prefixes) for s in shortfalls)

        for _ in range(REQUIREMENT_PASSES):
            moved = False
            for j, joint_parts in enumerate(self.parts):
                if self.owner[j] != j or not misses(current, j):
                    continue
                for c in range(len(joint_parts)):
                    trial = list(self.tied([[*current[:j], c, *current[j + 1 :]]])[0])
                    if c != current[j] and not misses(trial, j):
                        current, moved = trial, True
                        break
            if not moved:
                break
        return tuple(current)

    def least(self) -> tuple[int, ...] | None:
        """The feasible combination of least value (the first tried among equals), or None."""
        feasible = [c for c in self.tried if math.isfinite(self.values[c])]
        return min(feasible, key=lambda c: self.values[c]) if feasible else None

    def best(self) -> tuple[int, ...] | None:
        """The combination chosen: :meth:`least`, or the lightest alike in an impulse objective.

        For an impulse objective alone, the lightest combination within
        :data:`collision_reflex.optimize.recommend.RESOLUTION` of the least impulse, as a run recommends a continuous
        design (:func:`collision_reflex.optimize.recommend.recommend`): a smaller difference ranks no design, and
        the lighter is the better build.
        """
        least = self.least()
        name = impulse_objective(self.problem)
        if least is None or name is None:
            return least
        feasible = [c for c in self.tried if math.isfinite(self.values[c])]
        return lightest_alike(feasible, lambda c: self.results[c].numpy_objectives, name, least)

    def trials(self) -> tuple[Trial, ...]:
        """Every combination tried, in the order tried."""
        return tuple(self.tried.values())


def impulse_objective(problem: DesignProblem | None) -> str | None:
    """The name of ``problem``'s objective when it is one impulse objective alone, else None."""
    names = [] if problem is None else list(problem.objective)
    return names[0] if len(names) == 1 and names[0] in IMPULSE_OBJECTIVES else None


def objective_value(problem: DesignProblem, objectives: Mapping[str, float]) -> float:
    """``problem``'s objective for a design's objective values [their units]: the NLP's, at its scale.

    The weighted, start-normalised objectives with the tie-break term, scaled as ``problem`` scales them, so
    that designs of different (catalogue) problems compare on one scale.
    """
    values: dict[str, Any] = dict(objectives)  # plain numbers: the formula is backend-agnostic arithmetic
    return float(objective_expression(problem.objective, values, problem.objective_scale))
