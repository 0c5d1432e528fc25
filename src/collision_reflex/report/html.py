"""The HTML sizing report: one self-contained page (inline CSS, SVG and one small script; nothing loaded)."""

from __future__ import annotations

import math
import re
import statistics
from collections.abc import Mapping
from typing import Any

from .. import __version__
from ..plots import margin_text
from ..record.design import DesignRecord, QuickSnap
from ..record.run import (
    ArmRunRecord,
    CatalogueJoint,
    CatalogueRecord,
    HumanContactRecord,
    RunRecord,
    TransmissionTried,
)
from ..vocabulary import GLOBAL_VARIABLES
from .assumptions import UNITS, assumption_rows
from .certainty import domain_sentence, statistics_rows, worst_pose_sentence
from .figures import has_duty_cycle
from .front import front_cards
from .sizing import requirement_sentence
from .verdict import verdict
from .wording import group_name, mm, number, unit

SOLVER_TOLERANCE = 1e-5
"""Relative tolerance to which the report trusts the optimiser's numbers (that of
:data:`collision_reflex.optimize.dominance.MERGE_TOLERANCE`): smaller values beside their scale print as 0."""


def settled(value: object, scale: object = 1.0) -> object:
    """``value``, or 0 where it is solver noise: within :data:`SOLVER_TOLERANCE` of zero relative to ``scale``.

    A margin of ``-9.7e-9`` (a constraint met to the solver's tolerance) or a required torque of ``3.6e-15``
    N·m next to a peak torque of 1.3 N·m are zeros that the optimiser did not round; printed, they read as
    values.
    """
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not isinstance(scale, (int, float)):
        return value
    return 0.0 if abs(value) <= SOLVER_TOLERANCE * abs(scale) else value


def _settled_rows(rows: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """``pareto.csv``'s rows with the solver noise settled.

    Each joint's required torques against its peak torque, and its margins (relative: against 1).
    """
    settled_rows = []
    for row in rows:
        copy = dict(row)
        for column, value in row.items():
            required = _REQUIRED.match(column)
            if required:
                copy[column] = settled(value, row.get(f"peak_torque[{required.group('joint')}] [N*m]"))
            elif _MARGIN.match(column):
                copy[column] = settled(value)
        settled_rows.append(copy)
    return settled_rows


_REQUIRED = re.compile(r"^required_\w*torque\[(?P<joint>.+)\] \[N\*m\]$")
_MARGIN = re.compile(r"^\w*margin\[.+\] \[-\]$")


def margin_cell(value: object) -> Any:
    """A table cell for a margin (:func:`~collision_reflex.plots.margin_text`), red when negative.

    "–" where the joint has no such requirement.
    """
    import markupsafe

    if not isinstance(value, (int, float)) or isinstance(value, bool):
        return markupsafe.Markup("<td>–</td>")
    value = float(settled(value))  # type: ignore[arg-type]
    bad = ' class="bad"' if value < 0 else ""
    return markupsafe.Markup(f"<td{bad}>{markupsafe.escape(margin_text(value))}</td>")


def change(value: object) -> str:
    """A relative difference as a signed percentage (``+9.88 %``), "–" when unknown."""
    if not isinstance(value, (int, float)) or isinstance(value, bool):
        return "–"
    percent = 100 * value
    return (f"{percent:+,.0f} %" if abs(percent) >= 100 else f"{percent:+.3g} %").replace("-", "−")


def gearbox_name(text: object) -> str:
    """A gearbox as the tables name it: its kind and unit, without the scaling note in brackets."""
    return "–" if not text else str(text).split(" (")[0]


def _velocity_summary(record: DesignRecord) -> dict[str, float]:
    v_star = [v for v in record["optimal_velocity"] if math.isfinite(v)]
    v0 = record["approach_velocity"]
    return {
        "v0": v0,
        "min": min(v_star) if v_star else math.inf,
        "median": statistics.median(v_star) if v_star else math.inf,
        "max": max(v_star) if v_star else math.inf,
        "below": sum(v0 < v for v in v_star),
        "count": len(record["optimal_velocity"]),
    }


def _objective_units() -> dict[str, str]:
    """Each optimiser objective's unit, by name (the catalogue section's columns)."""
    from ..optimize import OBJECTIVES  # lazy: casadi

    return {name: unit for name, (_, unit, _) in OBJECTIVES.items()}


def solved_by(record: DesignRecord) -> str:
    """How a design record's solve treated the samples: ``full NLP: all 336 samples``, or an active set.

    ``active set: 72 of 4096 samples``, from its ``solver`` record's ``method`` and ``active_samples``; "–"
    for a record written without them.
    """
    solver = record.get("solver") or {}
    method, active = solver.get("method"), solver.get("active_samples")
    if method is None or active is None:
        return "–"
    total = len(record.get("impulses") or ()) or active
    if method == "active set":
        return f"active set: {active} of {total} samples"
    if method == "full NLP":
        return f"full NLP: all {total} samples"
    return f"full NLP: {method} ({total})"  # e.g. "all samples: the mean impulse ... needs every sample"


# A number with an exponent ("9.25e-06", "2e7") in prose: the browser may break a line after its minus sign.
_PROSE_NUMBER = re.compile(r"\d+(?:\.\d+)?e[+-]?\d+")


def whole_numbers(text: str) -> Any:
    """``text`` escaped for HTML, each number with an exponent kept on one line (a citation's figures)."""
    import markupsafe

    escaped = str(markupsafe.escape(text))
    return markupsafe.Markup(
        _PROSE_NUMBER.sub(lambda m: f'<span class="nowrap">{m.group(0)}</span>', escaped)
    )


def render_html(results: RunRecord, rows: list[dict[str, Any]], svgs: dict[str, str]) -> str:
    """The report page for a run's results; ``rows`` are the rows of ``pareto.csv``."""
    import jinja2

    environment = jinja2.Environment(
        loader=jinja2.PackageLoader("collision_reflex.report", "templates"),
        autoescape=jinja2.select_autoescape(["html", "j2"]),
        undefined=jinja2.StrictUndefined,
        trim_blocks=True,
        lstrip_blocks=True,
    )
    for name, function in {
        "n": number,
        "settled": settled,
        "whole_numbers": whole_numbers,
        "solved_by": solved_by,
        "mm": mm,
        "unit": unit,
        "margin_cell": margin_cell,
        "change": change,
        "gearbox_name": gearbox_name,
    }.items():
        environment.filters[name] = function
    template = environment.get_template(f"{results['kind']}_report.html.j2")
    context: dict[str, Any] = {
        "results": results,
        "rows": _settled_rows(rows),
        "columns": list(rows[0]) if rows else [],
        "svgs": svgs,
        "assumptions": assumption_rows(results),
        "version": __version__,
    }
    if results["kind"] == "arm":
        context.update(_arm_context(results))
    return template.render(**context)


def _arm_context(results: ArmRunRecord) -> dict[str, Any]:
    """What the arm report's sections show beside the record: sentences, table rows, the front's cards."""
    recommended = results.get("recommended") or results["chosen"]
    domain = results.get("domain")
    worst = recommended.get("worst_case")
    search = worst["searched"] if worst else None
    kept = search["domain_kept"] if search else None
    catalogue = results.get("catalogue")
    return {
        # Redone from the record (the same function wrote designs.json's ``verdict``), so that a report
        # re-rendered from an edited designs.json says what its numbers say.
        "verdict": verdict(results),
        "duty_cycle": has_duty_cycle(results),
        "units": _objective_units(),
        "requirement": requirement_sentence(
            str(results.get("requirement", "")), (results.get("resolved") or {}).get("rating")
        ),
        "domain_sentence": domain_sentence(domain, float(recommended["approach_velocity"]), kept)
        if domain and worst
        else None,
        "worst_pose": worst_pose_sentence(recommended),
        "statistics": statistics_rows(recommended),
        "velocity": _velocity_summary(recommended),
        **_front_table(results),
        **_transmission_table(results.get("transmission_choice")),
        "human_contact": _human_contact(results.get("human_contact")),
        "solved": _solved(results),
        "part_sources": _part_sources(catalogue["joints"] if catalogue else []),
        **_tried_table(catalogue),
        "catalogue_modules": any(j.get("module") for j in recommended["joints"]),
        "front_cards": front_cards(results),
    }


def _front_table(results: ArmRunRecord) -> dict[str, Any]:
    """The front's table: per design its objectives, actuator mass, threshold and approach velocity, and snap."""
    from ..optimize import OBJECTIVES  # lazy: casadi

    pareto = results["pareto"]
    names = list(dict.fromkeys([*pareto["objectives"], "actuator_mass"]))
    extra = [key for key in GLOBAL_VARIABLES if key not in names]
    columns = [f"{n.replace('_', ' ')} [{unit(OBJECTIVES[n][1])}]" for n in names] + [
        f"{key.replace('_', ' ')} [{unit(UNITS[key])}]" for key in extra
    ]
    recommended = results.get("recommended")
    index = recommended.get("pareto_index") if recommended else None
    catalogue = results.get("catalogue")
    snaps = catalogue["pareto"] if catalogue else []
    rows = []
    points: list[Mapping[str, Any]] = list(pareto["points"])  # read by the columns' names
    for i, point in enumerate(points):
        snap = snaps[i] if i < len(snaps) else None
        text, ok = _snap_text(snap)
        rows.append(
            {
                "design": f"{i}" + (" (recommended)" if i == index else ""),
                "values": [point["objectives"].get(n) for n in names] + [point[key] for key in extra],
                "snap": text,
                "snap_ok": ok,
            }
        )
    return {"front_columns": columns, "front_rows": rows}


def _snap_text(snap: QuickSnap | None) -> tuple[str, bool]:
    """A Pareto design's quick catalogue snap in a few words, and whether it meets the requirements."""
    if not snap:
        return "–", True
    if snap.get("missing"):
        return "no part within bounds for " + ", ".join(m["joint"] for m in snap["missing"]), False
    said = ", ".join(dict.fromkeys(str(part) for part in snap["parts"]))  # every joint has a part
    if snap["feasible"]:
        return said, True
    shortfalls = list(snap["shortfalls"])
    more = f" (and {len(shortfalls) - 1} more)" if len(shortfalls) > 1 else ""
    return f"{said}; misses {shortfalls[0]}{more}", False


def _human_contact(record: HumanContactRecord | None) -> dict[str, Any] | None:
    """The human-contact section: the record, and its most limiting body region (every region: the figure)."""
    if not record or not record["regions"]:
        return None
    row = min(record["regions"], key=lambda row: row["slowest"])
    limiting = {"region": row["region"].replace("_", " "), "slowest": row["slowest"], "iso": row["iso_speed"]}
    return {**record, "limiting": limiting}


def _transmission_table(tried: list[TransmissionTried] | None) -> dict[str, Any]:
    """Each assignment of the gearbox options tried: the option per group of joints, objective, mass."""
    if not tried:
        return {"transmission_groups": [], "transmission_rows": []}
    groups = list(tried[0]["assignment"])
    rows = [
        {
            "options": [entry["assignment"].get(group, "–") for group in groups],
            "objective": entry["objective"],
            "mass": entry.get("actuator_mass"),
            "outcome": "chosen"
            if entry["chosen"]
            else ("–" if entry["objective"] is not None else entry["status"]),
        }
        for entry in tried
    ]
    return {"transmission_groups": [group_name(g.split(", ")) for g in groups], "transmission_rows": rows}


def _solved(results: ArmRunRecord) -> list[tuple[str, DesignRecord]]:
    """The designs of the solver table: the single-objective optimum, each Pareto design, the catalogue design."""
    solved = [("single-objective optimum", results["chosen"])]
    solved += [(f"Pareto {i}", point) for i, point in enumerate(results["pareto"]["points"])]
    catalogue = results.get("catalogue")
    design = catalogue["design"] if catalogue else None
    if design is not None:
        solved.append(("catalogue design", design))
    return solved


TRIED_SHOWN = 5
"""How many catalogue combinations the report lists, best first (``designs.json`` keeps every one)."""


def _tried_table(catalogue: CatalogueRecord | None) -> dict[str, Any]:
    """The catalogue combinations re-solved, best first: a column per group of joints that always share parts."""
    tried = catalogue["tried"] if catalogue else []
    joints = [j["joint"] for j in catalogue["joints"]] if catalogue else []
    if not tried or not joints:
        return {"tried_groups": [], "tried_rows": [], "tried_count": 0}
    groups: list[list[int]] = []
    for index in range(len(joints)):
        if groups and all(t["parts"][index] == t["parts"][groups[-1][0]] for t in tried):
            groups[-1].append(index)
        else:
            groups.append([index])
    ranked = sorted(tried, key=lambda t: (t["objective"] is None, t["objective"] or 0.0))[:TRIED_SHOWN]
    rows = [
        {
            "parts": [t["parts"][group[0]] for group in groups],
            "objective": t["objective"],
            "outcome": "solved" if t["objective"] is not None else _why_not(str(t["status"])),
        }
        for t in ranked
    ]
    return {
        "tried_groups": [group_name([joints[i] for i in group]) for group in groups],
        "tried_rows": rows,
        "tried_count": len(tried),
    }


def _why_not(status: str) -> str:
    """A refused or failed combination's reason in a few words: the quoted check, or the first shortfall."""
    quoted = re.search(r"'([^']+)'", status)
    if quoted:
        return "refused: " + quoted.group(1)
    first = status.split("; ")[0]
    return first + (")" if "(" in first and not first.endswith(")") else "")


def _part_sources(joints: list[CatalogueJoint]) -> list[tuple[str, str]]:
    """Each catalogue part's source once, with its estimates (a part on several joints is cited once)."""
    sources: dict[str, str] = {}
    for joint in joints:
        for part, source, cited, estimates in (
            (
                joint.get("motor"),
                joint.get("source"),
                joint.get("sources") or {},
                joint.get("estimates") or {},
            ),
            (joint.get("gearbox"), joint.get("gearbox_source"), {}, joint.get("gearbox_estimates") or {}),
        ):
            if not part or not source or part in sources:
                continue
            said = [str(source)]
            said += [f"{field.replace('_', ' ')}: {text}" for field, text in cited.items()]
            if estimates:  # how each was estimated: the catalogue entry (crx motors --catalogue) says
                said.append("estimated: " + ", ".join(field.replace("_", " ") for field in estimates))
            sources[part] = "; ".join(said)
    return list(sources.items())
