"""The duty cycle of an arm study: built from the study's ``duty_cycle`` section, every problem located.

A trajectory file's own problems (a missing joint column, non-increasing time, NaN, a wrong unit, too few or
too coarse samples) are reported at the study's ``duty_cycle.file`` line, quoting the CSV file and line
(``cycle.csv:17: ...``). Columns that name no joint of the arm are ignored (a recording often holds more, e.g.
a gripper or a time stamp). Via points and per-joint limits are checked against the arm's joints and limits.

Without a duty cycle the torque requirement is the static one: gravity (and the payload) over the contact
samples; :func:`describe_duty_cycle` says so.

The payload is given once: as ``duty_cycle.payload`` (mass and inertia), or, as before duty cycles existed,
as ``constraints.payload`` (a mass), which a duty cycle then carries as a point mass. Both at once is an error.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from .._io import not_a_file
from ..arm.duty_cycle import DutyCycle, Payload
from ..arm.kinematic_tree import joint_kinematics
from ..arm.rating import Rating
from ..errors import InvalidParameter, StudyFileError, StudyProblem, TrajectoryError
from .load import LoadedStudy
from .motion_specs import DutyCycleSpec
from .schema import ArmStudy

if TYPE_CHECKING:
    from ..arm import Arm

STATIC_REQUIREMENT = (
    "no duty cycle: the torque requirement is the static one (gravity and payload over the contact samples)"
)
"""What a study without a duty cycle says about its torque requirement."""

_SECTION = ("duty_cycle",)


def payload_of(study: ArmStudy) -> Payload | None:
    """The payload the study's arm carries: ``duty_cycle.payload``, else ``constraints.payload`` as a point mass."""
    spec = study.duty_cycle.payload if study.duty_cycle is not None else None
    if spec is not None:
        return Payload(spec.mass, np.asarray(spec.inertia, dtype=float))
    mass = study.constraints.payload
    return Payload(mass) if mass > 0 else None


def study_duty_cycle(loaded: LoadedStudy, arm: Arm) -> DutyCycle | None:
    """The duty cycle of an arm study for ``arm``, or ``None`` when the study gives none.

    Raises
    ------
    StudyFileError: at the ``duty_cycle`` line of the problem; a trajectory file's problems name the CSV file
        and line.
    """
    study = loaded.study
    assert isinstance(study, ArmStudy)
    spec = study.duty_cycle
    if spec is None:
        return None
    payload = payload_of(study)
    if spec.file is not None:
        return _from_file(loaded, arm, spec.file, payload)
    return _through_via_points(loaded, arm, spec, payload)


def study_rating(loaded: LoadedStudy, arm: Arm) -> Rating | None:
    """The rating of an arm study for ``arm`` (per-joint figures in its joint order), or None without one.

    Raises
    ------
    StudyFileError: at the ``rating`` entry that names no joint of the arm or misses one.
    """
    study = loaded.study
    assert isinstance(study, ArmStudy)
    spec = study.rating
    joints, problems = list(arm.joint_names), list[StudyProblem]()
    figures = {
        name: None if value is None else per_joint_values(loaded, ("rating", name), value, joints, problems)
        for name in ("joint_speeds", "joint_accelerations", "stopping_time")
        for value in (getattr(spec, name),)
    }
    if problems:
        raise StudyFileError(loaded.source.file, problems)
    if all(value is None for value in figures.values()):
        return None
    payload = (
        payload_of(study) if spec.payload is None else (Payload(spec.payload) if spec.payload > 0 else None)
    )
    return Rating(payload=payload, **figures)


def static_requirement(study: ArmStudy) -> str:
    """What a study without a duty cycle requires of its joints' torques (given torques, or gravity)."""
    if study.constraints.torque_required is not None:
        return "no duty cycle: the torque requirement is constraints.torque_required (static)"
    return STATIC_REQUIREMENT


def prismatic_joints(arm: Arm) -> list[str]:
    """The arm's prismatic joints (positions in m, speeds in m/s); the others are revolute."""
    kinds = joint_kinematics(arm.model, arm.name)
    return [name for name, joint in zip(arm.joint_names, kinds, strict=True) if not joint.revolute]


def _from_file(loaded: LoadedStudy, arm: Arm, file: str, payload: Payload | None) -> DutyCycle:
    where = (*_SECTION, "file")
    path = loaded.path(file)
    if (why := not_a_file(path)) is not None:  # a folder, a pipe or a device is not 'no such file'
        raise loaded.fail(where, f"{file!r} ({why})", "a path relative to the study file's folder")
    try:
        cycle = DutyCycle.from_csv(path, arm.joint_names, payload, prismatic=prismatic_joints(arm))
    except TrajectoryError as error:
        located = f"{file}:{error.line}" if error.line is not None else file
        raise loaded.fail(
            where,
            f"{located}: {error.reason}",
            "a trajectory file: a time column and one position column per joint, units in the header",
        ) from None
    lower, upper = position_limits(arm)
    outside = np.argwhere((cycle.q < lower) | (cycle.q > upper))
    if outside.size:
        sample, j = map(int, outside[0])
        raise loaded.fail(
            where,
            f"{file}: {arm.joint_names[j]} at {cycle.q[sample, j]:.6g} at t = {cycle.t[sample]:.6g} s",
            f"positions within the joint limits [{lower[j]:.6g}, {upper[j]:.6g}] (rad or m)",
        )
    return cycle


def _through_via_points(
    loaded: LoadedStudy, arm: Arm, spec: DutyCycleSpec, payload: Payload | None
) -> DutyCycle:
    joints = list(arm.joint_names)
    problems: list[StudyProblem] = []
    via = spec.via or []
    lower, upper = position_limits(arm)
    for index, point in enumerate(via):
        if len(point) != len(joints):
            problems.append(
                loaded.problem(
                    (*_SECTION, "via", index),
                    f"{len(point)} joint positions",
                    f"{len(joints)}, one per joint: " + ", ".join(joints),
                )
            )
            continue
        outside = [j for j, value in enumerate(point) if not lower[j] <= value <= upper[j]]
        if outside:
            j = outside[0]
            problems.append(
                loaded.problem(
                    (*_SECTION, "via", index, j),
                    f"{point[j]:.6g} for joint {joints[j]}",
                    f"a position within the joint limits [{lower[j]:.6g}, {upper[j]:.6g}] (rad or m)",
                )
            )
    limits = {
        name: per_joint_values(loaded, (*_SECTION, name), getattr(spec, name), joints, problems)
        for name in ("max_speed", "max_acceleration")
    }
    if problems:
        raise StudyFileError(loaded.source.file, problems)
    try:
        return DutyCycle.through_via_points(
            via,
            joints,
            limits["max_speed"],
            limits["max_acceleration"],
            rate=float(spec.rate),  # type: ignore[arg-type]
            dwell=spec.dwell,
            payload=payload,
        )
    except InvalidParameter as error:  # pragma: no cover - the schema checks the same bounds first
        raise loaded.fail(_SECTION, str(error), "a motion through the via points") from None


def position_limits(arm: Arm) -> tuple[np.ndarray, np.ndarray]:
    """The URDF's position limits per joint [rad or m]; infinite where it gives none.

    As :meth:`~collision_reflex.arm.Arm.joint_limits` reads them, without its stand-in full turn for a revolute
    joint without limits (continuous, or limits that are empty or huge): a via point may be anywhere there.
    """
    lower, upper = np.full(arm.nv, -np.inf), np.full(arm.nv, np.inf)
    low, high = arm.model.lowerPositionLimit, arm.model.upperPositionLimit
    real, _ = arm.joint_limits()
    for v, joint in enumerate(joint_kinematics(arm.model, arm.name)):
        lo, hi = (low[joint.idx_q], high[joint.idx_q]) if joint.nq == 1 else (np.nan, np.nan)
        if lo == real[v] and lo < hi:  # joint_limits kept the URDF's limits
            lower[v], upper[v] = lo, hi
    return lower, upper


def per_joint_values(
    loaded: LoadedStudy, path: tuple[str, ...], value: Any, joints: list[str], problems: list[StudyProblem]
) -> np.ndarray:
    """A limit at ``path`` given for every joint (a number) or by joint name (a mapping naming every joint)."""
    if not isinstance(value, Mapping):
        return np.full(len(joints), float(value))
    unknown = [key for key in value if key not in joints]
    missing = [joint for joint in joints if joint not in value]
    for key in unknown:
        problems.append(
            loaded.problem((*path, key), f"joint {key!r}, not a joint of the arm", ", ".join(joints))
        )
    if missing:
        problems.append(
            loaded.problem(
                path,
                "no limit for " + ", ".join(missing),
                "a limit for every joint (or one number for all)",
            )
        )
    return np.array([float(value.get(joint, np.nan)) for joint in joints])


def describe_duty_cycle(cycle: DutyCycle | None, study: ArmStudy, prismatic: Sequence[str] = ()) -> str:
    """One line: the cycle's duration, samples, peak joint speed (and which joint), payload; or the static note.

    The peak speed is the largest over the revolute joints [rad/s], and over the ``prismatic`` ones [m/s].
    """
    if cycle is None:
        return static_requirement(study)
    speeds = np.max(np.abs(cycle.qd), axis=0)
    peaks = []
    for unit, linear in (("rad/s", False), ("m/s", True)):
        joints = [j for j, name in enumerate(cycle.joint_names) if (name in prismatic) == linear]
        if joints:
            fastest = max(joints, key=lambda j: speeds[j])
            peaks.append(f"{speeds[fastest]:.4g} {unit} ({cycle.joint_names[fastest]})")
    payload = f", payload {cycle.payload.mass:g} kg" if cycle.payload is not None else ", no payload"
    return (
        f"duty cycle of {cycle.duration:.4g} s, {cycle.t.size} samples, peak joint speed "
        f"{' and '.join(peaks)}{payload}"
    )
