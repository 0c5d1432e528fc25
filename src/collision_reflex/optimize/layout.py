"""The decision-variable layout: where each design variable lives in the NLP's ``x``, and what it gives.

All design variables are positive and optimised as their logarithms: per joint the stator diameter (and
optionally stack length) of a motor scaled from a reference motor, the gear ratio and the software stiffness;
globally the sensing threshold and the approach velocity. A variable with equal bounds is fixed and takes no
entry of ``x``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import NamedTuple

import casadi as ca
import numpy as np

from ..errors import InvalidParameter
from ..hardware.gearboxes import CatalogueGearbox, ScaledGearbox
from ..model import effective as formulas
from ..model.impulse import series_stiffness
from ..vocabulary import GLOBAL_VARIABLES, MODULE_VARIABLES, PER_JOINT_VARIABLES
from .constraints import Constraints
from .space import Bounds, DesignSpace
from .technology import ActuatorTechnology


@dataclass
class DesignLayout:
    """Where each design variable lives: a slice of the NLP's ``x`` (log values) or a fixed value."""

    bounds: dict[str, list[Bounds]] = field(default_factory=dict)
    slices: dict[str, list[int | None]] = field(default_factory=dict)
    size: int = 0

    def add(self, name: str, bounds: list[Bounds], owner: list[int] | None = None) -> None:
        """Append variable ``name`` with one bounds per entry; fixed entries take no place in ``x``.

        ``owner``: per entry the entry whose variable it shares (its own index: none shared); sharing entries
        take the intersection of their bounds (:meth:`DesignSpace.module_of`).
        """
        owner = list(range(len(bounds))) if owner is None else owner
        shared = {k: [b for b, o in zip(bounds, owner, strict=True) if o == k] for k in set(owner)}
        bounds = [_intersection(shared[o]) for o in owner]
        self.bounds[name] = bounds
        indices: list[int | None] = []
        for k, b in enumerate(bounds):
            if b.is_fixed:
                indices.append(None)
            elif owner[k] != k:
                indices.append(indices[owner[k]])
            else:
                indices.append(self.size)
                self.size += 1
        self.slices[name] = indices

    def expressions(self, x: ca.MX) -> dict[str, ca.MX]:
        """Each variable as an MX column (exp of its log variable, or its fixed value)."""
        out = {}
        for name, bounds in self.bounds.items():
            parts = [
                ca.exp(x[i]) if i is not None else ca.MX(b.lower)
                for i, b in zip(self.slices[name], bounds, strict=True)
            ]
            out[name] = ca.vertcat(*parts)
        return out

    def log_bounds(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Lower bounds, upper bounds and start (log-midpoint) of the free variables, in log space."""
        lower, upper, start = (np.empty(self.size) for _ in range(3))
        for name, bounds in self.bounds.items():
            for i, b in zip(self.slices[name], bounds, strict=True):
                if i is not None:
                    lower[i], upper[i], start[i] = math.log(b.lower), math.log(b.upper), math.log(b.midpoint)
        return lower, upper, start

    def values(self, x: np.ndarray) -> dict[str, np.ndarray]:
        """Numeric values [SI] of every variable at ``x``."""
        return {
            name: np.array(
                [
                    math.exp(x[i]) if i is not None else b.lower
                    for i, b in zip(self.slices[name], bounds, strict=True)
                ]
            )
            for name, bounds in self.bounds.items()
        }


def design_layout(
    space: DesignSpace,
    technology: ActuatorTechnology,
    constraints: Constraints,
    n_joints: int,
    joint_names: tuple[str, ...] | None = None,
) -> DesignLayout:
    """The design variables with their bounds: per joint, then global.

    With force sensing the noise floor bounds the threshold from below; a joint's gear-ratio bounds are
    intersected with its gearbox's ratio range (``joint_names`` name the joints in errors).
    """
    layout = DesignLayout()
    defaults = {"stack_length": technology.default_stack_lengths(n_joints)}
    names = joint_names or tuple(f"joint{j + 1}" for j in range(n_joints))
    owner = space.module_of(n_joints)
    for name in PER_JOINT_VARIABLES:
        joint_bounds = space.per_joint(name, n_joints, defaults.get(name))
        if name == "gear_ratio":
            gearboxes = technology.joint_gearboxes(n_joints)
            joint_bounds = [
                _within_ratio_range(b, g, joint)
                for b, g, joint in zip(joint_bounds, gearboxes, names, strict=True)
            ]
        if name in MODULE_VARIABLES:
            _check_module_bounds(name, joint_bounds, owner, names)
            layout.add(name, joint_bounds, owner)
        else:
            layout.add(name, joint_bounds)
    for shared in GLOBAL_VARIABLES:
        bounds = space.global_bounds(shared)
        if shared == "threshold" and technology.sensing == "force":
            bounds = _with_noise_floor(bounds, constraints.threshold_floor)
        layout.add(shared, [bounds])
    return layout


def _intersection(bounds: list[Bounds]) -> Bounds:
    """The bounds all of ``bounds`` allow (checked non-empty by :func:`_check_module_bounds`)."""
    return Bounds(max(b.lower for b in bounds), min(b.upper for b in bounds), bounds[0].name)


def _check_module_bounds(name: str, bounds: list[Bounds], owner: list[int], joints: tuple[str, ...]) -> None:
    """Raise unless the joints of each module have bounds of ``name`` in common."""
    for k in sorted(set(owner)):
        members = [j for j, o in enumerate(owner) if o == k]
        if len(members) > 1:
            low, high = max(bounds[j].lower for j in members), min(bounds[j].upper for j in members)
            if low > high:
                raise InvalidParameter(
                    f"{name} bounds of the module {', '.join(joints[j] for j in members)}",
                    [(bounds[j].lower, bounds[j].upper) for j in members],
                    "bounds that overlap: the module's joints share one actuator",
                    "widen the joints' bounds or take the joint out of the module",
                )


def _within_ratio_range(
    bounds: Bounds, gearbox: CatalogueGearbox | ScaledGearbox | None, joint: str
) -> Bounds:
    """The gear-ratio bounds of ``joint`` intersected with its gearbox's ratio range.

    Raises
    ------
    InvalidParameter: the two ranges do not overlap (the message names the joint, the gearbox and both).
    """
    if gearbox is None:
        return bounds
    lower, upper = gearbox.clip(bounds)
    if lower > upper:
        low, high = gearbox.ratio_range
        raise InvalidParameter(
            f"gear_ratio bounds of {joint}",
            (bounds.lower, bounds.upper),
            f"a range that overlaps the ratios of its gearbox {gearbox.name!r}, {low:g} to {high:g}",
            "widen the gear-ratio bounds or choose another gearbox",
        )
    return Bounds(lower, upper, bounds.name)


def _with_noise_floor(bounds: Bounds, floor: float) -> Bounds:
    """With force sensing the noise floor [N] is a lower bound on the threshold variable itself."""
    if floor <= 0:
        return bounds
    if bounds.upper < floor:
        raise InvalidParameter(
            "threshold bounds",
            (bounds.lower, bounds.upper),
            f"an upper bound >= the sensing noise floor {floor} N",
            "raise the threshold's upper bound or lower the floor",
        )
    return Bounds(max(bounds.lower, floor), bounds.upper, "threshold")


class DesignQuantities(NamedTuple):
    """Symbolic joint quantities of a design (see :func:`design_quantities`)."""

    values: dict[str, ca.MX]
    design_column: ca.MX
    actuator_mass: ca.MX
    peak_torque: ca.MX
    finger_inertia: ca.MX
    reflected_inertia: ca.MX
    continuous_torque: ca.MX
    max_speed: ca.MX | None
    driving_peak_torque: ca.MX

    def joint_function(self, x: ca.MX) -> ca.Function:
        """CasADi function of ``x`` giving the joint numbers.

        Outputs (n_joints each): actuator (motor and gearbox) masses [kg], peak torques ``N tau_p`` [N m],
        finger inertias and reflected inertias [kg m^2].
        """
        outputs = [self.actuator_mass, self.peak_torque, self.finger_inertia, self.reflected_inertia]
        return ca.Function("joint_numbers", [x], outputs)


def design_quantities(
    layout: DesignLayout, z: ca.MX, technology: ActuatorTechnology, k_mech: np.ndarray
) -> DesignQuantities:
    """Symbolic joint quantities of the design variables ``z`` (log values).

    Gives the variables themselves, the per-sample function's design column, the actuator masses carried at
    the joints (motor and gearbox) [kg], the peak output torques ``N tau_p`` of the reaction [N m], the
    reflected inertia acting on the finger [kg m^2] (zero unless ``reflected_inertia_in == "finger"``), the
    reflected inertia ``N^2 (J_m + J_g)`` [kg m^2], the driving continuous torques ``eta N tau_c`` [N m], the
    motors' maximum speeds [rad/s] (None when the reference motor's is not known) and the driving peak torques
    ``eta N tau_p`` [N m] (:meth:`ActuatorTechnology.joint_quantities`); ``k_mech`` is the joint mechanical
    stiffness [N m/rad].
    """
    values = layout.expressions(z)
    joint = technology.joint_quantities(
        values["stator_diameter"], values["stack_length"], values["gear_ratio"]
    )
    design_column = ca.vertcat(
        joint.actuator_mass,
        joint.reflected_inertia,
        series_stiffness(ca.DM(k_mech), values["software_stiffness"]),
        values["threshold"],
        values["approach_velocity"],
    )
    in_finger = technology.finger_joints(values["gear_ratio"].shape[0])
    finger_inertia = formulas.finger_inertia(joint.reflected_inertia, ca.DM(in_finger))
    return DesignQuantities(
        values,
        design_column,
        joint.actuator_mass,
        joint.peak_torque,
        finger_inertia,
        joint.reflected_inertia,
        joint.driving_continuous_torque,
        joint.motor.max_speed,
        joint.driving_peak_torque,
    )
