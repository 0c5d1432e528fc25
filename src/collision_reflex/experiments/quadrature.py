"""The measured collision reflex: the area under a trace's force over its contact window.

As in the paper, the area is integrated by adaptive Gauss-Kronrod quadrature (QUADPACK through
``scipy.integrate.quad``, with the sample times as breakpoints) over a shape-preserving piecewise-cubic
(PCHIP) interpolant of the floor-corrected samples; PCHIP does not overshoot next to a sharp impact peak as a
spline would. The trapezoid rule over the same samples is the cross-check.

Uncertainty, combined in quadrature (independent sources):

- noise: white noise of standard deviation ``sigma`` on each sample propagates through the trapezoid weights
  ``w_i`` as ``sigma sqrt(sum w_i^2)`` (about ``sigma T sqrt(n)`` for ``n`` samples ``T`` apart);
- floor: the floor level is the mean of ``m`` pre-impact samples, uncertain by ``sigma / sqrt(m)``, and it
  is subtracted over the whole window of duration ``D``: ``D sigma / sqrt(m)``;
- discretisation: the difference between the quadrature and the trapezoid rule (how much the answer
  depends on how the samples are joined), plus QUADPACK's own error estimate.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .traces import Trace
from .window import ContactWindow


@dataclass(frozen=True)
class ImpulseEstimate:
    """Impulse of one trace over its contact window [N*s].

    Attributes
    ----------
    value: adaptive Gauss-Kronrod quadrature of the interpolated samples [N*s].
    trapezoid: trapezoid rule over the same samples [N*s].
    uncertainty: one-standard-deviation uncertainty [N*s], the root sum of squares of the parts below.
    noise: part from the sample noise [N*s].
    floor: part from the uncertainty of the subtracted noise floor [N*s].
    discretisation: ``|value - trapezoid|`` plus QUADPACK's error estimate [N*s].
    duration: length of the contact window [s].
    """

    value: float
    trapezoid: float
    uncertainty: float
    noise: float
    floor: float
    discretisation: float
    duration: float


def measure_impulse(trace: Trace, window: ContactWindow) -> ImpulseEstimate:
    """Integrate ``trace``'s force above its noise floor over ``window``.

    Parameters
    ----------
    trace: the trace [s, N].
    window: its contact window, from :func:`~collision_reflex.experiments.find_contact`.
    """
    from scipy.integrate import quad
    from scipy.integrate import trapezoid as trapezoid_rule
    from scipy.interpolate import PchipInterpolator

    time = trace.time[window.slice]
    force = trace.force[window.slice] - window.floor.level
    interpolant = PchipInterpolator(time, force)
    breakpoints = time[1:-1]
    value, quad_error = quad(
        interpolant,
        time[0],
        time[-1],
        points=breakpoints,
        limit=breakpoints.size + 50,
        epsabs=0.0,
        epsrel=1e-10,
    )
    trapezoid = float(trapezoid_rule(force, time))
    steps = np.diff(time)
    weights = np.concatenate([[steps[0]], steps[1:] + steps[:-1], [steps[-1]]]) / 2
    sigma = window.floor.sigma
    noise = sigma * float(np.sqrt(np.sum(weights**2)))
    duration = float(time[-1] - time[0])
    floor = duration * sigma / np.sqrt(window.floor.samples)
    discretisation = abs(value - trapezoid) + abs(quad_error)
    return ImpulseEstimate(
        value=float(value),
        trapezoid=trapezoid,
        uncertainty=float(np.sqrt(noise**2 + floor**2 + discretisation**2)),
        noise=noise,
        floor=float(floor),
        discretisation=float(discretisation),
        duration=duration,
    )
