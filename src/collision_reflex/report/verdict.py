"""The verdict an arm study's report opens with, decided from its results.

One place for the HTML report, ``designs.json`` (``verdict``) and ``crx run``'s closing print: at most ten
sentences, each said once: the design to build (its catalogue parts) and the continuous optimum, how sure its
worst case is (:mod:`.certainty`), what sizes its joints and what the design bounds decide (:mod:`.sizing`),
the front (a plain sentence when it is flat or degenerate) and the transmission choice (:mod:`.front_verdict`),
and warnings, merged into one line where there would be more lines. Every function reads plain data (the
records of :func:`collision_reflex.optimize.results.design_record` and the results of
:func:`collision_reflex.study.arm_results.arm_results`), so the verdict can be redone from a saved
``designs.json``.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import cast

from ..record.design import DesignRecord, JointRecord
from ..record.run import ArmRunRecord, Bounds, CatalogueJoint, CatalogueRecord
from .certainty import certainty_sentences, statistics_warnings, study_objectives
from .front_verdict import front_verdict, transmission_choice_sentences
from .sizing import bound_sentences, oversized_warnings, sized_by_sentences
from .wording import general, group_name, grouped, joint_runs, percent, words

MAX_LINES = 10
"""The verdict's length: what to build, how sure, what sizes it, what the bounds decide, the front, warnings."""


def verdict(results: ArmRunRecord) -> list[str]:
    """The verdict of an arm study's results (:func:`collision_reflex.study.arm_results.arm_results`).

    At most :data:`MAX_LINES` sentences, each said once: the design to build, the continuous optimum it comes
    from, how sure its worst case is, what sizes its joints, what the design bounds decide, the front, the
    transmission choice, and warnings (merged into one line where there would be more lines).
    """
    recommended = results.get("recommended") or {**results["chosen"], "source": "optimum", "reason": ""}
    bounds = results.get("bounds")
    resolved = results.get("resolved") or {}
    catalogue = results.get("catalogue") or None
    lines = build_sentences(recommended, catalogue)
    exchanged = "worst_case_impulse" in study_objectives(resolved) or not resolved
    lines += certainty_sentences(recommended, exchanged)
    lines += sized_by_sentences(recommended, str(results.get("requirement", "static (gravity only)")))
    if bounds is not None:
        lines += bound_sentences(recommended, bounds)
    lines += front_verdict(results["pareto"], recommended, resolved, results.get("human_contact"))
    lines += transmission_choice_sentences(results.get("transmission_choice"))
    warnings = verdict_warnings(results, recommended, bounds, catalogue)
    room = MAX_LINES - len(lines)
    if len(warnings) > room:
        rest = [w.removeprefix("Warning: ").removeprefix("WARNING: ") for w in warnings[max(room - 1, 0) :]]
        warnings = [*warnings[: max(room - 1, 0)], "Warnings: " + " ".join(rest)]
    return lines + warnings


def _sensing(record: DesignRecord) -> str:
    unit = "N" if record["sensing"] == "force" else "m (position error)"
    return (
        f"threshold {general(record['threshold'])} {unit}, approach velocity "
        f"{general(record['approach_velocity'])} m/s"
    )


def _motor(joint: JointRecord) -> str:
    return (
        f"{general(joint['stator_diameter'] * 1e3, 3)} mm × {general(joint['stack_length'] * 1e3, 3)} mm "
        f"motor at N = {general(joint['gear_ratio'])}"
    )


def build_sentences(recommended: DesignRecord, catalogue: CatalogueRecord | None) -> list[str]:
    """What to build: the catalogue design when there is one, then the continuous optimum it was snapped from."""
    objectives = recommended["objectives"]
    worst_case = recommended.get("worst_case")
    worst = worst_case["domain"] if worst_case else objectives.get("worst_case_impulse")
    figures = ", ".join(
        f"{name} {general(value)} {unit}"
        for name, value, unit in (
            ("worst-case impulse", worst, "N·s"),
            ("mean impulse", objectives.get("mean_impulse"), "N·s"),
            ("actuator mass", objectives.get("actuator_mass"), "kg"),
        )
        if value is not None
    )
    source = str(recommended.get("source", "optimum"))
    continuous = f"{grouped(recommended['joints'], _motor)}; {_sensing(recommended)} ({figures})"
    if catalogue is None:
        return [f"Build: the continuous optimum ({source}): {continuous}. Its motors are scaled, not sold."]
    design = catalogue["design"]
    if design is None:
        return [
            f"No design built from catalogue parts meets the requirements: the continuous optimum ({source}) is "
            f"the best design, with scaled motors: {continuous}."
        ]
    undecided = {e["joint"] for e in design.get("undecided", ()) if e["variable"] == "gear_ratio"}

    def part(joint: CatalogueJoint) -> str:
        return (
            f"{joint['motor']}"
            + (f" + {joint['gearbox']}" if joint["gearbox"] else "")
            + f" at N = {general(cast(float, joint['gear_ratio']))}"  # every joint has a part
            + (" (a ratio no objective decides: the solver's start)" if joint["joint"] in undecided else "")
        )

    changes = ", ".join(
        f"{words(name)} {'+' if change >= 0 else '−'}{percent(abs(change) * 100)} %"
        for name in ("worst_case_impulse", "actuator_mass")
        if (change := catalogue["relative_difference"].get(name)) is not None
    )
    values = catalogue["objectives"]
    return [
        f"Build from catalogue parts: {grouped(catalogue['joints'], part)}; {_sensing(design)}: worst impulse "
        f"over the samples {general(values['worst_case_impulse'])} N·s, actuator mass "
        f"{general(values['actuator_mass'])} kg ({changes} against the continuous optimum).",
        f"Continuous optimum ({source}): {continuous}.",
    ]


def verdict_warnings(
    results: ArmRunRecord,
    record: DesignRecord,
    bounds: Bounds | None,
    catalogue: CatalogueRecord | None,
) -> list[str]:
    """Every warning of the verdict: oversized joints, uncertain statistics, Pareto designs the checks fail."""
    warnings = oversized_warnings(record, bounds) if bounds is not None else []
    pareto = results["pareto"]
    warnings += statistics_warnings(record, results.get("resolved") or {}, pareto)
    uncertified = [
        str(point.get("label", i))
        for i, point in enumerate(pareto["points"])
        if (worst := point.get("worst_case")) and worst["searched"] and not worst["certified"]
    ]
    if uncertified:
        named = (
            "; ".join(uncertified)
            if len(uncertified) <= 2
            else f"{len(uncertified)} of {len(pareto['points'])}"
        )
        warnings.append(f"Warning: the worst case of Pareto designs {named} is not certified.")
    if catalogue:
        warnings += _joint_warnings(catalogue["warnings"])
    # Where the simulator validates neither placement of the reflected inertia (the study's transmissions).
    warnings += [str(line) for line in results.get("transmissions", ()) if str(line).startswith("Warning")]
    contact = results.get("human_contact")
    exceeded = [row for row in contact["regions"] if row["above_approach"]] if contact else []
    if contact and exceeded:
        warnings.append(
            f"Warning: the approach speed {general(contact['approach_velocity'])} m/s exceeds the ISO/TS 15066 "
            "permissible speed against "
            + "; ".join(
                f"the {row['region'].replace('_', ' ')} at {row['above_approach']} of {contact['samples']} "
                f"contact samples (slowest {general(row['slowest'])} m/s)"
                for row in exceeded
            )
            + "."
        )
    held = contact.get("held_to") if contact else None
    if held and held["below"] and held["slowest"] is not None:
        warnings.append(
            f"Warning: held to the {held['region'].replace('_', ' ')} at its samples, the design is faster than it "
            f"permits at {held['below']} of {held['fresh_samples']:,} fresh poses (slowest {general(held['slowest'])} m/s)."
        )
    return warnings


def _joint_warnings(texts: Sequence[str]) -> list[str]:
    """``joint: what`` warnings, those that say the same of consecutive joints said once."""
    named = [
        (name, what) if sep else ("", text) for text in texts for name, sep, what in [text.partition(": ")]
    ]
    return [
        f"Warning: {group_name(names) + ': ' if names else ''}{what}." for names, what in joint_runs(named)
    ]


__all__ = [
    "build_sentences",
    "verdict",
]
