"""How sure a sampled statistic of the collision impulse is: the mean and a high quantile with their errors.

A mean or a quantile over random samples of the contact domain is an estimate; its sampling error shrinks as
one over the square root of the number of configurations. The samples of one configuration (its directions) are
correlated, so the error comes from a cluster bootstrap: configurations are drawn with replacement, each with all
its drawn samples, and the statistic recomputed; the 0.5 and 99.5 percentiles of the replicates bound a 99 %
interval. A percentile interval of a skewed statistic covers less than its level with a few hundred
configurations (measured on correlated lognormal samples, 300 configurations of 14 samples: 95 % intervals held
the true mean in 90 % and the true 99th percentile in 86-88 % of 200 seeded draws; 99 % intervals in 96 % and
93 %), so the stated interval is the 99 % one. The relative error is its larger half-width over the estimate.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import InvalidParameter

BOOTSTRAP_REPLICATES = 1000
"""Bootstrap replicates of a statistic: enough for the 0.5 and 99.5 percentiles (five replicates beyond each)."""

LEVEL = 0.99
"""Confidence level of the stated intervals (the module's description says why not 95 %)."""

_CHUNK = 50

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
    """The mean and the ``quantile`` of ``impulses`` [N*s] with their :data:`LEVEL` intervals.

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
    order = np.argsort(values)
    means, quantiles = [], []
    for start in range(0, BOOTSTRAP_REPLICATES, _CHUNK):  # in chunks: a replicate's weights are one row of n
        count = min(_CHUNK, BOOTSTRAP_REPLICATES - start)
        picks = generator.integers(0, n_clusters, size=(count, n_clusters))
        # Each replicate's multiplicity of every cluster, then of every sample (counted as its cluster).
        counts = np.zeros((count, n_clusters))
        np.add.at(counts, (np.arange(count)[:, None], picks), 1.0)
        weights = counts[:, cluster]  # (count, n)
        means.append(weights @ values / weights.sum(axis=1))
        cumulative = np.cumsum(weights[:, order], axis=1)
        # The weighted quantile of each replicate: the first sorted value whose cumulative weight reaches q.
        position = (cumulative < quantile * cumulative[:, -1:]).sum(axis=1)
        quantiles.append(values[order][np.minimum(position, values.size - 1)])

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
    }
