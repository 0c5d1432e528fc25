"""The motion an arm must make (:class:`DutyCycle`) and what it carries (:class:`Payload`).

A duty cycle is joint positions, velocities and accelerations over time, with the payload held at the contact
point. It comes from sampled positions (arrays or a CSV file), whose derivatives are those of an interpolating
quintic spline, or from via configurations and joint limits (:mod:`collision_reflex.arm.motion_profiles`).

Derivatives of sampled positions: a quintic (``k = 5``) interpolating B-spline, SciPy's
``make_interp_spline`` with not-a-knot ends. The torques depend on the accelerations, and a quintic's second
derivative is twice continuously differentiable with an error of order ``h^4`` in the step ``h`` (a cubic
spline's acceleration is only piecewise linear, with an error of order ``h^2``). The spline interpolates: a
noisy recording should be filtered before it is given. Samples too coarse for the spline are refused: where
the accelerations of the quintic and of a cubic spline through the same samples differ, at the midpoints
between samples, by more than :data:`COARSE_TOLERANCE` of the joint's largest acceleration, the motion between
samples is not determined by them (for a sine that happens below about 10 samples per period).

CSV layout: optional leading ``#`` comment lines, then a header with a time column (``time`` or ``t``) and one
column per joint, named by the joint, each with its unit in brackets (``time [s]``, ``shoulder [deg]``,
``slide [mm]``; a joint column must name its unit, the time column without one is in s), then one row per
sample. Other columns are ignored.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .. import _validate
from .._io import read_limited
from .._table import HEADER, TableProblem, read_table
from ..errors import InvalidParameter, TraceError, TrajectoryError
from ..experiments.traces import unit_factor
from ..vocabulary import TIME_COLUMN_NAMES
from .motion_profiles import MAX_CYCLE_SAMPLES, checked_motion, trapezoidal_motion

SPLINE_ORDER = 5
"""Order of the interpolating spline differentiated for velocities and accelerations (quintic)."""
MIN_SAMPLES = SPLINE_ORDER + 1
"""Fewest samples an interpolating spline of :data:`SPLINE_ORDER` needs."""
COARSE_TOLERANCE = 0.1
"""Largest relative disagreement between the quintic's and a cubic's accelerations between samples."""


@dataclass(frozen=True, eq=False)
class Payload:
    """A rigid payload held with its centre of mass at the arm's contact point.

    Attributes
    ----------
    mass: payload mass [kg], > 0.
    inertia: (3, 3) rotational inertia about its centre of mass, in the axes of the contact frame [kg m^2];
        symmetric positive semi-definite. Default zero (a point mass).
    """

    mass: float
    inertia: np.ndarray = field(default_factory=lambda: np.zeros((3, 3)))

    def __post_init__(self) -> None:
        mass = _validate.positive("mass", self.mass)
        if np.ndim(mass) != 0:
            raise InvalidParameter("mass", self.mass, "a finite payload mass > 0 [kg]")
        inertia = _validate.real("inertia", self.inertia, "a finite 3x3 matrix [kg m^2]")
        if inertia.shape != (3, 3) or not np.all(np.isfinite(inertia)):
            raise InvalidParameter("inertia", self.inertia, "a finite 3x3 matrix [kg m^2]")
        scale = max(float(np.max(np.abs(inertia))), 1e-300)
        if not np.allclose(inertia, inertia.T, rtol=0, atol=1e-12 * scale):
            raise InvalidParameter("inertia", inertia.tolist(), "a symmetric matrix [kg m^2]")
        if np.min(np.linalg.eigvalsh(inertia)) < -1e-12 * scale:
            raise InvalidParameter("inertia", inertia.tolist(), "a positive semi-definite matrix [kg m^2]")
        object.__setattr__(self, "mass", mass)
        object.__setattr__(self, "inertia", inertia)


MAX_JOINT_SPEED = 1e4
"""Fastest joint speed a duty cycle may hold [rad/s or m/s]: 95,000 rpm at the joint, far beyond any robot's, so
a larger one is a wrong unit or a wrong time column, never a motion."""


@dataclass(frozen=True, eq=False)
class DutyCycle:
    """Joint motion over one cycle, with the payload carried.

    Attributes
    ----------
    joint_names: one name per joint, in the column order of the arrays.
    t: (n,) strictly increasing sample times [s].
    q: (n, nv) joint positions [rad or m].
    qd: (n, nv) joint velocities [rad/s or m/s].
    qdd: (n, nv) joint accelerations [rad/s^2 or m/s^2].
    payload: what the arm holds at its contact point, or None.
    """

    joint_names: tuple[str, ...]
    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    payload: Payload | None = None

    def __post_init__(self) -> None:
        names = tuple(str(name) for name in _joint_names(self.joint_names))
        if not names or len(set(names)) != len(names):
            raise InvalidParameter("joint_names", self.joint_names, "distinct joint names, at least one")
        object.__setattr__(self, "joint_names", names)
        t = _validate.real("t", self.t, "a 1-D array of at least 2 times [s]")
        if t.ndim != 1 or t.size < 2:
            raise InvalidParameter("t", t.shape, "a 1-D array of at least 2 times [s]")
        if t.size > MAX_CYCLE_SAMPLES:
            raise InvalidParameter(
                "t",
                f"{t.size:,} samples",
                f"at most {MAX_CYCLE_SAMPLES:,} samples",
                "the requirement is evaluated at every sample: resample the cycle more coarsely",
            )
        _check_times(t, "")
        object.__setattr__(self, "t", t)
        for name in ("q", "qd", "qdd"):
            values = _validate.real(name, getattr(self, name), f"an array of shape ({t.size}, {len(names)})")
            if values.shape != (t.size, len(names)):
                raise InvalidParameter(name, values.shape, f"an array of shape ({t.size}, {len(names)})")
            bad = np.flatnonzero(~np.all(np.isfinite(values), axis=1))
            if bad.size:
                raise InvalidParameter(name, values, "finite values", f"sample {int(bad[0])} is not")
            object.__setattr__(self, name, values)
        too_fast = np.flatnonzero(np.any(np.abs(self.qd) > MAX_JOINT_SPEED, axis=1))
        if too_fast.size:
            sample = int(too_fast[0])
            raise InvalidParameter(
                "qd",
                f"{float(np.max(np.abs(self.qd[sample]))):.3g} at t = {t[sample]:.6g} s",
                f"joint speeds of at most {MAX_JOINT_SPEED:g} rad/s (or m/s)",
                "no robot joint moves so fast: check the positions' unit and the time column's",
            )
        if self.payload is not None and not isinstance(self.payload, Payload):
            raise InvalidParameter("payload", self.payload, "a Payload or None")

    @property
    def duration(self) -> float:
        """Length of the cycle [s]."""
        return float(self.t[-1] - self.t[0])

    def columns(self, joint_names: Sequence[str]) -> np.ndarray:
        """Indices of ``joint_names`` (e.g. an arm's joints, in its order) among this cycle's joints."""
        missing = [name for name in joint_names if name not in self.joint_names]
        if missing:
            raise InvalidParameter(
                "joint_names",
                missing,
                "joints of the duty cycle: " + ", ".join(self.joint_names),
                "the duty cycle must give every joint of the arm",
            )
        return np.array([self.joint_names.index(name) for name in joint_names], dtype=int)

    # ------------------------------------------------------------------ constructors
    @classmethod
    def from_positions(
        cls,
        t: Any,
        q: Any,
        joint_names: Sequence[str],
        payload: Payload | None = None,
        *,
        source: str = "",
        lines: np.ndarray | None = None,
    ) -> DutyCycle:
        """A duty cycle from sampled positions; velocities and accelerations of a quintic spline through them.

        Parameters
        ----------
        t: (n,) strictly increasing times [s], n >= :data:`MIN_SAMPLES`.
        q: (n, nv) joint positions [rad or m].
        joint_names: the joints of the columns of ``q``.
        payload: the payload carried, if any.
        source, lines: the file and the file line of each sample, for error messages.

        Raises
        ------
        TrajectoryError: NaN, non-increasing times, too few samples, or samples too coarse for the spline;
            located at the file line (or sample index).
        """
        from scipy.interpolate import make_interp_spline

        t = _validate.real("t", t, "a 1-D array of strictly increasing times [s]")
        q = _validate.real("q", q, "joint positions (n, nv) [rad or m]")
        names = tuple(_joint_names(joint_names))
        if t.ndim != 1 or q.shape != (t.size, len(names)):
            raise InvalidParameter(
                "q", q.shape, f"an array of shape ({t.size}, {len(names)}) for t {t.shape}"
            )

        def line(index: int) -> int | None:
            return int(lines[index]) if lines is not None else None

        if t.size < MIN_SAMPLES:
            raise TrajectoryError(
                source,
                f"too few samples for the derivatives: {t.size}, need at least {MIN_SAMPLES} "
                f"(an interpolating spline of order {SPLINE_ORDER})",
            )
        for what, values in (("time", t[:, None]), *((name, q[:, [j]]) for j, name in enumerate(names))):
            bad = np.flatnonzero(~np.isfinite(values[:, 0]))
            if bad.size:
                raise TrajectoryError(
                    source,
                    f"missing or non-numeric {what} ({float(values[bad[0], 0])!r}) at sample {int(bad[0])}",
                    line(int(bad[0])),
                )
        _check_times(t, source, lines)
        with np.errstate(
            over="ignore", invalid="ignore", divide="ignore"
        ):  # a non-finite result is refused next
            quintic = make_interp_spline(t, q, k=SPLINE_ORDER)
            velocity, acceleration = quintic.derivative(1), quintic.derivative(2)
            qd, qdd = velocity(t), acceleration(t)
        bad = np.flatnonzero(~(np.isfinite(qd) & np.isfinite(qdd)).all(axis=1))
        if bad.size:
            raise TrajectoryError(
                source,
                f"the speeds or accelerations at sample {int(bad[0])} exceed the float64 range: time steps of "
                f"{float(np.min(np.diff(t))):.3g} s are too short for the positions (check the time unit)",
                line(int(bad[0])),
            )
        _check_resolution(t, q, acceleration, names, source, line)
        return cls(names, t, q, qd, qdd, payload)

    @classmethod
    def from_csv(
        cls,
        path: str | os.PathLike[str],
        joint_names: Sequence[str],
        payload: Payload | None = None,
        *,
        prismatic: Sequence[str] = (),
    ) -> DutyCycle:
        """Read a trajectory file (layout in the module docstring) and differentiate it.

        Parameters
        ----------
        path: the CSV file.
        joint_names: the joints to read, each a column of the file.
        payload: the payload carried, if any.
        prismatic: the joints among ``joint_names`` whose positions are lengths (default m); the others are
            angles (default rad).

        Raises
        ------
        TrajectoryError: the file cannot be read, a joint or the time column is missing, a unit is not of the
            column's kind, a value is NaN, the times do not increase, there are too few samples or they are too
            coarse; located at the file line.
        """
        source = str(path)
        header_line, table = _read_table(path)
        columns: dict[str, str] = {}
        for column in map(str, table.columns):
            match = HEADER.match(column)
            name = match.group("name") if match else None
            if name is None or name in columns:  # pandas renames a repeated 'j1 [deg]' to 'j1 [deg].1'
                shown = name or column.rsplit(".", 1)[0]
                raise TrajectoryError(
                    source,
                    f"the header names the column {shown[:60]!r} twice; name each column once",
                    header_line,
                )
            columns[name] = column
        lowered = {name.lower(): column for name, column in columns.items()}
        time_column = next((lowered[n] for n in TIME_COLUMN_NAMES if n in lowered), None)
        if time_column is None:
            raise TrajectoryError(
                source, f"no time column among {list(columns.values())}; name one 'time [s]'", header_line
            )
        t = _column(table, time_column, "s", "time", source, header_line)
        q = joint_positions(table, joint_names, prismatic, source, header_line)
        lines = np.arange(t.size) + header_line + 1
        return cls.from_positions(t, q, joint_names, payload, source=source, lines=lines)

    @classmethod
    def through_via_points(
        cls,
        via_points: Any,
        joint_names: Sequence[str],
        max_velocity: Any,
        max_acceleration: Any,
        *,
        rate: float = 1000.0,
        dwell: Any = 0.0,
        payload: Payload | None = None,
    ) -> DutyCycle:
        """A motion through via configurations: synchronised trapezoids (see :mod:`.motion_profiles`).

        Parameters
        ----------
        via_points: (k, nv) joint configurations to pass through, at rest at each [rad or m], k >= 2.
        joint_names: the joints of the columns.
        max_velocity: joint speed limits [rad/s or m/s], scalar or (nv,), > 0.
        max_acceleration: joint acceleration limits [rad/s^2 or m/s^2], scalar or (nv,), > 0.
        rate: sampling rate [Hz], > 0; the phase switching times are sampled as well.
        dwell: time at rest at each via point [s], scalar or (k,), >= 0 (the first before moving, the last
            after arriving).
        payload: the payload carried, if any.

        Returns
        -------
        The cycle, with analytic velocities and accelerations; it starts and ends at rest.
        """
        names = tuple(_joint_names(joint_names))
        points, speeds, accelerations, rate, dwell = checked_motion(
            via_points, max_velocity, max_acceleration, rate, dwell
        )
        if points.shape[1] != len(names):
            raise InvalidParameter(
                "via_points", points.shape, f"an array of shape (k >= 2, {len(names)}) [rad or m]"
            )
        t, q, qd, qdd = trapezoidal_motion(points, speeds, accelerations, rate, dwell)
        return cls(names, t, q, qd, qdd, payload)


def joint_positions(
    table: Any, joint_names: Sequence[str], prismatic: Sequence[str], source: str, header_line: int
) -> np.ndarray:
    """The joints' columns of a table (text cells) in SI, shape (rows, joints): rad, or m for ``prismatic``.

    Each joint's header names its unit (``shoulder [deg]``, ``slide [mm]``): a bare angle could be degrees or
    radians. A cell that is not a number is NaN (the callers locate it).

    Raises
    ------
    TrajectoryError: a joint without a column, a column without a unit or with one of another kind.
    """
    columns = {HEADER.match(str(c)).group("name"): str(c) for c in table.columns}  # type: ignore[union-attr]
    missing = [name for name in joint_names if name not in columns]
    if missing:
        raise TrajectoryError(
            source,
            f"no column for joint(s) {', '.join(missing)}; the header names {list(columns.values())}, "
            "and needs one column per joint: " + ", ".join(joint_names),
            header_line,
        )
    bare = [columns[name] for name in joint_names if not (HEADER.match(columns[name]).group("unit") or "")]  # type: ignore[union-attr]
    if bare:
        name = HEADER.match(bare[0]).group("name")  # type: ignore[union-attr]
        raise TrajectoryError(
            source,
            f"joint column(s) {', '.join(map(repr, bare))} without a unit: write '{name} [deg]' or "
            f"'{name} [rad]' (a bare angle could be either; a prismatic joint's '[mm]')",
            header_line,
        )
    return np.column_stack(
        [
            _column(
                table,
                columns[name],
                "m" if name in prismatic else "rad",
                f"joint {name!r}",
                source,
                header_line,
            )
            for name in joint_names
        ]
    )


def _column(
    table: Any, column: str, default_unit: str, what: str, source: str, header_line: int
) -> np.ndarray:
    """A column's values in SI, by the unit its header names (``default_unit`` when it names none)."""
    import pandas as pd

    match = HEADER.match(column)
    unit = (match.group("unit") if match else None) or default_unit
    try:
        scale = unit_factor(unit, default_unit, what, source)
    except TraceError as error:
        raise TrajectoryError(source, error.reason, header_line) from None
    return pd.to_numeric(table[column], errors="coerce").to_numpy(dtype=float) * scale


def _read_table(path: str | os.PathLike[str]) -> tuple[int, Any]:
    """The header's file line (1-based) and the table of strings below it."""
    source = str(path)
    try:
        text = read_limited(path).decode("utf-8")
    except (OSError, UnicodeDecodeError, ValueError) as error:
        reason = getattr(error, "strerror", None) or error
        raise TrajectoryError(source, f"cannot read the file ({reason})") from None
    lines = text.splitlines()
    header = 0
    while header < len(lines) and (lines[header].startswith("#") or not lines[header].strip()):
        header += 1
    if header >= len(lines):
        raise TrajectoryError(source, "no header line and no samples")
    try:
        return header + 1, read_table(lines, header)
    except TableProblem as problem:
        raise TrajectoryError(source, problem.reason, problem.line) from None


def _joint_names(value: Any) -> Sequence[Any] | np.ndarray:
    """``value`` if it is a sequence of joint names (not one string), else raise."""
    if isinstance(value, str | bytes) or not isinstance(value, Sequence | np.ndarray):
        raise InvalidParameter("joint_names", value, "a sequence of joint names, e.g. ('joint1', 'joint2')")
    return value


def _check_times(t: np.ndarray, source: str, lines: np.ndarray | None = None) -> None:
    """Refuse NaN and non-increasing (or repeated) times, at the offending sample."""
    bad = np.flatnonzero(~np.isfinite(t))
    steps = np.diff(t)
    late = np.flatnonzero(steps <= 0) + 1
    if not bad.size and not late.size:
        return
    index = int(bad[0]) if bad.size else int(late[0])
    where = int(lines[index]) if lines is not None else None
    if bad.size:
        raise TrajectoryError(
            source, f"missing or non-numeric time ({float(t[index])!r}) at sample {index}", where
        )
    raise TrajectoryError(
        source,
        f"time does not increase at sample {index}: t = {t[index]:.9g} s follows t = {t[index - 1]:.9g} s; "
        "samples must be in strictly increasing time order, each time once",
        where,
    )


def _check_resolution(
    t: np.ndarray, q: np.ndarray, acceleration: Any, names: tuple[str, ...], source: str, line: Any
) -> None:
    """Refuse samples too coarse for the spline (criterion in the module docstring)."""
    from scipy.interpolate import make_interp_spline

    midpoints = 0.5 * (t[1:] + t[:-1])
    quintic = acceleration(midpoints)
    cubic = make_interp_spline(t, q, k=3).derivative(2)(midpoints)
    scale = np.max(np.abs(acceleration(t)), axis=0)
    disagreement = np.abs(quintic - cubic)
    moving = (scale > 0) & (np.ptp(q, axis=0) > 0)  # a joint held still has only round-off accelerations
    relative = np.zeros_like(disagreement)
    relative[:, moving] = disagreement[:, moving] / scale[moving]
    worst = np.unravel_index(int(np.argmax(relative)), relative.shape)
    if relative[worst] > COARSE_TOLERANCE:
        sample, joint = int(worst[0]), int(worst[1])
        raise TrajectoryError(
            source,
            f"sampling too coarse for the derivatives of joint {names[joint]!r} between samples {sample} and "
            f"{sample + 1} (t = {t[sample]:.9g} s and {t[sample + 1]:.9g} s): a quintic and a cubic spline "
            f"through the samples differ there by {relative[worst]:.0%} of the joint's peak acceleration (at most {COARSE_TOLERANCE:.0%}); "
            "sample the motion more finely (or, if the positions are noisy, filter them first: the spline "
            "interpolates every sample)",
            line(sample + 1),
        )
