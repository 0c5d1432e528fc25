"""Actuator studies: single-joint actuators compared in a 1D collision at a lever (no arm, no optimiser).

Each candidate is a :class:`collision_reflex.hardware.actuators.Actuator`; its ``contact_parameters`` map it to the contact
at the study's lever (the paper's "Actuator Selection and the Collision Reflex": inertia ``J / L²``, stiffness ``k / L²``,
torque ``τ / L``, the threshold by its sensing scheme). The object hit (``load.contact_stiffness``, e.g. a force sensor) is a spring in series with
the joint's, during sensing and reaction alike.
"""

from __future__ import annotations

import math
from dataclasses import replace
from typing import Any

import numpy as np

from ..errors import CollisionReflexError
from ..hardware.actuators import Actuator, CurrentThreshold, ForceThreshold, PositionThreshold
from ..model.impulse import minimum_impulse, optimal_velocity, phase_impulses, series_stiffness
from ..optimize.dominance import dominated_mask
from .actuator_specs import SensingSpec
from .load import LoadedStudy
from .prepare import check_motors, gearbox_for, motor_for
from .resolve import resolved_study
from .schema import ActuatorCandidate, ActuatorStudy


def check_actuator_study(loaded: LoadedStudy) -> dict[str, Any]:
    """Build every candidate actuator (raising located errors); returns them by name."""
    study = loaded.study
    assert isinstance(study, ActuatorStudy)
    catalogue = check_motors(loaded)
    actuators = {}
    for name, candidate in study.actuators.items():
        try:
            actuators[name] = _actuator(
                candidate, candidate.sensing or study.sensing, study.load.lever, catalogue
            )
            _contact(actuators[name], candidate, study)
        except CollisionReflexError as error:
            raise loaded.fail(
                ("actuators", name),
                f"an actuator that cannot be built ({error})",
                "a motor, gear ratio and stiffnesses the actuator model accepts",
            ) from None
    return actuators


def _actuator(
    candidate: ActuatorCandidate, sensing: SensingSpec, lever: float, catalogue: dict[str, Any]
) -> Any:
    return Actuator(
        motor_for(candidate.motor, catalogue),
        gear_ratio=candidate.gear_ratio,
        mechanical_stiffness=candidate.mechanical_stiffness,
        software_stiffness=candidate.software_stiffness,
        sensing=sensing_scheme(sensing, lever),
        gearbox=gearbox_for(candidate.gearbox),
        gearbox_inertia=candidate.gearbox_inertia,
    )


def sensing_scheme(sensing: SensingSpec, lever: float) -> Any:
    """The actuator model's sensing scheme for a study's sensing.

    A contact position error ``e`` [m] is the joint error ``e / L`` [rad] at the lever ``L`` [m].
    """
    if sensing.scheme == "force":
        return ForceThreshold(sensing.value)
    if sensing.scheme == "position":
        return PositionThreshold(sensing.value / lever)
    return CurrentThreshold(sensing.value)


def _contact(actuator: Any, candidate: ActuatorCandidate, study: ActuatorStudy) -> Any:
    """The candidate's collision parameters at the contact, with the object hit in series."""
    params = actuator.contact_parameters(
        study.load.lever, m_f=study.load.finger_mass, reflected_inertia_in=candidate.reflected_inertia_in
    )
    if study.load.contact_stiffness is None:
        return params
    return replace(
        params,
        k=float(series_stiffness(params.k, study.load.contact_stiffness)),
        k_m=float(series_stiffness(params.k_m, study.load.contact_stiffness)),
    )


def evaluate_actuator_study(loaded: LoadedStudy) -> dict[str, Any]:
    """Every candidate's 1D collision, as plain data (SI units).

    Parameters at the contact, impulse and phases at the study's approach velocity and over its velocity range,
    optimal velocity and minimum impulse.
    """
    study = loaded.study
    assert isinstance(study, ActuatorStudy)
    actuators = check_actuator_study(loaded)
    velocities = np.geomspace(study.velocities.min, study.velocities.max, study.velocities.count)
    candidates = []
    for name, candidate in study.actuators.items():
        actuator = actuators[name]
        params = _contact(actuator, candidate, study)
        m_f, k, k_m, F_s, a = params.m_f, params.k, params.k_m, params.F_s, params.a
        sensing = candidate.sensing or study.sensing
        common = (m_f, k, k_m, F_s, a)
        at_v0 = phase_impulses(*common, study.approach_velocity, study.reaction)
        sweep = phase_impulses(*common, velocities, study.reaction)
        v_star = float(optimal_velocity(m_f, k, F_s, study.reaction, k_m, a))
        candidates.append(
            {
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
                "reflected_inertia_in": candidate.reflected_inertia_in,
                "contact": {
                    "m_f": m_f,
                    "m_r": params.m_r,
                    "k": k,
                    "k_m": k_m,
                    "F_s": F_s,
                    "F_a": params.F_a,
                    "a": a,
                },
                "impulse": {
                    "initial": float(at_v0.initial),
                    "sensing": float(at_v0.sensing),
                    "reaction": float(at_v0.reaction),
                    "total": float(at_v0.total),
                },
                "optimal_velocity": v_star,
                "minimum_impulse": float(minimum_impulse(*common, study.reaction)),
                "sweep": {
                    "initial": np.broadcast_to(sweep.initial, velocities.shape).tolist(),
                    "sensing": np.broadcast_to(sweep.sensing, velocities.shape).tolist(),
                    "reaction": np.broadcast_to(sweep.reaction, velocities.shape).tolist(),
                    "total": np.broadcast_to(sweep.total, velocities.shape).tolist(),
                },
            }
        )
    for record in candidates:
        if not all(math.isfinite(v) for v in record["contact"].values()):
            raise loaded.fail(
                ("actuators", record["name"]),
                "an actuator with non-finite contact parameters",
                "finite stiffness, inertia and torque",
            )

    # Pareto-optimal: no other candidate has both a lower minimum impulse and a lower mass (exact comparison).
    values = np.array([[c["minimum_impulse"], c["mass"]] for c in candidates]).reshape(-1, 2)
    for record, dominated in zip(candidates, dominated_mask(values, tolerance=0.0), strict=True):
        record["pareto_optimal"] = not bool(dominated)
    return {
        "kind": "actuator",
        "study": study.name,
        "description": study.description,
        "resolved": resolved_study(loaded),
        "lever": study.load.lever,
        "approach_velocity": study.approach_velocity,
        "velocities": velocities.tolist(),
        "candidates": candidates,
    }
