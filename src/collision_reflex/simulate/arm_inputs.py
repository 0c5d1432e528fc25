"""The validated inputs of a simulated arm collision and the closed form at its impact configuration.

The joints (configuration, direction and joint parameters, the arm's where not given), the controller
(detector, reaction and drive) and the arm-level closed form the simulation is compared with, with the reference
motion it assumes; see :mod:`collision_reflex.simulate.arm` for the model.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from .. import _validate
from ..arm.effective import effective_parameters
from ..errors import InvalidParameter
from ..model.impulse import phase_impulses, series_stiffness, sprung_reaction, total_impulse
from .dynamics import admittance_share

_CURRENT_LEVER_SHARE = 0.1  # joints with a smaller share of the largest lever sense no current by default


@dataclass(frozen=True)
class ArmJoints:
    """The validated inputs of an arm collision.

    Impact configuration (nv,) [rad], unit direction (task_dim,), and per joint (nv,) the mechanical and
    software stiffness [N m/rad], the reflected inertia [kg m^2] and the torque limit [N m]; the arm's motor
    masses (nv,) [kg].
    """

    q0: np.ndarray
    u: np.ndarray
    k_m: np.ndarray
    k_s: np.ndarray
    inertia: np.ndarray
    tau_max: np.ndarray
    motor_mass: np.ndarray


def arm_joints(
    arm: Any,
    q: Any,
    direction: Any,
    software_stiffness: Any,
    mechanical_stiffness: Any,
    reflected_inertia: Any,
    torque_limit: Any,
) -> ArmJoints:
    """Check the configuration, the direction and the joint parameters (the arm's where not given)."""
    nv = int(arm.nv)
    if arm.nq != nv:
        raise InvalidParameter(
            "arm",
            arm.name,
            "one configuration coordinate per joint",
            "continuous joints are not supported here",
        )
    params = arm.joint_parameters
    k_m = _joint(
        "mechanical_stiffness",
        params.mechanical_stiffness if mechanical_stiffness is None else mechanical_stiffness,
        nv,
        allow_inf=True,
    )
    if not np.all(np.isfinite(k_m)):
        raise InvalidParameter(
            "mechanical_stiffness",
            k_m,
            "finite joint stiffnesses [N m/rad]",
            "the joints must be elastic: give mechanical_stiffness",
        )
    k_s = _joint("software_stiffness", software_stiffness, nv, allow_inf=True)
    inertia = _joint(
        "reflected_inertia", params.reflected_inertia if reflected_inertia is None else reflected_inertia, nv
    )
    tau_max = _joint(
        "torque_limit", params.torque_limit if torque_limit is None else torque_limit, nv, allow_inf=True
    )
    q0 = np.asarray(q, dtype=float).reshape(-1)
    if q0.shape != (nv,) or not np.all(np.isfinite(q0)):
        raise InvalidParameter("q", q, f"{nv} finite joint angles [rad]")
    u = np.asarray(direction, dtype=float).reshape(-1)
    if u.shape != (arm.task_dim,) or not np.all(np.isfinite(u)) or np.linalg.norm(u) == 0:
        raise InvalidParameter("direction", direction, f"a nonzero vector of {arm.task_dim} task coordinates")
    space = arm.configuration_space
    lower, upper = space.lower_position_limit, space.upper_position_limit
    if np.any(q0 <= lower) or np.any(q0 >= upper):
        raise InvalidParameter(
            "q", q, "a configuration strictly inside the joint limits", "q is at or past one"
        )
    u = u / np.linalg.norm(u)
    return ArmJoints(q0, u, k_m, k_s, inertia, tau_max, np.asarray(params.motor_mass, dtype=float))


def _joint(name: str, value: Any, nv: int, allow_inf: bool = False) -> np.ndarray:
    """One value per joint (nv,), a scalar broadcast, each > 0."""
    array = (
        np.broadcast_to(np.asarray(value, dtype=float), (nv,)).copy()
        if np.ndim(value) == 0
        else (np.asarray(value, dtype=float).reshape(-1))
    )
    if array.shape != (nv,):
        raise InvalidParameter(name, value, f"one value or {nv} values, one per joint")
    _validate.positive(name, array, allow_inf=allow_inf)
    return array


@dataclass(frozen=True)
class ArmSensing:
    """The controller: detector, reaction and drive.

    Scheme, observer gain [1/s], sample rate [Hz] (or None), per-joint current thresholds [N m] (nv,), the
    retreat, the blanking after the impact [s] (None: the scheme's default), the drive and its joint damping
    [N m s/rad] (nv,), the force threshold [N].
    """

    detection: str
    observer_gain: float
    sample_rate: float | None
    current_threshold: np.ndarray
    retreat: str
    blanking: float | None
    drive: str
    software_damping: np.ndarray
    threshold: float


def arm_sensing(
    arm: Any,
    joints: ArmJoints,
    threshold: float,
    detection: str,
    observer_gain: float,
    sample_rate: float | None,
    current_threshold: Any,
    retreat: str,
    blanking: float | None,
    drive: str,
    software_damping: Any,
) -> ArmSensing:
    """The controller of an arm collision, its per-joint settings checked or made from the joints.

    The current thresholds [N m] are ``current_threshold`` or made from ``threshold`` [N] (see
    :func:`collision_reflex.simulate.simulate_arm_collision` for the other settings).
    """
    return ArmSensing(
        detection,
        float(observer_gain),
        None if sample_rate is None else float(sample_rate),
        _current_threshold(arm, joints, threshold, current_threshold),
        retreat,
        blanking,
        drive,
        _impedance_damping(joints, drive, software_damping),
        threshold,
    )


def _impedance_damping(joints: ArmJoints, drive: str, software_damping: Any) -> np.ndarray:
    """The impedance drive's joint damping (nv,) [N m s/rad]; its software stiffness must be finite."""
    nv = joints.q0.size
    damping = np.broadcast_to(np.asarray(software_damping, dtype=float), (nv,)).copy()
    _validate.non_negative("software_damping", damping)
    if drive == "impedance" and not np.all(np.isfinite(joints.k_s)):
        raise InvalidParameter(
            "software_stiffness",
            joints.k_s,
            "finite joint stiffnesses [N m/rad]",
            "the impedance drive needs them",
        )
    return damping


def _current_threshold(arm: Any, joints: ArmJoints, threshold: float, given: Any) -> np.ndarray:
    """Per-joint motor-torque thresholds [N m]: ``given``, or ``threshold |J(q0)^T u|``.

    By default a joint whose lever is below a tenth of the largest is left out (an infinite threshold): it
    barely feels the contact, and a threshold that small would trip on the links' inertial torques.
    """
    if given is not None:
        return _joint("current_threshold", given, joints.q0.size, allow_inf=True)
    lever = np.abs(arm.kinematics(joints.q0[None]).jacobian[0].T @ joints.u)
    return np.where(lever >= _CURRENT_LEVER_SHARE * float(np.max(lever)), threshold * lever, math.inf)


@dataclass(frozen=True)
class ImpactClosedForm:
    """The arm-level closed form at the impact configuration, and the reference motion it assumes.

    effective: the effective 1D parameters (``m_f, m_r, k, k_m, F_a, a``; SI).
    share: per joint, the share of the reference velocity the admittance follows (nv,).
    reference_rate: the motors' reference velocity ``J(q0)^+ u v0`` (nv,) [rad/s].
    robot_velocity: the robot velocity at detection along ``u`` [m/s].
    impulse: the closed form's impulse [N*s].
    sprung_impulse: the same with the spring's push on the robot mass in the reaction [N*s].
    detected_impulse: its impact and sensing impulses [N*s].
    """

    effective: dict[str, float]
    share: np.ndarray
    reference_rate: np.ndarray
    robot_velocity: float
    impulse: float
    sprung_impulse: float
    detected_impulse: float


def impact_closed_form(
    arm: Any, joints: ArmJoints, approach_velocity: float, threshold: float, reaction: str
) -> ImpactClosedForm:
    """Issue 4's effective parameters at ``q0`` along ``u`` through :mod:`collision_reflex.model.impulse`."""
    u = joints.u
    samples = arm.kinematics(joints.q0[None])
    effective = effective_parameters(
        samples,
        u[None],
        joints.inertia,
        series_stiffness(joints.k_m, joints.k_s),
        joints.k_m,
        joints.tau_max,
        motor_mass=joints.motor_mass if np.any(joints.motor_mass > 0) else None,
    )
    eff = {name: float(getattr(effective, name)[0, 0]) for name in ("m_f", "m_r", "k", "k_m", "F_a", "a")}
    if bool(effective.singular[0, 0]):
        raise InvalidParameter(
            "direction", u, "a direction the arm can move along at q", "q is singular there"
        )
    jac0 = samples.jacobian[0]
    reachable = jac0 @ (np.linalg.pinv(jac0) @ u)
    if np.linalg.norm(reachable - u) > 1e-6:
        raise InvalidParameter("direction", u, "a direction the contact point can move along at q")
    share = admittance_share(joints.k_m, joints.k_s)
    reference_rate = np.linalg.pinv(jac0) @ u * approach_velocity  # theta_ref' [rad/s]
    robot_velocity = float(u @ jac0 @ (share * reference_rate))
    impulse = total_impulse(
        eff["m_f"],
        eff["k"],
        eff["k_m"],
        threshold,
        eff["a"],
        approach_velocity,
        reaction,
        robot_velocity if reaction == "moving" else None,
    )
    v_r = robot_velocity if reaction == "moving" else None
    phases = phase_impulses(
        eff["m_f"], eff["k"], eff["k_m"], threshold, eff["a"], approach_velocity, reaction, v_r
    )
    detected = float(phases.initial + phases.sensing)
    _, sprung = sprung_reaction(threshold, eff["k_m"], eff["F_a"], eff["m_r"], max(v_r or 0.0, 0.0))
    return ImpactClosedForm(
        eff, share, reference_rate, robot_velocity, float(impulse), detected + sprung, detected
    )
