"""What a sampled force sensor reports for the model's force profile.

The model's impact pulse (the compression quarter-period of ``m_f`` on the sensor stiffness ``k_m``) lasts
``pi/2 sqrt(m_f/k_m)``, about 0.1 ms for ``m_f = 0.1 kg`` and ``k_m = 2e7 N/m``: shorter than one sample at
3500 Hz. Comparing the model's instantaneous force with the samples would make the fit depend on where the
samples happen to fall. The sensor is therefore modelled as it reports:

1. an integrating sampler: each sample is the mean force over its sampling interval
   ``[t_i - T/2, t_i + T/2]`` (``T = 1 / sampling_rate``), so a pulse shorter than a sample keeps its area;
2. optionally a causal digital Butterworth low-pass of the given cutoff (``bandwidth``), the kind of filter a
   force/torque data-acquisition system applies, with unit DC gain, so areas are kept again;
3. optionally saturation at ``+-full_scale`` (a clipped sensor; applied by the synthetic-trace generator
   after the noise, never by the fit, which refuses clipped traces).

Both the synthetic-trace generator and the one-shot fit use :func:`model_samples`, so the fit compares like
with like. The interval means are exact to rounding: an interval is split at the profile's breakpoints
(impact, end of the pulse, detection ``t1``, end of contact ``t2``) and every smooth piece is integrated by
Gauss-Legendre quadrature (the ramp and the reaction are polynomials of degree 1 and 2, integrated exactly).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from .. import _validate
from ..errors import InvalidParameter
from ..model.impulse import collision_times, force_profile, impact_pulse_duration

# 8 Gauss-Legendre nodes integrate the pulse's sine over a quarter period to ~1e-13 relative and the ramp
# and the reaction's parabola exactly.
_GAUSS_NODES = 8


@dataclass(frozen=True)
class SensorModel:
    """A force sensor sampled at a fixed rate.

    Parameters
    ----------
    sampling_rate: samples per second [Hz] (the paper's ATI Mini40 stream: 3500 Hz).
    bandwidth: cutoff frequency of the sensor's digital low-pass filter [Hz], below the Nyquist frequency
        ``sampling_rate / 2``; ``None`` for no filter (samples are interval means only).
    filter_order: order of the Butterworth low-pass (1 to 8).
    full_scale: the sensor's range [N]: readings saturate at ``+-full_scale``; ``None`` for no limit.
    """

    sampling_rate: float
    bandwidth: float | None = None
    filter_order: int = 2
    full_scale: float | None = None

    def __post_init__(self) -> None:
        _validate.positive("sampling_rate", self.sampling_rate)
        if self.bandwidth is not None:
            _validate.positive("bandwidth", self.bandwidth)
            if self.bandwidth >= self.sampling_rate / 2:
                raise InvalidParameter(
                    "bandwidth",
                    self.bandwidth,
                    f"a cutoff below the Nyquist frequency {self.sampling_rate / 2:g} Hz",
                    "give the sensor's low-pass cutoff, or None for no filter",
                )
        if not isinstance(self.filter_order, int) or not 1 <= self.filter_order <= 8:
            raise InvalidParameter("filter_order", self.filter_order, "an integer from 1 to 8")
        if self.full_scale is not None:
            _validate.positive("full_scale", self.full_scale)

    @property
    def period(self) -> float:
        """Sampling interval [s]."""
        return 1.0 / self.sampling_rate

    def filtered(self, samples: np.ndarray) -> np.ndarray:
        """Pass interval-mean samples [N] (last axis is time) through the low-pass, starting at rest."""
        if self.bandwidth is None:
            return samples
        from scipy.signal import lfilter

        b, a = _butterworth(self.filter_order, self.bandwidth / (self.sampling_rate / 2))
        return lfilter(b, a, samples, axis=-1)

    def saturated(self, samples: np.ndarray) -> np.ndarray:
        """Readings [N] clipped to the sensor's range."""
        if self.full_scale is None:
            return samples
        return np.clip(samples, -self.full_scale, self.full_scale)


@functools.lru_cache(maxsize=32)
def _butterworth(order: int, cutoff: float) -> tuple[np.ndarray, np.ndarray]:
    from scipy.signal import butter

    b, a = butter(order, cutoff)
    return b, a


def model_samples(
    times: np.ndarray,
    m_f: float,
    k: float,
    k_m: float,
    F_s: float,
    a: float,
    v0: float,
    impact_time: float,
    sensor: SensorModel,
    reaction: str = "at_rest",
) -> np.ndarray:
    """What ``sensor`` reports at ``times`` [s] for the model's force profile with impact at ``impact_time``.

    Parameters
    ----------
    times: sample times [s], shape (n,), spaced ``sensor.period`` apart (the filter assumes a fixed rate).
    m_f, k, k_m, F_s, a, v0, reaction: the model's parameters as :func:`collision_reflex.model.force_profile`:
        finger mass [kg], sensing stiffness [N/m], mechanical stiffness [N/m], threshold [N], reaction
        acceleration [m/s^2], pre-impact velocity [m/s].
    impact_time: time of impact on the trace's clock [s].
    sensor: the sensor model.

    Returns
    -------
    Readings [N], shape (n,), without noise, bias or saturation.
    """
    model = (m_f, k, k_m, F_s, a, v0)
    t1, t2 = collision_times(*model, reaction)
    half = sensor.period / 2
    shifted = np.asarray(times, dtype=float) - impact_time
    lower, upper = shifted - half, shifted + half
    pulse_end = float(impact_pulse_duration(m_f, k_m))
    breakpoints = np.array([0.0, pulse_end, float(t1), float(t2)])
    means = np.zeros(shifted.shape)
    in_contact = (upper > 0.0) & (lower < float(t2))
    # Intervals holding a breakpoint or part of the pulse are split at the breakpoints and each smooth piece
    # gets 8 Gauss-Legendre nodes; the others see only the ramp's line or the reaction's parabola, which 2
    # nodes integrate exactly.
    split = in_contact & (
        np.any((breakpoints[None, :] > lower[:, None]) & (breakpoints[None, :] < upper[:, None]), axis=1)
        | (lower < pulse_end)
    )
    plain = in_contact & ~split
    if np.any(plain):
        nodes, weights = np.polynomial.legendre.leggauss(2)
        centre = shifted[plain]
        force = force_profile(centre[:, None] + half * nodes, *model, reaction)
        means[plain] = force @ weights / 2
    if np.any(split):
        lo, hi = lower[split], upper[split]
        edges = np.concatenate(
            [lo[:, None], np.clip(breakpoints[None, :], lo[:, None], hi[:, None]), hi[:, None]], axis=1
        )
        edges.sort(axis=1)
        left, right = edges[:, :-1], edges[:, 1:]
        nodes, weights = np.polynomial.legendre.leggauss(_GAUSS_NODES)
        centre, radius = (left + right) / 2, (right - left) / 2
        force = force_profile(centre[..., None] + radius[..., None] * nodes, *model, reaction)
        means[split] = np.sum(force * weights * radius[..., None], axis=(1, 2)) / sensor.period
    return sensor.filtered(means)
