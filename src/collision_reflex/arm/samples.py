"""Configuration-dependent quantities of an arm stacked over configurations, and their task inverse inertia.

The stack is :class:`ArmSamples`; the task-space inverse inertia is ``J M^-1 J^T``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, NamedTuple

import numpy as np
import numpy.typing as npt

from ..errors import InvalidParameter
from ..model import effective
from ..model.effective import finger_mass_matrix
from .joints import joint_array
from .kinematic_tree import JointKinematics, forward_kinematics, plane_basis, skew, support_mask


class GravityTerms(NamedTuple):
    """What gravity asks of each joint, stacked over ``n`` configurations (the fields of :class:`ArmSamples`).

    gravity: (n, nv) of the structure [N m]; motor_gravity: (n, nv motors, nv) per kg of each motor [N m/kg];
    contact_gravity: (n, nv) per kg at the contact point [N m/kg].
    """

    gravity: np.ndarray
    motor_gravity: np.ndarray
    contact_gravity: np.ndarray


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
        """Number of joints."""
        return int(self.mass_matrix.shape[-1])

    @property
    def task_dim(self) -> int:
        """Dimension of the contact space: 2 for a planar arm, 3 otherwise."""
        return int(self.jacobian.shape[1])

    def take(self, index: Any) -> ArmSamples:
        """The samples at ``index`` (an integer array, slice or boolean mask over configurations)."""
        allowed = f"an integer, slice, boolean mask or integer array over {self.count} configurations"
        if isinstance(index, bool | np.bool_):
            raise InvalidParameter("index", index, allowed)
        try:
            single = np.ndim(np.arange(self.count)[index]) == 0  # an integer: keep the leading axis
        except (IndexError, TypeError, ValueError):
            raise InvalidParameter("index", index, allowed) from None
        picked: dict[str, Any] = {}
        for name in self.__dataclass_fields__:
            value = getattr(self, name)
            if value is not None:
                value = np.asarray(value)[index]
                picked[name] = value[None] if single else value
            else:
                picked[name] = None
        return ArmSamples(**picked)

    def structure_mass_matrix(self, motor_mass: npt.ArrayLike | None = None) -> np.ndarray:
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


@dataclass(frozen=True)
class ContactKinematics:
    """What the batched kinematics of an arm needs.

    Its structure-only Pinocchio model (no armature), with a frame at the contact point, and the joint tree.

    model, data: the structure model and its data.
    contact_frame_id: the frame at the contact point.
    contact_joint: the model joint that carries the contact point; contact_local: the point in that joint's
        frame [m].
    joints: the joint tree (:func:`collision_reflex.arm.kinematic_tree.joint_kinematics`).
    motor_masks: (nv motors, nv) masks of the joints that move each motor's parent link.
    gravity: gravity acceleration of the model [m/s^2], (3,).
    plane: (3, 2) basis of a planar arm's plane, None for a spatial arm.
    """

    model: Any
    data: Any
    contact_frame_id: int
    contact_joint: int
    contact_local: np.ndarray
    joints: list[JointKinematics]
    motor_masks: np.ndarray
    gravity: np.ndarray
    plane: np.ndarray | None

    @classmethod
    def of_model(
        cls, model: Any, joints: list[JointKinematics], contact_joint: int, contact_local: np.ndarray
    ) -> ContactKinematics:
        """From a fixed-base ``pinocchio.Model`` (copied), its joint tree and the contact point.

        The contact point is ``contact_local`` [m] in the frame of joint ``contact_joint``.
        """
        import pinocchio as pin

        structure = model.copy()
        structure.armature = np.zeros(model.nv)
        # A frame at the contact point itself, so that Pinocchio's frame Jacobian is the contact Jacobian.
        frame_id = structure.addFrame(
            pin.Frame(
                "collision_reflex_contact_point",
                contact_joint,
                pin.SE3(np.eye(3), contact_local),
                pin.FrameType.OP_FRAME,
            )
        )
        supports = [set(structure.supports[j]) for j in range(structure.njoints)]
        return cls(
            model=structure,
            data=structure.createData(),
            contact_frame_id=int(frame_id),
            contact_joint=contact_joint,
            contact_local=contact_local,
            joints=joints,
            motor_masks=np.array([support_mask(structure, supports[jk.parent]) for jk in joints]),
            gravity=np.asarray(structure.gravity.linear, dtype=float).copy(),
            plane=plane_basis(structure, joints),
        )

    def samples(self, q: np.ndarray, full: bool = True) -> ArmSamples:
        """:class:`ArmSamples` at checked configurations ``q`` (n, nq) [rad, m].

        See :meth:`collision_reflex.arm.Arm.kinematics`.
        """
        import pinocchio as pin

        model, data = self.model, self.data

        n, nv = q.shape[0], self.model.nv
        mass = np.empty((n, nv, nv))
        contact_jacobian = np.empty((n, 6, nv))
        crba, frame_jacobian = pin.crba, pin.computeFrameJacobian
        frame, aligned = self.contact_frame_id, pin.LOCAL_WORLD_ALIGNED
        for s, qs in enumerate(q):
            mass[s] = crba(model, data, qs)
            contact_jacobian[s] = frame_jacobian(model, data, qs, frame, aligned)
        jacobian3 = np.ascontiguousarray(contact_jacobian[:, :3])
        jacobian = jacobian3 if self.plane is None else np.einsum("tp,stj->spj", self.plane, jacobian3)
        if not full:
            return ArmSamples(q=q, mass_matrix=mass, jacobian=jacobian)

        gravity, motor_jac, rotations, origins = self._motor_jacobians(q)
        contact_joint = self.contact_joint - 1
        contact = origins[contact_joint] + rotations[contact_joint] @ self.contact_local
        return ArmSamples(
            q=q,
            mass_matrix=mass,
            jacobian=jacobian,
            motor_mass_influence=np.swapaxes(motor_jac, -1, -2) @ motor_jac,
            contact_position=contact,
            joint_positions=np.stack(origins, axis=1),
            **self._gravity_terms(gravity, motor_jac, jacobian3)._asdict(),
        )

    def gravity_terms(self, q: np.ndarray) -> GravityTerms:
        """The gravity fields of :meth:`samples` alone, at checked configurations ``q`` (n, nq).

        The same numbers, without the mass matrix and the motor-mass inertia terms: what holding the arm still
        needs (:func:`collision_reflex.arm.static_hold.hold_torques`), at a fraction of the cost.
        """
        import pinocchio as pin

        jacobian3 = np.empty((q.shape[0], 3, self.model.nv))
        frame_jacobian, frame, aligned = (
            pin.computeFrameJacobian,
            self.contact_frame_id,
            pin.LOCAL_WORLD_ALIGNED,
        )
        for s, qs in enumerate(q):
            jacobian3[s] = frame_jacobian(self.model, self.data, qs, frame, aligned)[:3]
        gravity, motor_jac, _, _ = self._motor_jacobians(q)
        return self._gravity_terms(gravity, motor_jac, jacobian3)

    def _gravity_terms(
        self, gravity: np.ndarray, motor_jac: np.ndarray, jacobian3: np.ndarray
    ) -> GravityTerms:
        """The structure's gravity torques, and per kg at each motor point and at the contact point."""
        return GravityTerms(
            gravity=gravity,
            motor_gravity=-np.einsum("sitj,t->sij", motor_jac, self.gravity),
            contact_gravity=-np.einsum("stj,t->sj", jacobian3, self.gravity),
        )

    def _motor_jacobians(
        self, q: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, list[np.ndarray], list[np.ndarray]]:
        """Generalized gravity, the motor points' Jacobians and the joint frames at ``q`` (n, nq).

        Gravity (n, nv) [N m]; Jacobians (n, motor i, 3, nv) [m/rad]; per joint its frame's rotation (n, 3, 3)
        and origin (n, 3) [m].
        """
        import pinocchio as pin

        model, data = self.model, self.data
        n, nv = q.shape[0], model.nv
        spatial = np.empty((n, 6, nv))
        gravity = np.empty((n, nv))
        joint_jacobians, generalized_gravity = pin.computeJointJacobians, pin.computeGeneralizedGravity
        for s, qs in enumerate(q):
            spatial[s] = joint_jacobians(model, data, qs)  # world frame, every joint
            gravity[s] = generalized_gravity(model, data, qs)
        rotations, origins, motor_points = forward_kinematics(self.joints, q)
        linear, angular = spatial[:, :3], spatial[:, 3:]
        # Motor i sits at joint i's origin on the parent link: it moves with the parent link's point there.
        points = np.stack(motor_points, axis=1)  # (n, motor i, 3)
        motor_jac = self.motor_masks[None, :, None, :] * (
            linear[:, None] - skew(points) @ angular[:, None]
        )  # (n, motor i, 3, nv)
        return gravity, motor_jac, rotations, origins


def task_inverse_inertia(mass_matrix: np.ndarray, jacobian: np.ndarray) -> np.ndarray:
    """``J M^-1 J^T`` (n, m, m) [1/kg] for stacked mass matrices and Jacobians.

    Mass matrices (n, nv, nv) [kg m^2], Jacobians (n, m, nv) [m/rad]. The result is the inverse of the
    task-space (operational-space) inertia, the ellipsoid of gyration.
    """
    try:
        return np.asarray(effective.task_inverse_inertia(jacobian, mass_matrix))
    except np.linalg.LinAlgError:
        raise InvalidParameter(
            "mass_matrix",
            "singular",
            "positive-definite structure mass matrices",
            "every joint must move some link with mass or inertia",
        ) from None
