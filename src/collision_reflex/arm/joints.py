"""Per-joint actuation of an arm and the checks of per-joint input arrays.

The actuation: reflected inertia, torque limit, stiffnesses, motor mass.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from .. import _validate
from ..errors import InvalidParameter


@dataclass(frozen=True)
class JointParameters:
    """Per-joint actuation of an arm, arrays of shape (nv,).

    reflected_inertia: rotor (and gearbox) inertia seen at the joint, ``N^2 (J_m + J_g)`` [kg m^2], >= 0.
    torque_limit: largest output torque of the joint [N m], > 0 (``nan`` when unknown).
    stiffness: lumped joint stiffness while sensing, mechanical and software springs in series [N m/rad].
    mechanical_stiffness: joint mechanical stiffness, the spring left during the reaction [N m/rad].
    motor_mass: mass of the joint's motor (and gearbox), carried by the parent link at the joint [kg].
    """

    reflected_inertia: np.ndarray
    torque_limit: np.ndarray
    stiffness: np.ndarray
    mechanical_stiffness: np.ndarray
    motor_mass: np.ndarray

    def __post_init__(self) -> None:
        arrays = [
            np.atleast_1d(_validate.real(n, getattr(self, n), "real numbers, one per joint"))
            for n in _JOINT_FIELDS
        ]
        size = max(a.size for a in arrays)
        for name, array in zip(_JOINT_FIELDS, arrays, strict=True):
            if array.ndim != 1 or array.size not in (1, size):
                raise InvalidParameter(name, array, f"one value or {size} values, one per joint")
            array = np.broadcast_to(array, (size,)).copy()
            array.flags.writeable = False
            object.__setattr__(self, name, array)
        _validate.non_negative("reflected_inertia", self.reflected_inertia)
        _validate.non_negative("motor_mass", self.motor_mass)
        _validate.positive("stiffness", self.stiffness, allow_inf=True)
        _validate.positive("mechanical_stiffness", self.mechanical_stiffness, allow_inf=True)
        known = self.torque_limit[~np.isnan(self.torque_limit)]
        _validate.positive("torque_limit", known, allow_inf=True)

    @property
    def size(self) -> int:
        """Number of joints."""
        return int(self.reflected_inertia.size)

    @classmethod
    def from_actuators(cls, actuators: Any, nv: int) -> JointParameters:
        """From one actuator per joint, or one actuator used at every joint.

        An actuator is anything with ``reflected_inertia`` [kg m^2], ``peak_torque`` [N m], ``stiffness`` and
        ``mechanical_stiffness`` [N m/rad] and ``mass`` [kg] (:class:`collision_reflex.hardware.actuators.Actuator`).
        """
        nv = joint_count("nv", nv)
        items = list(actuators) if isinstance(actuators, list | tuple) else [actuators] * nv
        if len(items) != nv:
            raise InvalidParameter(
                "actuators", f"{len(items)} actuators", f"one actuator, or {nv} (one per joint)"
            )
        try:
            return cls(
                reflected_inertia=np.array([float(a.reflected_inertia) for a in items]),
                torque_limit=np.array([float(a.peak_torque) for a in items]),
                stiffness=np.array([float(a.stiffness) for a in items]),
                mechanical_stiffness=np.array([float(a.mechanical_stiffness) for a in items]),
                motor_mass=np.array([float(a.mass) for a in items]),
            )
        except InvalidParameter:
            raise
        except (AttributeError, TypeError, ValueError) as error:  # a missing or non-numeric attribute
            raise InvalidParameter(
                "actuators",
                actuators,
                "Actuator objects (with reflected_inertia, peak_torque, stiffness, mechanical_stiffness, mass)",
                str(error),
            ) from None


MAX_JOINTS = 10_000
"""Most joints an arm may have: far beyond any robot's, so that a wrong count is refused before allocating."""


def joint_count(name: str, value: Any) -> int:
    """``value`` as a number of joints, a whole number in [1, :data:`MAX_JOINTS`]; else raise."""
    return _validate.integer(name, value, 1, MAX_JOINTS)


_JOINT_FIELDS = ("reflected_inertia", "torque_limit", "stiffness", "mechanical_stiffness", "motor_mass")


def joint_array(
    name: str, value: Any, nv: int, *, allow_inf: bool = False, allow_zero: bool = False
) -> np.ndarray:
    """``value`` as one float per joint, (nv,), checked: a scalar is broadcast; NaN (unknown) is refused."""
    nv = joint_count("nv", nv)
    hint = "the URDF gives none for some joint; pass actuators= to the Arm or give the values explicitly"
    array = _validate.real(name, value, f"real numbers, one value or {nv}, one per joint")
    if array.ndim > 1 or array.size not in (1, nv):
        raise InvalidParameter(name, array, f"one value or {nv} values, one per joint")
    if np.any(np.isnan(array)):
        raise InvalidParameter(name, value, "known values for every joint", hint)
    try:
        if allow_zero:
            _validate.non_negative(name, array)
        else:
            _validate.positive(name, array, allow_inf=allow_inf)
    except InvalidParameter as error:
        raise InvalidParameter(name, value, error.allowed, hint) from None
    return np.broadcast_to(array, (nv,)).astype(float)
