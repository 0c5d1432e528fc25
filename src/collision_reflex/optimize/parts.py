"""A combination of catalogue parts (one per joint): its design problem, its gear ratios, its quick evaluation.

A combination's problem (:func:`catalogue_problem`) is the continuous one with each joint's motor (and gearbox)
the part's, at the part's own size. Without a re-solve, :func:`evaluate_parts` puts the parts into a continuous
design at the gear ratios that cover the requirement of their own masses (:func:`covering_gear_ratios`) and
says which torque and speed requirements they miss: the quick snap of every Pareto design (each joint's
nearest part, :func:`quick_parts`), and the catalogue search's start.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

import numpy as np

from .._interrupt import interruptible
from .build import build_problem
from .candidates import BOUND_TOLERANCE, CataloguePart, JointCandidates
from .design import Design
from .duty import duty_values
from .evaluate import evaluate_design
from .objectives import objective_values
from .problem import DesignProblem

if TYPE_CHECKING:
    from ..arm.robot import Arm
    from .samples import ContactSamples
    from .technology import ActuatorTechnology

__all__ = [
    "REQUIREMENT_PASSES",
    "PartsEvaluation",
    "catalogue_problem",
    "covering_gear_ratios",
    "evaluate_parts",
    "matched_gear_ratio",
    "quick_parts",
]

REQUIREMENT_PASSES = 4
"""Passes of :func:`evaluate_parts` raising the gear ratios to the requirement of the parts' own masses (it
changes little with the ratio: a few passes settle it)."""


def catalogue_problem(
    problem: DesignProblem,
    parts: Sequence[CataloguePart],
    arm: Arm,
    samples: ContactSamples | None = None,
) -> DesignProblem:
    """``problem`` with each joint's motor the catalogue motor of ``parts`` at its own size.

    Each joint's stator diameter and stack length are fixed at its part's, its gear ratio within the part's
    bounds; the objective, constraints and the other bounds are ``problem``'s, and so are the samples unless
    ``samples`` are given (a subset of them, for an active-set round).
    """
    technology = _parts_technology(problem, parts)
    space = replace(
        problem.space,
        stator_diameter=[p.motor.stator_diameter for p in parts],
        stack_length=[p.motor.stack_length for p in parts],
        gear_ratio=[p.gear_ratio for p in parts],
    )
    return build_problem(
        arm,
        problem.samples if samples is None else samples,
        space,
        technology,
        problem.objective,
        problem.constraints,
        problem.bounded_objectives,
    )


def _parts_technology(problem: DesignProblem, parts: Sequence[CataloguePart]) -> ActuatorTechnology:
    """``problem``'s technology with each joint's motor (and gearbox) the one of ``parts``."""
    chosen = tuple(p.gearbox for p in parts)
    return replace(
        problem.technology,
        reference_motor=tuple(p.motor for p in parts),
        gearboxes=chosen if any(g is not None for g in chosen) else None,
    )


def matched_gear_ratio(part: CataloguePart, design: Design, joint: int) -> float:
    """The gear ratio that gives ``part``'s motor the continuous design's peak output torque, within its bounds.

    ``N = N_c tau_c / tau_p`` (``N_c tau_c`` the continuous joint's peak torque [N*m]), clipped to the part's
    gear-ratio bounds (within its gearbox's ratios): the catalogue design's start, and the ratio of a part
    evaluated without a re-solve.
    """
    wanted = float(design.peak_torque[joint]) / part.motor.peak_torque
    low, high = part.ratio_range
    return float(np.clip(wanted, low, high))


def quick_parts(joints: Sequence[JointCandidates], design: Design) -> tuple[CataloguePart, ...] | None:
    """Each joint's nearest part for a quick snap, None when a joint has none.

    The nearest motor's, and of its offered gear ratios (a gearbox of discrete ratios) the smallest that keeps
    ``design``'s peak output torque, else the largest.
    """
    chosen = []
    for j, joint in enumerate(joints):
        if not joint.parts:
            return None
        motor = joint.parts[0].motor
        own = [p for p in joint.parts if p.motor is motor]
        wanted = float(design.peak_torque[j]) / motor.peak_torque * (1 - BOUND_TOLERANCE)
        chosen.append(
            next((p for p in own if not p.gear_ratio.is_fixed or p.gear_ratio.lower >= wanted), own[-1])
        )
    return tuple(chosen)


def covering_gear_ratios(
    problem: DesignProblem, design: Design, parts: Sequence[CataloguePart]
) -> np.ndarray:
    """Each joint's gear ratio [-] for ``parts`` that covers the requirement of the parts' own masses.

    :func:`matched_gear_ratio`, raised (within the part's bounds) until the driving peak torque covers the
    peak requirement (and with a duty cycle the continuous torque covers the cycle's RMS) of the parts'
    masses and reflected inertias, the rest of the design ``design``'s (fixed ratios are kept).
    """
    parts = tuple(parts)
    technology = _parts_technology(problem, parts)
    gear = np.array([matched_gear_ratio(p, design, j) for j, p in enumerate(parts)])
    ranges = np.array([p.ratio_range for p in parts])
    for _ in range(REQUIREMENT_PASSES):  # heavier parts need more torque: raise the ratio to cover it
        snapped = _parts_design(design, parts, technology, gear)
        required = _required_torque(problem, snapped)
        efficiency = snapped.gearbox_efficiency
        wanted = np.maximum(gear, required / (efficiency * snapped.motor_peak_torque))
        if problem.duty is not None:
            rms = duty_values(problem.duty, snapped, technology).required_rms_torque
            continuous = np.array([p.motor.continuous_torque for p in parts])
            wanted = np.maximum(wanted, rms / (efficiency * continuous))
        if all(p.gear_ratio.is_fixed for p in parts) or np.allclose(wanted, gear, rtol=BOUND_TOLERANCE):
            break
        gear = np.where(
            [p.gear_ratio.is_fixed for p in parts], gear, np.clip(wanted, ranges[:, 0], ranges[:, 1])
        )
    return gear


@dataclass(frozen=True)
class PartsEvaluation:
    """A design of catalogue parts evaluated without a re-solve (the quick snap of every Pareto design).

    parts: the part per joint; design: the continuous design with each joint's motor replaced by its part's
    (see :func:`evaluate_parts` for the gear ratios); objectives: every objective [its unit] (NumPy path);
    required_torque: per joint [N*m]; shortfalls: the requirements it misses (peak torque, the gearbox's
    ratings, and with a duty cycle RMS torque and motor speed), empty when it meets them all.
    """

    parts: tuple[CataloguePart, ...]
    design: Design
    objectives: dict[str, float]
    required_torque: np.ndarray
    shortfalls: tuple[str, ...]

    @property
    def feasible(self) -> bool:
        """Whether the design meets every torque and speed requirement."""
        return not self.shortfalls


@interruptible()
def evaluate_parts(problem: DesignProblem, design: Design, parts: Sequence[CataloguePart]) -> PartsEvaluation:
    """``design`` with each joint's motor (and gearbox) the one of ``parts``, evaluated (no re-solve).

    The gear ratios are :func:`covering_gear_ratios`; software stiffness, threshold and approach
    velocity are ``design``'s. The actuator quantities come from the technology's one formula
    (:meth:`~collision_reflex.optimize.technology.ActuatorTechnology.joint_quantities`), the impulses from the
    NumPy path (:func:`collision_reflex.optimize.evaluate.evaluate_design`), the requirement from ``problem``'s
    own torque-requirement function (and duty cycle); gearbox ratings are checked as the problem's rows are.
    """
    parts = tuple(parts)
    technology = _parts_technology(problem, parts)
    gear = covering_gear_ratios(problem, design, parts)
    snapped = _parts_design(design, parts, technology, gear)
    figures = technology.gearbox_figures(len(parts))
    impulses = evaluate_design(problem, snapped)
    masses = snapped.actuator_mass
    required = _required_torque(problem, snapped)
    names = design.joint_names
    shortfalls = _below("peak torque", snapped.driving_peak_torque, "the required", required, names)
    shortfalls += _below("gearbox peak rating", figures.peak_torque, "the required", required, names)
    if problem.duty is not None:
        values = duty_values(problem.duty, snapped, technology)
        rms = values.required_rms_torque
        shortfalls += _below("continuous torque", values.continuous_torque, "the cycle's RMS", rms, names)
        shortfalls += _below("gearbox rated torque", figures.rated_torque, "the cycle's RMS", rms, names)
        speed = values.max_motor_speed
        shortfalls += _below(
            "motor speed limit", values.speed_limit, "the motor speed", speed, names, "rad/s"
        )
        shortfalls += _below(
            "gearbox input speed limit", figures.max_input_speed, "the motor speed", speed, names, "rad/s"
        )
    objectives = objective_values(impulses, masses.sum(), snapped.approach_velocity, problem.samples)
    return PartsEvaluation(parts, snapped, objectives, required, tuple(shortfalls))


def _parts_design(
    design: Design, parts: tuple[CataloguePart, ...], technology: ActuatorTechnology, gear: np.ndarray
) -> Design:
    """``design`` with the motors (and gearboxes) of ``parts`` at gear ratios ``gear`` [-]."""
    diameter = np.array([p.motor.stator_diameter for p in parts])
    stack = np.array([p.motor.stack_length for p in parts])
    joint = technology.joint_quantities(diameter, stack, gear)
    return replace(
        design,
        stator_diameter=diameter,
        stack_length=stack,
        gear_ratio=gear,
        rotor_inertia=np.asarray(joint.motor.rotor_inertia, dtype=float),
        reflected_inertia=np.asarray(joint.reflected_inertia, dtype=float),
        motor_peak_torque=np.asarray(joint.motor.peak_torque, dtype=float),
        peak_torque=np.asarray(joint.peak_torque, dtype=float),
        motor_mass=np.asarray(joint.motor.mass, dtype=float),
        gearbox=joint.gearbox.names,
        gearbox_mass=joint.gearbox.mass,
        gearbox_inertia=joint.gearbox.inertia,
        gearbox_efficiency=joint.gearbox.efficiency,
    )


def _required_torque(problem: DesignProblem, design: Design) -> np.ndarray:
    """Each joint's required peak torque [N*m] for ``design``'s masses (and reflected inertias, with a cycle)."""
    arguments = (
        (design.actuator_mass,) if problem.duty is None else (design.actuator_mass, design.reflected_inertia)
    )
    return np.asarray(problem.required_torque_function(*arguments), dtype=float).ravel()


def _below(
    capacity_name: str,
    capacity: np.ndarray,
    need_name: str,
    need: np.ndarray,
    joints: Sequence[str],
    unit: str = "N*m",
) -> list[str]:
    """``joint: <capacity> 1.2 N*m below <need> 1.5 N*m`` for every joint whose capacity is short of its need."""
    return [
        f"{joint}: {capacity_name} {capacity[j]:.4g} {unit} below {need_name} {need[j]:.4g} {unit}"
        for j, joint in enumerate(joints)
        if capacity[j] < need[j] * (1 - BOUND_TOLERANCE)
    ]
