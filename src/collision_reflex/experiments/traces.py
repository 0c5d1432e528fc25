"""Force-time traces: the data type, CSV reading and writing, and the checks that make a trace usable.

CSV layout
----------
Leading comment lines ``# key: value`` carry the trial's metadata; then a header and one row per sample::

    # velocity: 100 mm/s
    # system: U8 soft
    # sensor stiffness: 2e7 N/m
    time [ms],force [N]
    0.0,0.013
    ...

- Columns are found by name, case-insensitively: time (``time`` or ``t``), force (``force``, ``fz`` or
  ``f``). A unit in brackets or parentheses (``time [ms]``, ``force (lbf)``) is read with pint; a column
  without one takes the unit given by the caller (default s and N).
- Metadata keys: ``velocity`` (pre-impact velocity; a plain number is m/s), ``system`` (a name used to group
  trials), ``sensor stiffness`` (``k_m``; a plain number is N/m), ``trial`` (a name). Other keys are kept as
  text. Values given by the caller fill in what a file leaves out.
- Many trials in one file: a ``trial`` column names each row's trial; ``velocity [...]``, ``system`` and
  ``sensor stiffness [...]`` columns, when present, give the metadata per trial (constant within a trial).
"""

from __future__ import annotations

import math
import os
import re
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, NoReturn

import numpy as np

from .._io import atomic_open, read_limited
from .._table import HEADER, TableProblem, read_table
from .._units import QuantityError, check_unit, parse_quantity, si_scale
from ..errors import TraceError
from ..vocabulary import TIME_COLUMN_NAMES

if TYPE_CHECKING:
    import pandas as pd

MIN_SAMPLES = 20
"""Fewest samples a trace may have: enough for a noise floor and a contact of a few samples."""

_FORCE_NAMES = ("force", "fz", "f")
_META_COLUMNS = {"velocity": "m/s", "system": None, "sensor stiffness": "N/m"}
_META_TARGETS = {"velocity": "v0", "sensor stiffness": "k_m"}  # metadata key -> Trace field


@dataclass(frozen=True, eq=False)
class Trace:
    """One trial: force samples over time, with what is known about the collision.

    Attributes
    ----------
    time: sample times [s], shape (n,).
    force: contact force [N], shape (n,); positive in compression.
    v0: pre-impact velocity [m/s], or ``None`` if unknown (then the impulse is measured but the model
        is not fitted).
    system: name of the system tested; trials of one system are aggregated together.
    name: the trial's name.
    source: the file it was read from (``""`` if made in memory).
    k_m: mechanical (sensor) stiffness [N/m] for this trial, or ``None`` for the analysis default.
    lines: the file line (1-based) of each sample, shape (n,), for messages; ``None`` if not from a file.
    metadata: any other ``key: value`` metadata, as text.
    """

    time: np.ndarray
    force: np.ndarray
    v0: float | None = None
    system: str = ""
    name: str = ""
    source: str = ""
    k_m: float | None = None
    lines: np.ndarray | None = None
    metadata: Mapping[str, str] = field(default_factory=dict)

    def __post_init__(self) -> None:
        time = np.asarray(self.time, dtype=float)
        force = np.asarray(self.force, dtype=float)
        if time.ndim != 1 or force.shape != time.shape:
            self.fail(f"time and force must be 1-D of one length, got shapes {time.shape} and {force.shape}")
        object.__setattr__(self, "time", time)
        object.__setattr__(self, "force", force)
        for name in ("v0", "k_m"):
            value = getattr(self, name)
            if value is not None and not (math.isfinite(value) and value > 0):
                self.fail(f"{name} = {value!r} is invalid: expected a finite number > 0")

    @property
    def label(self) -> str:
        """A short name for tables and messages: the trial name, else the file's stem."""
        return self.name or (Path(self.source).stem if self.source else "trace")

    def line_of(self, index: int) -> int | None:
        """File line of sample ``index``, if known."""
        return None if self.lines is None else int(self.lines[index])

    def fail(self, reason: str, index: int | None = None) -> NoReturn:
        """Raise a :class:`TraceError` for this trace, at sample ``index`` if given."""
        raise TraceError(self.source, self.name, reason, None if index is None else self.line_of(index))

    def check(self) -> None:
        """Raise :class:`TraceError` if the samples cannot be analysed.

        That is: too short, NaNs, or time not increasing.
        """
        n = self.time.size
        if n < MIN_SAMPLES:
            self.fail(f"too short: {n} samples, need at least {MIN_SAMPLES}")
        for name, values in (("time", self.time), ("force", self.force)):
            bad = np.flatnonzero(~np.isfinite(values))
            if bad.size:
                self.fail(
                    f"missing or non-numeric {name} ({bad.size} sample(s), first {values[bad[0]]!r}); "
                    "remove or repair those rows",
                    int(bad[0]),
                )
        steps = np.diff(self.time)
        bad = np.flatnonzero(steps <= 0)
        if bad.size:
            i = int(bad[0]) + 1
            self.fail(
                f"non-monotonic time: t = {self.time[i]:.9g} s follows t = {self.time[i - 1]:.9g} s; "
                "samples must be in increasing time order",
                i,
            )


def to_si(
    value: str | float, default_unit: str, what: str, source: str = "", line: int | None = None
) -> float:
    """A number with an optional unit (``"100 mm/s"``, ``"2e7"``) in SI, as a float.

    ``default_unit`` is the unit of a plain number and also fixes the dimension expected. Text is read by the
    package's bounded quantity grammar (:func:`collision_reflex._units.parse_quantity`).
    """
    try:
        magnitude = parse_quantity(value, default_unit) if isinstance(value, str) else float(value)
        return magnitude * si_scale(default_unit)
    except (QuantityError, ValueError, TypeError) as error:
        raise TraceError(
            source,
            "",
            f"{what} = {value!r:.60} is not a quantity in {default_unit} or a compatible unit ({error})",
            line,
        ) from None


def unit_factor(unit: str, default_unit: str, what: str, source: str = "") -> float:
    """The factor converting values in ``unit`` to SI; ``unit`` must have ``default_unit``'s dimension."""
    try:
        return parse_quantity(f"1 {unit}", check_unit(default_unit)) * si_scale(default_unit)
    except QuantityError as error:
        raise TraceError(
            source,
            "",
            f"the {what} column's unit {unit!r:.60} is not a unit of {default_unit}'s kind ({error})",
            1,
        ) from None


def read_traces(
    path: str | os.PathLike[str],
    *,
    time_unit: str = "s",
    force_unit: str = "N",
    v0: float | None = None,
    system: str | None = None,
    k_m: float | None = None,
) -> list[Trace]:
    """Read the trials of one CSV file (layout in the module docstring).

    Parameters
    ----------
    path: the CSV file.
    time_unit, force_unit: units of the time and force columns when their headers name none.
    v0: pre-impact velocity [m/s] for trials whose metadata gives none.
    system: system name for trials whose metadata gives none (default: the file's parent folder's name).
    k_m: sensor stiffness [N/m] for trials whose metadata gives none.

    Returns
    -------
    The trials, in file order. Their samples are not checked here (see :meth:`Trace.check`), so a bad trial
    does not hide the good ones.

    Raises
    ------
    TraceError: the file cannot be read, or has no time or force column.
    """
    source = str(path)
    try:
        lines = read_limited(path).decode("utf-8").splitlines()
    except (OSError, UnicodeDecodeError, ValueError) as error:
        reason = getattr(error, "strerror", None) or error
        raise TraceError(source, "", f"cannot read the file ({reason})") from None
    metadata, header_line = _leading_metadata(lines)
    if header_line >= len(lines):
        raise TraceError(source, "", "no header line and no samples")
    table = _read_table(lines, header_line, source)
    file_lines = np.arange(len(table)) + header_line + 2  # header is line header_line + 1
    columns = _column_names(table, header_line + 1, source)
    time, force = _samples(table, columns, time_unit, force_unit, source)

    default_system = system if system is not None else Path(path).resolve().parent.name
    file_meta = {
        "v0": _meta_value(metadata, "velocity", "m/s", v0, source),
        "k_m": _meta_value(metadata, "sensor stiffness", "N/m", k_m, source),
        "system": metadata.get("system", default_system),
    }
    others = {
        k: v for k, v in metadata.items() if k not in ("velocity", "sensor stiffness", "system", "trial")
    }
    if "trial" not in columns:
        return [
            Trace(
                time,
                force,
                name=metadata.get("trial", ""),
                source=source,
                lines=file_lines,
                metadata=others,
                **file_meta,  # type: ignore[arg-type]
            )
        ]

    trial_names = table[columns["trial"]].to_numpy(dtype=str)
    traces = []
    for name in dict.fromkeys(trial_names):  # file order, each once
        rows = np.flatnonzero(trial_names == name)
        meta = {**file_meta, **_trial_columns(table, columns, rows, file_lines, str(name), source)}
        traces.append(
            Trace(
                time[rows],
                force[rows],
                name=str(name),
                source=source,
                lines=file_lines[rows],
                metadata=others,
                **meta,
            )
        )
    return traces


def _column_names(table: pd.DataFrame, line: int, source: str) -> dict[str, str]:
    """Lower-case column name (its unit left out) -> the header as written; a malformed header is refused."""
    columns = {}
    for header in map(str, table.columns):
        match = HEADER.match(header)
        if match is None:
            shown = header if len(header) <= 40 else header[:37] + "..."
            raise TraceError(
                source,
                "",
                f"column header {shown!r} is not a name with an optional unit in brackets, e.g. 'time [ms]'",
                line,
            )
        columns[match.group("name").lower()] = header
    return columns


def _leading_metadata(lines: list[str]) -> tuple[dict[str, str], int]:
    """The ``# key: value`` metadata before the header, and the header's index in ``lines``."""
    metadata: dict[str, str] = {}
    header_line = 0
    while header_line < len(lines) and (lines[header_line].startswith("#") or not lines[header_line].strip()):
        key, sep, value = lines[header_line].lstrip("#").partition(":")
        if sep:
            metadata[_normalise(key)] = value.strip()
        header_line += 1
    return metadata, header_line


def _read_table(lines: list[str], header_line: int, source: str) -> pd.DataFrame:
    """The CSV table from the header on, as text, without trailing blank lines."""
    try:
        return read_table(lines, header_line)
    except TableProblem as problem:
        raise TraceError(source, "", problem.reason, problem.line) from None


def _samples(
    table: pd.DataFrame, columns: Mapping[str, str], time_unit: str, force_unit: str, source: str
) -> tuple[np.ndarray, np.ndarray]:
    """Time [s] and force [N] columns in SI; a non-numeric cell becomes NaN (reported by the check)."""
    import pandas as pd

    time_column = _find(columns, TIME_COLUMN_NAMES, "time", source)
    force_column = _find(columns, _FORCE_NAMES, "force", source)
    time_scale = _column_factor(time_column, time_unit, "time", source)
    force_scale = _column_factor(force_column, force_unit, "force", source)
    time = pd.to_numeric(table[time_column], errors="coerce").to_numpy(dtype=float) * time_scale
    force = pd.to_numeric(table[force_column], errors="coerce").to_numpy(dtype=float) * force_scale
    return time, force


def _trial_columns(
    table: pd.DataFrame,
    columns: Mapping[str, str],
    rows: np.ndarray,
    file_lines: np.ndarray,
    name: str,
    source: str,
) -> dict[str, Any]:
    """One trial's metadata from the per-trial columns (``velocity``, ``system``, ``sensor stiffness``)."""
    meta: dict[str, Any] = {}
    for key, unit in _META_COLUMNS.items():
        if key not in columns:
            continue
        values = table[columns[key]].to_numpy(dtype=str)[rows]
        if np.any(values != values[0]):
            raise TraceError(
                source, name, f"the {key!r} column changes within the trial", int(file_lines[rows[0]])
            )
        target = _META_TARGETS.get(key, key)
        if unit is None:
            meta[target] = values[0]
        else:
            scale = _column_factor(columns[key], unit, key, source)
            meta[target] = to_si(values[0], unit, key, source, int(file_lines[rows[0]])) * scale
    return meta


def write_trace(path: str | os.PathLike[str], trace: Trace, time_unit: str = "ms", digits: int = 6) -> Path:
    """Write one trial as CSV (metadata comments, ``time [time_unit]``, ``force [N]``), atomically."""
    scale = 1.0 / unit_factor(time_unit, "s", "time")
    lines = []
    if trace.name:
        lines.append(f"# trial: {trace.name}")
    if trace.v0 is not None:
        lines.append(f"# velocity: {trace.v0:.9g} m/s")
    if trace.system:
        lines.append(f"# system: {trace.system}")
    if trace.k_m is not None:
        lines.append(f"# sensor stiffness: {trace.k_m:.9g} N/m")
    lines.extend(f"# {key}: {value}" for key, value in trace.metadata.items())
    lines.append(f"time [{time_unit}],force [N]")
    lines.extend(
        f"{t:.{digits + 3}g},{f:.{digits}g}" for t, f in zip(trace.time * scale, trace.force, strict=True)
    )
    with atomic_open(path) as handle:
        handle.write("\n".join(lines) + "\n")
    return Path(path)


def _normalise(key: str) -> str:
    return re.sub(r"[\s_\-]+", " ", key.strip().lower())


def _find(columns: Mapping[str, str], names: tuple[str, ...], what: str, source: str) -> str:
    for name in names:
        if name in columns:
            return columns[name]
    raise TraceError(
        source,
        "",
        f"no {what} column among {list(columns.values())}; name one "
        + " or ".join(repr(n) for n in names)
        + (" (with its unit in brackets, e.g. 'time [ms]')" if what == "time" else ""),
        1,
    )


def _column_factor(column: str, default_unit: str, what: str, source: str) -> float:
    match = HEADER.match(column)
    unit = match.group("unit") if match else None
    return (
        unit_factor(unit, default_unit, what, source)
        if unit
        else unit_factor(default_unit, default_unit, what)
    )


def _meta_value(
    metadata: Mapping[str, str], key: str, unit: str, default: float | None, source: str
) -> float | None:
    if key not in metadata:
        return default
    return to_si(metadata[key], unit, key, source)
