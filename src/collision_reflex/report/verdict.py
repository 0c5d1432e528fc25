"""The verdict an arm study's report opens with, as plain sentences decided from its results record.

One place for the HTML report, ``designs.json`` (``verdict``) and ``crx run``'s closing print: the recommended
design, the bounds and constraints that are active on each joint, how far each objective spans over the front
(and a plain sentence when the front is flat or degenerate), the lightest design near the best impulse, the kind
of torque requirement, warnings about oversized joints, and the design built from catalogue parts. Every
function reads plain data (the records of :func:`collision_reflex.optimize.results.design_record` and the results of
:func:`collision_reflex.study.arm_results.arm_results`), so the verdict can be redone from a saved
``designs.json``.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any, Literal

import numpy as np

ACTIVE_TOLERANCE = 1e-3
"""Relative distance below which a design variable is at its bound, and a margin below which its constraint
is active (the solver's own tolerances are far smaller: a bound or constraint this close is what set the value)."""

FLAT_SPAN = 1.0
"""Span [%] of an objective over the front below which the front is flat in it: no design choice that matters."""

NEAR_BEST = 0.05
"""How far above the best impulse (relative) a design may be for "the lightest design within 5 % of the best"."""

OVERSIZED_MARGIN = 2.0
"""Peak-torque margin above which a joint is oversized (more than 3x its requirement) unless its motor is at its
smallest size."""

MARGINS = (("torque_margin", "peak torque"), ("rms_margin", "RMS torque"), ("speed_margin", "speed"))
"""Per-joint margins of a design record (``peak / required - 1``) and the constraint each belongs to; a margin
absent or ``None`` means the design has no such requirement."""

Position = Literal["lower", "upper", "fixed"] | None


def _words(name: str) -> str:
    return name.replace("_", " ")


def _g(value: float, digits: int = 4) -> str:
    return f"{value:.{digits}g}"


def _percent(value: float) -> str:
    """A percentage to 3 significant digits, without exponents (``< 0.001``, ``0.354``, ``12.3``, ``1,750``)."""
    if value < 1e-3:
        return "< 0.001" if value > 0 else "0"
    return f"{value:,.0f}" if value >= 100 else f"{value:.3g}"


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


def motor_at_smallest_size(joint: Mapping[str, Any], bounds: Mapping[str, Any]) -> bool:
    """Whether a joint's motor is at its smallest size.

    Stator diameter and stack length each at their lower bounds or fixed, and at least one of them a design
    variable.
    """
    name = joint["joint"]
    positions = [bound_position(joint[key], bounds[key][name]) for key in ("stator_diameter", "stack_length")]
    return all(p in ("lower", "fixed") for p in positions) and "lower" in positions


def joint_limits(
    joint: Mapping[str, Any], bounds: Mapping[str, Any], requirement: str, undecided: Sequence[str] = ()
) -> list[str]:
    """The bounds and constraints that are active on one joint of a design record, in words.

    ``undecided``: the joint's design variables that no objective decides (the record's ``undecided``; an
    undecided gear ratio is not called the objective's choice, :func:`undecided_sentence` says what it is).
    """
    name = joint["joint"]
    size = {key: bound_position(joint[key], bounds[key][name]) for key in ("stator_diameter", "stack_length")}
    phrases = []
    if motor_at_smallest_size(joint, bounds):
        phrases.append("motor at its smallest size")
    elif all(p in ("upper", "fixed") for p in size.values()) and "upper" in size.values():
        phrases.append("motor at its largest size")
    else:
        phrases += [f"{_words(key)} at its {p} bound" for key, p in size.items() if p in ("lower", "upper")]
    for key in ("gear_ratio", "software_stiffness"):
        position = bound_position(joint[key], bounds[key][name])
        if position in ("lower", "upper"):
            phrases.append(f"{_words(key)} at its {position} bound ({_g(joint[key])})")
    if joint.get("torque_margin") is None:
        phrases.append(
            "no torque requirement: static gravity-only requirement is zero for this joint"
            if requirement.startswith("static")
            else "no torque requirement"
        )
    for key, constraint in MARGINS:
        margin = joint.get(key)
        if margin is not None and margin < ACTIVE_TOLERANCE:
            by = joint.get("required_by") if key == "torque_margin" else None
            phrases.append(f"sized by {constraint}" + (f" ({by})" if by else ""))
    margin = joint.get("torque_margin")
    chosen_ratio = "gear_ratio" not in undecided
    if margin is not None and margin > OVERSIZED_MARGIN and motor_at_smallest_size(joint, bounds):
        phrases.append(_smallest_motor_excess(joint, bounds["gear_ratio"][name], 1 + margin, chosen_ratio))
    return phrases


def _smallest_motor_excess(
    joint: Mapping[str, Any], ratio_bounds: Sequence[float], multiple: float, chosen_ratio: bool = True
) -> str:
    """Why a joint at its smallest motor has ``multiple`` times its required peak torque, in words.

    The motor itself, or the gear ratio the objective chose: the peak torque grows with the ratio, which the
    collision reflex may want higher (a harder braking torque ``N tau_p``) than the motion needs.
    ``chosen_ratio`` False: no objective decides the ratio (:func:`undecided_sentence` says so), so it is not
    called the objective's choice.
    """
    ratio, lowest = float(joint["gear_ratio"]), float(ratio_bounds[0])
    said = f"peak torque {_g(multiple, 3)}× its requirement"
    if bound_position(ratio, ratio_bounds) in ("lower", "fixed"):
        return f"{said}: even the smallest motor is more than it needs"
    at_lowest = multiple * lowest / ratio
    lowest_said = f"{_g(at_lowest, 3)}× at its lowest ratio, {_g(lowest)}"
    if at_lowest > 1 + OVERSIZED_MARGIN:
        return f"{said} at N = {_g(ratio)} ({lowest_said}): even the smallest motor is more than it needs"
    if not chosen_ratio:
        return f"{said} at N = {_g(ratio)} ({lowest_said})"
    return (
        f"{said} at N = {_g(ratio)}, the ratio the objective chose ({lowest_said}): the gear ratio, not the "
        "motor, gives the excess"
    )


UNDECIDED_UNITS = {"software_stiffness": " N·m/rad", "stator_diameter": " m", "stack_length": " m"}
"""Units printed after an undecided variable's value (none for the gear ratio)."""


def undecided_sentence(joint: Mapping[str, Any], undecided: Sequence[str]) -> str:
    """That no objective decides these design variables of a joint, with their values, as a sentence.

    A software stiffness that changes no impulse belongs to a joint no contact sample loads (the contact forces
    exert no torque about its axis): said as the reason.
    """
    one = len(undecided) == 1
    values = " and ".join(
        f"{_words(key)} ({_g(joint[key])}{UNDECIDED_UNITS.get(key, '')})" for key in undecided
    )
    reason = ", as no contact sample loads this joint" if "software_stiffness" in undecided else ""
    them = "it" if one else "them"
    return (
        f"Its {values} change{'s' if one else ''} no impulse and not the actuator mass anywhere within "
        f"{'its' if one else 'their'} bounds{reason}: no objective decides {them}, and "
        f"{'it is' if one else 'they are'} where the solver started; choose {them} on grounds this study does not "
        "model."
    )


def design_limits(record: Mapping[str, Any], bounds: Mapping[str, Any]) -> list[str]:
    """The global design variables (threshold, approach velocity) of a record at a bound or undecided, in words.

    Undecided: named in the record's ``undecided`` (no objective changes with it).
    """
    undecided = {entry["variable"] for entry in record.get("undecided", ()) if entry["joint"] is None}
    phrases = []
    for key in ("threshold", "approach_velocity"):
        position = bound_position(record[key], bounds[key])
        if key in undecided:
            phrases.append(
                f"{_words(key)} ({_g(record[key])}) changes no objective anywhere within its bounds: no "
                "objective decides it, the value is where the solver started"
            )
        elif position in ("lower", "upper"):
            phrases.append(f"{_words(key)} at its {position} bound ({_g(record[key])})")
    return phrases


def design_sentence(record: Mapping[str, Any]) -> str:
    """A design in one sentence: per joint its motor size and gear ratio; the threshold and approach velocity."""
    joints = []
    for joint in record["joints"]:
        motor = f"{_g(joint['stator_diameter'] * 1e3, 3)} mm × {_g(joint['stack_length'] * 1e3, 3)} mm motor"
        nearest = joint.get("nearest_catalogue_motor")
        joints.append(
            f"{joint['joint']}: {motor}"
            + (f" (nearest catalogue motor {nearest})" if nearest else "")
            + f" at N = {_g(joint['gear_ratio'])}"
        )
    threshold = f"{_g(record['threshold'])} " + (
        "N" if record["sensing"] == "force" else "m (position error)"
    )
    values = {**record["objectives"]}
    if record.get("worst_case"):  # the worst case over the contact domain as searched, not over the samples
        values["worst_case_impulse"] = record["worst_case"]["domain"]
    objectives = ", ".join(
        f"{_words(name)} {_g(values[name])} {unit}"
        for name, unit in (("worst_case_impulse", "N·s"), ("mean_impulse", "N·s"), ("actuator_mass", "kg"))
        if name in values
    )
    return (
        "; ".join(joints)
        + f"; threshold {threshold}, approach velocity {_g(record['approach_velocity'])} m/s ({objectives})."
    )


def domain_sentence(domain: Mapping[str, Any], velocity: float, kept: float | None) -> str:
    """Where the worst case is taken: the contact domain's floor, its speed check and what it keeps.

    ``kept``: the fraction of the joint-limit box in the domain at ``velocity`` [m/s] (None: unknown).
    """
    floor = float(domain["min_singular_value"])
    where = (
        f"configurations within the joint limits whose contact Jacobian has a smallest singular value of at "
        f"least {_g(floor * 1e3, 3)} mm ({_g(floor / domain['reach'], 2)} × the {_g(domain['reach'], 3)} m reach)"
        if floor > 0
        else "every configuration within the joint limits (no singular-value floor: near singular poses the "
        "worst case is unbounded)"
    )
    share = f"; it keeps {_percent(100 * kept)} % of the joint-limit box" if kept is not None else ""
    return (
        f"Contact domain: {where}, hit along the directions the joints can follow at the approach velocity "
        f"({_g(velocity)} m/s) within their speed limits{share}."
    )


def worst_case_sentences(
    record: Mapping[str, Any],
    domain: Mapping[str, Any] | None,
    pareto: Mapping[str, Any],
    exchanged: bool = True,
) -> list[str]:
    """The recommended design's worst case over the contact domain, where it occurs, and how sure it is.

    Also names the Pareto designs whose worst case the search could not certify. ``exchanged``: the study
    minimises or bounds the worst case, so that searched points joined its samples (else they are only
    reported).
    """
    worst = record.get("worst_case")
    if not worst or domain is None:
        return []
    search = worst.get("searched")
    lines = [domain_sentence(domain, float(record["approach_velocity"]), (search or {}).get("domain_kept"))]
    if search is None:
        lines.append(
            f"Worst case {_g(worst['sampled'])} N·s over the samples; no search of the domain ran, so it is a "
            "sampled value, not a bound."
        )
        return lines
    pose = ", ".join(f"{np.degrees(v):.0f}" for v in search["q"])
    direction = ", ".join(f"{v:+.2f}" for v in search["direction"])
    effort = f"{search['starts']} local searches, {search['evaluations']:,} impulses evaluated"
    if worst["certified"]:
        lines.append(
            f"Worst case {_g(worst['domain'])} N·s, certified over the domain: {effort}, none more than "
            f"{_g(100 * worst['tolerance'], 2)} % above the samples' worst case {_g(worst['sampled'])} N·s. The "
            f"searched worst pose: q = [{pose}] deg, contact direction u = [{direction}]."
        )
    else:
        excess = worst["domain"] / worst["sampled"] - 1
        remedy = (
            "more search rounds (optimizer.worst_case_search.rounds) or samples may certify it"
            if exchanged
            else "the worst case is no objective of this study, so the points found do not join its samples "
            "(make worst_case_impulse an objective or a Pareto objective to bound it)"
        )
        lines.append(
            f"Worst case NOT certified: the search ({effort}) found {_g(worst['domain'])} N·s, "
            f"{_percent(100 * excess)} % above the samples' worst case {_g(worst['sampled'])} N·s, at q = [{pose}] "
            f"deg along u = [{direction}]. Take {_g(worst['domain'])} N·s as the worst case found, not as a bound; "
            f"{remedy}."
        )
    uncertified = [
        str(point.get("label", i))
        for i, point in enumerate(pareto.get("points", ()))
        if point.get("worst_case")
        and point["worst_case"].get("searched")
        and not point["worst_case"]["certified"]
    ]
    if uncertified:
        lines.append(
            "Pareto designs whose worst case the search found above their samples' (not certified): "
            + "; ".join(uncertified)
            + "."
        )
    return lines


def statistics_sentences(
    record: Mapping[str, Any], study: Mapping[str, Any], pareto: Mapping[str, Any] | None = None
) -> list[str]:
    """The recommended design on fresh samples and on its own: worst case, mean and quantile with their errors.

    Warnings when a fresh sample exceeds a design's worst case, when a fresh statistic's error exceeds the
    study's ``samples.error_tolerance`` (naming the fresh configurations that would meet it), and when the mean
    is an objective whose error on the optimised samples exceeds it.
    """
    tolerance = float((study.get("samples") or {}).get("error_tolerance", 0.02))
    lines = []
    fresh = record.get("fresh")
    if fresh and fresh.get("largest") is not None:
        worst = float(record["worst_case"]["domain"])
        stats = fresh["statistics"]
        check = (
            f"WARNING: {_g(fresh['largest'])} N·s, {_percent(100 * (fresh['largest'] / worst - 1))} % above its "
            f"worst case {_g(worst)} N·s, which is therefore not a bound"
            if fresh["exceeds"]
            else f"{_g(fresh['largest'])} N·s, within its worst case {_g(worst)} N·s"
        )
        lines.append(
            f"Checked on {fresh['configurations']:,} fresh configurations of the domain ({fresh['samples']:,} "
            f"samples it was not optimised on): largest impulse {check}; {_statistics_phrase(stats)}, 99 % "
            "bootstrap intervals."
        )
        error = max(estimate["relative_error"] for estimate in stats.values())
        if error > tolerance:
            needed = int(np.ceil(fresh["configurations"] * (error / tolerance) ** 2))
            lines.append(
                f"Warning: the fresh statistics are uncertain by up to {_percent(100 * error)} %, more than the "
                f"study's {_percent(100 * tolerance)} % (samples.error_tolerance): about {needed:,} fresh "
                "configurations (samples.fresh) would meet it."
            )
    exceeded = [
        str(point.get("label", i))
        for i, point in enumerate((pareto or {}).get("points", ()))
        if (point.get("fresh") or {}).get("exceeds")
    ]
    if exceeded:
        lines.append("Pareto designs whose worst case a fresh sample exceeds: " + "; ".join(exceeded) + ".")
    statistics = record.get("statistics")
    if not statistics:
        return lines
    mean = statistics["mean_impulse"]
    lines.append(
        f"On the samples it was optimised on ({mean['configurations']} configurations, {mean['samples']:,} "
        f"samples): {_statistics_phrase(statistics)}."
    )
    objectives = study_objectives(study)
    for name in ("mean_impulse", "cvar_impulse"):
        estimate = statistics.get(name)
        if name not in objectives or estimate is None or estimate["relative_error"] <= tolerance:
            continue
        needed = int(np.ceil(estimate["configurations"] * (estimate["relative_error"] / tolerance) ** 2))
        lines.append(
            f"Warning: the {_STATISTIC_NAMES[name]}, an objective, is uncertain by "
            f"{_percent(100 * estimate['relative_error'])} % on the samples it was optimised on, more than the "
            f"study's {_percent(100 * tolerance)} % (samples.error_tolerance): about {needed:,} configurations "
            "(samples.configurations.random.count) would meet it."
        )
    return lines


def study_objectives(study: Mapping[str, Any]) -> set[str]:
    """The objectives a resolved study names: its objective (a name or a weighted sum) and its Pareto ones."""
    objective = study.get("objective") or ()
    named = {objective} if isinstance(objective, str) else set(objective)
    return named | set((study.get("pareto") or {}).get("objectives") or ())


_STATISTIC_NAMES = {"mean_impulse": "mean impulse", "cvar_impulse": "CVaR impulse"}


def _statistics_phrase(statistics: Mapping[str, Any]) -> str:
    """``mean ..., mean of the worst 5 % (CVaR) ..., 99th percentile ...``, each with its relative error."""

    def one(estimate: Mapping[str, Any]) -> str:
        return f"{_g(estimate['value'])} N·s (± {_percent(100 * estimate['relative_error'])} %)"

    parts = [f"mean impulse {one(statistics['mean_impulse'])}"]
    if "cvar_impulse" in statistics:
        from ..optimize.objectives import CVAR_LEVEL

        parts.append(
            f"mean of the worst {_g(100 * (1 - CVAR_LEVEL), 2)} % (CVaR) {one(statistics['cvar_impulse'])}"
        )
    quantile = statistics["quantile_impulse"]
    parts.append(f"{_g(100 * quantile['quantile'], 3)}th percentile {one(quantile)}")
    return ", ".join(parts)


def objective_spans(points: Sequence[Mapping[str, Any]], objectives: Sequence[str]) -> dict[str, float]:
    """Each objective's span over ``points`` [%].

    That is (largest - smallest) / |best|, best the value the front optimises toward (the smallest, or the
    largest for a maximised objective).
    """
    from ..optimize import OBJECTIVES

    spans = {}
    for name in objectives:
        values = [float(p["objectives"][name]) for p in points]
        best = min(values) if OBJECTIVES[name][0] > 0 else max(values)
        spans[name] = 100 * (max(values) - min(values)) / max(abs(best), 1e-300)
    return spans


def front_sentences(pareto: Mapping[str, Any]) -> list[str]:
    """The front's spans, and a plain sentence when it is flat or degenerate.

    Flat: an objective spans less than :data:`FLAT_SPAN`; degenerate: one point (every repeat merged), or every
    objective flat.
    """
    from ..optimize.pareto import MERGE_TOLERANCE

    points, names = pareto["points"], pareto["objectives"]
    if not points:
        return []
    merged = int(pareto.get("merged", 0))
    lines = []
    if merged:
        lines.append(
            f"{merged} solved point(s) repeated a reported design (objectives equal within {MERGE_TOLERANCE:g} "
            "relative, the solver's tolerance) and were merged."
        )
    if len(points) == 1:
        return [
            *lines,
            "Degenerate front: one design. The objectives "
            + " and ".join(_words(n) for n in names)
            + " do not trade off within these bounds; the recommended design is the only choice.",
        ]
    spans = objective_spans(points, names)
    lines.insert(
        0,
        f"The front ({len(points)} designs) spans "
        + ", ".join(f"{_percent(s)} % in {_words(n)}" for n, s in spans.items())
        + ".",
    )
    flat = [n for n in names if spans[n] < FLAT_SPAN]
    real = [n for n in names if spans[n] >= FLAT_SPAN]
    if flat and not real:
        lines.append(
            f"Degenerate front: every design within {FLAT_SPAN:g} % in every objective; the designs are "
            "practically one."
        )
    elif flat:
        choice = " and ".join(_words(n) for n in real)
        lines += [
            f"Flat front: all designs within {_g(spans[n], 2)} % of the best {_words(n)}: {choice} "
            + ("is the only real choice." if len(real) == 1 else "are the only real choices.")
            for n in flat
        ]
    return lines


def flat_impulse_reason(
    pareto: Mapping[str, Any], record: Mapping[str, Any], resolved: Mapping[str, Any]
) -> list[str]:
    """Why an impulse objective is flat over the front, with the recommended design's impulse phases.

    The impact phase ``m_f v0`` is the links' (and, with ``reflected_inertia_in: finger``, the rotors'); the
    sensing and reaction phases are what the actuators set. Empty unless an impulse objective is flat.
    """
    from ..optimize.objectives import IMPULSE_OBJECTIVES

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
        where = (
            "the links' inertia with the actuator masses they carry; the rotors sit behind the joint springs "
            "(reflected_inertia_in: robot)"
        )
    elif placement == "finger" and not own - {None, "finger"}:
        where = "the links' inertia with the actuator masses and the rotors (reflected_inertia_in: finger)"
    else:
        where = (
            "the links' inertia with the actuator masses, and the rotors of the joints placed in the impact"
        )
    why = "is one design" if one else f"is flat in {_words(flat[0])}"
    return [
        f"Why the front {why}: at the recommended design the impact phase m_f v0, set by "
        f"{where}, carries {_g(share_worst, 3)} % of the worst sample's impulse ({_g(initial[worst], 4)} of "
        f"{_g(total[worst], 4)} N·s) and {_g(share_all, 3)} % of all samples' together. The sensing and reaction "
        "phases, which the motors, gears and controller set, carry the rest, and the actuator masses on the links "
        "move the impact little: actuator mass buys almost nothing here"
        + (
            ", and what it adds to the links' mass only raises it: the lightest actuators that meet the "
            "requirements are also the gentlest."
            if one
            else "."
        )
    ]


def lightest_near_best(pareto: Mapping[str, Any], within: float = NEAR_BEST) -> tuple[int, str] | None:
    """The lightest front design within ``within`` (relative) of the best impulse, and its sentence.

    None when the front does not trade an impulse objective against the actuator mass, or is one design.
    """
    from ..optimize.objectives import IMPULSE_OBJECTIVES

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
        f"Lightest design within {_g(100 * within)} % of the best {_words(impulse)}: Pareto design {index}, "
        f"{_g(chosen['actuator_mass'])} kg at {_g(chosen[impulse])} N·s ({_g(above, 2)} % above the best)."
    )


def requirement_sentence(requirement: str, rating: Mapping[str, Any] | None = None) -> str:
    """What the torque requirement is, and what it leaves out; ``rating``: the resolved study's, if any."""
    if rating and requirement.startswith(("duty", "rated")):
        cycle = "the duty cycle (peak, RMS, speed), " if requirement.startswith("duty") else ""
        return (
            f"Torque requirement: {cycle}the rated motion (each joint alone, either way, at its rated speed "
            "while accelerating at its rated acceleration, and braking from its rated speed within its stopping "
            "time), all with the rated payload at every sampled configuration, and the static hold there and at "
            "each joint's worst pose within the joint limits; each joint's peak requirement is the largest of these (the table says which), its speed the largest rated or "
            "cycle speed."
        )
    if requirement.startswith("static"):
        return (
            f"Torque requirement: {requirement}. The peak torque covers gravity (and the payload) over the "
            "sampled configurations and each joint's worst pose within the joint limits only: the motion's dynamics, RMS (thermal) torque and motor speed are not "
            "checked; give the study a duty cycle to size for them."
        )
    if requirement.startswith("duty"):
        return (
            f"Torque requirement: {requirement}, and the static hold: the arm and its rated payload held still "
            "at every sampled configuration and at each joint's worst pose within the joint limits; each joint's "
            "peak requirement is the larger of the two."
        )
    return f"Torque requirement: {requirement}."


def oversized_warnings(record: Mapping[str, Any], bounds: Mapping[str, Any]) -> list[str]:
    """A warning for each oversized joint.

    Oversized: a peak-torque margin above :data:`OVERSIZED_MARGIN` while its motor could be smaller (not at its
    smallest size).
    """
    warnings = []
    for joint in record["joints"]:
        margin = joint.get("torque_margin")
        if margin is not None and margin > OVERSIZED_MARGIN and not motor_at_smallest_size(joint, bounds):
            warnings.append(
                f"Warning: {joint['joint']} delivers {_g(1 + margin, 3)}× its required peak torque "
                f"({_g(joint['peak_torque'])} vs {_g(joint['required_torque'])} N·m) with a motor above its "
                "smallest size: nothing in the study sizes this actuator; check its requirement."
            )
    return warnings


def verdict(results: Mapping[str, Any]) -> list[str]:
    """The verdict of an arm study's results (:func:`collision_reflex.study.arm_results.arm_results`)."""
    recommended = results.get("recommended") or {**results["chosen"], "source": "optimum", "reason": ""}
    bounds = results.get("bounds")
    requirement = str(results.get("requirement", "static (gravity only)"))
    reason = str(recommended.get("reason", ""))
    lines = [f"Recommended design ({recommended.get('source', 'optimum')}): {design_sentence(recommended)}"]
    if reason:
        lines.append(f"Why this design: {reason}.")
    resolved = results.get("resolved") or {}
    exchanged = "worst_case_impulse" in study_objectives(resolved) or not resolved
    lines += worst_case_sentences(recommended, results.get("domain"), results["pareto"], exchanged)
    lines += statistics_sentences(recommended, results.get("resolved") or {}, results.get("pareto"))
    lines.append(requirement_sentence(requirement, resolved.get("rating")))
    if results.get("speed_limits"):
        lines.append(str(results["speed_limits"]))
    lines += [str(line) for line in results.get("transmissions", ())]
    lines += transmission_choice_sentences(results.get("transmission_choice"))
    if bounds is not None:
        undecided = recommended.get("undecided", ())
        at_bound = False
        for joint in recommended["joints"]:
            own = [entry["variable"] for entry in undecided if entry["joint"] == joint["joint"]]
            phrases = joint_limits(joint, bounds, requirement, own)
            at_bound = at_bound or any(" bound" in phrase or " size" in phrase for phrase in phrases)
            lines.append(
                f"{joint['joint']}: "
                + (", ".join(phrases) if phrases else "no bound or constraint active")
                + "."
                + (f" {undecided_sentence(joint, own)}" if own else "")
            )
        limits = design_limits(recommended, bounds)
        if limits:
            lines.append("Sensing and approach: " + ", ".join(limits) + ".")
        if limits or at_bound:
            lines.append(
                "A variable at a bound of the study's design section, with no requirement named beside it, is "
                "held there by that bound alone: the objectives would take it beyond. The bound, not the "
                "physics, decides it; widen it to see where the design would settle."
            )
    lines += module_sentences(recommended)
    lines += front_sentences(results["pareto"])
    lines += flat_impulse_reason(results["pareto"], recommended, results.get("resolved") or {})
    near = lightest_near_best(results["pareto"])
    if near is not None:
        lines.append(near[1])
    if bounds is not None:
        lines += oversized_warnings(recommended, bounds)
    if results.get("catalogue"):
        lines += catalogue_sentences(results["catalogue"])
    return lines


def transmission_choice_sentences(tried: Sequence[Mapping[str, Any]] | None) -> list[str]:
    """The gearbox options tried per module and the one chosen, with each assignment's objective."""
    if not tried:
        return []
    chosen = next(t for t in tried if t["chosen"])

    def described(entry: Mapping[str, Any]) -> str:
        parts = "; ".join(f"{joints}: {option}" for joints, option in entry["assignment"].items())
        if entry["objective"] is None:
            return f"{parts} (no design: {entry['status']})"
        return (
            f"{parts} (objective {_g(entry['objective'], 4)}, actuators {_g(entry['actuator_mass'], 4)} kg)"
        )

    others = [described(t) for t in tried if not t["chosen"]]
    return [
        f"Transmissions chosen among the study's gearbox options, by the objective at each assignment's "
        f"optimum: {described(chosen)}; also tried: " + " / ".join(others) + "."
    ]


def module_sentences(record: Mapping[str, Any]) -> list[str]:
    """One sentence per actuator module of a design record: its joints and what sizes it."""
    out = []
    for joint in record["joints"]:
        members = joint.get("module")
        if not members or joint["joint"] != members[0]:
            continue
        by = joint.get("required_by") or "nothing"
        origin = next((m for m in members if by.endswith(f" of {m}")), joint["joint"])
        out.append(
            f"Module {', '.join(members)}: one actuator (motor, gearbox, gear ratio) for all of them, sized for "
            f"the most demanding, {origin} ({by.removesuffix(f' of {origin}')}); each table row gives that "
            "requirement."
        )
    return out


def catalogue_sentences(catalogue: Mapping[str, Any]) -> list[str]:
    """The catalogue design in one sentence, what it costs against the continuous one, and its warnings.

    A gear ratio that no objective decides (the design's ``undecided``) is said to be the solver's start.

    ``catalogue``: the ``catalogue`` entry of the results (:class:`collision_reflex.study.arm_results.
    CatalogueRecord`).
    """
    warnings = [f"Warning: {text}." for text in catalogue["warnings"]]
    if catalogue["design"] is None:
        return [
            f"No design built from catalogue parts meets the requirements ({catalogue['method']}).",
            *warnings,
        ]
    undecided = {
        entry["joint"]
        for entry in catalogue["design"].get("undecided", ())
        if entry["variable"] == "gear_ratio"
    }
    parts = ", ".join(
        f"{j['joint']} {j['motor']}"
        + (f" + {j['gearbox']}" if j["gearbox"] else "")
        + f" at N = {_g(j['gear_ratio'])}"
        + (" (a ratio no objective decides: the solver's start)" if j["joint"] in undecided else "")
        for j in catalogue["joints"]
    )
    costs = ", ".join(
        f"{_words(name)} {'+' if change >= 0 else '−'}{_percent(abs(change) * 100)} %"
        for name in ("worst_case_impulse", "mean_impulse", "actuator_mass")
        if (change := catalogue["relative_difference"].get(name)) is not None
    )
    return [
        f"Built from catalogue parts ({catalogue['method']}): {parts}; against the continuous design {costs}.",
        *warnings,
    ]


__all__ = [
    "bound_position",
    "catalogue_sentences",
    "design_sentence",
    "front_sentences",
    "joint_limits",
    "lightest_near_best",
    "objective_spans",
    "oversized_warnings",
    "undecided_sentence",
    "verdict",
]
