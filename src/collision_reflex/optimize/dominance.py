"""Dominance between designs' objective values, and the hypervolume a front dominates.

Which designs a front keeps (:func:`non_dominated`), which repeat another (:func:`merge_repeats`), with the
tolerances they judge by. Everything here is minimised: a maximised objective is negated first
(:func:`minimised`).
"""

from __future__ import annotations

import itertools
from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING

import numpy as np

from ..errors import InvalidParameter
from .objectives import OBJECTIVES

if TYPE_CHECKING:
    from .design_result import DesignResult


DOMINANCE_TOLERANCE = 1e-9
"""Relative difference below which two objective values count as equal.

Relative to each objective's largest magnitude."""

MERGE_TOLERANCE = 1e-5
"""Relative difference below which two solved designs' objectives are equal: one point of the front, and no
reason to prefer one design over the other.

IPOPT stops at ``tol = 1e-8`` on its scaled optimality error, so one optimum reached from different starts or
under different bounds repeats its objective values to about 1e-7 relative; a lexicographic anchor holds its
first objective within :data:`~collision_reflex.optimize.epsilon.ANCHOR_SLACK` (1e-6) of the optimum. Ten
times the larger, 1e-5, merges such repeats and stays far below any difference a designer acts on."""


def minimised(values: np.ndarray, names: Sequence[str]) -> np.ndarray:
    """Objective values with maximised objectives negated, so that smaller is better in every column."""
    return values * np.array([OBJECTIVES[name][0] for name in names], dtype=float)


def _differences(values: np.ndarray) -> np.ndarray:
    """(n, n, m) differences of minimised ``values`` (n, m), relative to each column's largest magnitude.

    ``[i, j] < 0`` where point i is better than point j.
    """
    scale = np.maximum(np.abs(values).max(axis=0), 1e-300)
    return (values[:, None, :] - values[None, :, :]) / scale


def dominance(values: np.ndarray, tolerance: float) -> np.ndarray:
    """(n, n) booleans of minimised ``values`` (n, m): ``[i, j]`` if point i dominates point j.

    Point i dominates point j when it is no worse in any column and better in one, by more than ``tolerance``
    of the column's largest magnitude.
    """
    diff = _differences(values)
    return np.all(diff <= tolerance, axis=2) & np.any(diff < -tolerance, axis=2)


def dominated_mask(values: np.ndarray, tolerance: float = DOMINANCE_TOLERANCE) -> np.ndarray:
    """(n,) booleans: which rows of ``values`` (n, m; every column minimised) another row dominates."""
    values = np.asarray(values, dtype=float)
    if not len(values):
        return np.zeros(0, dtype=bool)
    return np.asarray(dominance(values, tolerance).any(axis=0), dtype=bool)


def non_dominated(
    results: Sequence[DesignResult], names: Sequence[str], tolerance: float = DOMINANCE_TOLERANCE
) -> tuple[list[DesignResult], list[DesignResult]]:
    """Split results into the non-dominated ones (sorted by the first objective) and the dominated ones.

    ``a`` dominates ``b`` if it is no worse in every objective and better by more than ``tolerance`` (relative)
    in at least one; near-duplicates (equal within the tolerance) keep the first found.
    """
    if not results:
        return [], []
    values = minimised(np.array([[r.numpy_objectives[n] for n in names] for r in results]), names)
    same = np.all(np.abs(_differences(values)) <= tolerance, axis=2)
    earlier_duplicate = np.tril(same, k=-1).any(axis=1)  # [i, j] with j < i
    dropped = dominance(values, tolerance).any(axis=0) | earlier_duplicate
    keep = sorted(np.flatnonzero(~dropped).tolist(), key=lambda i: values[i, 0])
    return [results[i] for i in keep], [results[i] for i in np.flatnonzero(dropped).tolist()]


def same_point(a: Mapping[str, float], b: Mapping[str, float], names: Sequence[str]) -> bool:
    """Whether two designs' objective values agree within :data:`MERGE_TOLERANCE` (relative) in every objective."""
    return all(
        abs(a[name] - b[name]) <= MERGE_TOLERANCE * max(abs(a[name]), abs(b[name]), 1e-300) for name in names
    )


def merge_repeats(
    results: Sequence[DesignResult], names: Sequence[str]
) -> tuple[list[DesignResult], list[DesignResult]]:
    """Drop the results that repeat an earlier one (:func:`same_point`): ``(kept, merged)``, order kept."""
    kept: list[DesignResult] = []
    merged: list[DesignResult] = []
    for result in results:
        repeat = any(same_point(result.numpy_objectives, k.numpy_objectives, names) for k in kept)
        (merged if repeat else kept).append(result)
    return kept, merged


def hypervolume(points: np.ndarray, reference: np.ndarray) -> float:
    """Hypervolume (minimisation) of ``points`` (n, 2 or 3) bounded by ``reference``.

    Exact: a sweep over the first objective (2D), or slices over the third (3D) each measured in 2D.
    """
    points = np.asarray(points, dtype=float)
    reference = np.asarray(reference, dtype=float)
    inside = points[np.all(points < reference, axis=1)]
    if inside.size == 0:
        return 0.0
    if inside.shape[1] == 2:
        ordered = inside[np.argsort(inside[:, 0])]
        volume, best_second = 0.0, reference[1]
        for first, second in ordered:
            if second < best_second:
                volume += (reference[0] - first) * (best_second - second)
                best_second = second
        return float(volume)
    if inside.shape[1] == 3:
        levels = np.unique(inside[:, 2])
        volume = 0.0
        for low, high in itertools.pairwise(np.append(levels, reference[2])):
            active = inside[inside[:, 2] <= low]
            volume += hypervolume(active[:, :2], reference[:2]) * (high - low)
        return float(volume)
    raise InvalidParameter("points", points.shape, "2 or 3 objectives")
