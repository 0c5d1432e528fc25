"""Solve a :class:`DesignProblem` with IPOPT and return the design with every objective and margin."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import replace

import numpy as np

from .. import _validate
from .._interrupt import interruptible
from ..errors import InvalidParameter
from .design_result import DesignResult
from .ipopt import IpoptOptions
from .multistart import multi_start
from .problem import DesignProblem
from .retries import solve_start, start_point


@interruptible()
def solve(
    problem: DesignProblem,
    epsilon: Mapping[str, float] | None = None,
    x0: np.ndarray | DesignResult | None = None,
    ipopt_options: IpoptOptions | None = None,
    starts: int = 1,
    rng: np.random.Generator | None = None,
    *,
    retry: bool = True,
) -> DesignResult:
    """Solve ``problem`` with IPOPT (exact Hessian, MUMPS).

    A failed solve (any status but those of :data:`.ipopt.CONVERGED`: infeasibility detected, restoration failed, the
    iteration cap, ...) is retried as :data:`.retries.RETRIES` says, then an elastic feasibility solve decides whether
    any design meets the constraints: only then is the problem reported infeasible. Each retry reuses the
    problem's solvers (one per set of options, built on first use). ``DesignResult.attempts`` lists the runs.

    Parameters
    ----------
    problem: the NLP (:func:`collision_reflex.optimize.build_problem`).
    epsilon: upper bounds on objectives built as bounded (lower bound for ``approach_velocity``) [their units].
    x0: start point in the NLP's variables, or a neighbouring :class:`DesignResult` of the same problem, whose
        point and multipliers then warm-start IPOPT; default the problem's start point.
    ipopt_options: options merged over :data:`.ipopt.DEFAULT_IPOPT_OPTIONS` (e.g. ``{"ipopt.max_iter": 100}``), and
        under each retry's.
    starts: number of start points (multi-start). The problem is not convex (a worst case over samples) and
        IPOPT finds a local optimum; with ``starts > 1`` it is also started from ``starts - 1`` points drawn
        log-uniformly within the bounds; every start is screened at a loose tolerance and those on distinct
        central paths are finished, the best returned (:func:`.multistart.multi_start`).
    rng: random generator for the extra starts (default ``numpy.random.default_rng(0)``, reproducible).
    retry: False: no retries and no feasibility solve; a failed solve raises :class:`SolverFailed` with its
        status (e.g. ``"Maximum_Iterations_Exceeded"``), for a step that may stop early (a lexicographic
        tie-break).

    Raises
    ------
    SolverFailed: status ``"Infeasible"`` when the feasibility solve confirms that no design within the bounds
        meets the constraints (``violated`` names them, with the shortfall in their units); otherwise the last
        attempt's status, when no attempt converged although the problem is feasible (or undecided).
    """
    epsilon = checked_epsilon(epsilon)
    start_point(problem, x0)  # x0 refused before the other arguments
    if isinstance(starts, bool) or not isinstance(starts, int) or starts < 1:
        raise InvalidParameter("starts", starts, "an integer >= 1")
    if ipopt_options is not None and not isinstance(ipopt_options, Mapping):
        raise InvalidParameter("ipopt_options", ipopt_options, "a mapping of IPOPT option name to value")
    if starts > 1:
        return multi_start(
            problem, epsilon, x0, ipopt_options, starts, rng or np.random.default_rng(0), retry
        )
    return solve_start(problem, epsilon, x0, ipopt_options, retry=retry)


def checked_epsilon(epsilon: Mapping[str, float] | None) -> dict[str, float] | None:
    """``epsilon`` with every bound a finite number; NaN, infinities and non-numbers refused."""
    if epsilon is None:
        return None
    if not isinstance(epsilon, Mapping):
        raise InvalidParameter("epsilon", epsilon, "a mapping of objective name to bound")
    checked = {}
    for name, bound in epsilon.items():
        allowed = "a finite number (leave the objective out for no bound)"
        value = _validate.real(f"epsilon[{name!r}]", bound, allowed)
        if value.ndim or not np.isfinite(value):
            raise InvalidParameter(f"epsilon[{name!r}]", bound, allowed)
        checked[name] = float(value)
    return checked


def warm_start(
    problem: DesignProblem, built: DesignProblem, optimum: DesignResult, x0: np.ndarray
) -> DesignResult:
    """``optimum`` of ``problem`` as a warm start of ``built`` from point ``x0``.

    ``built`` has ``problem``'s samples and auxiliaries, its design variables a subset of ``problem``'s (a
    catalogue problem fixes the motors) and rows matched by label (an objective bound ``problem`` lacks, say).
    The multipliers carried over: of each design variable free in both (by name and joint), of the
    auxiliaries (in the same places after the design variables) and of each row by its label; a row or
    variable ``problem`` does not have starts at zero. Both problems are scaled from their own starts, so the
    multipliers are only near ``built``'s: measured on the shipped studies' catalogue problems, scaling them
    to ``built``'s objective and torque scales saved no iterations.
    """
    assert optimum.multipliers is not None
    bounds, rows = optimum.multipliers
    lam_x = np.zeros(built.x0.size)
    for name, indices in built.layout.slices.items():
        for i, k in zip(indices, problem.layout.slices[name], strict=True):
            if i is not None and k is not None:
                lam_x[i] = bounds[k]
    lam_x[built.layout.size :] = bounds[problem.layout.size :]
    where = {label: k for k, label in enumerate(problem.constraint_labels)}
    lam_g = np.array([rows[where[label]] if label in where else 0.0 for label in built.constraint_labels])
    return replace(optimum, x=x0, multipliers=(lam_x, lam_g))
