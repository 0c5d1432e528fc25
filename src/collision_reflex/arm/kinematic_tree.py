"""The joint tree of a fixed-base Pinocchio model with 1-DoF joints.

Joint descriptions, the plane of a planar arm, and forward kinematics batched over configurations (SI: rad,
m).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import InvalidParameter


@dataclass(frozen=True)
class JointKinematics:
    """What the batched forward kinematics needs about one 1-DoF joint (SI, parent-joint frame)."""

    parent: int  # index of the parent joint in the model (0: the world)
    idx_q: int
    nq: int  # 1, or 2 for an unbounded revolute joint stored as (cos, sin)
    revolute: bool
    axis: np.ndarray  # unit axis in the joint frame
    rotation: np.ndarray  # placement of the joint frame in the parent joint frame
    translation: np.ndarray

    # Cached: forward kinematics uses them at every call, often for one configuration at a time.
    @functools.cached_property
    def rotation_skew(self) -> np.ndarray:
        """``R_p K``: the placement rotation times the skew matrix of the axis (Rodrigues' ``sin`` term)."""
        return self.rotation @ skew(self.axis)

    @functools.cached_property
    def rotation_skew2(self) -> np.ndarray:
        """``R_p K^2``: the placement rotation times the squared skew matrix (Rodrigues' ``1 - cos`` term)."""
        cross = skew(self.axis)
        return self.rotation @ cross @ cross


def skew(vector: np.ndarray) -> np.ndarray:
    """Cross-product matrices ``[v]x`` of vectors (..., 3) -> (..., 3, 3), so that ``[v]x w = v x w``."""
    x, y, z = vector[..., 0], vector[..., 1], vector[..., 2]
    zero = np.zeros_like(x)
    return np.stack([zero, -z, y, z, zero, -x, -y, x, zero], axis=-1).reshape(*vector.shape[:-1], 3, 3)


def support_mask(model: Any, joints: set[int]) -> np.ndarray:
    """(nv,) mask of the velocity indices of ``joints`` (model joint ids; 0, the world, has none)."""
    mask = np.zeros(model.nv)
    for j in joints:
        if j > 0:
            joint = model.joints[j]
            mask[joint.idx_v : joint.idx_v + joint.nv] = 1.0
    return mask


def joint_kinematics(model: Any, robot: str) -> list[JointKinematics]:
    """Describe every joint of a fixed-base model with 1-DoF joints; refuse anything else clearly."""
    import pinocchio as pin

    if model.njoints < 2:
        raise InvalidParameter("model", robot, "a robot with at least one joint")
    data = model.createData()
    q0 = pin.neutral(model)
    pin.computeJointJacobians(model, data, q0)
    joints = []
    for j in range(1, model.njoints):
        joint = model.joints[j]
        if joint.nv != 1 or joint.nq not in (1, 2):
            raise InvalidParameter(
                "model",
                f"joint {model.names[j]!r} ({joint.shortname()}, nq={joint.nq}, nv={joint.nv})",
                "a fixed-base robot whose joints are revolute or prismatic",
                "floating-base robots: use collision_reflex.arm.metrics for the impact mitigation factor, or load "
                "the URDF without a root joint",
            )
        local = np.asarray(pin.getJointJacobian(model, data, j, pin.LOCAL))[:, joint.idx_v]
        linear, angular = local[:3], local[3:]
        revolute = bool(np.linalg.norm(angular) > 1e-9)
        if revolute and np.linalg.norm(linear) > 1e-9:
            raise InvalidParameter("model", model.names[j], "revolute or prismatic joints (not helical)")
        axis = angular if revolute else linear
        placement = model.jointPlacements[j]
        joints.append(
            JointKinematics(
                parent=int(model.parents[j]),
                idx_q=int(joint.idx_q),
                nq=int(joint.nq),
                revolute=revolute,
                axis=axis / np.linalg.norm(axis),
                rotation=np.array(placement.rotation),
                translation=np.array(placement.translation),
            )
        )
        if joint.idx_v != j - 1:
            raise InvalidParameter("model", robot, "joints numbered in velocity order")
    return joints


def plane_basis(model: Any, joints: list[JointKinematics]) -> np.ndarray | None:
    """(3, 2) world basis of the plane of motion of a planar arm; None for a spatial arm.

    An arm is planar when every revolute axis is parallel (and every prismatic axis perpendicular to them) in
    all configurations.
    """
    import pinocchio as pin

    data = model.createData()
    rng = np.random.default_rng(0)  # a few fixed test configurations; the answer is geometric
    normal = None
    for trial in range(3):
        q = pin.neutral(model) if trial == 0 else random_configuration(model, joints, rng)
        pin.computeJointJacobians(model, data, q)
        spatial = np.asarray(data.J)
        for v, joint in enumerate(joints):
            if not joint.revolute:
                continue
            axis = spatial[3:, v] / np.linalg.norm(spatial[3:, v])
            if normal is None:
                normal = axis
            elif np.linalg.norm(np.cross(normal, axis)) > 1e-9:
                return None
        if normal is None:
            return None  # prismatic only: treat as spatial
        for v, joint in enumerate(joints):
            if not joint.revolute and abs(np.dot(spatial[:3, v], normal)) > 1e-9:
                return None
    assert normal is not None
    normal = normal * np.sign(normal[np.argmax(np.abs(normal))])
    first = np.eye(3)[int(np.argmin(np.abs(normal)))]
    first = first - np.dot(first, normal) * normal
    first /= np.linalg.norm(first)
    second = np.cross(normal, first)
    return np.stack([first, second], axis=1)


def random_configuration(model: Any, joints: list[JointKinematics], rng: np.random.Generator) -> np.ndarray:
    """A random configuration (nq,) of ``model`` [rad, m], drawn with ``rng``."""
    import pinocchio as pin

    q = pin.neutral(model)
    for joint in joints:
        angle = rng.uniform(-np.pi, np.pi)
        if joint.nq == 1:
            q[joint.idx_q] = angle if joint.revolute else rng.uniform(-0.1, 0.1)
        else:
            q[joint.idx_q : joint.idx_q + 2] = np.cos(angle), np.sin(angle)
    return q


def forward_kinematics(
    joints: list[JointKinematics], q: np.ndarray
) -> tuple[list[np.ndarray], list[np.ndarray], list[np.ndarray]]:
    """Joint frames for all configurations at once, one array per joint.

    Rotations (n, 3, 3) and origins (n, 3) [m] of the joint frames, and the parent-side points of the joint
    origins (n, 3), where the motors sit [m].
    """
    n = q.shape[0]
    rotations: list[np.ndarray] = []
    origins: list[np.ndarray] = []
    motor_points: list[np.ndarray] = []
    for joint in joints:
        if joint.parent == 0:
            parent_rotation = np.broadcast_to(np.eye(3), (n, 3, 3))
            parent_origin = np.zeros((n, 3))
        else:
            parent_rotation = rotations[joint.parent - 1]
            parent_origin = origins[joint.parent - 1]
        point = parent_origin + parent_rotation @ joint.translation
        motor_points.append(point)
        if joint.nq == 1:
            coordinate = q[:, joint.idx_q]
        else:
            coordinate = np.arctan2(q[:, joint.idx_q + 1], q[:, joint.idx_q])
        if joint.revolute:
            # placement rotation times Rodrigues' rotation about the axis, as R_p + sin R_p K + (1-cos) R_p K^2
            local = (
                joint.rotation
                + np.sin(coordinate)[:, None, None] * joint.rotation_skew
                + (1 - np.cos(coordinate))[:, None, None] * joint.rotation_skew2
            )
            rotations.append(parent_rotation @ local)
            origins.append(point)
        else:
            placed = parent_rotation @ joint.rotation
            rotations.append(placed)
            origins.append(point + coordinate[:, None] * (placed @ joint.axis))
    return rotations, origins, motor_points
