"""Joint motions through via configurations under joint speed and acceleration limits.

Between two consecutive via configurations every joint moves on the straight line of joint space,
``q(t) = q_a + s(t) (q_b - q_a)``, with one trapezoidal time scaling ``s`` from 0 to 1 shared by all joints
(synchronised: the joints start and stop together). ``s`` is the fastest trapezoid whose speed and
acceleration keep every joint within its limits, so the joint that limits a segment reaches its limit. A
trapezoid rather than a minimum-jerk polynomial: it is the time-optimal motion under the limits the user
states (the requirement is "move as fast as the limits allow"), its accelerations are piecewise constant, so
any sampling holds their exact extremes, and the samples include the switching times, where the speed peaks.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from .. import _validate
from ..errors import InvalidParameter

MAX_CYCLE_SAMPLES = 200_000
"""Most samples a duty cycle may hold: the requirement evaluates the arm's dynamics at each (a million rows grew a
smoke run past 10 GB); an hour of motion at 50 Hz is 180,000."""


@dataclass(frozen=True)
class TrapezoidSegment:
    """One synchronised move from ``start`` to ``end`` [rad or m], each (nv,).

    Attributes
    ----------
    start, end: the via configurations [rad or m].
    accelerate: duration of the acceleration (and of the deceleration) phase [s].
    duration: total duration [s]; the speed is constant between ``accelerate`` and ``duration - accelerate``.
    peak_rate: largest ``ds/dt`` of the time scaling [1/s].
    """

    start: np.ndarray
    end: np.ndarray
    accelerate: float
    duration: float
    peak_rate: float

    @classmethod
    def fastest(
        cls, start: np.ndarray, end: np.ndarray, max_velocity: np.ndarray, max_acceleration: np.ndarray
    ) -> TrapezoidSegment:
        """The fastest synchronised trapezoid between two configurations within per-joint limits.

        Parameters
        ----------
        start, end: configurations [rad or m], (nv,); they must differ.
        max_velocity: joint speed limits [rad/s or m/s], (nv,).
        max_acceleration: joint acceleration limits [rad/s^2 or m/s^2], (nv,).
        """
        distance = np.abs(end - start)
        moving = distance > 0
        # Limits on the time scaling s: |q_j'| = D_j s' <= v_j and |q_j''| = D_j s'' <= a_j.
        rate = float(np.min(max_velocity[moving] / distance[moving]))
        acceleration = float(np.min(max_acceleration[moving] / distance[moving]))
        if rate**2 / acceleration >= 1.0:  # triangular: the speed limit is never reached
            accelerate = float(np.sqrt(1.0 / acceleration))
            return cls(start, end, accelerate, 2.0 * accelerate, acceleration * accelerate)
        accelerate = rate / acceleration
        return cls(start, end, accelerate, accelerate + 1.0 / rate, rate)

    @property
    def switch_times(self) -> np.ndarray:
        """Times at which the acceleration changes, from the segment's start [s]."""
        return np.array([0.0, self.accelerate, self.duration - self.accelerate, self.duration])

    def evaluate(self, tau: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Positions, velocities and accelerations (m, nv) at times ``tau`` (m,) from the segment's start [s].

        At a switching time the acceleration of the phase that starts there is returned.
        """
        t_a, duration, peak = self.accelerate, self.duration, self.peak_rate
        s_ddot_max = peak / t_a
        tau = np.clip(tau, 0.0, duration)
        rising, falling = tau < t_a, tau >= duration - t_a
        to_end = duration - tau
        s = np.where(
            rising,
            0.5 * s_ddot_max * tau**2,
            np.where(falling, 1.0 - 0.5 * s_ddot_max * to_end**2, 0.5 * peak * t_a + peak * (tau - t_a)),
        )
        s_dot = np.where(rising, s_ddot_max * tau, np.where(falling, s_ddot_max * to_end, peak))
        s_ddot = np.where(rising, s_ddot_max, np.where(falling, -s_ddot_max, 0.0))
        s_ddot = np.where(tau >= duration, 0.0, s_ddot)  # at rest once arrived
        delta = self.end - self.start
        return (
            self.start + s[:, None] * delta,
            s_dot[:, None] * delta,
            s_ddot[:, None] * delta,
        )


def trapezoidal_motion(
    via_points: np.ndarray,
    max_velocity: np.ndarray,
    max_acceleration: np.ndarray,
    rate: float,
    dwell: np.ndarray,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Times, positions, velocities and accelerations of a motion through via configurations.

    Parameters
    ----------
    via_points: (k, nv) configurations [rad or m], k >= 2; consecutive equal ones are a pause.
    max_velocity, max_acceleration: per-joint limits [rad/s, rad/s^2 or m/s, m/s^2], (nv,), > 0.
    rate: sampling rate [Hz] of the uniform time grid; the switching times are added to it.
    dwell: (k,) time at rest at each via point [s] (the first before moving, the last after arriving).

    Returns
    -------
    ``t`` (n,) [s] from 0, and ``q``, ``qd``, ``qdd`` (n, nv), analytic.

    Raises :class:`InvalidParameter` naming the argument for misshapen, non-finite or out-of-range inputs, and
    for a motion that would take more than :data:`MAX_CYCLE_SAMPLES` samples.
    """
    via_points, max_velocity, max_acceleration, rate, dwell = checked_motion(
        via_points, max_velocity, max_acceleration, rate, dwell
    )
    with _validate.combining(max_velocity=max_velocity, max_acceleration=max_acceleration):
        t, segments, clock = _time_grid(via_points, max_velocity, max_acceleration, rate, dwell)
    nv = via_points.shape[1]
    q = np.empty((t.size, nv))
    qd = np.zeros((t.size, nv))
    qdd = np.zeros((t.size, nv))
    position = via_points[0]
    starts = np.array([start for start, _ in segments] + [np.inf])
    owner = np.searchsorted(starts, t, side="right") - 1
    q[:] = via_points[0]
    for index, (start, segment) in enumerate(segments):
        here = owner == index
        if segment is None:
            q[here] = position
            continue
        q[here], qd[here], qdd[here] = segment.evaluate(t[here] - start)
        position = segment.end
    q[t >= clock] = position
    qd[t >= clock] = 0.0
    qdd[t >= clock] = 0.0
    return t, q, qd, qdd


def _time_grid(
    via_points: np.ndarray,
    max_velocity: np.ndarray,
    max_acceleration: np.ndarray,
    rate: float,
    dwell: np.ndarray,
) -> tuple[np.ndarray, list[tuple[float, TrapezoidSegment | None]], float]:
    """The sample times, the segments (start time, move or None for a rest) and the total duration [s]."""
    segments: list[tuple[float, TrapezoidSegment | None]] = []
    clock = 0.0
    breaks = [0.0]
    for index in range(len(via_points)):
        if dwell[index] > 0:
            segments.append((clock, None))
            clock += float(dwell[index])
            breaks.append(clock)
        if index + 1 == len(via_points) or np.array_equal(via_points[index], via_points[index + 1]):
            continue
        move = TrapezoidSegment.fastest(
            via_points[index], via_points[index + 1], max_velocity, max_acceleration
        )
        segments.append((clock, move))
        breaks.extend(clock + move.switch_times[1:])
        clock += move.duration
    if clock <= 0:
        raise InvalidParameter("via_points", via_points, "configurations that differ, or a dwell > 0")
    if not clock * rate < MAX_CYCLE_SAMPLES:  # also refuses an infinite duration
        raise InvalidParameter(
            "max_velocity, max_acceleration, rate, dwell",
            f"a motion of {clock:.3g} s sampled at {rate:.3g} Hz",
            f"at most {MAX_CYCLE_SAMPLES:,} samples",
            "raise the limits, lower the rate or shorten the dwells",
        )
    grid = np.arange(int(np.floor(clock * rate)) + 1) / rate
    t = np.unique(np.concatenate([grid, breaks]))
    # Switching times that fall within rounding of a grid time would make near-repeated samples.
    t = t[np.concatenate([[True], np.diff(t) > 1e-9 * max(clock, 1.0)])]
    t[-1] = clock
    return t, segments, clock


def checked_motion(
    via_points: Any, max_velocity: Any, max_acceleration: Any, rate: Any, dwell: Any
) -> tuple[np.ndarray, np.ndarray, np.ndarray, float, np.ndarray]:
    """The inputs of :func:`trapezoidal_motion` as float64 arrays of their shapes, checked; else raise."""
    points = _validate.real("via_points", via_points, "joint configurations (k >= 2, nv) [rad or m]")
    if points.ndim != 2 or points.shape[0] < 2 or points.shape[1] < 1:
        raise InvalidParameter("via_points", points.shape, "an array of shape (k >= 2, nv >= 1) [rad or m]")
    if not np.all(np.isfinite(points)):
        raise InvalidParameter("via_points", points, "finite joint positions [rad or m]")
    nv, k = points.shape[1], points.shape[0]
    limits = []
    for name, value in (("max_velocity", max_velocity), ("max_acceleration", max_acceleration)):
        allowed = "finite limits > 0, one per joint or one for all"
        array = _validate.real(name, value, allowed)
        if array.ndim > 1 or array.size not in (1, nv) or not np.all(np.isfinite(array) & (array > 0)):
            raise InvalidParameter(name, value, f"{allowed} ({nv} joints)")
        limits.append(np.broadcast_to(array, (nv,)).copy())
    if np.ndim(_validate.real("rate", rate, "a finite sampling rate > 0 [Hz]")) != 0:
        raise InvalidParameter("rate", rate, "a finite sampling rate > 0 [Hz]")
    rate = _validate.positive("rate", rate)
    allowed = "finite times >= 0 [s], one per via point or one for all"
    rest = _validate.real("dwell", dwell, allowed)
    if rest.ndim > 1 or rest.size not in (1, k) or not np.all(np.isfinite(rest) & (rest >= 0)):
        raise InvalidParameter("dwell", dwell, f"{allowed} ({k} via points)")
    return points, limits[0], limits[1], float(rate), np.broadcast_to(rest, (k,)).copy()
