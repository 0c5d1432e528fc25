"""Pareto sets of actuator designs by epsilon-constraint sweeps with lexicographic anchors.

This is the one sweep, for the library and for studies alike, in-process or through any
:class:`concurrent.futures.Executor` (:class:`~.sweep.Runner`). Its pieces, their warm starts and their
barrier strategies are in :mod:`.epsilon`; which points a front keeps, in :mod:`.dominance`.
"""

from __future__ import annotations

import os
import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from .. import _validate
from .._io import atomic_open
from ..errors import InvalidParameter, SolverFailed
from .design_result import DesignResult
from .dominance import DOMINANCE_TOLERANCE, dominance, hypervolume, merge_repeats, minimised, non_dominated
from .epsilon import epsilon_grid, point_start, solve_anchor, solve_point
from .ipopt import IpoptOptions
from .objectives import OBJECTIVES
from .pieces import ProblemBuilder, check_active_set
from .results import PointFailure, SweepPoint, record_row, result_record
from .sweep import Runner, check_count

if TYPE_CHECKING:
    from pathlib import Path

    import pandas as pd

    from ..record.design import SolvedRecord


@dataclass(frozen=True)
class ParetoSet:
    """Non-dominated designs for two or three objectives.

    objectives: the objective names, the first one the sweep minimised.
    points: the non-dominated results, sorted by the first objective; labels: what each point solved.
    failed: the solves that did not succeed (sweep points, anchors' lexicographic steps).
    dominated: results the sweep found that another point dominates (kept for inspection), with their labels.
    total_time: wall time of the sweep [s]; computed, reused: pieces of the sweep solved now and found finished.
    """

    objectives: tuple[str, ...]
    points: tuple[DesignResult, ...]
    failed: tuple[PointFailure, ...] = ()
    dominated: tuple[DesignResult, ...] = ()
    total_time: float = 0.0
    solver_builds: int = 0
    labels: tuple[str, ...] = ()
    dominated_labels: tuple[str, ...] = ()
    computed: int = 0
    reused: int = 0
    merged: int = 0
    """Solved points dropped as repeats of a reported point (objectives equal within
    :data:`~.dominance.MERGE_TOLERANCE`)."""

    def values(self, numpy_path: bool = True) -> np.ndarray:
        """(n_points, n_objectives) objective values in their units (NumPy path by default)."""
        source = (lambda r: r.numpy_objectives) if numpy_path else (lambda r: r.objectives)
        return np.array([[source(r)[name] for name in self.objectives] for r in self.points])

    def records(self) -> list[SolvedRecord]:
        """Every point as a result record (:func:`collision_reflex.optimize.results.result_record`)."""
        labels = self.labels or ("",) * len(self.points)
        return [result_record(r, label) for r, label in zip(self.points, labels, strict=True)]

    def to_frame(self) -> pd.DataFrame:
        """One row per design (:func:`collision_reflex.optimize.results.record_row`).

        The columns are the objectives, the per-joint design and the solver status, each with its unit.
        """
        import pandas as pd  # lazy: pandas

        return pd.DataFrame([record_row(record, i) for i, record in enumerate(self.records())])

    def to_csv(self, path: str | os.PathLike[str]) -> None:
        """Write :meth:`to_frame` as CSV, atomically."""
        with atomic_open(path, "w", newline="") as handle:
            self.to_frame().to_csv(handle, index=False)

    def dominating(
        self, objectives: Mapping[str, float], tolerance: float = DOMINANCE_TOLERANCE
    ) -> int | None:
        """Index of the first point that dominates a design with these objective values, or None."""
        indices = self.all_dominating(objectives, tolerance)
        return indices[0] if indices else None

    def all_dominating(
        self,
        objectives: Mapping[str, float],
        tolerance: float = DOMINANCE_TOLERANCE,
        names: Sequence[str] | None = None,
    ) -> list[int]:
        """Indices of every point that dominates a design with these objective values (relative ``tolerance``).

        ``names``: the objectives judged (default the front's own); every design carries every objective.
        """
        if not self.points:
            return []
        names = tuple(self.objectives if names is None else names)
        mine = [[objectives[name] for name in names]]
        values = np.vstack([[[r.numpy_objectives[n] for n in names] for r in self.points], mine])
        beaten = dominance(minimised(values, names), tolerance)[:-1, -1]
        return [int(i) for i in np.flatnonzero(beaten)]

    def hypervolume(self, reference: Sequence[float]) -> float:
        """Hypervolume dominated by the front up to ``reference`` (objective units).

        Maximised objectives are negated, as everything here is minimised.
        """
        return hypervolume(
            minimised(self.values(), self.objectives), minimised(np.array([reference]), self.objectives)[0]
        )

    def plot(self, path: str | os.PathLike[str], chosen: Sequence[float] | None = None) -> Path:
        """Draw the front to ``path`` and give the path of the figure.

        2 objectives: a line plot; 3: a scatter coloured by the third; ``chosen``: a design's objective values
        to mark.
        """
        from ..plots.design_front import plot_design_front  # lazy: matplotlib

        units = [OBJECTIVES[name][1] for name in self.objectives]
        return plot_design_front(path, self.objectives, units, self.values(), chosen)


def pareto_front(
    build: ProblemBuilder,
    objectives: Sequence[str] = ("worst_case_impulse", "actuator_mass"),
    points: int = 20,
    ipopt_options: IpoptOptions | None = None,
    anchor_starts: int = 1,
    *,
    runner: Runner | None = None,
    active_set: str = "auto",
    known: Mapping[str, DesignResult] | None = None,
) -> ParetoSet:
    """Pareto set of two or three objectives by epsilon-constraint sweeps.

    Anchors first: each objective is minimised, then (lexicographically) the others are minimised with it held
    at its optimum, so every anchor is non-dominated. The bounds on the other objectives are then spread
    evenly between the anchors; every point starts from the first objective's anchor (:mod:`.epsilon`).

    Parameters
    ----------
    build: ``build(objective, bounded_objectives) -> DesignProblem``, e.g.
        ``lambda obj, bounded: build_problem(arm, samples, space, technology, obj, constraints, bounded)``.
        Each objective's problem is built once per process (its solver is reused for every point); through a
        process pool, ``build`` must be picklable (see :class:`~.pieces.ProblemBuilder`).
    objectives: 2 or 3 names of :data:`OBJECTIVES`; the sweep minimises the first and bounds the others.
    points: number of points requested on the front (anchors included); for three objectives the bounds form
        a grid of about that many points.
    anchor_starts: start points of each anchor's first solve (multi-start, see :func:`solve`); more starts
        make the anchors more robust against local optima, at the cost of a solve each.
    runner: where the pieces (an anchor, a point) run, how many at a time, how finished ones are kept and
        found again on resuming, and whom to tell of the progress (:class:`~.sweep.Runner`; default: in this
        process, one at a time, nothing kept).
    active_set: ``"auto"`` solves every anchor and point on active sets of the samples when the problem has
        at least :data:`collision_reflex.optimize.active_set.ACTIVE_SET_THRESHOLD` of them, ``"always"`` does
        so whatever their number, ``"never"`` solves the full NLP (see :func:`~.pieces.solve_with`); each
        result says which (``method``, and ``active_samples`` in its record).
    known: optima already found of some of ``objectives`` alone, by name (each of ``build(name, ())``, as
        :func:`~.optimum.single_optimum` finds it, from at least ``anchor_starts`` starts and with the same
        ``active_set``): such an anchor takes it as its first solve instead of solving again
        (:func:`~.epsilon.solve_anchor`), so that the front's end is that optimum.

    Raises
    ------
    SolverFailed: an anchor's first solve failed (the bounds of the sweep are then unknown).
    """
    started = time.perf_counter()
    names = tuple(objectives)
    if len(names) not in (2, 3) or len(set(names)) != len(names):
        raise InvalidParameter("objectives", names, "2 or 3 different objective names")
    for name in names:
        _validate.choice("objective", name, tuple(OBJECTIVES))
    check_active_set(build, active_set)
    check_count("points", points, 2)
    check_count("anchor_starts", anchor_starts, 1)
    sweep = (runner or Runner()).schedule(points)
    anchor_tasks = {
        f"anchor-{name}": (
            solve_anchor,
            (build, name, names, ipopt_options, anchor_starts, active_set, (known or {}).get(name)),
        )
        for name in names
    }
    anchors = sweep.run(anchor_tasks)
    by_objective = {name: _solved(anchors[f"anchor-{name}"], name) for name in names}
    grid = epsilon_grid(by_objective, names[1:], points - len(names))
    start, initial = point_start(by_objective[names[0]], anchors[f"anchor-{names[0]}"].start, names)
    sweep.total = len(names) + len(grid)
    point_tasks = {
        f"point-{i:03d}": (solve_point, (build, names, epsilon, start, ipopt_options, active_set, initial))
        for i, epsilon in enumerate(grid)
    }
    # Submitted from the far end of the grid, whose points are the farthest from their start and the dearest:
    # a worker then does not solve the dearest point alone while the others idle. Each point is a pure function
    # of its bounds: the order changes no number.
    solved = sweep.run(dict(reversed(point_tasks.items())))
    pieces = [*anchors.values(), *(solved[name] for name in point_tasks)]
    label = {id(p.result): p.label for p in pieces if p.result is not None}
    front, dominated = non_dominated([p.result for p in pieces if p.result is not None], names)
    front, repeats = merge_repeats(front, names)
    return ParetoSet(
        names,
        tuple(front),
        tuple(f for p in pieces for f in p.failures),
        tuple(dominated),
        time.perf_counter() - started,
        solver_builds=len(names),
        labels=tuple(label[id(r)] for r in front),
        dominated_labels=tuple(label[id(r)] for r in dominated),
        computed=sweep.computed,
        reused=sweep.reused,
        merged=len(repeats),
    )


def _solved(anchor: SweepPoint, name: str) -> DesignResult:
    """The design of ``name``'s anchor.

    Raises
    ------
    SolverFailed: the anchor's first solve failed.
    """
    if anchor.result is None:
        failure = anchor.failures[0]
        raise SolverFailed(
            f"the Pareto anchor of {name} could not be solved: {failure.message}", failure.status, {}, []
        )
    return anchor.result
