"""The constraints of a design problem: the user's requirements and the NLP's constraint rows.

:class:`Constraints` holds what the caller asks for (torque requirement, sensing noise floor); the rest builds
the NLP's ``lower <= g <= upper`` rows, each with a label: reaction capacities within the joint torques,
``w^T x = 1`` for the finger-mass directions, the torque requirement and the noise floor.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import casadi as ca
import numpy as np

from ..arm.duty_cycle import DutyCycle
from ..arm.rating import Rating
from ..errors import InvalidParameter
from ..model.contact import BodyRegion
from .samples import ContactSamples, kinematic_term, loaded_joints
from .technology import ActuatorTechnology

if TYPE_CHECKING:
    from ..arm.samples import ArmSamples

STATIC_REQUIREMENT = "static (gravity only)"
"""The requirement without a duty cycle: gravity torques over the sampled configurations only."""
GIVEN_REQUIREMENT = "given peak torques"
"""The requirement when the caller gives the peak torques."""
DUTY_REQUIREMENT = "duty cycle (peak, RMS, speed)"
"""The requirement of a duty cycle: peak and RMS torque and the motor speed, and the static hold besides."""
RATED_REQUIREMENT = "rated motion (peak, speed)"
"""The requirement of a rating without a duty cycle: the rated motion's and the braking's peak torques and the
rated speeds, and the static hold besides."""

TorqueDemands = tuple[np.ndarray, np.ndarray, list[str]]
"""One joint's affine torque demands ``b + S m`` [N m]: bases ``b`` (R,), slopes ``S`` (R, n) per actuator mass
[N m/kg] and one label per demand."""


@dataclass(frozen=True)
class Constraints:
    """Constraints of a design problem.

    payload: mass carried at the contact point [kg], adds its gravity torques to the requirement (with a duty
        cycle: to the static hold, which every sampled configuration must meet besides the cycle).
    safety_factor: peak output torque must be at least this times the required torque [-], >= 1.
    torque_required: per-joint required torque [N m]; ``None`` derives it from Pinocchio gravity torques of the
        structure, the motors and the payload over the sampled configurations.
    threshold_floor: sensing noise floor [N]: the contact-force threshold may not go below it.
    duty_cycle: the motion the arm must make, with its payload (:class:`collision_reflex.arm.DutyCycle`).
        Given, it adds to the static hold (the arm and ``payload`` held still at every sampled configuration):
        per joint the peak torque over the cycle (rotor term and safety factor included), the RMS torque within
        the continuous torque, and the motor speed over the cycle and the approach within the motor's maximum
        speed (:mod:`collision_reflex.optimize.duty`); the peak requirement is the larger of the two. The
        cycle's own payload moves with it; ``torque_required`` must then be left unset.
    hold_poses: the kinematics (:meth:`collision_reflex.arm.Arm.kinematics`) of further configurations the static
        hold must meet, one per joint in order (:func:`collision_reflex.arm.static_hold.worst_hold_poses`: each
        joint's worst pose within the joint limits), or None.
    rating: the robot's rated joint speeds, accelerations and stopping times with its payload
        (:class:`collision_reflex.arm.rating.Rating`): the rated motion's and the braking's states at every
        sampled configuration add to the peak requirement and the rated speeds to the speed requirement, as a
        duty cycle's samples do (:mod:`collision_reflex.optimize.duty`); ``torque_required`` must be left unset.
    body_region: a human body region (:class:`collision_reflex.model.BodyRegion`, one with a permissible
        transient force) whose transient-force limit the approach must keep at every sample in the contact
        domain, the robot mass taken with its rotors on the links (:mod:`collision_reflex.optimize.body_region`);
        None for none.
    """

    payload: float = 0.0
    safety_factor: float = 1.0
    torque_required: Sequence[float] | None = None
    threshold_floor: float = 0.0
    duty_cycle: DutyCycle | None = None
    rating: Rating | None = None
    hold_poses: ArmSamples | None = None
    body_region: BodyRegion | None = None

    def __post_init__(self) -> None:
        if self.body_region is not None and (
            not isinstance(self.body_region, BodyRegion) or self.body_region.transient_force is None
        ):
            raise InvalidParameter(
                "body_region",
                self.body_region,
                "a BodyRegion with a permissible transient force, or None",
                "ISO/TS 15066 permits no transient contact with a region without one",
            )
        if not (math.isfinite(self.payload) and self.payload >= 0):
            raise InvalidParameter("payload", self.payload, "a finite mass >= 0 [kg]")
        if not (math.isfinite(self.safety_factor) and self.safety_factor >= 1):
            raise InvalidParameter("safety_factor", self.safety_factor, "a finite number >= 1")
        if not (math.isfinite(self.threshold_floor) and self.threshold_floor >= 0):
            raise InvalidParameter("threshold_floor", self.threshold_floor, "a finite force >= 0 [N]")
        if self.torque_required is not None:
            required = np.asarray(self.torque_required, dtype=float)
            if required.ndim != 1 or not np.all(np.isfinite(required) & (required >= 0)):
                raise InvalidParameter(
                    "torque_required", self.torque_required, "one torque >= 0 per joint [N m]"
                )
        if self.duty_cycle is not None:
            if not isinstance(self.duty_cycle, DutyCycle):
                raise InvalidParameter("duty_cycle", self.duty_cycle, "a DutyCycle or None")
            if self.torque_required is not None:
                raise InvalidParameter(
                    "duty_cycle",
                    "given with torque_required",
                    "one requirement",
                    "the duty cycle's torques and the static hold size the joints; leave torque_required unset",
                )

        if self.rating is not None:
            if not isinstance(self.rating, Rating):
                raise InvalidParameter("rating", self.rating, "a Rating or None")
            if self.torque_required is not None and self.rating.moves:
                raise InvalidParameter(
                    "rating",
                    "given with torque_required",
                    "one requirement",
                    "the rated motion and the static hold size the joints; leave torque_required unset",
                )

    @property
    def moves(self) -> bool:
        """True when a duty cycle or a rated motion adds to the static hold."""
        return self.duty_cycle is not None or (self.rating is not None and self.rating.moves)

    @property
    def requirement(self) -> str:
        """What sizes the torques: :data:`STATIC_REQUIREMENT`, :data:`GIVEN_REQUIREMENT`, :data:`DUTY_REQUIREMENT` or :data:`RATED_REQUIREMENT`."""
        if self.duty_cycle is not None:
            return DUTY_REQUIREMENT
        if self.moves:
            return RATED_REQUIREMENT
        return STATIC_REQUIREMENT if self.torque_required is None else GIVEN_REQUIREMENT


@dataclass
class ConstraintList:
    """The NLP's constraints ``lower <= g <= upper`` as they are added, each row with a label."""

    parts: list[ca.MX] = field(default_factory=list)
    lower: list[np.ndarray] = field(default_factory=list)
    upper: list[np.ndarray] = field(default_factory=list)
    labels: list[str] = field(default_factory=list)

    def add(self, expression: ca.MX, lower: float, upper: float, names: list[str]) -> None:
        """Append the rows of ``expression`` with common bounds and one label per row."""
        self.parts.append(expression)
        self.lower.append(np.full(len(names), lower))
        self.upper.append(np.full(len(names), upper))
        self.labels.extend(names)


@dataclass(frozen=True)
class ModelTerms:
    """The symbolic quantities the model's constraints bound (see :func:`add_model_constraints`).

    log_compliance: log reaction compliances ``g_s = log(1/F_a)`` (n_samples).
    peak_torque: peak output torques [N m] (n_joints).
    normalisation: ``w_s^T x_s`` per sample (1 x n_samples).
    thresholds: contact-force thresholds [N] (1 x n_samples).
    actuator_mass: actuator (motor and gearbox) masses carried at the joints [kg] (n_joints).
    driving_torque: driving peak output torques ``eta N tau_p`` [N m] (n_joints), what the torque requirement
        must be within (the reaction capacity keeps ``N tau_p``, see
        :meth:`~collision_reflex.optimize.technology.ActuatorTechnology.joint_quantities`).
    """

    log_compliance: ca.MX
    peak_torque: ca.MX
    normalisation: ca.MX
    thresholds: ca.MX
    actuator_mass: ca.MX
    driving_torque: ca.MX


def add_model_constraints(
    g: ConstraintList,
    terms: ModelTerms,
    torque_scale: np.ndarray,
    torque_demands: list[TorqueDemands],
    samples: ContactSamples,
    technology: ActuatorTechnology,
    constraints: Constraints,
    joint_names: tuple[str, ...],
) -> None:
    """Add the constraints of the model itself to ``g``.

    They are: reaction capacities within the joint torques, ``w^T x = 1`` for the finger-mass directions, the
    torque requirement (rows divided by ``torque_scale`` [N m], the requirement at the start) and the sensing
    noise floor.
    """
    n_samples = samples.size
    # g_s + log tau_i >= log|w_si| for every loaded (sample, joint), i.e. 1/F_a >= |w_si| / tau_i.
    loaded = loaded_joints(samples)
    pair_sample, pair_joint = np.nonzero(loaded)
    log_arm = np.log(np.abs(samples.joint_moment_arms[pair_sample, pair_joint]))
    g.add(
        # ca.vec: CasADi indexes a 1x1 expression (one sample) into a row; every term here is a column.
        ca.vec(terms.log_compliance[pair_sample.tolist()])
        + ca.vec(ca.log(terms.peak_torque)[pair_joint.tolist()])
        - log_arm,
        0.0,
        np.inf,
        [
            f"reaction capacity of sample {s} within the torque of {joint_names[j]}"
            for s, j in zip(pair_sample, pair_joint, strict=True)
        ],
    )

    g.add(ca.transpose(terms.normalisation), 1.0, 1.0, [f"w^T x = 1 at sample {s}" for s in range(n_samples)])

    # Torque: driving peak output torque covers the requirement in every sampled configuration, as linear
    # constraints scaled by the requirement at the start; only demands that can be the largest somewhere in
    # the box of actuator masses allowed by the bounds can bind, the others are dropped (exactly).
    for j, (bases, slopes, demand_labels) in enumerate(torque_demands):
        demand = ca.DM(bases) + ca.mtimes(ca.DM(slopes), terms.actuator_mass)
        g.add(
            (terms.driving_torque[j] - demand) / torque_scale[j],
            0.0,
            np.inf,
            [f"peak torque of {joint_names[j]} >= {label}" for label in demand_labels],
        )

    if technology.sensing == "position" and constraints.threshold_floor > 0:
        g.add(
            ca.transpose(terms.thresholds) / constraints.threshold_floor,
            1.0,
            np.inf,
            [f"contact threshold of sample {s} >= noise floor" for s in range(n_samples)],
        )


def add_gearbox_peak_constraints(
    g: ConstraintList,
    terms: ModelTerms,
    torque_demands: list[TorqueDemands],
    technology: ActuatorTechnology,
    joint_names: tuple[str, ...],
) -> None:
    """Add, per joint with a gearbox, its rating: every torque demand within its repeated peak torque.

    The demands are the static (or given) requirement's, safety factor included, as the motor's rows; each
    row is divided by the rating, so that its margin reads as a fraction of it.
    """
    figures = technology.gearbox_figures(len(joint_names))
    for j, (bases, slopes, demand_labels) in enumerate(torque_demands):
        rating = figures.peak_torque[j]
        if not np.isfinite(rating):
            continue
        demand = ca.DM(bases) + ca.mtimes(ca.DM(slopes), terms.actuator_mass)
        g.add(
            1.0 - demand / rating,
            0.0,
            np.inf,
            [
                f"gearbox {figures.names[j]} of {joint_names[j]}: repeated peak rating {rating:.4g} N*m >= {label}"
                for label in demand_labels
            ],
        )


def check_gearbox_ratings(
    torque_demands: list[TorqueDemands],
    technology: ActuatorTechnology,
    joint_names: tuple[str, ...],
    mass_low: np.ndarray,
    mass_high: np.ndarray,
) -> None:
    """Refuse a gearbox whose repeated peak torque is below the least its joint's requirement can be.

    The requirement is the largest demand ``b + S m``; over the box of actuator masses ``[mass_low,
    mass_high]`` [kg] it is at least each demand's smallest value there, so a rating below the largest of
    those cannot be met by any design within the bounds.

    Raises
    ------
    InvalidParameter: names the joint, the gearbox, its rating and the least requirement [N m].
    """
    figures = technology.gearbox_figures(len(joint_names))
    for j, (bases, slopes, _) in enumerate(torque_demands):
        rating = figures.peak_torque[j]
        if not np.isfinite(rating) or bases.size == 0:
            continue
        least = float((bases + np.minimum(slopes * mass_low, slopes * mass_high).sum(axis=1)).max())
        if least > rating * (1 + 1e-9):
            raise InvalidParameter(
                f"gearbox {figures.names[j]} of {joint_names[j]}",
                f"repeated peak rating {rating:.4g} N*m",
                f"a rating >= {least:.4g} N*m, the least torque {joint_names[j]} needs within the bounds "
                "(safety factor included)",
                "choose a gearbox of a higher rating, or lower the payload, the safety factor or the given torques",
            )


def torque_requirement_rows(
    samples: ContactSamples, constraints: Constraints, joint_names: tuple[str, ...]
) -> tuple[list[tuple[np.ndarray, np.ndarray]], list[str]]:
    """Affine torque demands ``d0 + D m`` [N m] (``m``: actuator masses [kg]) the peak torques must cover.

    Given torques: one demand. Otherwise, per sampled configuration, plus and minus the gravity torque of the
    structure, the motors (linear in their masses) and the payload at the contact point, all times the safety
    factor.
    """
    n = len(joint_names)
    factor = constraints.safety_factor
    if constraints.torque_required is not None:
        given = np.asarray(constraints.torque_required, dtype=float)
        if given.shape != (n,):
            raise InvalidParameter("torque_required", given.shape, f"{n} values, one per joint")
        return [(factor * given, np.zeros((n, n)))], ["the given required torque"]
    gravity, contact_gravity, motor_gravity = (
        kinematic_term(samples, name) for name in ("gravity", "contact_gravity", "motor_gravity")
    )
    rows, labels = [], []
    poses = [
        (gravity[c], contact_gravity[c], motor_gravity[c], f"configuration {c}")
        for c in np.unique(samples.config_index)
    ]
    hold = constraints.hold_poses
    if hold is not None:
        assert (
            hold.gravity is not None and hold.contact_gravity is not None and hold.motor_gravity is not None
        )
        poses += [
            (
                hold.gravity[k],
                hold.contact_gravity[k],
                hold.motor_gravity[k],
                f"the worst hold pose of {name}",
            )
            for k, name in enumerate(joint_names[: hold.gravity.shape[0]])
        ]
    for structure, payload, motors, where in poses:
        base = structure + constraints.payload * payload
        per_motor = motors.T  # (joint j, motor i)
        for sign, word in ((1.0, "+"), (-1.0, "-")):
            rows.append((sign * factor * base, sign * factor * per_motor))
            labels.append(f"{word}gravity torque at {where}")
    return rows, labels


def binding_torque_demands(
    samples: ContactSamples,
    constraints: Constraints,
    joint_names: tuple[str, ...],
    mass_low: np.ndarray,
    mass_high: np.ndarray,
) -> list[TorqueDemands]:
    """Per joint, the torque demands ``b + S m`` [N m] that can bind: ``(b (R,), S (R, n), labels)``.

    A demand whose largest value over the box of actuator masses ``[mass_low, mass_high]`` [kg] is below another
    demand's smallest value there never sets the requirement, so it is left out: an exact reduction (on arms,
    from two rows per sampled configuration to a handful). The stronger pairwise test of
    :func:`undominated_rows` is not applied here: on the Panda benchmark it kept fewer rows but raised the IPOPT
    iterations of a solve and of a front (to the same optimum).
    """
    rows, labels = torque_requirement_rows(samples, constraints, joint_names)
    demands = []
    for j in range(len(joint_names)):
        bases = np.array([base[j] for base, _ in rows])
        slopes = np.array([per_motor[j] for _, per_motor in rows])
        keep = binding_rows(bases, slopes, mass_low, mass_high)
        demands.append(
            (bases[keep], slopes[keep], [label for label, k in zip(labels, keep, strict=True) if k])
        )
    return demands


def binding_rows(bases: np.ndarray, slopes: np.ndarray, low: np.ndarray, high: np.ndarray) -> np.ndarray:
    """Mark the affine demands ``b + S v`` that can be the largest for some ``v`` in the box ``[low, high]``.

    ``bases`` (R,), ``slopes`` (R, k), ``low``/``high`` (k,) bounds of the variables ``v``. A demand whose
    largest value over the box is below another demand's smallest value there never is the largest: dropping
    it leaves the maximum unchanged everywhere in the box (exact). Returns a (R,) bool mask.
    """
    smallest = bases + np.minimum(slopes * low, slopes * high).sum(axis=1)
    largest = bases + np.maximum(slopes * low, slopes * high).sum(axis=1)
    return largest >= smallest.max() - 1e-12 * abs(smallest.max())


def undominated_rows(rows: np.ndarray, low: np.ndarray, high: np.ndarray) -> np.ndarray:
    """Mark the linear demands ``r . x`` not covered by another one everywhere in the box ``[low, high]``.

    ``rows`` (R, k), ``low``/``high`` (k,) bounds of ``x`` (a constant term is an entry with ``low = high =
    1``). Row ``a`` dominates row ``b`` when ``D(a, b) = min over the box of (a - b) . x >= 0``, i.e.
    ``sum_k min((a - b)_k low_k, (a - b)_k high_k) >= 0`` (a linear function's minimum over a box is at a
    corner, one coordinate at a time): then ``a . x >= b . x`` everywhere in the box and ``b`` can go.

    Rows are visited by decreasing value at the box's centre ``c`` (ties by index), each dropped when a row
    kept before it dominates it. Exact: the kept rows' maximum is every row's everywhere in the box. A row
    ``a`` dominating ``b`` has ``a . c >= b . c``, with equality only when ``a - b`` is zero over the box (a
    linear function >= 0 on a box and 0 at its centre is 0 on it), so ``a`` is visited first; dominance is
    transitive (``D(a, c) >= D(a, b) + D(b, c)``: the minimum of a sum is at least the sum of the minima), so
    a row dominated by a dropped row is dominated by the kept row that dropped it, and so on. Returns a
    (R,) bool mask.
    """
    centre = rows @ (0.5 * (low + high))
    keep = np.zeros(rows.shape[0], dtype=bool)
    kept: list[int] = []
    for b in np.lexsort((np.arange(rows.shape[0]), -centre)):
        if kept:
            difference = rows[kept] - rows[b]
            if np.any(np.minimum(difference * low, difference * high).sum(axis=1) >= 0):
                continue
        kept.append(int(b))
        keep[b] = True
    return keep


def required_torque_function(demands: list[TorqueDemands], n_joints: int) -> ca.Function:
    """CasADi function: actuator masses [kg] -> required peak torque per joint [N m].

    The requirement is the largest binding demand (safety factor included), for reporting.
    """
    masses = ca.MX.sym("actuator_mass", n_joints)
    required = [ca.mmax(ca.DM(bases) + ca.mtimes(ca.DM(slopes), masses)) for bases, slopes, _ in demands]
    return ca.Function("required_torque", [masses], [ca.vertcat(*required)])
