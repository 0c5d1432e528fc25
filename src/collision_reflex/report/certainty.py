"""How sure a design's worst case is, in the verdict's and the report's words.

The contact domain it is taken over, the worst pose the search found, whether the search certified it, its
check on fresh samples, and the statistics with their errors (and a warning where an error exceeds the
study's tolerance). Every function reads a design record of
:func:`collision_reflex.optimize.results.design_record` (plain data).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from ..record.design import DesignRecord, Estimate
from ..record.run import DomainRecord, ParetoRecord
from .wording import general, percent


def domain_sentence(domain: DomainRecord, velocity: float, kept: float | None) -> str:
    """Where the worst case is taken: the contact domain's floor, its speed check and what it keeps.

    ``kept``: the fraction of the joint-limit box in the domain at ``velocity`` [m/s] (None: unknown).
    """
    floor = float(domain["min_singular_value"])
    where = (
        f"configurations within the joint limits whose contact Jacobian has a smallest singular value of at "
        f"least {general(floor * 1e3, 3)} mm ({general(floor / domain['reach'], 2)} × the "
        f"{general(domain['reach'], 3)} m reach)"
        if floor > 0
        else "every configuration within the joint limits (no singular-value floor: near singular poses the "
        "worst case is unbounded)"
    )
    share = f"; it keeps {percent(100 * kept)} % of the joint-limit box" if kept is not None else ""
    return (
        f"Contact domain: {where}, hit along the directions the joints can follow at the approach velocity "
        f"({general(velocity)} m/s) within their speed limits{share}."
    )


def worst_pose_sentence(record: DesignRecord) -> str | None:
    """Where the search found a design's worst case, and how hard it looked; None without a search."""
    worst = record.get("worst_case")
    search = worst["searched"] if worst else None
    if search is None:
        return None
    pose = ", ".join(f"{np.degrees(v):.0f}" for v in search["q"])
    direction = ", ".join(f"{v:+.2f}" for v in search["direction"])
    return (
        f"The worst pose found: q = [{pose}] deg, contact direction u = [{direction}] ({search['starts']} local "
        f"searches, {search['evaluations']:,} impulses evaluated)."
    )


def certainty_sentences(record: DesignRecord, exchanged: bool = True) -> list[str]:
    """How sure the recommended design's worst case is (its search), and its check on fresh samples."""
    worst = record.get("worst_case")
    lines = []
    if worst:
        search = worst.get("searched")
        if search is None:
            lines.append(
                f"Worst case {general(worst['sampled'])} N·s over the samples only: no search of the contact "
                "domain ran, so it is a sampled value, not a bound."
            )
        elif worst["certified"]:
            lines.append(
                f"Worst case {general(worst['domain'])} N·s, certified over the contact domain: "
                f"{search['starts']} local searches found nothing more than "
                f"{general(100 * worst['tolerance'], 2)} % above the samples' worst case."
            )
        else:
            remedy = (
                "more search rounds (optimizer.worst_case_search.rounds) or samples may certify it"
                if exchanged
                else "the worst case is no objective of this study, so the points found do not join its "
                "samples (make worst_case_impulse an objective to bound it)"
            )
            excess = worst["domain"] / worst["sampled"] - 1
            lines.append(
                f"Warning: worst case NOT certified: the search found {general(worst['domain'])} N·s, "
                f"{percent(100 * excess)} % above the samples' {general(worst['sampled'])} N·s; take it as a "
                f"worst case found, not a bound; {remedy}."
            )
    fresh = record.get("fresh")
    largest = fresh["largest"] if fresh else None
    if fresh and largest is not None and worst:
        bound = float(worst["domain"])
        mean = fresh["statistics"]["mean_impulse"]
        check = (
            f"WARNING: largest {general(largest)} N·s, {percent(100 * (largest / bound - 1))} % "
            "above the worst case, which is therefore not a bound"
            if fresh["exceeds"]
            else f"largest {general(largest)} N·s, within the worst case"
        )
        lines.append(
            f"On {fresh['configurations']:,} fresh configurations it was not optimised on: {check}; mean "
            f"{general(mean['value'])} N·s (± {percent(100 * mean['relative_error'])} %)."
        )
    return lines


def statistics_rows(record: DesignRecord) -> list[tuple[str, str, str]]:
    """The recommended design's statistics: (statistic, on fresh samples, on the optimised samples).

    Each value with its relative error (the larger half-width of a 99 % cluster-bootstrap interval).
    """
    checked = record.get("fresh")
    fresh = (checked.get("statistics") if checked else None) or {}
    own = record.get("statistics") or {}
    from ..optimize.objectives import CVAR_LEVEL  # lazy: casadi

    names = {
        "mean_impulse": "mean impulse",
        "cvar_impulse": f"mean of the worst {general(100 * (1 - CVAR_LEVEL), 2)} % (CVaR)",
        "quantile_impulse": "99th percentile",
    }

    def one(estimate: Estimate | None) -> str:
        if not estimate:
            return "–"
        return f"{general(estimate['value'])} N·s ± {percent(100 * estimate['relative_error'])} %"

    return [
        (label, one(fresh.get(key)), one(own.get(key)))
        for key, label in names.items()
        if key in fresh or key in own
    ]


def statistics_warnings(
    record: DesignRecord, study: Mapping[str, Any], pareto: ParetoRecord | None = None
) -> list[str]:
    """Warnings on the statistics: errors beyond the study's tolerance, Pareto designs a fresh sample beats.

    A fresh statistic whose error exceeds ``samples.error_tolerance`` names the fresh configurations that would
    meet it; an objective's statistic on the optimised samples names the configurations.
    """
    tolerance = float((study.get("samples") or {}).get("error_tolerance", 0.02))
    lines = []
    fresh = record.get("fresh")
    if fresh and fresh.get("largest") is not None:
        error = max(estimate["relative_error"] for estimate in fresh["statistics"].values())
        if error > tolerance:
            needed = int(np.ceil(fresh["configurations"] * (error / tolerance) ** 2))
            lines.append(
                f"Warning: the fresh statistics are uncertain by up to {percent(100 * error)} %, more than the "
                f"study's {percent(100 * tolerance)} % (samples.error_tolerance): about {needed:,} fresh "
                "configurations (samples.fresh) would meet it."
            )
    exceeded = [
        str(point.get("label", i))
        for i, point in enumerate(pareto["points"] if pareto else [])
        if (checked := point.get("fresh")) and checked["exceeds"]
    ]
    if exceeded:
        lines.append(
            "Warning: a fresh sample exceeds the worst case of Pareto designs " + "; ".join(exceeded) + "."
        )
    statistics = record.get("statistics") or {}
    objectives = study_objectives(study)
    for name in ("mean_impulse", "cvar_impulse"):
        estimate = statistics.get(name)
        if name not in objectives or estimate is None or estimate["relative_error"] <= tolerance:
            continue
        needed = int(np.ceil(estimate["configurations"] * (estimate["relative_error"] / tolerance) ** 2))
        lines.append(
            f"Warning: the {_STATISTIC_NAMES[name]}, an objective, is uncertain by "
            f"{percent(100 * estimate['relative_error'])} % on the samples it was optimised on, more than the "
            f"study's {percent(100 * tolerance)} % (samples.error_tolerance): about {needed:,} configurations "
            "(samples.configurations.random.count) would meet it."
        )
    return lines


def study_objectives(study: Mapping[str, Any]) -> set[str]:
    """The objectives a resolved study names: its objective (a name or a weighted sum) and its Pareto ones."""
    objective = study.get("objective") or ()
    named = {objective} if isinstance(objective, str) else set(objective)
    return named | set((study.get("pareto") or {}).get("objectives") or ())


_STATISTIC_NAMES = {"mean_impulse": "mean impulse", "cvar_impulse": "CVaR impulse"}


__all__ = [
    "certainty_sentences",
    "domain_sentence",
    "statistics_rows",
    "statistics_warnings",
    "worst_pose_sentence",
]
