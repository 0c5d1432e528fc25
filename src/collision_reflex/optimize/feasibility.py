"""Decide whether a :class:`DesignProblem` has a feasible design, and say what cannot be met and by how much.

IPOPT's own infeasibility verdict comes from its restoration phase, which can fail on feasible problems (the
barrier parameter small, far from the feasible set). The feasibility solve here is an elastic problem that is
always feasible: every constraint row gets non-negative slacks,

    minimise sum(s_low + s_high)  subject to  lbg <= g(x) + s_low - s_high <= ubg,  lbx <= x <= ubx,

with the design's bounds kept hard. Its minimum is zero exactly when the design problem is feasible; a
positive minimum confirms infeasibility, and the slacks left at the end say which constraints cannot be met.
The rows are in the NLP's scaled units (each divided by a requirement or a bound), so the slacks compare;
:func:`physical_violations` turns the violated rows back into their physical units.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import casadi as ca
import numpy as np

from ..errors import Violation
from .design import design_at
from .duty import duty_values
from .objectives import OBJECTIVES, objective_values
from .problem import DesignProblem

FEASIBLE_VIOLATION = 1e-6
"""Largest total slack [-] (sum over the NLP's scaled rows, each about 1 at the requirement) of a feasibility
solve that still counts as feasible: IPOPT meets its constraints to about 1e-8 at convergence, so a larger
remainder is a constraint that cannot be met, not round-off."""

OBJECTIVE_UNITS = {
    "worst_case_impulse": "N*s",
    "mean_impulse": "N*s",
    "cvar_impulse": "N*s",
    "actuator_mass": "kg",
    "approach_velocity": "m/s",
}
"""The unit of each objective of :data:`OBJECTIVES`, for the violated bounds on them."""


@dataclass(frozen=True)
class Feasibility:
    """The end of a feasibility solve.

    x: the NLP point reached (auxiliaries at their exact values); total_violation: the sum of the slacks left
    [-, scaled rows]; feasible: whether it is below :data:`FEASIBLE_VIOLATION`; status and iterations: IPOPT's;
    converged: whether IPOPT converged (a verdict is only as good as the solve); violations: the violated
    constraints at ``x`` in their physical units, worst (in scaled terms) first.
    """

    x: np.ndarray
    total_violation: float
    feasible: bool
    status: str
    iterations: int
    converged: bool
    violations: tuple[Violation, ...]


def feasibility_solver(problem: DesignProblem, options: Mapping[str, str | float]) -> ca.Function:
    """The elastic feasibility solver of ``problem`` for IPOPT ``options``, built once and kept with it.

    Its variables are the NLP's ``x`` followed by the slacks ``s_low`` and ``s_high`` (one each per row of
    ``g``); its parameters those of the NLP (the objective bounds).
    """
    key = "feasibility " + repr(sorted(options.items()))
    solver = problem._solvers.get(key)
    if solver is None:
        rows = ca.Function("rows", [problem.nlp["x"], problem.nlp["p"]], [problem.nlp["g"]])
        n_x, n_g = problem.nlp["x"].shape[0], problem.lbg.size
        x = ca.MX.sym("x", n_x)
        low, high = ca.MX.sym("s_low", n_g), ca.MX.sym("s_high", n_g)
        p = ca.MX.sym("p", problem.nlp["p"].shape[0])
        nlp = {
            "x": ca.vertcat(x, low, high),
            "f": ca.sum1(low) + ca.sum1(high),
            "g": rows(x, p) + low - high,
            "p": p,
        }
        solver = ca.nlpsol("actuator_feasibility", "ipopt", nlp, dict(options))
        problem._solvers[key] = solver
    return solver


def solve_feasibility(
    problem: DesignProblem,
    start: np.ndarray,
    parameters: np.ndarray,
    options: Mapping[str, str | float],
    epsilon: Mapping[str, float],
) -> Feasibility:
    """Minimise the total constraint violation from ``start`` (an NLP point) under the objective bounds.

    ``parameters`` are the NLP's (:meth:`DesignProblem.parameters` of ``epsilon``, the bounds [their units]).
    The slacks start where the start point's rows put them, so the elastic problem starts feasible.
    """
    solver = feasibility_solver(problem, options)
    start = problem.exact_point(np.clip(start, problem.lbx, problem.ubx))
    low0, high0 = problem.row_excess(start, parameters)
    n_g = problem.lbg.size
    # A slack on a side without a bound would only loosen nothing: it is fixed at zero.
    low_upper = np.where(np.isfinite(problem.lbg), np.inf, 0.0)
    high_upper = np.where(np.isfinite(problem.ubg), np.inf, 0.0)
    solution = solver(
        x0=np.concatenate([start, low0, high0]),
        lbx=np.concatenate([problem.lbx, np.zeros(2 * n_g)]),
        ubx=np.concatenate([problem.ubx, low_upper, high_upper]),
        lbg=problem.lbg,
        ubg=problem.ubg,
        p=parameters,
    )
    stats = solver.stats()
    status = str(stats.get("return_status", "unknown"))
    x = problem.exact_point(np.asarray(solution["x"]).ravel()[: problem.lbx.size])
    violation = np.maximum(*problem.row_excess(x, parameters))
    total = float(violation.sum())
    return Feasibility(
        x=x,
        total_violation=total,
        feasible=total <= FEASIBLE_VIOLATION,
        status=status,
        iterations=int(stats.get("iter_count", -1)),
        converged=bool(stats.get("success", False)) or status == "Solved_To_Acceptable_Level",
        violations=physical_violations(problem, x, violation, epsilon),
    )


def physical_violations(
    problem: DesignProblem, x: np.ndarray, violation: np.ndarray, epsilon: Mapping[str, float]
) -> tuple[Violation, ...]:
    """The violated rows (``violation`` [-] per row, scaled) at ``x`` in their units, worst first, one per kind.

    A torque row gives the joint's shortfall of peak torque below its requirement [N*m]; an objective bound
    its excess over ``epsilon`` [the objective's unit]; the noise floor the threshold's shortfall [m]; the duty
    cycle's RMS torque its excess over the continuous torque [N*m] and its speeds their excess over the
    motor's maximum speed [rad/s]. Other rows (the model's auxiliaries, always satisfiable) keep their scaled
    amount [-].
    """
    evaluated = problem.evaluate(x)
    impulses, thresholds = (np.asarray(evaluated[i]).ravel() for i in (0, 3))
    required, peak = (np.asarray(evaluated[i]).ravel() for i in (4, 5))
    objectives = objective_values(impulses, evaluated[1], evaluated[2], problem.samples)
    duty = None
    if problem.duty is not None:
        duty = duty_values(problem.duty, design_at(problem, x), problem.technology)
    found: dict[str, Violation] = {}
    for row in np.argsort(-violation):
        if violation[row] <= FEASIBLE_VIOLATION / violation.size:
            break
        label = problem.constraint_labels[row]
        joint = next((j for j, name in enumerate(problem.joint_names) if f" of {name} " in label), None)
        kind, amount, unit = label, float(violation[row]), "-"
        if label.startswith("peak torque of") and joint is not None:
            kind, amount, unit = (
                f"peak torque of {problem.joint_names[joint]}",
                required[joint] - peak[joint],
                "N*m",
            )
        elif label.endswith("within its bound"):
            name = label.removesuffix(" within its bound")
            kind, unit = label, OBJECTIVE_UNITS[name]
            amount = OBJECTIVES[name][0] * (objectives[name] - epsilon.get(name, objectives[name]))
        elif label.endswith(">= noise floor"):
            kind, unit = "contact threshold >= noise floor", "m"
            amount = problem.constraints.threshold_floor - float(thresholds.min())
        elif duty is not None and joint is not None and label.startswith("RMS torque"):
            amount = float(duty.required_rms_torque[joint] - duty.continuous_torque[joint])
            kind, unit = f"RMS torque of {problem.joint_names[joint]} <= continuous torque", "N*m"
        elif duty is not None and joint is not None and label.startswith("motor speed"):
            amount = float(duty.max_motor_speed[joint] - duty.speed_limit[joint])
            kind, unit = f"motor speed of {problem.joint_names[joint]} <= its maximum speed", "rad/s"
        found.setdefault(kind, Violation(label, float(amount), unit))
    return tuple(found.values())
