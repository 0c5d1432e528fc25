"""What the optimiser may change: the design variables and their bounds."""

from __future__ import annotations

import math
import numbers
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..errors import InvalidParameter
from ..vocabulary import GLOBAL_VARIABLES, PER_JOINT_VARIABLES

SUPPORTED_RANGES: dict[str, tuple[float, float]] = {
    "stator_diameter": (1e-6, 1e3),
    "stack_length": (1e-6, 1e3),
    "gear_ratio": (1.0, 1e6),
    "software_stiffness": (1e-9, 1e12),
    "threshold": (1e-12, 1e12),
    "approach_velocity": (1e-9, 1e6),
}
"""Range of each design variable that the model evaluates without overflow [its SI unit].

The motor and gearbox scaling laws raise the diameter to the fourth power and the gear ratio to the second,
and the problem's scaling takes logarithms; bounds outside these (far wider than any actuator) are refused.
The study files' physical ranges are narrower still."""


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
            if isinstance(value, np.ndarray) and value.size == 1:  # a 1-element array is one number
                value = value.reshape(()).item()
            if not (_is_number(value) and math.isfinite(value) and value > 0):
                raise InvalidParameter(f"{self.name} {side} bound", value, "a finite number > 0")
            object.__setattr__(self, side, float(value))
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
    allowed = "Bounds, a (lower, upper) pair or a number (fixed)"
    if _is_number(value):
        return Bounds.fixed(float(value), name)  # type: ignore[arg-type]
    if isinstance(value, (tuple, list)) and len(value) == 2:
        if not all(_is_number(v) for v in value):
            raise InvalidParameter(name, value, allowed)
        return Bounds(float(value[0]), float(value[1]), name)
    raise InvalidParameter(name, value, allowed)


def _is_number(value: object) -> bool:
    return isinstance(value, numbers.Real) and not isinstance(value, (bool, np.bool_))


def _entries(value: object) -> list[object] | None:
    """The per-joint entries of a per-joint variable's value, or None if one bounds covers every joint."""
    if isinstance(value, Sequence) and not isinstance(value, str):
        if not (isinstance(value, tuple) and len(value) == 2 and all(_is_number(v) for v in value)):
            return list(value)
    return None


@dataclass(frozen=True)
class DesignSpace:
    """Bounds of the design variables (SI units).

    Per-joint variables take one bounds for every joint (each joint still gets its own variable) or a sequence
    with one bounds per joint: ``stator_diameter`` [m], ``stack_length`` [m] (``None``: the reference motor's,
    fixed), ``gear_ratio`` [-] (>= 1), ``software_stiffness`` [N m/rad]. Global variables: ``threshold`` (the
    contact-force threshold [N] for force sensing, the contact position-error threshold [m] for position
    sensing) and ``approach_velocity`` [m/s]. Any variable is fixed by giving a number. Bounds must lie within
    :data:`SUPPORTED_RANGES` (checked here, naming the variable).

    ``modules``: groups of joint indices built from one actuator module, as arms are (one motor, gearbox and
    gear ratio for several joints, bought and spared as one part): the joints of a group share one variable of
    each of :data:`MODULE_VARIABLES`, within the intersection of their bounds, and the module must meet the
    largest requirement of its joints; each joint keeps its own software stiffness.
    """

    stator_diameter: BoundsLike | Sequence[BoundsLike]
    gear_ratio: BoundsLike | Sequence[BoundsLike]
    software_stiffness: BoundsLike | Sequence[BoundsLike]
    threshold: BoundsLike
    approach_velocity: BoundsLike
    stack_length: BoundsLike | Sequence[BoundsLike] | None = None
    modules: tuple[tuple[int, ...], ...] = ()

    def __post_init__(self) -> None:
        seen: set[int] = set()
        for group in self.modules:
            members = list(group)
            if len(members) < 2 or not all(_is_number(j) and int(j) == j and j >= 0 for j in members):
                raise InvalidParameter("modules", self.modules, "groups of two or more joint indices >= 0")
            if seen & set(members) or len(set(members)) != len(members):
                raise InvalidParameter(
                    "modules",
                    self.modules,
                    "groups in which every joint appears once",
                    "a joint has one actuator",
                )
            seen |= set(members)
        for name in (*PER_JOINT_VARIABLES, *GLOBAL_VARIABLES):
            value = getattr(self, name)
            if value is None and name == "stack_length":
                continue
            entries = _entries(value) if name in PER_JOINT_VARIABLES else None
            for i, entry in enumerate([value] if entries is None else entries):
                label = name if entries is None else f"{name}[{i}]"
                _within_supported(as_bounds(entry, label), name)

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
        entries = _entries(value)
        if entries is not None:
            if len(entries) != n_joints:
                raise InvalidParameter(name, value, f"one bounds for all joints or a sequence of {n_joints}")
            bounds = [as_bounds(v, f"{name}[{i}]") for i, v in enumerate(entries)]  # type: ignore[arg-type]
        else:
            bounds = [as_bounds(value, f"{name}[{i}]") for i in range(n_joints)]
        return bounds

    def module_of(self, n_joints: int) -> list[int]:
        """Per joint the index of the joint whose actuator variables it uses: its module's first, else its own.

        Raises
        ------
        InvalidParameter: a module names a joint index beyond ``n_joints``.
        """
        owner = list(range(n_joints))
        for group in self.modules:
            if max(group) >= n_joints:
                raise InvalidParameter("modules", self.modules, f"joint indices below {n_joints}")
            for j in group:
                owner[j] = min(group)
        return owner

    def global_bounds(self, name: str) -> Bounds:
        """The bounds of global variable ``name`` (``threshold`` or ``approach_velocity``)."""
        return as_bounds(getattr(self, name), name)


def module_envelope(values: np.ndarray, owner: Sequence[int]) -> np.ndarray:
    """Per joint the largest of ``values`` over its module (``owner``: :meth:`DesignSpace.module_of`)."""
    values = np.asarray(values, dtype=float)
    owners = np.asarray(owner)
    return np.array([values[owners == owners[j]].max() for j in range(values.size)])


def _within_supported(bounds: Bounds, variable: str) -> None:
    """Raise if ``bounds`` of ``variable`` leave :data:`SUPPORTED_RANGES`."""
    low, high = SUPPORTED_RANGES[variable]
    if variable == "gear_ratio" and bounds.lower < 1:
        raise InvalidParameter(f"{bounds.name} lower bound", bounds.lower, "a gear ratio >= 1")
    if bounds.lower < low or bounds.upper > high:
        raise InvalidParameter(
            f"{bounds.name} bounds",
            (bounds.lower, bounds.upper),
            f"within the supported range [{low:g}, {high:g}] (SI units)",
            "beyond it the scaling laws overflow; physical actuators lie far inside",
        )
