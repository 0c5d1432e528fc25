"""A run's result files, written from its results (plain data).

The files are ``designs.json``, ``pareto.csv``, figures (PNG and SVG), ``report.html`` and optionally
``report.pdf``. :func:`render_report` redoes the figures and the report from a folder's saved ``designs.json``
alone.
"""

from __future__ import annotations

import contextlib
import csv
import math
import os
import re
import time
import warnings
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any, TypeVar

from .._interrupt import interruptible
from .._io import atomic_open, read_json
from ..errors import CollisionReflexError
from ..record.checked import ResultsDamaged
from ..record.read import read_run_record
from ..record.run import ActuatorRunRecord, RunRecord
from .figures import draw_figures
from .files import (
    DESIGNS,
    PARETO,
    REPORT,
    TIMINGS,
    write_json,
    write_text,
)
from .html import render_html
from .pdf import html_to_pdf


def pareto_rows(results: RunRecord) -> list[dict[str, Any]]:
    """The rows of ``pareto.csv``.

    One row per Pareto design (arm studies; the chosen design if there is no front) or per candidate actuator
    (actuator studies).
    """
    from ..optimize.results import record_row  # lazy: casadi

    if results["kind"] == "actuator":
        return _actuator_rows(results)
    points = results["pareto"]["points"] or [results["chosen"]]
    rows = [record_row(record, index) for index, record in enumerate(points)]
    # Wall times are not results (see TIMING_KEYS): the report's solver table shows them.
    return [{k: v for k, v in row.items() if k.split(" [")[0] not in TIMING_KEYS} for row in rows]


def _actuator_rows(results: ActuatorRunRecord) -> list[dict[str, Any]]:
    candidates = results["candidates"]
    rows = []
    for candidate in candidates:
        rows.append(
            {
                "actuator": candidate["name"],
                "motor": candidate["motor"],
                "gear_ratio [-]": candidate["gear_ratio"],
                "mass [kg]": candidate["mass"],
                "reflected_inertia [kg*m^2]": candidate["reflected_inertia"],
                "peak_torque [N*m]": candidate["peak_torque"],
                "threshold [N]": candidate["contact"]["F_s"],
                "impulse_at_v0 [N*s]": candidate["impulse"]["total"],
                "optimal_velocity [m/s]": candidate["optimal_velocity"],
                "minimum_impulse [N*s]": candidate["minimum_impulse"],
                "pareto_optimal": candidate["pareto_optimal"],
            }
        )
    return rows


TIMING_KEYS = frozenset({"solve_time", "build_time", "search_time"})
"""Wall times in the results [s]: kept in ``timings.json``, so that the other result files are the same bytes
for the same study on every executor and machine load."""


T = TypeVar("T")

STAGES = "stages"
"""The prefix of the stage times in ``timings.json``: ``stages/<stage>/wall`` and ``stages/<stage>/cpu`` [s]."""


class StageTimes:
    """The wall and CPU time of each stage of a run [s], for ``timings.json`` (see :data:`STAGES`).

    CPU time is this process's (the work a pool's workers do is not in it); on a loaded machine it is steadier
    than wall time. A stage timed twice adds up.
    """

    def __init__(self) -> None:
        self.times: dict[str, float] = {}

    @contextlib.contextmanager
    def stage(self, name: str) -> Iterator[None]:
        """Time the body of the ``with`` block as stage ``name``; a Ctrl-C in it is never lost (:mod:`.._interrupt`)."""
        wall, cpu = time.perf_counter(), time.process_time()
        try:
            with interruptible():
                yield
        finally:
            for kind, spent in (("wall", time.perf_counter() - wall), ("cpu", time.process_time() - cpu)):
                key = f"{STAGES}/{name}/{kind}"
                self.times[key] = self.times.get(key, 0.0) + spent

    def timed(self, name: str, function: Callable[..., T]) -> Callable[..., T]:
        """``function``, each call timed as stage ``name``."""

        def call(*args: Any, **kwargs: Any) -> T:
            with self.stage(name):
                return function(*args, **kwargs)

        return call


def write_outputs(
    folder: str | os.PathLike[str],
    results: RunRecord,
    figures: bool = True,
    stages: StageTimes | None = None,
) -> Path:
    """Write ``designs.json``, ``pareto.csv``, ``timings.json`` and the report (with its figures) into ``folder``.

    ``timings.json`` holds the solver times and, last, the times of ``stages`` with those of writing the
    result files, drawing the figures and writing the report.
    """
    folder = Path(folder)
    stages = stages if stages is not None else StageTimes()
    numbers, timings = split_timings(results)
    with stages.stage("result files"):
        write_json(folder / DESIGNS, numbers)
        write_json(folder / TIMINGS, timings)
        _write_csv(folder / PARETO, pareto_rows(results))
    report = render_report(folder, results, figures=figures, stages=stages)
    write_json(folder / TIMINGS, {**timings, **stages.times})
    return report


def split_timings(data: Any, at: str = "") -> tuple[Any, dict[str, float]]:
    """``data`` without its wall times, and those times by their path (``pareto/points/0/solver/solve_time``)."""
    timings: dict[str, float] = {}
    if isinstance(data, dict):
        kept = {}
        for key, value in data.items():
            if key in TIMING_KEYS and isinstance(value, (int, float)):
                timings[f"{at}{key}"] = value
            else:
                kept[key], inner = split_timings(value, f"{at}{key}/")
                timings.update(inner)
        return kept, timings
    if isinstance(data, list):
        if all(isinstance(value, (int, float)) for value in data):
            return data, timings  # a per-sample array: no times inside
        items = []
        for index, value in enumerate(data):
            item, inner = split_timings(value, f"{at}{index}/")
            items.append(item)
            timings.update(inner)
        return items, timings
    return data, timings


def with_timings(data: Any, timings: dict[str, float]) -> Any:
    """``data`` with the times of :func:`split_timings` put back (paths that no longer exist are skipped).

    A solver record without its times (``timings.json`` deleted) gets None: the report prints "–".
    """
    _unknown_timings(data)
    for path, value in timings.items():
        *parents, key = path.split("/")
        node = data
        for part in parents:
            try:
                node = node[int(part)] if isinstance(node, list) else node[part]
            except (KeyError, IndexError, ValueError, TypeError):
                break
        else:
            if isinstance(node, dict):
                node[key] = value
    return data


def _write_csv(path: Path, rows: list[dict[str, Any]]) -> None:
    """``rows`` as CSV: every key of any row a column (in order of appearance), a missing or None value empty.

    Written with the standard library, as pandas' ``DataFrame(rows).to_csv(index=False, float_format="%.10g")``
    writes these rows (the same bytes for the shipped studies' results), without the cost of importing pandas
    in a study run.
    """
    columns = list(dict.fromkeys(key for row in rows for key in row))
    with atomic_open(path, "w", newline="", encoding="utf-8") as handle:
        writer = csv.writer(handle, lineterminator="\n")
        writer.writerow(columns)
        writer.writerows([_csv_text(row.get(column)) for column in columns] for row in rows)


def _csv_text(value: Any) -> str:
    """One CSV cell: floats to 10 significant digits, NaN and None empty, anything else as ``str`` gives it."""
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return ""
    if isinstance(value, float):
        return f"{value:.10g}"
    return str(value)


def _unknown_timings(data: Any) -> None:
    """Set every solver record's times to None (unknown), in place."""
    if isinstance(data, dict):
        solver = data.get("solver")
        if isinstance(solver, dict):
            for key in TIMING_KEYS:
                solver.setdefault(key, None)
        for value in data.values():
            _unknown_timings(value)
    elif isinstance(data, list):
        for value in data:
            _unknown_timings(value)


def render_report(
    folder: str | os.PathLike[str],
    results: RunRecord | None = None,
    figures: bool = True,
    stages: StageTimes | None = None,
) -> Path:
    """Redraw the figures and rewrite the report from the results saved in ``folder``.

    Writes ``report.html`` (and ``report.pdf`` if the study asks); ``stages`` gets the times of the figures,
    the HTML and the PDF.

    Raises
    ------
    ResultsMissing
        ``folder`` has no readable ``designs.json``.
    ResultsDamaged
        A field the report draws from is missing or damaged (the message names the file and the field).
    """
    import jinja2  # lazily, like every heavy library: importing the package stays quick

    folder = Path(folder)
    stages = stages if stages is not None else StageTimes()
    saved = results is None
    if results is None:
        results = _read_results(folder)
    try:
        with stages.stage("figures"):
            svgs = _figures(folder, results, figures)
        with stages.stage("report"):
            html = render_html(results, pareto_rows(results), svgs)
        pdf = bool(results["resolved"]["outputs"]["pdf"])
    except ResultsDamaged as error:
        raise ResultsDamaged(f"{folder / DESIGNS}: {error}; run the study again") from None
    except (
        AttributeError,
        ArithmeticError,
        LookupError,
        TypeError,
        ValueError,
        jinja2.TemplateError,
    ) as error:
        if not saved:
            raise  # results handed over by a run: a defect, not a damaged file
        raise ResultsDamaged(f"{folder / DESIGNS}: {_unusable(error)}; run the study again") from None
    write_text(folder / REPORT, html)
    if pdf:
        try:
            with stages.stage("pdf"):
                html_to_pdf(folder / REPORT, folder / "report.pdf")
        except CollisionReflexError as error:
            warnings.warn(f"report.pdf not written: {error}", stacklevel=2)
    return folder / REPORT


def _read_results(folder: Path) -> RunRecord:
    """The results saved in ``folder``: ``designs.json``, checked against its type, with ``timings.json``'s times."""
    results = read_run_record(folder / DESIGNS)
    timings_path = folder / TIMINGS
    try:
        timings = read_json(timings_path) if timings_path.exists() else {}
    except ValueError as error:
        raise ResultsDamaged(f"{timings_path} cannot be read ({error}); run the study again") from None
    return with_timings(results, timings if isinstance(timings, dict) else {})


def _figures(folder: Path, results: RunRecord, figures: bool) -> dict[str, str]:
    return (
        draw_figures(folder / "figures", results, results["resolved"]["outputs"]["figures"])
        if figures
        else {}
    )


def _unusable(error: Exception) -> str:
    """What a render error says about the saved results, on one line."""
    import jinja2  # lazy, as in render_report

    if isinstance(error, KeyError):
        return f"field {error.args[0]!r} is missing"
    found = re.search(r"has no attribute '([^']+)'", str(error))
    if isinstance(error, jinja2.UndefinedError) and found:
        return f"field {found.group(1)!r} is missing"
    text = " ".join(str(error).split())
    return f"a field holds a value of the wrong kind ({type(error).__name__}: {text[:120]})"
