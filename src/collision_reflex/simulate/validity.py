"""Where the arm-level closed form holds: the time-domain arm collision against the closed form, swept.

For an arm and a design's joint parameters, :func:`validity_map` simulates the collision
(:func:`collision_reflex.simulate.simulate_arm_collision`) over configurations x directions x approach
velocities (multiples of the closed form's optimum ``v*``) x the ratio of the contact stiffness to the joint
stiffness along ``u``, for each detection scheme the simulator offers, and compares each simulated impulse with
the closed form for both placements of the reflected inertia (``robot``: behind the joint springs, the paper's
arm model; ``finger``: rigidly on the link side, a stiff transmission). A row is *valid* where the two agree
within the tolerance (5 % by default).

The closed form compared is the one a study uses, with the object hit as a spring in series with the joints
(as the actuator study does): ``k`` and ``k_m`` along ``u`` are each in series with the contact stiffness
``k_c``. Every simulation is checked against a work budget first (:func:`check_arm_work`): a setting whose step
would collapse (a very stiff wall) or whose approach would last very long is refused at once, and recorded as a
failed row, never run for hours.
"""

from __future__ import annotations

import copy
import dataclasses
import itertools
import math
import time
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

from .. import _validate
from ..arm.effective import effective_parameters
from ..errors import InvalidParameter, SimulationError
from ..model.impulse import optimal_velocity, phase_impulses, series_stiffness, sprung_reaction
from ..model.joint_space import DETECTIONS as JOINT_SPACE_DETECTIONS
from ..model.joint_space import JointSpaceArm
from . import arm as arm_simulation
from .arm_detection import DETECTIONS
from .contact import damping_from_ratio
from .dynamics import admittance_share

VELOCITY_RATIOS: tuple[float, ...] = (0.1, 0.3, 1.0, 3.0, 10.0)
"""Approach velocities swept, as multiples of the closed form's optimum ``v* = F_s / sqrt(2 k m_f)``."""

STIFFNESS_RATIOS: tuple[float, ...] = (0.1, 10.0)
"""Contact stiffness over the joints' mechanical stiffness along ``u``: 0.1 is a stiff transmission hitting a
compliant object, 10 compliant joints hitting a stiff one."""

PLACEMENTS: tuple[str, ...] = ("robot", "finger")
"""Where the closed form puts the reflected inertia ``N^2 J_m`` (see :data:`REFLECTED_INERTIA_PLACEMENTS`)."""

TOLERANCE = 0.05
"""Agreement that counts as valid: ``|I_sim / I_closed - 1| <= 5 %``."""

MAX_STEPS = 200_000
"""Default work budget of one arm simulation [integrator steps] (the simulator's; tens of seconds at most)."""

REACTION_MODELS: tuple[str, ...] = ("constant", "sprung", "joint_space")
"""The closed form's reaction: ``"constant"``, the paper's constant acceleration ``a = F_a / m_r``;
``"sprung"``, :func:`collision_reflex.model.impulse.sprung_reaction` (the compressed spring also pushes the
robot mass away, the term the constant acceleration leaves out); ``"joint_space"``,
:func:`collision_reflex.model.joint_space.joint_space_collision` (all three phases with the links' motion along
the wall, linearised at ``q``; it places each inertia where the arm has it, so it is the same under both
placements, and it takes the contact as rigid: against a compliant object it leaves the object out)."""

DRIVES: tuple[str, ...] = arm_simulation.ARM_DRIVES
"""The simulated drives: ``"ideal"`` (an ideal admittance) and ``"impedance"`` (the physical impedance loop
with the rotor inertia; a finite software stiffness needed)."""

CONTACT_DAMPING_RATIO = 2.0
"""The simulated contact's damping, as a ratio of critical for the finger mass (the simulator's default: a
plastic impact, restitution 0.02)."""

TORQUE_DETECTION = "spring_torque"
"""The simulator's default detection: the contact force estimated from the joint spring torques."""


@dataclass(frozen=True)
class JointDesign:
    """A design's joint parameters, one value per joint or one for all, and its detection threshold.

    Attributes
    ----------
    mechanical_stiffness: joint spring between link and motor [N m/rad], finite.
    reflected_inertia: ``N^2 J_m`` per joint [kg m^2].
    torque_limit: output torque limit per joint [N m].
    threshold: contact-force threshold of the detector ``F_s`` [N].
    software_stiffness: joint software stiffness [N m/rad]; ``inf`` for ideally velocity-controlled motors.
    motor_mass: motor (and gearbox) mass per joint [kg], carried by the parent link; None: the arm's.
    software_damping: the impedance drive's joint damping [N m s/rad] (``drive="impedance"`` only).
    """

    mechanical_stiffness: Any
    reflected_inertia: Any
    torque_limit: Any
    threshold: float
    software_stiffness: Any = math.inf
    motor_mass: Any = None
    software_damping: Any = 0.0

    def on(self, arm: Any) -> Any:
        """``arm`` with this design's motor masses (the arm itself when they are the arm's)."""
        if self.motor_mass is None:
            return arm
        params = arm.joint_parameters
        mass = np.broadcast_to(np.asarray(self.motor_mass, dtype=float), params.motor_mass.shape)
        _validate.non_negative("motor_mass", mass)
        out = copy.copy(arm)
        out.joint_parameters = dataclasses.replace(params, motor_mass=mass.copy())
        return out

    def simulator_keywords(self) -> dict[str, Any]:
        """The keywords of :func:`simulate_arm_collision` that carry the joint parameters."""
        return {
            "mechanical_stiffness": self.mechanical_stiffness,
            "reflected_inertia": self.reflected_inertia,
            "torque_limit": self.torque_limit,
            "software_stiffness": self.software_stiffness,
            "software_damping": self.software_damping,
        }


def available_detections() -> tuple[str, ...]:
    """The detection schemes of the arm simulator, its default first."""
    return (TORQUE_DETECTION, *(s for s in DETECTIONS if s != TORQUE_DETECTION))


@dataclass(frozen=True)
class ArmClosedForm:
    """The arm closed form at one configuration and direction, against a contact of given stiffness.

    Attributes
    ----------
    m_f, m_r: effective finger and robot masses along ``u`` [kg]; k, k_m: lumped and mechanical stiffness along
    ``u``, each in series with the contact [N/m]; F_a: the motors' force along ``-u`` [N]; a: reaction
    acceleration ``F_a / m_r`` [m/s^2]; v_r: robot velocity at detection along ``u`` per unit approach velocity
    [-]; threshold: ``F_s`` [N]; reaction: ``"moving"`` or ``"at_rest"``.
    """

    m_f: float
    m_r: float
    k: float
    k_m: float
    F_a: float
    a: float
    v_r: float
    threshold: float
    reaction: str
    joint_space: JointSpaceArm | None = None

    def impulse(self, approach_velocity: float, model: str = "constant", detection: str = "force") -> float:
        """The closed form's impulse [N*s] at the approach velocity [m/s] with a reaction of :data:`REACTION_MODELS`.

        ``detection`` (a scheme of the simulator) matters to ``"joint_space"`` only, which models the contact
        force, spring-torque and position signals (:data:`collision_reflex.model.joint_space.DETECTIONS`) and
        takes the contact force for the others (the observer estimates it, lagged).
        """
        _validate.choice("model", model, REACTION_MODELS)
        v0 = float(approach_velocity)
        if model == "joint_space":
            if self.joint_space is None:
                raise InvalidParameter("model", model, "a closed form made by arm_closed_form")
            scheme = detection if detection in JOINT_SPACE_DETECTIONS else "force"
            return self.joint_space.collision(self.threshold, v0, detection=scheme).total
        robot_velocity = self.v_r * v0 if self.reaction == "moving" else None
        phases = phase_impulses(
            self.m_f, self.k, self.k_m, self.threshold, self.a, v0, self.reaction, robot_velocity
        )
        if model == "constant":
            return float(phases.total)
        _, reaction = sprung_reaction(self.threshold, self.k_m, self.F_a, self.m_r, robot_velocity or 0.0)
        return float(phases.initial + phases.sensing + reaction)


def arm_closed_form(
    arm: Any,
    q: npt.ArrayLike,
    direction: npt.ArrayLike,
    joints: JointDesign,
    placement: str = "robot",
    contact_stiffness: float = math.inf,
    reaction: str = "moving",
) -> ArmClosedForm:
    """The arm closed form of a design at configuration ``q`` [rad] along ``direction``.

    Parameters
    ----------
    arm: a :class:`collision_reflex.Arm`.
    q: configuration (nq,) [rad]; direction: collision direction in task coordinates, normalised here.
    joints: the design's joint parameters.
    placement: ``"robot"`` or ``"finger"`` (reflected inertia also in ``m_f``).
    contact_stiffness: stiffness of the object hit [N/m], in series with ``k`` and ``k_m``; ``inf``: rigid.
    reaction: ``"moving"`` (robot still moving at detection, as the simulation) or ``"at_rest"``.
    """
    arm = joints.on(arm)
    _validate.choice("placement", placement, PLACEMENTS)
    _validate.choice("reaction", reaction, arm_simulation.ARM_REACTIONS)
    _validate.positive("contact_stiffness", contact_stiffness, allow_inf=True)
    nv = int(arm.nv)
    inertia = np.broadcast_to(np.asarray(joints.reflected_inertia, dtype=float), (nv,))
    k_m = np.broadcast_to(np.asarray(joints.mechanical_stiffness, dtype=float), (nv,))
    k_s = np.broadcast_to(np.asarray(joints.software_stiffness, dtype=float), (nv,))
    u = np.asarray(direction, dtype=float).reshape(-1)
    u = u / np.linalg.norm(u)
    samples = arm.kinematics(np.asarray(q, dtype=float)[None])
    motor_mass = np.asarray(arm.joint_parameters.motor_mass, dtype=float)
    effective = effective_parameters(
        samples,
        u[None],
        inertia,
        series_stiffness(k_m, k_s),
        k_m,
        joints.torque_limit,
        motor_mass=motor_mass if np.any(motor_mass > 0) else None,
        finger_joint_inertia=inertia if placement == "finger" else None,
    )
    if bool(effective.singular[0, 0]):
        raise InvalidParameter(
            "direction", direction, "a direction the arm can move along at q", "q is singular"
        )
    jac = samples.jacobian[0]
    v_r = float(u @ jac @ (admittance_share(k_m, k_s) * (np.linalg.pinv(jac) @ u)))
    value = {name: float(getattr(effective, name)[0, 0]) for name in ("m_f", "m_r", "k", "k_m", "F_a", "a")}
    return ArmClosedForm(
        m_f=value["m_f"],
        m_r=value["m_r"],
        k=float(series_stiffness(value["k"], contact_stiffness)),
        k_m=float(series_stiffness(value["k_m"], contact_stiffness)),
        F_a=value["F_a"],
        a=value["a"],
        v_r=v_r,
        threshold=float(joints.threshold),
        reaction=reaction,
        joint_space=JointSpaceArm(
            samples.structure_mass_matrix(motor_mass if np.any(motor_mass > 0) else None)[0],
            jac,
            u,
            k_m,
            inertia,
            joints.torque_limit,
            k_s,
        ),
    )


@dataclass(frozen=True)
class ValidityCase:
    """One simulated collision of the map: where, how fast, against what, detected how.

    Attributes
    ----------
    configuration, direction: indices into the map's configurations and directions.
    velocity_ratio: ``v0 / v*``; stiffness_ratio: contact over joint stiffness along ``u``; detection: scheme;
    drive: :data:`DRIVES`.
    """

    configuration: int
    direction: int
    velocity_ratio: float
    stiffness_ratio: float
    detection: str
    drive: str = "ideal"


def validity_map(
    arm: Any,
    joints: JointDesign,
    configurations: npt.ArrayLike,
    directions: npt.ArrayLike,
    *,
    velocity_ratios: Sequence[float] = VELOCITY_RATIOS,
    stiffness_ratios: Sequence[float] = STIFFNESS_RATIOS,
    detections: Sequence[str] | None = None,
    placements: Sequence[str] = PLACEMENTS,
    tolerance: float = TOLERANCE,
    reaction: str = "moving",
    max_steps: float = MAX_STEPS,
    drives: Sequence[str] = ("ideal",),
    contact_damping_ratio: float = CONTACT_DAMPING_RATIO,
) -> Any:
    """Where the arm closed form agrees with the time-domain simulation, as a :class:`pandas.DataFrame`.

    Parameters
    ----------
    arm: a :class:`collision_reflex.Arm`.
    joints: the design's joint parameters and threshold.
    configurations: (n, nq) impact configurations [rad]; directions: (d, task_dim) collision directions.
    velocity_ratios: approach velocities as multiples of ``v*`` (robot placement, rigid contact) [-].
    stiffness_ratios: contact stiffness over the joints' mechanical stiffness along ``u`` [-].
    detections: detection schemes to simulate; default every scheme the simulator offers.
    placements: closed-form placements of the reflected inertia compared with each simulation.
    tolerance: relative agreement that counts as valid [-].
    reaction: the closed form's reaction variant (``"moving"``: the robot's velocity at detection).
    max_steps: work budget of one simulation [integrator steps]; a case beyond it is refused and recorded.
    drives: the simulated drives (:data:`DRIVES`); ``"impedance"`` needs a finite software stiffness.
    contact_damping_ratio: the contact's damping as a ratio of critical for the finger mass (dimensionless).

    Returns
    -------
    One row per case, placement and reaction model (:data:`REACTION_MODELS`): ``configuration``,
    ``direction`` (indices), ``q``, ``u`` (as lists), ``velocity_ratio``, ``v0`` [m/s], ``stiffness_ratio``,
    ``contact_stiffness`` [N/m], ``detection``, ``drive``, ``placement``, ``reaction_model``, ``simulated``
    and ``closed_form`` [N*s], ``difference`` (``I_sim / I_closed - 1``), ``valid`` (within ``tolerance``),
    ``damper_share`` (:func:`damper_share`: the contact's viscous force in the sensing ramp over ``F_s``, a
    force the closed form's elastic object has not), ``object_deflection`` (``F_s / k_c`` [m], the contact
    point's travel into the object until detection, over which the closed form keeps the configuration
    fixed), ``error`` (why a case was refused or failed, else ``""``) and ``seconds`` (the simulation's
    wall time).
    """
    import pandas as pd  # lazy: pandas

    qs, us = _cases(arm, configurations, directions)
    schemes = _check_map_settings(
        joints,
        velocity_ratios,
        stiffness_ratios,
        detections,
        placements,
        tolerance,
        drives,
        contact_damping_ratio,
    )
    rows: list[dict[str, Any]] = []
    for i, q in enumerate(qs):
        for j, u in enumerate(us):
            reference = arm_closed_form(arm, q, u, joints, "robot", math.inf, reaction)
            v_star = float(optimal_velocity(reference.m_f, reference.k, joints.threshold))
            for ratio_k in stiffness_ratios:
                k_c = float(ratio_k) * reference.k_m
                closed = {p: arm_closed_form(arm, q, u, joints, p, k_c, reaction) for p in placements}
                for ratio_v, detection, drive in itertools.product(velocity_ratios, schemes, drives):
                    case = ValidityCase(i, j, float(ratio_v), float(ratio_k), detection, drive)
                    v0 = case.velocity_ratio * v_star
                    simulated = simulated_impulse(
                        arm,
                        q,
                        u,
                        joints,
                        v0,
                        k_c,
                        detection,
                        reaction,
                        max_steps,
                        drive=drive,
                        contact_damping_ratio=contact_damping_ratio,
                    )
                    share = damper_share(reference, v0, k_c, contact_damping_ratio)
                    rows.extend(
                        _row(case, q, u, v0, k_c, placement, model, form, simulated, tolerance, share)
                        for placement, form in closed.items()
                        for model in REACTION_MODELS
                    )
    return pd.DataFrame(rows)


def _cases(
    arm: Any, configurations: npt.ArrayLike, directions: npt.ArrayLike
) -> tuple[np.ndarray, np.ndarray]:
    """The map's configurations (n, nq) [rad] and directions (d, task_dim), checked."""
    qs = np.atleast_2d(np.asarray(configurations, dtype=float))
    us = np.atleast_2d(np.asarray(directions, dtype=float))
    if qs.ndim != 2 or qs.shape[1] != arm.nq or not np.all(np.isfinite(qs)):
        raise InvalidParameter(
            "configurations", configurations, f"rows of {arm.nq} finite joint angles [rad]"
        )
    norms = np.linalg.norm(us, axis=-1) if us.ndim == 2 else np.zeros(1)
    if us.ndim != 2 or us.shape[1] != arm.task_dim or not np.all(np.isfinite(norms) & (norms > 0)):
        raise InvalidParameter("directions", directions, f"nonzero rows of {arm.task_dim} task coordinates")
    return qs, us


def _check_map_settings(
    joints: JointDesign,
    velocity_ratios: Sequence[float],
    stiffness_ratios: Sequence[float],
    detections: Sequence[str] | None,
    placements: Sequence[str],
    tolerance: float,
    drives: Sequence[str],
    contact_damping_ratio: float,
) -> tuple[str, ...]:
    """Check the map's settings (see :func:`validity_map`); the detection schemes it simulates."""
    for name, values in (("velocity_ratios", velocity_ratios), ("stiffness_ratios", stiffness_ratios)):
        _validate.positive(name, np.asarray(values, dtype=float))
    _validate.positive("tolerance", tolerance)
    schemes = tuple(available_detections() if detections is None else detections)
    for scheme in schemes:
        _validate.choice("detection", scheme, available_detections())
    for drive in drives:
        _validate.choice("drive", drive, DRIVES)
    if "impedance" in drives and not np.all(np.isfinite(np.asarray(joints.software_stiffness, dtype=float))):
        raise InvalidParameter(
            "joints.software_stiffness",
            joints.software_stiffness,
            "finite joint stiffnesses [N m/rad]",
            "the impedance drive needs them",
        )
    _validate.positive("contact_damping_ratio", contact_damping_ratio)
    for placement in placements:
        _validate.choice("placement", placement, PLACEMENTS)
    return schemes


@dataclass(frozen=True)
class SimulatedImpulse:
    """A simulation's impulse [N*s] (NaN if refused or failed), why not (``""`` if run) and its wall time [s].

    Attributes
    ----------
    impulse: [N*s]; error: the refusal's or failure's message, ``""`` if it ran; seconds: wall time [s].
    """

    impulse: float
    error: str
    seconds: float


def simulated_impulse(
    arm: Any,
    q: npt.ArrayLike,
    u: npt.ArrayLike,
    joints: JointDesign,
    approach_velocity: float,
    contact_stiffness: float,
    detection: str = TORQUE_DETECTION,
    reaction: str = "moving",
    max_steps: float = MAX_STEPS,
    *,
    drive: str = "ideal",
    contact_damping_ratio: float = CONTACT_DAMPING_RATIO,
) -> SimulatedImpulse:
    """Simulate one collision of a design; a refusal (work budget) or failure is returned, not raised.

    Parameters
    ----------
    arm: a :class:`collision_reflex.Arm`; q: configuration [rad]; u: collision direction (task coordinates).
    joints: the design's joint parameters and threshold.
    approach_velocity: [m/s]; contact_stiffness: the wall's stiffness [N/m].
    detection: a scheme of :func:`available_detections`; reaction: the closed-form variant the simulator
        reports beside (``"moving"`` or ``"at_rest"``); max_steps: the work budget [integrator steps].
    drive: :data:`DRIVES`; contact_damping_ratio: the contact's damping, a ratio of critical for the finger.
    """
    start = time.perf_counter()
    try:
        result = arm_simulation.simulate_arm_collision(
            joints.on(arm),
            q,
            u,
            approach_velocity,
            joints.threshold,
            contact_stiffness=contact_stiffness,
            contact_damping_ratio=contact_damping_ratio,
            reaction=reaction,
            drive=drive,
            detection=detection,
            max_steps=max_steps,
            **joints.simulator_keywords(),
        )
    except (SimulationError, InvalidParameter) as error:
        return SimulatedImpulse(math.nan, str(error), time.perf_counter() - start)
    return SimulatedImpulse(float(result.impulse), "", time.perf_counter() - start)


def damper_share(
    closed: ArmClosedForm, approach_velocity: float, contact_stiffness: float, damping_ratio: float
) -> float:
    """The contact's viscous force during the sensing ramp over the threshold [-].

    In the ramp the chain's force rises as ``k v0 t`` (``k``: the joints' ``k_j`` in series with the contact)
    and the object is compressed at ``d' = k v0 / k_c``; its damper ``c = 2 zeta sqrt(m_f k_c)`` carries ``c
    d'`` of the force, which the closed form's elastic object has not, and which a contact sensor reading the
    elastic force ``k_c d`` misses (it detects when the wall's force is ``F_s`` plus this share of it). With
    ``v0 = r v*`` (``v*`` of the rigid contact) it is ``zeta r sqrt(2) k / sqrt(k_c k_j)``, symmetric in
    ``k_c`` and ``k_j``: 8.1 % at 0.1 ``v*`` with ``zeta = 2`` against an object 10 or 0.1 times the joints'
    stiffness, 81 % at ``v*``; 8.9 % at ``v*`` against one 1000 times as stiff (where the sensing phase is a small share of the impulse).

    Parameters
    ----------
    closed: the closed form at the rigid contact (robot placement): ``m_f`` [kg], the joints' ``k`` [N/m].
    approach_velocity: [m/s]; contact_stiffness: ``k_c`` [N/m]; damping_ratio: ``zeta`` (the simulator's).
    """
    k = float(series_stiffness(closed.k, contact_stiffness))
    damping = damping_from_ratio(damping_ratio, closed.m_f, contact_stiffness)
    return float(damping * k * approach_velocity / contact_stiffness / closed.threshold)


def _row(
    case: ValidityCase,
    q: np.ndarray,
    u: np.ndarray,
    v0: float,
    contact_stiffness: float,
    placement: str,
    model: str,
    closed: ArmClosedForm,
    simulated: SimulatedImpulse,
    tolerance: float,
    damper: float,
) -> dict[str, Any]:
    """One row of the map: a case against one placement's and reaction model's closed form."""
    closed_form = closed.impulse(v0, model, case.detection)
    difference = simulated.impulse / closed_form - 1
    return {
        "configuration": case.configuration,
        "direction": case.direction,
        "q": [float(x) for x in q],
        "u": [float(x) for x in u / np.linalg.norm(u)],
        "velocity_ratio": case.velocity_ratio,
        "v0": v0,
        "stiffness_ratio": case.stiffness_ratio,
        "contact_stiffness": contact_stiffness,
        "detection": case.detection,
        "drive": case.drive,
        "placement": placement,
        "reaction_model": model,
        "simulated": simulated.impulse,
        "closed_form": closed_form,
        "difference": difference,
        "valid": bool(abs(difference) <= tolerance),
        "damper_share": damper,
        "object_deflection": closed.threshold / contact_stiffness,
        "error": simulated.error,
        "seconds": simulated.seconds,
    }


MAP_INDEX: tuple[str, ...] = ("detection", "drive", "reaction_model", "placement", "stiffness_ratio")
"""The rows of the map's pivot tables; their columns are the velocity ratios."""


def validity_summary(table: Any) -> Any:
    """Share of valid cases per detection, placement, stiffness ratio and velocity ratio (a pivot table).

    Rows: :data:`MAP_INDEX`; columns: ``velocity_ratio``; values: the fraction of the configurations x
    directions where the closed form holds (failed cases count as not valid).
    """
    return table.pivot_table(
        index=list(MAP_INDEX),
        columns="velocity_ratio",
        values="valid",
        aggfunc="mean",
    )


def worst_difference(table: Any) -> Any:
    """Largest ``|I_sim / I_closed - 1|`` per :data:`MAP_INDEX` row and velocity ratio (``inf`` where one failed)."""
    frame = table.assign(magnitude=table["difference"].abs().fillna(math.inf))
    return frame.pivot_table(
        index=list(MAP_INDEX),
        columns="velocity_ratio",
        values="magnitude",
        aggfunc="max",
    )
