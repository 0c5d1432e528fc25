"""The resolved study: every default explicit, every quantity a number in SI units, paths absolute.

It is what a run actually used; it is written to the output folder, and its fingerprint decides whether a
restarted run may reuse finished results.
"""

from __future__ import annotations

import hashlib
import json
from typing import Any

import yaml

from .load import LoadedStudy
from .quantities import joint_position_si
from .schema import ArmStudy

UNITS_NOTE = "All quantities in SI units: m, kg, s, N, N*m, N*m/rad, rad, m/s (joint positions with theirs)."


def resolved_study(loaded: LoadedStudy) -> dict[str, Any]:
    """The study as plain data (JSON types), defaults filled in, quantities in SI, relative paths resolved."""
    data = loaded.study.model_dump(mode="json")
    if isinstance(loaded.study, ArmStudy):
        robot = data["robot"]
        if robot["urdf"] is not None:
            robot["urdf"] = str(loaded.path(robot["urdf"]))
        robot["package_dirs"] = [str(loaded.path(p)) for p in robot["package_dirs"]]
        trajectory = data["samples"]["configurations"]["trajectory"]
        if trajectory is not None:
            trajectory["file"] = str(loaded.path(trajectory["file"]))
        cycle = data["duty_cycle"]
        if cycle is not None and cycle["file"] is not None:
            cycle["file"] = str(loaded.path(cycle["file"]))
        for path in JOINT_POSITION_PATHS:
            _with_units(data, loaded.source.data, path)
    return data


JOINT_POSITION_PATHS = (("samples", "configurations", "list"), ("duty_cycle", "via"))
"""Where a study lists joint positions (rows of one position per joint)."""


def at_path(data: Any, path: tuple[str, ...]) -> Any:
    """The node of plain YAML data at ``path`` (mapping keys), or None where the path leaves the data."""
    for key in path:
        data = data.get(key) if isinstance(data, dict) else None
    return data


def _with_units(data: dict[str, Any], source: Any, path: tuple[str, ...]) -> None:
    """Write the joint positions at ``path`` with their units (a study file refuses bare ones): SI, as given."""
    rows, written = at_path(data, path), at_path(source, path)
    if not rows:
        return
    for row, written_row in zip(rows, written, strict=True):
        for j, (value, text) in enumerate(zip(row, written_row, strict=True)):
            row[j] = f"{value!r} {joint_position_si(text)[1]}"


def resolved_yaml(loaded: LoadedStudy) -> str:
    """:func:`resolved_study` as YAML, in the schema's field order, with a comment on units."""
    body = yaml.safe_dump(resolved_study(loaded), sort_keys=False, default_flow_style=None, width=110)
    return f"# Resolved study: every default explicit. {UNITS_NOTE}\n{body}"


def fingerprint(
    resolved: dict[str, Any], ignore: tuple[str, ...] = ("execution", "outputs", "description", "simulate")
) -> str:
    """A hash of what determines a run's numbers (execution settings and outputs do not).

    ``simulate`` does not either: its pieces are keyed by their own settings, so that a finished run can be
    simulated afterwards without solving again.
    """
    relevant = {key: value for key, value in resolved.items() if key not in ignore}
    text = json.dumps(relevant, sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode()).hexdigest()[:16]
