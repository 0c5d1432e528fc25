"""Actuator studies: single-joint actuators compared in a 1D collision at a lever (no arm, no optimiser).

A rotary joint seen at a contact point at lever ``L`` (MODEL.md §2): robot mass ``J / L²`` with ``J`` the
actuator's reflected inertia, stiffness ``k_rot / L²``, force ``τ / L``. The mechanical spring is in series with
the object hit (``load.contact_stiffness``, e.g. a force sensor). The contact-force threshold follows the
sensing scheme: a force threshold is used as is; a position-error threshold ``e`` gives ``F_s = k e``; a
motor-current threshold ``τ_s`` on the motor side gives ``F_s = N τ_s / L``.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..errors import CollisionReflexError
from ..impulse import minimum_impulse, optimal_velocity, phase_impulses, series_stiffness
from .load import LoadedStudy
from .prepare import check_motors, gearbox_for, motor_for
from .schema import ActuatorCandidate, ActuatorStudy, SensingSpec


def check_actuator_study(loaded: LoadedStudy) -> dict[str, Any]:
    """Build every candidate actuator (raising located errors); returns them by name."""
    study = loaded.study
    assert isinstance(study, ActuatorStudy)
    catalogue = check_motors(loaded)
    actuators = {}
    for name, candidate in study.actuators.items():
        try:
            actuators[name] = _actuator(candidate, catalogue)
        except CollisionReflexError as error:
            raise loaded.fail(("actuators", name), f"an actuator that cannot be built ({error})",
                              "a motor, gear ratio and stiffnesses the actuator model accepts") from None
    return actuators


def _actuator(candidate: ActuatorCandidate, catalogue: dict[str, Any]) -> Any:
    from ..actuators import Actuator

    return Actuator(
        motor_for(candidate.motor, catalogue),
        gear_ratio=candidate.gear_ratio,
        mechanical_stiffness=candidate.mechanical_stiffness,
        software_stiffness=candidate.software_stiffness,
        gearbox=gearbox_for(candidate.gearbox),
        gearbox_inertia=candidate.gearbox_inertia,
    )


def contact_threshold(sensing: SensingSpec, gear_ratio: float, lever: float, stiffness: float) -> float:
    """Contact force at detection [N] for a sensing scheme (see the module docstring).

    gear_ratio [-], lever [m], stiffness: the lumped sensing stiffness at the contact [N/m].
    """
    if sensing.scheme == "force":
        return float(sensing.value)
    if sensing.scheme == "position":
        return stiffness * sensing.value
    return gear_ratio * sensing.value / lever


def evaluate_actuator_study(loaded: LoadedStudy) -> dict[str, Any]:
    """Every candidate's 1D collision: parameters at the contact, impulse and phases at the study's approach
    velocity and over its velocity range, optimal velocity and minimum impulse. Plain data (SI units)."""
    study = loaded.study
    assert isinstance(study, ActuatorStudy)
    actuators = check_actuator_study(loaded)
    lever = study.load.lever
    velocities = np.geomspace(study.velocities.min, study.velocities.max, study.velocities.count)
    candidates = []
    for name, candidate in study.actuators.items():
        actuator = actuators[name]
        m_f = study.load.finger_mass
        m_r = float(actuator.reflected_inertia) / lever**2
        k_m = candidate.mechanical_stiffness / lever**2
        if study.load.contact_stiffness is not None:
            k_m = float(series_stiffness(k_m, study.load.contact_stiffness))
        k_s = candidate.software_stiffness / lever**2
        k = float(series_stiffness(k_m, k_s))
        force_capacity = float(actuator.peak_torque) / lever
        a = force_capacity / m_r
        sensing = candidate.sensing or study.sensing
        F_s = contact_threshold(sensing, candidate.gear_ratio, lever, k)
        common = (m_f, k, k_m, F_s, a)
        at_v0 = phase_impulses(*common, study.approach_velocity, study.reaction)
        sweep = phase_impulses(*common, velocities, study.reaction)
        v_star = float(optimal_velocity(m_f, k, F_s, study.reaction, k_m, a))
        candidates.append({
            "name": name,
            "motor": candidate.motor.reference,
            "stator_diameter": float(actuator.motor.stator_diameter),
            "gear_ratio": candidate.gear_ratio,
            "gearbox": candidate.gearbox.kind if candidate.gearbox else "direct drive",
            "reflected_inertia": float(actuator.reflected_inertia),
            "peak_torque": float(actuator.peak_torque),
            "mass": float(actuator.mass),
            "mechanical_stiffness": candidate.mechanical_stiffness,
            "software_stiffness": candidate.software_stiffness,
            "sensing": sensing.scheme,
            "contact": {"m_f": m_f, "m_r": m_r, "k": k, "k_m": k_m, "F_s": F_s, "F_a": force_capacity, "a": a},
            "impulse": {"initial": float(at_v0.initial), "sensing": float(at_v0.sensing),
                        "reaction": float(at_v0.reaction), "total": float(at_v0.total)},
            "optimal_velocity": v_star,
            "minimum_impulse": float(minimum_impulse(*common, study.reaction)),
            "sweep": {
                "initial": np.broadcast_to(sweep.initial, velocities.shape).tolist(),
                "sensing": np.broadcast_to(sweep.sensing, velocities.shape).tolist(),
                "reaction": np.broadcast_to(sweep.reaction, velocities.shape).tolist(),
                "total": np.broadcast_to(sweep.total, velocities.shape).tolist(),
            },
        })
    for record in candidates:
        if not all(math.isfinite(v) for v in record["contact"].values()):
            raise loaded.fail(("actuators", record["name"]), "an actuator with non-finite contact parameters",
                              "finite stiffness, inertia and torque")
    from .resolve import resolved_study

    return {
        "kind": "actuator",
        "study": study.name,
        "description": study.description,
        "resolved": resolved_study(loaded),
        "lever": lever,
        "approach_velocity": study.approach_velocity,
        "velocities": velocities.tolist(),
        "candidates": candidates,
    }
