"""The result of an active-set solve: a :class:`DesignResult` over all samples, with the NLPs it took."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field, fields

import numpy as np

from .design_result import DesignResult


@dataclass(frozen=True)
class ActiveSetRound:
    """One NLP of the active-set scheme.

    samples: active samples in the NLP; added: indices (into all samples) of the samples found violated at its
        design and added for the next;
    iterations: IPOPT iterations; solve_time: problem build, solver construction and IPOPT [s];
    worst_active, worst_all: the worst-case impulse over the active samples and over all samples at its design
    [N*s] (NumPy path).
    """

    samples: int
    added: np.ndarray
    iterations: int
    solve_time: float
    worst_active: float
    worst_all: float


@dataclass(frozen=True)
class ActiveSetResult(DesignResult):
    """A :class:`DesignResult` over all samples, found on an active set of them.

    Its impulses, objectives and NumPy objectives are those of every sample; ``x`` is the full problem's point
    (auxiliaries at their exact values) and ``multipliers`` None (they belong to the last subset's NLP).
    ``iterations`` add up the rounds of the start kept, ``solve_time`` [s] is the whole solve's (every start,
    the problem builds and the evaluations on all samples); ``status`` and ``attempts`` are the last round's.

    active_samples: indices (into all samples) of the samples in the last NLP.
    rounds: every NLP solved (:class:`ActiveSetRound`), in order.
    method: ``"active set"``, or why all samples were solved at once.
    last_round: the last NLP's own result (its point and multipliers), which warm-starts a solve of a problem
        of the same variables and rows on the same samples (``solve_active_set(warm=...)``); None when all
        samples were solved at once.
    """

    active_samples: np.ndarray = field(default_factory=lambda: np.empty(0, dtype=int))
    rounds: tuple[ActiveSetRound, ...] = ()
    method: str = "active set"
    last_round: DesignResult | None = None

    def active_set_json(self) -> dict[str, object]:
        """What the active set adds to a result, as JSON types (:func:`with_active_set` reads it back)."""
        return {
            "method": self.method,
            "active_samples": [int(i) for i in self.active_samples],
            "rounds": [
                {
                    "samples": r.samples,
                    "added": [int(i) for i in r.added],
                    "iterations": r.iterations,
                    "solve_time": r.solve_time,
                    "worst_active": r.worst_active,
                    "worst_all": r.worst_all,
                }
                for r in self.rounds
            ],
        }


def with_active_set(
    result: DesignResult, data: Mapping[str, object], last_round: DesignResult | None = None
) -> ActiveSetResult:
    """``result`` with the active set written by :meth:`ActiveSetResult.active_set_json` (and its last NLP's)."""
    rounds = data["rounds"]
    assert isinstance(rounds, list)
    return ActiveSetResult(
        **result_fields(result),  # type: ignore[arg-type]
        active_samples=np.asarray(data["active_samples"], dtype=int),
        rounds=tuple(
            ActiveSetRound(
                int(r["samples"]),
                np.asarray(r["added"], dtype=int),
                int(r["iterations"]),
                float(r["solve_time"]),
                float(r["worst_active"]),
                float(r["worst_all"]),
            )
            for r in rounds
        ),
        method=str(data["method"]),
        last_round=last_round,
    )


def solve_method(result: DesignResult) -> tuple[str, int]:
    """How ``result`` was solved and on how many samples its last NLP was: ``("active set", 72)``."""
    if isinstance(result, ActiveSetResult):
        return result.method, int(result.active_samples.size)
    return "full NLP", int(np.asarray(result.impulses).size)


def result_fields(result: DesignResult, **changes: object) -> dict[str, object]:
    """The fields of ``result`` as keywords, with ``changes``."""
    return {**{f.name: getattr(result, f.name) for f in fields(DesignResult)}, **changes}


def with_rounds(
    result: DesignResult | dict[str, object],
    impulses: np.ndarray,
    active: np.ndarray,
    rounds: tuple[ActiveSetRound, ...],
    method: str,
    total_time: float | None = None,
    last_round: DesignResult | None = None,
) -> ActiveSetResult:
    """The :class:`ActiveSetResult` of ``result`` (a result or its fields) with the rounds' totals."""
    values = result if isinstance(result, dict) else result_fields(result)
    values.update(
        impulses=impulses,
        iterations=sum(r.iterations for r in rounds),
        solve_time=sum(r.solve_time for r in rounds) if total_time is None else total_time,
    )
    return ActiveSetResult(
        **values,  # type: ignore[arg-type]
        active_samples=active,
        rounds=rounds,
        method=method,
        last_round=last_round,
    )
