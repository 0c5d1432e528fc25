"""An arm study's catalogue design, as plain data (``designs.json``: ``catalogue``).

The recommended design snapped to catalogue parts (re-solved), and every Pareto design's quick snap.
"""

from __future__ import annotations

import hashlib
import math
import threading
import time
from collections.abc import Callable, Sequence
from concurrent.futures import Executor
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, TypedDict

from ..hardware.catalogue import packaged_catalogue_path, read_entries
from ..hardware.gearboxes import load_gearbox_catalogue
from ..hardware.motors import Motor
from ..optimize import snap as snapping  # by module: a test replaces snap_to_catalogue
from ..optimize.blas import single_threaded_blas
from ..optimize.candidates import joint_candidates
from ..optimize.catalogue_search import solved_or_status
from ..optimize.parts import catalogue_problem, evaluate_parts, quick_parts
from ..optimize.pieces import built_problem
from ..optimize.recommend import recommend
from ..optimize.results import design_record
from ..record.design import MissingPart, QuickSnap
from ..record.run import CatalogueJoint, CatalogueRecord
from .arm_results import undecided
from .load import LoadedStudy
from .problems import IPOPT_OPTIONS, StudyProblems
from .schema import ArmStudy

if TYPE_CHECKING:
    from ..hardware.gearboxes import CatalogueGearbox
    from ..optimize import DesignProblem, DesignResult, ParetoSet
    from ..optimize.candidates import CataloguePart
    from ..optimize.snap import CatalogueDesign


@dataclass(frozen=True)
class SnapCatalogue:
    """The catalogue a study snaps to, and its settings.

    motors, gearboxes: the catalogue's motors and gearboxes by name (no gearboxes when no joint has one);
    provenance: per part, each field's source or estimate (as :func:`collision_reflex.hardware.catalogue.
    read_entries` gives it); files: the catalogue files read; candidates, max_combinations, gearbox_kinds:
    :func:`collision_reflex.optimize.snap.snap_to_catalogue`'s settings.
    """

    motors: dict[str, Motor]
    gearboxes: dict[str, CatalogueGearbox]
    provenance: dict[str, dict[str, str]]
    files: tuple[Path, ...]
    candidates: int
    max_combinations: int
    gearbox_kinds: tuple[str, ...] | None = None

    @property
    def key(self) -> str:
        """A digest of the catalogue files' bytes and the settings."""
        digest = hashlib.sha256()
        for file in self.files:
            digest.update(file.read_bytes())
        digest.update(f"{self.candidates}/{self.max_combinations}/{self.gearbox_kinds}".encode())
        return digest.hexdigest()[:16]


def study_catalogue(loaded: LoadedStudy) -> SnapCatalogue | None:
    """The catalogue an arm study snaps to (None when its ``catalogue.snap`` is false).

    Raises
    ------
    CatalogueError: the catalogue file cannot be read or has a bad entry (file, line and field).
    """
    study = loaded.study
    assert isinstance(study, ArmStudy)
    spec = study.catalogue
    if not spec.snap:
        return None
    file = loaded.path(spec.motors) if spec.motors is not None else packaged_catalogue_path()
    entries = read_entries(file, "motors")
    motors = {
        name: Motor(name=name, **{k: v for k, v in e.fields.items() if k not in ("sources", "estimates")})
        for name, e in entries.items()
    }
    provenance = {name: dict(e.provenance) for name, e in entries.items()}
    files: tuple[Path, ...] = (file,)
    gearboxes: dict[str, CatalogueGearbox] = {}
    geared = study.actuators.gearbox is not None or any(
        j.gearbox is not None for j in study.actuators.joints.values()
    )
    if geared:  # read only when a joint has a gearbox to snap
        gearbox_file = (
            loaded.path(spec.gearboxes)
            if spec.gearboxes is not None
            else packaged_catalogue_path("gearboxes.yaml")
        )
        gearboxes = load_gearbox_catalogue(gearbox_file)
        provenance.update(
            {name: dict(e.provenance) for name, e in read_entries(gearbox_file, "gearboxes").items()}
        )
        files += (gearbox_file,)
    kinds = None if spec.gearbox_kinds is None else tuple(spec.gearbox_kinds)
    return SnapCatalogue(motors, gearboxes, provenance, files, spec.candidates, spec.max_combinations, kinds)


def catalogue_results(
    problems: StudyProblems,
    chosen: DesignResult,
    front: ParetoSet | None,
    catalogue: SnapCatalogue,
    progress: Callable[[int, int], None] | None = None,
    executor: Executor | None = None,
) -> CatalogueRecord:
    """The recommended design snapped to ``catalogue`` (re-solved), and every Pareto design's quick snap.

    The recommended design is snapped by :func:`collision_reflex.optimize.snap.snap_to_catalogue` (exact or
    heuristic), its combinations solved through ``executor`` (default in this process: the same numbers
    either way), on active sets of the samples as the study's ``optimizer.active_set`` says (the sweep's
    rule); each Pareto design (the chosen one without a front) by :func:`quick_snap_record`.
    """
    started = time.perf_counter()
    problem = built_problem(problems, problems.objective)
    recommendation = recommend(chosen, front, problems.objective)
    snap = snapping.snap_to_catalogue(
        problem,
        recommendation.result,
        catalogue.motors,
        arm=problems.setup.arm,
        gearboxes=catalogue.gearboxes or None,
        candidates=catalogue.candidates,
        gearbox_kinds=catalogue.gearbox_kinds,
        max_combinations=catalogue.max_combinations,
        ipopt_options=IPOPT_OPTIONS,
        progress=progress,
        solve_many=None if executor is None else _ThroughExecutor(problems, recommendation.result, executor),
        active_set=problems.active_set,
    )
    joints = [_joint_record(snap, j, catalogue) for j in range(len(snap.joints))]
    design = None
    if snap.result is not None and snap.parts is not None:
        design = design_record(problem, snap.result, "catalogue design", catalogue.motors)
        parts_problem = catalogue_problem(problem, snap.parts, problems.setup.arm)
        design["undecided"] = undecided(problems, parts_problem, snap.result)
    results = front.points if front is not None and front.points else (chosen,)
    return {
        "key": catalogue.key,
        "snapped": recommendation.source,
        "method": snap.method,
        "candidates": catalogue.candidates,
        "max_combinations": catalogue.max_combinations,
        "warnings": list(snap.warnings),
        "joints": joints,
        "objectives": snap.objectives,
        "continuous_objectives": snap.continuous_objectives,
        "difference": snap.difference,
        "relative_difference": {k: _finite(v) for k, v in snap.relative_difference.items()},
        "design": design,
        "tried": [
            {"parts": list(t.parts), "objective": t.objective, "status": t.status, "iterations": t.iterations}
            for t in snap.tried
        ],
        "pareto": [quick_snap_record(problem, r, catalogue) for r in results],
        "solve_time": time.perf_counter() - started,
    }


_SNAP_LOCK = threading.RLock()
"""CasADi and IPOPT are not thread-safe: a process (a Dask worker with several threads) solves one combination
at a time; the snap runs after the sweep, so its pieces never meet the sweep's."""


@dataclass(frozen=True)
class _ThroughExecutor:
    """A :data:`collision_reflex.optimize.snap.PartsSolver` that solves each combination as a piece of work."""

    problems: StudyProblems
    optimum: DesignResult
    executor: Executor

    def __call__(
        self, combinations: Sequence[tuple[CataloguePart, ...]], warm: bool = True
    ) -> list[DesignResult | str]:
        futures = [
            self.executor.submit(solve_study_parts, self.problems, self.optimum, c, warm)
            for c in combinations
        ]
        try:
            return [future.result() for future in futures]
        except BaseException:
            for future in futures:
                future.cancel()
            raise


def solve_study_parts(
    problems: StudyProblems, optimum: DesignResult, parts: tuple[CataloguePart, ...], warm: bool = True
) -> DesignResult | str:
    """One combination of a study's catalogue snap, in any process (its problem built there once).

    ``warm``: as :func:`collision_reflex.optimize.catalogue_search.solve_parts` says.

    One solve at a time per process with single-threaded BLAS, as every piece of a sweep, so that the numbers
    are the same on every executor.
    """
    with _SNAP_LOCK, single_threaded_blas():
        problem = built_problem(problems, problems.objective)
        return solved_or_status(
            problem, optimum, parts, problems.setup.arm, IPOPT_OPTIONS, problems.active_set, warm
        )


def _joint_record(snap: CatalogueDesign, j: int, catalogue: SnapCatalogue) -> CatalogueJoint:
    """Joint ``j`` of a catalogue snap as plain data: its part and provenance, next to the continuous design."""
    candidates = snap.joints[j]
    part = snap.parts[j] if snap.parts is not None else None
    gearbox = None if part is None else part.gearbox
    continuous = snap.continuous.design
    return {
        "joint": candidates.joint,
        "part": None if part is None else part.label,
        "motor": None if part is None else part.motor.name,
        "gearbox": None if gearbox is None else gearbox.name,
        "gearbox_from_catalogue": None if part is None else part.gearbox_from_catalogue,
        "gearbox_source": None if gearbox is None else gearbox.source,
        "gearbox_estimates": {}
        if gearbox is None
        else _estimates(catalogue.provenance.get(gearbox.name, {})),
        "gear_ratio": None if snap.result is None else float(snap.result.design.gear_ratio[j]),
        "continuous_gear_ratio": float(continuous.gear_ratio[j]),
        "stator_diameter": None if part is None else part.motor.stator_diameter,
        "continuous_stator_diameter": float(continuous.stator_diameter[j]),
        "source": None if part is None else part.motor.source,
        **_provenance(part, catalogue),
        "candidates": [p.label for p in candidates.parts],
        "nearest": candidates.nearest,
        "misses": list(candidates.misses),
        "warning": candidates.warning,
    }


def quick_snap_record(problem: DesignProblem, result: DesignResult, catalogue: SnapCatalogue) -> QuickSnap:
    """A design's quick catalogue snap: the nearest candidate per joint, evaluated without a re-solve.

    Each joint's nearest part within bounds (:func:`collision_reflex.optimize.parts.quick_parts`) at the
    gear ratio that keeps the joint's peak torque, raised where the parts' own masses need more
    (:func:`collision_reflex.optimize.parts.evaluate_parts`), the other variables the design's: far cheaper than
    re-solving it (build and IPOPT). ``parts``: the
    part per joint (None: no catalogue part within bounds, with ``missing``: the nearest part and what it
    misses); ``feasible`` and ``shortfalls``: whether it meets every torque and speed requirement as it is;
    ``objectives``, ``difference``, ``relative_difference``: as in :class:`CatalogueRecord` (empty without
    parts).
    """
    joints = joint_candidates(
        problem, result, catalogue.motors, 1, catalogue.gearboxes or None, 1, screen=False
    )
    missing: list[MissingPart] = [
        {"joint": j.joint, "nearest": j.nearest, "misses": list(j.misses)} for j in joints if not j.parts
    ]
    parts = quick_parts(joints, result.design)
    record: QuickSnap = {
        "parts": [j.parts[0].label if j.parts else None for j in joints]
        if parts is None
        else [p.label for p in parts],
        "missing": missing,
        "feasible": False,
        "shortfalls": [],
        "objectives": {},
        "difference": {},
        "relative_difference": {},
    }
    if parts is None:
        return record
    evaluated = evaluate_parts(problem, result.design, parts)
    continuous = result.numpy_objectives
    difference = {k: v - continuous[k] for k, v in evaluated.objectives.items()}
    record["feasible"] = evaluated.feasible
    record["shortfalls"] = list(evaluated.shortfalls)
    record["objectives"] = evaluated.objectives
    record["difference"] = difference
    record["relative_difference"] = {
        k: _finite(d / continuous[k]) if continuous[k] != 0 else None for k, d in difference.items()
    }
    return record


class _Provenance(TypedDict):
    """A part's fields with a source other than its entry's (``sources``), and its estimated ones (methods)."""

    sources: dict[str, str]
    estimates: dict[str, str]


def _provenance(part: CataloguePart | None, catalogue: SnapCatalogue) -> _Provenance:
    """A part's fields with another source than its entry's ``sources``, and its ``estimates`` (methods)."""
    if part is None:
        return {"sources": {}, "estimates": {}}
    fields = catalogue.provenance.get(part.motor.name, {})
    default = f"source: {part.motor.source}"
    return {
        "sources": {
            k: v.removeprefix("source: ")
            for k, v in fields.items()
            if v.startswith("source: ") and v != default
        },
        "estimates": _estimates(fields),
    }


def _estimates(provenance: dict[str, str]) -> dict[str, str]:
    """The estimated fields of a part's provenance, with their methods."""
    return {k: v.removeprefix("ESTIMATE: ") for k, v in provenance.items() if v.startswith("ESTIMATE: ")}


def _finite(value: float) -> float | None:
    """``value``, or None where it is not finite (JSON has no inf)."""
    return float(value) if math.isfinite(value) else None
