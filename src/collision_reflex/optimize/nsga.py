"""Cross-check of the epsilon-constraint Pareto sweep with a black-box genetic algorithm (pymoo's NSGA-II).

Optional: needs the ``pymoo`` extra (``pip install "collision-reflex[pymoo]"``). It evaluates designs through the
NumPy path only (no derivatives), so it is independent of the CasADi model and of IPOPT.
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import CollisionReflexError, InvalidParameter
from .design import design_at
from .evaluate import evaluate_design
from .objectives import OBJECTIVES, objective_values
from .problem import DesignProblem


@dataclass(frozen=True)
class GeneticFront:
    """Non-dominated designs found by NSGA-II.

    objectives: the objective names; values: (n, n_objectives) their values [units of :data:`OBJECTIVES`];
    designs: (n, n_design) the log design variables; evaluations: how many designs were evaluated;
    total_time: wall time [s].
    """

    objectives: tuple[str, ...]
    values: np.ndarray
    designs: np.ndarray
    evaluations: int
    total_time: float


def nsga2_front(
    problem: DesignProblem,
    objectives: Sequence[str] = ("worst_case_impulse", "actuator_mass"),
    population: int = 100,
    generations: int = 200,
    seed: int = 0,
) -> GeneticFront:
    """Run NSGA-II on the design variables of ``problem`` (log space, same bounds) with its torque constraint.

    Parameters
    ----------
    problem: a problem from :func:`collision_reflex.build_problem` (its objective is not used).
    objectives: objective names to minimise (maximised ones are negated internally, reported as is).
    population, generations: NSGA-II settings.
    seed: random seed, for reproducible fronts.

    Raises
    ------
    InvalidParameter: a problem built with a duty cycle (this cross-check knows the static requirement only).
    """
    if problem.duty is not None:
        raise InvalidParameter(
            "problem",
            problem.requirement,
            "a problem with the static torque requirement",
            "the NSGA-II cross-check does not model a duty cycle's RMS and speed constraints",
        )

    try:
        from pymoo.algorithms.moo.nsga2 import NSGA2
        from pymoo.core.problem import ElementwiseProblem
        from pymoo.optimize import minimize
    except ImportError:  # pragma: no cover - depends on the environment
        raise CollisionReflexError(
            "the NSGA-II cross-check needs pymoo: pip install 'collision-reflex[pymoo]'"
        ) from None

    names = tuple(objectives)
    senses = np.array([OBJECTIVES[name][0] for name in names], dtype=float)
    lower, upper, _ = problem.layout.log_bounds()

    def evaluate(z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        design = design_at(problem, z)
        impulses = evaluate_design(problem, design)
        values = objective_values(
            impulses, design.actuator_mass.sum(), design.approach_velocity, problem.samples
        )
        required = np.asarray(problem.required_torque_function(design.actuator_mass)).ravel()
        # pymoo's convention: constraint values <= 0 are satisfied.
        return np.array([values[n] for n in names]) * senses, required - design.driving_peak_torque

    class _Design(ElementwiseProblem):
        def __init__(self) -> None:
            super().__init__(
                n_var=lower.size, n_obj=len(names), n_ieq_constr=problem.n_joints, xl=lower, xu=upper
            )

        def _evaluate(self, z: np.ndarray, out: dict[str, Any], *args: Any, **kwargs: Any) -> None:
            out["F"], out["G"] = evaluate(z)

    started = time.perf_counter()
    result = minimize(_Design(), NSGA2(pop_size=population), ("n_gen", generations), seed=seed, verbose=False)
    if result.F is None:
        raise CollisionReflexError("NSGA-II found no design that meets the torque requirement")
    values = np.atleast_2d(result.F) * senses
    return GeneticFront(
        names,
        values,
        np.atleast_2d(result.X),
        int(result.algorithm.evaluator.n_eval),
        time.perf_counter() - started,
    )
