"""From a validated study to the objects a run needs.

Motors from the catalogue, the arm, the samples, and the actuator of every joint. Every failure is located in
the study file.
"""

from __future__ import annotations

import difflib
from collections.abc import Iterator, Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from ..errors import StudyFileError, StudyProblem
from ..hardware.gearboxes import Gearbox
from ..hardware.motors import load_catalogue
from ..vocabulary import MODULE_VARIABLES, PER_JOINT_VARIABLES
from .actuator_specs import GearboxSpec, MotorSpec
from .duty import describe_duty_cycle, prismatic_joints, static_requirement, study_duty_cycle
from .load import LoadedStudy
from .robot import load_arm
from .samples import sample_counts
from .schema import ActuatorStudy, ArmStudy
from .source import PathKey, excerpt

if TYPE_CHECKING:
    from ..hardware.gearboxes import Gearbox
    from ..hardware.motors import Motor


def _motor_specs(study: ArmStudy | ActuatorStudy) -> Iterator[tuple[PathKey, MotorSpec]]:
    if isinstance(study, ArmStudy):
        yield ("actuators", "motor"), study.actuators.motor
        for joint, override in study.actuators.joints.items():
            if override.motor is not None:
                yield ("actuators", "joints", joint, "motor"), override.motor
    else:
        for name, candidate in study.actuators.items():
            yield ("actuators", name, "motor"), candidate.motor


def check_motors(loaded: LoadedStudy, catalogue: dict[str, Motor] | None = None) -> dict[str, Motor]:
    """The motor catalogue, after checking that every motor the study names is in it."""
    catalogue = catalogue if catalogue is not None else load_catalogue()
    problems: list[StudyProblem] = []
    names = sorted(catalogue)
    for path, spec in _motor_specs(loaded.study):
        if spec.reference not in catalogue:
            close = difflib.get_close_matches(spec.reference, names, n=1)
            field = (*path, "reference") if _written_as_mapping(loaded, path) else path
            problems.append(
                loaded.problem(
                    field,
                    f"motor {excerpt(spec.reference)}, not in the catalogue",
                    (f"{close[0]!r}? " if close else "") + "one of " + ", ".join(map(repr, names)),
                )
            )
    if problems:
        raise StudyFileError(loaded.source.file, problems)
    return catalogue


def _written_as_mapping(loaded: LoadedStudy, path: PathKey) -> bool:
    node: Any = loaded.source.data
    for key in path:
        node = node.get(key) if isinstance(node, dict) else None
    return isinstance(node, dict)


def motor_for(spec: MotorSpec, catalogue: Mapping[str, Motor]) -> Motor:
    """The :class:`collision_reflex.hardware.motors.Motor` a spec describes: the catalogue motor, scaled if asked."""
    motor = catalogue[spec.reference]
    if spec.stator_diameter is None and spec.stack_length is None:
        return motor
    return motor.scaled(
        stator_diameter=spec.stator_diameter, stack_length=spec.stack_length, law=spec.scaling_law
    )


def gearbox_for(spec: GearboxSpec | None) -> Gearbox | None:
    """The :class:`collision_reflex.hardware.actuators.Gearbox` of a spec (``None`` for direct drive)."""
    if spec is None:
        return None
    return Gearbox(
        spec.kind,
        stages=spec.stages,
        diameter=spec.diameter,
        length=spec.length,
        mass=spec.mass,
        inertia=spec.inertia,
        rated_torque=spec.rated_torque,
        source=spec.source,
    )


@dataclass(frozen=True)
class JointActuatorValues:
    """The nominal actuator of one joint of an arm study (SI units).

    The study's defaults with the joint's overrides applied.
    """

    joint: str
    motor: MotorSpec
    gearbox: GearboxSpec | None
    gear_ratio: float
    mechanical_stiffness: float
    software_stiffness: float


def joint_actuators(study: ArmStudy, joint_names: list[str]) -> list[JointActuatorValues]:
    """Per joint, the actuator defaults with the joint's overrides applied."""
    base = study.actuators
    out = []
    for joint in joint_names:
        override = base.joints.get(joint)

        def pick(name: str, override: Any = override) -> Any:
            value = getattr(override, name) if override is not None else None
            return value if value is not None else getattr(base, name)

        out.append(
            JointActuatorValues(
                joint,
                pick("motor"),
                pick("gearbox"),
                float(pick("gear_ratio")),
                float(pick("mechanical_stiffness")),
                float(pick("software_stiffness")),
            )
        )
    return out


def free_variables(study: ArmStudy, n_joints: int, joint_names: list[str] | None = None) -> dict[str, int]:
    """Number of free scalar design variables, by name (per joint unless ``joint_names`` are given).

    With ``joint_names``, the joints of an actuator module count once for the variables they share.
    """
    counts: dict[str, int] = {}
    design = study.design
    sharing = {
        name for group in study.actuators.modules for name in group[1:] if joint_names and name in joint_names
    }
    for name in (*PER_JOINT_VARIABLES, "threshold", "position_error", "approach_velocity"):
        spec = getattr(design, name)
        if spec is None:
            continue
        if name in PER_JOINT_VARIABLES:
            bounds = _per_joint_bounds(spec, n_joints, joint_names)
            shared = [j in sharing and name in MODULE_VARIABLES for j in joint_names or [""] * len(bounds)]
            free = sum(b.free for b, s in zip(bounds, shared, strict=True) if not s)
        else:
            free = int(spec.free)
        if free:
            counts[name] = free
    return counts


def _per_joint_bounds(spec: Any, n_joints: int, joint_names: list[str] | None) -> list[Any]:
    if joint_names is None:
        return [spec] * n_joints
    return [spec.joints.get(name, spec) for name in joint_names]


def per_joint_bounds(spec: Any, joint_names: list[str]) -> list[tuple[float, float]]:
    """``(lower, upper)`` per joint of a per-joint design variable (SI units)."""
    return [b.bounds for b in _per_joint_bounds(spec, len(joint_names), joint_names)]


def describe_study(loaded: LoadedStudy, load_robot: bool = True) -> str:
    """A one-line summary of a study.

    With ``load_robot`` the motors and (arm studies) the robot are loaded and checked, raising
    :class:`StudyFileError` at the offending line.
    """
    study = loaded.study
    if isinstance(study, ActuatorStudy):
        if load_robot:
            check_motors(loaded)
        return (
            f"actuator study {study.name!r}: {', '.join(study.actuators)} at a {study.load.lever * 1e3:g} mm lever, "
            f"{study.velocities.count} velocities in [{study.velocities.min:g}, {study.velocities.max:g}] m/s"
        )
    assert isinstance(study, ArmStudy)
    robot = study.robot.example_robot_data or study.robot.urdf
    text = f"arm study {study.name!r} on {robot}"
    n_joints = None
    if load_robot:
        check_motors(loaded)
        arm = load_arm(loaded)
        n_joints = len(arm.joint_names)
        n_config, n_dir = sample_counts(loaded, arm)  # random samples are counted, not drawn
        text += f" ({n_joints} joints: {', '.join(arm.joint_names)}), {n_config} configurations x {n_dir} directions"
        if study.samples.configurations.random is not None:
            text += " (those feasible there), drawn in the contact domain"
        cycle_summary = describe_duty_cycle(study_duty_cycle(loaded, arm), study, prismatic_joints(arm))
    else:
        cycle_summary = _duty_cycle_spec_summary(study)
    free = free_variables(study, n_joints or 1, list(arm.joint_names) if load_robot else None)

    def count(name: str, number: int) -> str:
        per_joint = name in PER_JOINT_VARIABLES and n_joints is None
        return f"{name} (per joint)" if per_joint else f"{name} ({number})"

    text += "; free design variables: " + (
        ", ".join(count(name, number) for name, number in free.items()) if free else "none"
    )
    text += "; objective: " + " + ".join(
        (f"{w:g} x " if w != 1 else "") + name for name, w in study.objective.items()
    )
    if study.pareto is not None:
        text += f"; Pareto front of {' vs '.join(study.pareto.objectives)} ({study.pareto.points} points)"
    return f"{text}; {cycle_summary}"


def _duty_cycle_spec_summary(study: ArmStudy) -> str:
    """What the study's duty cycle is, without the robot (its numbers need the arm)."""
    spec = study.duty_cycle
    if spec is None:
        return static_requirement(study)
    source = f"from {spec.file}" if spec.file is not None else f"through {len(spec.via or [])} via points"
    return f"duty cycle {source} (not loaded)"
