"""The Pareto front's hover cards: each Pareto design in a few lines of designer units, for the HTML report.

The report's front figure gives each design's marker the SVG id ``front-point-{i}``
(:data:`collision_reflex.plots.design_front.POINT_ID`); its script shows the card of that id when the marker is
hovered, focused or clicked.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

from ..plots.design_front import POINT_ID
from ..record.design import DesignRecord, JointRecord, QuickSnap
from ..record.run import ArmRunRecord
from .wording import significant, unit, words


def _objective_lines(objectives: Mapping[str, float], first: Sequence[str]) -> list[str]:
    """Each objective with its unit, the front's objectives (``first``) before the others."""
    from ..optimize import OBJECTIVES  # lazy: casadi

    names = [name for name in first if name in objectives]
    names += [name for name in objectives if name not in names]
    lines = []
    for name in names:
        shown = unit(OBJECTIVES[name][1]) if name in OBJECTIVES else ""
        lines.append(f"{words(name)} {significant(objectives[name], 4)} {shown}".rstrip())
    return lines


def _threshold_line(record: DesignRecord) -> str:
    threshold = float(record["threshold"])
    if record.get("sensing") == "position":  # a position-error threshold [m]
        return f"position-error threshold {significant(threshold * 1e3, 4)} mm"
    return f"threshold {significant(threshold, 4)} N"


def _joint_lines(joints: Sequence[JointRecord]) -> list[str]:
    """Each joint's motor, gear ratio and software stiffness; the gearbox once if every joint has the same."""
    gearboxes = [unit(g) if isinstance(g, str) and g else None for g in (j.get("gearbox") for j in joints)]
    common = len(set(gearboxes)) == 1
    lines = []
    for joint, gearbox in zip(joints, gearboxes, strict=True):
        line = (
            f"{joint['joint']}: {significant(joint['stator_diameter'] * 1e3, 3)} mm × "
            f"{significant(joint['stack_length'] * 1e3, 3)} mm motor, N = {significant(joint['gear_ratio'], 4)}, "
            f"k_s {significant(joint['software_stiffness'], 4)} N·m/rad"
        )
        lines.append(f"{line}; {gearbox}" if gearbox and not common else line)
    if common and gearboxes and gearboxes[0]:
        lines.append(f"gearbox of every joint: {gearboxes[0]}")
    return lines


def _parts(parts: Sequence[str | None]) -> str:
    """The parts in joint order, a run of joints with the same part as ``3 × part``."""
    runs: list[list[Any]] = []
    for part in parts:
        if runs and runs[-1][0] == part:
            runs[-1][1] += 1
        else:
            runs.append([part, 1])
    return ", ".join(f"{count} × {part or 'none'}" if count > 1 else part or "none" for part, count in runs)


def _catalogue_line(snap: QuickSnap) -> str:
    """The quick catalogue snap: its part per joint and whether it meets the requirements as it is."""
    parts = _parts(snap.get("parts") or ())
    missing = snap.get("missing") or []
    if missing:
        misses = "; ".join(
            f"{m['joint']}: no part within bounds, nearest {m['nearest']} misses {', '.join(m['misses'])}"
            for m in missing
        )
    elif snap.get("feasible"):
        return f"catalogue parts: {parts} (meets the requirements)"
    else:
        misses = "; ".join(unit(s) for s in snap.get("shortfalls") or ()) or "the requirements"
    return f"catalogue parts: {parts} (misses: {misses})"


def front_cards(results: ArmRunRecord) -> list[dict[str, Any]]:
    """One hover card per Pareto design of a run's results (``designs.json``), in Pareto order.

    Parameters
    ----------
    results
        A run's results: ``results["pareto"]["points"]`` the Pareto design records; the quick catalogue snap
        of design ``i`` from ``results["catalogue"]["pareto"][i]`` and the recommended design from
        ``results["recommended"]["pareto_index"]``, where present.

    Returns
    -------
    list of dict
        ``{"id": "front-point-i", "title": "Pareto design i", "lines": [...]}``: the design's objectives,
        threshold, approach velocity, each joint's motor (stator diameter × stack length in mm), gear ratio,
        software stiffness and gearbox, and its catalogue snap; the recommended design's title says so.
    """
    pareto = results["pareto"]
    catalogue = results.get("catalogue")
    snaps = catalogue["pareto"] if catalogue else []
    chosen = results.get("recommended")
    recommended = chosen.get("pareto_index") if chosen else None
    cards = []
    for index, record in enumerate(pareto["points"]):
        lines = _objective_lines(record["objectives"], pareto.get("objectives") or [])
        lines.append(_threshold_line(record))
        velocity = f"approach velocity {significant(record['approach_velocity'], 4)} m/s"
        if velocity not in lines:  # an objective of the front already says it
            lines.append(velocity)
        lines += _joint_lines(record["joints"])
        if index < len(snaps) and snaps[index]:
            lines.append(_catalogue_line(snaps[index]))
        title = f"Pareto design {index}" + (" — recommended" if index == recommended else "")
        cards.append({"id": POINT_ID.format(index), "title": title, "lines": lines})
    return cards
