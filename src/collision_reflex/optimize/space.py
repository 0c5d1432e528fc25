"""What the optimiser may change (design variables with bounds) and what it evaluates against (samples)."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..errors import InvalidParameter

PER_JOINT_VARIABLES = ("stator_diameter", "stack_length", "gear_ratio", "software_stiffness")
GLOBAL_VARIABLES = ("threshold", "approach_velocity")
OPTIMIZED_SENSING_SCHEMES: tuple[str, ...] = ("force", "position")
"""The schemes of :data:`collision_reflex.model.sensing.SENSING_SCHEMES` the optimiser handles: a
contact-force threshold ``F_s`` [N] or a contact-point position-error threshold ``e_th`` [m] with
``F_s = k(u) e_th``. A motor-current threshold (``"current"``) makes the contact threshold a minimum over joints,
which is evaluated but not optimised."""


@dataclass(frozen=True)
class Bounds:
    """Bounds of one design variable, in SI units; ``lower == upper`` fixes it.

    Every design variable is a positive physical quantity, and the optimiser works with its logarithm, so the
    bounds must be finite and > 0.
    """

    lower: float
    upper: float
    name: str = "variable"

    def __post_init__(self) -> None:
        for side, value in (("lower", self.lower), ("upper", self.upper)):
            if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
                raise InvalidParameter(f"{self.name} {side} bound", value, "a finite number > 0")
        if self.lower > self.upper:
            raise InvalidParameter(
                f"{self.name} bounds", (self.lower, self.upper), "lower <= upper", "swap or widen the bounds"
            )

    @classmethod
    def fixed(cls, value: float, name: str = "variable") -> Bounds:
        return cls(value, value, name)

    @property
    def is_fixed(self) -> bool:
        return self.lower == self.upper

    @property
    def midpoint(self) -> float:
        """Geometric mean of the bounds: the middle in the optimiser's log space."""
        return math.sqrt(self.lower * self.upper)


BoundsLike = Bounds | tuple[float, float] | float


def as_bounds(value: BoundsLike, name: str) -> Bounds:
    """A ``Bounds`` from bounds, a ``(lower, upper)`` pair, or a number (fixed)."""
    if isinstance(value, Bounds):
        return Bounds(value.lower, value.upper, name)
    if isinstance(value, (int, float)):
        return Bounds.fixed(float(value), name)
    if isinstance(value, (tuple, list)) and len(value) == 2:
        return Bounds(float(value[0]), float(value[1]), name)
    raise InvalidParameter(name, value, "Bounds, a (lower, upper) pair or a number (fixed)")


@dataclass(frozen=True)
class DesignSpace:
    """Bounds of the design variables (SI units).

    Per-joint variables take one bounds for every joint (each joint still gets its own variable) or a sequence
    with one bounds per joint: ``stator_diameter`` [m], ``stack_length`` [m] (``None``: the reference motor's,
    fixed), ``gear_ratio`` [-] (>= 1), ``software_stiffness`` [N m/rad]. Global variables: ``threshold`` (the
    contact-force threshold [N] for force sensing, the contact position-error threshold [m] for position
    sensing) and ``approach_velocity`` [m/s]. Any variable is fixed by giving a number.
    """

    stator_diameter: BoundsLike | Sequence[BoundsLike]
    gear_ratio: BoundsLike | Sequence[BoundsLike]
    software_stiffness: BoundsLike | Sequence[BoundsLike]
    threshold: BoundsLike
    approach_velocity: BoundsLike
    stack_length: BoundsLike | Sequence[BoundsLike] | None = None

    def per_joint(self, name: str, n_joints: int, default: float | None = None) -> list[Bounds]:
        """The bounds of per-joint variable ``name`` for each of ``n_joints`` joints."""
        value = getattr(self, name)
        if value is None:
            if default is None:
                raise InvalidParameter(name, value, "bounds or a value")
            value = default
        if isinstance(value, Sequence) and not (
            isinstance(value, tuple) and len(value) == 2 and all(isinstance(v, (int, float)) for v in value)
        ):
            if len(value) != n_joints:
                raise InvalidParameter(name, value, f"one bounds for all joints or a sequence of {n_joints}")
            bounds = [as_bounds(v, f"{name}[{i}]") for i, v in enumerate(value)]
        else:
            bounds = [as_bounds(value, f"{name}[{i}]") for i in range(n_joints)]
        if name == "gear_ratio":
            for b in bounds:
                if b.lower < 1:
                    raise InvalidParameter(f"{b.name} lower bound", b.lower, "a gear ratio >= 1")
        return bounds

    def global_bounds(self, name: str) -> Bounds:
        return as_bounds(getattr(self, name), name)


@dataclass(frozen=True)
class Constraints:
    """Constraints of a design problem.

    payload: mass carried at the contact point [kg], adds its gravity torques to the requirement.
    safety_factor: peak output torque must be at least this times the required torque [-], >= 1.
    torque_required: per-joint required torque [N m]; ``None`` derives it from Pinocchio gravity torques of the
        structure, the motors and the payload over the sampled configurations.
    threshold_floor: sensing noise floor [N]: the contact-force threshold may not go below it.
    """

    payload: float = 0.0
    safety_factor: float = 1.0
    torque_required: Sequence[float] | None = None
    threshold_floor: float = 0.0

    def __post_init__(self) -> None:
        if not (math.isfinite(self.payload) and self.payload >= 0):
            raise InvalidParameter("payload", self.payload, "a finite mass >= 0 [kg]")
        if not (math.isfinite(self.safety_factor) and self.safety_factor >= 1):
            raise InvalidParameter("safety_factor", self.safety_factor, "a finite number >= 1")
        if not (math.isfinite(self.threshold_floor) and self.threshold_floor >= 0):
            raise InvalidParameter("threshold_floor", self.threshold_floor, "a finite force >= 0 [N]")
        if self.torque_required is not None:
            required = np.asarray(self.torque_required, dtype=float)
            if required.ndim != 1 or not np.all(np.isfinite(required) & (required >= 0)):
                raise InvalidParameter(
                    "torque_required", self.torque_required, "one torque >= 0 per joint [N m]"
                )


@dataclass(frozen=True)
class ContactSamples:
    """Contact cases the design is evaluated on: sample ``s`` is configuration ``config_index[s]`` of
    ``kinematics`` hit along unit direction ``directions[s]`` (world-aligned, ``task_dim`` components).

    kinematics: :class:`collision_reflex.arm.ArmSamples` of the configurations.
    directions: (n_samples, task_dim) unit vectors.
    config_index: (n_samples,) index into the configurations.
    """

    kinematics: Any
    directions: np.ndarray
    config_index: np.ndarray
    labels: tuple[str, ...] = field(default=())

    def __post_init__(self) -> None:
        directions = np.atleast_2d(np.asarray(self.directions, dtype=float))
        index = np.asarray(self.config_index, dtype=int).ravel()
        task_dim = self.kinematics.jacobian.shape[1]
        if directions.shape != (index.size, task_dim):
            raise InvalidParameter("directions", directions.shape, f"shape ({index.size}, {task_dim})")
        norms = np.linalg.norm(directions, axis=1)
        if not np.all(np.isfinite(norms) & (norms > 0)):
            raise InvalidParameter("directions", self.directions, "non-zero finite vectors")
        if index.size == 0 or index.min() < 0 or index.max() >= self.kinematics.q.shape[0]:
            raise InvalidParameter("config_index", index, f"indices in [0, {self.kinematics.q.shape[0]})")
        object.__setattr__(self, "directions", directions / norms[:, None])
        object.__setattr__(self, "config_index", index)

    @classmethod
    def grid(cls, kinematics: Any, directions: np.ndarray) -> ContactSamples:
        """Every configuration of ``kinematics`` with every direction."""
        directions = np.atleast_2d(np.asarray(directions, dtype=float))
        n_config = kinematics.q.shape[0]
        index = np.repeat(np.arange(n_config), directions.shape[0])
        return cls(kinematics, np.tile(directions, (n_config, 1)), index)

    @property
    def size(self) -> int:
        return int(self.config_index.size)

    @property
    def joint_moment_arms(self) -> np.ndarray:
        """``w = J^T u`` per sample, (n_samples, nv): joint torque per unit contact force [m or N m/N]."""
        jacobian = self.kinematics.jacobian[self.config_index]
        return np.einsum("sdj,sd->sj", jacobian, self.directions)
