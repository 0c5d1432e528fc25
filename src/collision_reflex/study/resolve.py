"""The resolved study: every default explicit, every quantity a number in SI units, paths absolute.

It is what a run actually used; it is written to the output folder, and its fingerprint decides whether a
restarted run may reuse finished results. A run resolves its study once (:class:`ResolvedStudy`: the validated
study, its resolved data and text, and the fingerprint), and every part of the run, in any process, takes that
object.
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import dataclass
from typing import Any

import yaml

from .load import LoadedStudy, study_from_data
from .quantities import joint_position_si
from .schema import ArmStudy, Study

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
        catalogue = data["catalogue"]
        for kind in ("motors", "gearboxes"):
            if catalogue[kind] is not None:
                catalogue[kind] = str(loaded.path(catalogue[kind]))
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
    return _as_yaml(resolved_study(loaded))


def _as_yaml(resolved: dict[str, Any]) -> str:
    body = yaml.safe_dump(resolved, sort_keys=False, default_flow_style=None, width=110)
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


@dataclass(frozen=True, eq=False)
class ResolvedStudy:
    """A study as a run solves it, resolved once.

    loaded: the validated resolved study (paths absolute; relative ones of the file's other sections resolve
    against the study file's folder); data: it as plain data (:func:`resolved_study`); text: it as YAML, what
    ``study.resolved.yaml`` holds; fingerprint: :func:`fingerprint` of the data it was made from (as a gearbox
    option was assigned, before validation fills in defaults: a finished run's fingerprint stays valid). Equal (and
    hashed) by its text: the problems a process builds are cached by it. Picklable: a process pool's or a Dask
    cluster's workers receive it as it is.
    """

    loaded: LoadedStudy
    data: dict[str, Any]
    text: str
    fingerprint: str

    @classmethod
    def of(cls, loaded: LoadedStudy, data: dict[str, Any] | None = None) -> ResolvedStudy:
        """``loaded`` resolved, or ``data``: resolved data derived from it (shrunk, a gearbox option assigned).

        The data are validated as they are (no YAML between); problems are told at ``loaded``'s file.
        """
        data = resolved_study(loaded) if data is None else data
        validated = study_from_data(data, loaded.source.file, loaded.directory)
        resolved = resolved_study(validated)
        return cls(validated, resolved, _as_yaml(resolved), fingerprint(data))

    @property
    def study(self) -> Study:
        """The validated study."""
        return self.loaded.study

    def __eq__(self, other: object) -> bool:
        return isinstance(other, ResolvedStudy) and other.text == self.text

    def __hash__(self) -> int:
        return hash(self.text)


def resolve_study(loaded: LoadedStudy, smoke: bool = False) -> ResolvedStudy:
    """The study a run of ``loaded`` solves; with ``smoke``, shrunk for a quick run (:func:`smoke_study`)."""
    return ResolvedStudy.of(loaded, smoke_study(resolved_study(loaded)) if smoke else None)


def smoke_study(data: dict[str, Any]) -> dict[str, Any]:
    """A resolved study shrunk for a quick run.

    A few configurations, directions, fresh configurations, Pareto points and velocities, and a lighter
    worst-case search. The shrunk study is what the run records as its resolved study.
    """
    data = {**data}
    if data.get("kind") == "actuator":
        data["velocities"] = {**data["velocities"], "count": min(data["velocities"]["count"], 12)}
        return data
    samples = {**data["samples"]}
    configurations = {**samples["configurations"]}
    if configurations.get("random"):
        configurations["random"] = {
            **configurations["random"],
            "count": min(configurations["random"]["count"], 3),
        }
    if configurations.get("list"):
        configurations["list"] = configurations["list"][:2]
    if configurations.get("trajectory"):
        configurations["trajectory"] = {
            **configurations["trajectory"],
            "every": max(configurations["trajectory"]["every"], 50),
        }
    directions = {**samples["directions"]}
    for key in ("circle", "sphere"):
        if directions.get(key):
            directions[key] = min(directions[key], 6)
    for key in ("named", "list"):
        if directions.get(key):
            directions[key] = directions[key][:4]
    data["samples"] = {
        **samples,
        "configurations": configurations,
        "directions": directions,
        "fresh": min(samples.get("fresh", 0), 64),
    }
    optimizer = {**data.get("optimizer", {})}
    search = {**optimizer.get("worst_case_search", {})}
    if search:  # a lighter search: a few starts, two rounds
        search.update(
            starts=min(search["starts"], 3),
            random_starts=min(search["random_starts"], 2),
            rounds=min(search["rounds"], 2),
        )
        data["optimizer"] = {**optimizer, "worst_case_search": search}
    data.pop("simulate", None)  # the time-domain simulation is no quick check
    if data.get("pareto"):
        data["pareto"] = {**data["pareto"], "points": min(data["pareto"]["points"], 4)}
    return data
