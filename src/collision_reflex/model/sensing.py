"""Sensing schemes: how contact is detected, and the threshold each scheme gives.

As in the paper's "Actuator Selection and the Collision Reflex" and its
experiments.

One vocabulary for the whole package:

- ``"force"``: a contact-force threshold ``F_s`` [N] (a force sensor or an external-force observer);
- ``"position"``: a position-error threshold ``e_th`` [m] (or [rad] at a joint), so ``F_s = k e_th`` grows with
  the stiffness ``k`` the error builds up against;
- ``"current"``: a motor-current (torque) threshold on the motor side of the transmission, so the joint-side
  threshold torque is ``N tau_s`` (plus any joint friction); at a contact the first joint to reach its
  threshold detects.

The formulas are plain arithmetic, so they take floats, NumPy arrays and CasADi expressions alike.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from .. import _validate
from .._backend import is_symbolic
from ..errors import InvalidParameter
from ..vocabulary import OPTIMIZED_SENSING_SCHEMES, SENSING_SCHEMES


def sensing_scheme(name: str, allowed: tuple[str, ...] = SENSING_SCHEMES) -> str:
    """The scheme called ``name``, checked against ``allowed``."""
    _validate.choice("sensing", name, allowed)
    return name


def threshold_force(sensing: str, threshold: Any, stiffness: Any) -> Any:
    """Force (or torque) at detection for the ``"force"`` and ``"position"`` schemes.

    Parameters
    ----------
    sensing: ``"force"`` or ``"position"``.
    threshold: ``F_s`` [N] for ``"force"``; the position-error threshold ``e_th`` [m] (or [rad]) for
        ``"position"``.
    stiffness: the stiffness the position error builds up against, ``k`` [N/m] (or [N m/rad]); unused for
        ``"force"``.

    Returns
    -------
    ``F_s`` [N] (or the joint torque [N m] for joint units): ``threshold`` itself, or ``k e_th``.
    """
    _validate.choice("sensing", sensing, OPTIMIZED_SENSING_SCHEMES)
    threshold = _validate.non_negative("threshold", threshold)
    if sensing == "force":
        return threshold
    return _validate.positive("stiffness", stiffness, allow_inf=True) * threshold


def current_threshold_torque(gear_ratio: Any, motor_torque: Any, friction_torque: Any = 0.0) -> Any:
    """Joint-side threshold torque of a motor-current threshold [N m]: ``N tau_s + tau_friction``.

    Parameters
    ----------
    gear_ratio: transmission ratio ``N`` [-].
    motor_torque: motor-side threshold torque ``tau_s`` [N m] (current times torque constant).
    friction_torque: joint-side friction the motor overcomes before the contact loads it [N m].
    """
    gear_ratio = _validate.positive("gear_ratio", gear_ratio)
    motor_torque = _validate.positive("motor_torque", motor_torque)
    friction_torque = _validate.non_negative("friction_torque", friction_torque)
    with _validate.combining(
        gear_ratio=gear_ratio, motor_torque=motor_torque, friction_torque=friction_torque
    ):
        torque = gear_ratio * motor_torque + friction_torque
    if not is_symbolic(torque) and not np.all(np.isfinite(torque)):  # Python floats overflow to inf silently
        raise InvalidParameter(
            "gear_ratio, motor_torque",
            (gear_ratio, motor_torque),
            "values whose N tau_s is below about 1.8e308",
        )
    return torque
