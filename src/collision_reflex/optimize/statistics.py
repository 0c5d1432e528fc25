"""How sure a sampled statistic of the collision impulse is: mean, high quantile and CVaR with their errors.

A mean or a quantile over random samples of the contact domain is an estimate; its sampling error shrinks as
one over the square root of the number of configurations. The samples of one configuration (its directions) are
correlated, so the error comes from a cluster bootstrap: configurations are drawn with replacement, each with all
its drawn samples, and the statistic recomputed; the 0.5 and 99.5 percentiles of the replicates bound a 99 %
interval. A percentile interval of a skewed statistic covers less than its level with a few hundred
configurations, so the stated interval is the 99 % one (benchmarks/results/worst_case.md gives the coverage
measured at 95 %). The relative error is its larger half-width over the estimate.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import InvalidParameter
from .objectives import CVAR_LEVEL, conditional_value_at_risk

BOOTSTRAP_REPLICATES = 1000
"""Bootstrap replicates of a statistic: enough for the 0.5 and 99.5 percentiles (five replicates beyond each)."""

LEVEL = 0.99
"""Confidence level of the stated intervals (the module's description says why not 95 %)."""

_CHUNK = 20
"""Bootstrap replicates drawn at a time (a replicate's cluster counts are one row)."""

_TAIL_FACTOR = 2
"""Samples ranked per replicate: this many times the widest tail's share of the samples (the quantile's and the
CVaR's). A replicate's tail fits in them unless the ranked samples weigh less than half their expected weight
in it, far beyond the 99 % interval; a replicate whose tail does not fit is ranked over every sample."""

QUANTILE = 0.99
"""The quantile of the impulse every design reports beside its mean."""


@dataclass(frozen=True)
class Estimate:
    """A sampled statistic with its :data:`LEVEL` interval (cluster bootstrap).

    value: the estimate [N*s]; low, high: the interval's ends [N*s]; configurations, samples: how many the
    estimate rests on.
    """

    value: float
    low: float
    high: float
    configurations: int
    samples: int

    @property
    def relative_error(self) -> float:
        """The interval's larger half-width relative to the estimate [-]."""
        return (
            float(max(self.value - self.low, self.high - self.value) / abs(self.value)) if self.value else 0.0
        )

    def to_json(self) -> dict[str, float | int]:
        """The estimate as JSON types."""
        return {
            "value": self.value,
            "low": self.low,
            "high": self.high,
            "relative_error": self.relative_error,
            "configurations": self.configurations,
            "samples": self.samples,
        }


def impulse_statistics(
    impulses: np.ndarray,
    groups: np.ndarray,
    quantile: float = QUANTILE,
    rng: np.random.Generator | None = None,
) -> dict[str, Estimate]:
    """The mean, the ``quantile`` and the CVaR of ``impulses`` [N*s] with their :data:`LEVEL` intervals.

    Keyed ``mean_impulse``, ``quantile_impulse`` and ``cvar_impulse`` (at :data:`~.objectives.CVAR_LEVEL`).

    ``groups`` (n,) names each impulse's configuration (the bootstrap's clusters); ``rng`` draws the replicates
    (default ``numpy.random.default_rng(0)``: the same figures for the same samples).

    Raises
    ------
    InvalidParameter: no impulses, shapes that differ, non-finite impulses, or a quantile outside (0, 1).
    """
    values = np.asarray(impulses, dtype=float).ravel()
    labels = np.asarray(groups).ravel()
    if values.size == 0 or labels.shape != values.shape:
        raise InvalidParameter(
            "impulses", values.shape, f"a non-empty array, one group label each {labels.shape}"
        )
    if not np.all(np.isfinite(values)):
        raise InvalidParameter("impulses", values, "finite impulses [N*s]")
    if not 0 < quantile < 1:
        raise InvalidParameter("quantile", quantile, "a quantile in (0, 1)")
    generator = rng if rng is not None else np.random.default_rng(0)
    _, cluster = np.unique(labels, return_inverse=True)
    n_clusters = int(cluster.max()) + 1
    sizes = np.bincount(cluster).astype(float)
    sums = np.bincount(cluster, weights=values)
    # A replicate's quantile lies in the upper tail: only the largest samples are ranked per replicate (those
    # whose weight does not reach the quantile's tail fall back to every sample).
    descending = np.argsort(values)[::-1]
    widest = 1 - min(quantile, CVAR_LEVEL)
    top = descending[: min(values.size, max(64, int(np.ceil(_TAIL_FACTOR * widest * values.size))))]
    means, quantiles, tails = [], [], []
    for start in range(0, BOOTSTRAP_REPLICATES, _CHUNK):
        count = min(_CHUNK, BOOTSTRAP_REPLICATES - start)
        picks = generator.integers(0, n_clusters, size=(count, n_clusters))
        # Each replicate's multiplicity of every cluster; a sample counts as many times as its cluster.
        flat = (np.arange(count)[:, None] * n_clusters + picks).ravel()
        counts = np.bincount(flat, minlength=count * n_clusters).reshape(count, n_clusters).astype(float)
        total = counts @ sizes
        means.append(counts @ sums / total)
        found = _tail_statistics(values, counts, cluster, descending, top, total, (quantile, CVAR_LEVEL))
        quantiles.append(found[0][0])
        tails.append(found[1][1])

    def estimate(value: float, replicates: np.ndarray) -> Estimate:
        low, high = np.percentile(replicates, [50 * (1 - LEVEL), 50 * (1 + LEVEL)])
        return Estimate(
            float(value), float(min(low, value)), float(max(high, value)), n_clusters, values.size
        )

    return {
        "mean_impulse": estimate(float(values.mean()), np.concatenate(means)),
        "quantile_impulse": estimate(
            float(np.quantile(values, quantile, method="inverted_cdf")), np.concatenate(quantiles)
        ),
        "cvar_impulse": estimate(
            conditional_value_at_risk(values, np.ones(values.size)), np.concatenate(tails)
        ),
    }


def _tail_statistics(
    values: np.ndarray,
    counts: np.ndarray,
    cluster: np.ndarray,
    descending: np.ndarray,
    top: np.ndarray,
    total: np.ndarray,
    levels: tuple[float, ...],
) -> list[tuple[np.ndarray, np.ndarray]]:
    """Each replicate's weighted quantile and CVaR of ``values`` at each of ``levels``.

    A replicate's weights are its clusters' ``counts`` (replicates, clusters); ``total`` (replicates,) their sums.

    The quantile is the inverted CDF's: the smallest value whose cumulative weight from below reaches the level
    of ``total``, i.e. the largest value with no more than the tail's weight ``(1 - level) total`` strictly
    above it. The CVaR is the weighted mean of that tail (the values above, and the quantile for the rest of the
    tail's weight). Ranked over the ``top`` samples (the largest, in ``descending`` order), over all for a
    replicate whose tail reaches beyond them.
    """
    tails = [(1 - level) * total for level in levels]

    def ranked(order: np.ndarray, rows: np.ndarray) -> tuple[list[tuple[np.ndarray, np.ndarray]], np.ndarray]:
        weights = counts[rows][:, cluster[order]]
        ordered = values[order]
        above = np.cumsum(weights, axis=1) - weights  # weight strictly above each ranked sample
        weighted = np.cumsum(weights * ordered, axis=1) - weights * ordered
        at = np.arange(rows.size)
        out = []
        for tail in tails:
            position = (above <= tail[rows, None]).sum(axis=1) - 1
            quantile = ordered[position]
            cvar = (weighted[at, position] + (tail[rows] - above[at, position]) * quantile) / tail[rows]
            out.append((quantile, cvar))
        return out, above[:, -1] + weights[:, -1]

    rows = np.arange(counts.shape[0])
    found, ranked_weight = ranked(top, rows)
    beyond = ranked_weight <= tails[int(np.argmin(levels))]  # the widest tail reaches beyond the ranked top
    if np.any(beyond) and top.size < values.size:
        again, _ = ranked(descending, rows[beyond])
        for (quantile, cvar), (quantile_all, cvar_all) in zip(found, again, strict=True):
            quantile[beyond], cvar[beyond] = quantile_all, cvar_all
    return found
