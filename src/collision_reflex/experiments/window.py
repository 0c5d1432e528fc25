"""The contact window of a trace: noise floor from the pre-impact samples, first rise, return to the floor.

The noise floor (level and standard deviation) is estimated from the samples before the contact. To find
them without knowing the contact, a robust first guess locates the first rise: the trace is cut into short
blocks, and the blocks whose median lies within a few noise deviations of the lowest one are taken to be
free of contact (a contact only adds force; the noise deviation is the median of the blocks' robust
spreads, since most blocks are either at the floor or on a slow ramp). Their pooled median and median
absolute deviation are the guess, wherever those blocks lie: before the impact, after the contact, or both.
A slow approach, whose ramp fills most of the trace, no longer passes for the floor. The floor is then
re-estimated from the samples before the first rise.
The contact runs from the first sample above ``level + n_sigma * sigma`` to the last one, and is widened on
each side until the force is back at the floor's level, so the rising and falling edges are integrated too.
Samples inside the contact that dip below the threshold (after a short impact pulse the sensing ramp starts
near zero) stay inside: the contact ends only when the force has returned to the floor for good.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import _validate
from .traces import Trace

MIN_BASELINE_SAMPLES = 10
"""Fewest pre-impact samples from which a noise floor is estimated."""

MIN_CONTACT_SAMPLES = 3
"""Fewest samples above the threshold that count as a contact rather than a noise spike."""

_MAD_TO_SIGMA = 1.4826  # median absolute deviation of a normal distribution, in standard deviations


@dataclass(frozen=True)
class NoiseFloor:
    """Force reported with nothing in contact.

    Attributes
    ----------
    level: mean of the pre-impact samples [N] (the sensor's bias, subtracted before integrating).
    sigma: their standard deviation [N].
    samples: how many pre-impact samples were used.
    """

    level: float
    sigma: float
    samples: int

    def __post_init__(self) -> None:
        _validate.non_negative("sigma", self.sigma)
        if self.samples < 2:
            raise ValueError("a noise floor needs at least two samples")


@dataclass(frozen=True)
class ContactWindow:
    """Where a trace is in contact.

    Attributes
    ----------
    start, stop: sample indices; the contact is ``slice(start, stop)``, edges at the floor included.
    floor: the noise floor.
    threshold: force above which a sample is in contact [N], ``floor.level + n_sigma * floor.sigma``.
    """

    start: int
    stop: int
    floor: NoiseFloor
    threshold: float

    def __post_init__(self) -> None:
        if not 0 <= self.start < self.stop:
            raise ValueError(f"empty contact window [{self.start}, {self.stop})")

    @property
    def slice(self) -> slice:
        """The contact's samples, ``start:stop``."""
        return slice(self.start, self.stop)


def find_contact(trace: Trace, n_sigma: float = 5.0, clip_run: int = 3) -> ContactWindow:
    """Noise floor and contact window of ``trace``.

    Parameters
    ----------
    trace: a trace that passes :meth:`Trace.check`.
    n_sigma: threshold above the floor, in standard deviations of the noise (5: a false rise on fewer than
        one in a million samples of Gaussian noise).
    clip_run: this many equal consecutive readings at the trace's extreme mark a saturated (clipped) sensor.

    Raises
    ------
    TraceError: no contact, too few pre-impact samples, contact still on at the end, or clipped.
    """
    _validate.positive("n_sigma", n_sigma)
    trace.check()
    force = trace.force
    n = force.size
    level, spread = _quiet_floor(force)
    first = _first_rise(force, level, n_sigma * spread, force.max())
    if first is None:
        trace.fail(
            f"no contact: no {MIN_CONTACT_SAMPLES} samples rise above the noise floor "
            f"({level:.4g} N +- {spread:.2g} N, peak {force.max():.4g} N)"
        )
    # Re-estimate the floor from everything before the rise, less two samples of guard for a slow edge.
    baseline = force[: max(first - 2, 0)]
    if baseline.size < MIN_BASELINE_SAMPLES:
        trace.fail(
            f"too short before contact: {baseline.size} pre-impact samples, need at least "
            f"{MIN_BASELINE_SAMPLES} to estimate the noise floor; record longer before the impact",
            first,
        )
    floor = NoiseFloor(float(np.mean(baseline)), float(np.std(baseline, ddof=1)), baseline.size)
    threshold = floor.level + _margin(n_sigma * floor.sigma, force.max() - floor.level)
    above = np.flatnonzero(force > threshold)
    if above.size < MIN_CONTACT_SAMPLES:
        trace.fail(f"no contact: only {above.size} sample(s) above the threshold {threshold:.4g} N")
    _check_clipping(trace, clip_run, floor.level, threshold - floor.level)
    start, last = int(above[0]), int(above[-1])
    while start > 0 and force[start - 1] > floor.level:
        start -= 1
    stop = last + 1
    while stop < n and force[stop] > floor.level:
        stop += 1
    if stop >= n:
        trace.fail(
            "contact still on at the end of the trace (the force never returns to the noise floor "
            f"{floor.level:.4g} N); record longer after the contact",
            n - 1,
        )
    # Include the first sample back at the floor on each side, so the edges are integrated to the floor.
    return ContactWindow(max(start - 1, 0), stop + 1, floor, threshold)


def _quiet_floor(force: np.ndarray) -> tuple[float, float]:
    """A robust first guess of the floor's level and noise deviation [N], from the blocks free of contact."""
    size = 2 * MIN_BASELINE_SAMPLES
    count = max(force.size // size, 1)
    blocks = force[: count * size].reshape(count, -1) if force.size >= size else force[None, :]
    medians = np.median(blocks, axis=1)
    spreads = _MAD_TO_SIGMA * np.median(np.abs(blocks - medians[:, None]), axis=1)
    noise = float(np.median(spreads))
    quiet = blocks[medians <= medians.min() + 3 * noise].ravel()
    level = float(np.median(quiet))
    return level, _MAD_TO_SIGMA * float(np.median(np.abs(quiet - level)))


def _margin(noise: float, peak: float) -> float:
    # A noiseless (synthetic) trace has sigma = 0: use a tiny fraction of the peak instead of zero.
    return max(noise, 1e-9 * abs(peak))


def _first_rise(force: np.ndarray, level: float, margin: float, peak: float) -> int | None:
    above = np.flatnonzero(force > level + _margin(margin, peak - level))
    return int(above[0]) if above.size >= MIN_CONTACT_SAMPLES else None


def _check_clipping(trace: Trace, run: int, level: float, margin: float) -> None:
    force = trace.force
    for extreme in (force.max(), force.min()):
        if abs(extreme - level) <= margin:
            continue  # a flat stretch at the floor (a noiseless record) is not saturation
        hits = force == extreme
        # Length of the longest run of consecutive samples at the extreme value.
        edges = np.diff(np.concatenate([[0], hits.astype(int), [0]]))
        starts, ends = np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)
        longest = int(np.max(ends - starts))
        if longest >= run:
            first = int(starts[np.argmax(ends - starts)])
            trace.fail(
                f"clipped: {longest} consecutive samples at {extreme:.6g} N (a saturated sensor); the "
                "impulse would be underestimated, so use a sensor with a larger range",
                first,
            )
