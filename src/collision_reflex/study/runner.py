"""Running a study end to end.

Validate everything first, then do the independent work through an executor, keep each finished piece, and
write the results and the report.

A run restarted with the same command finds its finished pieces in ``OUT/points`` and does only the rest; the
same study (and seed) gives the same numbers whatever the executor, because every piece of work is a pure
function of the resolved study and its own inputs.
"""

from __future__ import annotations

import contextlib
import os
import time
from collections.abc import Callable
from concurrent.futures import Executor
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, cast

import numpy as np

from .._interrupt import caused_by_interrupt
from ..report.outputs import StageTimes
from .arm_results import CatalogueRecord, SnapCatalogue, arm_results, catalogue_results, study_catalogue
from .arm_setup import ExtraSamples
from .executors import open_executor
from .load import LoadedStudy, load_study, parse_study
from .resolve import fingerprint, resolved_study, resolved_yaml
from .schema import ActuatorStudy, ArmStudy
from .store import OutputFolderUnusable, RunFolder

if TYPE_CHECKING:
    from ..optimize import DesignResult, ParetoSet
    from .arm_setup import StudyProblems

SMOKE_ENVIRONMENT = "CRX_SMOKE"
"""Set to 1 to run every study with small sample counts (tests, quick checks): see :func:`smoke_study`."""


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


def smoke_study(data: dict[str, Any]) -> dict[str, Any]:
    """A resolved study shrunk for a quick run.

    A few configurations, directions, fresh configurations, Pareto points and velocities, and a lighter
    worst-case search. The shrunk study is what the run records as its resolved study.
    """
    data = {**data}
    if data.get("kind") == "actuator":
        data["velocities"] = {**data["velocities"], "count": min(data["velocities"]["count"], 12)}
        return data
    samples = {**data["samples"]}
    configurations = {**samples["configurations"]}
    if configurations.get("random"):
        configurations["random"] = {
            **configurations["random"],
            "count": min(configurations["random"]["count"], 3),
        }
    if configurations.get("list"):
        configurations["list"] = configurations["list"][:2]
    if configurations.get("trajectory"):
        configurations["trajectory"] = {
            **configurations["trajectory"],
            "every": max(configurations["trajectory"]["every"], 50),
        }
    directions = {**samples["directions"]}
    for key in ("circle", "sphere"):
        if directions.get(key):
            directions[key] = min(directions[key], 6)
    for key in ("named", "list"):
        if directions.get(key):
            directions[key] = directions[key][:4]
    data["samples"] = {
        **samples,
        "configurations": configurations,
        "directions": directions,
        "fresh": min(samples.get("fresh", 0), 64),
    }
    optimizer = {**data.get("optimizer", {})}
    search = {**optimizer.get("worst_case_search", {})}
    if search:  # a lighter search: a few starts, two rounds
        search.update(
            starts=min(search["starts"], 3),
            random_starts=min(search["random_starts"], 2),
            rounds=min(search["rounds"], 2),
        )
        data["optimizer"] = {**optimizer, "worst_case_search": search}
    data.pop("simulate", None)  # the time-domain simulation is no quick check
    if data.get("pareto"):
        data["pareto"] = {**data["pareto"], "points": min(data["pareto"]["points"], 4)}
    return data


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
    from .. import __version__

    started = time.perf_counter()
    stages = StageTimes()
    with stages.stage("load"):
        loaded = load_study(path)
        smoke = bool(os.environ.get(SMOKE_ENVIRONMENT, "")) if smoke is None else smoke
        resolved = resolved_study(loaded)
        as_written = loaded
        if smoke:
            resolved = smoke_study(resolved)
            loaded = parse_study(_dump(resolved), str(path), loaded.directory)
        text = resolved_yaml(loaded)
    transmissions = None
    if isinstance(loaded.study, ArmStudy) and isinstance(loaded.study.actuators.gearbox, list):
        from .transmission_choice import choose_transmissions

        with stages.stage("transmissions"):  # the best gearbox option per module, by the study's objective
            resolved, transmissions = choose_transmissions(as_written, resolved)  # located as written
            loaded = parse_study(_dump(resolved), str(path), loaded.directory)
            text = resolved_yaml(loaded)
    # Robot, motors, samples and the problem build: every problem is raised here, located in the file as
    # written, before any output.
    with stages.stage("prepare"):
        _prepare(as_written, text)
        catalogue = study_catalogue(loaded) if isinstance(loaded.study, ArmStudy) else None
    folder = RunFolder(Path(out) if out is not None else default_output_folder(loaded, smoke))
    execution = resolved.get("execution", {})
    kind = executor or execution.get("executor", "serial")
    if scheduler is None and kind == "dask":
        scheduler = execution.get("scheduler")
    resumed = folder.claim(
        fingerprint(resolved),
        text,
        {
            "study": loaded.study.name,
            "study_file": str(path),
            "smoke": smoke,
            "version": __version__,
            "started": time.strftime("%Y-%m-%dT%H:%M:%S%z"),
        },
    )
    progress = _Progress(quiet)
    try:
        n_workers = workers or execution.get("workers", 2)
        # Work in flight: one at a time in-process; a few per worker for a pool (so that finished work is saved
        # while the rest runs); everything at once for a Dask cluster, whose size is its own business.
        window = 1 if kind == "serial" and scheduler is None else (10**6 if scheduler else 2 * n_workers)
        with open_executor(kind, n_workers, scheduler) as pool:
            if isinstance(loaded.study, ArmStudy):
                results, counts = _run_arm(
                    loaded.study, text, folder, pool, progress, window, stages, catalogue, transmissions
                )
            else:
                with stages.stage("actuators"):
                    results, counts = _run_actuators(loaded, folder, progress)
        progress.stop()
        from ..report import write_outputs

        write_outputs(folder.path, results, figures=figures, stages=stages)
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


def _dump(data: dict[str, Any]) -> str:
    import yaml

    return yaml.safe_dump(data, sort_keys=False)


def _prepare(loaded: LoadedStudy, text: str) -> None:
    """Check everything a run needs.

    Problems are located in ``loaded`` (the file as written), while the problem is built from ``text`` (the
    resolved study that runs).
    """
    if isinstance(loaded.study, ArmStudy):
        from .arm_setup import checked_setup

        checked_setup(loaded, text)
    else:
        from .actuator_study import check_actuator_study

        check_actuator_study(loaded)


class _Progress:
    """Rich progress bars on stderr (none when quiet).

    Drawn from the first bar on: the bars' refresh thread starts then, after the run's executor has started
    its workers (a local pool forks them: :data:`~collision_reflex.study.executors.START_METHOD`).
    """

    def __init__(self, quiet: bool) -> None:
        self._bar: Any = None
        if not quiet:
            from rich.console import Console
            from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn

            self._bar = Progress(
                TextColumn("{task.description}"),
                BarColumn(),
                MofNCompleteColumn(),
                TimeElapsedColumn(),
                console=Console(stderr=True),
            )

    def _add(self, description: str, **counts: int) -> Any:
        if not self._bar.live.is_started:
            self._bar.start()
        return self._bar.add_task(description, **counts)

    def stage(self, description: str, total: int, done: int = 0) -> Callable[[], None]:
        if self._bar is None:
            return lambda: None
        task = self._add(description, total=total, completed=done)
        return lambda: self._bar.advance(task)

    def counter(self, description: str) -> Callable[[int, int], None]:
        """A ``progress(done, total)`` callback drawing one bar."""
        state: dict[str, Any] = {}

        def update(done: int, total: int) -> None:
            if self._bar is None:
                return
            if "task" not in state:
                state["task"] = self._add(description, total=total)
            self._bar.update(state["task"], completed=done, total=total)

        return update

    def stop(self) -> None:
        if self._bar is not None:
            self._bar.stop()
            self._bar = None


def _run_arm(
    study: ArmStudy,
    text: str,
    folder: RunFolder,
    pool: Executor,
    progress: _Progress,
    window: int,
    stages: StageTimes,
    catalogue: SnapCatalogue | None = None,
    transmissions: list[dict[str, Any]] | None = None,
) -> tuple[dict[str, Any], tuple[int, int]]:
    """The study's optimum (multi-started), its Pareto front by the optimiser's one sweep, and the verdict.

    Each stage is timed into ``stages``. After each round of solves, every design's worst case is searched
    over the contact domain (:mod:`.worst_case`); with a worst-case objective the violators join the samples and
    the next round solves on them, until none is found or ``optimizer.worst_case_search.rounds`` is reached.

    Then, with a ``catalogue``, the recommended design and every Pareto design snapped to it
    (:func:`.arm_results.catalogue_results`). Each piece is saved as it finishes and found again when the run
    resumes (the snap as ``catalogue``, reused while the catalogue file and the settings are the same).
    ``transmissions``: the gearbox assignments tried before (:func:`.transmission_choice.choose_transmissions`),
    kept in the results.
    """
    from ..optimize.pieces import release_problems
    from ..report.verdict import verdict
    from .arm_setup import StudyProblems
    from .worst_case import exchanges_samples, search_designs, violators

    search = study.optimizer.worst_case_search
    extra: ExtraSamples = ()
    computed = reused = 0
    optimum: DesignResult | None = None  # the last round's, which the next one starts from
    for round_ in range(search.rounds if search.enabled else 1):
        if round_:  # the last round's problems, on fewer samples, are not solved again
            release_problems()
        problems = StudyProblems(text, extra)
        prefix = f"round-{round_}-{_digest(extra)}-" if extra else ""
        optimum, front, counts = _solve_round(
            problems, study, folder, pool, progress, window, stages, prefix, optimum
        )
        computed, reused = computed + counts[0], reused + counts[1]
        if not search.enabled:
            searches = {}
            break
        designs = {
            "optimum": optimum,
            **(dict(zip(front.labels, front.points, strict=True)) if front else {}),
        }
        searches = stages.timed("worst-case search", search_designs)(problems, designs, search, pool)
        added = violators(designs, searches, search.tolerance)
        if not added or not exchanges_samples(study) or round_ == search.rounds - 1:
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
        "resolved": resolved_study(parse_study(text, "resolved study")),
        **stages.timed("results", arm_results)(problems, optimum, front, snapped, searches, search.tolerance),
    }
    if transmissions is not None:
        results["transmission_choice"] = transmissions
    if study.simulate is not None:
        from ..optimize.recommend import recommend
        from .simulate_design import simulate_designs

        recommended = recommend(optimum, front, problems.objective).result
        results["simulation"] = stages.timed("simulation", simulate_designs)(
            problems, recommended, front, study.simulate, folder
        )
    results["verdict"] = stages.timed("results", verdict)(results)
    return results, (computed, reused)


def _solve_round(
    problems: StudyProblems,
    study: ArmStudy,
    folder: RunFolder,
    pool: Executor,
    progress: _Progress,
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
    from ..errors import SolverFailed, StudyRunFailed
    from ..optimize.active_set_result import ActiveSetResult
    from ..optimize.optimum import OPTIMUM_STARTS, known_optima, single_optimum
    from ..optimize.pareto import pareto_front
    from ..optimize.pieces import built_problem
    from ..optimize.sweep import Runner
    from .arm_setup import IPOPT_OPTIONS

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
    import hashlib

    return hashlib.sha256(repr(extra).encode()).hexdigest()[:10]


def _run_actuators(
    loaded: LoadedStudy, folder: RunFolder, progress: _Progress
) -> tuple[dict[str, Any], tuple[int, int]]:
    from .actuator_study import evaluate_actuator_study

    assert isinstance(loaded.study, ActuatorStudy)
    saved = folder.finished("actuators")
    if saved is None:
        advance = progress.stage("actuators", 1)
        saved = evaluate_actuator_study(loaded)
        folder.save("actuators", saved)
        advance()
        return saved, (1, 0)
    return saved, (0, 1)


__all__ = ["RunResult", "run_study", "smoke_study"]
