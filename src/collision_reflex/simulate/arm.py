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

The inputs and the closed form are checked and made in :mod:`.arm_inputs`, the equations of motion are
:mod:`.arm_dynamics` and the integration, phase by phase, :mod:`.arm_integration`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from .. import _validate
from ..vocabulary import CONTROLLED_DRIVES, REACTION_MODES, RETREATS
from .arm_detection import DETECTIONS
from .arm_dynamics import ArmDynamics
from .arm_inputs import ArmJoints, ImpactClosedForm, arm_joints, arm_sensing, impact_closed_form
from .arm_integration import ArmTrace, integrate_arm_collision


@dataclass(frozen=True)
class ArmCollision:
    """A simulated arm collision and the arm-level closed form for the same configuration and direction.

    Attributes
    ----------
    q: the configuration at impact (nq,) [rad].
    direction: the unit collision direction, in the arm's task coordinates (task_dim,).
    approach_velocity: approach velocity of the contact point [m/s].
    t: trace times [s], impact at 0; contact_force: the wall force at ``t`` [N].
    impulse: simulated impulse on the wall [N*s].
    detection_time, reaction_time, contact_end: [s].
    effective: the effective 1D parameters at ``q`` along ``direction`` (``m_f, m_r, k, k_m, F_a, a``; SI).
    robot_velocity: the closed form's robot velocity at detection along ``u``, ``u^T J S J^+ u v0`` with
        ``S = diag(k_s / (k_s + k_m))`` [m/s] (``v0`` for ideally velocity-controlled motors).
    closed_form: the closed form's impulse [N*s] with ``reaction`` (and ``robot_velocity`` if moving).
    reaction: the closed form's reaction variant.
    detection: the detection scheme (:data:`collision_reflex.simulate.arm_detection.DETECTIONS`).
    retreat: the reaction's motor torques (:data:`~collision_reflex.vocabulary.RETREATS`).
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
    approach_velocity: approach velocity of the contact point [m/s], > 0.
    threshold: contact-force threshold of the detector [N], > 0.
    software_stiffness: joint software stiffness [N m/rad] (scalar or (nv,)); ``inf`` (default) for ideally
        velocity-controlled motors.
    mechanical_stiffness: joint spring between link and motor [N m/rad] (scalar or (nv,)), finite; default
        the arm's joint parameters.
    reflected_inertia: motor-side inertia ``N^2 J_m`` per joint [kg m^2], > 0; default the arm's.
    torque_limit: output torque limit per joint [N m], > 0; default the arm's.
    contact_stiffness: the wall's contact stiffness [N/m].
    contact_damping_ratio: its damping as a ratio of critical for the effective finger mass (dimensionless;
        2 gives a restitution of 0.02, see :func:`collision_reflex.simulate.contact_restitution`).
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
        :data:`~collision_reflex.vocabulary.RETREATS`.
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
        :data:`CONTROLLED_DRIVES`.
    software_damping: the impedance drive's joint damping ``d_s`` [N m s/rad], >= 0 (scalar or (nv,)).
    max_steps: the work budget [integrator steps]: a setting expected to need more is refused at once, and a
        run that takes four times as many right-hand-side evaluations as the budget allows is stopped.
    """
    _check_settings(reaction, detection, retreat, drive, observer_gain, max_steps, sample_rate, blanking)
    v0, F_s = _checked_contact(approach_velocity, threshold, contact_stiffness, delay, contact_damping_ratio)
    joints = arm_joints(
        arm, q, direction, software_stiffness, mechanical_stiffness, reflected_inertia, torque_limit
    )
    closed = impact_closed_form(arm, joints, v0, F_s, reaction)
    sensing = arm_sensing(
        arm,
        joints,
        F_s,
        detection,
        observer_gain,
        sample_rate,
        current_threshold,
        retreat,
        blanking,
        drive,
        software_damping,
    )
    dynamics = ArmDynamics(arm, joints, closed, contact_stiffness, contact_damping_ratio, sensing)
    trace = integrate_arm_collision(dynamics, closed, v0, F_s, delay, rtol, max_steps)
    return _collision(joints, closed, trace, v0, reaction, detection, retreat)


def _check_settings(
    reaction: str,
    detection: str,
    retreat: str,
    drive: str,
    observer_gain: float,
    max_steps: float,
    sample_rate: float | None,
    blanking: float | None,
) -> None:
    """Check the simulation's choices and the controller's settings (see :func:`simulate_arm_collision`)."""
    _validate.choice("reaction", reaction, REACTION_MODES)
    _validate.choice("detection", detection, DETECTIONS)
    _validate.choice("retreat", retreat, RETREATS)
    _validate.choice("drive", drive, CONTROLLED_DRIVES)
    _validate.positive("observer_gain", observer_gain)
    _validate.positive("max_steps", max_steps)
    if sample_rate is not None:
        _validate.positive("sample_rate", sample_rate)
    if blanking is not None:
        _validate.non_negative("blanking", blanking)


def _checked_contact(
    approach_velocity: float, threshold: float, contact_stiffness: float, delay: float, damping_ratio: float
) -> tuple[float, float]:
    """Check the approach and the contact; the approach velocity [m/s] and the threshold [N] as floats."""
    for name, value in (
        ("approach_velocity", approach_velocity),
        ("threshold", threshold),
        ("contact_stiffness", contact_stiffness),
    ):
        _validate.positive(name, value)
    _validate.non_negative("delay", delay)
    _validate.positive("contact_damping_ratio", damping_ratio)
    return float(approach_velocity), float(threshold)


def _collision(
    joints: ArmJoints,
    closed: ImpactClosedForm,
    trace: ArmTrace,
    approach_velocity: float,
    reaction: str,
    detection: str,
    retreat: str,
) -> ArmCollision:
    """The simulated collision's record: the integration's trace and phases beside the closed form."""
    return ArmCollision(
        q=joints.q0,
        direction=joints.u,
        approach_velocity=approach_velocity,
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
