"""Time-domain collision of an arm with elastic joints against a compliant wall.

It is compared with the arm-level closed form (the paper's section "Collision Reflex in Higher
Dimensions").

Each joint is a link side and a motor side coupled by the joint's mechanical spring ``k_m,i``::

    links:   M(q) q'' + C(q, q') q' = K_m (theta - q) - J(q)^T n f          (Pinocchio's ABA, no armature)
    motors:  B theta'' = tau - K_m (theta - q),   B = diag(N_i^2 J_m,i)      (rotor side, diagonal)

``J`` is the contact point's translational Jacobian, ``n`` the wall normal (the collision direction ``u``) and
``f`` the wall force, a stiff Kelvin-Voigt contact that cannot pull (the wall is frictionless: the contact point
may slide along it). Gravity is left out, as in the closed form.

Approach and sensing follow the 1D ideal drive (:mod:`collision_reflex.simulate`) joint by joint: each motor is
ideally velocity-controlled along ``theta_ref' = J(q0)^+ u v0`` (the contact point approaches along ``u`` at
``v0``) and its software stiffness ``k_s,i`` acts as an admittance, so that the joint springs are the series
``K = K_m K_s / (K_m + K_s)`` of the closed form. Detection is on the contact force estimated from the joint
spring torques (a joint-torque sensor or observer): ``f_est = (J^T u) . tau_spring / |J^T u|^2``. At
detection (plus an optional delay) the admittance is switched off and the motors push with
``tau = -F_a J^T u``, ``F_a = min_i tau_max,i / |(J^T u)_i|``: the largest force along ``-u`` before the first
joint saturates, as the closed form's ``a = F_a / m_r`` assumes.

What the closed form leaves out and this model keeps: the links' motion along the wall after the impact (the
finger's momentum is only removed along ``u``), the motors' acceleration off the direction ``u`` during the
reaction, the wall's compliance and rebound, and the change of ``J`` during the contact.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from .. import _validate
from .._compat import renamed_keywords
from ..errors import InvalidParameter, SimulationError
from ..model.impulse import collision_times, series_stiffness, total_impulse
from .contact import damping_from_ratio
from .dynamics import admittance_share
from .setup import oscillation_period

ARM_REACTIONS: tuple[str, ...] = ("at_rest", "moving")
_MAX_REBOUNDS = 50  # contacts after the reaction before the finger is taken to keep hitting the wall
_RENAMED_KEYWORDS = {
    "velocity": "approach_velocity",
    "wall_stiffness": "contact_stiffness",
    "wall_damping_ratio": "contact_damping_ratio",
}


@dataclass(frozen=True)
class ArmCollision:
    """A simulated arm collision and the arm-level closed form for the same configuration and direction.

    Attributes
    ----------
    q: the configuration at impact (nq,) [rad].
    direction: the unit collision direction, in the arm's task coordinates (task_dim,).
    approach_velocity: approach velocity of the contact point [m/s] (formerly ``velocity``).
    t: trace times [s], impact at 0; contact_force: the wall force at ``t`` [N].
    impulse: simulated impulse on the wall [N*s].
    detection_time, reaction_time, contact_end: [s].
    effective: the effective 1D parameters at ``q`` along ``direction`` (``m_f, m_r, k, k_m, F_a, a``; SI).
    robot_velocity: the closed form's robot velocity at detection along ``u``, ``u^T J S J^+ u v0`` with
        ``S = diag(k_s / (k_s + k_m))`` [m/s] (``v0`` for ideally velocity-controlled motors).
    closed_form: the closed form's impulse [N*s] with ``reaction`` (and ``robot_velocity`` if moving).
    reaction: the closed form's reaction variant.
    """

    q: np.ndarray
    direction: np.ndarray
    approach_velocity: float
    t: np.ndarray
    contact_force: np.ndarray
    impulse: float
    detection_time: float
    reaction_time: float
    contact_end: float
    effective: dict[str, float]
    robot_velocity: float
    closed_form: float
    reaction: str

    @property
    def relative_difference(self) -> float:
        """``impulse / closed_form - 1``."""
        return self.impulse / self.closed_form - 1


_renamed = renamed_keywords(velocity="approach_velocity")
ArmCollision.__init__ = _renamed(ArmCollision.__init__)  # type: ignore[method-assign]


@renamed_keywords(**_RENAMED_KEYWORDS)
def simulate_arm_collision(
    arm: Any,
    q: Any,
    direction: Any,
    approach_velocity: float,
    threshold: float,
    *,
    software_stiffness: Any = math.inf,
    mechanical_stiffness: Any = None,
    reflected_inertia: Any = None,
    torque_limit: Any = None,
    contact_stiffness: float = 1e6,
    contact_damping_ratio: float = 2.0,
    delay: float = 0.0,
    reaction: str = "moving",
    rtol: float = 1e-9,
) -> ArmCollision:
    """Simulate the collision of the arm's contact point with a wall.

    The contact point is driven along ``direction`` into the wall at ``approach_velocity``.

    Parameters
    ----------
    arm: a :class:`collision_reflex.Arm` (fixed base, one coordinate per joint).
    q: configuration at impact (nq,) [rad].
    direction: collision direction in the arm's task coordinates (task_dim,), normalised here; it is the
        wall's inward normal.
    approach_velocity: approach velocity of the contact point [m/s], > 0 (formerly ``velocity``).
    threshold: contact-force threshold of the detector [N], > 0.
    software_stiffness: joint software stiffness [N m/rad] (scalar or (nv,)); ``inf`` (default) for ideally
        velocity-controlled motors.
    mechanical_stiffness: joint spring between link and motor [N m/rad] (scalar or (nv,)), finite; default
        the arm's joint parameters.
    reflected_inertia: motor-side inertia ``N^2 J_m`` per joint [kg m^2], > 0; default the arm's.
    torque_limit: output torque limit per joint [N m], > 0; default the arm's.
    contact_stiffness: the wall's contact stiffness [N/m] (formerly ``wall_stiffness``).
    contact_damping_ratio: its damping as a ratio of critical for the effective finger mass (dimensionless;
        2 gives a restitution of 0.02, see :func:`collision_reflex.simulate.contact_restitution`; formerly
        ``wall_damping_ratio``).
    delay: sensing delay [s], >= 0.
    reaction: the closed form's variant to compare with, ``"moving"`` (with the robot velocity at detection)
        or ``"at_rest"``.
    rtol: the integrator's relative tolerance.
    """
    _validate.choice("reaction", reaction, ARM_REACTIONS)
    for name, value in (
        ("approach_velocity", approach_velocity),
        ("threshold", threshold),
        ("contact_stiffness", contact_stiffness),
    ):
        _validate.positive(name, value)
    _validate.non_negative("delay", delay)
    _validate.positive("contact_damping_ratio", contact_damping_ratio)
    joints = _joints(
        arm, q, direction, software_stiffness, mechanical_stiffness, reflected_inertia, torque_limit
    )
    closed = _closed_form(arm, joints, float(approach_velocity), float(threshold), reaction)
    dynamics = _ArmDynamics(arm, joints, closed, contact_stiffness, contact_damping_ratio)
    trace = _integrate(dynamics, closed, float(approach_velocity), float(threshold), delay, rtol)
    return ArmCollision(
        q=joints.q0,
        direction=joints.u,
        approach_velocity=float(approach_velocity),
        t=np.concatenate(trace.times),
        contact_force=np.concatenate(trace.forces),
        impulse=trace.impulse,
        detection_time=trace.detection_time,
        reaction_time=trace.reaction_time,
        contact_end=trace.contact_end,
        effective=closed.effective,
        robot_velocity=closed.robot_velocity,
        closed_form=closed.impulse,
        reaction=reaction,
    )


@dataclass(frozen=True)
class _Joints:
    """The validated inputs of an arm collision.

    Impact configuration (nv,) [rad], unit direction (task_dim,), and per joint (nv,) the mechanical and
    software stiffness [N m/rad], the reflected inertia [kg m^2] and the torque limit [N m]; the arm's motor
    masses (nv,) [kg].
    """

    q0: np.ndarray
    u: np.ndarray
    k_m: np.ndarray
    k_s: np.ndarray
    inertia: np.ndarray
    tau_max: np.ndarray
    motor_mass: np.ndarray


def _joints(
    arm: Any,
    q: Any,
    direction: Any,
    software_stiffness: Any,
    mechanical_stiffness: Any,
    reflected_inertia: Any,
    torque_limit: Any,
) -> _Joints:
    """Check the configuration, the direction and the joint parameters (the arm's where not given)."""
    nv = int(arm.nv)
    if arm.nq != nv:
        raise InvalidParameter(
            "arm",
            arm.name,
            "one configuration coordinate per joint",
            "continuous joints are not supported here",
        )
    params = arm.joint_parameters
    k_m = _joint(
        "mechanical_stiffness",
        params.mechanical_stiffness if mechanical_stiffness is None else mechanical_stiffness,
        nv,
        allow_inf=True,
    )
    if not np.all(np.isfinite(k_m)):
        raise InvalidParameter(
            "mechanical_stiffness",
            k_m,
            "finite joint stiffnesses [N m/rad]",
            "the joints must be elastic: give mechanical_stiffness",
        )
    k_s = _joint("software_stiffness", software_stiffness, nv, allow_inf=True)
    inertia = _joint(
        "reflected_inertia", params.reflected_inertia if reflected_inertia is None else reflected_inertia, nv
    )
    tau_max = _joint(
        "torque_limit", params.torque_limit if torque_limit is None else torque_limit, nv, allow_inf=True
    )
    q0 = np.asarray(q, dtype=float).reshape(-1)
    if q0.shape != (nv,) or not np.all(np.isfinite(q0)):
        raise InvalidParameter("q", q, f"{nv} finite joint angles [rad]")
    u = np.asarray(direction, dtype=float).reshape(-1)
    if u.shape != (arm.task_dim,) or not np.all(np.isfinite(u)) or np.linalg.norm(u) == 0:
        raise InvalidParameter("direction", direction, f"a nonzero vector of {arm.task_dim} task coordinates")
    u = u / np.linalg.norm(u)
    return _Joints(q0, u, k_m, k_s, inertia, tau_max, np.asarray(params.motor_mass, dtype=float))


def _joint(name: str, value: Any, nv: int, allow_inf: bool = False) -> np.ndarray:
    """One value per joint (nv,), a scalar broadcast, each > 0."""
    array = (
        np.broadcast_to(np.asarray(value, dtype=float), (nv,)).copy()
        if np.ndim(value) == 0
        else (np.asarray(value, dtype=float).reshape(-1))
    )
    if array.shape != (nv,):
        raise InvalidParameter(name, value, f"one value or {nv} values, one per joint")
    _validate.positive(name, array, allow_inf=allow_inf)
    return array


@dataclass(frozen=True)
class _ClosedForm:
    """The arm-level closed form at the impact configuration, and the reference motion it assumes.

    effective: the effective 1D parameters (``m_f, m_r, k, k_m, F_a, a``; SI).
    share: per joint, the share of the reference velocity the admittance follows (nv,).
    reference_rate: the motors' reference velocity ``J(q0)^+ u v0`` (nv,) [rad/s].
    robot_velocity: the robot velocity at detection along ``u`` [m/s].
    impulse: the closed form's impulse [N*s].
    """

    effective: dict[str, float]
    share: np.ndarray
    reference_rate: np.ndarray
    robot_velocity: float
    impulse: float


def _closed_form(
    arm: Any, joints: _Joints, approach_velocity: float, threshold: float, reaction: str
) -> _ClosedForm:
    """Issue 4's effective parameters at ``q0`` along ``u`` through :mod:`collision_reflex.model.impulse`."""
    from ..arm import effective_parameters

    u = joints.u
    samples = arm.kinematics(joints.q0[None])
    effective = effective_parameters(
        samples,
        u[None],
        joints.inertia,
        series_stiffness(joints.k_m, joints.k_s),
        joints.k_m,
        joints.tau_max,
        motor_mass=joints.motor_mass if np.any(joints.motor_mass > 0) else None,
    )
    eff = {name: float(getattr(effective, name)[0, 0]) for name in ("m_f", "m_r", "k", "k_m", "F_a", "a")}
    if bool(effective.singular[0, 0]):
        raise InvalidParameter(
            "direction", u, "a direction the arm can move along at q", "q is singular there"
        )
    jac0 = samples.jacobian[0]
    share = admittance_share(joints.k_m, joints.k_s)
    reference_rate = np.linalg.pinv(jac0) @ u * approach_velocity  # theta_ref' [rad/s]
    robot_velocity = float(u @ jac0 @ (share * reference_rate))
    impulse = total_impulse(
        eff["m_f"],
        eff["k"],
        eff["k_m"],
        threshold,
        eff["a"],
        approach_velocity,
        reaction,
        robot_velocity if reaction == "moving" else None,
    )
    return _ClosedForm(eff, share, reference_rate, robot_velocity, float(impulse))


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


class _ArmDynamics:
    """Links, motors and wall: the right-hand side of the state ``(q, q', theta, theta', impulse)``.

    It also gives the estimated contact force. Before the reaction ``theta`` is algebraic (ideal admittance).
    """

    def __init__(
        self,
        arm: Any,
        joints: _Joints,
        closed: _ClosedForm,
        contact_stiffness: float,
        contact_damping_ratio: float,
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
        """Motor angles and velocities: integrated during the reaction, the admittance's before."""
        nv = self.nv
        if self.reacting:
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
        """Time derivative of the state at ``t`` [s]: link and motor accelerations, the wall force."""
        nv = self.nv
        qs, dq = y[:nv], y[nv : 2 * nv]
        theta, dtheta = self.motor_state(t, y)
        position, jac = self.contact_kinematics(qs)
        force = self.wall_force(position, jac, dq)
        spring = self.k_m * (theta - qs)
        ddq = self.pin.aba(self.model, self.data, qs, dq, spring - jac.T @ self.normal * force)
        out = np.empty_like(y)
        out[:nv] = dq
        out[nv : 2 * nv] = ddq
        out[2 * nv : 3 * nv] = dtheta
        out[3 * nv : 4 * nv] = (self.torque - spring) / self.inertia if self.reacting else 0.0
        out[-1] = force
        return out

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
        y[2 * nv : 3 * nv], y[3 * nv : 4 * nv] = self.motors(t, y[:nv], y[nv : 2 * nv])
        lever = self.contact_kinematics(y[:nv])[1].T @ self.normal
        F_a = float(np.min(self.tau_max / np.maximum(np.abs(lever), 1e-300)))
        self.reacting = True
        self.push = -F_a * lever
        self.torque = self.push
        return y


@dataclass
class _ArmTrace:
    """What the integration records: trace segments and the phase times [s], the impulse [N*s]."""

    times: list[np.ndarray]
    forces: list[np.ndarray]
    detection_time: float = math.nan
    reaction_time: float = math.nan
    contact_end: float = math.nan
    impulse: float = math.nan

    def add(self, solution: Any, dynamics: _ArmDynamics) -> None:
        self.times.append(solution.t[1:])
        self.forces.append(dynamics.wall_forces(solution))


def _time_scales(
    dynamics: _ArmDynamics, closed: _ClosedForm, approach_velocity: float, threshold: float, delay: float
) -> tuple[float, float, float]:
    """Largest step, simulated time limit and the finger's period on the joint springs [s]."""
    eff = closed.effective
    finger_period = oscillation_period(eff["m_f"], eff["k_m"])
    periods = [
        oscillation_period(eff["m_f"], dynamics.contact_stiffness),
        finger_period,
        oscillation_period(eff["m_r"], eff["k_m"]),
        min(oscillation_period(b, k) for b, k in zip(dynamics.inertia, dynamics.k_m, strict=True)),
    ]
    max_step = min(periods) / 16  # a sixteenth of the shortest period in play
    # Fifty closed-form contacts (paper's reaction) and delays, and twenty of the longest periods.
    _, t2 = collision_times(eff["m_f"], eff["k"], eff["k_m"], threshold, eff["a"], approach_velocity)
    duration = 50 * (t2 + delay) + 20 * max(periods)
    return max_step, float(duration), finger_period


def _integrate(
    dynamics: _ArmDynamics,
    closed: _ClosedForm,
    approach_velocity: float,
    threshold: float,
    delay: float,
    rtol: float,
) -> _ArmTrace:
    """Integrate the arm's collision, phase by phase.

    Impact and sensing until detection, the delay, then the reaction until the finger has left the wall for
    good.
    """
    from scipy.integrate import solve_ivp  # here: SciPy's import time is paid only by a simulation

    max_step, duration, finger_period = _time_scales(dynamics, closed, approach_velocity, threshold, delay)
    nv = dynamics.nv
    y = np.zeros(4 * nv + 1)
    y[:nv] = dynamics.q0
    y[nv : 2 * nv] = dynamics.v_ref  # the links move with the motors before the impact
    options: dict[str, Any] = {"method": "DOP853", "rtol": rtol, "atol": 1e-12, "max_step": max_step}
    trace = _ArmTrace([np.array([0.0])], [np.array([0.0])])

    def detected(t: float, y: np.ndarray) -> float:
        return dynamics.force_estimate(t, y) - threshold

    detected.terminal, detected.direction = True, 1  # type: ignore[attr-defined]

    # 1. Impact and sensing until the estimated force reaches the threshold.
    solution = solve_ivp(dynamics.rhs, (0.0, duration), y, events=detected, **options)
    trace.add(solution, dynamics)
    if solution.status != 1:
        raise SimulationError(
            f"the contact force never reached the threshold {threshold:g} N within {duration:.3g} s; lower it"
        )
    t = trace.detection_time = float(solution.t[-1])
    y = solution.y[:, -1].copy()
    # 2. The delay, still tracking the reference.
    if delay > 0:
        solution = solve_ivp(dynamics.rhs, (t, t + delay), y, **options)
        trace.add(solution, dynamics)
        y, t = solution.y[:, -1].copy(), t + delay
    trace.reaction_time = t
    # 3. The reaction: admittance off, the motors push at the force limit along -u.
    y = dynamics.start_reaction(t, y)
    _react(dynamics, trace, t, y, duration, 2 * finger_period, options)
    return trace


def _react(
    dynamics: _ArmDynamics,
    trace: _ArmTrace,
    t: float,
    y: np.ndarray,
    duration: float,
    watch: float,
    options: dict[str, Any],
) -> None:
    """Push until the finger leaves the wall; then the reflex is over: the motors stop pushing and coast away.

    Watch ``watch`` [s] for a rebound into the wall before stopping (a constant torque kept on would spin the
    arm round into the wall again, which is no part of the reflex), and push again if there is one.
    """
    from scipy.integrate import solve_ivp

    def separated(t: float, y: np.ndarray) -> float:
        return dynamics.penetration(y)

    separated.terminal, separated.direction = True, -1  # type: ignore[attr-defined]

    for _ in range(_MAX_REBOUNDS):
        solution = solve_ivp(dynamics.rhs, (t, duration), y, events=separated, **options)
        trace.add(solution, dynamics)
        y, t = solution.y[:, -1].copy(), float(solution.t[-1])
        if solution.status != 1:
            raise SimulationError(f"the contact had not ended after {duration:.3g} s; lengthen it")
        trace.contact_end = t
        dynamics.torque = np.zeros(dynamics.nv)
        coast = solve_ivp(dynamics.rhs, (t, t + watch), y, **options)
        trace.add(coast, dynamics)
        rebound = coast.y[-1, -1] > y[-1]
        y, t = coast.y[:, -1].copy(), float(coast.t[-1])
        if not rebound:
            break
        dynamics.torque = dynamics.push
    else:
        raise SimulationError(
            f"the finger kept hitting the wall again after the reaction ({_MAX_REBOUNDS} rebounds)"
        )
    trace.impulse = float(y[-1])
