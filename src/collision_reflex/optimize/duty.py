"""The duty cycle's requirements on each joint's actuator: peak torque, RMS torque and motor speed.

With a duty cycle (:class:`collision_reflex.arm.DutyCycle`, in :attr:`Constraints.duty_cycle`) joint ``j``
must meet, over the cycle's samples ``t``:

- peak: ``eta_j N_j tau_p,j >= SF max_t |d_j(t)|`` with the joint-side demand ``d_j(t) = tau_j(t) + N_j^2
  (J_m,j + J_g,j) qdd_j(t)`` (:func:`collision_reflex.arm.dynamics.joint_side_torque`; ``eta``, ``J_g`` the
  gearbox's efficiency and input inertia, 1 and 0 without one). It is affine in ``x_j = [1, m_0, ...,
  m_{nv-1}, N_j^2 (J_m,j + J_g,j)]`` (actuator masses, motor and gearbox [kg], reflected inertia [kg m^2]):
  ``d_j = B_j x_j``, so the peak is the linear rows ``+-SF B_j(t) x_j <= eta_j N_j tau_p,j``; rows another
  row covers everywhere within the variable bounds are dropped exactly
  (:func:`collision_reflex.optimize.constraints.undominated_rows`);
- continuous (thermal): ``eta_j N_j tau_c,j >= RMS_t d_j`` as ``x_j^T Q_j x_j / (eta_j N_j tau_c,j)^2 <= 1``
  (smooth, of order one); no safety factor: the RMS is a thermal average, the safety factor covers the peak;
- speed: ``N_j max_t |qd_j(t)| <= omega_max,j`` and, for the approach itself, ``N_j v0 max_s |(J_s^+ u_s)_j|
  <= omega_max,j`` over the contact samples ``s`` (``J_s^+`` the pseudo-inverse of the contact Jacobian: the
  joint speeds that move the contact point along ``u_s`` at ``v0``). Both are linear in the log design
  variables (``omega_max`` of the scaled motor is a power law of its size); the approach needs one row per
  joint, at the sample with the largest joint rate, since ``v0`` is common to all samples.

A joint's gearbox adds its ratings (:func:`add_gearbox_duty_constraints`): the peak demand within its repeated
peak torque, the RMS demand within its rated torque, the motor speed within its maximum input speed. The
payload is the cycle's. :func:`torque_speed_points` gives the cycle's motor-side (speed, torque) points and the approach's
motor speeds of a design, for a torque-speed figure.
"""

from __future__ import annotations

import functools
import hashlib
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, NamedTuple, TypeVar, cast

import casadi as ca
import numpy as np

from ..arm.dynamics import CycleTorques, cycle_torques, joined, max_speed
from ..arm.rating import rated_torques
from ..errors import InvalidParameter
from ..hardware.motors import scaled_motor_quantities
from .constraints import ConstraintList, binding_rows, undominated_rows
from .samples import ContactSamples

if TYPE_CHECKING:
    from ..arm.duty_cycle import DutyCycle
    from ..arm.rating import Rating
    from ..arm.robot import Arm
    from .design import Design
    from .layout import DesignLayout, DesignQuantities
    from .problem import DesignProblem
    from .technology import ActuatorTechnology

PEAK, RMS, SPEED = "peak torque", "RMS torque", "speed"
"""The duty cycle's constraints, as error messages and labels name them."""
GEARBOX_RATINGS = ("peak rating", "rated torque (RMS)", "input speed")
"""A gearbox's ratings the duty cycle's peak, RMS and motor speed must be within, as error messages name them."""
T = TypeVar("T")
REACHABLE_TOLERANCE = 0.02
"""Best margin, found on a grid (:func:`check_reachable`), below which a requirement is refused before solving:
the grid's step in gear ratio (1/240 of the log range) can underestimate the best margin by about this much."""


@dataclass(frozen=True)
class DutyRequirement:
    """What a duty cycle asks of every joint, as numbers the constraints are made of.

    torques: the cycle's joint torques, split in the motor masses (:class:`collision_reflex.arm.dynamics.CycleTorques`).
    approach_rates: (n_samples, nv) joint speeds per unit approach speed, ``J_s^+ u_s`` [rad/m or m/m].
    safety_factor: the peak torque must be this times the peak demand [-].
    """

    torques: CycleTorques
    approach_rates: np.ndarray
    safety_factor: float

    @property
    def cycle_speed(self) -> np.ndarray:
        """``max_t |qd_j(t)|`` per joint over the cycle [rad/s], (nv,)."""
        return max_speed(self.torques.qd)

    @property
    def approach_rate(self) -> np.ndarray:
        """``max_s |(J_s^+ u_s)_j|`` per joint [rad/m], (nv,): joint speed per unit approach speed."""
        return np.abs(self.approach_rates).max(axis=0)

    def demand(self, actuator_mass: np.ndarray, reflected_inertia: np.ndarray) -> np.ndarray:
        """Joint-side torques over the cycle [N m], (n, nv).

        For the actuator (motor and gearbox) masses carried at the joints [kg] and ``N^2 (J_m + J_g)``
        [kg m^2].
        """
        return self.torques.demand(actuator_mass, reflected_inertia)

    def joint_speed(self, approach_velocity: float) -> np.ndarray:
        """Largest joint speed over the cycle and the approach at ``approach_velocity`` [m/s], [rad/s] (nv,)."""
        return np.maximum(self.cycle_speed, approach_velocity * self.approach_rate)


class DutyValues(NamedTuple):
    """A design's requirements and capacities over a duty cycle, per joint (nv,) each.

    required_torque: ``SF max_t |d_j|`` [N m]; required_rms_torque: ``RMS_t d_j`` [N m]; continuous_torque:
    the driving continuous torque ``eta N tau_c`` [N m]; max_motor_speed: ``N`` times the largest joint speed over the cycle and the approach
    [rad/s]; speed_limit: the scaled motor's maximum speed [rad/s].
    """

    required_torque: np.ndarray
    required_rms_torque: np.ndarray
    continuous_torque: np.ndarray
    max_motor_speed: np.ndarray
    speed_limit: np.ndarray


class TorqueSpeedPoints(NamedTuple):
    """One joint's motor-side operating points: the cycle's (speed, torque) and the approach's speeds.

    cycle_speed: (n,) motor speed ``N qd(t)`` [rad/s]; cycle_torque: (n,) motor torque ``d(t) / (eta N)``
    [N m] (no safety factor; ``eta`` the gearbox efficiency, 1 without one); approach_speed: (n_samples,) motor speed ``N v0 |J^+ u|`` of each contact sample
    [rad/s], signed as the joint moves.
    """

    cycle_speed: np.ndarray
    cycle_torque: np.ndarray
    approach_speed: np.ndarray


def approach_joint_rates(samples: ContactSamples) -> np.ndarray:
    """Joint speeds per unit approach speed ``J_s^+ u_s`` per contact sample, (n_samples, nv) [rad/m or m/m].

    ``J_s`` is the contact Jacobian (task_dim, nv) of sample ``s``'s configuration and ``u_s`` its direction;
    the pseudo-inverse gives the least-norm joint speeds that move the contact point at unit speed along ``u``.
    """
    jacobian = samples.kinematics.jacobian[samples.config_index]
    return np.einsum("sjd,sd->sj", np.linalg.pinv(jacobian), samples.directions)


def duty_requirement(
    arm: Arm,
    samples: ContactSamples,
    cycle: DutyCycle | None,
    rating: Rating | None,
    technology: ActuatorTechnology,
    safety_factor: float,
) -> DutyRequirement | None:
    """The motion's requirement on ``arm``: the duty cycle's and the rating's states, or None without either.

    RNEA over the cycle's samples and over the rated motion's and the braking's states at every configuration
    of ``samples`` (:func:`collision_reflex.arm.rating.rated_torques`); approach rates over ``samples``.

    Raises
    ------
    InvalidParameter: the reference motor has no maximum speed (the speed requirement needs it).
    """
    moving = rating is not None and rating.moves
    if cycle is None and not moving:
        return None
    for motor in technology.motors:
        if motor.max_speed is None:
            raise InvalidParameter(
                "reference_motor.max_speed",
                None,
                "a maximum speed [rad/s] when a duty cycle or rated motion is given",
                f"motor {motor.name!r} has none: add max_speed to its catalogue entry (e.g. '3000 rpm') or "
                "give Motor(..., max_speed=...)",
            )
    parts = []
    # The arm's own object in the keys (and kept in the memo with the torques): its id is not reused meanwhile.
    if cycle is not None:
        payload = () if cycle.payload is None else (cycle.payload.mass, cycle.payload.inertia)
        key = _digest(id(arm), cycle.joint_names, cycle.t, cycle.q, cycle.qd, cycle.qdd, *payload)
        held, torques = _CYCLE_TORQUES.get(key, lambda: (arm, cycle_torques(arm, cycle)))
        assert held is arm
        parts.append(torques)
    if moving:
        assert rating is not None
        kinematics = samples.kinematics
        payload = () if rating.payload is None else (rating.payload.mass, rating.payload.inertia)
        fields = (rating.joint_speeds, rating.joint_accelerations, rating.stopping_time)
        key = _digest(id(arm), kinematics.q, *(f if f is not None else "-" for f in fields), *payload)
        held, rated = _CYCLE_TORQUES.get(key, lambda: (arm, rated_torques(arm, kinematics, rating)))
        assert held is arm and rated is not None
        parts.append(rated)
    torques = parts[0] if len(parts) == 1 else joined(*parts)
    return DutyRequirement(torques, approach_joint_rates(samples), float(safety_factor))


def peak_rows(
    duty: DutyRequirement, x_low: np.ndarray, x_high: np.ndarray
) -> list[tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """Per joint the peak demands that can bind: ``(rows (R, nv + 2), sample index (R,), sign (R,))``.

    Row ``r`` is ``sign SF B_j(t)`` so that ``rows @ x_j <= N tau_p`` is the peak requirement. ``x_low`` and
    ``x_high`` (nv, nv + 2) bound ``x_j`` per joint (its first entry is 1); rows another row covers everywhere
    within them are dropped, exactly: first by the box test of
    :func:`collision_reflex.optimize.constraints.binding_rows`, then by pairwise dominance
    (:func:`collision_reflex.optimize.constraints.undominated_rows`). On a sampled cycle few rows remain, and
    the solve needs fewer IPOPT iterations with them than with every row.
    """
    kept = []
    for j in range(duty.torques.nv):
        basis = duty.safety_factor * duty.torques.demand_basis(j)
        key = _digest(basis, x_low[j], x_high[j])
        kept.append(_KEPT_ROWS.get(key, functools.partial(_joint_peak_rows, basis, x_low[j], x_high[j])))
    return kept


def _joint_peak_rows(
    basis: np.ndarray, x_low: np.ndarray, x_high: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """One joint's rows of :func:`peak_rows` from its demand basis (safety factor applied), read-only."""
    rows = np.vstack([basis, -basis])
    keep = binding_rows(rows[:, 0], rows[:, 1:], x_low[1:], x_high[1:])
    keep[keep] = undominated_rows(rows[keep], x_low, x_high)
    index = np.tile(np.arange(basis.shape[0]), 2)
    sign = np.repeat([1.0, -1.0], basis.shape[0])
    kept = (rows[keep], index[keep], sign[keep])
    for array in kept:
        array.flags.writeable = False  # kept in the memo and shared by every problem built from it
    return kept


def add_duty_constraints(
    g: ConstraintList,
    duty: DutyRequirement,
    design: DesignQuantities,
    demands: list[tuple[np.ndarray, np.ndarray, np.ndarray]],
    torque_scale: np.ndarray,
    joint_names: tuple[str, ...],
) -> None:
    """Add the duty cycle's peak, RMS and speed rows to ``g`` (see the module's docstring).

    ``demands``: :func:`peak_rows`; ``torque_scale``: per joint the peak requirement at the start [N m], which
    the peak rows are divided by.
    """
    states = duty.torques.labels
    gear, velocity = design.values["gear_ratio"], design.values["approach_velocity"][0]
    assert design.max_speed is not None  # duty_requirement checked the reference motor
    log_limit = ca.log(design.max_speed)
    for j, name in enumerate(joint_names):
        x_j = ca.vertcat(1.0, design.actuator_mass, design.reflected_inertia[j])
        rows, index, sign = demands[j]
        g.add(
            (design.driving_peak_torque[j] - ca.mtimes(ca.DM(rows), x_j)) / torque_scale[j],
            0.0,
            np.inf,
            [
                f"peak torque of {name} >= {'+' if s > 0 else '-'}{duty.safety_factor:g} x demand at {states[i]}"
                for i, s in zip(index, sign, strict=True)
            ],
        )
        if not duty.torques.timed:
            continue
        form = ca.DM(duty.torques.rms_form(j))
        g.add(
            ca.bilin(form, x_j, x_j) / design.continuous_torque[j] ** 2,
            -np.inf,
            1.0,
            [f"RMS torque of {name} over the cycle <= driving continuous torque"],
        )
    for rate, label, speed in (
        (duty.cycle_speed, "the motion", 1.0),
        (duty.approach_rate, "the approach", velocity),
    ):
        moving = np.flatnonzero(rate > 0).tolist()
        if moving:
            g.add(
                ca.log(gear[moving] * speed) + ca.DM(np.log(rate[moving])) - log_limit[moving],
                -np.inf,
                0.0,
                [f"motor speed of {joint_names[j]} over {label} <= its maximum speed" for j in moving],
            )


def add_gearbox_duty_constraints(
    g: ConstraintList,
    duty: DutyRequirement,
    design: DesignQuantities,
    demands: list[tuple[np.ndarray, np.ndarray, np.ndarray]],
    technology: ActuatorTechnology,
    joint_names: tuple[str, ...],
) -> None:
    """Add each gearbox's ratings over the cycle to ``g``: peak, RMS and input speed.

    Per joint with a gearbox: the peak rows ``demands`` (:func:`peak_rows`, safety factor included) within its
    repeated peak torque, the RMS demand within its rated torque (no safety factor, as the motor's), and the
    motor speed over the cycle and the approach within its maximum input speed where the catalogue gives one.
    Rows are divided by the rating, so their margins read as fractions of it.
    """
    figures = technology.gearbox_figures(len(joint_names))
    gear, velocity = design.values["gear_ratio"], design.values["approach_velocity"][0]
    for j, name in enumerate(joint_names):
        if not figures.names[j]:
            continue
        label = f"gearbox {figures.names[j]} of {name}"
        x_j = ca.vertcat(1.0, design.actuator_mass, design.reflected_inertia[j])
        rows, index, sign = demands[j]
        states = duty.torques.labels
        g.add(
            1.0 - ca.mtimes(ca.DM(rows), x_j) / figures.peak_torque[j],
            0.0,
            np.inf,
            [
                f"{label}: repeated peak rating {figures.peak_torque[j]:.4g} N*m >= "
                f"{'+' if s > 0 else '-'}{duty.safety_factor:g} x demand at {states[i]}"
                for i, s in zip(index, sign, strict=True)
            ],
        )
        if duty.torques.timed:
            g.add(
                ca.bilin(ca.DM(duty.torques.rms_form(j)), x_j, x_j) / figures.rated_torque[j] ** 2,
                -np.inf,
                1.0,
                [f"{label}: RMS output over the cycle <= rated {figures.rated_torque[j]:.4g} N*m"],
            )
        limit = figures.max_input_speed[j]
        for rate, over, speed in (
            (duty.cycle_speed[j], "the motion", 1.0),
            (duty.approach_rate[j], "the approach", velocity),
        ):
            if np.isfinite(limit) and rate > 0:
                g.add(
                    ca.log(gear[j] * speed * rate / limit),
                    -np.inf,
                    0.0,
                    [f"{label}: input speed over {over} <= its maximum {limit:.4g} rad/s"],
                )


def duty_values(duty: DutyRequirement, design: Design, technology: ActuatorTechnology) -> DutyValues:
    """A design's requirements and capacities over the cycle (NumPy; see :class:`DutyValues`)."""
    joint = technology.joint_quantities(design.stator_diameter, design.stack_length, design.gear_ratio)
    demand = duty.demand(design.actuator_mass, design.reflected_inertia).T  # (nv, n)
    return DutyValues(
        required_torque=duty.safety_factor * np.abs(demand).max(axis=1),
        required_rms_torque=np.sqrt((demand**2) @ duty.torques.weights),
        continuous_torque=np.asarray(joint.driving_continuous_torque, dtype=float),
        max_motor_speed=design.gear_ratio * duty.joint_speed(design.approach_velocity),
        speed_limit=np.asarray(joint.motor.max_speed, dtype=float) * np.ones(design.gear_ratio.size),
    )


def torque_speed_points(problem: DesignProblem, design: Design) -> tuple[TorqueSpeedPoints, ...]:
    """Per joint, the motor-side (speed [rad/s], torque [N m]) points of the cycle and the approach's speeds.

    For a torque-speed figure over the motor's envelope (peak and continuous torque, maximum speed). Needs a
    problem built with a duty cycle.
    """
    duty = problem.duty
    if duty is None:
        raise InvalidParameter(
            "problem", "built without a duty cycle", "a problem with Constraints(duty_cycle=...)"
        )
    gear = design.gear_ratio
    demand = duty.demand(design.actuator_mass, design.reflected_inertia)
    approach = design.approach_velocity * duty.approach_rates * gear
    ratio = design.gearbox_efficiency * gear  # output torque per motor torque
    return tuple(
        TorqueSpeedPoints(gear[j] * duty.torques.qd[:, j], demand[:, j] / ratio[j], approach[:, j])
        for j in range(duty.torques.nv)
    )


def check_reachable(
    duty: DutyRequirement,
    layout: DesignLayout,
    technology: ActuatorTechnology,
    mass_low: np.ndarray,
    mass_high: np.ndarray,
    joint_names: tuple[str, ...],
) -> None:
    """Refuse a requirement no design within the bounds can meet, naming the joint, the constraint and its best margin.

    Per joint its own motor size and gear ratio go over a grid within their bounds (the gear ratio on 241
    log-spaced values, the diameter on 41, the stack length on 9 when free, the bounds included), and the
    other motors' masses are taken at their most favourable within ``[mass_low, mass_high]`` [kg] separately at
    every sample: the margins found are upper bounds of the reachable ones, so a requirement refused here
    cannot be met. The approach speed is taken at the lowest approach velocity allowed. Refused when the best
    margin is below ``-REACHABLE_TOLERANCE``: one constraint alone (the gearbox's ratings among them), or all
    of them together.

    Raises
    ------
    InvalidParameter: a requirement that cannot be met; the message names the joint, the constraint and the
        best margin reachable.
    """
    bounds = layout.bounds
    velocity = bounds["approach_velocity"][0].lower
    speed_need = duty.joint_speed(velocity)
    weights = duty.torques.weights
    n_joints = len(joint_names)
    figures, motors = technology.gearbox_figures(n_joints), technology.joint_motors(n_joints)
    for j, name in enumerate(joint_names):
        basis = duty.torques.demand_basis(j)
        slopes = basis[:, 1:-1]
        low = basis[:, 0] + np.minimum(slopes * mass_low, slopes * mass_high).sum(axis=1)
        high = basis[:, 0] + np.maximum(slopes * mass_low, slopes * mass_high).sum(axis=1)
        demand = (low, high, basis[:, -1])
        key = _digest(
            *demand,
            weights,
            duty.safety_factor,
            float(speed_need[j]),
            motors[j],
            technology.scaling_law,
            *(float(getattr(figures, field)[j]) for field in _GEARBOX_FIELDS),
            *(bounds[variable][j] for variable in ("gear_ratio", "stator_diameter", "stack_length")),
        )
        best = _BEST_MARGINS.get(
            key,
            functools.partial(
                _best_margins, duty, technology, bounds, j, demand, weights, float(speed_need[j])
            ),
        )
        gearbox = figures.names[j]
        labels = (PEAK, RMS, SPEED, *(f"gearbox {gearbox} {rating}" for rating in GEARBOX_RATINGS))
        what = " and ".join(dict.fromkeys(duty.torques.sources))
        # The gearbox's ratings first: no bound of the study moves them (another gearbox must be chosen).
        for label, value in sorted(
            zip(labels, best[:-1], strict=True), key=lambda p: not p[0].startswith("gearbox")
        ):
            if value < -REACHABLE_TOLERANCE:
                _refuse(what, name, label, value)
        if best[-1] < -REACHABLE_TOLERANCE:
            _refuse(what, name, " and ".join(labels[: 6 if gearbox else 3]) + " together", best[-1])


class _Memo:
    """Results of a pure computation by a digest of everything it reads (:func:`_digest`), the newest kept.

    The problems of one study (its objective's, the Pareto anchors', every active-set round's, every catalogue
    combination's) repeat the duty cycle's work (its reachability grids, its peak rows, its RNEA over the
    cycle) at every build, and a run builds many.
    """

    def __init__(self, size: int) -> None:
        self.size = size
        self.store: dict[bytes, Any] = {}

    def get(self, key: bytes, compute: Callable[[], T]) -> T:
        """The result kept under ``key``, else ``compute()`` kept under it."""
        if key not in self.store:
            self.store[key] = compute()
            while len(self.store) > self.size:
                del self.store[next(iter(self.store))]  # the oldest first
        return cast("T", self.store[key])


def _digest(*parts: object) -> bytes:
    """A digest of ``parts``: arrays by their values exactly, anything else by its ``repr``."""
    digest = hashlib.blake2b(digest_size=20)
    for part in parts:
        if isinstance(part, np.ndarray):
            digest.update(repr((part.shape, part.dtype.str)).encode())
            digest.update(np.ascontiguousarray(part).tobytes())
        else:
            digest.update(repr(part).encode())
        digest.update(b"\x00")
    return digest.digest()


_BEST_MARGINS = _Memo(256)
"""Each joint's best margins over its grid (:func:`_best_margins`)."""
_KEPT_ROWS = _Memo(256)
"""Each joint's peak rows (:func:`_joint_peak_rows`)."""
_CYCLE_TORQUES = _Memo(8)
"""An arm's torques over a cycle (:func:`collision_reflex.arm.dynamics.cycle_torques`: RNEA at every sample)."""
_GEARBOX_FIELDS = ("efficiency", "counted_inertia", "peak_torque", "rated_torque", "max_input_speed")
"""The gearbox figures :func:`_best_margins` reads."""


def _best_margins(
    duty: DutyRequirement,
    technology: ActuatorTechnology,
    bounds: dict,
    joint: int,
    demand: tuple[np.ndarray, np.ndarray, np.ndarray],
    weights: np.ndarray,
    joint_speed: float,
) -> np.ndarray:
    """Best margins of one joint over the grid of its own variables.

    They are: peak, RMS and speed, its gearbox's peak, rated torque and input speed (inf without one), all
    together.
    """

    def grid(name: str, count: int) -> np.ndarray:
        b = bounds[name][joint]
        return np.array([b.lower]) if b.is_fixed else np.geomspace(b.lower, b.upper, count)

    n_joints = len(bounds["gear_ratio"])
    reference = technology.joint_motors(n_joints)[joint]
    gearbox = technology.gearbox_figures(n_joints)
    efficiency, gearbox_inertia = gearbox.efficiency[joint], gearbox.counted_inertia[joint]
    gears = grid("gear_ratio", 241)[:, None]
    ratings = np.ones_like(gears[:, 0])
    low, high, acceleration = demand
    best = np.full(7, -np.inf)
    for length in grid("stack_length", 9):
        for diameter in grid("stator_diameter", 41):
            motor = scaled_motor_quantities(reference, diameter, length, technology.scaling_law)
            rotor = gears**2 * (motor.rotor_inertia + gearbox_inertia) * acceleration  # (gears, n)
            # The smallest |demand| at each sample over the other motors' masses (0 if the interval holds 0).
            least = np.maximum(0.0, np.maximum(low + rotor, -(high + rotor)))
            peak_need, rms_need = duty.safety_factor * least.max(axis=1), np.sqrt((least**2) @ weights)
            speed_need = gears[:, 0] * joint_speed
            margins = np.column_stack(
                [
                    margin(efficiency * gears[:, 0] * motor.peak_torque, peak_need),
                    margin(efficiency * gears[:, 0] * motor.continuous_torque, rms_need),
                    margin(motor.max_speed * ratings, speed_need),
                    margin(gearbox.peak_torque[joint] * ratings, peak_need),
                    margin(gearbox.rated_torque[joint] * ratings, rms_need),
                    margin(gearbox.max_input_speed[joint] * ratings, speed_need),
                ]
            )
            best[:-1] = np.maximum(best[:-1], margins.max(axis=0))
            best[-1] = max(best[-1], float(margins.min(axis=1).max()))
    return best


def margin(capacity: np.ndarray, need: np.ndarray) -> np.ndarray:
    """``capacity / need - 1`` [-] per joint, infinite where nothing is needed (a result record shows None)."""
    with np.errstate(divide="ignore"):
        return np.where(need > 0, capacity / np.where(need > 0, need, 1.0) - 1.0, np.inf)


def _refuse(what: str, joint: str, constraint: str, margin: float) -> None:
    """Refuse ``joint``'s ``constraint`` of the motion ``what`` (e.g. "duty cycle and braking")."""
    gearbox = constraint.startswith("gearbox")
    raise InvalidParameter(
        f"{what} requirement of {joint}",
        f"{constraint}: best margin reachable {margin:+.1%}",
        f"a design within the bounds that meets its {constraint} requirement",
        ("choose a gearbox of higher ratings, " if gearbox else "widen the motor-size or gear-ratio bounds, ")
        + "or ask for a gentler motion (slower, lighter payload, a longer stopping time)",
    )
