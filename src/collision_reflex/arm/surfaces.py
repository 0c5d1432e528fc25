"""Collision-reflex surfaces: the impulse of a collision swept over directions at one configuration.

By sweeping the collision direction ``u`` over the circle (a planar arm) or the sphere (a spatial arm), the
1D metric applied with the effective parameters along ``u`` gives a closed surface around the contact point
(the paper's ``fig:two_link``). Along a singular direction of the arm the impulse is infinite; the surface
reports it so (and flags it) rather than failing.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

from .. import _validate
from ..errors import InvalidParameter
from .directions import unit_directions
from .effective import CollisionImpulses, EffectiveParameters, collision_impulses
from .robot import Arm

DEFAULT_DIRECTION_COUNT = {2: 360, 3: 2000}
"""Directions swept by default: one per degree on the circle, 2000 Fibonacci points on the sphere."""


@dataclass(frozen=True)
class ReflexSurface:
    """The collision impulse along each direction at one configuration of an arm (SI units).

    arm_name: the arm's name.
    q: (nq,) configuration.
    directions: (d, task_dim) unit directions (plane coordinates for a planar arm).
    parameters: effective parameters along each direction, arrays of shape (d,).
    impulses: phase and total impulses [N s], ``v*`` [m/s] and thresholds [N], arrays of shape (d,).
    v0: approach velocity [m/s].
    contact_position: (3,) world position of the contact point [m].
    joint_positions: (nv, 3) world positions of the joint origins [m].
    plane: (3, 2) basis of a planar arm's plane, None for a spatial arm.
    """

    arm_name: str
    q: np.ndarray
    directions: np.ndarray
    parameters: EffectiveParameters
    impulses: CollisionImpulses
    v0: float
    contact_position: np.ndarray
    joint_positions: np.ndarray
    plane: np.ndarray | None

    def __post_init__(self) -> None:
        if self.impulses.total.shape != (self.directions.shape[0],):
            raise InvalidParameter("impulses", self.impulses.total.shape, f"({self.directions.shape[0]},)")

    @property
    def impulse(self) -> np.ndarray:
        """Total impulse along each direction [N s], ``inf`` along singular directions."""
        return self.impulses.total

    @property
    def task_dim(self) -> int:
        """Dimension of the directions: 2 for a planar arm, 3 otherwise."""
        return int(self.directions.shape[1])

    def points(self, scale: float = 1.0, cap: float | None = None) -> np.ndarray:
        """Surface points ``scale * min(I(u), cap) * u`` relative to the contact point, (d, task_dim).

        In [m per N s times ``scale``]; ``cap`` [N s] bounds the infinite values of singular directions.
        """
        if np.ndim(_validate.positive("scale", scale)) != 0:
            raise InvalidParameter("scale", scale, "one finite number > 0")
        if cap is not None and np.ndim(_validate.positive("cap", cap)) != 0:
            raise InvalidParameter("cap", cap, "one finite impulse > 0 [N s], or None")
        radius = self.impulse if cap is None else np.minimum(self.impulse, cap)
        return scale * radius[:, None] * self.directions

    def to_plane(self, points: np.ndarray) -> np.ndarray:
        """World points (..., 3) [m] in the plane coordinates of a planar arm (..., 2)."""
        if self.plane is None:
            raise InvalidParameter("plane", None, "a planar arm")
        points = _validate.arrays("points", points)
        with _validate.combining(points=points, plane=self.plane):
            return points @ self.plane

    def extremes(self) -> tuple[np.ndarray, np.ndarray]:
        """Directions of the smallest and the largest impulse (the largest may be a singular one)."""
        return self.directions[int(np.argmin(self.impulse))], self.directions[int(np.argmax(self.impulse))]


def reflex_surface(
    arm: Arm,
    q: npt.ArrayLike,
    v0: float,
    threshold: npt.ArrayLike | None = None,
    *,
    directions: Any = None,
    sensing: str | None = None,
    reaction: str = "at_rest",
    task_stiffness: npt.ArrayLike | None = None,
    stiffness_form: str = "compliance",
    joint_threshold: npt.ArrayLike | None = None,
) -> ReflexSurface:
    """The collision-reflex surface of ``arm`` at configuration ``q``.

    Parameters
    ----------
    arm: the arm, with its actuators (reflected inertia, stiffness, torque limits, motor masses).
    q: (nq,) configuration.
    v0: approach velocity [m/s], > 0.
    threshold: the sensing threshold, a force [N] (``sensing="force"``) or a position error [m]
        (``"position"``); joint-side threshold torques [N m] for ``"current"`` go in ``joint_threshold``. When neither
        ``threshold``, ``sensing`` nor ``joint_threshold`` is given, the arm's actuators' sensing schemes are used
        (:meth:`collision_reflex.arm.Arm.sensing_options`).
    directions: a count, names or vectors (see :func:`collision_reflex.arm.directions.unit_directions`); default
        :data:`DEFAULT_DIRECTION_COUNT` evenly spread.
    sensing, reaction: see :func:`collision_reflex.arm.collision_impulses`.
    task_stiffness: Cartesian controller stiffness [N/m] in series with the joints, see
        :func:`collision_reflex.arm.effective_parameters`.
    stiffness_form: ``"compliance"`` or ``"paper"``.
    joint_threshold: joint-side threshold torques [N m] for ``sensing="current"``.
    """
    configuration = _validate.real("q", q, f"one configuration of shape ({arm.nq},)")
    if configuration.shape != (arm.nq,):
        raise InvalidParameter("q", configuration.shape, f"one configuration of shape ({arm.nq},)")
    spec = DEFAULT_DIRECTION_COUNT[arm.task_dim] if directions is None else directions
    units = unit_directions(spec, arm.task_dim, arm.plane)
    if threshold is None and sensing is None and joint_threshold is None:
        detection = arm.sensing_options()
        sensing = detection["sensing"]
        threshold = detection.get("threshold")
        joint_threshold = detection.get("joint_threshold")
    sensing = sensing or ("current" if joint_threshold is not None else "force")
    samples = arm.kinematics(configuration[None])
    params = arm.effective_parameters(
        samples,
        units,
        stiffness_form=stiffness_form,
        joint_threshold=joint_threshold,
        task_stiffness=task_stiffness,
    )
    result = collision_impulses(params, v0, threshold, sensing, reaction)
    assert samples.contact_position is not None and samples.joint_positions is not None  # full kinematics
    return ReflexSurface(
        arm_name=arm.name,
        q=configuration,
        directions=units,
        parameters=_first(params),
        impulses=_first(result),
        v0=float(v0),
        contact_position=samples.contact_position[0],
        joint_positions=samples.joint_positions[0],
        plane=arm.plane,
    )


def _first(batch: Any) -> Any:
    """The first configuration's row of every array field of a result dataclass."""
    fields = {}
    for name in batch.__dataclass_fields__:
        value = getattr(batch, name)
        fields[name] = None if value is None else np.array(np.asarray(value)[0])
    return type(batch)(**fields)
