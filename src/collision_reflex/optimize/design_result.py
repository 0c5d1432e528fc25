"""The result of a solve: the design found, every objective by both paths, its margins and how it was found."""

from __future__ import annotations

import warnings
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .constraints import STATIC_REQUIREMENT
from .design import Design, design_at
from .duty import duty_values, margin
from .evaluate import evaluate_design
from .ipopt import Attempt
from .objectives import OBJECTIVES, objective_values
from .problem import DesignProblem

AGREEMENT_TOLERANCE = 1e-6
"""Largest relative difference allowed between the CasADi and NumPy evaluations of a design's objectives:
both evaluate the same closed forms in double precision, so any larger difference is a modelling bug."""


@dataclass(frozen=True)
class DesignResult:
    """An optimised design and how it was found.

    objectives: every objective of :data:`OBJECTIVES` from the CasADi model [its unit].
    numpy_objectives: the same re-evaluated through the NumPy path; the two agree to
        :data:`AGREEMENT_TOLERANCE` (relative).
    impulses: (n_samples,) collision impulse per sample [N*s] (NumPy path).
    required_torque, torque_margin: per joint, the required peak torque [N m] (safety factor included) and
        ``eta peak_torque / required_torque - 1`` (``eta`` the gearbox efficiency, 1 without one).
    requirement: what sized the torques (:attr:`collision_reflex.optimize.Constraints.requirement`), e.g.
        ``"static (gravity only)"``.
    required_rms_torque, rms_margin: per joint, the RMS torque over the duty cycle [N m] and
        ``eta N tau_c / RMS - 1``; None without a duty cycle.
    max_motor_speed, speed_limit, speed_margin: per joint, the motor speed ``N max |qd|`` over the cycle and
        the approach [rad/s], the motor's maximum speed [rad/s] and ``limit / speed - 1``; None without a duty
        cycle.
    status, success, iterations, solve_time [s], build_time [s]: solver statistics: the status and iterations
        of the attempt kept (``"Solved_To_Acceptable_Level"`` marks a point kept at IPOPT's acceptable
        tolerance), the time of every attempt.
    attempts: every IPOPT run of the solve (:class:`Attempt`), the kept one last; more than one means retries.
    """

    design: Design
    objectives: dict[str, float]
    numpy_objectives: dict[str, float]
    impulses: np.ndarray
    required_torque: np.ndarray
    torque_margin: np.ndarray
    status: str
    success: bool
    iterations: int
    solve_time: float
    build_time: float
    epsilon: dict[str, float] = field(default_factory=dict)
    requirement: str = STATIC_REQUIREMENT
    required_rms_torque: np.ndarray | None = None
    rms_margin: np.ndarray | None = None
    max_motor_speed: np.ndarray | None = None
    speed_limit: np.ndarray | None = None
    speed_margin: np.ndarray | None = None
    x: np.ndarray = field(default_factory=lambda: np.empty(0), repr=False)
    multipliers: tuple[np.ndarray, np.ndarray] | None = field(default=None, repr=False)
    attempts: tuple[Attempt, ...] = ()

    @property
    def worst_sample(self) -> int:
        """Index of the sample with the largest impulse."""
        return int(np.argmax(self.impulses))


def design_result(
    problem: DesignProblem,
    x: np.ndarray,
    attempts: tuple[Attempt, ...],
    stats: dict,
    epsilon: dict[str, float],
    multipliers: tuple[np.ndarray, np.ndarray],
) -> DesignResult:
    """The result at ``x``, found by the last of ``attempts`` (IPOPT's ``stats``), all timed."""
    design = design_at(problem, x)
    evaluated = problem.evaluate(problem.exact_point(x))
    objectives = objective_values(evaluated[0], evaluated[1], evaluated[2], problem.samples)
    numpy_impulses = evaluate_design(problem, design)
    numpy_objectives = objective_values(
        numpy_impulses, design.actuator_mass.sum(), design.approach_velocity, problem.samples
    )
    check_agreement(objectives, numpy_objectives, OBJECTIVES)
    required = np.asarray(evaluated[4]).ravel()
    duty: dict[str, Any] = {}
    if problem.duty is not None:
        values = duty_values(problem.duty, design, problem.technology)
        duty = {
            "required_rms_torque": values.required_rms_torque,
            "rms_margin": margin(values.continuous_torque, values.required_rms_torque),
            "max_motor_speed": values.max_motor_speed,
            "speed_limit": values.speed_limit,
            "speed_margin": margin(values.speed_limit, values.max_motor_speed),
        }
    return DesignResult(
        design=design,
        objectives=objectives,
        numpy_objectives=numpy_objectives,
        impulses=numpy_impulses,
        required_torque=required,
        torque_margin=design.driving_peak_torque / np.maximum(required, 1e-300) - 1,
        status=attempts[-1].status,
        success=True,
        iterations=int(stats.get("iter_count", -1)),
        solve_time=sum(attempt.solve_time for attempt in attempts),
        build_time=problem.build_time,
        epsilon=epsilon,
        requirement=problem.requirement,
        **duty,
        x=x,
        multipliers=multipliers,
        attempts=attempts,
    )


def check_agreement(
    objectives: Mapping[str, float], numpy_objectives: Mapping[str, float], names: Iterable[str]
) -> None:
    """Warn of each objective in ``names`` whose CasADi and NumPy values differ beyond the tolerance.

    :data:`AGREEMENT_TOLERANCE` (relative): both evaluate the same closed forms, so a larger difference is a
    modelling bug.
    """
    for name in names:
        a, b = objectives[name], numpy_objectives[name]
        if abs(a - b) > AGREEMENT_TOLERANCE * max(abs(a), abs(b)):
            warnings.warn(
                f"CasADi and NumPy evaluations of {name} differ: {a!r} vs {b!r}", RuntimeWarning, stacklevel=4
            )
