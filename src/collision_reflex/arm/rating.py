"""What a robot is rated for, and the motion states that rating asks of its joints.

A datasheet states a robot's rated payload, its joint speeds and accelerations and how fast it stops. Beside
holding the payload still (the static hold, :mod:`collision_reflex.optimize.constraints`), every joint must then
deliver, at every sampled configuration ``q``:

- **rated motion**: the joints moving at their rated speeds ``v`` while accelerating at their rated accelerations
  ``a``: the instant a trapezoidal move reaches its top speed, where speed and acceleration are both largest;
- **braking**: the joints stopping from their rated speeds within their stopping times ``t_s``, at the constant
  deceleration ``v / t_s`` (a protective stop brakes every joint at once).

Which way each joint moves is chosen per joint ``i`` so that the inertial torque adds to gravity's:
``qdd_j = sign(g_i) sign(M_ij) a_j`` gives ``|g_i + M_i. qdd| = |g_i| + sum_j |M_ij| a_j``, the largest joint-``i``
torque over every combination of rated accelerations (exact for the links and the payload at rest; the
motor masses, carried at the joints, change ``M`` little and the velocity terms follow the chosen directions).
So each configuration gives ``nv`` states per requirement, ``(q, s_i v, s_i a)``, for
:func:`collision_reflex.arm.dynamics.state_torques`, untimed (they add to the peak, not to the RMS).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ..errors import InvalidParameter
from .duty_cycle import Payload
from .dynamics import CycleTorques, state_torques

if TYPE_CHECKING:
    from .robot import Arm
    from .samples import ArmSamples

RATED_MOTION, BRAKING = "rated motion", "braking"
"""The rating's requirements, as reports name them."""


@dataclass(frozen=True, eq=False)
class Rating:
    """A robot's rating, per joint in the arm's joint order (None where the datasheet gives nothing).

    joint_speeds: (nv,) rated joint speeds [rad/s or m/s], > 0.
    joint_accelerations: (nv,) rated joint accelerations [rad/s^2 or m/s^2], > 0.
    stopping_time: (nv,) time to stop from the rated speed [s], > 0 (needs ``joint_speeds``).
    payload: the rated payload, carried in the rated motion and the braking (held at the contact point).
    """

    joint_speeds: np.ndarray | None = None
    joint_accelerations: np.ndarray | None = None
    stopping_time: np.ndarray | None = None
    payload: Payload | None = None

    def __post_init__(self) -> None:
        for name in ("joint_speeds", "joint_accelerations", "stopping_time"):
            value = getattr(self, name)
            if value is None:
                continue
            array = np.asarray(value, dtype=float)
            if array.ndim != 1 or array.size == 0 or not np.all(np.isfinite(array) & (array > 0)):
                raise InvalidParameter(name, value, "one finite value > 0 per joint")
            object.__setattr__(self, name, array)
        if self.stopping_time is not None and self.joint_speeds is None:
            raise InvalidParameter(
                "stopping_time", "given without joint_speeds", "the rated joint speeds it stops from"
            )
        if self.payload is not None and not isinstance(self.payload, Payload):
            raise InvalidParameter("payload", self.payload, "a Payload or None")

    @property
    def moves(self) -> bool:
        """True when the rating asks for motion (speeds or accelerations), not only a payload."""
        return self.joint_speeds is not None or self.joint_accelerations is not None

    def check_joints(self, nv: int) -> None:
        """Refuse per-joint figures that are not ``nv`` long."""
        for name in ("joint_speeds", "joint_accelerations", "stopping_time"):
            value = getattr(self, name)
            if value is not None and value.size != nv:
                raise InvalidParameter(name, value.size, f"{nv} values, one per joint")


def rated_torques(arm: Arm, kinematics: ArmSamples, rating: Rating) -> CycleTorques | None:
    """The rated motion's and the braking's states at every configuration of ``kinematics``, with their torques.

    None when the rating asks for no motion. See the module for the states.
    """
    if not rating.moves:
        return None
    nv = kinematics.mass_matrix.shape[-1]
    rating.check_joints(nv)
    speed = np.zeros(nv) if rating.joint_speeds is None else rating.joint_speeds
    acceleration = np.zeros(nv) if rating.joint_accelerations is None else rating.joint_accelerations
    n = kinematics.q.shape[0]
    # direction[k]: joint j moving alone, either way, for state k = (c, j, sign) of configuration c.
    direction = np.tile(np.repeat(np.eye(nv), 2, axis=0) * np.tile([1.0, -1.0], nv)[:, None], (n, 1))
    q = np.repeat(kinematics.q, 2 * nv, axis=0)
    # Braking moves against its deceleration; the velocity terms are even in the speed either way.
    states = [(RATED_MOTION, direction * speed, direction * acceleration)]
    if rating.stopping_time is not None:
        states.append((BRAKING, -direction * speed, direction * speed / rating.stopping_time))
    names = [f"{'+' if sign > 0 else '-'}{name}" for name in arm.joint_names for sign in (1, -1)]
    labels, sources = [], []
    for source, _, _ in states:
        labels += [f"{source} of {moving} at configuration {c}" for c in range(n) for moving in names]
        sources += [source] * (n * 2 * nv)
    return state_torques(
        arm,
        np.vstack([q] * len(states)),
        np.vstack([qd for _, qd, _ in states]),
        np.vstack([qdd for _, _, qdd in states]),
        rating.payload,
        np.zeros(len(labels)),
        tuple(labels),
        tuple(sources),
    )
