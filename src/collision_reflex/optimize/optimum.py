"""The optimum of one objective, multi-started, run, saved and found again like a piece of a sweep."""

from __future__ import annotations

from collections.abc import Hashable

import numpy as np

from ..errors import SolverFailed
from .design_result import DesignResult
from .ipopt import IpoptOptions
from .pieces import ProblemBuilder, check_active_set, one_at_a_time, solved_point
from .results import SweepPoint
from .sweep import Runner, check_count

OPTIMUM_STARTS = 4
"""Start points of the single-objective solve by default: the given start and three seeded random ones (see
:func:`collision_reflex.optimize.solve.solve`), against local optima of the non-convex worst case. Each start is
screened at a loose tolerance and only those on distinct central paths are finished: fewer iterations than
finishing every start, for the same optimum."""


def single_optimum(
    build: ProblemBuilder,
    objective: Hashable,
    ipopt_options: IpoptOptions | None = None,
    *,
    runner: Runner | None = None,
    starts: int = OPTIMUM_STARTS,
    active_set: str = "auto",
    x0: np.ndarray | None = None,
    initial: np.ndarray | None = None,
) -> tuple[DesignResult, bool]:
    """The optimum of one objective (a name, or what ``build`` takes for a weighted one).

    It is run, saved and found again like a piece of :func:`~.pareto.pareto_front`, as ``runner`` says (its
    name: ``optimum``, or ``optimum-<starts>-starts``; default in this process, nothing kept). ``starts``:
    start points of the solve (multi-start, seeded: see :func:`collision_reflex.optimize.solve.solve`; on an
    active set each start settles its own); ``active_set``: as :func:`~.pareto.pareto_front`; ``x0`` and
    ``initial``: the first start's point and first active samples, as :func:`~.pieces.solve_with` takes them.
    Returns the result and whether it was found finished.

    Raises
    ------
    SolverFailed: every start failed.
    """
    check_count("starts", starts, 1)
    check_active_set(build, active_set)
    name = "optimum" if starts == 1 else f"optimum-{starts}-starts"
    pieces = (runner or Runner()).schedule(1)
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
    ``active_set``, ``x0`` and ``initial``: see :func:`~.pieces.solve_with`.
    """
    return solved_point(
        "optimum",
        build,
        objective,
        (),
        active_set,
        x0=x0,
        ipopt_options=ipopt_options,
        starts=starts,
        initial=initial,
    )
