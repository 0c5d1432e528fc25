"""The HTML sizing report: one self-contained page (inline CSS and SVG, no scripts, no network)."""

from __future__ import annotations

import math
import re
import statistics
from pathlib import PurePath
from typing import Any

from .. import __version__

SOLVER_TOLERANCE = 1e-5
"""Relative tolerance to which the report trusts the optimiser's numbers (that of
:data:`collision_reflex.optimize.pareto.MERGE_TOLERANCE`): smaller values beside their scale print as 0."""

UNITS = {
    "stator_diameter": "m",
    "stack_length": "m",
    "mechanical_stiffness": "N*m/rad",
    "software_stiffness": "N*m/rad",
    "threshold": "N",
    "error": "m",
    "motor_torque": "N*m",
    "approach_velocity": "m/s",
    "payload": "kg",
    "threshold_floor": "N",
    "torque_required": "N*m",
    "contact_offset": "m",
    "lever": "m",
    "finger_mass": "kg",
    "contact_stiffness": "N/m",
    "position_error": "m",
    "list": "rad",
}


def number(value: object, digits: int = 4) -> str:
    """A number with ``digits`` significant digits (the precision every table of the report uses)."""
    if value is None:
        return "–"
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return str(value)
    if math.isinf(value):
        return "∞" if value > 0 else "−∞"
    return f"{value:.{digits}g}"


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


def _shown_path(value: str) -> str:
    """An absolute local path as its file name: a report names no folder of the machine it was made on."""
    path = PurePath(value)
    return path.name if path.is_absolute() or re.match(r"^[A-Za-z]:[\\/]", value) else value


def _assumptions(resolved: dict[str, Any]) -> list[tuple[str, str]]:
    """The resolved study flattened to (field, value with unit) rows."""
    rows: list[tuple[str, str]] = []

    def walk(prefix: str, value: Any, unit: str) -> None:
        if isinstance(value, dict):
            if not value:
                rows.append((prefix, "–"))
            for key, item in value.items():
                walk(f"{prefix}.{key}" if prefix else str(key), item, UNITS.get(str(key), unit))
        elif isinstance(value, list) and value and all(isinstance(v, (int, float)) for v in value):
            rows.append(
                (prefix, "[" + ", ".join(number(v) for v in value) + "]" + (f" {unit}" if unit else ""))
            )
        elif isinstance(value, list) and len(value) > 6 and all(isinstance(v, list) for v in value):
            rows.append((prefix, f"{len(value)} entries"))
        elif isinstance(value, list):
            for index, item in enumerate(value):
                walk(f"{prefix}[{index}]", item, unit)
            if not value:
                rows.append((prefix, "[]"))
        elif isinstance(value, (int, float)) and not isinstance(value, bool):
            rows.append((prefix, number(value) + (f" {unit}" if unit else "")))
        elif isinstance(value, str):
            rows.append((prefix, _shown_path(value)))
        else:
            rows.append((prefix, "–" if value is None else str(value)))

    for key, value in resolved.items():
        if key in ("name", "description"):
            continue
        walk(key, value, UNITS.get(key, ""))
    return rows


def _velocity_summary(record: dict[str, Any]) -> dict[str, float]:
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
    from ..optimize import OBJECTIVES

    return {name: unit for name, (_, unit, _) in OBJECTIVES.items()}


def solved_by(record: dict[str, Any]) -> str:
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


def render_html(results: dict[str, Any], rows: list[dict[str, Any]], svgs: dict[str, str]) -> str:
    """The report page for a run's results; ``rows`` are the rows of ``pareto.csv``."""
    import jinja2

    environment = jinja2.Environment(
        loader=jinja2.PackageLoader("collision_reflex.report", "templates"),
        autoescape=jinja2.select_autoescape(["html", "j2"]),
        undefined=jinja2.StrictUndefined,
        trim_blocks=True,
        lstrip_blocks=True,
    )
    environment.filters["n"] = number
    environment.filters["settled"] = settled
    environment.filters["whole_numbers"] = whole_numbers
    environment.filters["solved_by"] = solved_by
    template = environment.get_template(f"{results['kind']}_report.html.j2")
    context: dict[str, Any] = {
        "results": results,
        "rows": _settled_rows(rows),
        "columns": list(rows[0]) if rows else [],
        "svgs": svgs,
        "assumptions": _assumptions(results["resolved"]),
        "version": __version__,
    }
    if results["kind"] == "arm":
        from .figures import has_duty_cycle
        from .verdict import verdict

        # Redone from the record (the same function wrote designs.json's ``verdict``), so that a report
        # re-rendered from an edited designs.json says what its numbers say.
        context["verdict"] = verdict(results)
        context["duty_cycle"] = has_duty_cycle(results)
        context["objective_units"] = _objective_units()
        context["velocity"] = {
            "chosen": _velocity_summary(results["chosen"]),
            **{str(i): _velocity_summary(p) for i, p in enumerate(results["pareto"]["points"])},
        }
    return template.render(**context)
