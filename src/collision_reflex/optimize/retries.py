"""Solve a :class:`DesignProblem` from one start: IPOPT, its retries, then a feasibility solve that decides.

A failed run is retried as :data:`RETRIES` says; when every retry fails, an elastic feasibility solve
(:mod:`.feasibility`) either confirms that no design meets the constraints (raised, naming them and what to
change) or finds a feasible point for a last attempt.
"""

from __future__ import annotations

import time
from collections.abc import Mapping

import numpy as np

from .. import _validate
from .._interrupt import interruptible
from ..errors import InvalidParameter, SolverFailed, Violation
from .design_result import DesignResult, design_result
from .feasibility import solve_feasibility
from .ipopt import DEFAULT_IPOPT_OPTIONS, WARM_START_OPTIONS, Attempt, Found, IpoptOptions, IpoptRuns
from .problem import DesignProblem

RETRIES = (
    # Another barrier strategy from the same start: the monotone barrier's parameter can reach ~1e-9 before
    # convergence, after which IPOPT's restoration phase may wrongly report infeasibility.
    ("adaptive barrier", {"ipopt.mu_strategy": "adaptive"}, "start"),
    # The problem's own start: the log-midpoint design with the gear ratios raised to cover the torques.
    ("default start, adaptive barrier", {"ipopt.mu_strategy": "adaptive"}, "default"),
)
"""What :func:`solve_start` tries after a failed run, in order: (name, options merged over the requested ones,
start). After these, an elastic feasibility solve (:mod:`.feasibility`) decides: infeasible (raised) or a
feasible point, from which a last attempt (``"feasible start, adaptive barrier"``) starts."""


@interruptible()  # each start of a multi-start: a lost Ctrl-C ends it, not only the whole solve
def solve_start(
    problem: DesignProblem,
    epsilon: Mapping[str, float] | None,
    x0: np.ndarray | DesignResult | None,
    ipopt_options: IpoptOptions | None,
    *,
    retry: bool = True,
) -> DesignResult:
    """Solve ``problem`` from ``x0`` (a point, a neighbouring result to warm-start from, or None: its own start).

    ``epsilon`` checked, ``ipopt_options`` merged over :data:`.ipopt.DEFAULT_IPOPT_OPTIONS`; ``retry`` as
    :func:`collision_reflex.optimize.solve` says.
    """
    warm = x0.multipliers if isinstance(x0, DesignResult) else None
    start = np.clip(start_point(problem, x0), problem.lbx, problem.ubx)
    requested = {**DEFAULT_IPOPT_OPTIONS, **(ipopt_options or {})}
    attempts = IpoptRuns(problem, problem.parameters(epsilon))
    found = attempts.run("requested", {**requested, **(WARM_START_OPTIONS if warm else {})}, start, warm)
    tried = set() if warm else {(repr(sorted(requested.items())), start.tobytes())}
    if found is None and not retry:
        status = attempts.records[-1].status
        raise SolverFailed(
            f"IPOPT stopped with {status} after {attempts.records[-1].iterations} iterations (a step without "
            "retries: its start is kept)",
            status,
            attempts.last_stats,
            [],
            problem,
            attempts.records,
        )
    for name, change, where in RETRIES if found is None else ():
        options = {**requested, **change}
        retry_start = start if where == "start" else np.clip(problem.x0, problem.lbx, problem.ubx)
        key = (repr(sorted(options.items())), retry_start.tobytes())
        if key not in tried:
            tried.add(key)
            found = attempts.run(name, options, retry_start)
            if found is not None:
                break
    if found is None:
        found = _decide(problem, dict(epsilon or {}), {**requested, **RETRIES[0][1]}, attempts)
    x, stats, multipliers = found
    return design_result(problem, x, tuple(attempts.records), stats, dict(epsilon or {}), multipliers)


def _decide(
    problem: DesignProblem, epsilon: dict[str, float], options: dict[str, str | float], attempts: IpoptRuns
) -> Found:
    """After every retry failed: a feasibility solve, then either infeasible (raised) or a last attempt.

    Raises
    ------
    SolverFailed: ``"Infeasible"`` when the feasibility solve confirms it; otherwise the last attempt's
        status, the problem being feasible (or, if the feasibility solve failed too, undecided).
    """
    started = time.perf_counter()
    verdict = solve_feasibility(problem, problem.x0, attempts.parameters, options, epsilon)
    attempts.records.append(
        Attempt("feasibility", verdict.status, verdict.iterations, time.perf_counter() - started)
    )
    design_status = next(a.status for a in reversed(attempts.records) if a.name != "feasibility")
    if verdict.converged and not verdict.feasible:
        what = "; ".join(_shortfall(v) for v in verdict.violations[:3])
        raise SolverFailed(
            f"no design within the bounds meets the constraints (confirmed by a feasibility solve): {what}. "
            + _advice(verdict.violations),
            "Infeasible",
            attempts.last_stats,
            list(verdict.violations),
            problem,
            attempts.records,
        )
    if verdict.feasible:
        found = attempts.run("feasible start, adaptive barrier", options, verdict.x)
        if found is not None:
            return found
        design_status = attempts.records[-1].status
    tried = ", ".join(f"{a.name}: {a.status} after {a.iterations} iterations" for a in attempts.records)
    decided = (
        "a feasibility solve found a design that meets every constraint"
        if verdict.feasible
        else "the feasibility solve did not converge either, so feasibility is undecided"
    )
    raise SolverFailed(
        f"the optimiser did not converge ({tried}); {decided}. Raise ipopt.max_iter, try more start points "
        "(starts), or narrow the bounds.",
        design_status,
        attempts.last_stats,
        list(verdict.violations),
        problem,
        attempts.records,
    )


def _shortfall(violation: Violation) -> str:
    """``peak torque of joint1 >= the given required torque: not met by 49.1 N*m``."""
    unit = "" if violation.unit == "-" else f" {violation.unit}"
    return f"{violation.label}: not met by {violation.amount:.3g}{unit}"


ADVICE = {
    "peak torque": "raise the upper bounds of the gear ratio or the motor size, or lower the payload, the "
    "safety factor or the given torques",
    "within its bound": "relax the objective bounds",
    "noise floor": "lower the threshold floor or raise the threshold's upper bound",
    "RMS torque": "raise the upper bound of the motor size or shorten the duty cycle's loads",
    "motor speed": "lower the upper bound of the gear ratio or slow the duty cycle",
    "gearbox": "choose a gearbox of a higher torque (or speed) rating, or lower the payload, the safety factor "
    "or the given torques",
}
"""What to do about each kind of constraint that cannot be met (found in its label)."""


def _advice(violations: tuple[Violation, ...]) -> str:
    """What to change, for the kinds of constraints in ``violations``."""
    hints = [hint for key, hint in ADVICE.items() if any(key in v.label for v in violations)]
    return ("To meet them: " + "; ".join(hints) + ".") if hints else "Widen the bounds."


def start_point(problem: DesignProblem, x0: np.ndarray | DesignResult | None) -> np.ndarray:
    """The start point in the NLP's variables: ``x0`` (or its point) checked, or the problem's own."""
    if x0 is None:
        return problem.x0
    point = x0.x if isinstance(x0, DesignResult) else x0
    allowed = f"{problem.x0.size} finite numbers (the NLP's variables), a DesignResult, or None"
    array = _validate.real("x0", point, allowed)
    if array.shape != problem.x0.shape or not np.all(np.isfinite(array)):
        raise InvalidParameter("x0", point, allowed)
    return array
