"""Fresh samples: every reported design checked on contact samples it was not optimised on.

An optimiser fits its design to its samples, so the statistics of those samples flatter it: the worst case it
reports is a maximum over them and its mean is biased low. After the solves, ``samples.fresh`` configurations are
drawn anew in the contact domain, from an independent stream of the study's seed, each with the study's
directions feasible there. Each design is evaluated on those of them inside its own domain (its approach
velocity's speed caps): the largest impulse says whether its worst case holds, the mean and the high quantile
with their bootstrap intervals (:func:`collision_reflex.optimize.statistics.impulse_statistics`) say what the
design does, with an error that the number of fresh configurations sets, not the solver's sample count.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from ..optimize.evaluate import sample_impulses
from ..optimize.samples import ContactSamples
from ..optimize.statistics import QUANTILE, impulse_statistics

if TYPE_CHECKING:
    from ..arm.domain import DomainDraw
    from ..optimize import Design
    from .arm_setup import ArmSetup

FRESH_STREAM = 0x0F7E5
"""Spawn key of the fresh samples' generator under the study's seed: a stream independent of the optimised
samples' (``numpy.random.SeedSequence``)."""

CHUNK_CONFIGURATIONS = 4096
"""Fresh configurations whose kinematics are held at a time (memory stays bounded however many are drawn)."""


@dataclass(frozen=True)
class FreshImpulses:
    """A design's impulses at the fresh samples inside its domain.

    impulses: [N*s] (k,); configuration: (k,) each one's fresh configuration; q: (k_max, nq) [rad] and
    direction: the configuration and direction of the largest.
    """

    impulses: np.ndarray
    configuration: np.ndarray
    q: np.ndarray | None
    direction: np.ndarray | None


def fresh_draw(setup: ArmSetup) -> DomainDraw | None:
    """The study's fresh configurations and their directions' speed caps, or None.

    None without random configurations or with ``samples.fresh: 0``.

    Drawn in the domain at the slowest approach the design space allows (the largest domain: every design's
    samples are among them); a design keeps the directions whose speed cap its approach velocity meets.
    """
    spec = setup.study.samples
    random = spec.configurations.random
    if random is None or spec.fresh == 0:
        return None
    rng = np.random.default_rng(np.random.SeedSequence(random.seed, spawn_key=(FRESH_STREAM,)))
    slowest = float(setup.space.global_bounds("approach_velocity").lower)
    return setup.domain.draw(setup.arm, spec.fresh, setup.directions, slowest, rng)


def fresh_impulses(setup: ArmSetup, draw: DomainDraw, designs: Sequence[Design]) -> list[FreshImpulses]:
    """Each design's impulses at the fresh samples of ``draw`` inside its domain.

    The kinematics are computed once for all designs, :data:`CHUNK_CONFIGURATIONS` configurations at a time.
    """
    config_index, direction_index = np.nonzero(draw.feasible)
    found: list[list[tuple[np.ndarray, np.ndarray]]] = [[] for _ in designs]
    for first in range(0, draw.q.shape[0], CHUNK_CONFIGURATIONS):
        rows = np.flatnonzero((config_index >= first) & (config_index < first + CHUNK_CONFIGURATIONS))
        if rows.size == 0:
            continue
        chunk = ContactSamples(
            setup.arm.kinematics(draw.q[first : first + CHUNK_CONFIGURATIONS]),
            setup.directions[direction_index[rows]],
            config_index[rows] - first,
            speed_cap=draw.speed_cap[config_index[rows], direction_index[rows]],
        )
        for out, design in zip(found, designs, strict=True):
            inside = chunk.inside(design.approach_velocity)
            if np.any(inside):
                kept = ContactSamples(chunk.kinematics, chunk.directions[inside], chunk.config_index[inside])
                out.append((sample_impulses(kept, setup.technology, design), rows[inside]))
    results = []
    for out in found:
        impulses = np.concatenate([i for i, _ in out]) if out else np.empty(0)
        where = np.concatenate([r for _, r in out]) if out else np.empty(0, dtype=int)
        worst = where[int(np.argmax(impulses))] if impulses.size else None
        results.append(
            FreshImpulses(
                impulses,
                config_index[where],
                None if worst is None else draw.q[config_index[worst]],
                None if worst is None else setup.directions[direction_index[worst]],
            )
        )
    return results


def fresh_record(
    fresh: FreshImpulses, worst_case: float, tolerance: float, statistics: bool = False
) -> dict[str, Any]:
    """What the fresh samples say of a design, as plain data.

    ``configurations``, ``samples``: how many lie in the design's domain; ``largest`` [N*s] the largest impulse
    there with ``q`` [rad] and ``direction`` where it occurs; ``mean`` [N*s]; ``exceeds``: ``largest`` is
    above ``worst_case`` (the design's reported worst case [N*s]) by more than ``tolerance`` [-]. With
    ``statistics``, the mean and the :data:`~collision_reflex.optimize.statistics.QUANTILE` quantile with their
    bootstrap intervals (``statistics``: ``mean_impulse`` and ``quantile_impulse``, as
    :meth:`~collision_reflex.optimize.statistics.Estimate.to_json`).
    """
    impulses = fresh.impulses
    out: dict[str, Any] = {
        "configurations": int(np.unique(fresh.configuration).size),
        "samples": int(impulses.size),
    }
    if impulses.size == 0 or fresh.q is None or fresh.direction is None:
        return {**out, "largest": None, "q": None, "direction": None, "mean": None, "exceeds": False}
    largest = float(impulses.max())
    out.update(
        largest=largest,
        q=fresh.q.tolist(),
        direction=fresh.direction.tolist(),
        mean=float(impulses.mean()),
        exceeds=bool(largest > worst_case * (1 + tolerance)),
    )
    if statistics:
        out["statistics"] = {
            name: estimate.to_json()
            for name, estimate in impulse_statistics(impulses, fresh.configuration).items()
        }
        out["statistics"]["quantile_impulse"]["quantile"] = QUANTILE
    return out
