"""The front and the transmission choice, in the verdict's words.

The front's ranges and spans, a plain sentence when it is flat or one design (and why an impulse objective is
flat), its lightest design near the best impulse, and the gearbox assignment the study's objective chose.
Every function reads the results of :func:`collision_reflex.study.arm_results.arm_results` (plain data).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any, cast

import numpy as np

from ..record.design import DesignRecord
from ..record.run import HumanContactRecord, ParetoRecord, TransmissionTried
from ..vocabulary import IMPULSE_OBJECTIVES
from .wording import general, group_name, objective_unit, percent, words

FLAT_SPAN = 1.0
"""Span [%] of an objective over the front below which the front is flat in it: no design choice that matters."""

NEAR_BEST = 0.05
"""How far above the best impulse (relative) a design may be for "the lightest design within 5 % of the best"."""


def objective_spans(points: Sequence[DesignRecord], objectives: Sequence[str]) -> dict[str, float]:
    """Each objective's span over ``points`` [%].

    That is (largest - smallest) / |best|, best the value the front optimises toward (the smallest, or the
    largest for a maximised objective).
    """
    from ..optimize import OBJECTIVES  # lazy: casadi

    spans = {}
    for name in objectives:
        values = [float(p["objectives"][name]) for p in points]
        best = min(values) if OBJECTIVES[name][0] > 0 else max(values)
        spans[name] = 100 * (max(values) - min(values)) / max(abs(best), 1e-300)
    return spans


def front_sentences(pareto: ParetoRecord) -> list[str]:
    """The front's ranges and spans, and a plain sentence when it is flat or degenerate.

    Flat: an objective spans less than :data:`FLAT_SPAN`; degenerate: one point (every repeat merged), or every
    objective flat.
    """
    points, names = pareto["points"], pareto["objectives"]
    if not points:
        return []
    if len(points) == 1:
        return [
            "One design on the front: "
            + " and ".join(words(n) for n in names)
            + " do not trade off within these bounds."
        ]
    spans = objective_spans(points, names)

    def ranged(name: str) -> str:
        values = [float(p["objectives"][name]) for p in points]
        unit = objective_unit(name).replace("*", "·")
        low, high = general(min(values)), general(max(values))
        return f"{words(name)} {low if low == high else f'{low}–{high}'} {unit} ({percent(spans[name])} %)"

    lines = [f"Front of {len(points)} designs: " + ", ".join(ranged(n) for n in names) + "."]
    flat = [n for n in names if spans[n] < FLAT_SPAN]
    real = [n for n in names if spans[n] >= FLAT_SPAN]
    if flat and not real:
        lines.append(
            f"Degenerate front: every design within {FLAT_SPAN:g} % in every objective; the designs are "
            "practically one."
        )
    elif flat:
        choice = " and ".join(words(n) for n in real)
        lines.append(
            "Flat in "
            + " and ".join(words(n) for n in flat)
            + f" (less than {FLAT_SPAN:g} % between its designs): {choice} "
            + ("is the only real choice." if len(real) == 1 else "are the only real choices.")
        )
    return lines


def flat_impulse_reason(pareto: ParetoRecord, record: DesignRecord, resolved: Mapping[str, Any]) -> list[str]:
    """Why an impulse objective is flat over the front, with the recommended design's impulse phases.

    The impact phase ``m_f v0`` is the links' (and, with ``reflected_inertia_in: finger``, the rotors'); the
    sensing and reaction phases are what the actuators set. Empty unless an impulse objective is flat.
    """
    points, names = pareto.get("points") or [], pareto.get("objectives") or []
    phases = record.get("phases")
    if not points or not phases:
        return []
    one = len(points) == 1  # the front collapsed: no design trades the objectives
    spans = objective_spans(points, names)
    flat = [n for n in names if n in IMPULSE_OBJECTIVES and (one or spans[n] < FLAT_SPAN)]
    if not flat:
        return []
    initial, sensing, reaction = (
        np.asarray(phases[k], dtype=float) for k in ("initial", "sensing", "reaction")
    )
    total = initial + sensing + reaction
    worst = int(np.argmax(total))
    share_worst = 100 * initial[worst] / total[worst]
    share_all = 100 * initial.sum() / total.sum()
    placement = resolved.get("reflected_inertia_in", "robot")
    own = {
        p.get("reflected_inertia_in") for p in (resolved.get("actuators") or {}).get("joints", {}).values()
    }
    if placement == "robot" and not own - {None, "robot"}:
        where = "the links with the actuator masses they carry (the rotors sit behind the joint springs)"
    elif placement == "finger" and not own - {None, "finger"}:
        where = "the links with the actuator masses and the rotors"
    else:
        where = "the links with the actuator masses and the rotors of the joints placed in the impact"
    return [
        f"Why: the impact phase m_f v0, set by {where}, carries {general(share_worst, 3)} % of the worst "
        f"sample's impulse and {general(share_all, 3)} % of all samples'; the motors, gears and controller set "
        "only the rest, so actuator mass buys almost nothing here"
        + (
            " and what it adds to the links only raises the impact: the lightest actuators that meet the "
            "requirements are also the gentlest."
            if one
            else "."
        )
    ]


def lightest_near_best(pareto: ParetoRecord, within: float = NEAR_BEST) -> tuple[int, str] | None:
    """The lightest front design within ``within`` (relative) of the best impulse, and its sentence.

    None when the front does not trade an impulse objective against the actuator mass, or is one design.
    """
    names = pareto["objectives"]
    impulse = next((n for n in IMPULSE_OBJECTIVES if n in names), None)
    points = pareto["points"]
    if impulse is None or "actuator_mass" not in names or len(points) < 2:
        return None
    best = min(p["objectives"][impulse] for p in points)
    near = [i for i, p in enumerate(points) if p["objectives"][impulse] <= best * (1 + within)]
    index = min(near, key=lambda i: points[i]["objectives"]["actuator_mass"])
    chosen = points[index]["objectives"]
    above = 100 * (chosen[impulse] / best - 1)
    return index, (
        f"The lightest within {general(100 * within)} % of the best {words(impulse)}: Pareto design {index}, "
        f"{general(chosen['actuator_mass'])} kg at {general(chosen[impulse])} N·s ({general(above, 2)} % above "
        "the best)."
    )


def front_verdict(
    pareto: ParetoRecord,
    record: DesignRecord,
    resolved: Mapping[str, Any],
    contact: HumanContactRecord | None = None,
) -> list[str]:
    """The front in one sentence: its spans (or why it is flat or one design) and its lightest good design.

    Also what caps the approach of a study held to a body region (``contact``: the run's human-contact record).
    """
    lines = front_sentences(pareto)
    reason = flat_impulse_reason(pareto, record, resolved) + held_region_reason(contact)
    near = lightest_near_best(pareto)
    said = " ".join(lines + reason + ([near[1]] if near else []))
    return [said] if said else []


def held_region_reason(contact: HumanContactRecord | None) -> list[str]:
    """What caps the permissible approach of a design held to a body region: the links' own mass at its slowest pose.

    Empty unless the run held its designs to a region and checked them on fresh poses.
    """
    held = contact.get("held_to") if contact else None
    if not held:
        return []
    speed, mass, links, slowest = (held[k] for k in ("links_speed", "robot_mass", "link_mass", "slowest"))
    if speed is None or mass is None or links is None or slowest is None:
        return []
    gain = 100 * (speed / slowest - 1)
    return [
        f"What caps the speed: its slowest fresh pose meets the {held['region'].replace('_', ' ')} with "
        f"{general(mass, 3)} kg, {general(links, 3)} kg the links'; with the links alone "
        f"{general(speed, 3)} m/s, {general(gain, 2)} % faster: no actuators gain more."
    ]


def transmission_choice_sentences(tried: Sequence[TransmissionTried] | None) -> list[str]:
    """The transmission chosen among the study's gearbox options, in one sentence (the report's table has all)."""
    if not tried:
        return []
    chosen = next(t for t in tried if t["chosen"])
    options = sorted(set(chosen["assignment"].values()))
    where = (
        f"{options[0]} at every joint"
        if len(options) == 1
        else "; ".join(
            f"{group_name(joints.split(', '))}: {option}" for joints, option in chosen["assignment"].items()
        )
    )
    others = [t["objective"] for t in tried if not t["chosen"] and t["objective"] is not None]
    runner_up = f"; the next best {general(min(others), 4)}" if others else ""
    return [
        f"Transmission: {where}, the best of {len(tried)} assignments of the gearbox options by the study's "
        f"objective ({general(cast(float, chosen['objective']), 4)}{runner_up})."  # the chosen one has a design
    ]


__all__ = [
    "front_sentences",
    "lightest_near_best",
    "objective_spans",
]
