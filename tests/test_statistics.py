"""Sampled statistics of the impulse: their stated intervals cover the true value, checked on a 10^5-sample
reference of a planar 2R arm's impulses in its contact domain."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from collision_reflex.errors import InvalidParameter
from collision_reflex.optimize.design import design_at
from collision_reflex.optimize.evaluate import sample_impulses
from collision_reflex.optimize.objectives import CVAR_LEVEL
from collision_reflex.optimize.pieces import built_problem
from collision_reflex.optimize.samples import ContactSamples
from collision_reflex.optimize.statistics import QUANTILE, impulse_statistics
from collision_reflex.study.load import load_study
from collision_reflex.study.problems import StudyProblems
from collision_reflex.study.resolve import resolve_study

pytestmark = pytest.mark.xdist_group("test_statistics")  # one pytest-xdist worker: set-ups made once

ROOT = Path(__file__).resolve().parents[1]
DIRECTIONS = np.column_stack([np.cos(a := np.arange(8) * np.pi / 4 + 0.1), np.sin(a)])


@pytest.fixture(scope="module")
def impulses_of():
    problems = StudyProblems(resolve_study(load_study(ROOT / "studies" / "two_link_paper.yaml")))
    setup = problems.setup
    problem = built_problem(problems, problems.objective)
    design = design_at(problem, problem.x0)

    def draw(configurations: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
        found = setup.domain.draw(
            setup.arm, configurations, DIRECTIONS, design.approach_velocity, np.random.default_rng(seed)
        )
        config, direction = np.nonzero(found.feasible)
        samples = ContactSamples(setup.arm.kinematics(found.q), DIRECTIONS[direction], config)
        return sample_impulses(samples, setup.technology, design), config

    return draw


def test_stated_intervals_cover_the_true_mean_and_quantile(impulses_of):
    reference, _ = impulses_of(12_500, 12345)
    assert reference.size >= 95_000  # about 10^5 samples: the reference's own error is a tenth of a run's
    true_mean, true_quantile = reference.mean(), np.quantile(reference, QUANTILE)
    true_cvar = np.sort(reference)[-round((1 - CVAR_LEVEL) * reference.size) :].mean()
    runs, covered = 100, {"mean_impulse": 0, "quantile_impulse": 0, "cvar_impulse": 0}
    errors = []
    for seed in range(runs):
        values, groups = impulses_of(150, seed)
        stats = impulse_statistics(values, groups, rng=np.random.default_rng(seed))
        truths = (
            ("mean_impulse", true_mean),
            ("quantile_impulse", true_quantile),
            ("cvar_impulse", true_cvar),
        )
        for name, truth in truths:
            covered[name] += stats[name].low <= truth <= stats[name].high
        errors.append(stats["mean_impulse"].relative_error)
    # 99 % intervals; a percentile bootstrap of a skewed statistic covers less than its level: at least 90 %.
    assert all(count >= 0.9 * runs for count in covered.values()), covered
    # Not vacuous: intervals half as wide would miss far more often (the error is a real few per cent).
    assert 0.01 < np.median(errors) < 0.3


def test_the_error_shrinks_as_one_over_the_root_of_the_configurations(impulses_of):
    small = impulse_statistics(*impulses_of(100, 1))["mean_impulse"]
    large = impulse_statistics(*impulses_of(1600, 1))["mean_impulse"]
    assert large.relative_error == pytest.approx(small.relative_error / 4, rel=0.35)


def test_bad_samples_are_refused():
    with pytest.raises(InvalidParameter, match="finite"):
        impulse_statistics(np.array([1.0, np.nan]), np.array([0, 1]))
    with pytest.raises(InvalidParameter, match="quantile"):
        impulse_statistics(np.array([1.0, 2.0]), np.array([0, 1]), quantile=1.0)
    with pytest.raises(InvalidParameter, match="non-empty"):
        impulse_statistics(np.array([]), np.array([]))


@pytest.mark.parametrize("top", [64, 2000])  # the ranked top alone, and with replicates falling back to all
def test_each_replicate_s_quantile_and_cvar_are_those_of_its_resampled_impulses(top):
    """A replicate's weighted quantile against NumPy's inverted-CDF quantile of the samples it repeats, and its
    CVaR against the mean of the repeated samples' top (1 - level) share, the boundary sample's part pro rata."""
    from collision_reflex.optimize.statistics import _tail_statistics

    rng = np.random.default_rng(3)
    clusters, per = 400, 5
    cluster = np.repeat(np.arange(clusters), per)
    values = np.round(rng.lognormal(size=cluster.size), 2)  # rounded: ties, as equal impulses give
    counts = np.zeros((30, clusters))
    np.add.at(counts, (np.arange(30)[:, None], rng.integers(0, clusters, (30, clusters))), 1.0)
    descending = np.argsort(values)[::-1]
    levels = (0.5, 0.95, 0.99)
    total = counts @ np.bincount(cluster)
    for q, (found, cvar) in zip(
        levels,
        _tail_statistics(values, counts, cluster, descending, descending[:top], total, levels),
        strict=True,
    ):
        for row, value, tail_mean in zip(counts, found, cvar, strict=True):
            repeated = np.sort(np.repeat(values, row[cluster].astype(int)))[::-1]
            assert value == np.quantile(repeated, q, method="inverted_cdf")
            share = (1 - q) * repeated.size  # the tail's weight in samples, a fraction of one at its end
            whole = int(np.floor(share))
            expected = (repeated[:whole].sum() + (share - whole) * repeated[whole]) / share
            assert tail_mean == pytest.approx(expected, rel=1e-12)


def test_cvar_is_the_tail_mean_and_the_rockafellar_uryasev_minimum():
    from collision_reflex.optimize.objectives import conditional_value_at_risk

    rng = np.random.default_rng(8)
    values = rng.lognormal(size=200)
    # Equal weights, a tail of exactly 10 samples: their mean.
    assert conditional_value_at_risk(values, np.ones(200), 0.95) == pytest.approx(
        np.sort(values)[-10:].mean()
    )
    # Unequal weights: the minimum over t of t + E[(v - t)+] / (1 - level), scanned over every candidate t.
    weights = rng.uniform(0.2, 2.0, 200)
    p = weights / weights.sum()
    scanned = min(t + p @ np.maximum(values - t, 0) / 0.1 for t in values)
    assert conditional_value_at_risk(values, weights, 0.9) == pytest.approx(scanned, rel=1e-12)
    # Zero-weight samples (points a search added) take no part.
    assert conditional_value_at_risk(np.r_[values, 1e6], np.r_[weights, 0.0], 0.9) == pytest.approx(scanned)
