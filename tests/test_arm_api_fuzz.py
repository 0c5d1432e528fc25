"""Seeded fuzz of the public arm API: one argument of a valid call at a time is made hostile.

The names of ``collision_reflex.arm.__all__``, the public methods of :class:`~collision_reflex.arm.Arm` and of
its results, and the functions their docs point to (:mod:`collision_reflex.arm.dynamics`, the motion
profiles, the joint checks). Every call either returns a result whose floats are not NaN (where NaN is not a
documented value) or raises :class:`InvalidParameter` (a :class:`TrajectoryError` for a duty cycle's samples, a
:class:`FrameNotFound` for an unknown frame name).
A TypeError, IndexError, MemoryError, OverflowError or bare ValueError from inside is a finding.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from collision_reflex import arm, hardware
from collision_reflex.arm import actuation, dynamics, joints, motion_profiles
from collision_reflex.errors import FrameNotFound, InvalidParameter, TrajectoryError
from fuzz_values import hostile_values, result_floats

SEED = 41
HOSTILE: tuple[Any, ...] = (
    math.nan,
    math.inf,
    -math.inf,
    0,
    -1,
    -0.0,
    1e-300,
    1e300,
    2**62,
    True,
    "x",
    None,
    1 + 1j,
    [1, [2]],
    np.array([]),
    np.ones((3, 3, 3)),
    np.ones(7),
    np.float32(1.5),
    np.float32("nan"),
    np.array([1.0, np.nan]),
)
URDF = Path(__file__).resolve().parents[1] / "designs" / "planar_two_link.urdf"
ARM = arm.Arm.from_urdf(URDF, "tip")
ACTUATOR = hardware.Actuator(
    motor=hardware.reference_motor(), gear_ratio=10.0, mechanical_stiffness=1e3, software_stiffness=1e2
)
DRIVEN = ARM.with_actuators(ACTUATOR)
NAMES = tuple(ARM.joint_names)
TWO = np.array([1e-3, 1e-3])
Q = np.array([[0.3, 0.5], [0.1, 1.2]])
SAMPLES = ARM.kinematics(Q)
DIRECTIONS = arm.circle_directions(4)
T = np.linspace(0.0, 1.0, 8)
CYCLE = arm.DutyCycle.from_positions(T, np.column_stack([np.sin(T), np.cos(T)]), NAMES)
TORQUES = arm.cycle_torques(ARM, CYCLE)
JOINTS = {"stiffness": np.array([1e3, 1e3]), "mechanical_stiffness": np.array([1e4, 1e4])}
EFFECTIVE = {"reflected_inertia": TWO, **JOINTS, "torque_limit": np.array([10.0, 10.0])}
PARAMS = arm.effective_parameters(SAMPLES, DIRECTIONS, **EFFECTIVE)
SURFACE = arm.reflex_surface(DRIVEN, np.array([0.3, 0.5]), 0.2, 20.0)
METRIC = {"samples": SAMPLES, "reflected_inertia": TWO, "motor_mass": np.array([0.5, 0.5])}
LEGS = [0.1, 0.8, -1.6, -0.1, 0.8, -1.6, 0.1, -0.8, 1.6, -0.1, -0.8, 1.6]
SOLO12_STANDING = np.array([0, 0, 0.235, 0, 0, 0, 1, *LEGS])  # its reference "standing" configuration
MOTION = {"max_velocity": 1.0, "max_acceleration": 2.0, "rate": 100.0, "dwell": 0.1}


@dataclasses.dataclass(frozen=True)
class Case:
    """A known-valid call; ``nan_fields`` are arguments whose NaN is documented ("unknown")."""

    function: Callable[..., Any]
    kwargs: dict[str, Any]
    nan_fields: tuple[str, ...] = ()


CASES: dict[str, Case] = {
    "JointParameters": Case(
        arm.JointParameters, {**EFFECTIVE, "motor_mass": np.array([0.5, 0.5])}, nan_fields=("torque_limit",)
    ),
    "JointParameters.from_actuators": Case(
        arm.JointParameters.from_actuators, {"actuators": ACTUATOR, "nv": 2}
    ),
    "Payload": Case(arm.Payload, {"mass": 1.0, "inertia": np.eye(3) * 1e-3}),
    "DutyCycle": Case(
        arm.DutyCycle, {"joint_names": NAMES, "t": CYCLE.t, "q": CYCLE.q, "qd": CYCLE.qd, "qdd": CYCLE.qdd}
    ),
    "DutyCycle.from_positions": Case(
        arm.DutyCycle.from_positions, {"t": T, "q": CYCLE.q, "joint_names": NAMES}
    ),
    "DutyCycle.through_via_points": Case(
        arm.DutyCycle.through_via_points,
        {"via_points": np.array([[0.0, 0.0], [1.0, 0.5], [0.2, 0.1]]), "joint_names": NAMES, **MOTION},
    ),
    "circle_directions": Case(arm.circle_directions, {"count": 4, "start": 0.1}),
    "sphere_directions": Case(arm.sphere_directions, {"count": 4}),
    "unit_directions": Case(arm.unit_directions, {"spec": DIRECTIONS, "task_dim": 2}),
    "effective_parameters": Case(
        arm.effective_parameters,
        {
            "samples": SAMPLES,
            "directions": DIRECTIONS,
            **EFFECTIVE,
            "config_index": np.array([0, 1, 0, 1]),
            "motor_mass": np.array([0.5, 0.5]),
            "finger_joint_inertia": np.array([1e-4, 1e-4]),
            "task_stiffness": 1e3,
            "singular_tolerance": 1e-12,
        },
    ),
    "effective_parameters[current]": Case(
        arm.effective_parameters,
        {"samples": SAMPLES, "directions": DIRECTIONS, **EFFECTIVE, "joint_threshold": np.array([1.0, 1.0])},
    ),
    "collision_impulses": Case(arm.collision_impulses, {"params": PARAMS, "v0": 0.2, "threshold": 20.0}),
    "collision_impulses[moving]": Case(
        arm.collision_impulses, {"params": PARAMS, "v0": 0.2, "threshold": 20.0, "reaction": "moving"}
    ),
    "cycle_torques": Case(arm.cycle_torques, {"arm": ARM, "cycle": CYCLE}),
    "joint_side_torque": Case(
        arm.joint_side_torque,
        {"torque": np.ones((8, 2)), "reflected_inertia": TWO, "acceleration": np.ones((8, 2))},
    ),
    "ellipsoid_of_gyration": Case(arm.ellipsoid_of_gyration, METRIC),
    "generalized_inertia_ellipsoid": Case(arm.generalized_inertia_ellipsoid, METRIC),
    "dynamic_manipulability_ellipsoid": Case(arm.dynamic_manipulability_ellipsoid, METRIC),
    "effective_mass": Case(arm.effective_mass, {**METRIC, "directions": DIRECTIONS}),
    "impact_mitigation_factor": Case(
        arm.impact_mitigation_factor,
        {"robot": "solo12", "reflected_inertia": 1e-3, "q": SOLO12_STANDING, "contact_frame": "FL_FOOT"},
    ),
    "reflex_surface": Case(
        arm.reflex_surface, {"arm": DRIVEN, "q": np.array([0.3, 0.5]), "v0": 0.2, "threshold": 20.0}
    ),
    "Arm": Case(
        arm.Arm, {"model": ARM.model, "contact_frame": "tip", "contact_offset": np.array([0.01, 0, 0])}
    ),
    "Arm.configuration": Case(ARM.configuration, {"angles": np.array([0.3, 0.5])}),
    "Arm.joint_coordinates": Case(ARM.joint_coordinates, {"q": np.array([0.3, 0.5])}),
    "Arm.sample_configurations": Case(
        ARM.sample_configurations, {"count": 3, "rng": np.random.default_rng(0)}
    ),
    "Arm.kinematics": Case(ARM.kinematics, {"q": Q}),
    "Arm.gravity_terms": Case(ARM.gravity_terms, {"q": Q}),
    "Arm.effective_parameters": Case(
        DRIVEN.effective_parameters, {"samples": SAMPLES, "directions": DIRECTIONS}
    ),
    "Arm.with_scaled_motors": Case(
        ARM.with_scaled_motors,
        {"stator_diameter": 0.06, "torque_required": np.array([10.0, 5.0]), "mechanical_stiffness": 1e3},
    ),
    "ArmSamples.take": Case(SAMPLES.take, {"index": np.array([0])}),
    "ArmSamples.structure_mass_matrix": Case(
        SAMPLES.structure_mass_matrix, {"motor_mass": np.array([0.5, 0.5])}
    ),
    "ReflexSurface.points": Case(SURFACE.points, {"scale": 2.0, "cap": 1.0}),
    "ReflexSurface.to_plane": Case(SURFACE.to_plane, {"points": np.ones((3, 3))}),
    "CycleTorques.torque": Case(TORQUES.torque, {"motor_mass": np.array([0.5, 0.5])}),
    "CycleTorques.demand": Case(
        TORQUES.demand, {"motor_mass": np.array([0.5, 0.5]), "reflected_inertia": TWO}
    ),
    "CycleTorques.demand_basis": Case(TORQUES.demand_basis, {"joint": 1}),
    "CycleTorques.rms_form": Case(TORQUES.rms_form, {"joint": 1}),
    "dynamics.peak": Case(dynamics.peak, {"values": np.ones((2, 8))}),
    "dynamics.rms": Case(dynamics.rms, {"values": np.ones((2, 8)), "t": T}),
    "dynamics.time_weights": Case(dynamics.time_weights, {"t": T}),
    "dynamics.max_speed": Case(dynamics.max_speed, {"velocity": np.ones((8, 2))}),
    "actuation.joint_parameters": Case(
        actuation.joint_parameters,
        {"actuators": None, "nv": 2, "armature": TWO, "torque_limit": np.array([10.0, 10.0])},
        nan_fields=("torque_limit",),
    ),
    "actuation.scaled_actuators": Case(
        actuation.scaled_actuators,
        {"stator_diameter": 0.06, "torque_required": np.array([10.0, 5.0]), "nv": 2},
    ),
    "joints.joint_array": Case(joints.joint_array, {"name": "x", "value": np.array([1.0, 2.0]), "nv": 2}),
    "motion_profiles.trapezoidal_motion": Case(
        motion_profiles.trapezoidal_motion,
        {
            "via_points": np.array([[0.0, 0.0], [1.0, 0.5]]),
            "max_velocity": np.array([1.0, 1.0]),
            "max_acceleration": np.array([2.0, 2.0]),
            "rate": 100.0,
            "dwell": np.array([0.1, 0.1]),
        },
    ),
}
# Public names of arm.__all__ that take no numbers of their own: result records (built by the functions above).
RECORDS = {"ArmSamples", "CollisionImpulses", "CycleTorques", "EffectiveParameters", "Ellipsoid"}
RECORDS |= {"ImpactMitigation", "ReflexSurface"}
NOT_NUMBERS = {
    "name",
    "samples",
    "params",
    "arm",
    "cycle",
    "rng",
    "model",
    "contact_frame",
    "robot",
    "reaction",
}


def _calls() -> Iterator[Any]:
    rng = np.random.default_rng(SEED)
    for label, case in CASES.items():
        for name in case.kwargs:
            if name not in NOT_NUMBERS:
                yield pytest.param(label, name, hostile_values(HOSTILE, rng, 2), id=f"{label}-{name}")


def test_every_public_arm_name_is_covered() -> None:
    covered = {label.split(".")[0].split("[")[0] for label in CASES}
    assert set(arm.__all__) - RECORDS <= covered, set(arm.__all__) - RECORDS - covered
    public = {n for n in vars(arm.Arm) if not n.startswith("_") and callable(getattr(ARM, n, None))}
    exempt = {"from_urdf", "from_example_robot_data", "with_actuators", "sensing_options", "visual_model"}
    exempt |= {"fingerprint", "joint_limits"}  # loaders, an actuator swap, no-argument queries
    assert public - exempt <= {label.split(".", 1)[1] for label in CASES if label.startswith("Arm.")}


@pytest.mark.parametrize("label", list(CASES))
def test_valid_calls_give_no_nan(label: str) -> None:
    case = CASES[label]
    assert not any(math.isnan(x) for x in result_floats(case.function(**case.kwargs)))


@pytest.mark.parametrize(("label", "name", "values"), list(_calls()))
def test_hostile_argument(label: str, name: str, values: list[Any]) -> None:
    case = CASES[label]
    findings = []
    for value in values:
        try:
            result = case.function(**{**case.kwargs, name: value})
        except (InvalidParameter, TrajectoryError, FrameNotFound):
            continue
        except Exception as error:  # anything else from inside is the finding
            findings.append(f"{value!r}: {type(error).__name__}: {error}"[:300])
            continue
        if name in case.nan_fields:
            continue  # NaN is documented there ("unknown") and is passed on
        if any(math.isnan(x) for x in result_floats(result)):
            findings.append(f"{value!r}: returned NaN in {result!r}"[:300])
    assert not findings, "\n".join(findings)
