"""An arm study's results as plain data (``designs.json``).

The record holds the chosen design (the single-objective optimum as solved), the recommended design and why,
the Pareto front as the optimiser decided it, the bounds the designs were solved within, the torque
requirement's kind, and where each contact sample comes from. With a duty cycle, the recommended design
also holds its torque-speed data (``recommended.torque_speed``, :func:`torque_speed_record`).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, TypedDict

import numpy as np

from ..optimize.duty import torque_speed_points
from ..optimize.pareto import MERGE_TOLERANCE, built_problem, recommend
from ..optimize.results import design_record
from ..optimize.space import GLOBAL_VARIABLES, PER_JOINT_VARIABLES
from .arm_setup import ArmSetup, SampleLayout, StudyProblems, sample_layout

if TYPE_CHECKING:
    from ..optimize import DesignProblem, DesignResult, ParetoSet

SAVED_DIGITS = 7
"""Significant digits of the saved torque-speed data: compact, and within 5e-7 relative of the computed points."""


class ParetoRecord(TypedDict):
    """The Pareto front as plain data: objective names, designs on the front, failed points, dominated designs.

    Each design is a :func:`collision_reflex.optimize.results.design_record`; each failure a
    :meth:`collision_reflex.optimize.results.PointFailure.as_dict`; ``merged``: solved points dropped as
    repeats of a reported one (objectives equal within the solver tolerance).
    """

    objectives: list[str]
    points: list[dict[str, Any]]
    failed: list[dict[str, Any]]
    dominated: list[dict[str, Any]]
    merged: int


class ArmResults(TypedDict):
    """An arm study's own part of ``designs.json``.

    The samples, the chosen and recommended designs, the Pareto front, the bounds of the design variables
    (``{variable: {joint: [lower, upper]}}`` and ``{threshold|approach_velocity: [lower, upper]}``, SI units)
    the kind of torque requirement (:attr:`collision_reflex.optimize.Constraints.requirement`) and, with a duty
    cycle, where the motors' speed limits come from.
    """

    samples: SampleLayout
    chosen: dict[str, Any]
    recommended: dict[str, Any]
    pareto: ParetoRecord
    bounds: dict[str, Any]
    requirement: str
    speed_limits: str | None


class JointTorqueSpeed(TypedDict):
    """One joint's saved torque-speed data, motor side, named as :class:`~collision_reflex.plots.torque_speed.JointOperatingPoints`'s fields.

    ``speed`` [rad/s] and ``torque`` [N*m]: the duty cycle's motor speed ``N qd(t)`` and torque ``d(t) / N``
    (signed, no safety factor); ``approach_speed`` [rad/s]: the approach's motor speed at each contact sample;
    the envelope ``peak_torque`` and ``continuous_torque`` [N*m] and ``max_speed`` [rad/s] (None when the
    catalogue gives none); ``rms_torque`` [N*m]: the cycle's RMS motor torque. Rounded to
    :data:`SAVED_DIGITS` significant digits.
    """

    joint: str
    speed: list[float]
    torque: list[float]
    approach_speed: list[float]
    peak_torque: float
    continuous_torque: float
    max_speed: float | None
    rms_torque: float


def _rounded(values: Any) -> list[float]:
    """``values`` flattened to floats rounded to :data:`SAVED_DIGITS` significant digits."""
    return [float(f"{v:.{SAVED_DIGITS}g}") for v in np.asarray(values, dtype=float).ravel()]


def torque_speed_record(problem: DesignProblem, result: DesignResult) -> list[JointTorqueSpeed] | None:
    """Per joint, a design's motor-side torque-speed data for the report's figure; None without a duty cycle.

    The points are :func:`collision_reflex.optimize.duty.torque_speed_points`; the envelope is the scaled
    motor's (:func:`collision_reflex.hardware.motors.scaled_motor_quantities`); the RMS motor torque is the
    record's joint-side RMS divided by the gear ratio and the gearbox efficiency.
    """
    if problem.duty is None or result.required_rms_torque is None:
        return None
    design = result.design
    technology = problem.technology
    motor = technology.motor_quantities(design.stator_diameter, design.stack_length)
    n = len(design.joint_names)
    continuous = np.broadcast_to(np.asarray(motor.continuous_torque, dtype=float), (n,))
    max_speed = None if motor.max_speed is None else np.broadcast_to(np.asarray(motor.max_speed, float), (n,))
    rms_torque = np.asarray(result.required_rms_torque, dtype=float) / (
        design.gearbox_efficiency * design.gear_ratio
    )
    out: list[JointTorqueSpeed] = []
    for j, (name, points) in enumerate(
        zip(design.joint_names, torque_speed_points(problem, design), strict=True)
    ):
        out.append(
            {
                "joint": name,
                "speed": _rounded(points.cycle_speed),
                "torque": _rounded(points.cycle_torque),
                "approach_speed": _rounded(points.approach_speed),
                "peak_torque": _rounded(design.motor_peak_torque[j])[0],
                "continuous_torque": _rounded(continuous[j])[0],
                "max_speed": None if max_speed is None else _rounded(max_speed[j])[0],
                "rms_torque": _rounded(rms_torque[j])[0],
            }
        )
    return out


def design_bounds(setup: ArmSetup) -> dict[str, Any]:
    """The bounds every design of the study was solved within, as plain data [SI units]."""
    joints = list(setup.arm.joint_names)
    space = setup.space
    defaults = {"stack_length": setup.technology.default_stack_lengths(len(joints))}
    out: dict[str, Any] = {}
    for name in PER_JOINT_VARIABLES:
        bounds = space.per_joint(name, len(joints), defaults.get(name))
        out[name] = {j: [b.lower, b.upper] for j, b in zip(joints, bounds, strict=True)}
    for name in GLOBAL_VARIABLES:
        one = space.global_bounds(name)
        out[name] = [one.lower, one.upper]
    return out


def arm_results(problems: StudyProblems, chosen: DesignResult, front: ParetoSet | None) -> ArmResults:
    """``samples``, ``chosen``, ``recommended``, ``pareto``, ``bounds`` and ``requirement`` of an arm study.

    The chosen design (the optimum of the study's objective, as solved) records ``dominated_by``: the index of
    a Pareto design that dominates it, or None. The recommended design
    (:func:`collision_reflex.optimize.pareto.recommend`) records ``source`` (``optimum`` or ``Pareto design
    <i>``), ``pareto_index`` and ``reason``, and with a duty cycle its ``torque_speed``
    (:func:`torque_speed_record`).
    """
    setup = problems.setup
    # Every problem of a study shares its samples and technology: one of them evaluates every record.
    problem = built_problem(problems, problems.objective)

    def record(result: DesignResult, label: str) -> dict[str, Any]:
        return design_record(problem, result, label, setup.catalogue)

    pareto: ParetoRecord = {"objectives": [], "points": [], "failed": [], "dominated": [], "merged": 0}
    chosen_record = record(chosen, "optimum")
    chosen_record["dominated_by"] = None
    if front is not None:
        pareto = {
            "objectives": list(front.objectives),
            "points": [record(r, label) for r, label in zip(front.points, front.labels, strict=True)],
            "failed": [failure.as_dict() for failure in front.failed],
            "dominated": [
                record(r, label) for r, label in zip(front.dominated, front.dominated_labels, strict=True)
            ],
            "merged": front.merged,
        }
        # The recommendation's rule: values within the solver tolerance count as equal.
        chosen_record["dominated_by"] = front.dominating(chosen.numpy_objectives, MERGE_TOLERANCE)
    recommendation = recommend(chosen, front, problems.objective)
    recommended = (
        dict(pareto["points"][recommendation.pareto_index])
        if recommendation.pareto_index is not None
        else {k: v for k, v in chosen_record.items() if k != "dominated_by"}
    )
    recommended.update(
        source=recommendation.source, pareto_index=recommendation.pareto_index, reason=recommendation.reason
    )
    torque_speed = torque_speed_record(problem, recommendation.result)
    if torque_speed is not None:
        recommended["torque_speed"] = torque_speed
    return {
        "samples": sample_layout(setup),
        "chosen": chosen_record,
        "recommended": recommended,
        "pareto": pareto,
        "bounds": design_bounds(setup),
        "requirement": setup.constraints.requirement,
        "speed_limits": speed_limits(setup),
    }


def speed_limits(setup: ArmSetup) -> str | None:
    """Where the motors' speed limits come from, for the report (None without a duty cycle, which uses none)."""
    from ..hardware.motors import scaling_law

    if setup.constraints.duty_cycle is None:
        return None
    motor = setup.technology.motors[0]
    law = scaling_law(setup.technology.scaling_law).speed
    return (
        f"Speed limits: the reference motor {motor.name} turns at most {motor.max_speed:.4g} rad/s (its "
        f"catalogue entry gives the source, or the method where the figure is an estimate); a scaled motor's "
        f"limit follows omega_max ∝ (l/l0)^{law.length_exponent:g} (r/r0)^{law.diameter_exponent:g}. "
        f"{law.source}"
    )
