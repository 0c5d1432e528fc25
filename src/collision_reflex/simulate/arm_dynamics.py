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

if TYPE_CHECKING:
    from .arm_inputs import ArmJoints, ArmSensing, ImpactClosedForm


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


def impact_pulse_duration(
    finger_mass: float,
    contact_stiffness: float,
    contact_damping: float,
    joint_stiffness: float,
    approach_velocity: float,
    threshold: float,
) -> float:
    """How long the impact pulse can hold a contact-force sensor above its threshold [s].

    During the impact the finger (mass ``m_f``) sits between the contact (``k_c``, damper ``c``) and the joint
    springs along ``u`` (``k_m``), in parallel: ``K = k_c + k_m``, ``omega = sqrt(K / m_f)``, damping ratio
    ``zeta = c / (2 sqrt(K m_f))``. Its free motion from ``v0`` decays at ``sigma = zeta omega`` (underdamped)
    or at the slow root ``omega (zeta - sqrt(zeta^2 - 1))`` (overdamped), from an elastic force of at most
    ``A = k_c v0 / omega``. The pulse is over after half a period, or when ``A exp(-sigma t)`` has fallen to
    half the threshold, whichever is later.

    Parameters
    ----------
    finger_mass: ``m_f`` [kg]; contact_stiffness: ``k_c`` [N/m]; contact_damping: ``c`` [N s/m];
    joint_stiffness: ``k_m`` along ``u`` [N/m]; approach_velocity: ``v0`` [m/s]; threshold: ``F_s`` [N].
    """
    stiffness = contact_stiffness + joint_stiffness
    omega = math.sqrt(stiffness / finger_mass)
    zeta = contact_damping / (2 * math.sqrt(stiffness * finger_mass))
    decay = omega * (zeta - math.sqrt(zeta**2 - 1)) if zeta > 1 else omega * zeta
    amplitude = contact_stiffness * approach_velocity / omega
    fall = math.log(max(2 * amplitude / threshold, 1.0)) / decay if decay > 0 else math.inf
    return max(math.pi / omega, fall)


class ArmDynamics:
    """Links, motors, wall and observer: the right-hand side of the state ``(q, q', theta, theta', s, impulse)``.

    ``s`` is the momentum observer's integral (zero unless it detects). It also gives the detectors'
    estimates. Before the reaction ``theta`` is algebraic (ideal admittance).
    """

    def __init__(
        self,
        arm: Any,
        joints: ArmJoints,
        closed: ImpactClosedForm,
        contact_stiffness: float,
        contact_damping_ratio: float,
        sensing: ArmSensing,
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
        _, jac0 = self.contact_kinematics(joints.q0)
        self.approach_velocity = float(self.normal @ (jac0 @ self.v_ref))  # v0 [m/s]
        pulse = impact_pulse_duration(
            closed.effective["m_f"],
            contact_stiffness,
            self.contact_damping,
            closed.effective["k_m"],
            self.approach_velocity,
            sensing.threshold,
        )
        default_blanking = pulse if sensing.detection == "force" else 0.0
        self.blanking = default_blanking if sensing.blanking is None else sensing.blanking
        self.initial_momentum = self.mass_matrix(joints.q0) @ self.v_ref  # p(0) [N m s]
        self.lumped_stiffness = closed.effective["k"]
        self.evaluations, self.max_evaluations = 0, math.inf
        self.reacting = False
        self.torque = np.zeros(self.nv)  # motor torques of the reaction [N m]
        self.push = self.torque  # the reaction's torques, kept for a rebound
        self.brake_speed: float | None = None  # set once the reflex is over: the motors brake to a stop

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
            if self.brake_speed is not None:
                torque = self.brake_torque(dtheta)
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

    def residual_motor_torque(self, t: float, y: np.ndarray) -> np.ndarray:
        """Motor torques less the model's expectation for the motion, ``C(q, q') q'`` (nv,) [N m].

        The reference runs at constant joint rates (no commanded acceleration) and gravity is left out, so
        the model's torque is the links' Coriolis and centrifugal torque at the measured ``q, q'``.
        """
        nv = self.nv
        qs, dq = y[:nv], y[nv : 2 * nv]
        expected = np.asarray(self.pin.rnea(self.model, self.data, qs, dq, np.zeros(nv)))
        return self.motor_torque(t, y) - expected

    def position_error(self, t: float, y: np.ndarray) -> float:
        """The contact point's error along ``n`` against the motors' commanded path [m].

        ``n . (p(theta_ref(t)) - p(q))``: the reference joint angles ``q0 + theta_ref' t`` through the forward
        kinematics, less the contact point's position.
        """
        commanded, _ = self.contact_kinematics(self.q0 + self.v_ref * t)
        position, _ = self.contact_kinematics(y[: self.nv])
        return float(self.normal @ (commanded - position))

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

    def brake(self, y: np.ndarray | None) -> None:
        """Once the reflex is over (``y``: the state then) the motors brake to a stop; ``None``: push again.

        Braking opposes each motor's velocity with its torque limit (the push's size where the limit is
        infinite), smoothed below 5 % of the fastest motor's speed when it starts, so that the motors come to
        rest instead of coasting with the speed the push gave them.
        """
        if y is None:
            self.brake_speed, self.torque = None, self.push
            return
        self.brake_speed = 0.05 * float(np.max(np.abs(y[3 * self.nv : 4 * self.nv]))) + 1e-9

    def brake_torque(self, dtheta: np.ndarray) -> np.ndarray:
        """The braking motor torques (nv,) [N m] at motor velocities ``dtheta`` [rad/s] (see :meth:`brake`)."""
        assert self.brake_speed is not None
        limit = np.where(np.isfinite(self.tau_max), self.tau_max, np.abs(self.push))
        return -limit * np.tanh(dtheta / self.brake_speed)

    def motor_approach(self, y: np.ndarray) -> float:
        """The motors' velocity toward the wall [m/s]: the motor rates through the contact Jacobian, along ``n``."""
        nv = self.nv
        _, jac = self.contact_kinematics(y[:nv])
        return float(self.normal @ (jac @ y[3 * nv : 4 * nv]))

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
