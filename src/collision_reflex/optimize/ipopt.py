"""IPOPT for a :class:`DesignProblem`: its options, and its runs, each recorded as an :class:`Attempt`."""

from __future__ import annotations

import time
from collections.abc import Mapping
from typing import NamedTuple

import numpy as np

from .blas import single_threaded_blas
from .problem import DesignProblem

IpoptOptions = Mapping[str, str | float]
"""Options of CasADi's ``nlpsol`` with IPOPT (``"ipopt.<option>"`` and CasADi's own): strings, numbers, flags."""

DEFAULT_IPOPT_OPTIONS: dict[str, str | float] = {
    # For an NLP that CasADi differentiates itself (the feasibility solve): expanding its MX graph (mapped
    # per-sample functions) to SX makes every derivative evaluation much cheaper. The
    # design solvers get SX functions assembled per sample (DesignProblem.solver), nothing to expand.
    "expand": True,
    "ipopt.print_level": 0,
    "ipopt.sb": "yes",
    "print_time": False,
    "ipopt.tol": 1e-8,
    "ipopt.max_iter": 500,
    # Monotone barrier from mu = 1e-2: on arm problems (benchmarks/optimize_panda.py's) fewer iterations than
    # the adaptive strategy, to the same optimum.
    "ipopt.mu_strategy": "monotone",
    "ipopt.mu_init": 1e-2,
    "ipopt.linear_solver": "mumps",
    # No scaling of the KKT matrix by MUMPS (neither its row and column scaling nor its permuting scaling):
    # with its default (automatic) choice the KKT matrices of the UR5 study's fast points needed delayed
    # pivots, far more memory than MUMPS estimates and slow iterations; its option 8 avoids that, and without
    # scaling the iterations and optimum are those of option 8 again, in less CPU.
    "ipopt.mumps_scaling": 0,
    "ipopt.mumps_permuting_scaling": 0,
    # METIS ordering (MUMPS chose QAMD): on the Panda benchmark the same iterations and optimum in less IPOPT
    # time, most of which is MUMPS's factorizations (the inertia correction refactorizes), and on the UR5
    # study's sweep alike. Skipping the residual check of each step (fast_step_computation) saved more time on
    # the Panda but cost the UR5 sweep iterations.
    "ipopt.mumps_pivot_order": 5,
}
WARM_START_OPTIONS: dict[str, str | float] = {
    # Start from a neighbouring solution's primal and dual point, close to the central path.
    "ipopt.warm_start_init_point": "yes",
    "ipopt.warm_start_bound_push": 1e-6,
    "ipopt.warm_start_mult_bound_push": 1e-6,
    "ipopt.mu_init": 1e-4,
    # From a solution's multipliers the adaptive barrier needs fewer iterations than the monotone one (the
    # Panda benchmark's epsilon points from the anchor).
    "ipopt.mu_strategy": "adaptive",
}
CONVERGED = ("Solve_Succeeded", "Solved_To_Acceptable_Level")
"""IPOPT statuses whose point is kept; the status is kept in the result (an acceptable point is marked)."""
INTERRUPTED = "NonIpopt_Exception_Thrown"
"""IPOPT's status when CasADi caught an exception in a callback (Ctrl-C among them)."""

Found = tuple[np.ndarray, dict, tuple[np.ndarray, np.ndarray]]
"""A converged run: the point, IPOPT's statistics, the multipliers (bounds, constraints)."""


class Attempt(NamedTuple):
    """One IPOPT run of :func:`.solve.solve`: its name (see :data:`.retries.RETRIES`), status, iterations and time [s]."""

    name: str
    status: str
    iterations: int
    solve_time: float


class IpoptRuns:
    """The IPOPT runs of one solve: runs each (the problem's solver for its options, built once) and records it."""

    def __init__(self, problem: DesignProblem, parameters: np.ndarray) -> None:
        self.problem = problem
        self.parameters = parameters
        self.records: list[Attempt] = []
        self.last_stats: dict = {}

    def run(
        self,
        name: str,
        options: dict[str, str | float],
        start: np.ndarray,
        warm: tuple[np.ndarray, np.ndarray] | None = None,
    ) -> Found | None:
        """Run IPOPT from ``start`` (warm-started from the multipliers ``warm``); None if it did not converge."""
        problem = self.problem
        solver = problem.solver(options)
        multipliers = {} if warm is None else {"lam_x0": warm[0], "lam_g0": warm[1]}
        started = time.perf_counter()
        with single_threaded_blas():
            solution = solver(
                x0=start,
                lbx=problem.lbx,
                ubx=problem.ubx,
                lbg=problem.lbg,
                ubg=problem.ubg,
                p=self.parameters,
                **multipliers,
            )
        stats = dict(solver.stats())
        status = str(stats.get("return_status", "unknown"))
        if status == INTERRUPTED:
            raise KeyboardInterrupt  # CasADi caught Ctrl-C: stop the solve, never retry or record it
        iterations = int(stats.get("iter_count", -1))
        self.records.append(Attempt(name, status, iterations, time.perf_counter() - started))
        self.last_stats = stats
        if status not in CONVERGED:
            return None
        lam = (np.asarray(solution["lam_x"]).ravel(), np.asarray(solution["lam_g"]).ravel())
        return np.asarray(solution["x"]).ravel(), stats, lam
