"""The arm's collision in joint space: the 1D model's three phases with the links free to slide along the wall.

The arm-level closed form reduces the arm to a 1D finger mass ``m_f``, robot mass ``m_r``, spring ``k`` and force
``F_a`` along ``u``. What it leaves out is the links' motion *along* the wall. A frictionless wall removes the
finger's momentum along ``u`` only; the links keep the rest of it and, with the joint springs, oscillate in the
``nv - 1`` directions that keep the contact point on the wall. The contact force, the wall's reaction that holds
the point on it, then carries that oscillation: it rises as ``k v0 t`` *plus* a sum of sinusoids, reaches the
threshold earlier or later than ``t1 = F_s / (k v0)``, and the reaction starts from a spring compression other
than ``F_s / k``. This module derives it, linearised at the impact configuration (``M``, ``J`` frozen), with the
closed form's other assumptions kept: a rigid, plastic, frictionless contact and a threshold on a force
(:data:`DETECTIONS`: the contact force, the projected spring torques or the position error).

Derivation. Links ``q = q0 + xi``, motors ``theta``, contact lever ``c = J^T u`` (nv,), joint springs ``K``::

    M xi'' = K (theta - q) - c f,   c^T xi = 0   (the contact point stays on the wall)

so ``f = m_f c^T M^-1 K (theta - q)`` with ``m_f = 1 / (c^T M^-1 c)``, and with ``xi = N eta`` (``N`` an
orthonormal basis of the directions with ``c^T xi = 0``) the links move as ``N^T M N eta'' = N^T K (theta - q0 -
N eta)``: undamped modes ``zeta_j'' + w_j^2 zeta_j = forcing``, solved exactly (no integration).

1. Impact (plastic, instantaneous): ``I1 = m_f v0``; the links keep ``q'+ = q'- - M^-1 c m_f v0`` (along the
   wall).
2. Sensing: the motors follow the reference ``q0 + J^+ u v0 t`` through the admittance, the joints see the
   series stiffness ``K_l`` of ``K_m`` and ``K_s``; ``f(t) = k v0 t - sum_j h_j A_j sin(w_j t) / w_j`` (``k`` the
   compliance-form stiffness along ``u``); detection at its first crossing of ``F_s``; ``I2`` its integral.
3. Reaction: the software spring is zeroed, the rotors ``B = diag(N^2 J_m)`` integrated with the motors' push
   (``tau = -F_a c``, the closed form's; or each joint saturated), against ``K_m``, with the links: modes of
   ``(theta, eta)``; among them ``nv - 1`` free ones (motors and links sliding together along the wall, which
   carry no contact force). ``I3`` is the integral of ``f`` until it first returns to zero.

Limits that are tests: one joint (no directions along the wall) gives the 1D model exactly, ``m_f v0 + F_s^2 /
(2 k v0)`` and :func:`collision_reflex.model.impulse.sprung_reaction`; links without mass on the wall (all
modes fast) give the sprung reaction with the arm's ``m_r`` and ``F_a`` (the motors alone, ``B theta'' = tau -
c f``, ``f = k c^T (theta - q0)``, project onto ``u``); a push far above ``F_s`` gives the paper's
constant-acceleration reaction.

Not modelled: the change of ``M`` and ``J`` while the links slide (the linearisation: it grows with the
sliding distance), a compliant or damped contact, friction, and the contact after the force first returns to
zero (a finger that leaves the wall and comes back). A contact with a little restitution ``e`` lets the finger
fly off after the impact for about ``sqrt(6 m_f e / k)`` (the springs push with ``k v0 t``, from nothing: a 1D
estimate), independent of ``v0``: once that is comparable with ``t1`` (near 3 ``v*`` on the planar arm) the
detection fires on the second impact, which no plastic model describes. If the force falls to zero *before*
detection (the finger lifts off the wall) the result says so (``lifted_off``): the model then does not hold.

Numeric only (NumPy and SciPy): detection and the contact's end are first crossings of a sum of sinusoids, found
by sampling at a 32nd of the shortest period and refining with Brent's method. That is no smooth function of
the design, which is why the optimiser keeps the 1D closed form and this model serves to check it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
import numpy.typing as npt

from .. import _validate
from ..errors import InvalidParameter
from ..vocabulary import RETREATS
from .impulse import PhaseImpulses
from .modal import MAX_SAMPLES, SAMPLES_PER_PERIOD, Modes, first_crossing, normal_modes

DETECTIONS: tuple[str, ...] = ("force", "spring_torque", "position")
"""What crosses ``F_s`` at detection: ``"force"``, the contact force (a sensor at the contact: the closed form's
meaning); ``"spring_torque"``, the joint spring torques projected on ``u``, ``(J^T u) . K (theta - q) / |J^T
u|^2`` (joint-torque sensing without the links' inertia: it carries their oscillation differently); and
``"position"``, the contact point's position error times ``k``, which against the rigid wall is ``k v0 t``: the
1D model's ``t1`` exactly."""


@dataclass(frozen=True)
class JointSpaceCollision:
    """The joint-space collision's phases (:func:`joint_space_collision`).

    Attributes
    ----------
    phases: impulses of the impact, sensing (until the reaction starts) and reaction phases [N*s].
    detection_time: the contact force's first crossing of ``F_s`` after the impact [s] (the 1D model's
        ``t1 = F_s / (k v0)``).
    delay: from it to the reaction's start [s].
    reaction_duration: from the reaction's start until the contact force first returns to zero [s].
    lifted_off: the contact force fell to zero between the impact and the detection: the finger left the wall,
        which the model leaves out (its result is then not to be trusted).
    threshold_margin: the smallest relative change of ``F_s`` that moves the detection to another swing of the
        oscillating force [-] (``inf`` if none): an earlier peak ``p < F_s`` (lower ``F_s`` by ``1 - p/F_s``),
        or the crossing's own peak ``p`` if the force falls back below ``F_s`` after it (raise it by ``p/F_s -
        1``). A small margin (a few %) means the impulse jumps with a small change of the threshold or of the
        arm: the detection is ill-conditioned there, in the model and in the arm alike.
    sliding_pull: the largest pull of the sliding links off the wall until the reaction, over ``F_s`` [-]:
        ``-m_f q'^T H q'`` with ``H`` the curvature of the contact point's path (``normal_curvature``), 0 if it
        curves into the wall; None without ``H``. Right after the impact the springs push with nothing yet,
        so a pull of a few % or more lifts the finger off the wall, which the model leaves out.
    m_f, k: the effective finger mass and lumped stiffness along ``u`` [kg, N/m] (the 1D model's).
    """

    phases: PhaseImpulses
    detection_time: float
    delay: float
    reaction_duration: float
    lifted_off: bool
    threshold_margin: float
    sliding_pull: float | None
    m_f: float
    k: float

    @property
    def total(self) -> float:
        """The collision's impulse on the wall [N*s]."""
        return float(self.phases.total)


def joint_space_collision(
    mass_matrix: npt.ArrayLike,
    jacobian: npt.ArrayLike,
    direction: npt.ArrayLike,
    mechanical_stiffness: npt.ArrayLike,
    reflected_inertia: npt.ArrayLike,
    torque_limit: npt.ArrayLike,
    threshold: float,
    approach_velocity: float,
    *,
    software_stiffness: npt.ArrayLike = math.inf,
    retreat: str = "along_u",
    delay: float = 0.0,
    normal_curvature: npt.ArrayLike | None = None,
    detection: str = "force",
) -> JointSpaceCollision:
    """The arm's collision with the links' motion along the wall, linearised at the impact configuration.

    See the module's docstring for the derivation and its assumptions.

    Parameters
    ----------
    mass_matrix: the links' joint-space mass matrix ``M(q0)`` (nv, nv) [kg m^2], with the motor masses, without
        the reflected inertia (it sits behind the joint springs).
    jacobian: the contact point's translational Jacobian ``J(q0)`` (task_dim, nv) [m/rad].
    direction: the collision direction, the wall's inward normal (task_dim,), normalised here.
    mechanical_stiffness: joint springs ``K_m`` [N m/rad], finite, > 0 (scalar or (nv,)).
    reflected_inertia: rotor inertia behind each spring ``N^2 J_m`` [kg m^2], > 0.
    torque_limit: output torque limit per joint [N m], > 0 (``inf`` allowed for all but the first to saturate).
    threshold: the contact force at which the reaction starts ``F_s`` [N], > 0.
    approach_velocity: ``v0`` of the contact point along ``direction`` [m/s], > 0.
    software_stiffness: joint software stiffness ``K_s`` [N m/rad], > 0, ``inf`` (default) for ideally
        velocity-controlled motors; in series with ``K_m`` until detection, zeroed at it.
    retreat: the reaction's motor torques, :data:`~collision_reflex.vocabulary.RETREATS`.
    delay: from the threshold crossing to the reaction [s], >= 0; the motors keep tracking the reference
        meanwhile, and its impulse counts in the sensing phase (a sensor's lag: a contact-force sensor that
        reads a spring ``k_c`` in parallel with a damper ``c`` lags the force by ``c / k_c`` on a ramp).
    normal_curvature: the Hessian ``H`` (nv, nv) [m/rad^2] of the contact point's position along ``u`` at
        ``q0``, ``u^T J'(q) q' = q'^T H q'``; if given, ``sliding_pull`` reports how much the links' sliding
        unloads the contact (the model's force leaves that second-order term out).
    detection: what crosses the threshold, :data:`DETECTIONS`.
    """
    _validate.choice("retreat", retreat, RETREATS)
    _validate.choice("detection", detection, DETECTIONS)
    arm, F_s, v0, delay = _checked(
        mass_matrix,
        jacobian,
        direction,
        mechanical_stiffness,
        reflected_inertia,
        torque_limit,
        software_stiffness,
        threshold,
        approach_velocity,
        delay,
    )
    m_f, k, along_wall = arm.m_f, arm.k, arm.along_wall
    v_ref = arm.reference * v0

    # 1. Impact: the wall takes m_f v0 along u; the links keep their velocity along the wall.
    dq_impact = v_ref - arm.m_inv_c * m_f * float(arm.lever @ v_ref)

    # 2. Sensing: N^T M N eta'' + N^T K_l N eta = N^T K_l v_ref t;  f = g . (v_ref t - N eta).
    sensing, shapes = _sensing_modes(arm, v_ref, dq_impact)
    signal = _detection_signal(
        sensing, detection, shapes.T @ along_wall.T, arm.series, arm.lever, v_ref, k * v0
    )
    # The signal is k v0 t + oscillations no larger than `swing`: it reaches F_s by (F_s + swing) / (k v0).
    w = sensing.w
    swing = float(np.sum(np.abs(signal.h * (signal.dz0 - signal.p1 / w**2) / w)))  # w > 0 here
    horizon = (F_s + swing) / (k * v0) * (1 + 1e-9)
    t_c = first_crossing(signal, F_s, horizon, True, "the detection time")
    t_d = t_c + delay  # the reaction's start
    lifted, margin = _around_detection(sensing, t_c, t_d, F_s)
    pull = None
    if normal_curvature is not None:
        pull = _sliding_pull(normal_curvature, along_wall @ shapes, sensing, t_d, m_f, F_s)
    zeta, dzeta = sensing.state(t_d)
    xi, dxi = along_wall @ (shapes @ zeta), along_wall @ (shapes @ dzeta)
    theta_ref = v_ref * t_d
    share = arm.share
    theta = np.where(np.isinf(arm.k_s), theta_ref, share * theta_ref + (1 - share) * xi)  # admittance (- q0)
    dtheta = share * v_ref + (1 - share) * dxi

    # 3. Reaction: coordinates x = (theta - q0, eta), mass diag(B, N^T M N), springs K_m (theta - q0 - N eta).
    reaction = _reaction_modes(arm, _push(retreat, arm.lever, arm.tau_max), theta, dtheta, xi, dxi)
    # Oscillations about a negative mean force: it returns to zero within a few of the longest periods.
    horizon = 100 * max(reaction.longest_period(), reaction.shortest_period())
    duration = first_crossing(reaction, 0.0, horizon, False, "the reaction time")
    phases = PhaseImpulses(m_f * v0, sensing.impulse(t_d), reaction.impulse(duration))
    return JointSpaceCollision(phases, t_c, delay, duration, lifted, margin, pull, m_f, k)


@dataclass(frozen=True)
class _LinearArm:
    """The checked arm at its impact configuration, and what the three phases take from it.

    Per joint (nv,) ``K_m``, ``K_s``, the rotors ``B`` and the torque
    limits; the lever ``c = J^T u``, ``M^-1 c``, the reference rate ``J^+ u`` per unit ``v0``, the series
    stiffness ``K_l`` and the admittance's share of the reference per joint; ``m_f`` and ``k`` along ``u``; the
    basis ``N`` (nv, nv - 1) of the motions along the wall and the mass ``N^T M N`` there.
    """

    k_m: np.ndarray
    k_s: np.ndarray
    rotor: np.ndarray
    tau_max: np.ndarray
    lever: np.ndarray
    m_inv_c: np.ndarray
    reference: np.ndarray
    series: np.ndarray
    share: np.ndarray
    m_f: float
    k: float
    along_wall: np.ndarray
    mass_t: np.ndarray


def _checked(
    mass_matrix: npt.ArrayLike,
    jacobian: npt.ArrayLike,
    direction: npt.ArrayLike,
    mechanical_stiffness: npt.ArrayLike,
    reflected_inertia: npt.ArrayLike,
    torque_limit: npt.ArrayLike,
    software_stiffness: npt.ArrayLike,
    threshold: float,
    approach_velocity: float,
    delay: float,
) -> tuple[_LinearArm, float, float, float]:
    """Check the inputs of :func:`joint_space_collision`: the arm, ``F_s`` [N], ``v0`` [m/s] and the delay [s]."""
    mass = _validate.real("mass_matrix", mass_matrix, "a square matrix of real numbers [kg m^2]")
    if mass.ndim != 2 or mass.shape[0] != mass.shape[1] or mass.shape[0] == 0:
        raise InvalidParameter("mass_matrix", mass.shape, "a square (nv, nv) matrix")
    nv = mass.shape[0]
    jac = _validate.real("jacobian", jacobian, "a (task_dim, nv) matrix of real numbers [m/rad]")
    if jac.ndim != 2 or jac.shape[1] != nv or not np.all(np.isfinite(jac)):
        raise InvalidParameter("jacobian", jac.shape, f"a finite (task_dim, {nv}) matrix")
    u = _validate.real("direction", direction, "a vector of real numbers").reshape(-1)
    if u.shape != (jac.shape[0],) or not np.all(np.isfinite(u)) or np.linalg.norm(u) == 0:
        raise InvalidParameter("direction", direction, f"a nonzero vector of {jac.shape[0]} task coordinates")
    u = u / np.linalg.norm(u)
    k_m = _per_joint("mechanical_stiffness", mechanical_stiffness, nv, allow_inf=False)
    k_s = _per_joint("software_stiffness", software_stiffness, nv, allow_inf=True)
    rotor = _per_joint("reflected_inertia", reflected_inertia, nv, allow_inf=False)
    tau_max = _per_joint("torque_limit", torque_limit, nv, allow_inf=True)
    F_s = float(_validate.positive("threshold", threshold))
    v0 = float(_validate.positive("approach_velocity", approach_velocity))
    delay = float(_validate.non_negative("delay", delay))
    if not np.all(np.isfinite(mass)) or not np.allclose(mass, mass.T, rtol=1e-9, atol=0):
        raise InvalidParameter("mass_matrix", mass, "a finite symmetric matrix")
    try:
        np.linalg.cholesky(mass)
    except np.linalg.LinAlgError:
        raise InvalidParameter("mass_matrix", mass, "a positive definite matrix") from None
    return _linearised(mass, jac, u, k_m, k_s, rotor, tau_max), F_s, v0, delay


def _linearised(
    mass: np.ndarray,
    jac: np.ndarray,
    u: np.ndarray,
    k_m: np.ndarray,
    k_s: np.ndarray,
    rotor: np.ndarray,
    tau_max: np.ndarray,
) -> _LinearArm:
    """The arm along ``u`` and along the wall; a direction the contact point cannot move along is refused."""
    lever = jac.T @ u  # c = J^T u
    reference = np.linalg.pinv(jac) @ u  # J^+ u: the motors' reference rate per unit v0
    if np.linalg.norm(jac @ reference - u) > 1e-6 or not np.any(lever):
        raise InvalidParameter(
            "direction",
            u,
            "a direction the contact point can move along",
            "the Jacobian is singular along it",
        )
    m_inv_c = np.linalg.solve(mass, lever)
    m_f = 1 / float(lever @ m_inv_c)
    series = np.where(np.isinf(k_s), k_m, k_m * k_s / np.where(np.isinf(k_s), 1.0, k_m + k_s))
    share = np.where(np.isinf(k_s), 1.0, k_s / np.where(np.isinf(k_s), 1.0, k_m + k_s))  # of theta_ref
    k = 1 / float(lever @ (lever / series))
    along_wall = _wall_basis(lever)  # N (nv, nv - 1)
    mass_t = along_wall.T @ mass @ along_wall
    return _LinearArm(
        k_m, k_s, rotor, tau_max, lever, m_inv_c, reference, series, share, m_f, k, along_wall, mass_t
    )


def _sensing_modes(arm: _LinearArm, v_ref: np.ndarray, dq_impact: np.ndarray) -> tuple[Modes, np.ndarray]:
    """The contact force's modes during sensing, and the mode shapes (along the wall's basis)."""
    along_wall, mass_t, series = arm.along_wall, arm.mass_t, arm.series
    gain = arm.m_f * series * arm.m_inv_c  # f = g . (theta_ref - q)
    w, shapes = normal_modes(mass_t, along_wall.T @ (series[:, None] * along_wall))
    sensing = Modes(
        w=w,
        z0=np.zeros(w.size),
        dz0=shapes.T @ mass_t @ (along_wall.T @ dq_impact),
        p=np.zeros(w.size),
        p1=shapes.T @ along_wall.T @ (series * v_ref),
        h=-(shapes.T @ along_wall.T @ gain),
        h1=float(gain @ v_ref),
    )
    return sensing, shapes


def _push(retreat: str, lever: np.ndarray, tau_max: np.ndarray) -> np.ndarray:
    """The motors' torques in the reaction (nv,) [N m], :data:`~collision_reflex.vocabulary.RETREATS`."""
    if retreat == "along_u":
        # A joint without lever (c_i = 0) does not limit the force along u.
        limits = np.where(lever != 0, tau_max / np.where(lever != 0, np.abs(lever), 1.0), np.inf)
        push = -float(np.min(limits)) * lever
    else:
        push = -tau_max * np.sign(lever)
    if not np.all(np.isfinite(push)):
        raise InvalidParameter("torque_limit", tau_max, "finite limits on the joints that push the contact")
    return push


def _reaction_modes(
    arm: _LinearArm,
    push: np.ndarray,
    theta: np.ndarray,
    dtheta: np.ndarray,
    xi: np.ndarray,
    dxi: np.ndarray,
) -> Modes:
    """The contact force's modes in the reaction, from the motors' and links' state at its start.

    Motors ``theta - q0`` and links ``xi = q - q0`` [rad] with their rates; a push that does not unload the
    contact on average is refused.
    """
    nv, along_wall, k_m = arm.k_m.size, arm.along_wall, arm.k_m
    coupling = k_m[:, None] * along_wall
    mass_r = np.block([[np.diag(arm.rotor), np.zeros((nv, nv - 1))], [np.zeros((nv - 1, nv)), arm.mass_t]])
    stiff_r = np.block([[np.diag(k_m), -coupling], [-coupling.T, along_wall.T @ coupling]])
    w_r, shapes_r = normal_modes(mass_r, stiff_r)
    x0 = np.concatenate([theta, along_wall.T @ xi])
    dx0 = np.concatenate([dtheta, along_wall.T @ dxi])
    gain_m = arm.m_f * k_m * arm.m_inv_c  # f = g_m . (theta - q0 - N eta)
    reaction = Modes(
        w=w_r,
        z0=shapes_r.T @ mass_r @ x0,
        dz0=shapes_r.T @ mass_r @ dx0,
        p=shapes_r.T @ np.concatenate([push, np.zeros(nv - 1)]),
        p1=np.zeros(w_r.size),
        h=shapes_r.T @ np.concatenate([gain_m, -(along_wall.T @ gain_m)]),
    )
    free = w_r == 0
    mean_force = float(np.sum(reaction.h[~free] * reaction.p[~free] / w_r[~free] ** 2))
    if mean_force >= 0:
        raise InvalidParameter(
            "torque_limit",
            arm.tau_max,
            "a push that unloads the contact",
            "the motors' push does not pull the finger off",
        )
    return reaction


@dataclass(frozen=True)
class JointSpaceArm:
    """An arm at its impact configuration, as :func:`joint_space_collision` takes it (see there for units)."""

    mass_matrix: np.ndarray
    jacobian: np.ndarray
    direction: np.ndarray
    mechanical_stiffness: Any
    reflected_inertia: Any
    torque_limit: Any
    software_stiffness: Any = math.inf
    normal_curvature: Any = None

    def collision(
        self,
        threshold: float,
        approach_velocity: float,
        retreat: str = "along_u",
        delay: float = 0.0,
        detection: str = "force",
    ) -> JointSpaceCollision:
        """:func:`joint_space_collision` of this arm at ``threshold`` [N] and ``approach_velocity`` [m/s]."""
        return joint_space_collision(
            self.mass_matrix,
            self.jacobian,
            self.direction,
            self.mechanical_stiffness,
            self.reflected_inertia,
            self.torque_limit,
            threshold,
            approach_velocity,
            software_stiffness=self.software_stiffness,
            retreat=retreat,
            delay=delay,
            normal_curvature=self.normal_curvature,
            detection=detection,
        )


def _detection_signal(
    force: Modes,
    detection: str,
    to_modes: np.ndarray,
    series: np.ndarray,
    lever: np.ndarray,
    v_ref: np.ndarray,
    ramp: float,
) -> Modes:
    """The detector's signal during sensing [N], as the contact force's modes with other gains.

    ``to_modes`` maps joint vectors to modal forces (``Phi^T N^T``); ``ramp`` is ``k v0`` [N/s].
    """
    if detection == "force":
        return force
    if detection == "position":  # k (v0 t - penetration), no penetration into a rigid wall
        return replace(force, h=np.zeros(force.h.size), h1=ramp)
    # spring_torque: c . K_l (theta_ref - q) / |c|^2 with q - q0 = N eta.
    gain = series * lever / float(lever @ lever)
    return replace(force, h=-(to_modes @ gain), h1=float(gain @ v_ref))


def _wall_basis(lever: np.ndarray) -> np.ndarray:
    """An orthonormal basis (nv, nv - 1) of the joint motions that keep the contact point on the wall."""
    _, _, vt = np.linalg.svd(lever[None, :])
    return vt[1:].T


def _around_detection(sensing: Modes, t_c: float, t_d: float, F_s: float) -> tuple[bool, float]:
    """Whether the force falls to zero before the reaction starts at ``t_d``; the threshold margin.

    See :class:`JointSpaceCollision`. Sampled at a 32nd of the shortest period (peaks to 0.5 %) up to one
    longest period after the crossing ``t_c``.
    """
    step = sensing.shortest_period() / SAMPLES_PER_PERIOD
    if not math.isfinite(step):  # one joint: the force is the ramp k v0 t
        return False, math.inf
    end = max(t_d, t_c + sensing.longest_period())
    times = np.arange(1, min(math.ceil(end / step), MAX_SAMPLES) + 1) * step
    force = sensing.force(times)
    lifted = bool(np.any(force[times <= t_d] <= 0))
    inner = force[1:-1]
    peaks = (inner > force[:-2]) & (inner >= force[2:])
    earlier = inner[peaks & (times[1:-1] < t_c)]
    margins = [1 - float(earlier.max()) / F_s] if earlier.size else []
    after = times > t_c
    fallen = np.flatnonzero(after & (force < F_s))
    if fallen.size:  # the crossing's swing falls back below F_s: its peak decides
        swing = force[after & (times < times[fallen[0]])]
        margins.append(float(swing.max(initial=F_s)) / F_s - 1)
    return lifted, min(margins, default=math.inf)


def _sliding_pull(
    curvature: Any, to_joints: np.ndarray, sensing: Modes, t_d: float, m_f: float, F_s: float
) -> float:
    """``max(-m_f q'^T H q') / F_s`` over the sensing phase, ``q' = to_joints zeta'`` (sampled).

    Sampled as the threshold margin, at a 32nd of the shortest period.
    """
    nv = to_joints.shape[0]
    hessian = _validate.real("normal_curvature", curvature, "a (nv, nv) matrix of real numbers [m/rad^2]")
    if hessian.shape != (nv, nv) or not np.all(np.isfinite(hessian)):
        raise InvalidParameter("normal_curvature", hessian.shape, f"a finite ({nv}, {nv}) matrix")
    step = min(sensing.shortest_period() / SAMPLES_PER_PERIOD, t_d)
    times = np.linspace(0.0, t_d, min(math.ceil(t_d / step), MAX_SAMPLES) + 1)
    _, rates = sensing.state(times)
    velocities = rates @ to_joints.T  # q' (samples, nv)
    pull = -m_f * np.einsum("si,ij,sj->s", velocities, (hessian + hessian.T) / 2, velocities)
    return max(float(pull.max()) / F_s, 0.0)


def _per_joint(name: str, value: Any, nv: int, *, allow_inf: bool) -> np.ndarray:
    """One value per joint (nv,), a scalar broadcast, each > 0."""
    array = np.asarray(_validate.positive(name, value, allow_inf=allow_inf), dtype=float)
    if array.ndim == 0:
        return np.full(nv, float(array))
    array = array.reshape(-1)
    if array.shape != (nv,):
        raise InvalidParameter(name, value, f"one value or {nv} values, one per joint")
    return array
