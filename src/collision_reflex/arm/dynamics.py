"""Joint torques an arm needs over a duty cycle, exact in the motor masses, and their summary statistics.

Inverse dynamics (Pinocchio's RNEA) of the links and the payload gives ``tau0(t)``. RNEA is linear in the
inertial parameters, so a point motor mass ``m_i`` (motor ``i`` sits on joint ``i``'s parent link at joint
``i``'s origin, as in :class:`collision_reflex.arm.ArmSamples`) adds exactly ``m_i tau_unit[i](t)``, the
torques of a unit point mass there: ``tau(t; m) = tau0(t) + sum_i m_i tau_unit[i](t)``. The motor must also
accelerate its own rotor; on the joint side that is the reflected inertia ``N_i^2 J_m,i`` times the joint
acceleration (:func:`joint_side_torque`).

The statistics (:func:`peak`, :func:`rms`, :func:`max_speed`) take signals with time on the last axis and are
written on :mod:`collision_reflex._backend`, so they accept NumPy arrays (batched) and CasADi columns alike.
For the optimiser the demand of joint ``j`` is affine in ``x = [1, m_0, ..., m_{nv-1}, N_j^2 J_m,j]``:
``demand_j(t) = B_j(t) x`` (:meth:`CycleTorques.demand_basis`); its peak is the set of linear constraints
``-c <= B_j x <= c`` and its mean square is the quadratic form ``x^T Q_j x`` (:meth:`CycleTorques.rms_form`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from .. import _backend as backend
from .. import _validate
from .._backend import is_symbolic
from ..errors import InvalidParameter
from .duty_cycle import DutyCycle, Payload
from .joints import joint_array
from .kinematic_tree import forward_kinematics, joint_kinematics, support_mask

if TYPE_CHECKING:
    from .robot import Arm


@dataclass(frozen=True)
class CycleTorques:
    """Joint torques of an arm over a set of motion states, split so that the motor masses enter exactly.

    The states are a duty cycle's samples (timed: they carry quadrature weights for the RMS) and the rated
    motion's peak states (untimed: weight zero, see :mod:`collision_reflex.arm.rating`), or both
    (:func:`joined`).

    Attributes
    ----------
    joint_names: the arm's joints, the order of every last axis below.
    weights: (n,) each state's weight in the cycle's mean square: the trapezoidal weights over the cycle's
        duration (:func:`time_weights`), summing to 1; zero for an untimed state [-].
    labels: (n,) what each state is, for constraint labels ("t = 1.2 s", "braking at configuration 3 ...").
    sources: (n,) the requirement each state belongs to: ``"duty cycle"``, ``"rated motion"`` or ``"braking"``.
    qd, qdd: (n, nv) joint velocities [rad/s, m/s] and accelerations [rad/s^2, m/s^2].
    structure: (n, nv) ``tau0``: torques of the links and the payload (no motors, no rotors) [N m or N].
    per_motor_mass: (nv motors, n, nv) ``tau_unit``: torques of a 1 kg point mass at each motor [N m/kg].
    """

    joint_names: tuple[str, ...]
    weights: np.ndarray
    labels: tuple[str, ...]
    sources: tuple[str, ...]
    qd: np.ndarray
    qdd: np.ndarray
    structure: np.ndarray
    per_motor_mass: np.ndarray

    @property
    def nv(self) -> int:
        """Number of joints."""
        return int(self.structure.shape[1])

    @property
    def timed(self) -> bool:
        """True when some states are a timed cycle's (an RMS torque exists)."""
        return bool(np.any(self.weights > 0))

    def torque(self, motor_mass: Any = None) -> np.ndarray:
        """``tau0 + sum_i m_i tau_unit[i]`` [N m], (n, nv), for motor masses [kg] (scalar or (nv,))."""
        if motor_mass is None:
            return self.structure
        masses = joint_array("motor_mass", motor_mass, self.nv, allow_zero=True)
        return self.structure + np.einsum("i,isj->sj", masses, self.per_motor_mass)

    def demand(self, motor_mass: Any = None, reflected_inertia: Any = 0.0) -> np.ndarray:
        """The joint-side torque the actuators must give, (n, nv) [N m]: :func:`joint_side_torque`.

        Parameters
        ----------
        motor_mass: motor masses [kg], scalar or (nv,); default none.
        reflected_inertia: ``N^2 J_m`` per joint [kg m^2], scalar or (nv,).
        """
        reflected = joint_array("reflected_inertia", reflected_inertia, self.nv, allow_zero=True)
        return joint_side_torque(self.torque(motor_mass), reflected, self.qdd)

    def demand_basis(self, joint: int) -> np.ndarray:
        """``B_j`` (n, nv + 2) with ``demand_j(t) = B_j x``, ``x = [1, m_0, ..., m_{nv-1}, N_j^2 J_m,j]``.

        Columns: ``tau0_j`` [N m], ``tau_unit[i]_j`` [N m/kg] for each motor ``i``, ``qdd_j`` [rad/s^2].
        """
        joint = _validate.integer("joint", joint, 0, self.nv - 1)
        return np.column_stack(
            [self.structure[:, joint], self.per_motor_mass[:, :, joint].T, self.qdd[:, joint]]
        )

    def rms_form(self, joint: int) -> np.ndarray:
        """``Q_j`` (nv + 2, nv + 2) with ``rms(demand_j)^2 = x^T Q_j x`` exactly (``x`` as in :meth:`demand_basis`).

        ``Q_j = B_j^T diag(w) B_j`` with the states' :attr:`weights`, so that ``sqrt(quadratic_form(Q_j, x))``
        equals :func:`rms` of the cycle's demand (untimed states weigh nothing).
        """
        basis = self.demand_basis(joint)
        return basis.T @ (self.weights[:, None] * basis)


def joined(first: CycleTorques, second: CycleTorques) -> CycleTorques:
    """The states of ``first`` and then ``second`` (the same arm), as one set."""
    if first.joint_names != second.joint_names:
        raise InvalidParameter("joint_names", second.joint_names, f"the same joints: {first.joint_names}")
    return CycleTorques(
        joint_names=first.joint_names,
        weights=np.concatenate([first.weights, second.weights]),
        labels=first.labels + second.labels,
        sources=first.sources + second.sources,
        qd=np.vstack([first.qd, second.qd]),
        qdd=np.vstack([first.qdd, second.qdd]),
        structure=np.vstack([first.structure, second.structure]),
        per_motor_mass=np.concatenate([first.per_motor_mass, second.per_motor_mass], axis=1),
    )


def cycle_torques(arm: Arm, cycle: DutyCycle) -> CycleTorques:
    """Joint torques of an :class:`~collision_reflex.arm.Arm` over a duty cycle (its samples timed).

    Parameters
    ----------
    arm: the arm; its joints must all be in the cycle (by name), and its model's gravity is used.
    cycle: the motion; its payload (if any) is held with its centre of mass at the arm's contact point.
    """
    columns = cycle.columns(arm.joint_names)
    return state_torques(
        arm,
        arm.configuration(cycle.q[:, columns]),
        cycle.qd[:, columns],
        cycle.qdd[:, columns],
        cycle.payload,
        time_weights(cycle.t) / cycle.duration,
        tuple(f"t = {t:.4g} s" for t in cycle.t),
        ("duty cycle",) * cycle.t.size,
    )


def state_torques(
    arm: Arm,
    q: np.ndarray,
    qd: np.ndarray,
    qdd: np.ndarray,
    payload: Payload | None,
    weights: np.ndarray,
    labels: tuple[str, ...],
    sources: tuple[str, ...],
) -> CycleTorques:
    """Joint torques of an arm in the motion states ``(q (n, nq), qd (n, nv), qdd (n, nv))``.

    One Pinocchio pass per state: RNEA of the links and the payload, and the joint Jacobians with their time
    derivative, from which the torques of a unit mass at every motor are assembled for all states at once:
    ``tau_unit[i] = J_i^T (a_i - g)``, ``J_i`` the translational Jacobian of motor ``i``'s point and
    ``a_i = J_i qdd + dJ_i/dt qd`` its acceleration. The rotors are not included (see :func:`joint_side_torque`).
    ``payload`` (or None) is held with its centre of mass at the arm's contact point; ``weights``, ``labels``
    and ``sources`` are the states' (:class:`CycleTorques`).
    """
    import pinocchio as pin

    model = arm.model.copy()
    model.armature = np.zeros(model.nv)  # the rotors enter through joint_side_torque
    if payload is not None:
        _add_payload(model, arm.contact_frame, arm.contact_offset, payload)
    data = model.createData()
    n, nv = q.shape[0], model.nv
    structure = np.empty((n, nv))
    spatial = np.empty((n, 6, nv))
    spatial_rate = np.empty((n, 6, nv))
    rnea, variation = pin.rnea, pin.computeJointJacobiansTimeVariation
    for s in range(n):
        structure[s] = rnea(model, data, q[s], qd[s], qdd[s])
        variation(model, data, q[s], qd[s])  # world frame J and dJ/dt of every joint
        spatial[s] = data.J
        spatial_rate[s] = data.dJ

    joints = joint_kinematics(model, arm.name)
    supports = [set(model.supports[joint.parent]) for joint in joints]
    masks = np.array([support_mask(model, joints_above) for joints_above in supports])  # (motor i, nv)
    _, _, motor_points = forward_kinematics(joints, q)
    points = np.stack(motor_points, axis=2)  # (n, 3, motor i), world frame
    # Motor i moves with its parent link, driven by the joints of masks[i]: the link's spatial velocity and
    # acceleration (world frame, at the world origin), then its point p_i's velocity v = v_o + w x p and
    # classical acceleration a = a_o + dw/dt x p + w x v. Stacked matrix products (n, ., motor i) throughout.
    masked_qd = masks.T * qd[:, :, None]  # (n, nv, i)
    twist = spatial @ masked_qd
    accel = spatial @ (masks.T * qdd[:, :, None]) + spatial_rate @ masked_qd
    omega = twist[:, 3:]
    velocity = twist[:, :3] + np.cross(omega, points, axis=1)
    acceleration = accel[:, :3] + np.cross(accel[:, 3:], points, axis=1) + np.cross(omega, velocity, axis=1)
    force = acceleration - np.asarray(model.gravity.linear, dtype=float)[:, None]  # per kg, (n, 3, i)
    # tau_unit[i] = J_i^T f with J_i = masks[i] (lin - [p_i]x ang): lin^T f + ang^T (p_i x f).
    linear, angular = np.swapaxes(spatial[:, :3], 1, 2), np.swapaxes(spatial[:, 3:], 1, 2)
    unit = masks.T * (linear @ force + angular @ np.cross(points, force, axis=1))  # (n, nv, i)
    return CycleTorques(
        joint_names=tuple(arm.joint_names),
        weights=np.asarray(weights, dtype=float),
        labels=tuple(labels),
        sources=tuple(sources),
        qd=qd,
        qdd=qdd,
        structure=structure,
        per_motor_mass=np.ascontiguousarray(np.transpose(unit, (2, 0, 1))),
    )


def _add_payload(model: Any, frame_name: str, offset: np.ndarray, payload: Payload) -> None:
    """Append the payload to the body that carries the contact frame, its centre of mass at the contact point."""
    import pinocchio as pin

    frame = model.frames[model.getFrameId(frame_name)]
    rotation = np.asarray(frame.placement.rotation)
    placement = pin.SE3(rotation, np.asarray(frame.placement.act(offset), dtype=float))
    model.appendBodyToJoint(
        int(frame.parentJoint), pin.Inertia(payload.mass, np.zeros(3), payload.inertia), placement
    )


def joint_side_torque(torque: Any, reflected_inertia: Any, acceleration: Any) -> Any:
    """The torque a joint's actuator must deliver: ``tau(t) + N^2 J_m qdd(t)`` [N m].

    The rotor's own inertia, reflected through the gear (``N^2 J_m``, [kg m^2]), is accelerated with the joint
    (``qdd`` [rad/s^2]). The rotors' gyroscopic torques (their spin coupled with the link rotations) are
    neglected, as is the rotor's mass, which is part of the motor mass. Plain arithmetic: NumPy arrays broadcast
    (e.g. (n, nv) with (nv,)), CasADi expressions work as they are.
    """
    torque = _validate.arrays("torque", torque, ndim=0)
    reflected_inertia = _validate.non_negative("reflected_inertia", reflected_inertia)
    acceleration = _validate.arrays("acceleration", acceleration, ndim=0)
    with _validate.combining(torque=torque, reflected_inertia=reflected_inertia, acceleration=acceleration):
        return torque + reflected_inertia * acceleration


def time_weights(t: Any) -> np.ndarray:
    """Trapezoidal quadrature weights (n,) [s] over sample times ``t`` (n,), non-uniform allowed.

    ``sum_s w_s f(t_s)`` is the trapezoidal rule for the integral of ``f`` from ``t[0]`` to ``t[-1]``.
    """
    t = _validate.real("t", t, "at least 2 strictly increasing times [s]")
    if t.ndim != 1 or t.size < 2 or not np.all(np.diff(t) > 0):
        raise InvalidParameter("t", t, "at least 2 strictly increasing times [s]")
    steps = np.diff(t)
    weights = np.zeros(t.size)
    weights[:-1] += 0.5 * steps
    weights[1:] += 0.5 * steps
    return weights


def peak(values: Any) -> Any:
    """``max_t |values|`` over the last axis (NumPy, batched) or of a CasADi column."""
    values = _validate.arrays("values", values)
    if not is_symbolic(values) and values.shape[-1] == 0:
        raise InvalidParameter("values", values.shape, "at least one sample on the last axis")
    return _peak(values)


def _peak(values: Any) -> Any:
    return backend.largest(backend.absolute(values), axis=-1)


def rms(values: Any, t: Any) -> Any:
    """Root mean square over the cycle, time-weighted: ``sqrt(integral of values^2 dt / T)``.

    The integral is the trapezoidal rule over the sample times ``t`` (n,) [s] (non-uniform allowed,
    :func:`time_weights`), ``T = t[-1] - t[0]``. ``values``: time on the last axis, (..., n) NumPy, or an
    (n, 1) CasADi column.
    """
    weights = time_weights(t)
    duration = float(np.asarray(t, dtype=float)[-1] - np.asarray(t, dtype=float)[0])
    values = _validate.arrays("values", values)
    if not is_symbolic(values) and values.shape[-1] != weights.size:
        raise InvalidParameter(
            "values", values.shape, f"{weights.size} samples on the last axis, one per time"
        )
    weights = weights / duration
    with _validate.combining(values=values, t=weights):
        return backend.sqrt(backend.dot(values * values, weights))


def max_speed(velocity: Any) -> np.ndarray:
    """``max_t |qd_i(t)|`` per joint [rad/s or m/s], (nv,), of joint velocities (n, nv)."""
    velocity = _validate.arrays("velocity", velocity, ndim=2)
    return np.asarray(_peak(np.asarray(velocity, dtype=float).T))
