"""What the optimiser may change: the design variables and their bounds."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

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
        """Bounds that fix the variable at ``value`` [its SI unit]."""
        return cls(value, value, name)

    @property
    def is_fixed(self) -> bool:
        """Whether the bounds fix the variable (``lower == upper``)."""
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

    def per_joint(
        self, name: str, n_joints: int, default: float | Sequence[float] | None = None
    ) -> list[Bounds]:
        """The bounds of per-joint variable ``name`` for each of ``n_joints`` joints.

        ``default`` (one value, or one per joint) fixes the variable when the space leaves it out (None).
        """
        value = getattr(self, name)
        if value is None:
            if default is None:
                raise InvalidParameter(name, value, "bounds or a value")
            value = list(default) if isinstance(default, Sequence) else default
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
        """The bounds of global variable ``name`` (``threshold`` or ``approach_velocity``)."""
        return as_bounds(getattr(self, name), name)
