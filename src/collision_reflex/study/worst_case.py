"""An arm study's worst cases certified over its contact domain: the searches and the exchange of samples.

After a round of solves (the optimum and the Pareto front), each design's impulse is maximised over the contact
domain (:func:`collision_reflex.optimize.worst_case.search_worst_case`), from its worst samples and from random
points of the domain. When the study's objectives include the worst case, the maxima above a design's worst case
by more than the search's tolerance join the samples (:data:`~.arm_setup.ExtraSamples`), and the runner solves
again on them: the exchange method for semi-infinite programs.
"""

from __future__ import annotations

import dataclasses
import hashlib
from collections.abc import Mapping
from concurrent.futures import Executor
from typing import TYPE_CHECKING, Any

import numpy as np

from ..optimize.pieces import one_at_a_time
from ..optimize.worst_case import WorstCase, search_worst_case
from .arm_setup import ExtraSamples
from .problems import StudyProblems, study_setup
from .resolve import ResolvedStudy
from .run_specs import SearchSpec
from .schema import ArmStudy

if TYPE_CHECKING:
    from ..optimize import DesignResult
    from ..optimize.design import Design
    from .store import RunFolder


def exchanges_samples(study: ArmStudy) -> bool:
    """Whether the study's problems minimise or bound the worst case, so that violators join the samples.

    A mean impulse is a statistic of the drawn samples: adding searched points would bias it, so a study
    without a worst-case objective only reports its searched worst cases.
    """
    named = set(study.objective) | set(study.pareto.objectives if study.pareto is not None else ())
    return "worst_case_impulse" in named


@one_at_a_time
def _search_one(
    study: ResolvedStudy,
    design: Design,
    start_q: np.ndarray,
    start_directions: np.ndarray,
    random_starts: int,
    seed: tuple[int, int],
) -> WorstCase:
    """One design's search (a piece of work for an executor: picklable arguments, run in any process).

    The search needs the arm, its domain and the technology, which the searched samples do not change: the
    study's own setup serves every round (built once per process).
    """
    setup = study_setup(study)
    return search_worst_case(
        setup.arm,
        setup.domain,
        setup.technology,
        design,
        start_q,
        start_directions,
        random_starts=random_starts,
        rng=np.random.default_rng(list(seed)),
    )


def worst_samples(problems: StudyProblems, impulses: np.ndarray, count: int) -> tuple[np.ndarray, np.ndarray]:
    """The ``count`` samples of largest impulse with distinct configurations: (q (k, nq), directions (k, d))."""
    samples = problems.setup.samples
    order = np.argsort(np.asarray(impulses, dtype=float))[::-1]
    picked: list[int] = []
    seen: set[int] = set()
    for s in order:
        config = int(samples.config_index[s])
        if config not in seen:
            seen.add(config)
            picked.append(int(s))
        if len(picked) == count:
            break
    index = np.array(picked, dtype=int)
    return samples.kinematics.q[samples.config_index[index]], samples.directions[index]


def search_designs(
    problems: StudyProblems,
    results: Mapping[str, DesignResult],
    spec: SearchSpec,
    executor: Executor,
    folder: RunFolder | None = None,
) -> tuple[dict[str, WorstCase], tuple[int, int]]:
    """Each design's searched worst case over the study's domain, by label, and the searches (run, found saved).

    The searches run through ``executor``.
    With a run ``folder``, each search is saved as it finishes and found again by its inputs when the run resumes.
    """
    futures: dict[str, Any] = {}
    for index, (label, result) in enumerate(results.items()):
        start_q, start_directions = worst_samples(problems, result.impulses, spec.starts)
        arguments = (result.design, start_q, start_directions, spec.random_starts, (spec.seed, index))
        name = "search-" + _digest(np.asarray(result.x), start_q, start_directions, arguments[3:])
        saved = _restored(folder.finished(name)) if folder is not None else None
        if saved is not None:
            futures[label] = saved
        else:
            futures[label] = (name, executor.submit(_search_one, problems.study, *arguments))
    searches = {}
    for label, pending in futures.items():
        if isinstance(pending, WorstCase):
            searches[label] = pending
            continue
        name, future = pending
        searches[label] = future.result()
        if folder is not None:
            folder.save(name, _record(searches[label]))
    reused = sum(isinstance(pending, WorstCase) for pending in futures.values())
    return searches, (len(futures) - reused, reused)


_FIELDS = [field.name for field in dataclasses.fields(WorstCase)]


def _digest(*parts: Any) -> str:
    """A short hash of a search's inputs: arrays by their bytes and shape, the rest by their text."""
    digest = hashlib.sha256()
    for part in parts:
        if isinstance(part, np.ndarray):
            digest.update(repr(part.shape).encode() + np.ascontiguousarray(part, dtype=float).tobytes())
        else:
            digest.update(repr(part).encode())
    return digest.hexdigest()[:20]


def _record(search: WorstCase) -> dict[str, Any]:
    """A search as JSON types, every field with arrays as their shape and values (exact: floats as repr)."""
    values = {}
    for name in _FIELDS:
        value = getattr(search, name)
        if isinstance(value, np.ndarray):
            value = {"shape": list(value.shape), "values": value.ravel().tolist()}
        values[name] = value
    return {"fields": _FIELDS, "values": values}


def _restored(record: Mapping[str, Any] | None) -> WorstCase | None:
    """The search a :func:`_record` holds; None for none, or one this version did not write (searched again)."""
    if record is None or record.get("fields") != _FIELDS:
        return None
    try:
        values = dict(record["values"])
        for name, value in values.items():
            if isinstance(value, dict):
                values[name] = np.array(value["values"], dtype=float).reshape(value["shape"])
        return WorstCase(**values)
    except (KeyError, TypeError, ValueError):
        return None


def violators(
    results: Mapping[str, DesignResult], searches: Mapping[str, WorstCase], tolerance: float
) -> ExtraSamples:
    """The searched points above their design's sampled worst case by more than ``tolerance``, as samples."""
    found: list[tuple[tuple[float, ...], tuple[float, ...]]] = []
    for label, search in searches.items():
        level = results[label].numpy_objectives["worst_case_impulse"]
        for i in search.violators(level, tolerance):
            found.append(
                (tuple(map(float, search.maxima_q[i])), tuple(map(float, search.maxima_directions[i])))
            )
    return tuple(dict.fromkeys(found))  # one sample per point, in order


def worst_case_record(result: DesignResult, search: WorstCase | None, tolerance: float) -> dict[str, Any]:
    """What a design's record says of its worst case: over the samples, as searched, and whether it holds.

    ``sampled`` [N*s] the largest impulse over the samples in the design's domain; ``searched`` the search's result (None when none
    ran); ``domain`` [N*s] the larger of the two, the worst case over the domain as far as it was searched;
    ``certified``: no searched point exceeds the sampled worst case by more than ``tolerance``.
    """
    sampled = float(result.numpy_objectives["worst_case_impulse"])
    if search is None:
        return {"sampled": sampled, "searched": None, "domain": sampled, "certified": False}
    return {
        "sampled": sampled,
        "searched": search.to_json(),
        "domain": max(sampled, search.impulse),
        "certified": bool(search.impulse <= sampled * (1 + tolerance)),
        "tolerance": tolerance,
    }
