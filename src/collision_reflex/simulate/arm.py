"""Time-domain collision of an arm with elastic joints against a compliant wall, compared with the arm-level
closed form (MODEL.md §3, the paper's section "Collision Reflex in Higher Dimensions").

Each joint is a link side and a motor side coupled by the joint's mechanical spring ``k_m,i``::

    links:   M(q) q'' + C(q, q') q' = K_m (theta - q) - J(q)^T n f          (Pinocchio's ABA, no armature)
    motors:  B theta'' = tau - K_m (theta - q),   B = diag(N_i^2 J_m,i)      (rotor side, diagonal)

``J`` is the contact point's translational Jacobian, ``n`` the wall normal (the collision direction ``u``) and
``f`` the wall force, a stiff Kelvin-Voigt contact that cannot pull (the wall is frictionless: the contact point
may slide along it). Gravity is left out, as in the closed form.

Approach and sensing follow the 1D ideal drive (:mod:`collision_reflex.simulate.collision`) joint by joint: each motor is
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
from scipy.integrate import solve_ivp

from .. import _validate
from ..errors import InvalidParameter, SimulationError
from ..model.impulse import total_impulse

ARM_REACTIONS: tuple[str, ...] = ("at_rest", "moving")


@dataclass(frozen=True)
class ArmCollision:
    """A simulated arm collision and the arm-level closed form for the same configuration and direction.

    Attributes
    ----------
    q: the configuration at impact (nq,) [rad].
    direction: the unit collision direction, in the arm's task coordinates (task_dim,).
    velocity: approach velocity of the contact point [m/s].
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
    velocity: float
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


def simulate_arm_collision(
    arm: Any,
    q: Any,
    direction: Any,
    velocity: float,
    threshold: float,
    *,
    software_stiffness: Any = math.inf,
    mechanical_stiffness: Any = None,
    reflected_inertia: Any = None,
    torque_limit: Any = None,
    wall_stiffness: float = 1e6,
    wall_damping_ratio: float = 2.0,
    delay: float = 0.0,
    reaction: str = "moving",
    rtol: float = 1e-9,
) -> ArmCollision:
    """Drive the arm's contact point along ``direction`` into a wall at ``velocity`` and simulate the collision.

    Parameters
    ----------
    arm: a :class:`collision_reflex.Arm` (fixed base, one coordinate per joint).
    q: configuration at impact (nq,) [rad].
    direction: collision direction in the arm's task coordinates (task_dim,), normalised here; it is the
        wall's inward normal.
    velocity: approach velocity of the contact point [m/s], > 0.
    threshold: contact-force threshold of the detector [N], > 0.
    software_stiffness: joint software stiffness [N m/rad] (scalar or (nv,)); ``inf`` (default) for ideally
        velocity-controlled motors.
    mechanical_stiffness: joint spring between link and motor [N m/rad] (scalar or (nv,)), finite; default
        the arm's joint parameters.
    reflected_inertia: motor-side inertia ``N^2 J_m`` per joint [kg m^2], > 0; default the arm's.
    torque_limit: output torque limit per joint [N m], > 0; default the arm's.
    wall_stiffness: the wall's contact stiffness [N/m].
    wall_damping_ratio: its damping as a ratio of critical for the effective finger mass (2 gives a
        restitution of 0.02, see :func:`collision_reflex.simulate.collision.contact_restitution`).
    delay: sensing delay [s], >= 0.
    reaction: the closed form's variant to compare with, ``"moving"`` (with the robot velocity at detection)
        or ``"at_rest"``.
    rtol: the integrator's relative tolerance.
    """
    import pinocchio as pin

    from ..arm.core import effective_parameters

    _validate.choice("reaction", reaction, ARM_REACTIONS)
    for name, value in (("velocity", velocity), ("threshold", threshold), ("wall_stiffness", wall_stiffness)):
        _validate.positive(name, value)
    _validate.non_negative("delay", delay)
    _validate.positive("wall_damping_ratio", wall_damping_ratio)
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
    lumped = 1 / (1 / k_m + 1 / k_s)

    # The closed form at the impact configuration (issue 4's effective parameters; the impulse from
    # collision_reflex.model.impulse).
    samples = arm.kinematics(q0[None])
    effective = effective_parameters(
        samples,
        u[None],
        inertia,
        lumped,
        k_m,
        tau_max,
        motor_mass=params.motor_mass if np.any(params.motor_mass > 0) else None,
    )
    eff = {name: float(getattr(effective, name)[0, 0]) for name in ("m_f", "m_r", "k", "k_m", "F_a", "a")}
    if bool(effective.singular[0, 0]):
        raise InvalidParameter(
            "direction", direction, "a direction the arm can move along at q", "q is singular there"
        )
    jac0 = samples.jacobian[0]
    share = np.where(np.isinf(k_s), 1.0, k_s / np.where(np.isinf(k_s), 1.0, k_s + k_m))
    reference_rate = np.linalg.pinv(jac0) @ u * velocity  # theta_ref' [rad/s]
    robot_velocity = float(u @ jac0 @ (share * reference_rate))
    closed = float(
        total_impulse(
            eff["m_f"],
            eff["k"],
            eff["k_m"],
            threshold,
            eff["a"],
            velocity,
            reaction,
            robot_velocity if reaction == "moving" else None,
        )
    )

    # Link-side model: structure only (no armature), no gravity, motor masses carried by the parent links,
    # and a frame at the contact point.
    model = arm.model.copy()
    model.armature = np.zeros(nv)
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
    data = model.createData()
    plane = arm.plane  # (3, 2) orthonormal basis of a planar arm's plane (columns), or None
    normal = plane @ u if plane is not None else u  # world-aligned wall normal

    def contact_kinematics(qs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        pin.forwardKinematics(model, data, qs)
        pin.updateFramePlacement(model, data, contact_id)
        position = np.asarray(data.oMf[contact_id].translation).copy()
        jac = pin.computeFrameJacobian(model, data, qs, contact_id, pin.LOCAL_WORLD_ALIGNED)[:3]
        return position, np.asarray(jac)

    p0, _ = contact_kinematics(q0)
    w_f = 1 / eff["m_f"]
    wall_damping = 2 * wall_damping_ratio * math.sqrt(wall_stiffness / w_f)
    v_ref = reference_rate

    # State: q, q', theta, theta', impulse. Before the reaction theta is algebraic (ideal admittance).
    state = {"reacting": False, "torque": np.zeros(nv)}

    def motors(t: float, qs: np.ndarray, dq: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        reference = q0 + v_ref * t
        theta = np.where(
            np.isinf(k_s),
            reference,
            (np.where(np.isinf(k_s), 0, k_s) * reference + k_m * qs) / np.where(np.isinf(k_s), 1, k_s + k_m),
        )
        dtheta = share * v_ref + (1 - share) * dq
        return theta, dtheta

    def wall_force(position: np.ndarray, jac: np.ndarray, dq: np.ndarray) -> float:
        depth = float(normal @ (position - p0))
        if depth <= 0:
            return 0.0
        return max(wall_stiffness * depth + wall_damping * float(normal @ (jac @ dq)), 0.0)

    def rhs(t: float, y: np.ndarray) -> np.ndarray:
        qs, dq = y[:nv], y[nv : 2 * nv]
        if state["reacting"]:
            theta, dtheta = y[2 * nv : 3 * nv], y[3 * nv : 4 * nv]
        else:
            theta, dtheta = motors(t, qs, dq)
        position, jac = contact_kinematics(qs)
        force = wall_force(position, jac, dq)
        spring = k_m * (theta - qs)
        ddq = pin.aba(model, data, qs, dq, spring - jac.T @ normal * force)
        out = np.empty_like(y)
        out[:nv] = dq
        out[nv : 2 * nv] = ddq
        out[2 * nv : 3 * nv] = dtheta
        out[3 * nv : 4 * nv] = (state["torque"] - spring) / inertia if state["reacting"] else 0.0
        out[-1] = force
        return out

    def estimate(t: float, y: np.ndarray) -> float:
        qs, dq = y[:nv], y[nv : 2 * nv]
        theta = y[2 * nv : 3 * nv] if state["reacting"] else motors(t, qs, dq)[0]
        _, jac = contact_kinematics(qs)
        lever = jac.T @ normal
        return float(lever @ (k_m * (theta - qs)) / (lever @ lever))

    def detected(t: float, y: np.ndarray) -> float:
        return estimate(t, y) - threshold

    detected.terminal, detected.direction = True, 1  # type: ignore[attr-defined]

    def separated(t: float, y: np.ndarray) -> float:
        position, _ = contact_kinematics(y[:nv])
        return float(normal @ (position - p0))

    separated.terminal, separated.direction = True, -1  # type: ignore[attr-defined]

    # Steps: a sixteenth of the shortest period in play (wall contact, link and motor on the joint springs).
    m_r = eff["m_r"]
    periods = [
        2 * math.pi * math.sqrt(eff["m_f"] / wall_stiffness),
        2 * math.pi * math.sqrt(eff["m_f"] / eff["k_m"]),
        2 * math.pi * math.sqrt(m_r / eff["k_m"]),
        2 * math.pi * math.sqrt(float(np.min(inertia / k_m))),
    ]
    max_step = min(periods) / 16
    t1_estimate = threshold / (eff["k"] * velocity)
    duration = (
        50 * (t1_estimate + delay)
        + 50 * math.sqrt(2 * threshold / (eff["a"] * eff["k_m"]) + 1e-30)
        + 20 * max(periods)
    )

    y = np.zeros(4 * nv + 1)
    y[:nv] = q0
    y[nv : 2 * nv] = v_ref  # the links move with the motors before the impact
    options: dict[str, Any] = {"method": "DOP853", "rtol": rtol, "atol": 1e-12, "max_step": max_step}
    times, forces = [np.array([0.0])], [np.array([0.0])]

    def record(solution: Any) -> None:
        times.append(solution.t[1:])
        forces.append(
            np.array(
                [wall_force(*contact_kinematics(col[:nv]), col[nv : 2 * nv]) for col in solution.y.T[1:]]
            )
        )

    # 1. Impact and sensing until the estimated force reaches the threshold.
    solution = solve_ivp(rhs, (0.0, duration), y, events=detected, **options)
    record(solution)
    if solution.status != 1:
        raise SimulationError(
            f"the contact force never reached the threshold {threshold:g} N within {duration:.3g} s; lower it"
        )
    detection_time = float(solution.t[-1])
    y = solution.y[:, -1].copy()
    # 2. The delay, still tracking the reference.
    t = detection_time
    if delay > 0:
        solution = solve_ivp(rhs, (t, t + delay), y, **options)
        record(solution)
        y, t = solution.y[:, -1].copy(), t + delay
    reaction_time = t
    # 3. The reaction: admittance off, the motors push at the force limit along -u.
    theta, dtheta = motors(t, y[:nv], y[nv : 2 * nv])
    y[2 * nv : 3 * nv], y[3 * nv : 4 * nv] = theta, dtheta
    _, jac_now = contact_kinematics(y[:nv])
    lever = jac_now.T @ normal
    force_limit = float(np.min(tau_max / np.maximum(np.abs(lever), 1e-300)))
    state["reacting"] = True
    state["torque"] = -force_limit * lever
    contact_end = math.nan
    finger_period = 2 * math.pi * math.sqrt(eff["m_f"] / eff["k_m"])
    for _ in range(50):
        solution = solve_ivp(rhs, (t, duration), y, events=separated, **options)
        record(solution)
        y, t = solution.y[:, -1].copy(), float(solution.t[-1])
        if solution.status != 1:
            raise SimulationError(f"the contact had not ended after {duration:.3g} s; lengthen it")
        contact_end = t
        # The reflex is over: the motors stop pushing and coast away. Watch two periods of the finger on its
        # springs for a rebound into the wall before stopping (a constant torque kept on would spin the arm
        # round into the wall again, which is no part of the reflex).
        state["torque"] = np.zeros(nv)
        watch = solve_ivp(rhs, (t, t + 2 * finger_period), y, **options)
        record(watch)
        rebound = watch.y[-1, -1] > y[-1]
        y, t = watch.y[:, -1].copy(), float(watch.t[-1])
        if not rebound:
            break
        state["torque"] = -force_limit * lever
    else:
        raise SimulationError("the finger kept hitting the wall again after the reaction (50 rebounds)")
    return ArmCollision(
        q=q0,
        direction=u,
        velocity=float(velocity),
        t=np.concatenate(times),
        contact_force=np.concatenate(forces),
        impulse=float(y[-1]),
        detection_time=detection_time,
        reaction_time=reaction_time,
        contact_end=contact_end,
        effective=eff,
        robot_velocity=robot_velocity,
        closed_form=closed,
        reaction=reaction,
    )


def _joint(name: str, value: Any, nv: int, allow_inf: bool = False) -> np.ndarray:
    array = (
        np.broadcast_to(np.asarray(value, dtype=float), (nv,)).copy()
        if np.ndim(value) == 0
        else (np.asarray(value, dtype=float).reshape(-1))
    )
    if array.shape != (nv,):
        raise InvalidParameter(name, value, f"one value or {nv} values, one per joint")
    _validate.positive(name, array, allow_inf=allow_inf)
    return array
