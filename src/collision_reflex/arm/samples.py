"""Configuration-dependent quantities of an arm stacked over configurations (:class:`ArmSamples`), and the
task-space inverse inertia they give."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import InvalidParameter
from ..model import effective
from ..model.effective import finger_mass_matrix
from .joints import joint_array


@dataclass(frozen=True)
class ArmSamples:
    """Configuration-dependent quantities of an arm, stacked over ``n`` configurations (SI units).

    q: (n, nq) configurations.
    mass_matrix: (n, nv, nv) joint-space mass matrix of the structure (links only: no armature, no motor
        masses) [kg m^2, kg m, kg].
    jacobian: (n, task_dim, nv) translational Jacobian of the contact point, world-aligned axes (in the arm's
        plane for a planar arm) [m/rad].
    gravity: (n, nv) generalized gravity torques of the structure [N m].
    motor_mass_influence: (n, nv, nv, nv); ``[s, i]`` is the matrix ``A_i`` with
        ``M_bb(q; m) = M_bb0(q) + sum_i m_i A_i(q)`` for a point motor mass of joint ``i`` at that joint's
        origin, carried by its parent link [m^2 per rad^2].
    motor_gravity: (n, nv, nv); ``[s, i]`` is the gravity torque vector per kilogram of motor ``i`` [N m/kg].
    contact_gravity: (n, nv) gravity torque per kilogram of payload at the contact point [N m/kg].
    contact_position: (n, 3) world position of the contact point [m].
    joint_positions: (n, nv, 3) world positions of the joint origins [m].

    The gravity and motor-mass terms are None when :meth:`Arm.kinematics` was asked to skip them.
    """

    q: np.ndarray
    mass_matrix: np.ndarray
    jacobian: np.ndarray
    gravity: np.ndarray | None = None
    motor_mass_influence: np.ndarray | None = None
    motor_gravity: np.ndarray | None = None
    contact_gravity: np.ndarray | None = None
    contact_position: np.ndarray | None = None
    joint_positions: np.ndarray | None = None

    def __post_init__(self) -> None:
        mass = np.asarray(self.mass_matrix)
        if mass.ndim != 3 or mass.shape[1] != mass.shape[2]:
            raise InvalidParameter("mass_matrix", mass.shape, "an array of shape (n, nv, nv)")
        n, nv = mass.shape[0], mass.shape[-1]
        expected = {
            "q": (n, None),
            "mass_matrix": (n, nv, nv),
            "jacobian": (n, None, nv),
            "gravity": (n, nv),
            "motor_mass_influence": (n, nv, nv, nv),
            "motor_gravity": (n, nv, nv),
            "contact_gravity": (n, nv),
            "contact_position": (n, 3),
            "joint_positions": (n, nv, 3),
        }
        for name, shape in expected.items():
            value = getattr(self, name)
            if value is None:
                continue
            array = np.asarray(value, dtype=float)
            if array.ndim != len(shape) or any(
                s is not None and s != a for s, a in zip(shape, array.shape, strict=False)
            ):
                raise InvalidParameter(name, array.shape, f"an array of shape {shape} (None: any)")
            if not np.all(np.isfinite(array)):
                raise InvalidParameter(name, array, "finite values", "check the configurations and the model")
            object.__setattr__(self, name, array)
        if self.jacobian.shape[1] not in (2, 3):
            raise InvalidParameter("jacobian", self.jacobian.shape, "task dimension 2 or 3")

    @property
    def count(self) -> int:
        """Number of configurations."""
        return int(self.q.shape[0])

    @property
    def nv(self) -> int:
        return int(self.mass_matrix.shape[-1])

    @property
    def task_dim(self) -> int:
        return int(self.jacobian.shape[1])

    def take(self, index: Any) -> ArmSamples:
        """The samples at ``index`` (an integer array, slice or boolean mask over configurations)."""
        single = np.ndim(np.arange(self.count)[index]) == 0  # an integer: keep the leading axis
        picked: dict[str, Any] = {}
        for name in self.__dataclass_fields__:
            value = getattr(self, name)
            if value is not None:
                value = np.asarray(value)[index]
                picked[name] = value[None] if single else value
            else:
                picked[name] = None
        return ArmSamples(**picked)

    def structure_mass_matrix(self, motor_mass: Any = None) -> np.ndarray:
        """``M_bb(q; m) = M_bb0(q) + sum_i m_i A_i(q)`` [kg m^2], (n, nv, nv); ``motor_mass`` [kg], (nv,)."""
        if motor_mass is None:
            return self.mass_matrix
        masses = joint_array("motor_mass", motor_mass, self.nv, allow_zero=True)
        if not np.any(masses):
            return self.mass_matrix
        if self.motor_mass_influence is None:
            raise InvalidParameter(
                "motor_mass",
                motor_mass,
                "None for samples without motor terms",
                "compute the samples with Arm.kinematics(q, motor_terms=True)",
            )
        return np.asarray(finger_mass_matrix(self.mass_matrix, self.motor_mass_influence, masses))


def task_inverse_inertia(mass_matrix: np.ndarray, jacobian: np.ndarray) -> np.ndarray:
    """``J M^-1 J^T`` for stacked mass matrices (n, nv, nv) [kg m^2] and Jacobians (n, m, nv) [m/rad],
    (n, m, m) [1/kg]: the inverse of the task-space (operational-space) inertia, the ellipsoid of gyration."""
    try:
        return np.asarray(effective.task_inverse_inertia(jacobian, mass_matrix))
    except np.linalg.LinAlgError:
        raise InvalidParameter(
            "mass_matrix",
            "singular",
            "positive-definite structure mass matrices",
            "every joint must move some link with mass or inertia",
        ) from None
