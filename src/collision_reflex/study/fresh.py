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

from typing import TYPE_CHECKING, Any

import numpy as np

from ..optimize.evaluate import sample_impulses
from ..optimize.samples import ContactSamples
from ..optimize.statistics import QUANTILE, impulse_statistics

if TYPE_CHECKING:
    from ..optimize import Design
    from .arm_setup import ArmSetup

FRESH_STREAM = 0x0F7E5
"""Spawn key of the fresh samples' generator under the study's seed: a stream independent of the optimised
samples' (``numpy.random.SeedSequence``)."""


def fresh_samples(setup: ArmSetup) -> ContactSamples | None:
    """The study's fresh samples, or None (no random configurations, or ``samples.fresh: 0``).

    Configurations are drawn in the domain at the slowest approach the design space allows (the largest
    domain: every design's samples are among them); each sample carries its speed cap, so that a design keeps
    those inside its own domain.
    """
    spec = setup.study.samples
    random = spec.configurations.random
    if random is None or spec.fresh == 0:
        return None
    rng = np.random.default_rng(np.random.SeedSequence(random.seed, spawn_key=(FRESH_STREAM,)))
    slowest = float(setup.space.global_bounds("approach_velocity").lower)
    draw = setup.domain.draw(setup.arm, spec.fresh, setup.directions, slowest, rng)
    config_index, direction_index = np.nonzero(draw.feasible)
    kinematics = setup.arm.kinematics(draw.q)
    directions = setup.directions[direction_index]
    caps = setup.domain.speed_caps(kinematics.jacobian[config_index], directions)
    return ContactSamples(kinematics, directions, config_index, speed_cap=caps)


def fresh_impulses(
    samples: ContactSamples, setup: ArmSetup, design: Design
) -> tuple[np.ndarray, np.ndarray]:
    """``design``'s impulses [N*s] at the fresh samples inside its domain, and their configurations' indices."""
    inside = samples.inside(design.approach_velocity)
    if not np.any(inside):
        return np.empty(0), np.empty(0, dtype=int)
    kept = ContactSamples(
        samples.kinematics, samples.directions[inside], samples.config_index[inside]
    )
    return sample_impulses(kept, setup.technology, design), kept.config_index


def fresh_record(
    samples: ContactSamples,
    setup: ArmSetup,
    design: Design,
    worst_case: float,
    tolerance: float,
    statistics: bool = False,
) -> dict[str, Any]:
    """What the fresh samples say of ``design``, as plain data.

    ``configurations``, ``samples``: how many lie in the design's domain; ``largest`` [N*s] the largest impulse
    there with ``q`` [rad] and ``direction`` where it occurs; ``mean`` [N*s]; ``exceeds``: ``largest`` is
    above ``worst_case`` (the design's reported worst case [N*s]) by more than ``tolerance`` [-]. With
    ``statistics``, the mean and the :data:`~collision_reflex.optimize.statistics.QUANTILE` quantile with their
    bootstrap intervals (``statistics``: ``mean_impulse`` and ``quantile_impulse``, as
    :meth:`~collision_reflex.optimize.statistics.Estimate.to_json`).
    """
    impulses, configurations = fresh_impulses(samples, setup, design)
    out: dict[str, Any] = {"configurations": int(np.unique(configurations).size), "samples": int(impulses.size)}
    if impulses.size == 0:
        return {**out, "largest": None, "q": None, "direction": None, "mean": None, "exceeds": False}
    worst = int(np.argmax(impulses))
    where = np.flatnonzero(samples.inside(design.approach_velocity))[worst]
    largest = float(impulses[worst])
    out.update(
        largest=largest,
        q=samples.kinematics.q[samples.config_index[where]].tolist(),
        direction=samples.directions[where].tolist(),
        mean=float(impulses.mean()),
        exceeds=bool(largest > worst_case * (1 + tolerance)),
    )
    if statistics:
        out["statistics"] = {
            name: estimate.to_json() for name, estimate in impulse_statistics(impulses, configurations).items()
        }
        out["statistics"]["quantile_impulse"]["quantile"] = QUANTILE
    return out
