"""The fixed actuation choices a design varies within.

They are the reference motor, the scaling law, the mechanical stiffness, the sensing scheme and the reaction
model.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from .. import _validate
from ..hardware.actuators import REFLECTED_INERTIA_PLACEMENTS
from ..hardware.motors import Motor
from ..model.impulse import REACTION_MODES
from ..model.sensing import sensing_scheme
from .space import OPTIMIZED_SENSING_SCHEMES


@dataclass(frozen=True)
class ActuatorTechnology:
    """The fixed choices of actuation the design varies within.

    reference_motor: motor every joint's motor is scaled from.
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

    reference_motor: Motor
    mechanical_stiffness: float | Sequence[float]
    scaling_law: str = "haddadin"
    sensing: str = "force"
    reaction: str = "at_rest"
    reflected_inertia_in: str = "robot"

    def __post_init__(self) -> None:
        _validate.positive("mechanical_stiffness", np.asarray(self.mechanical_stiffness, dtype=float))
        object.__setattr__(self, "sensing", sensing_scheme(self.sensing, OPTIMIZED_SENSING_SCHEMES))
        _validate.choice("reaction", self.reaction, REACTION_MODES)
        _validate.choice("reflected_inertia_in", self.reflected_inertia_in, REFLECTED_INERTIA_PLACEMENTS)

    def joint_mechanical_stiffness(self, n_joints: int) -> np.ndarray:
        """The mechanical stiffness of each of ``n_joints`` joints [N m/rad], shape (n_joints,)."""
        return np.broadcast_to(np.asarray(self.mechanical_stiffness, dtype=float), (n_joints,)).copy()
