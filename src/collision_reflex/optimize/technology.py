"""The fixed actuation choices a design varies within.

They are the reference motor (one for every joint, or one per joint), the scaling law, the mechanical
stiffness, the sensing scheme and the reaction model. A catalogue motor is a joint's reference motor with its
stator diameter and stack length fixed at its own: its quantities are then its datasheet figures (scale factor
one), which is how a design is built from catalogue parts.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from .. import _validate
from ..errors import InvalidParameter
from ..hardware.actuators import REFLECTED_INERTIA_PLACEMENTS
from ..hardware.motors import Motor, MotorQuantities, scaled_motor_quantities
from ..model.impulse import REACTION_MODES
from ..model.sensing import sensing_scheme
from .space import OPTIMIZED_SENSING_SCHEMES


@dataclass(frozen=True)
class ActuatorTechnology:
    """The fixed choices of actuation the design varies within.

    reference_motor: motor every joint's motor is scaled from, or one motor per joint (a tuple).
    scaling_law: motor scaling law name (see :data:`collision_reflex.hardware.motors.SCALING_LAWS`).
    mechanical_stiffness: joint mechanical stiffness [N m/rad], one value or one per joint, finite > 0: it is
        the only spring left in the reaction phase.
    sensing: ``"force"`` (contact-force threshold) or ``"position"`` (contact position-error threshold), see
        :data:`collision_reflex.optimize.space.OPTIMIZED_SENSING_SCHEMES`.
    reaction: reaction-phase model, ``"at_rest"`` (the paper's) or ``"moving"``.
    reflected_inertia_in: where the reflected rotor inertia ``N^2 J_m`` acts. ``"robot"`` (default, the paper's
        arm model): behind the joint springs, in the robot mass ``m_r`` of the reaction phase only.
        ``"finger"``: also rigidly on the link side, in the finger mass ``m_f`` of the impact phase -- a stiff
        transmission with the compliance at the contact, as the paper measured for its geared A8 actuator
        (fitted finger mass 20 kg against 0.12 kg direct-drive).
    """

    reference_motor: Motor | tuple[Motor, ...]
    mechanical_stiffness: float | Sequence[float]
    scaling_law: str = "haddadin"
    sensing: str = "force"
    reaction: str = "at_rest"
    reflected_inertia_in: str = "robot"

    def __post_init__(self) -> None:
        _validate.positive("mechanical_stiffness", np.asarray(self.mechanical_stiffness, dtype=float))
        if not isinstance(self.reference_motor, Motor):
            motors = tuple(self.reference_motor)
            if not motors or not all(isinstance(m, Motor) for m in motors):
                raise InvalidParameter(
                    "reference_motor", self.reference_motor, "a Motor or a tuple of Motors"
                )
            object.__setattr__(self, "reference_motor", motors)
        object.__setattr__(self, "sensing", sensing_scheme(self.sensing, OPTIMIZED_SENSING_SCHEMES))
        _validate.choice("reaction", self.reaction, REACTION_MODES)
        _validate.choice("reflected_inertia_in", self.reflected_inertia_in, REFLECTED_INERTIA_PLACEMENTS)

    def joint_mechanical_stiffness(self, n_joints: int) -> np.ndarray:
        """The mechanical stiffness of each of ``n_joints`` joints [N m/rad], shape (n_joints,)."""
        return np.broadcast_to(np.asarray(self.mechanical_stiffness, dtype=float), (n_joints,)).copy()

    @property
    def motors(self) -> tuple[Motor, ...]:
        """The reference motors: the one of every joint, or each joint's."""
        return (self.reference_motor,) if isinstance(self.reference_motor, Motor) else self.reference_motor

    def joint_motors(self, n_joints: int) -> tuple[Motor, ...]:
        """The reference motor of each of ``n_joints`` joints."""
        if isinstance(self.reference_motor, Motor):
            return (self.reference_motor,) * n_joints
        if len(self.reference_motor) != n_joints:
            raise InvalidParameter(
                "reference_motor", len(self.reference_motor), f"one motor for all joints or {n_joints} motors"
            )
        return self.reference_motor

    def motor_quantities(self, stator_diameter: Any, stack_length: Any) -> MotorQuantities:
        """Each joint's motor quantities at its stator diameter and stack length [m] (one entry per joint).

        Works on NumPy arrays and CasADi columns alike (:func:`~collision_reflex.hardware.motors.
        scaled_motor_quantities`); ``max_speed`` is None when any joint's reference motor has none.
        """
        if isinstance(self.reference_motor, Motor):
            return scaled_motor_quantities(
                self.reference_motor, stator_diameter, stack_length, self.scaling_law
            )
        import casadi as ca  # lazily: the package imports without CasADi's start-up cost

        symbolic = isinstance(stator_diameter, (ca.MX, ca.SX, ca.DM))
        motors = self.joint_motors(stator_diameter.shape[0] if symbolic else np.size(stator_diameter))
        diameters = (
            stator_diameter if symbolic else np.broadcast_to(np.asarray(stator_diameter, float), len(motors))
        )
        lengths = stack_length if symbolic else np.broadcast_to(np.asarray(stack_length, float), len(motors))
        joints = [
            scaled_motor_quantities(motor, diameters[j], lengths[j], self.scaling_law)
            for j, motor in enumerate(motors)
        ]

        def stacked(field: str) -> Any:
            parts = [getattr(q, field) for q in joints]
            return ca.vertcat(*parts) if symbolic else np.array(parts, dtype=float)

        speeds = None if any(q.max_speed is None for q in joints) else stacked("max_speed")
        return MotorQuantities(
            stacked("rotor_inertia"),
            stacked("peak_torque"),
            stacked("continuous_torque"),
            stacked("mass"),
            speeds,
        )

    def default_stack_lengths(self, n_joints: int) -> list[float]:
        """Each joint's reference motor's stack length [m]: the stack length when the design leaves it out."""
        return [motor.stack_length for motor in self.joint_motors(n_joints)]
