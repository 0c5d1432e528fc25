"""Running a study end to end.

Validate everything first, then do the independent work through an executor, keep each finished piece, and
write the results and the report.

A run restarted with the same command finds its finished pieces in ``OUT/points`` and does only the rest; the
same study (and seed) gives the same numbers whatever the executor, because every piece of work is a pure
function of the resolved study (:class:`~.resolve.ResolvedStudy`, resolved once per run) and its own inputs.
"""

from __future__ import annotations

import contextlib
import hashlib
import os
import time
from concurrent.futures import Executor
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, cast

import numpy as np

from .. import __version__
from .._interrupt import caused_by_interrupt
from ..errors import SolverFailed, StudyRunFailed
from ..optimize import DesignResult, ParetoSet
from ..optimize.active_set_result import ActiveSetResult
from ..optimize.optimum import OPTIMUM_STARTS, known_optima, single_optimum
from ..optimize.pareto import pareto_front
from ..optimize.pieces import built_problem, release_problems
from ..optimize.recommend import recommend
from ..optimize.sweep import Runner
from ..record.read import pick_design
from ..report import write_outputs
from ..report.outputs import StageTimes
from ..report.verdict import verdict
from . import simulate_design
from .actuator_study import check_actuator_study, evaluate_actuator_study
from .arm_results import CatalogueRecord, arm_results
from .arm_setup import ExtraSamples
from .catalogue_snap import SnapCatalogue, catalogue_results, study_catalogue
from .executors import open_executor
from .load import LoadedStudy, load_study
from .problems import IPOPT_OPTIONS, StudyProblems, checked_setup
from .progress import RunProgress
from .region_search import search_draw, search_region
from .resolve import ResolvedStudy, resolve_study
from .safety import human_contact_record
from .schema import ArmStudy
from .store import OutputFolderUnusable, RunFolder
from .transmission_choice import choice_record, choose_transmissions
from .worst_case import exchanges_samples, search_designs, violators

if TYPE_CHECKING:
    from ..optimize.worst_case import WorstCase
    from ..record.run import ArmRunRecord, RunRecord

SMOKE_ENVIRONMENT = "CRX_SMOKE"
"""Set to 1 to run every study with small sample counts (tests, quick checks): see :func:`.resolve.smoke_study`."""

TRANSMISSIONS = "transmissions"
"""The run folder's piece that keeps the gearbox choice."""


@dataclass(frozen=True)
class RunResult:
    """Where a run wrote its results, and what it did.

    folder: the output folder; resumed: whether finished work was found and reused; computed: pieces of work
    done in this run; reused: pieces found finished; elapsed: wall time [s]; verdict: the sentences the report
    opens with (arm studies; empty for actuator studies).
    """

    folder: Path
    resumed: bool
    computed: int
    reused: int
    elapsed: float
    verdict: tuple[str, ...] = ()

    @property
    def report(self) -> Path:
        """The run's HTML report."""
        return self.folder / "report.html"


def default_output_folder(loaded: LoadedStudy, smoke: bool = False) -> Path:
    """``results/<study name>`` under the working directory (``results/<study name>-smoke`` for a smoke run).

    A smoke run has its own folder, so that a later full run into the default folder is not refused as
    another run's.
    """
    return Path.cwd() / "results" / (loaded.study.name + ("-smoke" if smoke else ""))


def run_study(
    path: str | os.PathLike[str],
    out: str | os.PathLike[str] | None = None,
    *,
    quiet: bool = False,
    scheduler: str | None = None,
    executor: str | None = None,
    workers: int | None = None,
    smoke: bool | None = None,
    figures: bool = True,
) -> RunResult:
    """Run the study in file ``path`` and write its results to ``out``.

    The default ``out`` is ``results/<name>`` (``results/<name>-smoke`` for a smoke run).

    Parameters
    ----------
    quiet: no progress bars (for scripts and logs).
    scheduler: a Dask scheduler address (``tcp://host:8786``): run the work on that cluster.
    executor, workers: override the study's execution settings (``serial``, ``processes``, ``dask``).
    smoke: shrink sample counts for a quick run (default: the environment variable ``CRX_SMOKE``).

    Raises
    ------
    StudyFileError: a bad study, with its lines; every input is checked before the output folder is touched,
        so nothing is written then.
    """
    started = time.perf_counter()
    stages = StageTimes()
    smoke = bool(os.environ.get(SMOKE_ENVIRONMENT, "")) if smoke is None else smoke
    study, catalogue, transmissions, folder, chosen_before = _prepared(path, out, smoke, stages)
    execution = study.data.get("execution", {})
    kind = executor or execution.get("executor", "serial")
    if scheduler is None and kind == "dask":
        scheduler = execution.get("scheduler")
    details = {"study": study.study.name, "study_file": str(path), "smoke": smoke, "version": __version__}
    resumed = folder.claim(
        study.fingerprint, study.text, {**details, "started": time.strftime("%Y-%m-%dT%H:%M:%S%z")}
    )
    if transmissions is not None:
        folder.save(TRANSMISSIONS, transmissions)
    progress = RunProgress(quiet)
    try:
        n_workers = workers or execution.get("workers", 2)
        # Work in flight: one at a time in-process; a few per worker for a pool (so that finished work is saved
        # while the rest runs); everything at once for a Dask cluster, whose size is its own business.
        window = 1 if kind == "serial" and scheduler is None else (10**6 if scheduler else 2 * n_workers)
        with open_executor(kind, n_workers, scheduler) as pool:
            if isinstance(study.study, ArmStudy):
                results, counts = _run_arm(
                    study, folder, pool, progress, window, stages, catalogue, transmissions
                )
            else:
                with stages.stage("actuators"):
                    results, counts = _run_actuators(study.loaded, folder, progress)
        if transmissions is not None:  # the gearbox choice is a piece of work too
            counts = (counts[0], counts[1] + 1) if chosen_before else (counts[0] + 1, counts[1])
        progress.stop()
        write_outputs(folder.path, cast("RunRecord", results), figures=figures, stages=stages)
    except OSError as error:  # a full disk, a folder made read-only meanwhile: finished pieces are kept
        progress.stop()
        with contextlib.suppress(OSError):
            folder.update_manifest(status="failed")
        raise OutputFolderUnusable.from_os_error(error, folder.path, exit_status=1) from None
    except BaseException as error:
        progress.stop()
        interrupted = caused_by_interrupt(error)
        folder.update_manifest(status="interrupted" if interrupted else "failed")
        if interrupted and not isinstance(error, KeyboardInterrupt):  # Ctrl-C surfacing as another error
            raise KeyboardInterrupt from error
        raise
    elapsed = time.perf_counter() - started
    folder.update_manifest(status="finished", elapsed=elapsed, computed=counts[0], reused=counts[1])
    return RunResult(folder.path, resumed, counts[0], counts[1], elapsed, tuple(results.get("verdict", ())))


def _prepared(
    path: str | os.PathLike[str], out: str | os.PathLike[str] | None, smoke: bool, stages: StageTimes
) -> tuple[ResolvedStudy, SnapCatalogue | None, dict[str, Any] | None, RunFolder, bool]:
    """The study a run solves (resolved once), its catalogue, gearbox choice and folder, all checked.

    Every problem (robot, motors, samples, the problem build) is raised here, located in the file as written,
    before any output. The gearbox choice (:func:`.transmission_choice.choice_record`) is read from the folder
    when an earlier run of the study made it; the last element says whether it was.
    """
    with stages.stage("load"):
        loaded = load_study(path)
        study = resolve_study(loaded, smoke)
    folder = RunFolder(Path(out) if out is not None else default_output_folder(loaded, smoke))
    transmissions, saved = None, None
    if isinstance(loaded.study, ArmStudy) and isinstance(loaded.study.actuators.gearbox, list):
        with stages.stage("transmissions"):  # the best gearbox option per module, by the study's objective
            written, saved = study, folder.peek(TRANSMISSIONS)
            study, tried = choose_transmissions(loaded, study, saved)  # located as written
            transmissions = choice_record(written, tried)
    chosen_before = transmissions is not None and saved == transmissions
    with stages.stage("prepare"):
        if isinstance(loaded.study, ArmStudy):
            checked_setup(loaded, study)
            return study, study_catalogue(study.loaded), transmissions, folder, chosen_before
        check_actuator_study(loaded)
    return study, None, transmissions, folder, chosen_before


def _run_arm(
    resolved: ResolvedStudy,
    folder: RunFolder,
    pool: Executor,
    progress: RunProgress,
    window: int,
    stages: StageTimes,
    catalogue: SnapCatalogue | None = None,
    transmissions: dict[str, Any] | None = None,
) -> tuple[dict[str, Any], tuple[int, int]]:
    """The study's optimum (multi-started), its Pareto front by the optimiser's one sweep, and the verdict.

    Each stage is timed into ``stages``. After each round of solves, every design's worst case is searched
    over the contact domain (:mod:`.worst_case`); with a worst-case objective the violators join the samples and
    the next round solves on them, until none is found or ``optimizer.worst_case_search.rounds`` is reached. A
    study held to a body region adds the poses a search draw finds beyond its permissible speed likewise
    (:mod:`.region_search`).

    Then, with a ``catalogue``, the recommended design and every Pareto design snapped to it
    (:func:`.catalogue_snap.catalogue_results`). Each piece is saved as it finishes and found again when the run
    resumes (the snap as ``catalogue``, reused while the catalogue file and the settings are the same).
    ``transmissions``: the gearbox choice made before (:func:`.transmission_choice.choice_record`), its
    assignments kept in the results.
    """
    study = resolved.study
    assert isinstance(study, ArmStudy)
    search = study.optimizer.worst_case_search
    extra: ExtraSamples = ()
    computed = reused = 0
    optimum: DesignResult | None = None  # the last round's, which the next one starts from
    draw = None
    for round_ in range(search.rounds if search.enabled else 1):
        if round_:  # the last round's problems, on fewer samples, are not solved again
            release_problems()
        problems = StudyProblems(resolved, extra)
        prefix = f"round-{round_}-{_digest(extra)}-" if extra else ""
        optimum, front, counts = _solve_round(
            problems, study, folder, pool, progress, window, stages, prefix, optimum
        )
        computed, reused = computed + counts[0], reused + counts[1]
        if not search.enabled:
            searches: dict[str, WorstCase] = {}
            break
        designs = {
            "optimum": optimum,
            **(dict(zip(front.labels, front.points, strict=True)) if front else {}),
        }
        searches, searched = stages.timed("worst-case search", search_designs)(
            problems, designs, search, pool, folder
        )
        computed, reused = computed + searched[0], reused + searched[1]
        added = violators(designs, searches, search.tolerance) if exchanges_samples(study) else ()
        draw = draw or search_draw(problems.setup)
        if draw is not None:
            found = stages.timed("region search", search_region)(
                problems.setup, draw, {k: v.design for k, v in designs.items()}, search.tolerance
            )
            added = tuple(dict.fromkeys(added + tuple(p for f in found.values() for p in f.added)))
        if not added or round_ == search.rounds - 1:
            break
        extra = extra + added
    assert optimum is not None  # at least one round ran
    snapped = None
    if catalogue is not None:
        saved = folder.finished("catalogue")
        key = catalogue.key + (f"-{_digest(extra)}" if extra else "")  # the same parts on the same samples
        if saved is not None and saved.get("key") == key:
            snapped, reused = cast("CatalogueRecord", saved), reused + 1
        else:
            snapped = stages.timed("catalogue snap", catalogue_results)(
                problems, optimum, front, catalogue, progress.counter("catalogue snap"), pool
            )
            snapped["key"] = key
            folder.save("catalogue", dict(snapped))
            computed += 1
    results = {
        "kind": "arm",
        "study": study.name,
        "description": study.description,
        "resolved": resolved.data,
        **stages.timed("results", arm_results)(problems, optimum, front, snapped, searches, search.tolerance),
    }
    if transmissions is not None:
        results["transmission_choice"] = transmissions["tried"]
    if study.simulate is not None:
        recommended = recommend(optimum, front, problems.objective).result
        results["simulation"] = stages.timed("simulation", simulate_design.simulate_designs)(
            problems, recommended, front, study.simulate, folder
        )
    results["human_contact"] = stages.timed("results", human_contact_record)(
        problems.setup, *reversed(pick_design(cast("ArmRunRecord", results), "recommended"))
    )
    results["verdict"] = stages.timed("results", verdict)(results)
    return results, (computed, reused)


def _solve_round(
    problems: StudyProblems,
    study: ArmStudy,
    folder: RunFolder,
    pool: Executor,
    progress: RunProgress,
    window: int,
    stages: StageTimes,
    prefix: str,
    before: DesignResult | None = None,
) -> tuple[DesignResult, ParetoSet | None, tuple[int, int]]:
    """The optimum and the Pareto front of ``problems``; their pieces saved under ``prefix``.

    The optimum is multi-started, or, in an exchange round, started from ``before`` (the last round's, on the
    samples but the ones a search added since) with its active samples and the added ones: the exchange method
    re-solves from its last design.
    """
    starts, x0, initial = OPTIMUM_STARTS, None, None
    if before is not None:
        full = built_problem(problems, problems.objective)
        n_design = full.layout.size
        starts, x0 = 1, full.exact_point(np.concatenate([before.x[:n_design], full.x0[n_design:]]))
        if isinstance(before, ActiveSetResult) and before.method == "active set":
            # The samples are the last round's and then the searched ones added since.
            added = np.arange(np.asarray(before.impulses).size, full.samples.size)
            initial = np.union1d(before.active_samples, added)

    def finished(name: str) -> dict[str, Any] | None:
        return folder.finished(prefix + name)

    def save(name: str, record: dict[str, Any]) -> None:
        folder.save(prefix + name, record)

    try:
        optimum, found = stages.timed("optimum", single_optimum)(
            problems,
            problems.objective,
            IPOPT_OPTIONS,
            runner=Runner(
                pool,
                finished=finished,
                save=save,
                progress=progress.counter("optimum of the study's objective"),
            ),
            starts=starts,
            active_set=problems.active_set,
            x0=x0,
            initial=initial,
        )
    except SolverFailed as error:
        raise StudyRunFailed(f"the optimum solve failed: {error.args[0]}", "optimum", error.status) from None
    computed, reused = (0, 1) if found else (1, 0)
    front = None
    if study.pareto is not None:
        try:
            front = stages.timed("pareto", pareto_front)(
                problems,
                tuple(study.pareto.objectives),
                study.pareto.points,
                IPOPT_OPTIONS,
                anchor_starts=study.pareto.anchor_starts,
                runner=Runner(pool, window, finished, save, progress=progress.counter("Pareto sweep")),
                active_set=problems.active_set,
                known=known_optima(problems.objective, optimum, study.pareto.anchor_starts),
            )
        except SolverFailed as error:
            raise StudyRunFailed(str(error.args[0]), "anchor", error.status) from None
        computed, reused = computed + front.computed, reused + front.reused
    return optimum, front, (computed, reused)


def _digest(extra: ExtraSamples) -> str:
    """A short digest of searched samples: the pieces solved on them are saved under it."""
    return hashlib.sha256(repr(extra).encode()).hexdigest()[:10]


def _run_actuators(
    loaded: LoadedStudy, folder: RunFolder, progress: RunProgress
) -> tuple[dict[str, Any], tuple[int, int]]:
    saved = folder.finished("actuators")
    if saved is None:
        advance = progress.stage("actuators", 1)
        saved = evaluate_actuator_study(loaded)
        folder.save("actuators", saved)
        advance()
        return saved, (1, 0)
    return saved, (0, 1)


__all__ = ["RunResult", "run_study"]
