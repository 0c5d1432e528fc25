"""The actuation of an arm's joints: its joint parameters, scaled motors per joint, and the sensing they give.

These are the parts of :class:`collision_reflex.arm.Arm` that depend only on the actuators and the number of
joints, not on the kinematics.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt

from .. import _validate
from ..errors import InvalidParameter
from ..hardware.actuators import Actuator, ForceThreshold, gear_ratio_for
from ..hardware.motors import reference_motor
from .joints import JointParameters, joint_array, joint_count

if TYPE_CHECKING:
    from ..hardware.actuators import CurrentThreshold, PositionThreshold
    from ..hardware.motors import Motor


def joint_parameters(
    actuators: Any, nv: int, armature: np.ndarray, torque_limit: np.ndarray
) -> JointParameters:
    """The :class:`JointParameters` of ``actuators`` (see :class:`~collision_reflex.arm.Arm`) for ``nv`` joints.

    Without actuators: the model's ``armature`` [kg m^2] and ``torque_limit`` [N m] per joint, rigid joints and
    no motor masses.
    """
    nv = joint_count("nv", nv)
    if isinstance(actuators, JointParameters):
        params = actuators
    elif actuators is not None:
        params = JointParameters.from_actuators(actuators, nv)
    else:
        params = JointParameters(
            reflected_inertia=armature,
            torque_limit=torque_limit,
            stiffness=np.full(nv, np.inf),
            mechanical_stiffness=np.full(nv, np.inf),
            motor_mass=np.zeros(nv),
        )
    if params.size != nv:
        raise InvalidParameter("actuators", params.size, f"{nv} joints' parameters")
    return params


def scaled_actuators(
    stator_diameter: float,
    torque_required: npt.ArrayLike,
    nv: int,
    *,
    reference: Motor | None = None,
    law: str = "haddadin",
    mechanical_stiffness: npt.ArrayLike = np.inf,
    software_stiffness: npt.ArrayLike = np.inf,
    sensing: ForceThreshold | PositionThreshold | CurrentThreshold | None = None,
) -> list[Actuator]:
    """One scaled motor per joint, geared to meet a torque requirement: ``N_i = max(1, tau_req,i / tau_p(r))``.

    Parameters
    ----------
    stator_diameter: stator outer diameter of every motor [m] (the paper's ``r_m``).
    torque_required: output torque per joint [N m] (scalar or (nv,)).
    nv: number of joints.
    reference: the motor scaled from; default the Omni+ OPN-060-013-A (``motors.reference_motor``).
    law: scaling law name (``motors.SCALING_LAWS``).
    mechanical_stiffness, software_stiffness: joint springs [N m/rad] (scalar or (nv,)).
    sensing: a sensing scheme of :mod:`collision_reflex.hardware.actuators` for every joint; default a 3 N
        force threshold.
    """
    required = joint_array("torque_required", torque_required, nv)
    if np.ndim(_validate.positive("stator_diameter", stator_diameter)) != 0:
        raise InvalidParameter(
            "stator_diameter", stator_diameter, "one finite diameter > 0 [m] for every motor"
        )
    motor = (reference if reference is not None else reference_motor()).scaled(
        stator_diameter=stator_diameter, law=law
    )
    ratios = np.atleast_1d(gear_ratio_for(required, motor.peak_torque))
    k_mech = joint_array("mechanical_stiffness", mechanical_stiffness, nv, allow_inf=True)
    k_soft = joint_array("software_stiffness", software_stiffness, nv, allow_inf=True)
    scheme = ForceThreshold() if sensing is None else sensing
    return [Actuator(motor, float(ratios[i]), float(k_mech[i]), float(k_soft[i]), scheme) for i in range(nv)]


def sensing_options(actuators: tuple[Any, ...] | None) -> dict[str, Any]:
    """The sensing of ``actuators`` as keyword arguments of the effective parameters and impulses.

    ``{"sensing": "force", "threshold": F_s}`` [N] for force thresholds at the contact, or
    ``{"sensing": "current", "joint_threshold": tau_s}`` [N m] for the joint-side schemes (motor current,
    and joint position errors, whose threshold is the joint torque ``k e_th`` as well), where the first
    joint to reach its threshold detects the contact.
    """
    if not actuators:
        raise InvalidParameter(
            "actuators", None, "Actuator objects with sensing schemes", "give the threshold explicitly"
        )
    schemes = [actuator.sensing for actuator in actuators]
    if all(isinstance(scheme, ForceThreshold) for scheme in schemes):
        forces = {float(scheme.force) for scheme in schemes}
        if len(forces) > 1:
            raise InvalidParameter(
                "actuators", sorted(forces), "one contact-force threshold for the whole arm"
            )
        return {"sensing": "force", "threshold": forces.pop()}
    if any(isinstance(scheme, ForceThreshold) for scheme in schemes):
        raise InvalidParameter(
            "actuators", [type(s).__name__ for s in schemes], "force thresholds at every joint or at none"
        )
    torques = [
        scheme.joint_threshold_torque(actuator) for scheme, actuator in zip(schemes, actuators, strict=True)
    ]
    return {"sensing": "current", "joint_threshold": np.array(torques)}
