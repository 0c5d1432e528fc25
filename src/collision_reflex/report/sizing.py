"""What sizes an arm design and what its design bounds hold, in the verdict's words.

The requirement, the constraint active at each joint (what sizes it), the variables a bound holds rather than
the physics, the ones no objective decides, and the oversized joints. Every function reads a design record of
:func:`collision_reflex.optimize.results.design_record` and the study's bounds (plain data).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any, Literal

from ..record.design import DesignRecord, JointRecord
from ..record.run import Bounds
from ..vocabulary import GLOBAL_VARIABLES
from .wording import general, group_name, grouped, words

ACTIVE_TOLERANCE = 1e-3
"""Relative distance below which a design variable is at its bound, and a margin below which its constraint
is active (the solver's own tolerances are far smaller: a bound or constraint this close is what set the value)."""

OVERSIZED_MARGIN = 2.0
"""Peak-torque margin above which a joint is oversized (more than 3x its requirement) unless its motor is at its
smallest size."""

MARGINS: tuple[tuple[Literal["torque_margin", "rms_margin", "speed_margin"], str], ...] = (
    ("torque_margin", "peak torque"),
    ("rms_margin", "RMS torque"),
    ("speed_margin", "speed"),
)
"""Per-joint margins of a design record (``peak / required - 1``) and the constraint each belongs to; a margin
absent or ``None`` means the design has no such requirement."""

Position = Literal["lower", "upper", "fixed"] | None


def bound_position(value: float, bounds: Sequence[float]) -> Position:
    """Where ``value`` is in ``bounds`` ``[lower, upper]``.

    At a bound (``"lower"``, ``"upper"``: within :data:`ACTIVE_TOLERANCE`, relative to the bound), ``"fixed"``
    (lower == upper: not a design choice), or None (inside).
    """
    lower, upper = float(bounds[0]), float(bounds[1])
    if lower == upper:
        return "fixed"
    if abs(value - lower) <= ACTIVE_TOLERANCE * abs(lower):
        return "lower"
    if abs(value - upper) <= ACTIVE_TOLERANCE * abs(upper):
        return "upper"
    return None


def motor_at_smallest_size(joint: JointRecord, bounds: Bounds) -> bool:
    """Whether a joint's motor is at its smallest size.

    Stator diameter and stack length each at their lower bounds or fixed, and at least one of them a design
    variable.
    """
    name = joint["joint"]
    positions = [bound_position(joint[key], bounds[key][name]) for key in ("stator_diameter", "stack_length")]
    return all(p in ("lower", "fixed") for p in positions) and "lower" in positions


def smallest_motor_excess(
    joint: JointRecord, ratio_bounds: Sequence[float], multiple: float, chosen_ratio: bool = True
) -> str:
    """Why a joint at its smallest motor has ``multiple`` times its required peak torque, in words.

    The motor itself, or the gear ratio the objective chose: the peak torque grows with the ratio, which the
    collision reflex may want higher (a harder braking torque ``N tau_p``) than the motion needs.
    ``chosen_ratio`` False: no objective decides the ratio (:func:`bound_sentences` says so), so it is not
    called the objective's choice.
    """
    ratio, lowest = float(joint["gear_ratio"]), float(ratio_bounds[0])
    said = f"peak torque {general(multiple, 3)}× its requirement"
    if bound_position(ratio, ratio_bounds) in ("lower", "fixed"):
        return f"{said}: even the smallest motor is more than it needs"
    at_lowest = multiple * lowest / ratio
    lowest_said = f"{general(at_lowest, 3)}× at its lowest ratio, {general(lowest)}"
    if at_lowest > 1 + OVERSIZED_MARGIN:
        return (
            f"{said} at N = {general(ratio)} ({lowest_said}): even the smallest motor is more than it needs"
        )
    if not chosen_ratio:
        return f"{said} at N = {general(ratio)} ({lowest_said})"
    return (
        f"{said} at N = {general(ratio)}, the ratio the objective chose ({lowest_said}): the gear ratio, not the "
        "motor, gives the excess"
    )


UNDECIDED_UNITS = {"software_stiffness": " N·m/rad", "stator_diameter": " m", "stack_length": " m"}
"""Units printed after an undecided variable's value (none for the gear ratio)."""


def requirement_sentence(requirement: str, rating: Mapping[str, Any] | None = None) -> str:
    """What the torque requirement is, and what it leaves out; ``rating``: the resolved study's, if any."""
    hold = "the static hold of the arm and its payload at every sampled pose and at each joint's worst pose"
    if rating and requirement.startswith(("duty", "rated")):
        cycle = "the duty cycle (peak, RMS, speed), " if requirement.startswith("duty") else ""
        return (
            f"Requirement: per joint the largest of {cycle}the rated motion (each joint alone at its rated speed "
            f"and acceleration, and braking from that speed within its stopping time) and {hold}, with the rated "
            "payload; the sized-by column says which."
        )
    if requirement.startswith("static"):
        return (
            f"Requirement: {requirement}: {hold}. The motion's dynamics, RMS (thermal) torque and motor speed "
            "are not checked; give the study a duty cycle or a rating to size for them."
        )
    if requirement.startswith("duty"):
        return f"Requirement: per joint the larger of the {requirement} and {hold}; the sized-by column says which."
    return f"Requirement: {requirement}."


def sized_by_sentences(record: DesignRecord, requirement: str) -> list[str]:
    """What sizes each joint (or module): the requirement whose constraint is active, in one sentence."""

    def active(joint: JointRecord) -> str:
        said = []
        for key, constraint in MARGINS:
            margin = joint.get(key)
            if margin is None or margin >= ACTIVE_TOLERANCE:
                continue
            by = str(joint.get("required_by") or constraint) if key == "torque_margin" else constraint
            if key == "torque_margin" and joint.get("module") and " of " not in by:
                by = f"{by} of {joint['joint']}"  # a module's members all name the joint that sizes it
            said.append(by)
        return ", ".join(said)

    if all(joint.get("torque_margin") is None for joint in record["joints"]):
        return [
            f"No joint has a torque requirement ({requirement}): nothing but the impulse and the mass sizes "
            "the actuators; give the study a rating or a duty cycle."
        ]
    sized = [j for j in record["joints"] if active(j)]
    if not sized:
        return [f"No joint is at its torque, RMS or speed limit ({requirement}): every margin is positive."]
    return [f"Sized by ({requirement}): {grouped(sized, active)}."]


def bound_sentences(record: DesignRecord, bounds: Bounds) -> list[str]:
    """What the study's design bounds decide, and what no objective decides: a sentence each."""
    undecided = list(record.get("undecided", ()))
    held: dict[str, list[str]] = {}  # what holds a variable -> the joints it holds, in joint order
    for joint in record["joints"]:
        name = joint["joint"]
        chosen = not any(e["joint"] == name and e["variable"] == "gear_ratio" for e in undecided)
        if motor_at_smallest_size(joint, bounds):
            margin = joint.get("torque_margin")
            excess = (
                f" ({smallest_motor_excess(joint, bounds['gear_ratio'][name], 1 + margin, chosen)})"
                if margin is not None and margin > OVERSIZED_MARGIN
                else ""
            )
            held.setdefault(f"motor at its smallest size{excess}", []).append(name)
        for key in ("gear_ratio", "software_stiffness"):
            if any(e["joint"] == name and e["variable"] == key for e in undecided):
                continue
            position = bound_position(joint[key], bounds[key][name])
            if position in ("lower", "upper"):  # the bound it sits on, not the solver's last digits
                bound = bounds[key][name][0 if position == "lower" else 1]
                value = f"{general(bound)}{UNDECIDED_UNITS.get(key, '')}"
                held.setdefault(f"{words(key)} at its {position} bound ({value})", []).append(name)
    phrases = design_limits_at_bound(record, bounds) + [
        f"{group_name(names)} {what}" for what, names in held.items()
    ]
    lines = []
    if phrases:
        lines.append(
            "Held by the design bounds, not the physics (widen them to see where the design settles): "
            + "; ".join(phrases)
            + "."
        )
    if undecided:
        free = ", ".join(
            f"{e['joint']} {words(e['variable'])}" if e["joint"] else words(e["variable"]) for e in undecided
        )
        lines.append(
            f"No objective decides {free} anywhere within the bounds (no contact sample loads it): it is where "
            "the solver started; choose it on grounds this study does not model."
        )
    return lines


def design_limits_at_bound(record: DesignRecord, bounds: Bounds) -> list[str]:
    """The threshold and approach velocity where a bound holds them (undecided ones are said elsewhere)."""
    undecided = {entry["variable"] for entry in record.get("undecided", ()) if entry["joint"] is None}
    units = {"threshold": " N" if record.get("sensing") == "force" else " m", "approach_velocity": " m/s"}
    return [
        f"{words(key)} at its {position} bound ({general(bounds[key][0 if position == 'lower' else 1])}{units[key]})"
        for key in GLOBAL_VARIABLES
        if key not in undecided
        and (position := bound_position(record[key], bounds[key])) in ("lower", "upper")
    ]


def oversized_warnings(record: DesignRecord, bounds: Bounds) -> list[str]:
    """A warning for each oversized joint.

    Oversized: a peak-torque margin above :data:`OVERSIZED_MARGIN` while its motor could be smaller (not at its
    smallest size).
    """
    warnings = []
    for joint in record["joints"]:
        margin = joint.get("torque_margin")
        if margin is not None and margin > OVERSIZED_MARGIN and not motor_at_smallest_size(joint, bounds):
            warnings.append(
                f"Warning: {joint['joint']} delivers {general(1 + margin, 3)}× its required peak torque "
                f"({general(joint['peak_torque'])} vs {general(joint['required_torque'])} N·m) with a motor "
                "above its smallest size: nothing in the study sizes this actuator; check its requirement."
            )
    return warnings


__all__ = [
    "bound_position",
    "bound_sentences",
    "oversized_warnings",
    "requirement_sentence",
    "sized_by_sentences",
]
