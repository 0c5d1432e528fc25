"""Catalogue candidates per joint: the parts one can buy near a continuous optimum's sized motor.

Among the catalogue motors within the design space's free motor bounds (stator diameter, and stack length where
it is a design variable) whose peak torque at the largest allowed gear ratio covers the joint's required torque
at the continuous optimum (and, with a duty cycle, whose continuous torque there covers the cycle's RMS torque
and that state a maximum speed), a joint keeps the ``candidates`` nearest to the continuous optimum's motor in
:func:`motor_distance` (log peak torque and log rotor inertia). A joint whose gearbox offers discrete ratios
gets, per motor, the offered ratios bracketing the continuous one as fixed gear ratios (those that give the
motor the continuous peak output torque); a gearbox given by its own figures is replaced by the nearest
catalogue gearboxes of its kind (:func:`gearbox_options`). A joint with no candidate is reported ("no
catalogue part within bounds") with the nearest motor and what it misses.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

from ..errors import InvalidParameter
from ..hardware.gearboxes import ScaledGearbox
from ..hardware.motors import Motor
from .space import Bounds, module_envelope

if TYPE_CHECKING:
    from ..hardware.gearboxes import CatalogueGearbox
    from .design_result import DesignResult
    from .problem import DesignProblem

__all__ = [
    "BOUND_TOLERANCE",
    "DEFAULT_CANDIDATES",
    "DEFAULT_GEARBOX_CANDIDATES",
    "CataloguePart",
    "JointCandidates",
    "gearbox_options",
    "joint_candidates",
    "motor_distance",
]

DEFAULT_CANDIDATES = 3
"""Catalogue motors considered per joint by default."""
DEFAULT_GEARBOX_CANDIDATES = 2
"""Catalogue gearboxes considered per joint by default, where the study gives a gearbox's own figures."""
COVERAGE_MARGIN = 0.1
"""Relative margin of the catalogue's range: a continuous motor within 10 % beyond the catalogue's smallest or
largest stator diameter and peak torque counts as covered (its nearest part is then at most that far)."""
BOUND_TOLERANCE = 1e-6
"""Relative slack on the motor bounds and the torque screen: a part at a bound is within it, and IPOPT's
optimum may pass a bound by its relaxation (1e-8 relative)."""


def motor_distance(motor: Motor, peak_torque: float, rotor_inertia: float) -> float:
    """Distance of a catalogue motor from a sized one (peak torque [N*m], rotor inertia [kg*m^2]) [-].

    The Euclidean distance in (log peak torque, log rotor inertia): the two figures that, with the gear ratio,
    set a joint's output torque and reflected inertia. A factor of e in one of them is a distance of 1.
    """
    return math.hypot(
        math.log(motor.peak_torque / peak_torque), math.log(motor.rotor_inertia / rotor_inertia)
    )


@dataclass(frozen=True)
class CataloguePart:
    """One joint's catalogue choice: a motor, its gearbox (if the joint has one), and the gear-ratio bounds.

    motor: the catalogue motor; gear_ratio: the ratio's bounds for this part (fixed at an offered ratio when the
    gearbox offers discrete ratios); distance: the motor's :func:`motor_distance` from the continuous optimum's
    motor [-]; gearbox: the joint's gearbox, None without one; gearbox_from_catalogue: whether that gearbox is
    a catalogue part (False: the study's own figures, kept because no gearbox catalogue was given).
    """

    motor: Motor
    gear_ratio: Bounds
    distance: float
    gearbox: CatalogueGearbox | None = None
    gearbox_from_catalogue: bool = True

    @property
    def label(self) -> str:
        """The motor's name, with the gearbox and the fixed gear ratio where there are."""
        gearbox = "" if self.gearbox is None else f" + {self.gearbox.name}"
        fixed = f" at N = {self.gear_ratio.lower:g}" if self.gear_ratio.is_fixed else ""
        return f"{self.motor.name}{gearbox}{fixed}"

    @property
    def ratio_range(self) -> tuple[float, float]:
        """The part's gear-ratio bounds within its gearbox's ratios [-]."""
        return _ratio_range(self.gear_ratio, self.gearbox)


@dataclass(frozen=True)
class JointCandidates:
    """One joint's candidate parts, nearest first, and what the catalogue offers around its optimum.

    joint: the joint's name; parts: the candidates (empty: no catalogue part within bounds); nearest: the
    nearest catalogue motor of all, within bounds or not; misses: what ``nearest`` misses when ``parts`` is
    empty (which bound, by how much); warning: set when the continuous optimum's motor lies outside the range
    the catalogue covers (its nearest part is then far away).
    """

    joint: str
    parts: tuple[CataloguePart, ...]
    nearest: str | None
    misses: tuple[str, ...] = ()
    warning: str | None = None


def joint_candidates(
    problem: DesignProblem,
    optimum: DesignResult,
    motors: Mapping[str, Motor] | Sequence[Motor],
    candidates: int = DEFAULT_CANDIDATES,
    gearboxes: Mapping[str, CatalogueGearbox] | None = None,
    gearbox_candidates: int = DEFAULT_GEARBOX_CANDIDATES,
    screen: bool = True,
    gearbox_kinds: Sequence[str] | None = None,
) -> tuple[JointCandidates, ...]:
    """Each joint's candidate parts near the continuous ``optimum`` of ``problem`` (module docstring).

    Parameters
    ----------
    problem: the continuous design problem (its bounds, requirement and gearboxes).
    optimum: its solution.
    motors: the catalogue motors, by name or as a sequence.
    candidates: motors kept per joint (>= 1), nearest first.
    gearboxes: the gearbox catalogue by name; a joint whose gearbox is not one of its entries (the study's own
        figures) gets its ``gearbox_candidates`` nearest entries of the same kind (:func:`gearbox_options`).
        None: every joint keeps its gearbox.
    gearbox_candidates: catalogue gearboxes kept per such joint (>= 1).
    screen: keep only parts with a sold ratio at which the motor is both strong and fast enough for the joint
        (:func:`_screened_parts`); False: the nearest within bounds whatever they miss, for a quick snap that
        reports what they miss.
    gearbox_kinds: the kinds of catalogue gearbox a joint of the study's own (or scaled) gearbox may take (its
        ``gearbox_candidates`` nearest of each); None: its own kind.
    """
    catalogue = _motor_list(motors)
    for name, value in (("candidates", candidates), ("gearbox_candidates", gearbox_candidates)):
        if not isinstance(value, int) or isinstance(value, bool) or value < 1:
            raise InvalidParameter(name, value, "an integer >= 1")
    design = optimum.design
    bounds = problem.layout.bounds
    space_ratios = problem.space.per_joint("gear_ratio", problem.n_joints)
    joint_gearboxes = problem.technology.joint_gearboxes(problem.n_joints)
    owner = problem.space.module_of(problem.n_joints)
    joint_speeds = (  # a module's motor must turn as fast as its fastest joint
        None
        if problem.duty is None
        else module_envelope(problem.duty.joint_speed(float(design.approach_velocity)), owner)
    )
    out: list[JointCandidates] = []
    for j, joint in enumerate(problem.joint_names):
        if owner[j] != j:  # a module's joints share its first joint's part
            out.append(replace(out[owner[j]], joint=joint))
            continue
        torque, inertia = float(design.motor_peak_torque[j]), float(design.rotor_inertia[j])
        required = float(optimum.required_torque[j])
        gearbox = joint_gearboxes[j]
        if isinstance(gearbox, ScaledGearbox):  # its unit at the continuous optimum's size
            gearbox = gearbox.unit(float(design.peak_torque[j]))
        options, gearbox_misses = gearbox_options(
            gearbox, space_ratios[j], required, gearboxes, gearbox_candidates, gearbox_kinds
        )
        largest = max((_ratio_range(space_ratios[j], g)[1] for g, _ in options), default=0.0)
        ranked = sorted(catalogue, key=lambda m: motor_distance(m, torque, inertia))
        rms = None if optimum.required_rms_torque is None else float(optimum.required_rms_torque[j])
        misses = {
            m.name: _misses(m, j, bounds, required, rms, largest, problem.duty is not None) for m in ranked
        }
        speed = None if joint_speeds is None or not screen else float(joint_speeds[j])
        parts = _nearest_parts(
            ranked,
            misses,
            candidates,
            options,
            space_ratios[j],
            float(design.peak_torque[j]),
            torque,
            inertia,
            required if screen else 0.0,
            speed,
        )
        nearest = ranked[0].name
        out.append(
            JointCandidates(
                joint,
                parts,
                nearest,
                () if parts else gearbox_misses if not options else misses[nearest],
                _coverage_warning(joint, catalogue, float(design.stator_diameter[j]), torque),
            )
        )
    return tuple(out)


def _nearest_parts(
    ranked: list[Motor],
    misses: dict[str, tuple[str, ...]],
    count: int,
    options: list[tuple[CatalogueGearbox | None, bool]],
    ratio: Bounds,
    output_torque: float,
    torque: float,
    inertia: float,
    required: float,
    joint_speed: float | None,
) -> tuple[CataloguePart, ...]:
    """The parts of the ``count`` nearest motors of ``ranked`` that can do the joint's work, nearest first.

    A motor that ``misses`` something is passed over; one that no gearbox of ``options`` makes fit
    (:func:`_screened_parts`, with the other arguments) gets in ``misses`` why not (updated in place).
    """
    kept: list[CataloguePart] = []
    fitting = 0
    for m in ranked:
        if fitting == count:
            break
        if misses[m.name]:
            continue
        screened = [
            _screened_parts(m, ratio, gearbox, listed, output_torque, torque, inertia, required, joint_speed)
            for gearbox, listed in options
        ]
        found = [part for fits, _ in screened for part in fits]
        if found:
            kept += found
            fitting += 1
        else:
            misses[m.name] = tuple(dict.fromkeys(why for _, whys in screened for why in whys))
    return tuple(kept)


def gearbox_options(
    gearbox: CatalogueGearbox | None,
    ratio: Bounds,
    required: float,
    catalogue: Mapping[str, CatalogueGearbox] | None,
    count: int = DEFAULT_GEARBOX_CANDIDATES,
    kinds: Sequence[str] | None = None,
) -> tuple[list[tuple[CatalogueGearbox | None, bool]], tuple[str, ...]]:
    """A joint's gearbox options ``(gearbox, from the catalogue)``, and what the nearest misses if none fits.

    No gearbox: ``[(None, True)]``. A catalogue entry (its name in ``catalogue``, or no catalogue given): kept.
    The study's own figures with a catalogue given: of each of ``kinds`` (None: the gearbox's own kind), the
    ``count`` entries nearest to it in (log repeated peak torque, log mass) whose ratios overlap the joint's
    gear-ratio bounds ``ratio`` and whose repeated peak rating covers the joint's ``required`` torque [N*m].
    """
    if gearbox is None:
        return [(None, True)], ()
    if catalogue is None or gearbox.name in catalogue:
        return [(gearbox, catalogue is not None)], ()

    def distance(other: CatalogueGearbox) -> float:
        return math.hypot(
            math.log(other.peak_torque / gearbox.peak_torque), math.log(other.mass / gearbox.mass)
        )

    wanted = [gearbox.kind] if kinds is None else list(kinds)
    ranked = sorted((g for g in catalogue.values() if g.kind in wanted), key=distance)
    fitting: list[tuple[CatalogueGearbox | None, bool]] = []
    for kind in wanted:
        of_kind = []
        for other in (g for g in ranked if g.kind == kind):
            low, high = other.clip(ratio)
            if low <= high * (1 + BOUND_TOLERANCE) and other.peak_torque >= required * (1 - BOUND_TOLERANCE):
                of_kind.append((other, True))
        fitting += of_kind[:count]
    if fitting:
        return fitting, ()
    if not ranked:
        return [], (f"no {' or '.join(wanted)} gearbox in the gearbox catalogue",)
    nearest = ranked[0]
    low, high = nearest.ratio_range
    found = [f"nearest gearbox {nearest.name}:"]
    if max(low, ratio.lower) > min(high, ratio.upper):
        found.append(
            f"ratios {low:g} to {high:g} outside the gear-ratio bounds {ratio.lower:g} to {ratio.upper:g}"
        )
    if nearest.peak_torque < required:
        found.append(
            f"repeated peak rating {nearest.peak_torque:.4g} N*m short of the required {required:.4g} N*m by "
            f"{required - nearest.peak_torque:.3g} N*m"
        )
    return [], (" ".join(found),)


def _motor_list(motors: Mapping[str, Motor] | Sequence[Motor]) -> list[Motor]:
    """The catalogue as a list of motors (a mapping's values), refused when empty or not motors."""
    listed = list(motors.values()) if isinstance(motors, Mapping) else list(motors)
    if not listed or not all(isinstance(m, Motor) for m in listed):
        raise InvalidParameter("motors", motors, "a non-empty catalogue of Motors (a mapping or a sequence)")
    return listed


def _misses(
    motor: Motor,
    joint: int,
    bounds: Mapping[str, list[Bounds]],
    required: float,
    required_rms: float | None,
    largest_ratio: float,
    needs_speed: bool,
) -> tuple[str, ...]:
    """What keeps ``motor`` from joint ``joint``: a free motor bound, the torque screens, a missing speed.

    The screens: the peak torque at the largest gear ratio covers the ``required`` torque [N*m], and with a duty
    cycle the continuous torque there covers the cycle's RMS torque ``required_rms`` [N*m] (both of the
    continuous optimum; gearbox losses left to the re-solve).
    """
    found = []
    for name in ("stator_diameter", "stack_length"):
        b = bounds[name][joint]
        value = getattr(motor, name)
        if b.is_fixed:  # not a design variable: the catalogue motor brings its own size
            continue
        what = name.replace("_", " ")
        if value < b.lower * (1 - BOUND_TOLERANCE):
            found.append(
                f"{what} {value * 1e3:.4g} mm below the lower bound {b.lower * 1e3:.4g} mm by "
                f"{(b.lower - value) * 1e3:.3g} mm"
            )
        elif value > b.upper * (1 + BOUND_TOLERANCE):
            found.append(
                f"{what} {value * 1e3:.4g} mm above the upper bound {b.upper * 1e3:.4g} mm by "
                f"{(value - b.upper) * 1e3:.3g} mm"
            )
    reachable = motor.peak_torque * largest_ratio
    if reachable < required * (1 - BOUND_TOLERANCE):
        found.append(
            f"peak torque {motor.peak_torque:.4g} N*m x the largest gear ratio {largest_ratio:.4g} = "
            f"{reachable:.4g} N*m, short of the required {required:.4g} N*m by {required - reachable:.3g} N*m"
        )
    if required_rms is not None and motor.continuous_torque * largest_ratio < required_rms * (
        1 - BOUND_TOLERANCE
    ):
        reachable = motor.continuous_torque * largest_ratio
        found.append(
            f"continuous torque {motor.continuous_torque:.4g} N*m x the largest gear ratio {largest_ratio:.4g} = "
            f"{reachable:.4g} N*m, short of the cycle's RMS {required_rms:.4g} N*m by "
            f"{required_rms - reachable:.3g} N*m"
        )
    if needs_speed and motor.max_speed is None:
        found.append("no maximum speed in its catalogue entry (the duty cycle's speed limit needs one)")
    return tuple(found)


def _screened_parts(
    motor: Motor,
    ratio: Bounds,
    gearbox: CatalogueGearbox | None,
    from_catalogue: bool,
    output_torque: float,
    torque: float,
    inertia: float,
    required: float,
    joint_speed: float | None,
) -> tuple[list[CataloguePart], tuple[str, ...]]:
    """``motor``'s parts with ``gearbox`` that can meet the joint's own needs, and why none can if so.

    A part is the ratio bounds, or an offered ratio: of the offered ratios at which the motor's peak torque
    covers the ``required`` torque [N*m] and its maximum speed (and the gearbox's input speed) the joint's
    ``joint_speed`` [rad/s, None: no speed requirement], the two bracketing the matched ratio, which gives the
    motor the continuous optimum's peak output torque ``output_torque`` [N*m]
    (:func:`collision_reflex.optimize.parts.matched_gear_ratio`).
    A joint's need depends on the other joints' parts only through the masses they add, so a part that fails
    here fails in every combination, and the search starts from parts that can each do their own joint's work.
    ``ratio``: the joint's gear-ratio bounds of the design space; ``torque`` [N*m], ``inertia`` [kg*m^2]: the
    continuous motor's.
    """
    matched = output_torque / motor.peak_torque
    distance = motor_distance(motor, torque, inertia)
    low, high = _ratio_range(ratio, gearbox)
    fastest = math.inf
    if joint_speed is not None and joint_speed > 0:
        gearbox_speed = None if gearbox is None else gearbox.max_input_speed
        limits = [s for s in (motor.max_speed, gearbox_speed) if s is not None]
        fastest = min(limits, default=math.inf) / joint_speed  # the largest ratio fast enough
    slowest = required / motor.peak_torque  # the smallest ratio strong enough
    if gearbox is None or gearbox.continuous_ratio:
        if max(low, slowest) <= min(high, fastest) * (1 + BOUND_TOLERANCE):
            return [CataloguePart(motor, ratio, distance, gearbox, from_catalogue)], ()
        offered = []
    else:
        tolerance = (ratio.lower * (1 - BOUND_TOLERANCE), ratio.upper * (1 + BOUND_TOLERANCE))
        offered = [r for r in gearbox.ratios if tolerance[0] <= r <= tolerance[1]]
        fits = [
            r
            for r in offered
            if r >= slowest * (1 - BOUND_TOLERANCE) and r <= fastest * (1 + BOUND_TOLERANCE)
        ]
        if fits:
            below = [r for r in fits if r <= matched]
            above = [r for r in fits if r >= matched]
            bracket = sorted({*below[-1:], *above[:1]})
            return [  # the gearbox as sold at that ratio: its figures there, where they vary with the ratio
                CataloguePart(
                    motor, Bounds.fixed(float(r), ratio.name), distance, gearbox.at_ratio(r), from_catalogue
                )
                for r in bracket
            ], ()
    with_gearbox = "" if gearbox is None else f" with {gearbox.name}"
    if slowest > fastest:
        why = (
            f"{motor.name}{with_gearbox}: no gear ratio both strong and fast enough: its peak torque needs "
            f"N >= {slowest:.4g} for the required {required:.4g} N*m, its speed limit allows N <= "
            f"{fastest:.4g} at the joint's {joint_speed:.4g} rad/s"
        )
    else:
        why = (
            f"{motor.name}{with_gearbox}: needs a gear ratio from {slowest:.4g} to {min(fastest, 1e9):.4g} "
            f"(peak torque for the required {required:.4g} N*m, speed limit), offered "
            + (
                ", ".join(f"{r:g}" for r in offered)
                if offered
                else "none"
                if gearbox is not None and not gearbox.continuous_ratio
                else f"{low:g} to {high:g}"
            )
        )
    return [], (why,)


def _ratio_range(bounds: Bounds, gearbox: CatalogueGearbox | None) -> tuple[float, float]:
    """``bounds`` within ``gearbox``'s ratios (empty when lower > upper); all of ``bounds`` without a gearbox.

    The intersection is the gearbox's own (:meth:`~collision_reflex.hardware.gearboxes.CatalogueGearbox.clip`).
    """
    return (bounds.lower, bounds.upper) if gearbox is None else gearbox.clip(bounds)


def _coverage_warning(joint: str, catalogue: list[Motor], diameter: float, torque: float) -> str | None:
    """A warning when the continuous motor (stator diameter [m], peak torque [N*m]) is outside the catalogue."""
    diameters = [m.stator_diameter for m in catalogue]
    torques = [m.peak_torque for m in catalogue]
    outside = []
    low, high = 1 / (1 + COVERAGE_MARGIN), 1 + COVERAGE_MARGIN
    if not min(diameters) * low <= diameter <= max(diameters) * high:
        outside.append(
            f"stator diameter {diameter * 1e3:.4g} mm (catalogue {min(diameters) * 1e3:.4g}–"
            f"{max(diameters) * 1e3:.4g} mm)"
        )
    if not min(torques) * low <= torque <= max(torques) * high:
        outside.append(f"peak torque {torque:.4g} N*m (catalogue {min(torques):.4g}–{max(torques):.4g} N*m)")
    if not outside:
        return None
    return (
        f"{joint}: the continuous optimum lies outside the range the catalogue covers, "
        + " and ".join(outside)
        + ": the nearest part is far from it"
    )
