"""The equations of motion of the simulated arm collision: links, motors, wall and momentum observer.

Links by Pinocchio's articulated-body algorithm (structure only, motor masses on their parent links, no
gravity), motors on the joint springs (diagonal rotor inertia), a Kelvin-Voigt wall that cannot pull; see
:mod:`collision_reflex.simulate.arm` for the model and :mod:`collision_reflex.simulate.arm_detection` for what
the detectors read from it.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np

from ..errors import SimulationError
from .contact import damping_from_ratio
from .setup import oscillation_period

if TYPE_CHECKING:
    from .arm import _ClosedForm, _Joints, _Sensing


def _link_model(arm: Any) -> tuple[Any, Any, int]:
    """Pinocchio's link-side model of ``arm``.

    Structure only (no armature), no gravity, motor masses carried by the parent links, and a frame at the
    contact point. Returns ``(model, data, contact frame id)``.
    """
    import pinocchio as pin

    params = arm.joint_parameters
    model = arm.model.copy()
    model.armature = np.zeros(model.nv)
    model.gravity.linear = np.zeros(3)
    for joint_id in range(1, model.njoints):
        mass = float(params.motor_mass[joint_id - 1])
        parent = int(model.parents[joint_id])
        if mass > 0 and parent > 0:
            placement = model.jointPlacements[joint_id]
            model.inertias[parent] = model.inertias[parent] + pin.Inertia(
                mass, np.asarray(placement.translation), np.zeros((3, 3))
            )
    frame = model.frames[model.getFrameId(arm.contact_frame)]
    local = np.asarray(frame.placement.act(np.asarray(arm.contact_offset, dtype=float)))
    contact_id = model.addFrame(
        pin.Frame(
            "collision_reflex_wall_contact",
            frame.parentJoint,
            pin.SE3(np.eye(3), local),
            pin.FrameType.OP_FRAME,
        )
    )
    return model, model.createData(), contact_id


class ArmDynamics:
    """Links, motors, wall and observer: the right-hand side of the state ``(q, q', theta, theta', s, impulse)``.

    ``s`` is the momentum observer's integral (zero unless it detects). It also gives the detectors'
    estimates. Before the reaction ``theta`` is algebraic (ideal admittance).
    """

    def __init__(
        self,
        arm: Any,
        joints: _Joints,
        closed: _ClosedForm,
        contact_stiffness: float,
        contact_damping_ratio: float,
        sensing: _Sensing,
    ) -> None:
        import pinocchio as pin

        self.pin = pin
        self.model, self.data, self.contact_id = _link_model(arm)
        self.nv = joints.q0.size
        self.q0, self.k_m, self.k_s, self.inertia = joints.q0, joints.k_m, joints.k_s, joints.inertia
        self.share, self.v_ref = closed.share, closed.reference_rate
        plane = arm.plane  # (3, 2) orthonormal basis of a planar arm's plane (columns), or None
        self.normal = plane @ joints.u if plane is not None else joints.u  # world-aligned wall normal
        self.p0, _ = self.contact_kinematics(joints.q0)
        self.contact_stiffness = contact_stiffness
        self.contact_damping = damping_from_ratio(
            contact_damping_ratio, closed.effective["m_f"], contact_stiffness
        )
        self.tau_max = joints.tau_max
        self.detection, self.retreat = sensing.detection, sensing.retreat
        self.observer_gain, self.current_threshold = sensing.observer_gain, sensing.current_threshold
        self.sample_rate = sensing.sample_rate
        self.drive, self.software_damping = sensing.drive, sensing.software_damping
        wall_period = oscillation_period(closed.effective["m_f"], contact_stiffness)
        default_blanking = 20 * wall_period if sensing.detection == "force" else 0.0
        self.blanking = default_blanking if sensing.blanking is None else sensing.blanking
        _, jac0 = self.contact_kinematics(joints.q0)
        self.approach_velocity = float(self.normal @ (jac0 @ self.v_ref))  # v0 [m/s]
        self.initial_momentum = self.mass_matrix(joints.q0) @ self.v_ref  # p(0) [N m s]
        self.lumped_stiffness = closed.effective["k"]
        self.evaluations, self.max_evaluations = 0, math.inf
        self.reacting = False
        self.torque = np.zeros(self.nv)  # motor torques of the reaction [N m]
        self.push = self.torque  # the reaction's torques, kept for a rebound

    def contact_kinematics(self, qs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Contact point position [m] (3,) and translational Jacobian (3, nv), world-aligned."""
        pin, model, data = self.pin, self.model, self.data
        pin.forwardKinematics(model, data, qs)
        pin.updateFramePlacement(model, data, self.contact_id)
        position = np.asarray(data.oMf[self.contact_id].translation).copy()
        jac = pin.computeFrameJacobian(model, data, qs, self.contact_id, pin.LOCAL_WORLD_ALIGNED)[:3]
        return position, np.asarray(jac)

    def motors(self, t: float, qs: np.ndarray, dq: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Motor angles [rad] and velocities [rad/s] of the ideal admittance drive at ``t`` [s]."""
        k_s, k_m = self.k_s, self.k_m
        reference = self.q0 + self.v_ref * t
        infinite = np.isinf(k_s)
        theta = np.where(
            infinite,
            reference,
            (np.where(infinite, 0, k_s) * reference + k_m * qs) / np.where(infinite, 1, k_s + k_m),
        )
        dtheta = self.share * self.v_ref + (1 - self.share) * dq
        return theta, dtheta

    def motor_state(self, t: float, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Motor angles and velocities: integrated (reaction, impedance drive), else the admittance's."""
        nv = self.nv
        if self.reacting or self.drive == "impedance":
            return y[2 * nv : 3 * nv], y[3 * nv : 4 * nv]
        return self.motors(t, y[:nv], y[nv : 2 * nv])

    def wall_force(self, position: np.ndarray, jac: np.ndarray, dq: np.ndarray) -> float:
        """Kelvin-Voigt wall force [N], zero out of contact and never pulling."""
        depth = float(self.normal @ (position - self.p0))
        if depth <= 0:
            return 0.0
        rate = float(self.normal @ (jac @ dq))
        return max(self.contact_stiffness * depth + self.contact_damping * rate, 0.0)

    def rhs(self, t: float, y: np.ndarray) -> np.ndarray:
        """Time derivative of the state at ``t`` [s]: link and motor accelerations, observer, wall force."""
        self.evaluations += 1
        if self.evaluations > self.max_evaluations:
            raise SimulationError(
                f"the arm collision needed more than {self.max_evaluations:.3g} right-hand-side evaluations "
                "(the work budget); stiffen nothing, raise max_steps, or lower contact_stiffness"
            )
        nv = self.nv
        qs, dq = y[:nv], y[nv : 2 * nv]
        theta, dtheta = self.motor_state(t, y)
        position, jac = self.contact_kinematics(qs)
        force = self.wall_force(position, jac, dq)
        spring = self.k_m * (theta - qs)
        ddq = self.pin.aba(self.model, self.data, qs, dq, spring - jac.T @ self.normal * force)
        out = np.zeros_like(y)
        out[:nv] = dq
        out[nv : 2 * nv] = ddq
        out[2 * nv : 3 * nv] = dtheta
        if self.reacting or self.drive == "impedance":
            torque = self.torque if self.reacting else self.impedance_torque(t, theta, dtheta)
            out[3 * nv : 4 * nv] = (torque - spring) / self.inertia
        if self.detection == "observer":
            coriolis = self.pin.computeCoriolisMatrix(self.model, self.data, qs, dq)
            out[4 * nv : 5 * nv] = spring + coriolis.T @ dq + self.observer_residual(y)  # no gravity here
        out[-1] = force
        return out

    def mass_matrix(self, qs: np.ndarray) -> np.ndarray:
        """The links' joint-space mass matrix ``M(q)`` (nv, nv) [kg m^2]."""
        upper = np.asarray(self.pin.crba(self.model, self.data, qs))
        return np.triu(upper) + np.triu(upper, 1).T

    def observer_residual(self, y: np.ndarray) -> np.ndarray:
        """The momentum observer's residual ``r = K (M(q) q' - p(0) - s)`` (nv,) [N m]: ``-J^T n f`` lagged."""
        nv = self.nv
        momentum = self.mass_matrix(y[:nv]) @ y[nv : 2 * nv]
        return self.observer_gain * (momentum - self.initial_momentum - y[4 * nv : 5 * nv])

    def impedance_torque(self, t: float, theta: np.ndarray, dtheta: np.ndarray) -> np.ndarray:
        """The impedance law ``k_s (theta_ref - theta) + d_s (theta_ref' - theta')`` saturated at the limit [N m]."""
        torque = self.k_s * (self.q0 + self.v_ref * t - theta) + self.software_damping * (self.v_ref - dtheta)
        return np.clip(torque, -self.tau_max, self.tau_max)

    def motor_torque(self, t: float, y: np.ndarray) -> np.ndarray:
        """Output-side motor torques ``B theta'' + K_m (theta - q)`` (nv,) [N m] (current times torque constant)."""
        if self.reacting:
            return self.torque.copy()
        if self.drive == "impedance":
            return self.impedance_torque(t, *self.motor_state(t, y))
        nv = self.nv
        theta, _ = self.motor_state(t, y)
        spring = self.k_m * (theta - y[:nv])
        # The admittance's motor acceleration (1 - share) q'': zero for an ideal velocity drive.
        ddq = self.rhs(t, y)[nv : 2 * nv]
        return self.inertia * (1 - self.share) * ddq + spring

    def force_estimate(self, t: float, y: np.ndarray) -> float:
        """Contact force along ``u`` estimated from the joint spring torques [N]."""
        qs = y[: self.nv]
        theta, _ = self.motor_state(t, y)
        _, jac = self.contact_kinematics(qs)
        lever = jac.T @ self.normal
        return float(lever @ (self.k_m * (theta - qs)) / (lever @ lever))

    def penetration(self, y: np.ndarray) -> float:
        """Depth of the contact point beyond the wall [m]."""
        position, _ = self.contact_kinematics(y[: self.nv])
        return float(self.normal @ (position - self.p0))

    def wall_forces(self, solution: Any) -> np.ndarray:
        """Wall force [N] at each step of a solution but the first."""
        nv = self.nv
        columns = solution.y.T[1:]
        return np.array([self.wall_force(*self.contact_kinematics(c[:nv]), c[nv : 2 * nv]) for c in columns])

    def start_reaction(self, t: float, y: np.ndarray) -> np.ndarray:
        """Switch the admittance off: the motors take over its state (returned) and push at the force limit.

        They push along -u, ``F_a = min_i tau_max,i / |(J^T u)_i|`` at the current configuration.
        """
        nv = self.nv
        y = y.copy()
        if self.drive != "impedance":  # the impedance drive's motors are integrated already
            y[2 * nv : 3 * nv], y[3 * nv : 4 * nv] = self.motors(t, y[:nv], y[nv : 2 * nv])
        lever = self.contact_kinematics(y[:nv])[1].T @ self.normal
        if self.retreat == "saturated":
            self.push = -self.tau_max * np.sign(lever)
        else:
            F_a = float(np.min(self.tau_max / np.maximum(np.abs(lever), 1e-300)))
            self.push = -F_a * lever
        self.reacting = True
        self.torque = self.push
        return y
