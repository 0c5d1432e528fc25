"""Seeded fuzz of the public numeric API: one argument of a valid call at a time is made hostile.

Every call either returns a result whose floats are finite (``inf`` only where the docstring names it a valid
result) or raises :class:`InvalidParameter`. A TypeError, IndexError, ZeroDivisionError, OverflowError or bare
ValueError from inside, or a NaN in the result, is a finding.
"""

from __future__ import annotations

import dataclasses
import inspect
import math
from collections.abc import Callable, Iterator
from typing import Any

import numpy as np
import pytest

import collision_reflex as cr
from collision_reflex import hardware, model
from collision_reflex.errors import InvalidParameter
from collision_reflex.model import effective
from fuzz_values import hostile_values, result_floats

SEED = 33
HOSTILE: tuple[Any, ...] = (
    math.nan,
    math.inf,
    -math.inf,
    0,
    -1,
    1e-300,
    1e300,
    True,
    "x",
    1 + 1j,
    [1, [2]],
    np.array([[1.0, 2.0]]),
    None,
)
MOTOR = hardware.reference_motor()
GEARBOX = next(iter(hardware.load_gearbox_catalogue().values()))
IMPULSE = {"m_f": 0.2, "k": 90.9, "k_m": 1000.0, "F_s": 200.0, "a": 20.0}  # the reproduction


@dataclasses.dataclass(frozen=True)
class Case:
    """A known-valid call; ``inf_result`` when the docstring names ``inf`` a valid result or field."""

    function: Callable[..., Any]
    kwargs: dict[str, Any]
    inf_result: bool = False
    nan_fields: tuple[str, ...] = ()  # dataclass fields whose NaN means "not given" (documented)


CASES: dict[str, Case] = {
    "model.BodyRegion": Case(
        model.BodyRegion,
        {
            "name": "hand",
            "stiffness": 75e3,
            "mass": 0.6,
            "transient_force": 280.0,
            "quasi_static_force": 140.0,
        },
        inf_result=True,
    ),
    "model.collision_times": Case(model.collision_times, {**IMPULSE, "v0": 0.1}),
    "model.contact_robot_mass": Case(
        model.contact_robot_mass,
        {"finger_mass": 0.2, "rotor_mass": 2.0, "contact_stiffness": 1e4, "mechanical_stiffness": 1e5},
    ),
    "model.current_threshold_torque": Case(
        model.current_threshold_torque, {"gear_ratio": 10.0, "motor_torque": 0.1, "friction_torque": 0.01}
    ),
    "model.force_profile": Case(model.force_profile, {"t": np.linspace(0.0, 0.1, 5), **IMPULSE, "v0": 0.1}),
    "model.iso_robot_mass": Case(model.iso_robot_mass, {"moving_mass": 5.0, "payload": 1.0}),
    "model.minimum_impulse": Case(model.minimum_impulse, IMPULSE),
    "model.optimal_velocity": Case(model.optimal_velocity, {"m_f": 0.2, "k": 90.9, "F_s": 200.0}),
    "model.optimal_velocity[moving]": Case(
        model.optimal_velocity,
        {"m_f": 0.2, "k": 90.9, "F_s": 200.0, "reaction": "moving", "k_m": 1000.0, "a": 20.0},
    ),
    "model.permissible_speed": Case(
        model.permissible_speed,
        {"force_limit": 280.0, "robot_mass": 5.0, "contact_stiffness": 75e3, "body_mass": 0.6},
    ),
    "model.phase_impulses": Case(model.phase_impulses, {**IMPULSE, "v0": 0.1}),
    "model.phase_impulses[moving]": Case(
        model.phase_impulses, {**IMPULSE, "v0": 0.1, "reaction": "moving", "v_r": 0.1}
    ),
    "model.rebound": Case(model.rebound, {"restitution": 0.5}, inf_result=True),
    "model.rebound_impulse": Case(
        model.rebound_impulse,
        {"finger_mass": 0.2, "stiffness": 90.9, "threshold": 200.0, "velocity": 0.1, "restitution": 0.5},
    ),
    "model.reduced_mass": Case(model.reduced_mass, {"robot_mass": 5.0, "body_mass": 0.6}),
    "model.series_stiffness": Case(model.series_stiffness, {"k_m": 1000.0, "k_s": 100.0}),
    "model.settled_rebound_speed": Case(
        model.settled_rebound_speed,
        {"finger_mass": 0.2, "stiffness": 90.9, "threshold": 200.0, "restitution": 0.5},
        inf_result=True,
    ),
    "model.threshold_force": Case(
        model.threshold_force, {"sensing": "force", "threshold": 3.0, "stiffness": 1e4}
    ),
    "model.total_impulse": Case(model.total_impulse, {**IMPULSE, "v0": 0.1}),
    "model.transient_contact": Case(
        model.transient_contact,
        {"velocity": 0.25, "robot_mass": 5.0, "contact_stiffness": 75e3, "body_mass": 0.6},
    ),
    "model.velocity_coefficients": Case(model.velocity_coefficients, IMPULSE),
    "hardware.Actuator": Case(
        hardware.Actuator,
        {"motor": MOTOR, "gear_ratio": 10.0, "mechanical_stiffness": 1e3, "software_stiffness": 1e2},
        inf_result=True,
    ),
    "hardware.CollisionParameters": Case(
        hardware.CollisionParameters,
        {"m_f": 0.2, "m_r": 2.0, "k": 90.9, "k_m": 1000.0, "F_s": 200.0, "a": 20.0, "F_a": 40.0},
    ),
    "hardware.CurrentThreshold": Case(
        hardware.CurrentThreshold, {"motor_torque": 0.1, "friction_torque": 0.01}
    ),
    "hardware.ForceThreshold": Case(hardware.ForceThreshold, {"force": 3.0}),
    "hardware.Gearbox": Case(
        hardware.Gearbox,
        {
            "kind": "planetary",
            "stages": 1,
            "diameter": 0.06,
            "length": 0.05,
            "mass": 0.5,
            "inertia": 1e-5,
            "rated_torque": 10.0,
        },
        nan_fields=("diameter", "length", "mass", "inertia", "rated_torque"),
    ),
    "hardware.Motor": Case(
        hardware.Motor,
        {
            "name": "m",
            "stator_diameter": 0.06,
            "stack_length": 0.0125,
            "rotor_inertia": 2.21e-5,
            "peak_torque": 1.3,
            "continuous_torque": 0.524,
            "mass": 0.195,
            "max_speed": 492.6,
            "torque_constant": 0.1,
        },
    ),
    "hardware.PositionThreshold": Case(hardware.PositionThreshold, {"error": 0.01}),
    "hardware.gear_ratio_for": Case(hardware.gear_ratio_for, {"torque_required": 13.0, "peak_torque": 1.3}),
    "hardware.scaled_motor_quantities": Case(
        hardware.scaled_motor_quantities,
        {"reference": MOTOR, "stator_diameter": 0.08, "stack_length": 0.02, "law": "haddadin"},
    ),
    "hardware.ScaledGearbox": Case(hardware.ScaledGearbox, {"reference": GEARBOX, "ratios": (3.0, 5.0)}),
    "hardware.CatalogueGearbox": Case(
        hardware.CatalogueGearbox,
        {
            "name": "g",
            "kind": "planetary",
            "ratios": (3.0, 5.0),
            "continuous_ratio": False,
            "rated_torque": 17.0,
            "peak_torque": 32.0,
            "mass": 1.8,
            "inertia": 2.5e-5,
            "source": "s",
            "efficiency": 0.97,
            "stages": 1,
            "momentary_torque": 80.0,
            "max_input_speed": 837.8,
            "diameter": 0.06,
            "length": 0.05,
        },
    ),
    "hardware.ScalingLaw": Case(
        hardware.ScalingLaw,
        {"name": "l", "mass_exponent": 2.0, "inertia_exponent": 4.0, "torque_exponent": 2.5},
    ),
    "hardware.reference_motor": Case(hardware.reference_motor, {}),
    "cr.reference_motor": Case(cr.reference_motor, {}),
    "cr.total_impulse": Case(cr.total_impulse, {**IMPULSE, "v0": 0.1}),
    "cr.optimal_velocity": Case(cr.optimal_velocity, {"m_f": 0.2, "k": 90.9, "F_s": 200.0}),
}
J = np.array([[0.3, 0.2]])  # a contact Jacobian row (1, nv) [m/rad]
M = np.array([[2.0, 0.3], [0.3, 1.0]])  # a joint-space mass matrix [kg m^2]
# The effective-parameter formulas (not in model.__all__; the arm and the optimiser's CasADi problem call them).
CASES.update(
    {
        "effective.reflected_inertia": Case(
            effective.reflected_inertia, {"gear_ratio": 10.0, "rotor_inertia": 2e-5}
        ),
        "effective.finger_inertia": Case(
            effective.finger_inertia, {"joint_reflected_inertia": 2e-3, "in_finger": 1.0}
        ),
        "effective.finger_mass_matrix": Case(
            effective.finger_mass_matrix,
            {
                "structure_mass_matrix": M,
                "motor_mass_influence": np.stack([M, M]),
                "motor_mass": np.array([0.5, 0.3]),
                "joint_finger_inertia": np.array([1e-3, 2e-3]),
            },
        ),
        "effective.task_inverse_inertia": Case(
            effective.task_inverse_inertia, {"jacobian": J, "mass_matrix": M}
        ),
        "effective.task_compliance": Case(
            effective.task_compliance, {"jacobian": J, "joint_values": np.array([100.0, 200.0])}
        ),
        "effective.torque_fractions": Case(
            effective.torque_fractions, {"moment_arms": J[0], "torque_limit": np.array([10.0, 5.0])}
        ),
        "effective.reaction_compliance": Case(
            effective.reaction_compliance, {"fractions": np.array([0.03, 0.04]), "joint_axis": -1}
        ),
        "effective.reaction_acceleration": Case(
            effective.reaction_acceleration, {"robot_compliance": 0.5, "reaction_compliance_": 0.04}
        ),
        "effective.finger_mass_direction": Case(
            effective.finger_mass_direction, {"moment_arms": J[0], "mass_matrix": M}
        ),
        "effective.finger_mass": Case(
            effective.finger_mass, {"direction": np.array([2.0, 1.0]), "mass_matrix": M}
        ),
    }
)
SKIPPED = {  # public names that take no numbers: result records, a table, file loaders, a law by name
    "model": {"PhaseImpulses", "Rebound", "TransientContact"},  # result records, built by the functions
    "hardware": {
        "SCALING_LAWS",
        "MotorQuantities",
        "load_catalogue",
        "load_gearbox_catalogue",
        "scaling_law",
    },
}
# (case, argument) -> reason, for a known finding left unfixed (a fix that would change numbers).
XFAIL: dict[tuple[str, str], str] = {}
LABEL_ONLY = {"name", "source", "kind"}  # free-text labels, not numbers
MODEL_OBJECTS = ("Motor", "Gearbox", "Threshold")  # arguments annotated with these take a model object


def _calls() -> Iterator[Any]:
    rng = np.random.default_rng(SEED)
    for label, case in CASES.items():
        for name, parameter in inspect.signature(case.function).parameters.items():
            if name in LABEL_ONLY or any(kind in str(parameter.annotation) for kind in MODEL_OBJECTS):
                continue
            reason = XFAIL.get((label, name))
            marks = [pytest.mark.xfail(strict=True, reason=reason)] if reason else []
            yield pytest.param(
                label, name, hostile_values(HOSTILE, rng, 3), id=f"{label}-{name}", marks=marks
            )


def test_every_public_numeric_callable_is_covered() -> None:
    for package, module in (("model", model), ("hardware", hardware)):
        covered = {label.split(".", 1)[1].split("[")[0] for label in CASES if label.startswith(package + ".")}
        assert set(module.__all__) - SKIPPED[package] == covered


@pytest.mark.parametrize("label", list(CASES))
def test_valid_calls_return_finite(label: str) -> None:
    case = CASES[label]
    result = case.function(**case.kwargs)
    assert all(math.isfinite(x) for x in result_floats(result, case.nan_fields)), result


@pytest.mark.parametrize(("label", "name", "values"), list(_calls()))
def test_hostile_argument(label: str, name: str, values: list[Any]) -> None:
    case = CASES[label]
    findings = []
    for value in values:
        try:
            result = case.function(**{**case.kwargs, name: value})
        except InvalidParameter:
            continue
        except Exception as error:  # anything else from inside is the finding
            findings.append(f"{value!r}: {type(error).__name__}: {error}")
            continue
        for x in result_floats(result, case.nan_fields):
            if math.isnan(x) or (math.isinf(x) and not case.inf_result):
                findings.append(f"{value!r}: returned {x} in {result!r}"[:300])
                break
    assert not findings, "\n".join(findings)
