"""Time-domain collision of an arm with elastic joints against a compliant wall.

It is compared with the arm-level closed form (the paper's section "Collision Reflex in Higher
Dimensions").

Each joint is a link side and a motor side coupled by the joint's mechanical spring ``k_m,i``::

    links:   M(q) q'' + C(q, q') q' = K_m (theta - q) - J(q)^T n f          (Pinocchio's ABA, no armature)
    motors:  B theta'' = tau - K_m (theta - q),   B = diag(N_i^2 J_m,i)      (rotor side, diagonal)

``J`` is the contact point's translational Jacobian, ``n`` the wall normal (the collision direction ``u``) and
``f`` the wall force, a stiff Kelvin-Voigt contact that cannot pull (the wall is frictionless: the contact point
may slide along it). Gravity is left out, as in the closed form.

Approach follows the 1D ideal drive (:mod:`collision_reflex.simulate`) joint by joint: each motor is ideally
velocity-controlled along ``theta_ref' = J(q0)^+ u v0`` (the contact point approaches along ``u`` at ``v0``)
and its software stiffness ``k_s,i`` acts as an admittance, so that the joint springs are the series ``K = K_m
K_s / (K_m + K_s)`` of the closed form. Detection (``detection=``, :mod:`.arm_detection`): a contact-force
sensor (``"force"``, the closed form's meaning of ``F_s``), a generalized-momentum observer (``"observer"``),
the joint spring torques projected on ``u`` (``"spring_torque"``, the default, kept from the first version),
the contact point's position error against the commanded path (``"position"``) or the residual motor
torques over the model's (``"current"``), optionally sampled.
At detection (plus an optional delay) the admittance is switched off and the motors push (``retreat=``) with
``tau = -F_a J^T u``, ``F_a = min_i tau_max,i / |(J^T u)_i|``, the largest force along ``-u`` before the first
joint saturates, as the closed form's ``a = F_a / m_r`` assumes, or every joint saturated (``"saturated"``).

What the closed form leaves out and this model keeps: the links' motion along the wall after the impact (the
finger's momentum is only removed along ``u``), the motors' acceleration off the direction ``u`` during the
reaction, the spring's push on the motors during the reaction, the wall's compliance and rebound, and the
change of ``J`` during the contact.

Why ``a/2`` matched the first test better than ``a`` (0.1 v*, spring-torque detection; elbow-up-x,
elbow-up-oblique, folded-x of ``tests/test_simulate_arm.py``): two errors of opposite sign, not a factor in
``a``. (1) The closed form's reaction moves the robot mass at the constant ``a``; the spring compressed by
``F_s`` pushes it away as well, ``m_r x'' = -F_a - k_m x``, and with ``F_s`` comparable to ``F_a`` the simulated
reaction impulse is well *below* the closed form's; :func:`collision_reflex.model.impulse.sprung_reaction`
(derived there, an option beside the paper's reaction: ``ArmCollision.closed_form_sprung``) matches it closely.
A smaller ``a`` moves the reaction the wrong way. (2) The spring-torque detector fires late: the impulse until
detection is above ``m_f v0 + F_s^2 / (2 k v0)`` (the contact force at detection is below ``F_s`` on
elbow-up-x: the joint torques carry the links' inertia as they oscillate along the wall). ``a/2`` adds
``(sqrt(2) - 1) I3``, which cancels (2) less (1). With the contact-force sensor the sensing phase matches on
folded-x, and so does the total with the sprung reaction; on the elbow-up configurations the contact force
itself ramps up slower than ``k v0 t`` (a larger impulse until detection): the operational-space inertia
couples the wall normal to the tangent, and the 1D reduction has no term for it. ``benchmarks/arm_reaction.py``
prints each phase against each model.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from .. import _validate
from .._compat import renamed_keywords
from ..errors import InvalidParameter, SimulationError
from ..model.impulse import collision_times, phase_impulses, series_stiffness, sprung_reaction, total_impulse
from .arm_detection import DETECTIONS, detection_margin, next_sample
from .arm_dynamics import ArmDynamics
from .budget import EVALUATIONS_PER_STEP, check_arm_work
from .dynamics import admittance_share
from .setup import oscillation_period

ARM_REACTIONS: tuple[str, ...] = ("at_rest", "moving")
ARM_DRIVES: tuple[str, ...] = ("ideal", "impedance")
"""``"ideal"``: velocity-controlled motors with the software stiffness as an ideal admittance (massless).
``"impedance"``: the 1D simulator's impedance drive per joint, motor torque ``k_s (theta_ref - theta) + d_s
(theta_ref' - theta')`` saturated at the torque limit, the rotor inertia integrated."""
RETREATS: tuple[str, ...] = ("along_u", "saturated")
"""``"along_u"``: the motors push with ``tau = -F_a J^T n``, each joint at most at its limit and the first at
it, the closed form's reaction. ``"saturated"``: a retreat command saturates every joint, ``tau_i = -tau_max,i
sign((J^T n)_i)`` (a real controller's reaction: more force along ``-n``, and a push off it)."""
_CURRENT_LEVER_SHARE = 0.1  # joints with a smaller share of the largest lever sense no current by default
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
    detection: the detection scheme (:data:`collision_reflex.simulate.arm_detection.DETECTIONS`).
    retreat: the reaction's motor torques (:data:`RETREATS`).
    detected_impulse: the simulated impulse on the wall until detection [N*s] (impact and sensing phases).
    closed_form_sprung: the closed form with :func:`collision_reflex.model.impulse.sprung_reaction` in place
        of the constant-acceleration reaction [N*s] (the spring's push on the robot mass kept).
    closed_form_detected: the closed form's impact and sensing impulses, ``m_f v0 + F_s^2 / (2 k v0)`` [N*s].
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
    detection: str = "spring_torque"
    retreat: str = "along_u"
    detected_impulse: float = math.nan
    closed_form_sprung: float = math.nan
    closed_form_detected: float = math.nan

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
    detection: str = "spring_torque",
    observer_gain: float = 200.0,
    sample_rate: float | None = None,
    current_threshold: Any = None,
    retreat: str = "along_u",
    max_steps: float = 2e5,
    blanking: float | None = None,
    drive: str = "ideal",
    software_damping: Any = 0.0,
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
    detection: the detection scheme, ``"spring_torque"`` (default, the joint spring torques projected on
        ``u``), ``"force"`` (a sensor at the contact: the closed form's meaning), ``"observer"`` (a
        generalized-momentum observer), ``"position"`` (contact-point position error, ``F_s = k e``) or
        ``"current"`` (motor torque per joint); see :mod:`collision_reflex.simulate.arm_detection`.
    observer_gain: the momentum observer's gain ``K`` [1/s], > 0 (``"observer"`` only).
    sample_rate: the detector's sample rate [Hz], > 0; None (default) for a continuous detector.
    current_threshold: per-joint thresholds on the residual motor torque [N m] (output side, ``inf``: the
        joint is not watched), ``"current"`` only; default ``threshold |J(q)^T u|`` on the joints with at
        least a tenth of the largest lever.
    retreat: the reaction's motor torques, ``"along_u"`` (default: the closed form's, each joint at most at
        its limit along the escape direction) or ``"saturated"`` (every joint at its limit); see
        :data:`RETREATS`.
    blanking: how long after the impact the detector takes a crossing of its threshold for the impact
        pulse [s], >= 0. A signal that rises above the threshold within it is blanked until it falls below
        again; if it has not by the end, the contact force holds above the threshold and it detects then; a
        signal still below the threshold at the end was armed all along. None (default): for ``"force"`` the
        impact pulse of the finger on the contact and the joint springs
        (:func:`collision_reflex.simulate.arm_dynamics.impact_pulse_duration`; the pulse, ``m_f v0``, would trip
        a contact sensor at once: the closed form's threshold means the force after it), 0 for the other
        schemes (their signal passes through the joints or a filter; an observer with ``K m_f v0 > F_s`` does
        detect the impact itself).
    drive: ``"ideal"`` (default) or ``"impedance"`` (finite ``software_stiffness`` needed), see
        :data:`ARM_DRIVES`.
    software_damping: the impedance drive's joint damping ``d_s`` [N m s/rad], >= 0 (scalar or (nv,)).
    max_steps: the work budget [integrator steps]: a setting expected to need more is refused at once, and a
        run that takes four times as many right-hand-side evaluations as the budget allows is stopped.
    """
    _validate.choice("reaction", reaction, ARM_REACTIONS)
    _validate.choice("detection", detection, DETECTIONS)
    _validate.choice("retreat", retreat, RETREATS)
    _validate.choice("drive", drive, ARM_DRIVES)
    _validate.positive("observer_gain", observer_gain)
    _validate.positive("max_steps", max_steps)
    if sample_rate is not None:
        _validate.positive("sample_rate", sample_rate)
    if blanking is not None:
        _validate.non_negative("blanking", blanking)
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
    sensing = _Sensing(
        detection,
        float(observer_gain),
        None if sample_rate is None else float(sample_rate),
        _current_threshold(arm, joints, float(threshold), current_threshold),
        retreat,
        blanking,
        drive,
        _impedance_damping(joints, drive, software_damping),
        float(threshold),
    )
    dynamics = ArmDynamics(arm, joints, closed, contact_stiffness, contact_damping_ratio, sensing)
    trace = _integrate(dynamics, closed, float(approach_velocity), float(threshold), delay, rtol, max_steps)
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
        detection=detection,
        retreat=retreat,
        detected_impulse=trace.detected_impulse,
        closed_form_sprung=closed.sprung_impulse,
        closed_form_detected=closed.detected_impulse,
    )


@dataclass(frozen=True)
class _Sensing:
    """The controller: detector, reaction and drive.

    Scheme, observer gain [1/s], sample rate [Hz] (or None), per-joint current thresholds [N m] (nv,), the
    retreat, the blanking after the impact [s] (None: the scheme's default), the drive and its joint damping
    [N m s/rad] (nv,), the force threshold [N].
    """

    detection: str
    observer_gain: float
    sample_rate: float | None
    current_threshold: np.ndarray
    retreat: str
    blanking: float | None
    drive: str
    software_damping: np.ndarray
    threshold: float


def _impedance_damping(joints: _Joints, drive: str, software_damping: Any) -> np.ndarray:
    """The impedance drive's joint damping (nv,) [N m s/rad]; its software stiffness must be finite."""
    nv = joints.q0.size
    damping = np.broadcast_to(np.asarray(software_damping, dtype=float), (nv,)).copy()
    _validate.non_negative("software_damping", damping)
    if drive == "impedance" and not np.all(np.isfinite(joints.k_s)):
        raise InvalidParameter(
            "software_stiffness",
            joints.k_s,
            "finite joint stiffnesses [N m/rad]",
            "the impedance drive needs them",
        )
    return damping


def _current_threshold(arm: Any, joints: _Joints, threshold: float, given: Any) -> np.ndarray:
    """Per-joint motor-torque thresholds [N m]: ``given``, or ``threshold |J(q0)^T u|``.

    By default a joint whose lever is below a tenth of the largest is left out (an infinite threshold): it
    barely feels the contact, and a threshold that small would trip on the links' inertial torques.
    """
    if given is not None:
        return _joint("current_threshold", given, joints.q0.size, allow_inf=True)
    lever = np.abs(arm.kinematics(joints.q0[None]).jacobian[0].T @ joints.u)
    return np.where(lever >= _CURRENT_LEVER_SHARE * float(np.max(lever)), threshold * lever, math.inf)


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
    space = arm.configuration_space
    lower, upper = space.lower_position_limit, space.upper_position_limit
    if np.any(q0 <= lower) or np.any(q0 >= upper):
        raise InvalidParameter(
            "q", q, "a configuration strictly inside the joint limits", "q is at or past one"
        )
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
    sprung_impulse: the same with the spring's push on the robot mass in the reaction [N*s].
    detected_impulse: its impact and sensing impulses [N*s].
    """

    effective: dict[str, float]
    share: np.ndarray
    reference_rate: np.ndarray
    robot_velocity: float
    impulse: float
    sprung_impulse: float
    detected_impulse: float


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
    reachable = jac0 @ (np.linalg.pinv(jac0) @ u)
    if np.linalg.norm(reachable - u) > 1e-6:
        raise InvalidParameter("direction", u, "a direction the contact point can move along at q")
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
    v_r = robot_velocity if reaction == "moving" else None
    phases = phase_impulses(
        eff["m_f"], eff["k"], eff["k_m"], threshold, eff["a"], approach_velocity, reaction, v_r
    )
    detected = float(phases.initial + phases.sensing)
    _, sprung = sprung_reaction(threshold, eff["k_m"], eff["F_a"], eff["m_r"], max(v_r or 0.0, 0.0))
    return _ClosedForm(
        eff, share, reference_rate, robot_velocity, float(impulse), detected + sprung, detected
    )


@dataclass
class _ArmTrace:
    """What the integration records: trace segments and the phase times [s], the impulse [N*s]."""

    times: list[np.ndarray]
    forces: list[np.ndarray]
    detection_time: float = math.nan
    detected_impulse: float = math.nan
    reaction_time: float = math.nan
    contact_end: float = math.nan
    impulse: float = math.nan

    def add(self, solution: Any, dynamics: ArmDynamics) -> None:
        self.times.append(solution.t[1:])
        self.forces.append(dynamics.wall_forces(solution))


def _time_scales(
    dynamics: ArmDynamics, closed: _ClosedForm, approach_velocity: float, threshold: float, delay: float
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
    if dynamics.drive == "impedance":  # the rotors on the software and joint springs
        periods.append(
            min(
                oscillation_period(b, k)
                for b, k in zip(dynamics.inertia, dynamics.k_s + dynamics.k_m, strict=True)
            )
        )
    if dynamics.detection == "observer":
        periods.append(2 * math.pi / dynamics.observer_gain)  # the observer's time constant, as a period
    max_step = min(periods) / 16  # a sixteenth of the shortest period in play
    # After the blanking (no detection can come sooner), fifty closed-form contacts (paper's reaction) and
    # delays, and twenty of the longest periods.
    _, t2 = collision_times(eff["m_f"], eff["k"], eff["k_m"], threshold, eff["a"], approach_velocity)
    duration = dynamics.blanking + 50 * (t2 + delay) + 20 * max(periods)
    return max_step, float(duration), finger_period


def _expected_span(
    closed: _ClosedForm, approach_velocity: float, threshold: float, delay: float, finger_period: float
) -> float:
    """The run's expected simulated time [s]: the closed form's contact, the delay and the watch after it."""
    eff = closed.effective
    _, t2 = collision_times(eff["m_f"], eff["k"], eff["k_m"], threshold, eff["a"], approach_velocity)
    return float(t2 + delay + 2 * finger_period)


def _integrate(
    dynamics: ArmDynamics,
    closed: _ClosedForm,
    approach_velocity: float,
    threshold: float,
    delay: float,
    rtol: float,
    max_steps: float,
) -> _ArmTrace:
    """Integrate the arm's collision, phase by phase.

    Impact and sensing until detection, the delay, then the reaction until the finger has left the wall for
    good.
    """
    from scipy.integrate import solve_ivp  # here: SciPy's import time is paid only by a simulation

    max_step, duration, finger_period = _time_scales(dynamics, closed, approach_velocity, threshold, delay)
    span = _expected_span(closed, approach_velocity, threshold, delay, finger_period)
    check_arm_work(span, max_step, max_steps)
    dynamics.max_evaluations = 4 * max_steps * EVALUATIONS_PER_STEP
    nv = dynamics.nv
    y = np.zeros(5 * nv + 1)
    y[:nv] = dynamics.q0
    y[nv : 2 * nv] = dynamics.v_ref  # the links move with the motors before the impact
    y[2 * nv : 3 * nv], y[3 * nv : 4 * nv] = dynamics.q0, dynamics.v_ref  # unloaded springs
    options: dict[str, Any] = {"method": "DOP853", "rtol": rtol, "atol": 1e-12, "max_step": max_step}
    trace = _ArmTrace([np.array([0.0])], [np.array([0.0])])

    def detected(t: float, y: np.ndarray) -> float:
        return detection_margin(dynamics, t, y, threshold)

    detected.terminal, detected.direction = True, 1  # type: ignore[attr-defined]

    # 1. Impact and sensing until the estimated force reaches the threshold, once armed.
    t, y, armed = _blank(dynamics, trace, y, threshold, options)
    if armed and detection_margin(dynamics, t, y, threshold) < 0:  # at or above it: it fires at once
        solution = solve_ivp(dynamics.rhs, (t, duration), y, events=detected, **options)
        trace.add(solution, dynamics)
        if solution.status != 1:
            raise SimulationError(
                f"the detector never reached the threshold {threshold:g} N within {duration:.3g} s; lower it"
            )
        t = float(solution.t[-1])
        y = solution.y[:, -1].copy()
    # A sampled detector sees the crossing at its next sample.
    t, y = _advance(dynamics, trace, t, y, next_sample(t, dynamics.sample_rate) - t, options)
    trace.detection_time, trace.detected_impulse = t, float(y[-1])
    # 2. The delay, still tracking the reference.
    t, y = _advance(dynamics, trace, t, y, delay, options)
    trace.reaction_time = t
    # 3. The reaction: admittance off, the motors push at the force limit along -u.
    y = dynamics.start_reaction(t, y)
    _react(dynamics, trace, t, y, duration, 2 * finger_period, options)
    return trace


def _blank(
    dynamics: ArmDynamics, trace: _ArmTrace, y: np.ndarray, threshold: float, options: dict[str, Any]
) -> tuple[float, np.ndarray, bool]:
    """Integrate through the blanking window after the impact.

    A rise above the threshold within the window is the impact pulse: the detector waits until the signal
    falls below again, and is armed from there. If it does not fall by the window's end, the force holds
    above the threshold and the detector fires there. A signal that stays below was armed all along (a first
    version waited for a fall in any case, and against a soft object, whose pulse never reaches the
    threshold, stayed blind for the whole window). Returns the time [s], the state then and whether the
    detector is armed (False: it fires at that time).
    """
    from scipy.integrate import solve_ivp

    window = dynamics.blanking
    if window <= 0:
        return 0.0, y, True

    def margin(t: float, y: np.ndarray) -> float:
        return detection_margin(dynamics, t, y, threshold)

    def rose(t: float, y: np.ndarray) -> float:
        return margin(t, y)

    def fell(t: float, y: np.ndarray) -> float:
        return margin(t, y)

    rose.terminal, rose.direction = True, 1  # type: ignore[attr-defined]
    fell.terminal, fell.direction = True, -1  # type: ignore[attr-defined]
    solution = solve_ivp(dynamics.rhs, (0.0, window), y, events=rose, **options)
    trace.add(solution, dynamics)
    t, y = float(solution.t[-1]), solution.y[:, -1].copy()
    if solution.status != 1:  # no rise within the window: armed all along, nothing crossed yet
        return t, y, True
    solution = solve_ivp(dynamics.rhs, (t, window), y, events=fell, **options)
    trace.add(solution, dynamics)
    t, y = float(solution.t[-1]), solution.y[:, -1].copy()
    return t, y, solution.status == 1


def _advance(
    dynamics: ArmDynamics,
    trace: _ArmTrace,
    t: float,
    y: np.ndarray,
    span: float,
    options: dict[str, Any],
) -> tuple[float, np.ndarray]:
    """Integrate ``span`` [s] on from ``t`` [s] without a mode change; the new time and state."""
    from scipy.integrate import solve_ivp

    if span <= 0:
        return t, y
    solution = solve_ivp(dynamics.rhs, (t, t + span), y, **options)
    trace.add(solution, dynamics)
    return t + span, solution.y[:, -1].copy()


def _react(
    dynamics: ArmDynamics,
    trace: _ArmTrace,
    t: float,
    y: np.ndarray,
    duration: float,
    watch: float,
    options: dict[str, Any],
) -> None:
    """Push until the finger leaves the wall; then the reflex is over: the motors stop pushing and coast away.

    Watch ``watch`` [s] for a rebound into the wall before stopping (a constant torque kept on would spin the
    arm round into the wall again, which is no part of the reflex), and push again from the moment it touches
    again, until it leaves again.
    """
    from scipy.integrate import solve_ivp

    def separated(t: float, y: np.ndarray) -> float:
        return dynamics.penetration(y)

    def touched(t: float, y: np.ndarray) -> float:
        return dynamics.penetration(y)

    separated.terminal, separated.direction = True, -1  # type: ignore[attr-defined]
    touched.terminal, touched.direction = True, 1  # type: ignore[attr-defined]

    for _ in range(_MAX_REBOUNDS):
        solution = solve_ivp(dynamics.rhs, (t, duration), y, events=separated, **options)
        trace.add(solution, dynamics)
        y, t = solution.y[:, -1].copy(), float(solution.t[-1])
        if solution.status != 1:
            raise SimulationError(f"the contact had not ended after {duration:.3g} s; lengthen it")
        trace.contact_end = t
        dynamics.torque = np.zeros(dynamics.nv)
        coast = solve_ivp(dynamics.rhs, (t, t + watch), y, events=touched, **options)
        trace.add(coast, dynamics)
        y, t = coast.y[:, -1].copy(), float(coast.t[-1])
        if coast.status != 1:  # no new touch within the watch
            break
        dynamics.torque = dynamics.push
    else:
        raise SimulationError(
            f"the finger kept hitting the wall again after the reaction ({_MAX_REBOUNDS} rebounds)"
        )
    trace.impulse = float(y[-1])
