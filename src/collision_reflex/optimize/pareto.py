"""Pareto sets of actuator designs by epsilon-constraint sweeps with lexicographic anchors and warm starts."""

from __future__ import annotations

import itertools
import os
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from .. import _validate
from ..errors import InvalidParameter, SolverFailed
from .problem import OBJECTIVES, DesignProblem
from .solve import DesignResult, solve

ANCHOR_SLACK = 1e-6
"""Relative slack on the first objective when the second is minimised at an anchor (lexicographic step): small
enough not to move the anchor visibly, large enough for IPOPT to find an interior point."""


@dataclass(frozen=True)
class ParetoSet:
    """Non-dominated designs for two or three objectives.

    objectives: the objective names, the first one the sweep minimised.
    points: the non-dominated results, sorted by the first objective.
    failed: ``(epsilon, reason)`` of sweep points the solver could not solve (too tight bounds, ...).
    dominated: results the sweep found that another point dominates (kept for inspection).
    total_time: wall time of the sweep [s].
    """

    objectives: tuple[str, ...]
    points: tuple[DesignResult, ...]
    failed: tuple[tuple[dict[str, float], str], ...] = ()
    dominated: tuple[DesignResult, ...] = ()
    total_time: float = 0.0
    solver_builds: int = 0

    def values(self, numpy_path: bool = True) -> np.ndarray:
        """(n_points, n_objectives) objective values in their units (NumPy path by default)."""
        source = (lambda r: r.numpy_objectives) if numpy_path else (lambda r: r.objectives)
        return np.array([[source(r)[name] for name in self.objectives] for r in self.points])

    def to_frame(self) -> Any:
        """A pandas DataFrame: one row per design with its objectives, per-joint design and solver stats."""
        import pandas as pd

        rows = []
        for index, result in enumerate(self.points):
            row: dict[str, Any] = {"point": index}
            for name in OBJECTIVES:
                row[f"{name} [{OBJECTIVES[name][1]}]"] = result.numpy_objectives[name]
            design = result.design
            for name in (
                "stator_diameter",
                "stack_length",
                "gear_ratio",
                "software_stiffness",
                "reflected_inertia",
                "peak_torque",
                "motor_mass",
            ):
                for joint, value in zip(design.joint_names, getattr(design, name), strict=True):
                    row[f"{name}[{joint}]"] = value
            for joint, value in zip(design.joint_names, result.torque_margin, strict=True):
                row[f"torque_margin[{joint}]"] = value
            row["threshold"] = design.threshold
            row["approach_velocity [m/s]"] = design.approach_velocity
            row["status"] = result.status
            row["iterations"] = result.iterations
            row["solve_time [s]"] = result.solve_time
            rows.append(row)
        return pd.DataFrame(rows)

    def to_csv(self, path: str | os.PathLike[str]) -> None:
        """Write :meth:`to_frame` as CSV, atomically."""
        from .._io import atomic_open

        with atomic_open(path, "w", newline="") as handle:
            self.to_frame().to_csv(handle, index=False)

    def hypervolume(self, reference: Sequence[float]) -> float:
        """Hypervolume dominated by the front up to ``reference`` (objective units; maximised objectives are
        negated, as everything here is minimised).
        """
        return hypervolume(
            _minimised(self.values(), self.objectives), _minimised(np.array([reference]), self.objectives)[0]
        )

    def plot(self, path: str | os.PathLike[str]) -> Any:
        """Draw the front (2 objectives: a line plot; 3: a scatter coloured by the third)."""
        from ..plots.pareto import plot_pareto

        return plot_pareto(self, path)


def pareto_front(
    build: Callable[[str, Sequence[str]], DesignProblem],
    objectives: Sequence[str] = ("worst_case_impulse", "actuator_mass"),
    points: int = 20,
    ipopt_options: dict[str, Any] | None = None,
    progress: Callable[[int, int], None] | None = None,
    anchor_starts: int = 1,
) -> ParetoSet:
    """Pareto set of two or three objectives by epsilon-constraint sweeps.

    Parameters
    ----------
    build: ``build(objective, bounded_objectives) -> DesignProblem``, e.g.
        ``lambda obj, bounded: build_problem(arm, samples, space, technology, obj, constraints, bounded)``.
        It is called once per objective (each problem's solver is reused for every point).
    objectives: 2 or 3 names of :data:`OBJECTIVES`; the sweep minimises the first and bounds the others.
    points: number of points requested on the front (anchors included); for three objectives the bounds form
        a grid of about that many points.
    progress: called as ``progress(done, total)`` after each solve.
    anchor_starts: start points of each anchor's first solve (multi-start, see :func:`solve`); more starts
        make the anchors more robust against local optima, at the cost of a solve each.

    Anchors first: each objective is minimised, then (lexicographically) the others are minimised with it held
    at its optimum, so every anchor is non-dominated. The bounds on the other objectives are then spread
    evenly between the anchors, and each point is started from its neighbour's solution (warm start).
    """
    started = time.perf_counter()
    names = tuple(objectives)
    if len(names) not in (2, 3) or len(set(names)) != len(names):
        raise InvalidParameter("objectives", names, "2 or 3 different objective names")
    for name in names:
        _validate.choice("objective", name, tuple(OBJECTIVES))
    if not isinstance(points, int) or points < 2:
        raise InvalidParameter("points", points, "an integer >= 2")
    problems = {name: build(name, tuple(other for other in names if other != name)) for name in names}
    total = points + len(names) * (len(names) - 1) + len(names) * (anchor_starts - 1)
    done = 0

    def tick() -> None:
        nonlocal done
        done += 1
        if progress is not None:
            progress(done, total)

    results: list[DesignResult] = []
    failed: list[tuple[dict[str, float], str]] = []
    anchors = {}
    for name in names:
        anchor = solve(problems[name], ipopt_options=ipopt_options, starts=anchor_starts)
        tick()
        # Lexicographic: hold this objective at its optimum, minimise the others in turn.
        for other in (o for o in names if o != name):
            bound = anchor_bound(name, anchor.objectives[name])
            try:
                anchor = solve(
                    problems[other], epsilon={name: bound}, x0=anchor.x, ipopt_options=ipopt_options
                )
            except SolverFailed as error:
                failed.append(({name: bound}, error.status))
            tick()
        anchors[name] = anchor
        results.append(anchor)

    primary, bounded = names[0], names[1:]
    grid = epsilon_grid(anchors, bounded, points - len(names))
    start = anchors[primary]
    for epsilon in grid:
        try:
            result = solve(problems[primary], epsilon=epsilon, x0=start, ipopt_options=ipopt_options)
        except SolverFailed as error:
            failed.append((epsilon, error.status))
        else:
            results.append(result)
            start = result
        tick()

    front, dominated = non_dominated(results, names)
    return ParetoSet(
        names,
        tuple(front),
        tuple(failed),
        tuple(dominated),
        time.perf_counter() - started,
        solver_builds=len(problems),
    )


def anchor_bound(name: str, value: float) -> float:
    """The anchor's bound on ``name``: its optimum with a relative slack toward feasibility."""
    sense = OBJECTIVES[name][0]
    return value * (1 + sense * ANCHOR_SLACK) if value > 0 else value + sense * ANCHOR_SLACK


def epsilon_grid(
    anchors: dict[str, DesignResult], bounded: Sequence[str], count: int
) -> list[dict[str, float]]:
    """Bounds on the bounded objectives spread between their values at the anchors, ordered so that each point
    is near the previous one (a snake through the grid for three objectives).
    """
    if count <= 0:
        return []
    ranges = {}
    for name in bounded:
        values = [anchor.numpy_objectives[name] for anchor in anchors.values()]
        ranges[name] = (max(values), min(values)) if OBJECTIVES[name][0] > 0 else (min(values), max(values))
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


def _minimised(values: np.ndarray, names: Sequence[str]) -> np.ndarray:
    """Objective values with maximised objectives negated, so that smaller is better in every column."""
    return values * np.array([OBJECTIVES[name][0] for name in names], dtype=float)


def non_dominated(
    results: list[DesignResult], names: Sequence[str], tolerance: float = 1e-9
) -> tuple[list[DesignResult], list[DesignResult]]:
    """Split results into the non-dominated ones (sorted by the first objective) and the dominated ones.

    ``a`` dominates ``b`` if it is no worse in every objective and better by more than ``tolerance`` (relative)
    in at least one; near-duplicates (equal within the tolerance) keep the first found.
    """
    values = _minimised(np.array([[r.numpy_objectives[n] for n in names] for r in results]), names)
    scale = np.maximum(np.abs(values).max(axis=0), 1e-300)
    keep: list[int] = []
    dropped: list[int] = []
    for i in range(len(results)):
        diff = (values - values[i]) / scale  # < 0: the other is better
        no_worse = np.all(diff <= tolerance, axis=1)
        better = np.any(diff < -tolerance, axis=1)
        duplicate_before = np.all(np.abs(diff) <= tolerance, axis=1) & (np.arange(len(results)) < i)
        if np.any(no_worse & better) or np.any(duplicate_before):
            dropped.append(i)
        else:
            keep.append(i)
    keep.sort(key=lambda i: values[i, 0])
    return [results[i] for i in keep], [results[i] for i in dropped]


def hypervolume(points: np.ndarray, reference: np.ndarray) -> float:
    """Hypervolume (minimisation) of ``points`` (n, 2 or 3) bounded by ``reference``.

    Exact: a sweep over the first objective (2D), or slices over the third (3D) each measured in 2D.
    """
    points = np.asarray(points, dtype=float)
    reference = np.asarray(reference, dtype=float)
    inside = points[np.all(points < reference, axis=1)]
    if inside.size == 0:
        return 0.0
    if inside.shape[1] == 2:
        ordered = inside[np.argsort(inside[:, 0])]
        volume, best_second = 0.0, reference[1]
        for first, second in ordered:
            if second < best_second:
                volume += (reference[0] - first) * (best_second - second)
                best_second = second
        return float(volume)
    if inside.shape[1] == 3:
        levels = np.unique(inside[:, 2])
        volume = 0.0
        for low, high in itertools.pairwise(np.append(levels, reference[2])):
            active = inside[inside[:, 2] <= low]
            volume += hypervolume(active[:, :2], reference[:2]) * (high - low)
        return float(volume)
    raise InvalidParameter("points", points.shape, "2 or 3 objectives")
