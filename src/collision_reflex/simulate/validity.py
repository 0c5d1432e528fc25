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

import functools
import itertools
import math
import time
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

from .. import _validate
from ..errors import InvalidParameter, SimulationError
from ..model.contact import COUPLED_STIFFNESS_RATIO, DECOUPLED_STIFFNESS_RATIO
from ..model.impulse import optimal_velocity, series_stiffness
from ..vocabulary import CONTROLLED_DRIVES, REFLECTED_INERTIA_PLACEMENTS
from . import arm as arm_simulation
from .arm_detection import DETECTIONS
from .contact import contact_restitution, damping_from_ratio, damping_ratio_for_restitution
from .design_closed_form import REACTION_MODELS, ArmClosedForm, JointDesign, arm_closed_form

VELOCITY_RATIOS: tuple[float, ...] = (0.1, 0.3, 1.0, 3.0, 10.0)
"""Approach velocities swept, as multiples of the closed form's optimum ``v* = F_s / sqrt(2 k m_f)``."""

STIFFNESS_RATIOS: tuple[float, ...] = (0.1, 10.0)
"""Contact stiffness over the joints' mechanical stiffness along ``u``: 0.1 is a stiff transmission hitting a
compliant object, 10 compliant joints hitting a stiff one."""

TOLERANCE = 0.05
"""Agreement that counts as valid: ``|I_sim / I_closed - 1| <= 5 %``."""

MAX_STEPS = 200_000
"""Default work budget of one arm simulation [integrator steps] (the simulator's; tens of seconds at most)."""

CONTACT_DAMPING_RATIO = 2.0
"""The simulated contact's damping, as a ratio of critical for the finger mass (the simulator's default: a
plastic impact, restitution 0.048 of the finger alone)."""

TORQUE_DETECTION = "spring_torque"
"""The simulator's default detection: the contact force estimated from the joint spring torques."""


def available_detections() -> tuple[str, ...]:
    """The detection schemes of the arm simulator, its default first."""
    return (TORQUE_DETECTION, *(s for s in DETECTIONS if s != TORQUE_DETECTION))


@dataclass(frozen=True)
class ValidityCase:
    """One simulated collision of the map: where, how fast, against what, detected how.

    Attributes
    ----------
    configuration, direction: indices into the map's configurations and directions.
    velocity_ratio: ``v0 / v*``; stiffness_ratio: contact over joint stiffness along ``u``; detection: scheme;
    drive: :data:`~collision_reflex.vocabulary.CONTROLLED_DRIVES`; contact_damping_ratio: the contact's damping,
    a ratio of critical for the finger mass.
    """

    configuration: int
    direction: int
    velocity_ratio: float
    stiffness_ratio: float
    detection: str
    drive: str = "ideal"
    contact_damping_ratio: float = CONTACT_DAMPING_RATIO


def validity_map(
    arm: Any,
    joints: JointDesign,
    configurations: npt.ArrayLike,
    directions: npt.ArrayLike,
    *,
    velocity_ratios: Sequence[float] = VELOCITY_RATIOS,
    stiffness_ratios: Sequence[float] = STIFFNESS_RATIOS,
    detections: Sequence[str] | None = None,
    placements: Sequence[str] = REFLECTED_INERTIA_PLACEMENTS,
    tolerance: float = TOLERANCE,
    reaction: str = "moving",
    max_steps: float = MAX_STEPS,
    drives: Sequence[str] = ("ideal",),
    contact_damping_ratio: float = CONTACT_DAMPING_RATIO,
    restitutions: Sequence[float] | None = None,
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
    drives: the simulated drives (:data:`~collision_reflex.vocabulary.CONTROLLED_DRIVES`); ``"impedance"`` needs a finite software stiffness.
    contact_damping_ratio: the contact's damping as a ratio of critical for the finger mass (dimensionless).
    restitutions: instead, the contact's coefficients of restitution for the finger alone, each in (0, 1]:
        the closed form's plastic impact against rebounding contacts.

    Returns
    -------
    One row per case, placement and reaction model (:data:`REACTION_MODELS`): ``configuration``,
    ``direction`` (indices), ``q``, ``u`` (as lists), ``velocity_ratio``, ``v0`` [m/s], ``stiffness_ratio``,
    ``contact_stiffness`` [N/m], ``restitution`` (the contact's, for the finger alone), ``transient_exact``
    (whether the compliant contact's closed form, ``F = v sqrt(mu k_c)``, has its robot mass exactly: a contact at
    least 100 times stiffer or at most 0.01 times as stiff as the joints along ``u``; in between it is the coupled
    bound, :func:`collision_reflex.model.contact_robot_mass`), ``detection``, ``drive``,
    ``placement``, ``reaction_model``, ``simulated``
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
    dampings = _damping_ratios(contact_damping_ratio, restitutions)
    rows: list[dict[str, Any]] = []
    for i, q in enumerate(qs):
        for j, u in enumerate(us):
            reference = arm_closed_form(arm, q, u, joints, "robot", math.inf, reaction)
            v_star = float(optimal_velocity(reference.m_f, reference.k, joints.threshold))
            for ratio_k in stiffness_ratios:
                k_c = float(ratio_k) * reference.k_m
                closed = {p: arm_closed_form(arm, q, u, joints, p, k_c, reaction) for p in placements}
                for ratio_v, detection, drive, damping in itertools.product(
                    velocity_ratios, schemes, drives, dampings
                ):
                    case = ValidityCase(i, j, float(ratio_v), float(ratio_k), detection, drive, damping)
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
                        contact_damping_ratio=damping,
                    )
                    share = damper_share(reference, v0, k_c, damping)
                    rows.extend(
                        _row(case, q, u, v0, k_c, placement, model, form, simulated, tolerance, share)
                        for placement, form in closed.items()
                        for model in REACTION_MODELS
                    )
    return pd.DataFrame(rows)


def _damping_ratios(ratio: float, restitutions: Sequence[float] | None) -> list[float]:
    """The contact damping ratios of a map: ``ratio``, or one per coefficient of restitution (the finger's)."""
    if restitutions is None:
        return [ratio]
    if not len(restitutions):
        raise InvalidParameter("restitutions", restitutions, "one or more coefficients in (0, 1]")
    return [damping_ratio_for_restitution(float(e)) for e in restitutions]


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
        _validate.choice("drive", drive, CONTROLLED_DRIVES)
    if "impedance" in drives and not np.all(np.isfinite(np.asarray(joints.software_stiffness, dtype=float))):
        raise InvalidParameter(
            "joints.software_stiffness",
            joints.software_stiffness,
            "finite joint stiffnesses [N m/rad]",
            "the impedance drive needs them",
        )
    _validate.positive("contact_damping_ratio", contact_damping_ratio)
    for placement in placements:
        _validate.choice("placement", placement, REFLECTED_INERTIA_PLACEMENTS)
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
    drive: :data:`~collision_reflex.vocabulary.CONTROLLED_DRIVES`; contact_damping_ratio: the contact's damping, a ratio of critical for the finger.
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
        "restitution": _restitution(case.contact_damping_ratio),
        "transient_exact": bool(
            case.stiffness_ratio >= DECOUPLED_STIFFNESS_RATIO
            or case.stiffness_ratio <= COUPLED_STIFFNESS_RATIO
        ),
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


@functools.lru_cache(maxsize=64)
def _restitution(damping_ratio: float) -> float:
    """The contact's restitution for the finger alone at ``damping_ratio`` (each case's row names it)."""
    return contact_restitution(damping_ratio)


MAP_INDEX: tuple[str, ...] = (
    "detection",
    "drive",
    "reaction_model",
    "placement",
    "stiffness_ratio",
    "restitution",
)
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
