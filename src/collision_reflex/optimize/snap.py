"""Snap a continuous optimum to catalogue parts: the best design built from motors one can buy.

A continuous optimum sizes each joint's motor freely ("a 41.7 mm motor at N = 200"). Here each joint gets a
catalogue motor instead (a joint's reference motor with its stator diameter and stack length fixed at its own,
so that its quantities are its datasheet figures), and the continuous variables that remain (gear ratio,
software stiffness, threshold, approach velocity) are re-optimised for that choice.

- **Candidates per joint**: the catalogue parts near the continuous optimum's motor that can do the joint's
  work (:func:`collision_reflex.optimize.candidates.joint_candidates`).
- **Exact** when the combinations of candidates number at most ``max_combinations``: every one is re-solved
  and the best feasible by the problem's objective is kept (for an impulse objective, the lightest within
  :data:`collision_reflex.optimize.recommend.RESOLUTION` of the least impulse).
- **Heuristic** beyond that: coordinate descent over joints from the nearest part of every joint; each pass
  tries, joint by joint, every other candidate of that joint with the rest held, and moves to any better
  design; it stops when a whole pass improves nothing. Its best is never worse than the nearest-part design
  (its start), and is chosen as the exact search's is; ``benchmarks/snap_gap.py`` measures its gap to
  enumeration.

How each combination is re-solved (warm starts, active sets) and searched: :mod:`collision_reflex.optimize.
catalogue_search`.

The objective is the problem's own, without the objective bounds of an epsilon-constraint point: a Pareto design
snapped is the study objective's best design of those parts. A catalogue design is the continuous problem with
more constraints, so it is never better than the (global) continuous optimum in the optimised objective; a
continuous optimum that is only local can be beaten.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from ..errors import InvalidParameter
from ..vocabulary import ACTIVE_SET_CHOICES
from .candidates import (
    DEFAULT_CANDIDATES,
    DEFAULT_GEARBOX_CANDIDATES,
    CataloguePart,
    JointCandidates,
    joint_candidates,
)
from .catalogue_search import (
    InProcessSolver,
    PartsSearch,
    PartsSolver,
    Trial,
    impulse_objective,
    warm_startable,
)
from .design_result import DesignResult
from .ipopt import IpoptOptions
from .recommend import RESOLUTION

if TYPE_CHECKING:
    from ..arm.robot import Arm
    from ..hardware.gearboxes import CatalogueGearbox
    from ..hardware.motors import Motor
    from .problem import DesignProblem

__all__ = [
    "DEFAULT_MAX_COMBINATIONS",
    "CatalogueDesign",
    "snap_to_catalogue",
]

DEFAULT_MAX_COMBINATIONS = 64
"""Largest number of combinations enumerated exactly by default; beyond it the heuristic runs."""


@dataclass(frozen=True)
class CatalogueDesign:
    """The best design built from catalogue parts, next to the continuous optimum it was snapped from.

    joints: per joint the candidates and catalogue coverage (:class:`JointCandidates`); parts: the chosen part
    per joint, None when no combination gave a feasible design; result: the re-optimised design (None with
    ``parts``); continuous: the continuous optimum; objectives, continuous_objectives: every objective of each
    [its unit] (NumPy path; empty without a result); difference: catalogue minus continuous [its unit];
    relative_difference: the same over the continuous value [-]; tried: every combination solved; method: how
    the answer was found (``"exact: enumerated 9 combinations"`` or ``"heuristic: ..."``); warnings: the
    joints' catalogue-coverage warnings and why no design was found, if none was.
    """

    joints: tuple[JointCandidates, ...]
    parts: tuple[CataloguePart, ...] | None
    result: DesignResult | None
    continuous: DesignResult
    objectives: dict[str, float]
    continuous_objectives: dict[str, float]
    difference: dict[str, float]
    relative_difference: dict[str, float]
    tried: tuple[Trial, ...]
    method: str
    warnings: tuple[str, ...] = field(default=())

    @property
    def found(self) -> bool:
        """Whether a feasible catalogue design was found."""
        return self.result is not None


def snap_to_catalogue(
    problem: DesignProblem,
    optimum: DesignResult,
    motors: Mapping[str, Motor] | Sequence[Motor],
    *,
    arm: Arm,
    gearboxes: Mapping[str, CatalogueGearbox] | None = None,
    candidates: int = DEFAULT_CANDIDATES,
    gearbox_candidates: int = DEFAULT_GEARBOX_CANDIDATES,
    gearbox_kinds: Sequence[str] | None = None,
    max_combinations: int = DEFAULT_MAX_COMBINATIONS,
    ipopt_options: IpoptOptions | None = None,
    progress: Callable[[int, int], None] | None = None,
    solve_many: PartsSolver | None = None,
    active_set: str = "auto",
) -> CatalogueDesign:
    """The best design built from catalogue motors near ``optimum``, re-optimised (module docstring).

    Parameters
    ----------
    problem: the continuous design problem (:func:`collision_reflex.optimize.build_problem`); each combination
        is this problem with every joint's motor fixed at a catalogue motor, its objective and constraints.
    optimum: the continuous optimum of ``problem`` (:func:`collision_reflex.optimize.solve`).
    motors: the catalogue motors (e.g. :func:`collision_reflex.hardware.load_catalogue`), by name or as a sequence.
    arm: the arm ``problem`` was built for (each combination's problem is built for it).
    gearboxes: the gearbox catalogue by name (e.g. :func:`collision_reflex.hardware.gearboxes.
        load_gearbox_catalogue`), for joints whose gearbox is the study's own figures; None keeps every joint's
        gearbox (see :func:`joint_candidates`).
    candidates: motors considered per joint (>= 1), the nearest first.
    gearbox_candidates: catalogue gearboxes considered per joint with the study's own gearbox figures (>= 1),
        of each kind in ``gearbox_kinds``.
    gearbox_kinds: the gearbox kinds such a joint may take in the catalogue design (a transmission is a design
        choice: strain-wave, planetary, ...); None: the kind of its own gearbox.
    max_combinations: the most combinations enumerated exactly (>= 1); beyond, the heuristic runs.
    ipopt_options: options of every re-solve (see :func:`collision_reflex.optimize.solve`).
    progress: called as ``progress(done, total)`` after each batch of combinations solved.
    solve_many: how combinations are solved (:data:`PartsSolver`), e.g. through an executor; default in this
        process. The combinations of a batch (every one when enumerating; a joint's candidates in a step of the
        heuristic) are independent, and the answer does not depend on where they run.
    active_set: how the default ``solve_many`` solves each combination's samples
        (:func:`collision_reflex.optimize.catalogue_search.solve_parts`): on an active set from
        :data:`collision_reflex.optimize.active_set.ACTIVE_SET_THRESHOLD` samples (``"auto"``, the sweep's
        rule), always or never; a given ``solve_many`` decides for itself.

    Raises
    ------
    InvalidParameter: an empty catalogue, ``candidates`` or ``max_combinations`` not an integer >= 1, an
        ``active_set`` not one of :data:`collision_reflex.optimize.active_set.ACTIVE_SET_CHOICES`.
    KeyboardInterrupt: Ctrl-C, from any re-solve (nothing is returned).
    """
    if not isinstance(max_combinations, int) or isinstance(max_combinations, bool) or max_combinations < 1:
        raise InvalidParameter("max_combinations", max_combinations, "an integer >= 1")
    if active_set not in ACTIVE_SET_CHOICES:
        raise InvalidParameter("active_set", active_set, "one of " + ", ".join(map(repr, ACTIVE_SET_CHOICES)))
    joints = joint_candidates(
        problem, optimum, motors, candidates, gearboxes, gearbox_candidates, gearbox_kinds=gearbox_kinds
    )
    warnings = [j.warning for j in joints if j.warning]
    empty = [j for j in joints if not j.parts]
    if empty:
        reasons = [
            f"{j.joint}: no catalogue part within bounds; the nearest, {j.nearest}, misses: "
            + "; ".join(j.misses)
            for j in empty
        ]
        return _design(joints, None, None, optimum, (), "none: " + " / ".join(reasons), [*warnings, *reasons])
    if solve_many is None:
        solve_many = InProcessSolver(problem, optimum, arm, ipopt_options, active_set)
    owner = problem.space.module_of(problem.n_joints)
    search = PartsSearch(problem, optimum.design, [j.parts for j in joints], solve_many, progress, owner)
    total = math.prod(len(j.parts) for k, j in enumerate(joints) if owner[k] == k)
    if total <= max_combinations:
        search.total = total
        search.values_of(search.tied(itertools.product(*(range(len(j.parts)) for j in joints))))
        method = f"exact: enumerated {total} combinations"
    else:
        passes = search.descend()
        method = (
            f"heuristic: coordinate descent over joints from the nearest parts, {len(search.tried)} of {total} "
            f"combinations solved in {passes} passes (more than max_combinations = {max_combinations})"
        )
    best, least = search.best(), search.least()
    if best is not None and warm_startable(problem, optimum, active_set):
        search.confirm(best)
    if best != least:
        assert best is not None and least is not None  # best is least without a feasible combination
        name = str(impulse_objective(problem)).replace("_", " ")
        masses = [search.results[c].numpy_objectives["actuator_mass"] for c in (best, least)]
        method += (
            f"; the lightest combination within {100 * RESOLUTION:g} % of the least {name} "
            f"({masses[0]:.4g} kg of actuators against {masses[1]:.4g} kg)"
        )
    if best is None:
        reason = "no combination of candidates gives a feasible design (every re-solve failed)"
        return _design(joints, None, None, optimum, search.trials(), method, [*warnings, reason])
    parts = tuple(j.parts[c] for j, c in zip(joints, best, strict=True))
    return _design(joints, parts, search.results[best], optimum, search.trials(), method, warnings)


def _design(
    joints: tuple[JointCandidates, ...],
    parts: tuple[CataloguePart, ...] | None,
    result: DesignResult | None,
    optimum: DesignResult,
    tried: tuple[Trial, ...],
    method: str,
    warnings: list[str],
) -> CatalogueDesign:
    """The :class:`CatalogueDesign` with its objectives compared to the continuous optimum's."""
    continuous = dict(optimum.numpy_objectives)
    mine = dict(result.numpy_objectives) if result is not None else {}
    difference = {name: mine[name] - continuous[name] for name in mine}
    relative = {
        name: difference[name] / continuous[name] if continuous[name] != 0 else math.inf for name in mine
    }
    return CatalogueDesign(
        joints, parts, result, optimum, mine, continuous, difference, relative, tried, method, tuple(warnings)
    )
