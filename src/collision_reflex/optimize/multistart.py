"""Multi-start: a :class:`DesignProblem` solved from many starts, each screened, the distinct optima finished."""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from ..errors import SolverFailed
from .design_result import DesignResult
from .ipopt import DEFAULT_IPOPT_OPTIONS, IpoptOptions
from .problem import DesignProblem
from .retries import solve_start

SCREENING_TOLERANCE = 1e-4
"""IPOPT's ``tol`` for the first run of every start of a multi-start (:func:`multi_start`): the run stops on the
central path, before the barrier's last decreases: on the 4 starts of each shipped study's optimum
(``studies/panda.yaml``, ``studies/ur5.yaml``) a screening run takes far fewer iterations than a start solved
alone to ``tol = 1e-8``, and only the starts on distinct paths are finished from their screened points. A looser ``tol`` (1e-3, 1e-2) changes little, as IPOPT also waits for its absolute complementarity
and constraint-violation tolerances (1e-4 by default). IPOPT's acceptable level at 1e-2, or a cap of 20-40
iterations, saved some of the Panda's iterations but split the UR5's merged paths (more finishes)."""
SAME_PATH_DISTANCE = 1e-3
"""Largest difference of any log design variable (0.1 % of the variable) at which two screened starts count as
one central path, so one optimum. Chosen on both shipped studies' 4 starts: the screened starts that lead to
one optimum lie well within it, and the closest pair seen that leads to different optima lies well beyond
it."""


def multi_start(
    problem: DesignProblem,
    epsilon: Mapping[str, float] | None,
    x0: np.ndarray | DesignResult | None,
    ipopt_options: IpoptOptions | None,
    starts: int,
    rng: np.random.Generator,
    retry: bool = True,
) -> DesignResult:
    """Best optimum over the given (or default) start and ``starts - 1`` random ones.

    Every start first runs to :data:`SCREENING_TOLERANCE`. Starts that stop within
    :data:`SAME_PATH_DISTANCE` of a better screened start's design are on its central path and are not run
    further unless the finish from that better start fails (then the next of its path is finished); every
    other one is finished to the full tolerance from its screened point and multipliers (warm
    start), and the best finished one is returned. So the result is the best of the distinct optima the starts
    lead to, each solved to the full tolerance; two optima whose designs differ by less than 0.1 % count as one.
    """
    n_design = problem.layout.size
    points: list[np.ndarray | DesignResult | None] = [x0]
    for _ in range(starts - 1):
        drawn = problem.x0.copy()
        drawn[:n_design] = rng.uniform(problem.lbx[:n_design], problem.ubx[:n_design])
        points.append(problem.exact_point(drawn))
    requested_tol = float({**DEFAULT_IPOPT_OPTIONS, **(ipopt_options or {})}["ipopt.tol"])
    screening = {**(ipopt_options or {}), "ipopt.tol": max(SCREENING_TOLERANCE, requested_tol)}
    failure: SolverFailed | None = None
    screened: list[tuple[float, DesignResult]] = []
    for point in points:
        try:
            result = solve_start(problem, epsilon, point, screening, retry=retry)
        except SolverFailed as error:
            if error.confirmed_infeasible:  # no design meets the constraints, from any start
                raise
            failure = error
            continue
        screened.append((problem.objective_value(result.x), result))
    screened.sort(key=lambda pair: pair[0])  # stable: a tie keeps the earlier start
    paths: list[list[DesignResult]] = []  # each path's starts, the best screened first
    for _, result in screened:
        path = next(
            (
                p
                for p in paths
                if np.max(np.abs(result.x[:n_design] - p[0].x[:n_design])) <= SAME_PATH_DISTANCE
            ),
            None,
        )
        if path is None:
            paths.append([result])
        else:
            path.append(result)
    best: DesignResult | None = None
    best_value = np.inf
    for path in paths:
        for result in path:  # the path's other starts only if the finish from its best one fails
            if requested_tol < SCREENING_TOLERANCE:
                try:
                    result = solve_start(problem, epsilon, result, ipopt_options, retry=retry)
                except SolverFailed as error:
                    failure = error
                    continue
            value = problem.objective_value(result.x)
            if value < best_value:
                best, best_value = result, value
            break
    if best is None:
        assert failure is not None  # every start failed
        raise failure
    return best
