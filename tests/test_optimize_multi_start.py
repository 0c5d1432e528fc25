"""The screened multi-start's choice of which starts to finish (``multistart.multi_start``), on a stand-in problem.

The problem has one design variable and two known local optima, ``x = -1`` (objective 0) and ``x = +1``
(objective 0.1), and IPOPT is replaced by a stand-in whose screening run stops part of the way to the optimum
of the start's basin (``x < 0`` or ``x > 0``) and whose finish reaches that optimum. So the optimum each start
leads to, and the one the multi-start must return, are known exactly, whatever the distance and the screened
objectives the real solver would give.
"""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from collision_reflex.errors import SolverFailed
from collision_reflex.optimize import multistart

BETTER, WORSE = -1.0, 1.0
"""The two local optima's designs; the objective is 0 at BETTER and 0.1 at WORSE."""


def _objective(x: np.ndarray) -> float:
    design = float(x[0])
    return (design - BETTER) ** 2 if design < 0 else (design - WORSE) ** 2 + 0.1


class _Draws:
    """Stands in for the random generator: the random starts' designs, in order."""

    def __init__(self, *designs: float) -> None:
        self.designs = list(designs)

    def uniform(self, low: np.ndarray, high: np.ndarray) -> np.ndarray:
        return np.array([self.designs.pop(0)])


def _problem(default_start: float) -> SimpleNamespace:
    return SimpleNamespace(
        layout=SimpleNamespace(size=1),
        x0=np.array([default_start]),
        lbx=np.array([-2.0]),
        ubx=np.array([2.0]),
        exact_point=lambda x: np.asarray(x, dtype=float),
        objective_value=_objective,
    )


def _stand_in_solver(monkeypatch, screened_at, fails_from=()):
    """Replace IPOPT: a screening run from a start stops at ``screened_at(start)``, a finish from a screened
    point reaches its basin's optimum, or raises SolverFailed when that point is in ``fails_from``. Returns the
    screened points the finishes started from, in order."""
    finished_from: list[float] = []

    def solve_start(problem, epsilon=None, x0=None, ipopt_options=None, *, retry=True):
        start = problem.x0 if x0 is None else getattr(x0, "x", x0)
        design = float(np.asarray(start)[0])
        if ipopt_options is not None and "ipopt.tol" in ipopt_options:  # the screening run
            return SimpleNamespace(x=np.array([screened_at(design)]))
        finished_from.append(design)
        if design in fails_from:
            raise SolverFailed("stand-in finish failed", "Restoration_Failed", {}, [])
        return SimpleNamespace(x=np.array([BETTER if design < 0 else WORSE]))

    monkeypatch.setattr(multistart, "solve_start", solve_start)
    return finished_from


def test_starts_screened_on_different_optima_are_both_finished(monkeypatch):
    # The start in the worse optimum's basin screens closer to it (objective 0.11) than the start in the better
    # one's basin (0.25): screening alone ranks the worse optimum first. The two screened designs are 1.4
    # apart, far beyond the same-path distance; merging them would finish only the worse optimum.
    screened = {-1.5: -0.5, 1.5: 0.9}
    finished_from = _stand_in_solver(monkeypatch, screened.__getitem__)
    assert _objective(np.array([0.9])) < _objective(np.array([-0.5]))
    assert abs(0.9 - (-0.5)) > multistart.SAME_PATH_DISTANCE
    result = multistart.multi_start(_problem(-1.5), None, None, None, 2, _Draws(1.5))
    assert sorted(finished_from) == [-0.5, 0.9]
    assert float(result.x[0]) == BETTER


def test_a_failed_finish_is_retried_from_the_next_start_on_its_path(monkeypatch):
    # Three starts screen within the same-path distance of each other, in the better optimum's basin; the
    # finish from the best screened one (-0.9998) fails, so the next best (-0.9996) is finished, and no further one.
    screened = {-1.5: -0.9996, -0.5: -0.9998, -0.3: -0.9994}
    assert max(screened.values()) - min(screened.values()) < multistart.SAME_PATH_DISTANCE
    finished_from = _stand_in_solver(monkeypatch, screened.__getitem__, fails_from={-0.9998})
    result = multistart.multi_start(_problem(-1.5), None, None, None, 3, _Draws(-0.5, -0.3))
    assert finished_from == [-0.9998, -0.9996]
    assert float(result.x[0]) == BETTER


def test_every_finish_of_a_path_failing_raises(monkeypatch):
    screened = {-1.5: -0.9996, -0.5: -0.9998}
    assert max(screened.values()) - min(screened.values()) < multistart.SAME_PATH_DISTANCE
    finished_from = _stand_in_solver(monkeypatch, screened.__getitem__, fails_from={-0.9996, -0.9998})
    with pytest.raises(SolverFailed, match="stand-in finish failed"):
        multistart.multi_start(_problem(-1.5), None, None, None, 2, _Draws(-0.5))
    assert finished_from == [-0.9998, -0.9996]
