"""Snap a continuous optimum to catalogue parts: the best design built from motors one can buy.

A continuous optimum sizes each joint's motor freely ("a 41.7 mm motor at N = 200"). Here each joint gets a
catalogue motor instead (a joint's reference motor with its stator diameter and stack length fixed at its own,
so that its quantities are its datasheet figures), and the continuous variables that remain (gear ratio,
software stiffness, threshold, approach velocity) are re-optimised for that choice.

- **Candidates per joint**: among the catalogue motors within the design space's free motor bounds (stator
  diameter, and stack length where it is a design variable) whose peak torque at the largest allowed gear ratio
  covers the joint's required torque at the continuous optimum (and, with a duty cycle, whose continuous torque
  there covers the cycle's RMS torque and that state a maximum speed), the ``candidates`` nearest to the
  continuous optimum's motor in :func:`motor_distance` (log peak torque and log rotor inertia). A joint whose
  gearbox offers discrete ratios gets, per motor, the offered ratios bracketing the continuous one as fixed gear
  ratios (those that give the motor the continuous peak output torque); a gearbox given by its own figures is replaced by the nearest catalogue gearboxes of its kind
  (:func:`gearbox_options`). A joint with no candidate is reported ("no catalogue part within bounds") with the
  nearest motor and what it misses.
- **Exact** when the combinations of candidates number at most ``max_combinations``: every one is re-solved
  and the best feasible by the problem's objective is kept (for an impulse objective, the lightest within
  :data:`collision_reflex.optimize.pareto.RESOLUTION` of the least impulse: :meth:`_Search.best`).
- **Heuristic** beyond that: coordinate descent over joints from the nearest part of every joint; each pass
  tries, joint by joint, every other candidate of that joint with the rest held, and moves to any better
  design; it stops when a whole pass improves nothing. Its best is never worse than the nearest-part design
  (its start), and is chosen as the exact search's is; ``benchmarks/snap_gap.py`` measures its gap to
  enumeration.

Each combination is solved on all samples or on an active set of them by the sweep's rule (``active_set``,
:func:`collision_reflex.optimize.active_set.uses_active_set`), the first round on the continuous optimum's active
samples. Each re-solve on all samples starts from the continuous optimum's values with the gear ratios raised
to cover the parts' own torque requirements (:func:`covering_gear_ratios`), IPOPT warm-started from the
continuous optimum's multipliers (:func:`warm_start`), in fewer IPOPT iterations than a cold start from the
matched gear ratios. A combination may have more than one local optimum (the warm and the cold start may reach
different ones, either of them the better); which one is found depends on its start, so the start is the same
for every combination (never another combination's solution: the result does not depend on the order of the
search), and the best combination is re-solved cold as well, from the matched gear ratios, keeping the better
(:meth:`_Search.confirm`). On an active set every re-solve is cold from the matched gear ratios (the continuous
optimum's multipliers are its subset's).

The objective is the problem's own, without the objective bounds of an epsilon-constraint point: a Pareto design
snapped is the study objective's best design of those parts. A catalogue design is the continuous problem with
more constraints, so it is never better than the (global) continuous optimum in the optimised objective; a
continuous optimum that is only local can be beaten.
"""

from __future__ import annotations

import functools
import itertools
import math
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, Any

import numpy as np

from .._interrupt import interruptible
from ..errors import InvalidParameter, SolverFailed
from ..hardware.gearboxes import ScaledGearbox
from .active_set import (
    ACTIVE_SET_CHOICES,
    ActiveSetResult,
    kept_problem,
    solve_active_set,
    uses_active_set,
)
from .objectives import IMPULSE_OBJECTIVES, objective_expression, objective_values
from .solve import Design, DesignResult, IpoptOptions, solve, warm_start
from .space import Bounds, module_envelope

if TYPE_CHECKING:
    from ..arm.robot import Arm
    from ..hardware.gearboxes import CatalogueGearbox
    from ..hardware.motors import Motor
    from .problem import DesignProblem
    from .samples import ContactSamples
    from .technology import ActuatorTechnology

__all__ = [
    "DEFAULT_CANDIDATES",
    "DEFAULT_GEARBOX_CANDIDATES",
    "DEFAULT_MAX_COMBINATIONS",
    "CatalogueDesign",
    "CataloguePart",
    "JointCandidates",
    "PartsEvaluation",
    "PartsSolver",
    "Trial",
    "catalogue_problem",
    "covering_gear_ratios",
    "evaluate_parts",
    "gearbox_options",
    "joint_candidates",
    "matched_gear_ratio",
    "motor_distance",
    "objective_value",
    "quick_parts",
    "snap_to_catalogue",
    "solve_parts",
    "solved_or_status",
    "warm_start",
]

PartsSolver = Callable[..., list["DesignResult | str"]]
"""``solve_many(combinations, warm=True)``: each combination (one part per joint) re-optimised, in any order or
place (an executor's workers), as its :class:`DesignResult`, or the status that says why it has none (IPOPT's,
or ``"refused: ..."`` for a problem refused before solving); ``warm``: as :func:`solve_parts` says. Default:
:func:`solve_parts` in this process."""

DEFAULT_CANDIDATES = 3
"""Catalogue motors considered per joint by default."""
DEFAULT_GEARBOX_CANDIDATES = 2
"""Catalogue gearboxes considered per joint by default, where the study gives a gearbox's own figures."""
DEFAULT_MAX_COMBINATIONS = 64
"""Largest number of combinations enumerated exactly by default; beyond it the heuristic runs."""
COVERAGE_MARGIN = 0.1
"""Relative margin of the catalogue's range: a continuous motor within 10 % beyond the catalogue's smallest or
largest stator diameter and peak torque counts as covered (its nearest part is then at most that far)."""
REQUIREMENT_PASSES = 4
"""Passes of :func:`evaluate_parts` raising the gear ratios to the requirement of the parts' own masses (it
changes little with the ratio: a few passes settle it)."""
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


@dataclass(frozen=True)
class Trial:
    """One combination tried: a part label per joint, its objective value (None: no feasible design) and status.

    The status is IPOPT's, or ``"refused: ..."`` when the problem of these parts was refused before solving;
    iterations: IPOPT's iterations of the design found (None without one).
    """

    parts: tuple[str, ...]
    objective: float | None
    status: str
    iterations: int | None = None


@dataclass(frozen=True)
class CatalogueDesign:
    """The best design built from catalogue parts, next to the continuous optimum it was snapped from.

    joints: per joint the candidates and catalogue coverage (:class:`JointCandidates`); parts: the chosen part
    per joint, None when no combination gave a feasible design; result: the re-optimised design (None with
    ``parts``); continuous: the continuous optimum; objectives, continuous_objectives: every objective of each
    [its unit] (NumPy path; empty without a result); difference: catalogue minus continuous [its unit];
    relative_difference: the same over the continuous value [-]; tried: every combination solved; method: how
    the answer was found (``"exact: enumerated 9 combinations"`` or ``"heuristic: ..."``); warnings: the
    joints' catalogue-coverage warnings and why no design was found, if none was.
    """

    joints: tuple[JointCandidates, ...]
    parts: tuple[CataloguePart, ...] | None
    result: DesignResult | None
    continuous: DesignResult
    objectives: dict[str, float]
    continuous_objectives: dict[str, float]
    difference: dict[str, float]
    relative_difference: dict[str, float]
    tried: tuple[Trial, ...]
    method: str
    warnings: tuple[str, ...] = field(default=())

    @property
    def found(self) -> bool:
        """Whether a feasible catalogue design was found."""
        return self.result is not None


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
        kept: list[CataloguePart] = []
        fitting = 0
        for m in ranked:
            if fitting == candidates:
                break
            if misses[m.name]:
                continue
            screened = [
                _screened_parts(
                    m,
                    space_ratios[j],
                    gearbox,
                    listed,
                    float(design.peak_torque[j]),
                    torque,
                    inertia,
                    required if screen else 0.0,
                    speed,
                )
                for gearbox, listed in options
            ]
            found = [part for fits, _ in screened for part in fits]
            if found:
                kept += found
                fitting += 1
            else:
                misses[m.name] = tuple(dict.fromkeys(why for _, whys in screened for why in whys))
        parts = tuple(kept)
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
            low, high = _ratio_range(ratio, other)
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


def _ratio_range(bounds: Bounds, gearbox: CatalogueGearbox | None) -> tuple[float, float]:
    """The gear-ratio bounds intersected with a gearbox's ratio range (empty when lower > upper)."""
    if gearbox is None:
        return bounds.lower, bounds.upper
    low, high = gearbox.ratio_range
    return max(bounds.lower, low), min(bounds.upper, high)


def _motor_list(motors: Mapping[str, Motor] | Sequence[Motor]) -> list[Motor]:
    """The catalogue as a list of motors (a mapping's values), refused when empty or not motors."""
    from ..hardware.motors import Motor

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
    motor the continuous optimum's peak output torque ``output_torque`` [N*m] (:func:`matched_gear_ratio`).
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
            return [
                CataloguePart(motor, Bounds.fixed(float(r), ratio.name), distance, gearbox, from_catalogue)
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


def snap_to_catalogue(
    problem: DesignProblem,
    optimum: DesignResult,
    motors: Mapping[str, Motor] | Sequence[Motor],
    *,
    arm: Arm,
    gearboxes: Mapping[str, CatalogueGearbox] | None = None,
    candidates: int = DEFAULT_CANDIDATES,
    gearbox_candidates: int = DEFAULT_GEARBOX_CANDIDATES,
    gearbox_kinds: Sequence[str] | None = None,
    max_combinations: int = DEFAULT_MAX_COMBINATIONS,
    ipopt_options: IpoptOptions | None = None,
    progress: Callable[[int, int], None] | None = None,
    solve_many: PartsSolver | None = None,
    active_set: str = "auto",
) -> CatalogueDesign:
    """The best design built from catalogue motors near ``optimum``, re-optimised (module docstring).

    Parameters
    ----------
    problem: the continuous design problem (:func:`collision_reflex.optimize.build_problem`); each combination
        is this problem with every joint's motor fixed at a catalogue motor, its objective and constraints.
    optimum: the continuous optimum of ``problem`` (:func:`collision_reflex.optimize.solve`).
    motors: the catalogue motors (e.g. :func:`collision_reflex.load_catalogue`), by name or as a sequence.
    arm: the arm ``problem`` was built for (each combination's problem is built for it).
    gearboxes: the gearbox catalogue by name (e.g. :func:`collision_reflex.hardware.gearboxes.
        load_gearbox_catalogue`), for joints whose gearbox is the study's own figures; None keeps every joint's
        gearbox (see :func:`joint_candidates`).
    candidates: motors considered per joint (>= 1), the nearest first.
    gearbox_candidates: catalogue gearboxes considered per joint with the study's own gearbox figures (>= 1),
        of each kind in ``gearbox_kinds``.
    gearbox_kinds: the gearbox kinds such a joint may take in the catalogue design (a transmission is a design
        choice: strain-wave, planetary, ...); None: the kind of its own gearbox.
    max_combinations: the most combinations enumerated exactly (>= 1); beyond, the heuristic runs.
    ipopt_options: options of every re-solve (see :func:`collision_reflex.optimize.solve`).
    progress: called as ``progress(done, total)`` after each batch of combinations solved.
    solve_many: how combinations are solved (:data:`PartsSolver`), e.g. through an executor; default in this
        process. The combinations of a batch (every one when enumerating; a joint's candidates in a step of the
        heuristic) are independent, and the answer does not depend on where they run.
    active_set: how the default ``solve_many`` solves each combination's samples (:func:`solve_parts`): on an
        active set from :data:`collision_reflex.optimize.active_set.ACTIVE_SET_THRESHOLD` samples (``"auto"``,
        the sweep's rule), always or never; a given ``solve_many`` decides for itself.

    Raises
    ------
    InvalidParameter: an empty catalogue, ``candidates`` or ``max_combinations`` not an integer >= 1, an
        ``active_set`` not one of :data:`collision_reflex.optimize.active_set.ACTIVE_SET_CHOICES`.
    KeyboardInterrupt: Ctrl-C, from any re-solve (nothing is returned).
    """
    if not isinstance(max_combinations, int) or isinstance(max_combinations, bool) or max_combinations < 1:
        raise InvalidParameter("max_combinations", max_combinations, "an integer >= 1")
    if active_set not in ACTIVE_SET_CHOICES:
        raise InvalidParameter("active_set", active_set, "one of " + ", ".join(map(repr, ACTIVE_SET_CHOICES)))
    joints = joint_candidates(
        problem, optimum, motors, candidates, gearboxes, gearbox_candidates, gearbox_kinds=gearbox_kinds
    )
    warnings = [j.warning for j in joints if j.warning]
    empty = [j for j in joints if not j.parts]
    if empty:
        reasons = [
            f"{j.joint}: no catalogue part within bounds; the nearest, {j.nearest}, misses: "
            + "; ".join(j.misses)
            for j in empty
        ]
        return _design(joints, None, None, optimum, (), "none: " + " / ".join(reasons), [*warnings, *reasons])
    if solve_many is None:
        solve_many = _InProcess(problem, optimum, arm, ipopt_options, active_set)
    owner = problem.space.module_of(problem.n_joints)
    search = _Search(problem, optimum.design, [j.parts for j in joints], solve_many, progress, owner)
    total = math.prod(len(j.parts) for k, j in enumerate(joints) if owner[k] == k)
    if total <= max_combinations:
        search.total = total
        search.values_of(search.tied(itertools.product(*(range(len(j.parts)) for j in joints))))
        method = f"exact: enumerated {total} combinations"
    else:
        passes = search.descend()
        method = (
            f"heuristic: coordinate descent over joints from the nearest parts, {len(search.tried)} of {total} "
            f"combinations solved in {passes} passes (more than max_combinations = {max_combinations})"
        )
    best, least = search.best(), search.least()
    if best is not None and _warm_startable(problem, optimum, active_set):
        search.confirm(best)
    if best != least:
        from .recommend import RESOLUTION

        assert best is not None and least is not None  # best is least without a feasible combination
        name = str(_impulse_objective(problem)).replace("_", " ")
        masses = [search.results[c].numpy_objectives["actuator_mass"] for c in (best, least)]
        method += (
            f"; the lightest combination within {100 * RESOLUTION:g} % of the least {name} "
            f"({masses[0]:.4g} kg of actuators against {masses[1]:.4g} kg)"
        )
    if best is None:
        reason = "no combination of candidates gives a feasible design (every re-solve failed)"
        return _design(joints, None, None, optimum, search.trials(), method, [*warnings, reason])
    parts = tuple(j.parts[c] for j, c in zip(joints, best, strict=True))
    return _design(joints, parts, search.results[best], optimum, search.trials(), method, warnings)


def _design(
    joints: tuple[JointCandidates, ...],
    parts: tuple[CataloguePart, ...] | None,
    result: DesignResult | None,
    optimum: DesignResult,
    tried: tuple[Trial, ...],
    method: str,
    warnings: list[str],
) -> CatalogueDesign:
    """The :class:`CatalogueDesign` with its objectives compared to the continuous optimum's."""
    continuous = dict(optimum.numpy_objectives)
    mine = dict(result.numpy_objectives) if result is not None else {}
    difference = {name: mine[name] - continuous[name] for name in mine}
    relative = {
        name: difference[name] / continuous[name] if continuous[name] != 0 else math.inf for name in mine
    }
    return CatalogueDesign(
        joints, parts, result, optimum, mine, continuous, difference, relative, tried, method, tuple(warnings)
    )


@dataclass(frozen=True)
class _InProcess:
    """The default :data:`PartsSolver`: :func:`solve_parts` for each combination, here, one after the other."""

    problem: DesignProblem
    optimum: DesignResult
    arm: Arm
    ipopt_options: IpoptOptions | None
    active_set: str = "auto"

    def __call__(
        self, combinations: Sequence[tuple[CataloguePart, ...]], warm: bool = True
    ) -> list[DesignResult | str]:
        return [
            solved_or_status(
                self.problem, self.optimum, parts, self.arm, self.ipopt_options, self.active_set, warm
            )
            for parts in combinations
        ]


def solved_or_status(
    problem: DesignProblem,
    optimum: DesignResult,
    parts: Sequence[CataloguePart],
    arm: Arm,
    ipopt_options: IpoptOptions | None = None,
    active_set: str = "auto",
    warm: bool = True,
) -> DesignResult | str:
    """:func:`solve_parts`, or the status that says why these parts have no design (see :data:`PartsSolver`)."""
    try:
        return solve_parts(problem, optimum, parts, arm, ipopt_options, active_set, warm)
    except SolverFailed as error:
        # What the parts miss at the ratios that cover their own masses says why, where anything does.
        shortfalls = evaluate_parts(problem, optimum.design, parts).shortfalls
        return error.status + (f" ({'; '.join(shortfalls)})" if shortfalls else "")
    except InvalidParameter as error:  # refused before solving: no design of these parts can meet it
        return f"refused: {error}"


class _Search:
    """Solves combinations of candidate parts (by index per joint) once each, and keeps their values."""

    def __init__(
        self,
        problem: DesignProblem,
        design: Design,
        parts: list[tuple[CataloguePart, ...]],
        solve_many: PartsSolver,
        progress: Callable[[int, int], None] | None,
        owner: Sequence[int] | None = None,
    ) -> None:
        self.problem, self.design, self.parts = problem, design, parts
        self.solve_many, self.progress = solve_many, progress
        # Per joint the joint whose part it takes (a module's first joint): combinations keep modules whole.
        self.owner = list(range(len(parts))) if owner is None else list(owner)
        self.values: dict[tuple[int, ...], float] = {}
        self.results: dict[tuple[int, ...], DesignResult] = {}
        self.tried: dict[tuple[int, ...], Trial] = {}
        self.total = 0

    def tied(self, combinations: Iterable[Sequence[int]]) -> list[tuple[int, ...]]:
        """The distinct ``combinations`` with every module's joints at its first joint's part."""
        return list(dict.fromkeys(tuple(c[o] for o in self.owner) for c in combinations))

    def values_of(self, combinations: list[tuple[int, ...]]) -> list[float]:
        """The problem's objective of each combination re-optimised (inf: no feasible design); new ones solved."""
        new = [c for c in dict.fromkeys(combinations) if c not in self.values]
        chosen = [tuple(self.parts[j][i] for j, i in enumerate(c)) for c in new]
        for combination, parts, solved in zip(new, chosen, self.solve_many(chosen), strict=True):
            labels = tuple(p.label for p in parts)
            if isinstance(solved, str):
                self.values[combination] = math.inf
                self.tried[combination] = Trial(labels, None, solved)
            else:
                value = objective_value(self.problem, solved.numpy_objectives)
                self.values[combination], self.results[combination] = value, solved
                self.tried[combination] = Trial(labels, value, solved.status, solved.iterations)
        if new and self.progress is not None:
            self.progress(len(self.tried), max(self.total, len(self.tried)))
        return [self.values[c] for c in combinations]

    def confirm(self, combination: tuple[int, ...]) -> None:
        """Solve ``combination`` again from the continuous optimum's values alone (cold) and keep the better.

        The warm start may lead a combination to another of its local optima than the cold start from the same
        values does, either of them the better; the chosen parts' design is then never worse than the cold
        start's.
        """
        parts = tuple(self.parts[j][i] for j, i in enumerate(combination))
        (solved,) = self.solve_many([parts], warm=False)
        if isinstance(solved, str):
            return
        value = objective_value(self.problem, solved.numpy_objectives)
        if value < self.values[combination]:
            self.values[combination], self.results[combination] = value, solved
            labels = tuple(p.label for p in parts)
            self.tried[combination] = Trial(labels, value, solved.status, solved.iterations)

    def descend(self) -> int:
        """Coordinate descent from the nearest parts until a pass improves nothing; the number of passes.

        A step solves every candidate of one joint with the others held (one batch) and moves to the best, if
        it is better than the current design by more than :data:`collision_reflex.optimize.pareto.MERGE_TOLERANCE`
        (relative): a smaller difference is within what re-solving repeats, and chasing it costs whole passes of
        re-solves for nothing a design would show. The best combination tried is kept either way
        (:meth:`best`).
        """
        from .dominance import MERGE_TOLERANCE

        current = self.start()
        (value,) = self.values_of([current])
        passes, improved = 0, True
        while improved:
            improved, passes = False, passes + 1
            for j, joint_parts in enumerate(self.parts):
                if self.owner[j] != j:  # moved with its module's first joint
                    continue
                options = self.tied((*current[:j], c, *current[j + 1 :]) for c in range(len(joint_parts)))
                values = self.values_of(options)
                best = min(range(len(options)), key=lambda i: values[i])
                # From an infeasible design (inf) any feasible one is a move.
                if values[best] < value and (
                    math.isinf(value) or value - values[best] > MERGE_TOLERANCE * abs(value)
                ):
                    current, value, improved = options[best], values[best], True
        return passes

    def start(self) -> tuple[int, ...]:
        """The nearest parts, each joint that misses its own requirement moved to its nearest part that meets it.

        The requirement is of the chosen parts' masses (:func:`evaluate_parts`, no solve), which the continuous
        optimum's lighter ones understate: from a start where two joints miss theirs, no step of the descent,
        which changes one joint, reaches a feasible design.
        """
        current = [0] * len(self.parts)

        def misses(combination: list[int], j: int) -> bool:
            parts = [self.parts[k][i] for k, i in enumerate(combination)]
            prefixes = tuple(
                f"{name}:" for name, o in zip(self.problem.joint_names, self.owner, strict=True) if o == j
            )
            shortfalls = evaluate_parts(self.problem, self.design, parts).shortfalls
            return any(s.startswith(prefixes) for s in shortfalls)

        for _ in range(REQUIREMENT_PASSES):
            moved = False
            for j, joint_parts in enumerate(self.parts):
                if self.owner[j] != j or not misses(current, j):
                    continue
                for c in range(len(joint_parts)):
                    trial = list(self.tied([[*current[:j], c, *current[j + 1 :]]])[0])
                    if c != current[j] and not misses(trial, j):
                        current, moved = trial, True
                        break
            if not moved:
                break
        return tuple(current)

    def least(self) -> tuple[int, ...] | None:
        """The feasible combination of least value (the first tried among equals), or None."""
        feasible = [c for c in self.tried if math.isfinite(self.values[c])]
        return min(feasible, key=lambda c: self.values[c]) if feasible else None

    def best(self) -> tuple[int, ...] | None:
        """The combination chosen: :meth:`least`, or the lightest alike in an impulse objective.

        For an impulse objective alone, the lightest combination within
        :data:`collision_reflex.optimize.pareto.RESOLUTION` of the least impulse, as a run recommends a continuous
        design (:func:`collision_reflex.optimize.pareto.recommend`): a smaller difference ranks no design, and
        the lighter is the better build.
        """
        from .recommend import lightest_alike

        least = self.least()
        name = _impulse_objective(self.problem)
        if least is None or name is None:
            return least
        feasible = [c for c in self.tried if math.isfinite(self.values[c])]
        return lightest_alike(feasible, lambda c: self.results[c].numpy_objectives, name, least)

    def trials(self) -> tuple[Trial, ...]:
        """Every combination tried, in the order tried."""
        return tuple(self.tried.values())


def _impulse_objective(problem: DesignProblem | None) -> str | None:
    """The name of ``problem``'s objective when it is one impulse objective alone, else None."""
    names = [] if problem is None else list(problem.objective)
    return names[0] if len(names) == 1 and names[0] in IMPULSE_OBJECTIVES else None


def objective_value(problem: DesignProblem, objectives: Mapping[str, float]) -> float:
    """``problem``'s objective for a design's objective values [their units]: the NLP's, at its scale.

    The weighted, start-normalised objectives with the tie-break term, scaled as ``problem`` scales them, so
    that designs of different (catalogue) problems compare on one scale.
    """
    values: dict[str, Any] = dict(objectives)  # plain numbers: the formula is backend-agnostic arithmetic
    return float(objective_expression(problem.objective, values, problem.objective_scale))


def catalogue_problem(
    problem: DesignProblem,
    parts: Sequence[CataloguePart],
    arm: Arm,
    samples: ContactSamples | None = None,
) -> DesignProblem:
    """``problem`` with each joint's motor the catalogue motor of ``parts`` at its own size.

    Each joint's stator diameter and stack length are fixed at its part's, its gear ratio within the part's
    bounds; the objective, constraints and the other bounds are ``problem``'s, and so are the samples unless
    ``samples`` are given (a subset of them, for an active-set round).
    """
    from .problem import build_problem

    technology = _parts_technology(problem, parts)
    space = replace(
        problem.space,
        stator_diameter=[p.motor.stator_diameter for p in parts],
        stack_length=[p.motor.stack_length for p in parts],
        gear_ratio=[p.gear_ratio for p in parts],
    )
    return build_problem(
        arm,
        problem.samples if samples is None else samples,
        space,
        technology,
        problem.objective,
        problem.constraints,
        problem.bounded_objectives,
    )


def quick_parts(joints: Sequence[JointCandidates], design: Design) -> tuple[CataloguePart, ...] | None:
    """Each joint's nearest part for a quick snap, None when a joint has none.

    The nearest motor's, and of its offered gear ratios (a gearbox of discrete ratios) the smallest that keeps
    ``design``'s peak output torque, else the largest.
    """
    chosen = []
    for j, joint in enumerate(joints):
        if not joint.parts:
            return None
        motor = joint.parts[0].motor
        own = [p for p in joint.parts if p.motor is motor]
        wanted = float(design.peak_torque[j]) / motor.peak_torque * (1 - BOUND_TOLERANCE)
        chosen.append(
            next((p for p in own if not p.gear_ratio.is_fixed or p.gear_ratio.lower >= wanted), own[-1])
        )
    return tuple(chosen)


def _parts_technology(problem: DesignProblem, parts: Sequence[CataloguePart]) -> ActuatorTechnology:
    """``problem``'s technology with each joint's motor (and gearbox) the one of ``parts``."""
    chosen = tuple(p.gearbox for p in parts)
    return replace(
        problem.technology,
        reference_motor=tuple(p.motor for p in parts),
        gearboxes=chosen if any(g is not None for g in chosen) else None,
    )


def matched_gear_ratio(part: CataloguePart, design: Design, joint: int) -> float:
    """The gear ratio that gives ``part``'s motor the continuous design's peak output torque, within its bounds.

    ``N = N_c tau_c / tau_p`` (``N_c tau_c`` the continuous joint's peak torque [N*m]), clipped to the part's
    gear-ratio bounds (within its gearbox's ratios): the catalogue design's start, and the ratio of a part
    evaluated without a re-solve.
    """
    wanted = float(design.peak_torque[joint]) / part.motor.peak_torque
    low, high = _ratio_range(part.gear_ratio, part.gearbox)
    return float(np.clip(wanted, low, high))


def _warm_startable(problem: DesignProblem, optimum: DesignResult, active_set: str) -> bool:
    """Whether a combination of parts is re-solved warm from ``optimum`` (:func:`solve_parts`).

    From a solution of ``problem`` itself with its multipliers: on all samples, ``optimum``'s own (a catalogue
    problem has the same samples, so the same auxiliaries); on active sets, those of ``optimum``'s last NLP
    (``last_round``), whose samples the combination's first round then holds.
    """
    if not uses_active_set(problem.samples.size, active_set):
        return optimum.multipliers is not None and optimum.x.size == problem.x0.size
    last = optimum.last_round if isinstance(optimum, ActiveSetResult) else None
    return (
        last is not None
        and last.multipliers is not None
        and optimum.impulses.size == problem.samples.size
        and optimum.x.size == problem.x0.size
    )


def _warm_round(
    problem: DesignProblem, optimum: ActiveSetResult, parts: Sequence[CataloguePart], arm: Arm, x0: np.ndarray
) -> ActiveSetResult:
    """``optimum`` as the warm start of ``parts``' active-set solve from ``x0`` (a point of the full problem).

    Its last NLP's point and multipliers are carried (:func:`warm_start`) to the parts' problem on the same
    samples (the solve's first round, :func:`_catalogue_on`), started at ``x0``'s design with those samples'
    auxiliaries at their exact values.
    """
    from .active_set import sample_subset

    subset = sample_subset(problem.samples, optimum.active_samples)
    solved_on = _subset_problem(problem, arm, subset)
    built = _catalogue_on(problem, parts, arm, subset)
    n_design = built.layout.size
    start = built.exact_point(np.concatenate([x0[:n_design], built.x0[n_design:]]))
    assert optimum.last_round is not None  # _warm_startable
    return replace(optimum, x=x0, last_round=warm_start(solved_on, built, optimum.last_round, start))


def _subset_problem(problem: DesignProblem, arm: Arm, subset: ContactSamples) -> DesignProblem:
    """``problem`` on the samples ``subset`` (its other inputs the same), built once per process and subset.

    The same for every combination of one snap: one build serves all of them.
    """
    from .problem import build_problem

    def build() -> DesignProblem:
        return build_problem(
            arm,
            subset,
            problem.space,
            problem.technology,
            problem.objective,
            problem.constraints,
            problem.bounded_objectives,
        )

    return kept_problem(("continuous", id(problem)), subset, build, holds=problem)


def _catalogue_on(
    problem: DesignProblem, parts: Sequence[CataloguePart], arm: Arm, samples: ContactSamples
) -> DesignProblem:
    """:func:`catalogue_problem` on ``samples`` (an active set's round), built once per process.

    The warm start's first round (:func:`_warm_round`) is then the solve's own, not built twice.
    """
    key = ("catalogue", id(problem), *((p.label, p.gear_ratio.lower, p.gear_ratio.upper) for p in parts))
    return kept_problem(key, samples, lambda: catalogue_problem(problem, parts, arm, samples), holds=problem)


def _parts_start(
    problem: DesignProblem,
    optimum: DesignResult,
    parts: Sequence[CataloguePart],
    built: DesignProblem,
    raised: bool,
) -> np.ndarray:
    """The start of ``parts``' problem ``built``: ``optimum``'s values, gear ratios matched (or ``raised``).

    Clipped to ``built``'s bounds, the auxiliaries at their exact values; ``raised``: the gear ratios at
    :func:`covering_gear_ratios`, else at :func:`matched_gear_ratio`.
    """
    design = optimum.design
    gear = (
        covering_gear_ratios(problem, design, parts)
        if raised
        else np.array([matched_gear_ratio(p, design, j) for j, p in enumerate(parts)])
    )
    known: dict[str, np.ndarray] = {
        "gear_ratio": gear,
        "software_stiffness": design.software_stiffness,
        "threshold": np.array([design.threshold]),
        "approach_velocity": np.array([design.approach_velocity]),
    }
    start = built.x0.copy()
    for name, values in known.items():
        for i, b, value in zip(built.layout.slices[name], built.layout.bounds[name], values, strict=True):
            if i is not None:
                start[i] = math.log(min(max(float(value), b.lower), b.upper))
    return built.exact_point(start)


@interruptible()
def solve_parts(
    problem: DesignProblem,
    optimum: DesignResult,
    parts: Sequence[CataloguePart],
    arm: Arm,
    ipopt_options: IpoptOptions | None = None,
    active_set: str = "auto",
    warm: bool = True,
) -> DesignResult:
    """The design of ``parts`` with the remaining continuous variables re-optimised.

    Started from ``optimum``'s values of those variables (clipped to their bounds). ``warm`` (solved on all
    samples, ``optimum`` of ``problem`` itself): the gear ratios at :func:`covering_gear_ratios` (a start that
    meets the parts' torque requirements) and IPOPT warm-started from ``optimum``'s multipliers
    (:func:`warm_start`); otherwise cold, the gear ratios at :func:`matched_gear_ratio`. ``active_set`` (one of
    :data:`collision_reflex.optimize.active_set.ACTIVE_SET_CHOICES`) says whether the samples are solved on an
    active set, by the sweep's rule (:func:`collision_reflex.optimize.active_set.uses_active_set`); on an
    active set the first round holds ``optimum``'s last active samples when it has them (the samples that bound
    the continuous optimum, most likely those that bound a catalogue design near it).

    Raises
    ------
    SolverFailed: no design of these parts meets the constraints (or the solver did not converge).
    InvalidParameter: the problem of these parts is refused before solving (a duty-cycle requirement or a
        gearbox rating that no design within the bounds can meet).
    """
    built = catalogue_problem(problem, parts, arm)
    full = not uses_active_set(built.samples.size, active_set)
    warm = warm and _warm_startable(problem, optimum, active_set)
    x0 = _parts_start(problem, optimum, parts, built, raised=warm)
    if full:
        return solve(
            built, x0=warm_start(problem, built, optimum, x0) if warm else x0, ipopt_options=ipopt_options
        )
    initial = None
    if (
        isinstance(optimum, ActiveSetResult)
        and optimum.active_samples.size
        and optimum.impulses.size == built.samples.size
    ):
        initial = optimum.active_samples
    first: ActiveSetResult | None = None
    if warm and isinstance(optimum, ActiveSetResult):
        first = _warm_round(problem, optimum, parts, arm, x0)
    return solve_active_set(
        functools.partial(_catalogue_on, problem, parts, arm),
        built.samples,
        ipopt_options=ipopt_options,
        initial=initial,
        x0=x0,
        full=built,
        warm=first,
    )


@dataclass(frozen=True)
class PartsEvaluation:
    """A design of catalogue parts evaluated without a re-solve (the quick snap of every Pareto design).

    parts: the part per joint; design: the continuous design with each joint's motor replaced by its part's
    (see :func:`evaluate_parts` for the gear ratios); objectives: every objective [its unit] (NumPy path);
    required_torque: per joint [N*m]; shortfalls: the requirements it misses (peak torque, the gearbox's
    ratings, and with a duty cycle RMS torque and motor speed), empty when it meets them all.
    """

    parts: tuple[CataloguePart, ...]
    design: Design
    objectives: dict[str, float]
    required_torque: np.ndarray
    shortfalls: tuple[str, ...]

    @property
    def feasible(self) -> bool:
        """Whether the design meets every torque and speed requirement."""
        return not self.shortfalls


@interruptible()
def evaluate_parts(problem: DesignProblem, design: Design, parts: Sequence[CataloguePart]) -> PartsEvaluation:
    """``design`` with each joint's motor (and gearbox) the one of ``parts``, evaluated (no re-solve).

    The gear ratios are :func:`covering_gear_ratios`; software stiffness, threshold and approach
    velocity are ``design``'s. The actuator quantities come from the technology's one formula
    (:meth:`~collision_reflex.optimize.technology.ActuatorTechnology.joint_quantities`), the impulses from the
    NumPy path (:func:`collision_reflex.optimize.evaluate.evaluate_design`), the requirement from ``problem``'s
    own torque-requirement function (and duty cycle); gearbox ratings are checked as the problem's rows are.
    """
    from .duty import duty_values
    from .evaluate import evaluate_design

    parts = tuple(parts)
    technology = _parts_technology(problem, parts)
    gear = covering_gear_ratios(problem, design, parts)
    snapped = _parts_design(design, parts, technology, gear)
    figures = technology.gearbox_figures(len(parts))
    impulses = evaluate_design(problem, snapped)
    masses = snapped.actuator_mass
    required = _required_torque(problem, snapped)
    names = design.joint_names
    shortfalls = _below("peak torque", snapped.driving_peak_torque, "the required", required, names)
    shortfalls += _below("gearbox peak rating", figures.peak_torque, "the required", required, names)
    if problem.duty is not None:
        values = duty_values(problem.duty, snapped, technology)
        rms = values.required_rms_torque
        shortfalls += _below("continuous torque", values.continuous_torque, "the cycle's RMS", rms, names)
        shortfalls += _below("gearbox rated torque", figures.rated_torque, "the cycle's RMS", rms, names)
        speed = values.max_motor_speed
        shortfalls += _below(
            "motor speed limit", values.speed_limit, "the motor speed", speed, names, "rad/s"
        )
        shortfalls += _below(
            "gearbox input speed limit", figures.max_input_speed, "the motor speed", speed, names, "rad/s"
        )
    objectives = objective_values(impulses, masses.sum(), snapped.approach_velocity, problem.samples)
    return PartsEvaluation(parts, snapped, objectives, required, tuple(shortfalls))


def covering_gear_ratios(
    problem: DesignProblem, design: Design, parts: Sequence[CataloguePart]
) -> np.ndarray:
    """Each joint's gear ratio [-] for ``parts`` that covers the requirement of the parts' own masses.

    :func:`matched_gear_ratio`, raised (within the part's bounds) until the driving peak torque covers the
    peak requirement (and with a duty cycle the continuous torque covers the cycle's RMS) of the parts'
    masses and reflected inertias, the rest of the design ``design``'s (fixed ratios are kept).
    """
    from .duty import duty_values

    parts = tuple(parts)
    technology = _parts_technology(problem, parts)
    gear = np.array([matched_gear_ratio(p, design, j) for j, p in enumerate(parts)])
    ranges = np.array([_ratio_range(p.gear_ratio, p.gearbox) for p in parts])
    for _ in range(REQUIREMENT_PASSES):  # heavier parts need more torque: raise the ratio to cover it
        snapped = _parts_design(design, parts, technology, gear)
        required = _required_torque(problem, snapped)
        efficiency = snapped.gearbox_efficiency
        wanted = np.maximum(gear, required / (efficiency * snapped.motor_peak_torque))
        if problem.duty is not None:
            rms = duty_values(problem.duty, snapped, technology).required_rms_torque
            continuous = np.array([p.motor.continuous_torque for p in parts])
            wanted = np.maximum(wanted, rms / (efficiency * continuous))
        if all(p.gear_ratio.is_fixed for p in parts) or np.allclose(wanted, gear, rtol=BOUND_TOLERANCE):
            break
        gear = np.where(
            [p.gear_ratio.is_fixed for p in parts], gear, np.clip(wanted, ranges[:, 0], ranges[:, 1])
        )
    return gear


def _parts_design(
    design: Design, parts: tuple[CataloguePart, ...], technology: ActuatorTechnology, gear: np.ndarray
) -> Design:
    """``design`` with the motors (and gearboxes) of ``parts`` at gear ratios ``gear`` [-]."""
    diameter = np.array([p.motor.stator_diameter for p in parts])
    stack = np.array([p.motor.stack_length for p in parts])
    joint = technology.joint_quantities(diameter, stack, gear)
    return replace(
        design,
        stator_diameter=diameter,
        stack_length=stack,
        gear_ratio=gear,
        rotor_inertia=np.asarray(joint.motor.rotor_inertia, dtype=float),
        reflected_inertia=np.asarray(joint.reflected_inertia, dtype=float),
        motor_peak_torque=np.asarray(joint.motor.peak_torque, dtype=float),
        peak_torque=np.asarray(joint.peak_torque, dtype=float),
        motor_mass=np.asarray(joint.motor.mass, dtype=float),
        gearbox=joint.gearbox.names,
        gearbox_mass=joint.gearbox.mass,
        gearbox_inertia=joint.gearbox.inertia,
        gearbox_efficiency=joint.gearbox.efficiency,
    )


def _required_torque(problem: DesignProblem, design: Design) -> np.ndarray:
    """Each joint's required peak torque [N*m] for ``design``'s masses (and reflected inertias, with a cycle)."""
    arguments = (
        (design.actuator_mass,) if problem.duty is None else (design.actuator_mass, design.reflected_inertia)
    )
    return np.asarray(problem.required_torque_function(*arguments), dtype=float).ravel()


def _below(
    capacity_name: str,
    capacity: np.ndarray,
    need_name: str,
    need: np.ndarray,
    joints: Sequence[str],
    unit: str = "N*m",
) -> list[str]:
    """``joint: <capacity> 1.2 N*m below <need> 1.5 N*m`` for every joint whose capacity is short of its need."""
    return [
        f"{joint}: {capacity_name} {capacity[j]:.4g} {unit} below {need_name} {need[j]:.4g} {unit}"
        for j, joint in enumerate(joints)
        if capacity[j] < need[j] * (1 - BOUND_TOLERANCE)
    ]
