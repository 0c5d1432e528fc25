"""The report's assumptions table: the study as run, in rows of part, assumption, value with unit, source."""

from __future__ import annotations

from typing import Any

from ..hardware.motors import get_motor, scaling_law
from ..record.run import RunRecord
from .wording import mm, number, shown_path, unit

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
    "mass": "kg",
    "joint_speeds": "rad/s",
    "joint_accelerations": "rad/s^2",
    "stopping_time": "s",
    "max_speed": "rad/s",
    "max_acceleration": "rad/s^2",
    "dwell": "s",
    "rate": "Hz",
    "min_singular_value": "m",
    "joint_speed_limit": "rad/s",
}
"""The SI unit of a resolved study's fields, by field name (a field inherits its section's)."""


ASSUMPTION_GROUPS = {
    "robot": "robot",
    "actuators": "actuators",
    "sensing": "sensing",
    "samples": "contact samples",
    "rating": "rating",
    "duty_cycle": "duty cycle",
    "design": "design bounds",
    "constraints": "constraints",
    "objective": "objective",
    "pareto": "Pareto front",
    "simulate": "simulation",
}
"""The resolved study's sections as the assumptions table names them (the others, the optimiser's, the
catalogue snap's and the executor's settings, are in ``study.resolved.yaml``)."""

_MILLIMETRES = {"stator_diameter", "stack_length", "contact_offset"}


def assumption_rows(results: RunRecord) -> list[tuple[str, str, str, str]]:
    """The study as run, as (part, assumption, value with unit, source) rows a designer reads.

    Empty fields are left out, a per-joint mapping that holds the same value for every joint is one row,
    motor sizes are in mm, and the model's own assumptions (the impulse model, the motor scaling and speed
    laws, the transmissions) carry their sources.
    """
    resolved = results["resolved"]
    rows: list[tuple[str, str, str, str]] = []
    catalogue = results.get("catalogue") if results["kind"] == "arm" else None
    cited = {j["motor"] for j in catalogue["joints"]} if catalogue else set()
    for key, group in ASSUMPTION_GROUPS.items():
        value = resolved.get(key)
        if key == "objective" and isinstance(value, dict):
            value = " + ".join(f"{number(w)} × {str(n).replace('_', ' ')}" for n, w in value.items())
        for field, text in _flattened(value, "", UNITS.get(key, "")):
            source = "cited with the catalogue parts" if text in cited else _source(key, field, resolved)
            rows.append((group, field or key.replace("_", " "), text, source))
    model = (
        [
            (
                "impulse",
                f"closed form, reaction from rest ({resolved.get('reaction', 'at_rest')}), rotors "
                + (
                    "in the impact"
                    if resolved.get("reflected_inertia_in") == "finger"
                    else "behind the joint springs"
                )
                + " unless a joint says otherwise",
                "Bhatia, Mason and Johnson, Reacting to Contact: Transparency and Collision Reflex in Actuation",
            ),
            ("contact", "rigid object, plastic impact (restitution 0)", ""),
        ]
        if results["kind"] == "arm"
        else []
    )
    actuators = resolved.get("actuators") or {}
    geared = actuators.get("gearbox") or any(
        j.get("gearbox") for j in (actuators.get("joints") or {}).values()
    )
    if actuators.get("gearbox_inertia") is False and geared:
        model.append(
            (
                "gearbox inertia",
                "Gearbox inertia ignored, as in the paper: the reflected inertia is the rotor's alone, N² J_m",
                "",
            )
        )
    notes = [results["speed_limits"], *results["transmissions"]] if results["kind"] == "arm" else []
    for note in notes:
        if note and not note.startswith("Warning"):
            label, _, said = note.partition(": ")
            model.append((label.lower(), said, ""))
    return [("model", *row) for row in model] + rows


def _source(section: str, field: str, resolved: dict[str, Any]) -> str:
    """The source of a resolved study's field where the toolkit knows it (a catalogue entry, a scaling law)."""
    if section == "constraints" and field == "body region":
        return "ISO/TS 15066:2016 Annex A, rotors on links"
    if section != "actuators":
        return ""
    motor = (resolved.get("actuators") or {}).get("motor") or {}
    try:
        if field == "motor.reference":
            return get_motor(str(motor["reference"])).source
        if field == "motor.scaling law":
            return scaling_law(str(motor["scaling_law"])).source
    except (KeyError, ValueError, LookupError, OSError):
        return ""
    return ""


def _flattened(value: Any, prefix: str, unit_name: str) -> list[tuple[str, str]]:
    """(field, text) rows of one study section; see :func:`assumption_rows`."""
    if value is None or value == {} or value == []:
        return []
    if isinstance(value, dict):
        if set(value) >= {"min", "max"} and not isinstance(value["min"], dict):
            low, high = (_shown(value[key], unit_name, prefix) for key in ("min", "max"))
            if " " in high and low.endswith(high.split(" ", 1)[1]):
                low = low.split(" ", 1)[0]  # the unit once: "30 to 160 mm"
            rows = [(prefix, f"{low} to {high}")]
            joints = value.get("joints") or {}
            return rows + [
                row
                for name, bounds in joints.items()
                for row in _flattened(bounds, f"{prefix}, {name}", unit_name)
            ]
        items = [(k, v) for k, v in value.items() if v is not None and v != {} and v != []]
        if (
            len(items) >= 2
            and all(isinstance(v, dict) for _, v in items)
            and _all_equal([v for _, v in items])
        ):
            return _flattened(items[0][1], f"{prefix}, each of {len(items)}".strip(", "), unit_name)
        if prefix and items and all(not isinstance(v, (dict, list)) for _, v in items):
            if len(items) >= 2 and _all_equal([v for _, v in items]):
                return [
                    (
                        prefix,
                        _shown(items[0][1], UNITS.get(str(items[0][0]), unit_name), prefix)
                        + f" (each of {len(items)})",
                    )
                ]
            return [
                (
                    prefix,
                    ", ".join(
                        f"{str(k).replace('_', ' ')} {_shown(v, UNITS.get(str(k), unit_name), str(k))}"
                        for k, v in items
                    ),
                )
            ]
        rows = []
        for key, item in items:
            field = f"{prefix}.{key}" if prefix else str(key)
            rows += _flattened(item, field.replace("_", " "), UNITS.get(str(key), unit_name))
        return rows
    if isinstance(value, list):
        if all(isinstance(v, list) for v in value) and all(
            isinstance(x, (int, float)) for v in value for x in v
        ):
            zero = all(x == 0 for v in value for x in v)
            return [] if zero else [(prefix, f"{len(value)} × {len(value[0]) if value else 0} matrix")]
        if all(isinstance(v, (int, float, str)) and not isinstance(v, bool) for v in value):
            if len(value) > 8:
                return [(prefix, f"{len(value)} values")]
            return [(prefix, ", ".join(_shown(v, unit_name, prefix) for v in value))]
        if len(value) > 4:
            return [(prefix, f"{len(value)} {prefix.rsplit('.', 1)[-1]} entries")]
        return [
            row for i, item in enumerate(value) for row in _flattened(item, f"{prefix}[{i + 1}]", unit_name)
        ]
    return [(prefix, _shown(value, unit_name, prefix))]


def _all_equal(values: list[Any]) -> bool:
    return all(v == values[0] for v in values[1:])


def _shown(value: Any, unit_name: str, field: str) -> str:
    """One value with its unit; motor sizes in mm, local paths as file names."""
    if isinstance(value, str):
        return shown_path(value)
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return "–" if value is None else str(value)
    if any(
        field.endswith(name.replace("_", " ")) or name.replace("_", " ") in field for name in _MILLIMETRES
    ):
        return f"{mm(value)} mm"
    return number(value) + (f" {unit(unit_name)}" if unit_name else "")
