"""One-shot least-squares fit of the model's force profile to one trace (the paper's ``tab:one_shot``).

Fitted: finger mass ``m_f`` [kg], software stiffness ``k_s`` [N/m], sensing threshold ``F_s`` [N], reaction
acceleration ``a`` [m/s^2], the time of impact on the trace's clock [s], and (a nuisance parameter) a small
offset of the noise floor, so that the floor's uncertainty reaches the parameters' uncertainties. Given: the mechanical (sensor)
stiffness ``k_m`` (the paper: 2e7 N/m, the ATI Mini40's) and the pre-impact velocity ``v0`` (from the trial's
metadata). The model is :func:`collision_reflex.model.force_profile` seen through the sensor
(:func:`~collision_reflex.experiments.model_samples`: interval means, then the sensor's low-pass), so the fit
compares like with like even when the impact pulse is shorter than one sample.

What the samples identify
-------------------------
- ``m_f``: from the *area* of the impact pulse, ``m_f v0``, given ``v0``. The pulse's shape (its height and
  its duration ``pi/2 sqrt(m_f/k_m)``) is not resolved at a few kHz; the area survives sampling and filtering.
  When ``m_f v0`` is small against the noise integrated over a few samples, the uncertainty says so.
- ``k = k_m k_s / (k_m + k_s)``: from the slope ``k v0`` of the sensing ramp, given ``v0``; ``k_s`` follows
  with ``k_m`` given. With ``k_s << k_m`` (the paper's case) ``k_s ~ k`` and ``k_m`` barely matters; for
  ``k_s`` comparable to ``k_m`` its uncertainty grows as ``(k_s/k)^2``.
- ``F_s``: the force at the peak where the ramp ends (detection).
- ``a``: only through ``a k_m``, the curvature of the reaction parabola ``F_s - k_m a tau^2 / 2`` (equivalently
  its duration ``sqrt(2 F_s / (a k_m))``); hence ``k_m`` must be given, and an error in ``k_m`` moves ``a``
  in inverse proportion. A reaction shorter than a couple of samples leaves ``a`` poorly determined.
- The impact time is pinned to a fraction of a sample by the ramp's start and by how the pulse's area splits
  between neighbouring samples; while the pulse lies wholly inside one sampling interval its position there
  is not determined (the fit tries both ends of that plateau) and its stated uncertainty is not meaningful.
- Not identifiable: ``k_m`` itself, ``m_r`` (only ``a = F_a / m_r`` appears), and ``m_f`` or ``k`` without a
  known ``v0`` (only ``m_f v0`` and ``k v0`` appear).

Uncertainties are one standard deviation from the Jacobian at the optimum, ``cov = s^2 (J^T J)^-1`` with
``s^2`` the residual variance, so a model that fits badly (e.g. a geared actuator with backlash) reports
larger uncertainties. A direction of the parameters that the samples do not determine to within a factor
``e`` (a singular value of ``J`` below ``s``; e.g. ``F_s`` and ``a`` when detection and the end of contact
fall into one sampling interval) is not identifiable: each parameter along it gets an infinite uncertainty
and a note, rather than the tiny one a pseudo-inverse would give by dropping that direction. A fit whose
residual is far above the noise floor (:data:`RESIDUAL_LIMIT`) gets a note as well: the model does not
describe the trace, and its parameters are not to be trusted. Parameters are fitted as logarithms (positive by construction, well scaled); their
uncertainties are mapped back to linear units to first order. Phase-impulse uncertainties are propagated
through :func:`collision_reflex.model.phase_impulses` the same way.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .. import _validate
from ..errors import FitFailed
from ..model.impulse import (
    PhaseImpulses,
    impact_pulse_duration,
    phase_impulses,
    reaction_duration,
    series_stiffness,
)
from ..vocabulary import REACTION_MODES
from .sensor import SensorModel, model_samples
from .traces import Trace
from .window import ContactWindow

PARAMETERS: tuple[str, ...] = ("m_f", "k_s", "F_s", "a")
"""The fitted model parameters, in the order of :attr:`OneShotFit.values`."""

PARAMETER_UNITS: Mapping[str, str] = {"m_f": "kg", "k_s": "N/m", "F_s": "N", "a": "m/s^2", "impact_time": "s"}

PAPER_SENSOR_STIFFNESS = 2e7
"""Stiffness of the paper's ATI Mini40 force sensor along the sensing direction [N/m] (its §Experiments)."""

_PHASES = ("initial", "sensing", "reaction", "total")

RESIDUAL_LIMIT = 1.5
"""Residual rms over the noise floor's deviation beyond which a fit is noted as not describing the trace.

The ratio of a good fit is 1 within ``1/sqrt(2 n)`` (``n`` samples, at least 20): 1.5 is well outside that."""

_RESTART_SHIFT = 0.25
"""How far the fit's restarts move a resolved pulse's impact time [samples] (:func:`_restarted`)."""

_RESOLVED_SAMPLES = 2  # fewest sampling intervals a reaction must span for its curvature (a) to be seen
# Largest uncertainty along a direction, in log units (a factor e), that counts as determined.
_IDENTIFIED = 1.0


@dataclass(frozen=True)
class OneShotFit:
    """The force-profile model fitted to one trace.

    Attributes
    ----------
    m_f: finger mass [kg].
    k_s: software stiffness [N/m].
    F_s: sensing threshold [N].
    a: reaction acceleration [m/s^2].
    impact_time: time of impact on the trace's clock [s].
    stderr: one-standard-deviation uncertainty of each of the above, by name (same units).
    k_m: the mechanical stiffness used [N/m] (given, not fitted).
    v0: the pre-impact velocity used [m/s] (given).
    sensor: the sensor model the profile was compared through.
    reaction: the reaction model (``"at_rest"``, the paper's, or ``"moving"``).
    residual_rms: root-mean-square residual of the fit [N].
    samples: number of samples fitted.
    phase_stderr: one-standard-deviation uncertainty of the phase impulses [N*s], keys ``initial``,
        ``sensing``, ``reaction``, ``total``.
    notes: what to be wary of: parameters that are not identifiable (their ``stderr`` is ``inf``), a
        residual far above the noise.
    """

    m_f: float
    k_s: float
    F_s: float
    a: float
    impact_time: float
    stderr: Mapping[str, float]
    k_m: float
    v0: float
    sensor: SensorModel
    reaction: str = "at_rest"
    residual_rms: float = 0.0
    samples: int = 0
    phase_stderr: Mapping[str, float] = field(default_factory=dict)
    notes: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        for name in (*PARAMETERS, "k_m", "v0"):
            _validate.positive(name, getattr(self, name))
        _validate.choice("reaction", self.reaction, REACTION_MODES)

    @property
    def values(self) -> tuple[float, float, float, float]:
        """``(m_f, k_s, F_s, a)``."""
        return (self.m_f, self.k_s, self.F_s, self.a)

    @property
    def k(self) -> float:
        """Lumped sensing stiffness [N/m], ``k_m`` and ``k_s`` in series."""
        return float(series_stiffness(self.k_m, self.k_s))

    @property
    def phases(self) -> PhaseImpulses:
        """The model's phase impulses at this trial's ``v0`` [N*s]."""
        return phase_impulses(self.m_f, self.k, self.k_m, self.F_s, self.a, self.v0, self.reaction)

    def samples_at(self, times: np.ndarray) -> np.ndarray:
        """What the fitted model has the sensor report at ``times`` [s] (floor subtracted) [N]."""
        return model_samples(
            times,
            self.m_f,
            self.k,
            self.k_m,
            self.F_s,
            self.a,
            self.v0,
            self.impact_time,
            self.sensor,
            self.reaction,
        )


def fit_one_shot(
    trace: Trace,
    window: ContactWindow,
    *,
    k_m: float = PAPER_SENSOR_STIFFNESS,
    bandwidth: float | None = None,
    reaction: str = "at_rest",
) -> OneShotFit:
    """Fit ``m_f, k_s, F_s, a`` and the impact time to one trace by least squares.

    Parameters
    ----------
    trace: the trace; its ``v0`` (pre-impact velocity [m/s]) must be known. Its own ``k_m``, if set, wins
        over the argument.
    window: its contact window (noise floor and extent), from :func:`find_contact`.
    k_m: mechanical (sensor) stiffness [N/m], not fitted (see the module docstring).
    bandwidth: cutoff of the sensor's low-pass filter [Hz], or ``None`` if the samples are unfiltered.
    reaction: ``"at_rest"`` (the paper's reaction) or ``"moving"``.

    Raises
    ------
    TraceError: no pre-impact velocity, or irregular sampling.
    FitFailed: the least-squares solver did not converge.
    """
    _validate.choice("reaction", reaction, REACTION_MODES)
    if trace.v0 is None:
        trace.fail("no pre-impact velocity: give it as '# velocity: ...' in the file or with --velocity")
    v0 = float(trace.v0)
    k_m = float(trace.k_m if trace.k_m is not None else k_m)
    _validate.positive("k_m", k_m)
    sensor = _sensor_for(trace, bandwidth)
    start = _initial_guess(trace, window, sensor, k_m, v0)
    # The whole trace is fitted: the pre- and post-contact samples pin down the floor level (a free offset,
    # so its uncertainty reaches the parameters') and the impact time. Weight by the noise; a noiseless
    # synthetic trace gets unit weights.
    problem = _Residuals(
        times=trace.time,
        force=trace.force - window.floor.level,
        sigma=window.floor.sigma if window.floor.sigma > 0 else 1.0,
        k_m=k_m,
        v0=v0,
        sensor=sensor,
        reaction=reaction,
        impact_guess=start["impact_time"],
    )
    x0 = np.array([math.log(start[name]) for name in PARAMETERS] + [0.0, 0.0])
    earliest, latest = _impact_range(trace, window, sensor, start["impact_time"])
    wide = math.log(1e3)  # parameters are searched within three decades of the initial guess
    offset = 10.0  # the floor's level is known from the pre-impact samples to far better than 10 sigma
    half_range = np.array([wide, wide, wide, wide, 0.0, offset])
    bounds = (x0 - half_range, x0 + half_range)
    bounds[0][4], bounds[1][4] = earliest - 1.0, latest + 1.0

    best = _restarted(problem, _scanned_solve(problem, x0, bounds, (earliest, latest)), bounds)
    if not best.success:
        raise FitFailed(f"one-shot fit of {trace.source or trace.label}", best.message)
    return _fit_record(problem, best)


@dataclass(frozen=True)
class _Residuals:
    """The weighted residuals of the one-shot fit [noise sigmas], a function of the fit's vector ``x``.

    ``x = (log m_f, log k_s, log F_s, log a, shift, offset)``, in kg, N/m, N and m/s^2 under the logarithms.

    ``shift`` moves the impact time from ``impact_guess`` [s] in samples; ``offset`` is the floor's offset in
    noise ``sigma`` [N]. ``times`` [s] and ``force`` [N] are the whole trace, floor subtracted.
    """

    times: np.ndarray
    force: np.ndarray
    sigma: float
    k_m: float
    v0: float
    sensor: SensorModel
    reaction: str
    impact_guess: float

    def unpack(self, x: np.ndarray) -> tuple[float, float, float, float, float]:
        """``(m_f, k_s, F_s, a, impact_time)`` in kg, N/m, N, m/s^2 and s."""
        m_f, k_s, F_s, a = np.exp(x[:4])
        return m_f, k_s, F_s, a, self.impact_guess + x[4] * self.sensor.period

    def __call__(self, x: np.ndarray) -> np.ndarray:
        m_f, k_s, F_s, a, t0 = self.unpack(x)
        k = series_stiffness(self.k_m, k_s)
        model = model_samples(self.times, m_f, k, self.k_m, F_s, a, self.v0, t0, self.sensor, self.reaction)
        return (model + x[5] * self.sigma - self.force) / self.sigma


def _solve(problem: _Residuals, x_start: np.ndarray, bounds: tuple[np.ndarray, np.ndarray]) -> Any:
    """One bounded least-squares run from ``x_start`` (clipped into the bounds)."""
    from scipy.optimize import least_squares

    x_start = np.clip(x_start, bounds[0], bounds[1])
    return least_squares(problem, x_start, bounds=bounds, method="trf", max_nfev=200)


def _shifted(x: np.ndarray, shift: float) -> np.ndarray:
    """``x`` with the impact time moved by ``shift`` samples."""
    moved = x.copy()
    moved[4] += shift
    return moved


def _impact_range(
    trace: Trace, window: ContactWindow, sensor: SensorModel, guess: float
) -> tuple[float, float]:
    """Earliest and latest impact time the samples allow, as shifts from ``guess`` [samples].

    The impact follows the last sample at the floor before the contact (less the filter's delay, by which
    the filtered rise lags) and precedes the first sample above the contact threshold.
    """
    period = sensor.period
    first = window.start + int(np.argmax(trace.force[window.slice] > window.threshold))
    delay = 0.0 if sensor.bandwidth is None else 2 * sensor.sampling_rate / sensor.bandwidth
    earliest = (float(trace.time[window.start]) - guess) / period - 1.0 - delay
    latest = (float(trace.time[first]) - guess) / period
    return min(earliest, -1.5), max(latest, 1.5)


def _scanned_solve(
    problem: _Residuals, x0: np.ndarray, bounds: tuple[np.ndarray, np.ndarray], shifts: tuple[float, float]
) -> Any:
    """Scan the impact time over ``shifts`` [samples] (the other parameters at their guesses) and refine.

    The refinement starts from the scan's best point and from the centroid guess; the better fit wins. A
    centroid guess can be samples off when the pulse is resolved, so the scan covers every impact time the
    samples allow (:func:`_impact_range`), not just a neighbourhood of the guess.
    """
    grid = np.arange(shifts[0], shifts[1] + 0.05, 0.05)  # a twentieth of a sample
    scan = [float(np.sum(problem(_shifted(x0, shift)) ** 2)) for shift in grid]
    best = _solve(problem, _shifted(x0, float(grid[int(np.argmin(scan))])), bounds)
    if abs(float(grid[int(np.argmin(scan))])) > 1.0:
        from_guess = _solve(problem, x0, bounds)
        if from_guess.cost < best.cost:
            best = from_guess
    return best


def _restarted(problem: _Residuals, best: Any, bounds: tuple[np.ndarray, np.ndarray]) -> Any:
    """The best of ``best`` and two fits restarted from other impact times, the other parameters kept.

    The impact pulse ends in a jump (the quarter sine stops at its peak), so the sampled model's cost has a
    kink wherever the pulse's end crosses a sample boundary, and the solver can stop on one: a clean trace of
    a resolved pulse fitted to 1.34 times its noise where the true parameters give 1.01, the pulse's end 0.01
    samples from a boundary. Restarts with the impact time :data:`_RESTART_SHIFT` samples earlier and later
    move the pulse's end off the kink, on either side.

    A pulse shorter than a sample that lies inside one sampling interval leaves the cost flat in the impact
    time instead, and the solver stops anywhere on that plateau; the data may want the pulse to spill a little
    into the previous or the next sample: the restarts are at both ends of the plateau.
    """
    period = problem.sensor.period
    m_f, _, _, _, t0 = problem.unpack(best.x)
    width = float(impact_pulse_duration(m_f, problem.k_m))
    if width < period:
        j = int(np.argmin(np.abs(problem.times - (t0 + width / 2))))
        ends = (problem.times[j] - period / 2 - 0.1 * width, problem.times[j] + period / 2 - 0.9 * width)
        starts = [(end - problem.impact_guess) / period for end in ends]
    else:
        starts = [best.x[4] - _RESTART_SHIFT, best.x[4] + _RESTART_SHIFT]
    for start in starts:
        x_start = best.x.copy()
        x_start[4] = start
        found = _solve(problem, x_start, bounds)
        if found.cost < best.cost:
            best = found
    return best


def _fit_record(problem: _Residuals, best: Any) -> OneShotFit:
    """The fit's record: values at the optimum, uncertainties from the Jacobian (module docstring)."""
    n, p = problem.times.size, best.x.size
    residual_variance = 2 * best.cost / max(n - p, 1)
    covariance, unidentified = _covariance(best.jac, residual_variance)
    m_f, k_s, F_s, a, t0 = problem.unpack(best.x)
    # Within a couple of samples the reaction shows only as an area that trades with the ramp's last sample:
    # its curvature (a) is not seen, whatever the local Jacobian says about the fit found.
    unidentified[3] |= _reaction_time(problem, F_s, a) < _RESOLVED_SAMPLES * problem.sensor.period
    log_stderr = np.sqrt(np.clip(np.diag(covariance), 0.0, None))
    log_stderr[unidentified] = math.inf
    stderr = {
        name: value * s for name, value, s in zip(PARAMETERS, (m_f, k_s, F_s, a), log_stderr, strict=False)
    }
    stderr["impact_time"] = float(log_stderr[4] * problem.sensor.period)
    residual_rms = float(np.sqrt(2 * best.cost / n)) * problem.sigma
    names = [name for name, bad in zip((*PARAMETERS, "impact_time"), unidentified, strict=False) if bad]
    return OneShotFit(
        m_f=m_f,
        k_s=k_s,
        F_s=F_s,
        a=a,
        impact_time=t0,
        stderr=stderr,
        k_m=problem.k_m,
        v0=problem.v0,
        sensor=problem.sensor,
        reaction=problem.reaction,
        residual_rms=residual_rms,
        samples=n,
        phase_stderr=_phase_stderr(
            best.x, covariance, unidentified, problem.k_m, problem.v0, problem.reaction
        ),
        notes=_notes(problem, names, residual_rms, F_s, a),
    )


def _covariance(jac: np.ndarray, residual_variance: float) -> tuple[np.ndarray, np.ndarray]:
    """Covariance of the fit's vector over its determined directions, and which entries are not identifiable.

    From the singular values ``s_i`` of the Jacobian (in noise units): the uncertainty along direction ``i``
    is ``sqrt(residual_variance) / s_i``; a direction beyond :data:`_IDENTIFIED` is not determined, and every
    entry with a share of it (a component above 0.1) is not identifiable.
    """
    _, singular, vt = np.linalg.svd(jac, full_matrices=False)
    with np.errstate(divide="ignore"):
        spread = np.sqrt(residual_variance) / singular
    determined = spread <= _IDENTIFIED
    v = vt.T
    covariance = (v[:, determined] * spread[determined] ** 2) @ v[:, determined].T
    unidentified = np.any(np.abs(v[:, ~determined]) > 0.1, axis=1)
    return covariance, unidentified


def _reaction_time(problem: _Residuals, F_s: float, a: float) -> float:
    """The fitted model's reaction time ``t2 - t1`` [s] (the robot moving at ``v0`` for ``"moving"``)."""
    v_r = problem.v0 if problem.reaction == "moving" else 0.0
    return float(reaction_duration(F_s, problem.k_m, a, v_r))


def _notes(
    problem: _Residuals, unidentified: list[str], residual_rms: float, F_s: float, a: float
) -> tuple[str, ...]:
    """What the fit's user must know: unidentifiable parameters, a residual far above the noise."""
    notes = []
    if unidentified:
        why = "the samples determine only a combination of them, or nothing of them"
        reaction = _reaction_time(problem, F_s, a)
        if {"F_s", "a"} & set(unidentified) and reaction < _RESOLVED_SAMPLES * problem.sensor.period:
            why = (
                f"the fitted reaction lasts {reaction:.2g} s, under {_RESOLVED_SAMPLES} sampling intervals of "
                f"{problem.sensor.period:.2g} s: detection and the end of contact share a sample or two"
            )
        notes.append(f"not identifiable: {', '.join(unidentified)} ({why}); their uncertainty is infinite")
    ratio = residual_rms / problem.sigma
    if problem.sigma > 0 and ratio > RESIDUAL_LIMIT:
        notes.append(
            f"residual rms {residual_rms:.3g} N is {ratio:.1f} times the noise floor's {problem.sigma:.3g} N: "
            "the model does not describe this trace; do not trust its parameters"
        )
    return tuple(notes)


def _sensor_for(trace: Trace, bandwidth: float | None) -> SensorModel:
    steps = np.diff(trace.time)
    period = float(np.median(steps))
    jitter = float(np.max(np.abs(steps - period))) / period
    if jitter > 0.05:  # the sensor model (interval means, digital filter) needs a fixed rate
        trace.fail(
            f"irregular sampling: steps vary by {jitter:.0%} around {period:.4g} s; the fit needs a fixed rate"
        )
    return SensorModel(1.0 / period, bandwidth)


def _initial_guess(
    trace: Trace, window: ContactWindow, sensor: SensorModel, k_m: float, v0: float
) -> dict[str, float]:
    """Read a starting point off the trace.

    The impact pulse is the run of samples from the first rise over its first peak down to the next local
    minimum (plus the filter's settling); its area above the ramp gives ``m_f v0`` and its centroid the
    impact time (interval means keep a pulse's centroid; the filter delays it by its group delay at DC, and
    the model's quarter-sine pulse has its centroid ``1/w = sqrt(m_f/k_m)`` after the impact). ``F_s`` is the
    smoothed peak after the pulse, ``k v0`` the slope up to it, and ``a`` follows from the reaction's duration.
    """
    from scipy.ndimage import median_filter

    period = sensor.period
    force = trace.force[window.slice] - window.floor.level
    time = trace.time[window.slice]
    above = np.flatnonzero(force > window.threshold - window.floor.level)
    first, last = int(above[0]), int(above[-1])
    settle = 0 if sensor.bandwidth is None else math.ceil(2 * sensor.sampling_rate / sensor.bandwidth)
    peak = first
    while peak + 1 <= last and force[peak + 1] > force[peak]:
        peak += 1
    pulse_end = peak
    while pulse_end + 1 <= last and force[pulse_end + 1] < force[pulse_end]:
        pulse_end += 1
    pulse_end = min(pulse_end + settle, last)
    pulse = slice(max(first - 1, 0), pulse_end + 1)
    pulse_force = force[pulse]
    centroid = float(np.sum(time[pulse] * pulse_force) / np.sum(pulse_force))
    area = float(np.sum(pulse_force)) * period

    # F_s and the ramp: the smoothed maximum after the pulse.
    smooth = median_filter(force, size=5, mode="nearest")
    after = pulse_end + 1 if pulse_end < last else first
    top = after + int(np.argmax(smooth[after : last + 1]))
    F_s = max(float(smooth[top]), 1e-3 * float(force.max()))
    # First pass at the impact time, refined once the pulse's own centroid offset is known.
    impact_time = centroid - _filter_delay(sensor) * period
    t1 = max(float(time[top]) - impact_time, period)
    k = min(F_s / (t1 * v0), 0.5 * k_m)
    k_s = _software_stiffness(k, k_m)
    duration = max(float(time[last] - time[top]), period)
    a = 2 * F_s / (k_m * duration**2)
    ramp_area = k * v0 * (float(time[pulse_end] - time[first]) + period) ** 2 / 2
    total_area = float(np.sum(force)) * period
    m_f = max(area - ramp_area, 0.01 * total_area) / v0
    impact_time -= math.sqrt(m_f / k_m)
    return {"m_f": m_f, "k_s": k_s, "F_s": F_s, "a": a, "impact_time": impact_time}


def _software_stiffness(k: float, k_m: float) -> float:
    """The software stiffness [N/m] that in series with ``k_m`` [N/m] gives ``k`` [N/m] (``k < k_m``).

    The inverse of :func:`~collision_reflex.model.impulse.series_stiffness`: compliances add there, so here
    ``1/k_s = 1/k - 1/k_m``.
    """
    return 1.0 / (1.0 / k - 1.0 / k_m)


def _filter_delay(sensor: SensorModel) -> float:
    """Group delay of the sensor's filter at zero frequency [samples].

    The centroid of its impulse response.
    """
    if sensor.bandwidth is None:
        return 0.0
    impulse = np.zeros(int(50 * sensor.sampling_rate / sensor.bandwidth) + 50)
    impulse[0] = 1.0
    response = sensor.filtered(impulse)
    return float(np.sum(np.arange(impulse.size) * response) / np.sum(response))


def _phase_stderr(
    x: np.ndarray, covariance: np.ndarray, unidentified: np.ndarray, k_m: float, v0: float, reaction: str
) -> dict[str, float]:
    """First-order propagation of the (log-)parameter covariance through the phase impulses.

    A phase that depends on a parameter that is not identifiable has an infinite uncertainty.
    """

    def phases(xx: np.ndarray) -> np.ndarray:
        m_f, k_s, F_s, a = np.exp(xx[:4])
        p = phase_impulses(m_f, series_stiffness(k_m, k_s), k_m, F_s, a, v0, reaction)
        return np.array([p.initial, p.sensing, p.reaction, p.total], dtype=float)

    step = 1e-6  # relative step in each parameter (log space): central differences, error ~ step^2
    gradient = np.zeros((len(_PHASES), x.size))
    for j in range(4):
        up, down = x.copy(), x.copy()
        up[j] += step
        down[j] -= step
        gradient[:, j] = (phases(up) - phases(down)) / (2 * step)
    variance = np.einsum("ij,jk,ik->i", gradient, covariance, gradient)
    # A dependence below a millionth (relative) of the phase is no dependence (central-difference noise).
    depends = np.abs(gradient[:, unidentified]) > 1e-6 * np.abs(phases(x))[:, None]
    variance[np.any(depends, axis=1)] = math.inf
    return {name: float(np.sqrt(max(v, 0.0))) for name, v in zip(_PHASES, variance, strict=True)}
