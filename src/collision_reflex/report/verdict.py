"""The verdict an arm study's report opens with, and the report's other sentences, decided from its results.

One place for the HTML report, ``designs.json`` (``verdict``) and ``crx run``'s closing print: at most ten
sentences, each said once: the design to build (its catalogue parts) and the continuous optimum, how sure its
worst case is, what sizes its joints, what the design bounds decide, the front (a plain sentence when it is flat
or degenerate), the transmission choice, and warnings. Every
function reads plain data (the records of :func:`collision_reflex.optimize.results.design_record` and the results of
:func:`collision_reflex.study.arm_results.arm_results`), so the verdict can be redone from a saved
``designs.json``.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any, Literal

import numpy as np

from .wording import group_name, words

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


def smallest_motor_excess(
    joint: Mapping[str, Any], ratio_bounds: Sequence[float], multiple: float, chosen_ratio: bool = True
) -> str:
    """Why a joint at its smallest motor has ``multiple`` times its required peak torque, in words.

    The motor itself, or the gear ratio the objective chose: the peak torque grows with the ratio, which the
    collision reflex may want higher (a harder braking torque ``N tau_p``) than the motion needs.
    ``chosen_ratio`` False: no objective decides the ratio (:func:`bound_sentences` says so), so it is not
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


def worst_pose_sentence(record: Mapping[str, Any]) -> str | None:
    """Where the search found a design's worst case, and how hard it looked; None without a search."""
    search = (record.get("worst_case") or {}).get("searched")
    if search is None:
        return None
    pose = ", ".join(f"{np.degrees(v):.0f}" for v in search["q"])
    direction = ", ".join(f"{v:+.2f}" for v in search["direction"])
    return (
        f"The worst pose found: q = [{pose}] deg, contact direction u = [{direction}] ({search['starts']} local "
        f"searches, {search['evaluations']:,} impulses evaluated)."
    )


def statistics_rows(record: Mapping[str, Any]) -> list[tuple[str, str, str]]:
    """The recommended design's statistics: (statistic, on fresh samples, on the optimised samples).

    Each value with its relative error (the larger half-width of a 99 % cluster-bootstrap interval).
    """
    fresh = (record.get("fresh") or {}).get("statistics") or {}
    own = record.get("statistics") or {}
    from ..optimize.objectives import CVAR_LEVEL

    names = {
        "mean_impulse": "mean impulse",
        "cvar_impulse": f"mean of the worst {_g(100 * (1 - CVAR_LEVEL), 2)} % (CVaR)",
        "quantile_impulse": "99th percentile",
    }

    def one(estimate: Mapping[str, Any] | None) -> str:
        if not estimate:
            return "–"
        return f"{_g(estimate['value'])} N·s ± {_percent(100 * estimate['relative_error'])} %"

    return [
        (label, one(fresh.get(key)), one(own.get(key)))
        for key, label in names.items()
        if key in fresh or key in own
    ]


def statistics_warnings(
    record: Mapping[str, Any], study: Mapping[str, Any], pareto: Mapping[str, Any] | None = None
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
    """The front's ranges and spans, and a plain sentence when it is flat or degenerate.

    Flat: an objective spans less than :data:`FLAT_SPAN`; degenerate: one point (every repeat merged), or every
    objective flat.
    """
    from ..optimize import OBJECTIVES

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
        unit = OBJECTIVES[name][1].replace("*", "·")
        low, high = _g(min(values)), _g(max(values))
        return f"{words(name)} {low if low == high else f'{low}–{high}'} {unit} ({_percent(spans[name])} %)"

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
        where = "the links with the actuator masses they carry (the rotors sit behind the joint springs)"
    elif placement == "finger" and not own - {None, "finger"}:
        where = "the links with the actuator masses and the rotors"
    else:
        where = "the links with the actuator masses and the rotors of the joints placed in the impact"
    return [
        f"Why: the impact phase m_f v0, set by {where}, carries {_g(share_worst, 3)} % of the worst sample's "
        f"impulse and {_g(share_all, 3)} % of all samples'; the motors, gears and controller set only the rest, "
        "so actuator mass buys almost nothing here"
        + (
            " and what it adds to the links only raises the impact: the lightest actuators that meet the "
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
        f"The lightest within {_g(100 * within)} % of the best {words(impulse)}: Pareto design {index}, "
        f"{_g(chosen['actuator_mass'])} kg at {_g(chosen[impulse])} N·s ({_g(above, 2)} % above the best)."
    )


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


MAX_LINES = 10
"""The verdict's length: what to build, how sure, what sizes it, what the bounds decide, the front, warnings."""


def verdict(results: Mapping[str, Any]) -> list[str]:
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
    lines += front_verdict(results["pareto"], recommended, resolved)
    lines += transmission_choice_sentences(results.get("transmission_choice"))
    warnings = verdict_warnings(results, recommended, bounds, catalogue)
    room = MAX_LINES - len(lines)
    if len(warnings) > room:
        rest = [w.removeprefix("Warning: ").removeprefix("WARNING: ") for w in warnings[max(room - 1, 0) :]]
        warnings = [*warnings[: max(room - 1, 0)], "Warnings: " + " ".join(rest)]
    return lines + warnings


def _runs(named: Sequence[tuple[str, str]]) -> list[tuple[list[str], str]]:
    """``(joint, text)`` pairs with consecutive joints of the same text gathered: ``([joints], text)``."""
    runs: list[tuple[list[str], str]] = []
    for name, text in named:
        if runs and runs[-1][1] == text and name and runs[-1][0]:
            runs[-1][0].append(name)
        else:
            runs.append(([name] if name else [], text))
    return runs


def _grouped(joints: Sequence[Mapping[str, Any]], text: Any) -> str:
    """``text(joint)`` per run of consecutive joints that it describes alike, named by :func:`group_name`."""
    runs = _runs([(joint["joint"], text(joint)) for joint in joints])
    return "; ".join(f"{group_name(names)}: {said}" for names, said in runs)


def _sensing(record: Mapping[str, Any]) -> str:
    unit = "N" if record["sensing"] == "force" else "m (position error)"
    return (
        f"threshold {_g(record['threshold'])} {unit}, approach velocity {_g(record['approach_velocity'])} m/s"
    )


def _motor(joint: Mapping[str, Any]) -> str:
    return (
        f"{_g(joint['stator_diameter'] * 1e3, 3)} mm × {_g(joint['stack_length'] * 1e3, 3)} mm motor at "
        f"N = {_g(joint['gear_ratio'])}"
    )


def build_sentences(recommended: Mapping[str, Any], catalogue: Mapping[str, Any] | None) -> list[str]:
    """What to build: the catalogue design when there is one, then the continuous optimum it was snapped from."""
    objectives = recommended["objectives"]
    worst = (recommended.get("worst_case") or {}).get("domain", objectives.get("worst_case_impulse"))
    figures = ", ".join(
        f"{name} {_g(value)} {unit}"
        for name, value, unit in (
            ("worst-case impulse", worst, "N·s"),
            ("mean impulse", objectives.get("mean_impulse"), "N·s"),
            ("actuator mass", objectives.get("actuator_mass"), "kg"),
        )
        if value is not None
    )
    source = str(recommended.get("source", "optimum"))
    continuous = f"{_grouped(recommended['joints'], _motor)}; {_sensing(recommended)} ({figures})"
    if catalogue is None:
        return [f"Build: the continuous optimum ({source}): {continuous}. Its motors are scaled, not sold."]
    if catalogue.get("design") is None:
        return [
            f"No design built from catalogue parts meets the requirements: the continuous optimum ({source}) is "
            f"the best design, with scaled motors: {continuous}."
        ]
    design = catalogue["design"]
    undecided = {e["joint"] for e in design.get("undecided", ()) if e["variable"] == "gear_ratio"}

    def part(joint: Mapping[str, Any]) -> str:
        return (
            f"{joint['motor']}"
            + (f" + {joint['gearbox']}" if joint["gearbox"] else "")
            + f" at N = {_g(joint['gear_ratio'])}"
            + (" (a ratio no objective decides: the solver's start)" if joint["joint"] in undecided else "")
        )

    changes = ", ".join(
        f"{words(name)} {'+' if change >= 0 else '−'}{_percent(abs(change) * 100)} %"
        for name in ("worst_case_impulse", "actuator_mass")
        if (change := catalogue["relative_difference"].get(name)) is not None
    )
    values = catalogue["objectives"]
    return [
        f"Build from catalogue parts: {_grouped(catalogue['joints'], part)}; {_sensing(design)}: worst impulse "
        f"over the samples {_g(values['worst_case_impulse'])} N·s, actuator mass {_g(values['actuator_mass'])} "
        f"kg ({changes} against the continuous optimum).",
        f"Continuous optimum ({source}): {continuous}.",
    ]


def certainty_sentences(record: Mapping[str, Any], exchanged: bool = True) -> list[str]:
    """How sure the recommended design's worst case is (its search), and its check on fresh samples."""
    worst = record.get("worst_case")
    lines = []
    if worst:
        search = worst.get("searched")
        if search is None:
            lines.append(
                f"Worst case {_g(worst['sampled'])} N·s over the samples only: no search of the contact domain "
                "ran, so it is a sampled value, not a bound."
            )
        elif worst["certified"]:
            lines.append(
                f"Worst case {_g(worst['domain'])} N·s, certified over the contact domain: {search['starts']} "
                f"local searches found nothing more than {_g(100 * worst['tolerance'], 2)} % above the samples' "
                "worst case."
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
                f"Warning: worst case NOT certified: the search found {_g(worst['domain'])} N·s, "
                f"{_percent(100 * excess)} % above the samples' {_g(worst['sampled'])} N·s; take it as a worst "
                f"case found, not a bound; {remedy}."
            )
    fresh = record.get("fresh")
    if fresh and fresh.get("largest") is not None and worst:
        bound = float(worst["domain"])
        mean = fresh["statistics"]["mean_impulse"]
        check = (
            f"WARNING: largest {_g(fresh['largest'])} N·s, {_percent(100 * (fresh['largest'] / bound - 1))} % "
            "above the worst case, which is therefore not a bound"
            if fresh["exceeds"]
            else f"largest {_g(fresh['largest'])} N·s, within the worst case"
        )
        lines.append(
            f"On {fresh['configurations']:,} fresh configurations it was not optimised on: {check}; mean "
            f"{_g(mean['value'])} N·s (± {_percent(100 * mean['relative_error'])} %)."
        )
    return lines


def sized_by_sentences(record: Mapping[str, Any], requirement: str) -> list[str]:
    """What sizes each joint (or module): the requirement whose constraint is active, in one sentence."""

    def active(joint: Mapping[str, Any]) -> str:
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
    return [f"Sized by ({requirement}): {_grouped(sized, active)}."]


def bound_sentences(record: Mapping[str, Any], bounds: Mapping[str, Any]) -> list[str]:
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
            if position in ("lower", "upper"):
                value = f"{_g(joint[key])}{UNDECIDED_UNITS.get(key, '')}"
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


def design_limits_at_bound(record: Mapping[str, Any], bounds: Mapping[str, Any]) -> list[str]:
    """The threshold and approach velocity where a bound holds them (undecided ones are said elsewhere)."""
    undecided = {entry["variable"] for entry in record.get("undecided", ()) if entry["joint"] is None}
    units = {"threshold": " N" if record.get("sensing") == "force" else " m", "approach_velocity": " m/s"}
    return [
        f"{words(key)} at its {position} bound ({_g(record[key])}{units[key]})"
        for key in ("threshold", "approach_velocity")
        if key not in undecided
        and (position := bound_position(record[key], bounds[key])) in ("lower", "upper")
    ]


def front_verdict(
    pareto: Mapping[str, Any], record: Mapping[str, Any], resolved: Mapping[str, Any]
) -> list[str]:
    """The front in one sentence: its spans (or why it is flat or one design) and its lightest good design."""
    lines = front_sentences(pareto)
    reason = flat_impulse_reason(pareto, record, resolved)
    near = lightest_near_best(pareto)
    said = " ".join(lines + reason + ([near[1]] if near else []))
    return [said] if said else []


def verdict_warnings(
    results: Mapping[str, Any],
    record: Mapping[str, Any],
    bounds: Mapping[str, Any] | None,
    catalogue: Mapping[str, Any] | None,
) -> list[str]:
    """Every warning of the verdict: oversized joints, uncertain statistics, Pareto designs the checks fail."""
    warnings = oversized_warnings(record, bounds) if bounds is not None else []
    pareto = results["pareto"]
    warnings += statistics_warnings(record, results.get("resolved") or {}, pareto)
    uncertified = [
        str(point.get("label", i))
        for i, point in enumerate(pareto.get("points", ()))
        if (point.get("worst_case") or {}).get("searched") and not point["worst_case"]["certified"]
    ]
    if uncertified:
        warnings.append(
            "Warning: the worst case of Pareto designs " + "; ".join(uncertified) + " is not certified."
        )
    if catalogue:
        warnings += _joint_warnings(catalogue["warnings"])
    # Where the simulator validates neither placement of the reflected inertia (the study's transmissions).
    warnings += [str(line) for line in results.get("transmissions", ()) if str(line).startswith("Warning")]
    return warnings


def _joint_warnings(texts: Sequence[str]) -> list[str]:
    """``joint: what`` warnings, those that say the same of consecutive joints said once."""
    named = [
        (name, what) if sep else ("", text) for text in texts for name, sep, what in [text.partition(": ")]
    ]
    return [f"Warning: {group_name(names) + ': ' if names else ''}{what}." for names, what in _runs(named)]


def transmission_choice_sentences(tried: Sequence[Mapping[str, Any]] | None) -> list[str]:
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
    runner_up = f"; the next best {_g(min(others), 4)}" if others else ""
    return [
        f"Transmission: {where}, the best of {len(tried)} assignments of the gearbox options by the study's "
        f"objective ({_g(chosen['objective'], 4)}{runner_up})."
    ]


__all__ = [
    "bound_position",
    "bound_sentences",
    "build_sentences",
    "certainty_sentences",
    "domain_sentence",
    "front_sentences",
    "lightest_near_best",
    "objective_spans",
    "oversized_warnings",
    "requirement_sentence",
    "sized_by_sentences",
    "statistics_rows",
    "statistics_warnings",
    "verdict",
    "worst_pose_sentence",
]
