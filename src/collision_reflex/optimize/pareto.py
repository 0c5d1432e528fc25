"""Pareto sets of actuator designs by epsilon-constraint sweeps with lexicographic anchors.

This is the one sweep, for the library and for studies alike, in-process or through any
:class:`concurrent.futures.Executor`.

Warm-start policy (one for every caller): each anchor's lexicographic steps start from the anchor found so
far; every epsilon point starts from the first objective's anchor as solved on the sweep's own problem, its
point and multipliers (:data:`collision_reflex.optimize.solve.WARM_START_OPTIONS`), or its point alone when
the approach velocity is bounded (:func:`warm_started_points`). A point's result is then a
pure function of the problem and its bounds, whatever the executor and the order in which the points finish;
the points run in parallel. Chaining each point from its neighbour instead leaves no parallelism and was not
faster even in series. On active sets of the samples (``active_set``, :func:`solve_with`) the same holds: every
epsilon point starts from the first anchor's active set and its last NLP (point and multipliers), and each
lexicographic step from its anchor's active set.

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

import contextlib
import dataclasses
import functools
import inspect
import itertools
import os
import threading
import time
import warnings
from collections.abc import Callable, Hashable, Iterable, Mapping, Sequence
from concurrent.futures import FIRST_COMPLETED, Executor, Future, wait
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, ParamSpec, Protocol, TypeVar, cast

import numpy as np

from .. import _validate
from ..errors import InvalidParameter, SolverFailed
from .active_set import ACTIVE_SET_CHOICES, solve_active_set, uses_active_set
from .active_set_result import ActiveSetResult
from .blas import single_threaded_blas
from .design_result import DesignResult
from .ipopt import IpoptOptions
from .objectives import IMPULSE_OBJECTIVES, OBJECTIVES, objective_values
from .problem import DesignProblem
from .results import PointFailure, SweepPoint, record_row, result_record
from .serial import SerialExecutor
from .solve import solve, warm_start
from .subsets import kept_problem, sample_subset

if TYPE_CHECKING:
    from pathlib import Path

    import pandas as pd

    from .samples import ContactSamples

_P = ParamSpec("_P")
_R = TypeVar("_R")

ANCHOR_SLACK = 1e-6
"""Relative slack on the first objective when the second is minimised at an anchor (lexicographic step): small
enough not to move the anchor visibly, large enough for IPOPT to find an interior point."""

DOMINANCE_TOLERANCE = 1e-9
"""Relative difference below which two objective values count as equal.

Relative to each objective's largest magnitude."""

MERGE_TOLERANCE = 1e-5
"""Relative difference below which two solved designs' objectives are equal: one point of the front, and no
reason to prefer one design over the other.

IPOPT stops at ``tol = 1e-8`` on its scaled optimality error, so one optimum reached from different starts or
under different bounds repeats its objective values to about 1e-7 relative; a lexicographic anchor holds its
first objective within :data:`ANCHOR_SLACK` (1e-6) of the optimum. Ten times the larger, 1e-5, merges such
repeats and stays far below any difference a designer acts on."""

LEXICOGRAPHIC_MAX_ITER = 150
"""Iteration cap of an anchor's lexicographic step: a step that reaches it stops there, keeps the anchor found
so far and is recorded among the sweep's failures (status ``Maximum_Iterations_Exceeded``)."""
LEXICOGRAPHIC_OPTIONS: dict[str, str | float] = {
    "ipopt.mu_strategy": "adaptive",
    "ipopt.max_iter": LEXICOGRAPHIC_MAX_ITER,
}
"""IPOPT options of a lexicographic step, over the sweep's (module docstring)."""

OPTIMUM_STARTS = 4
"""Start points of the single-objective solve by default: the given start and three seeded random ones (see
:func:`collision_reflex.optimize.solve.solve`), against local optima of the non-convex worst case. Each start is
screened at a loose tolerance and only those on distinct central paths are finished: fewer iterations than
finishing every start, for the same optimum."""


class ProblemBuilder(Protocol):
    """``build(objective, bounded_objectives[, samples]) -> DesignProblem``.

    Hashable (the problems are cached per process by builder); picklable (a module-level function, or a frozen
    dataclass) to run through a process pool. A builder that also takes ``samples`` (a
    :class:`collision_reflex.optimize.ContactSamples`, default all of its own) can be solved on active sets
    (:mod:`collision_reflex.optimize.active_set`): ``lambda obj, bounded, s=samples: build_problem(arm, s,
    ...)``.
    """

    def __call__(self, objective: Hashable, bounded: tuple[str, ...], /) -> DesignProblem:
        """Build the problem minimising ``objective`` (a name, or a weighted one) with ``bounded`` bounded."""
        ...

    def __hash__(self) -> int: ...


FinishedHook = Callable[[str], Mapping[str, Any] | None]
"""``finished(name)``: the saved JSON of a finished piece of a sweep (``anchor-<objective>``, ``point-007``),
or None to compute it."""
SaveHook = Callable[[str, dict[str, Any]], None]
"""``save(name, data)``: keep a piece of a sweep as it finishes (JSON types)."""


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
    """Solved points dropped as repeats of a reported point (objectives equal within :data:`MERGE_TOLERANCE`)."""

    def values(self, numpy_path: bool = True) -> np.ndarray:
        """(n_points, n_objectives) objective values in their units (NumPy path by default)."""
        source = (lambda r: r.numpy_objectives) if numpy_path else (lambda r: r.objectives)
        return np.array([[source(r)[name] for name in self.objectives] for r in self.points])

    def records(self) -> list[dict[str, Any]]:
        """Every point as a result record (:func:`collision_reflex.optimize.results.result_record`)."""
        labels = self.labels or ("",) * len(self.points)
        return [result_record(r, label) for r, label in zip(self.points, labels, strict=True)]

    def to_frame(self) -> pd.DataFrame:
        """One row per design (:func:`collision_reflex.optimize.results.record_row`).

        The columns are the objectives, the per-joint design and the solver status, each with its unit.
        """
        import pandas as pd

        return pd.DataFrame([record_row(record, i) for i, record in enumerate(self.records())])

    def to_csv(self, path: str | os.PathLike[str]) -> None:
        """Write :meth:`to_frame` as CSV, atomically."""
        from .._io import atomic_open

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
        beaten = _dominance(_minimised(values, names), tolerance)[:-1, -1]
        return [int(i) for i in np.flatnonzero(beaten)]

    def hypervolume(self, reference: Sequence[float]) -> float:
        """Hypervolume dominated by the front up to ``reference`` (objective units).

        Maximised objectives are negated, as everything here is minimised.
        """
        return hypervolume(
            _minimised(self.values(), self.objectives), _minimised(np.array([reference]), self.objectives)[0]
        )

    def plot(self, path: str | os.PathLike[str], chosen: Sequence[float] | None = None) -> Path:
        """Draw the front to ``path`` and give the path of the figure.

        2 objectives: a line plot; 3: a scatter coloured by the third; ``chosen``: a design's objective values
        to mark.
        """
        from ..plots.design_front import plot_design_front

        units = [OBJECTIVES[name][1] for name in self.objectives]
        return plot_design_front(path, self.objectives, units, self.values(), chosen)


def pareto_front(
    build: ProblemBuilder,
    objectives: Sequence[str] = ("worst_case_impulse", "actuator_mass"),
    points: int = 20,
    ipopt_options: IpoptOptions | None = None,
    progress: Callable[[int, int], None] | None = None,
    anchor_starts: int = 1,
    *,
    executor: Executor | None = None,
    in_flight: int | None = None,
    finished: FinishedHook | None = None,
    save: SaveHook | None = None,
    active_set: str = "auto",
    known: Mapping[str, DesignResult] | None = None,
) -> ParetoSet:
    """Pareto set of two or three objectives by epsilon-constraint sweeps.

    Anchors first: each objective is minimised, then (lexicographically) the others are minimised with it held
    at its optimum, so every anchor is non-dominated. The bounds on the other objectives are then spread
    evenly between the anchors; every point starts from the first objective's anchor (module docstring).

    Parameters
    ----------
    build: ``build(objective, bounded_objectives) -> DesignProblem``, e.g.
        ``lambda obj, bounded: build_problem(arm, samples, space, technology, obj, constraints, bounded)``.
        Each objective's problem is built once per process (its solver is reused for every point); through a
        process pool, ``build`` must be picklable (see :class:`ProblemBuilder`).
    objectives: 2 or 3 names of :data:`OBJECTIVES`; the sweep minimises the first and bounds the others.
    points: number of points requested on the front (anchors included); for three objectives the bounds form
        a grid of about that many points.
    progress: called as ``progress(done, total)`` after each piece (an anchor or a point).
    anchor_starts: start points of each anchor's first solve (multi-start, see :func:`solve`); more starts
        make the anchors more robust against local optima, at the cost of a solve each.
    executor: where the pieces run (default: in this process); a process pool or a Dask client's executor
        give the same numbers.
    in_flight: pieces submitted at a time (default 1 in-process, all otherwise); finished pieces are saved
        while the others run.
    finished, save: keep each finished piece (``save(name, json)``) and find it again (``finished(name)``), so
        that a sweep resumed after an interruption redoes only the rest.
    active_set: ``"auto"`` solves every anchor and point on active sets of the samples when the problem has
        at least :data:`collision_reflex.optimize.active_set.ACTIVE_SET_THRESHOLD` of them, ``"always"`` does
        so whatever their number, ``"never"`` solves the full NLP (see :func:`solve_with`); each result says
        which (``method``, and ``active_samples`` in its record).
    known: optima already found of some of ``objectives`` alone, by name (each of ``build(name, ())``, as
        :func:`single_optimum` finds it, from at least ``anchor_starts`` starts and with the same
        ``active_set``): such an anchor takes it as its first solve instead of solving again
        (:func:`solve_anchor`), so that the front's end is that optimum.

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
    _check_active_set(build, active_set)
    if not isinstance(points, int) or isinstance(points, bool) or points < 2:
        raise InvalidParameter("points", points, "an integer >= 2")
    for name, value in (
        ("anchor_starts", anchor_starts),
        ("in_flight", 1 if in_flight is None else in_flight),
    ):
        if not isinstance(value, int) or isinstance(value, bool) or value < 1:
            raise InvalidParameter(name, value, "an integer >= 1")
    sweep = _Sweep(
        executor or SerialExecutor(),
        in_flight or (1 if executor is None else 10**6),
        finished,
        save,
        progress,
        points,
    )
    anchor_tasks = {
        f"anchor-{name}": (
            solve_anchor,
            (build, name, names, ipopt_options, anchor_starts, active_set, (known or {}).get(name)),
        )
        for name in names
    }
    anchors = sweep.run(anchor_tasks)
    by_objective: dict[str, DesignResult] = {}
    for name in names:
        anchor = anchors[f"anchor-{name}"]
        if anchor.result is None:
            failure = anchor.failures[0]
            raise SolverFailed(
                f"the Pareto anchor of {name} could not be solved: {failure.message}", failure.status, {}, []
            )
        by_objective[name] = anchor.result
    grid = epsilon_grid(by_objective, names[1:], points - len(names))
    first = anchors[f"anchor-{names[0]}"].start
    origin = first if first is not None and warm_started_points(names) else by_objective[names[0]]
    start = origin if origin is first else origin.x
    initial = origin.active_samples if isinstance(origin, ActiveSetResult) else None
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


def single_optimum(
    build: ProblemBuilder,
    objective: Hashable,
    ipopt_options: IpoptOptions | None = None,
    progress: Callable[[int, int], None] | None = None,
    *,
    executor: Executor | None = None,
    finished: FinishedHook | None = None,
    save: SaveHook | None = None,
    starts: int = OPTIMUM_STARTS,
    active_set: str = "auto",
    x0: np.ndarray | None = None,
    initial: np.ndarray | None = None,
) -> tuple[DesignResult, bool]:
    """The optimum of one objective (a name, or what ``build`` takes for a weighted one).

    It is run, saved and found again like a piece of :func:`pareto_front` (its name: ``optimum``, or
    ``optimum-<starts>-starts``). ``starts``: start points of the solve (multi-start, seeded: see
    :func:`collision_reflex.optimize.solve.solve`; on an active set each start settles its own);
    ``active_set``: as :func:`pareto_front`; ``x0`` and ``initial``: the first start's point and first active
    samples, as :func:`solve_with` takes them. Returns the result and whether it was found finished.

    Raises
    ------
    SolverFailed: every start failed.
    """
    if not isinstance(starts, int) or isinstance(starts, bool) or starts < 1:
        raise InvalidParameter("starts", starts, "an integer >= 1")
    _check_active_set(build, active_set)
    name = "optimum" if starts == 1 else f"optimum-{starts}-starts"
    pieces = _Sweep(executor or SerialExecutor(), 1, finished, save, progress, 1)
    (point,) = pieces.run(
        {name: (solve_alone, (build, objective, ipopt_options, starts, active_set, x0, initial))}
    ).values()
    if point.result is None:
        failure = point.failures[0]
        raise SolverFailed(failure.message, failure.status, {}, [])
    return point.result, pieces.reused == 1


def known_optima(objective: Hashable, optimum: DesignResult, anchor_starts: int) -> dict[str, DesignResult]:
    """:func:`pareto_front`'s ``known`` from a study's optimum (of ``objective``, :data:`OPTIMUM_STARTS` starts).

    The optimum is that objective's anchor's first solve when the objective is one of them (not a weighted sum)
    and the anchors ask no more starts.
    """
    return {objective: optimum} if isinstance(objective, str) and anchor_starts <= OPTIMUM_STARTS else {}


class _Sweep:
    """Runs named pieces through an executor, a few at a time, reusing and saving finished ones."""

    def __init__(
        self,
        executor: Executor,
        in_flight: int,
        finished: FinishedHook | None,
        save: SaveHook | None,
        progress: Callable[[int, int], None] | None,
        total: int,
    ) -> None:
        self.executor, self.in_flight = executor, in_flight
        self.finished, self.save, self.progress = finished, save, progress
        self.total, self.done, self.computed, self.reused = total, 0, 0, 0

    def _tick(self) -> None:
        self.done += 1
        if self.progress is not None:
            self.progress(self.done, self.total)

    def run(
        self, tasks: Mapping[str, tuple[Callable[..., SweepPoint], tuple[object, ...]]]
    ) -> dict[str, SweepPoint]:
        """Every task's :class:`SweepPoint`, in the order of ``tasks``."""
        out: dict[str, SweepPoint] = {}
        queue = []
        for name, task in tasks.items():
            saved = _reusable(self.finished(name)) if self.finished is not None else None
            if saved is not None:
                out[name] = saved
                self.reused += 1
                self._tick()
            else:
                queue.append((name, task))
        pending: dict[Future, str] = {}
        try:
            while queue or pending:
                while queue and len(pending) < self.in_flight:
                    name, (function, args) = queue.pop(0)
                    pending[self.executor.submit(function, *args)] = name
                done, _ = wait(pending, return_when=FIRST_COMPLETED)
                self._collect(done, pending, out)
        except BaseException:
            for future in pending:
                future.cancel()
            # Interrupted (or failed): keep what finished meanwhile, so that the resumed run need not redo it.
            finished = [f for f in pending if f.done() and not f.cancelled() and f.exception() is None]
            with contextlib.suppress(Exception):
                self._collect(finished, pending, out)
            raise
        return {name: out[name] for name in tasks}

    def _collect(
        self, done: Iterable[Future], pending: dict[Future, str], out: dict[str, SweepPoint]
    ) -> None:
        """Take the results of ``done`` futures out of ``pending`` into ``out``, saving each."""
        for future in sorted(done, key=lambda f: pending[f]):
            name = pending.pop(future)
            out[name] = future.result()
            if self.save is not None:
                self.save(name, out[name].to_json())
            self.computed += 1
            self._tick()


def _reusable(saved: Mapping[str, Any] | None) -> SweepPoint | None:
    """A saved piece, or None if there is none or it is not one (another version's file): then it is redone."""
    if saved is None:
        return None
    try:
        return SweepPoint.from_json(saved)
    except (AttributeError, KeyError, TypeError, ValueError):
        return None


# --- pieces of a sweep (run in workers: picklable arguments, a picklable SweepPoint back) ---------------------

_SOLVER_LOCK = threading.RLock()
"""CasADi functions, IPOPT and (sequential) MUMPS are not thread-safe: within one process the pieces run one at a
time (a Dask worker with several threads, for instance); parallelism comes from processes."""


@functools.lru_cache(maxsize=16)
def built_problem(build: Hashable, objective: Hashable, bounded: tuple[str, ...] = ()) -> DesignProblem:
    """``build(objective, bounded)``, built once per process and builder.

    Later pieces reuse its solvers; the results do not depend on which piece came first.
    """
    problem: DesignProblem = build(objective, bounded)  # type: ignore[operator]
    return problem


def release_problems() -> None:
    """Drop this process's built problems (:func:`built_problem`, the active sets' subset problems).

    For a caller that moves on to other samples (a worst-case search's exchange round): the problems on the
    samples before would otherwise stay beside the new ones, each as large as its samples.
    """
    from .subsets import release_subsets

    built_problem.cache_clear()
    release_subsets()


def one_at_a_time(function: Callable[_P, _R]) -> Callable[_P, _R]:
    """Run a piece under the solver lock with single-threaded BLAS (the same numbers in every process).

    Within one process the pieces run one at a time (a Dask worker with several threads): BLAS's thread count
    is a process-wide setting, so a piece running beside another could see it changed under it.
    """

    @functools.wraps(function)
    def locked(*args: _P.args, **kwargs: _P.kwargs) -> _R:
        with _SOLVER_LOCK, single_threaded_blas():
            return function(*args, **kwargs)

    return locked


def warm_started_points(names: Sequence[str]) -> bool:
    """Whether a sweep of ``names`` starts its epsilon points from the anchor's multipliers (module docstring).

    Not when the approach velocity is bounded: on the UR5 study (impulse against approach velocity) the points
    warm-started from the anchor needed far more iterations, with either barrier, than from the anchor's point
    alone with the monotone barrier (and fewer still once the start meets the point's velocity bound, from
    ``mu = 1e-4``: :data:`POINT_START_OPTIONS`).
    """
    return "approach_velocity" not in names[1:]


def takes_samples(build: Hashable) -> bool:
    """Whether ``build`` accepts ``build(objective, bounded, samples)`` (it can build on active sets)."""
    try:
        inspect.signature(build).bind(None, (), None)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        return False
    return True


def _check_active_set(build: Hashable, active_set: str) -> None:
    """Refuse an unknown choice, and ``"always"`` with a builder that cannot build on a subset of samples."""
    _validate.choice("active_set", active_set, ACTIVE_SET_CHOICES)
    if active_set == "always" and not takes_samples(build):
        raise InvalidParameter(
            "active_set",
            active_set,
            "a builder taking the samples, build(objective, bounded, samples), to solve on active sets",
        )


def subset_problem(
    build: Hashable, objective: Hashable, bounded: tuple[str, ...], samples: ContactSamples
) -> DesignProblem:
    """``build(objective, bounded, samples)``, kept per process (:func:`~.active_set.kept_problem`)."""
    return kept_problem(
        (build, objective, bounded),
        samples,
        lambda: build(objective, bounded, samples),  # type: ignore[operator]
    )


def solve_with(
    build: ProblemBuilder,
    objective: Hashable,
    bounded: tuple[str, ...],
    active_set: str,
    epsilon: Mapping[str, float] | None = None,
    x0: np.ndarray | DesignResult | None = None,
    ipopt_options: IpoptOptions | None = None,
    starts: int = 1,
    *,
    retry: bool = True,
    initial: np.ndarray | None = None,
) -> DesignResult:
    """Solve ``build(objective, bounded)`` on all samples or on active sets of them, as ``active_set`` says.

    On active sets (:func:`collision_reflex.optimize.active_set.solve_active_set`) the solve starts from the
    design of ``x0`` and from the samples ``initial`` (indices; default its own first choice); an
    active-set result ``x0`` of the same problem also warm-starts the first round from its last NLP when that
    round has its samples. ``"auto"`` with a builder that does not take samples solves the full NLP, with a
    warning, whatever the number of samples.
    """
    problem = built_problem(build, objective, bounded)
    n_samples = problem.samples.size
    if uses_active_set(n_samples, active_set) and not takes_samples(build):
        warnings.warn(
            f"{n_samples} contact samples solved as one NLP: the problem builder does not take the samples "
            "(build(objective, bounded, samples)), so it cannot be solved on active sets",
            RuntimeWarning,
            stacklevel=2,
        )
    elif uses_active_set(n_samples, active_set):
        return solve_active_set(
            functools.partial(subset_problem, build, objective, bounded),
            problem.samples,
            epsilon,
            ipopt_options,
            initial=initial,
            starts=starts,
            x0=x0.x if isinstance(x0, DesignResult) else x0,
            retry=retry,
            full=problem,
            warm=x0 if isinstance(x0, ActiveSetResult) else None,
        )
    return solve(problem, epsilon, x0, ipopt_options, starts=starts, retry=retry)


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
    active sets (``active_set``, :func:`solve_with`) each step starts from the active samples of the last.
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


POINT_START_OPTIONS: dict[str, str | float] = {"ipopt.mu_init": 1e-4}
"""IPOPT options, under the sweep's, of an epsilon point started from the anchor's point alone (monotone barrier
from a smaller ``mu`` than a cold solve's 1e-2: the anchor's point is near the front). On the UR5 study's
points, each started at the anchor's design with the approach velocity raised to its bound
(:func:`velocity_within_bound`), it needed fewer iterations than ``mu = 1e-2`` or 1e-3, and than 1e-6, with
which some points needed a retry; the objectives were the same."""


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
    (``active_set``, :func:`solve_with`) it starts from the samples ``initial``.
    """
    label = "epsilon: " + ", ".join(_bound_text(k, v) for k, v in epsilon.items())
    options = ipopt_options
    if isinstance(start, DesignResult):
        x0: np.ndarray | DesignResult = start
    else:
        x0 = velocity_within_bound(built_problem(build, objectives[0], objectives[1:]), start, epsilon)
        options = {**POINT_START_OPTIONS, **(ipopt_options or {})}
    try:
        result = solve_with(
            build,
            objectives[0],
            objectives[1:],
            active_set,
            epsilon=epsilon,
            x0=x0,
            ipopt_options=options,
            initial=initial,
        )
    except SolverFailed as error:
        return SweepPoint(
            label, None, (PointFailure(objectives[0], epsilon, error.status, str(error.args[0])),)
        )
    return SweepPoint(label, result)


@one_at_a_time
def solve_alone(
    build: ProblemBuilder,
    objective: Hashable,
    ipopt_options: IpoptOptions | None,
    starts: int = 1,
    active_set: str = "auto",
    x0: np.ndarray | None = None,
    initial: np.ndarray | None = None,
) -> SweepPoint:
    """A single-objective optimum as a piece run like the sweep's.

    ``objective``: a name, or what ``build`` takes for a weighted one; ``starts``: start points (multi-start);
    ``active_set``, ``x0`` and ``initial``: see :func:`solve_with`.
    """
    try:
        result = solve_with(
            build,
            objective,
            (),
            active_set,
            x0=x0,
            ipopt_options=ipopt_options,
            starts=starts,
            initial=initial,
        )
    except SolverFailed as error:
        return SweepPoint(
            "optimum", None, (PointFailure(str(objective), {}, error.status, str(error.args[0])),)
        )
    return SweepPoint("optimum", result)


def _bound_text(name: str, value: float) -> str:
    """``mass <= 0.1`` for a minimised objective, ``approach_velocity >= 0.4`` for a maximised one."""
    return f"{name} {'<=' if OBJECTIVES[name][0] > 0 else '>='} {value:.4g}"


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


def _minimised(values: np.ndarray, names: Sequence[str]) -> np.ndarray:
    """Objective values with maximised objectives negated, so that smaller is better in every column."""
    return values * np.array([OBJECTIVES[name][0] for name in names], dtype=float)


def _dominance(values: np.ndarray, tolerance: float) -> np.ndarray:
    """(n, n) booleans of minimised ``values`` (n, m): ``[i, j]`` if point i dominates point j.

    Point i dominates point j when it is no worse in any column and better in one, by more than ``tolerance``
    of the column's largest magnitude.
    """
    scale = np.maximum(np.abs(values).max(axis=0), 1e-300)
    diff = (values[:, None, :] - values[None, :, :]) / scale  # [i, j] < 0: i is better than j
    return np.all(diff <= tolerance, axis=2) & np.any(diff < -tolerance, axis=2)


def dominated_mask(values: np.ndarray, tolerance: float = DOMINANCE_TOLERANCE) -> np.ndarray:
    """(n,) booleans: which rows of ``values`` (n, m; every column minimised) another row dominates."""
    values = np.asarray(values, dtype=float)
    if not len(values):
        return np.zeros(0, dtype=bool)
    return np.asarray(_dominance(values, tolerance).any(axis=0), dtype=bool)


def non_dominated(
    results: Sequence[DesignResult], names: Sequence[str], tolerance: float = DOMINANCE_TOLERANCE
) -> tuple[list[DesignResult], list[DesignResult]]:
    """Split results into the non-dominated ones (sorted by the first objective) and the dominated ones.

    ``a`` dominates ``b`` if it is no worse in every objective and better by more than ``tolerance`` (relative)
    in at least one; near-duplicates (equal within the tolerance) keep the first found.
    """
    if not results:
        return [], []
    values = _minimised(np.array([[r.numpy_objectives[n] for n in names] for r in results]), names)
    scale = np.maximum(np.abs(values).max(axis=0), 1e-300)
    same = np.all(np.abs((values[:, None, :] - values[None, :, :]) / scale) <= tolerance, axis=2)
    earlier_duplicate = np.tril(same, k=-1).any(axis=1)  # [i, j] with j < i
    dropped = _dominance(values, tolerance).any(axis=0) | earlier_duplicate
    keep = sorted(np.flatnonzero(~dropped).tolist(), key=lambda i: values[i, 0])
    return [results[i] for i in keep], [results[i] for i in np.flatnonzero(dropped).tolist()]


def same_point(a: Mapping[str, float], b: Mapping[str, float], names: Sequence[str]) -> bool:
    """Whether two designs' objective values agree within :data:`MERGE_TOLERANCE` (relative) in every objective."""
    return all(
        abs(a[name] - b[name]) <= MERGE_TOLERANCE * max(abs(a[name]), abs(b[name]), 1e-300) for name in names
    )


def merge_repeats(
    results: Sequence[DesignResult], names: Sequence[str]
) -> tuple[list[DesignResult], list[DesignResult]]:
    """Drop the results that repeat an earlier one (:func:`same_point`): ``(kept, merged)``, order kept."""
    kept: list[DesignResult] = []
    merged: list[DesignResult] = []
    for result in results:
        repeat = any(same_point(result.numpy_objectives, k.numpy_objectives, names) for k in kept)
        (merged if repeat else kept).append(result)
    return kept, merged


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
