"""Wall time of a study's Pareto front through each executor, where it goes, and whether the executors agree.

    PYTHONPATH=src python benchmarks/study_executors.py [STUDY] [--points 20] [--repeats 3] [--workers 2]
    PYTHONPATH=src python benchmarks/study_executors.py [STUDY] --runs [--smoke]

By default: the study's front (the UR5 study unless another is named) with ``--points`` points, solved
serially, on a local process pool and on a local Dask cluster of ``--workers`` processes, ``--repeats`` times
each, executors interleaved. Every executor starts cold: its start-up (starting the workers, forked on Linux with
this process's imports and the study's setup but no built problem, spawned elsewhere; building each problem
once per worker) is in its time, and the serial run builds its problems again.

It prints, per executor (medians over the repeats), the wall time and its speed-up over serial, and the largest
relative difference of the front's objectives from the serial front (0 expected: every point is a pure function
of the problem and its bounds). Then where the time goes, in CPU seconds, which a loaded machine stretches less
than wall time: the CPU of the parent and of the workers; per worker its start-up (from opening the executor
to its first piece, and the CPU it spent meanwhile: interpreter, imports), problem and solver construction,
solving (the pieces' CPU less construction), and idle time (wall time of the run a worker spent neither
starting nor working). ``quiet est.`` replays the run on an idle machine: each worker's start-up CPU, then
the pieces in the order they were submitted, each on the worker that frees first, each taking the CPU it took
here, the anchors before the points; its ratio to serial's is the speed-up a quiet machine would show
(an estimate: it ignores the parent's scheduling and the transfer of results). Target: >= 1.5x on 2 workers for
a 20-point front, on a quiet machine.

``--runs``: whole ``crx run`` runs instead (optimum, front, result files; no figures), once per executor.
"""

from __future__ import annotations

import argparse
import os
import resource
import statistics
import tempfile
import time
from collections.abc import Callable
from concurrent.futures import Executor, Future
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

ROOT = Path(__file__).resolve().parents[1]
EXECUTORS = ("serial", "processes", "dask")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("study", nargs="?", default=str(ROOT / "studies" / "ur5.yaml"))
    parser.add_argument("--points", type=int, default=20)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--executors", default=",".join(EXECUTORS), help="comma-separated (default: all)")
    parser.add_argument("--pieces", action="store_true", help="also print every piece's worker, CPU and span")
    parser.add_argument("--runs", action="store_true", help="whole study runs, once per executor")
    parser.add_argument("--smoke", action="store_true", help="with --runs: small sample counts")
    args = parser.parse_args()
    kinds = tuple(args.executors.split(","))
    if args.runs:
        compare_runs(args.study, args.smoke, args.workers, kinds)
    else:
        compare_fronts(args.study, args.points, args.repeats, args.workers, kinds, args.pieces)


def compare_fronts(
    study: str, points: int, repeats: int, workers: int, kinds: tuple[str, ...], pieces: bool = False
) -> None:
    """Median wall time of the study's front through each executor, its breakdown, the load and the agreement."""
    from collision_reflex.optimize.pareto import pareto_front
    from collision_reflex.optimize.sweep import Runner
    from collision_reflex.study.executors import open_executor
    from collision_reflex.study.load import load_study
    from collision_reflex.study.problems import IPOPT_OPTIONS, StudyProblems
    from collision_reflex.study.resolve import ResolvedStudy, resolved_study

    loaded = load_study(study)
    resolved = resolved_study(loaded)
    resolved["pareto"]["points"] = points
    problems = StudyProblems(ResolvedStudy.of(loaded, resolved))
    problems.setup  # noqa: B018 - the study's setup, built once in this process, as a run builds it to check
    objectives = tuple(resolved["pareto"]["objectives"])
    runs: dict[str, list[dict[str, float]]] = {kind: [] for kind in kinds}
    fronts: dict[str, np.ndarray] = {}
    load_before = os.getloadavg()
    for _ in range(repeats):
        for kind in kinds:
            _clear_solver_cache()  # every executor starts cold; a pool's workers build their own problems
            parent_cpu = _cpu_self()
            started = time.perf_counter()
            opened = time.time()
            with open_executor(kind, workers) as inner:
                executor = _Timed(inner)
                front = pareto_front(
                    problems,
                    objectives,
                    points,
                    IPOPT_OPTIONS,
                    runner=Runner(executor),
                    active_set=problems.active_set,  # as the study's run sweeps it
                )
                ended = time.time()
                children_cpu = _cpu_children_alive()
            wall = time.perf_counter() - started
            if pieces:
                _print_pieces(kind, executor.pieces, opened)
            runs[kind].append(
                _breakdown(executor.pieces, wall, _cpu_self() - parent_cpu, children_cpu, opened, ended, kind)
            )
            fronts.setdefault(kind, front.values(numpy_path=True))
    load_after = os.getloadavg()
    print(
        f"{Path(study).name}: {points}-point front of {objectives[0]} against {', '.join(objectives[1:])}, "
        f"{workers} workers, median of {repeats}; load average (1, 5, 15 min) "
        f"{_load(load_before)} before, {_load(load_after)} after"
    )
    medians = {
        kind: {key: statistics.median(r[key] for r in runs[kind]) for key in runs[kind][0]} for kind in kinds
    }
    serial = medians.get("serial", medians[kinds[0]])
    print(
        f"{'executor':<10}{'wall [s]':>9}{'all runs [s]':>20}{'speed-up':>9}{'points':>7}{'max rel. diff':>14}"
        f"{'quiet est. [s]':>15}{'est. speed-up':>14}"
    )
    for kind in kinds:
        m = medians[kind]
        diff = _difference(fronts[kind], fronts.get("serial", fronts[kinds[0]]))
        walls = " ".join(f"{r['wall']:.1f}" for r in runs[kind])
        print(
            f"{kind:<10}{m['wall']:>9.2f}{walls:>20}{serial['wall'] / m['wall']:>8.2f}x{len(fronts[kind]):>7}"
            f"{diff:>14.2e}{m['estimate']:>15.2f}{serial['estimate'] / m['estimate']:>13.2f}x"
        )
    print(
        "CPU [s], medians:"
        f"\n{'executor':<10}{'parent':>8}{'workers':>9}{'total':>8}{'start-up wall':>14}{'start-up CPU':>13}"
        f"{'construction':>13}{'solving':>9}{'idle':>7}{'pieces':>7}"
    )
    for kind in kinds:
        m = medians[kind]
        print(
            f"{kind:<10}{m['parent']:>8.1f}{m['workers']:>9.1f}{m['parent'] + m['workers']:>8.1f}"
            f"{m['startup_wall']:>14.1f}{m['startup_cpu']:>13.1f}{m['construction']:>13.1f}{m['solving']:>9.1f}"
            f"{m['idle']:>7.1f}{m['pieces']:>7.0f}"
        )
    print(
        "(start-up, construction, solving, idle: summed over the workers; serial: the one process. Start-up wall:"
        " opening the executor to each worker's first piece; idle: the rest of the run's wall time a worker did"
        " not work)"
    )


class _Timed(Executor):
    """An executor that runs each piece through :func:`_timed` and keeps the timings it sends back."""

    def __init__(self, inner: Executor) -> None:
        self.inner = inner
        self.pieces: list[dict[str, Any]] = []
        self.submitted = 0

    def submit(self, fn: Callable[..., Any], /, *args: Any, **kwargs: Any) -> Future:
        outer: Future = Future()
        self.submitted += 1
        order = self.submitted

        def unwrap(inner: Future) -> None:
            if inner.cancelled():
                outer.cancel()
            elif inner.exception() is not None:
                outer.set_exception(inner.exception())
            else:
                result, timing = inner.result()
                self.pieces.append({**timing, "order": order, "function": fn.__name__})
                outer.set_result(result)

        self.inner.submit(_timed, fn, args, kwargs).add_done_callback(unwrap)
        return outer


def _timed(fn: Callable[..., Any], args: tuple, kwargs: dict) -> tuple[Any, dict[str, float]]:
    """Run a piece and time it: wall interval, CPU, and the CPU of problem and solver construction within."""
    construction = _count_construction()
    start_wall, start_cpu, start_construction = time.time(), _cpu_self(), construction[0]
    result = fn(*args, **kwargs)
    cpu = _cpu_self() - start_cpu
    timing = {
        "pid": os.getpid(),
        "start": start_wall,
        "end": time.time(),
        "cpu_before": start_cpu,
        "cpu": cpu,
        "construction": construction[0] - start_construction,
    }
    return result, timing


def _count_construction() -> list[float]:
    """``[CPU seconds]`` this process spent in ``built_problem`` and ``DesignProblem.solver`` (counted from the
    first call; kept on the module, since a Dask worker receives this benchmark's functions by value)."""
    from collision_reflex.optimize import epsilon, pieces, problem

    counter: list[float] | None = getattr(pieces, "_benchmark_construction_cpu", None)
    if counter is not None:
        return counter
    total = [0.0]
    depth = [0]

    def counted(function: Callable[..., Any]) -> Callable[..., Any]:
        def call(*args: Any, **kwargs: Any) -> Any:
            started = _cpu_self()
            depth[0] += 1
            try:
                return function(*args, **kwargs)
            finally:
                depth[0] -= 1
                if depth[0] == 0:  # a solver built within a problem's construction counts once
                    total[0] += _cpu_self() - started

        call.cache_clear = getattr(function, "cache_clear", None)  # type: ignore[attr-defined]
        return call

    built = counted(pieces.built_problem)
    pieces.built_problem = built  # type: ignore[assignment]
    epsilon.built_problem = built  # type: ignore[assignment]  # the anchors and points call it from there
    problem.DesignProblem.solver = counted(problem.DesignProblem.solver)  # type: ignore[method-assign]
    pieces._benchmark_construction_cpu = total  # type: ignore[attr-defined]
    return total


def _print_pieces(kind: str, pieces: list[dict[str, Any]], opened: float) -> None:
    print(f"{kind}: piece, worker, CPU [s] (of which construction), start and end [s after opening]")
    for piece in sorted(pieces, key=lambda p: p["order"]):
        print(
            f"  {piece['order']:>3} {piece['function']:<12} {piece['pid']:>7} {piece['cpu']:>7.2f} "
            f"({piece['construction']:.2f}) {piece['start'] - opened:>7.1f} {piece['end'] - opened:>7.1f}"
        )


def _breakdown(
    pieces: list[dict[str, Any]],
    wall: float,
    parent_cpu: float,
    children_cpu: float,
    opened: float,
    ended: float,
    kind: str,
) -> dict[str, float]:
    """One run's figures (see the module docstring)."""
    by_worker: dict[int, list[dict[str, Any]]] = {}
    for piece in sorted(pieces, key=lambda p: p["start"]):
        by_worker.setdefault(piece["pid"], []).append(piece)
    serial = kind == "serial"
    startup_wall = 0.0 if serial else sum(w[0]["start"] - opened for w in by_worker.values())
    startup_cpu = 0.0 if serial else sum(w[0]["cpu_before"] for w in by_worker.values())
    busy = sum(p["end"] - p["start"] for p in pieces)
    construction = sum(p["construction"] for p in pieces)
    workers = 0.0 if serial else children_cpu
    return {
        "wall": wall,
        "parent": parent_cpu,
        "workers": workers,
        "startup_wall": startup_wall,
        "startup_cpu": startup_cpu,
        "construction": construction,
        "solving": sum(p["cpu"] for p in pieces) - construction,
        "idle": max(0.0, len(by_worker) * (ended - opened) - startup_wall - busy) if not serial else 0.0,
        "pieces": len(pieces),
        "estimate": _replay(pieces, by_worker, serial),
    }


def _replay(pieces: list[dict[str, Any]], by_worker: dict[int, list[dict[str, Any]]], serial: bool) -> float:
    """Wall time of the run on an idle machine: list scheduling of the pieces' CPU (module docstring)."""
    free = [0.0 if serial else w[0]["cpu_before"] for w in by_worker.values()]
    phase_end = 0.0
    previous = None
    for piece in sorted(pieces, key=lambda p: p["order"]):
        if piece["function"] != previous:  # the next stage waits for the previous one (anchors, then points)
            free = [max(f, phase_end) for f in free]
            previous = piece["function"]
        worker = int(np.argmin(free))
        free[worker] += piece["cpu"]
        phase_end = max(phase_end, free[worker])
    return phase_end


def _cpu_self() -> float:
    usage = resource.getrusage(resource.RUSAGE_SELF)
    return usage.ru_utime + usage.ru_stime


def _cpu_children_alive() -> float:
    """CPU so far of this process's descendants (the executor's workers, before they end)."""
    import psutil

    total = 0.0
    for child in psutil.Process().children(recursive=True):
        try:
            times = child.cpu_times()
        except psutil.Error:
            continue
        total += times.user + times.system
    return total


def compare_runs(study: str, smoke: bool, workers: int, kinds: tuple[str, ...]) -> None:
    """One whole study run per executor (no figures): wall time and agreement of ``pareto.csv``."""
    from collision_reflex.study.runner import run_study

    reference = None
    print(f"load average {_load(os.getloadavg())}")
    print(f"{'executor':<10}{'wall time [s]':>15}{'points':>8}{'max rel. diff':>15}")
    with tempfile.TemporaryDirectory() as tmp:
        for executor in kinds:
            started = time.perf_counter()
            result = run_study(
                study,
                Path(tmp) / executor,
                quiet=True,
                smoke=smoke,
                executor=executor,
                workers=workers,
                figures=False,
            )
            elapsed = time.perf_counter() - started
            table = pd.read_csv(result.folder / "pareto.csv")
            values = table[[c for c in table.columns if c.endswith(("[N*s]", "[kg]"))]].to_numpy(dtype=float)
            reference = values if reference is None else reference
            print(f"{executor:<10}{elapsed:>15.2f}{len(table):>8}{_difference(values, reference):>15.2e}")
    print(f"load average {_load(os.getloadavg())}")


def _clear_solver_cache() -> None:
    from collision_reflex.optimize.pieces import built_problem

    clear = getattr(built_problem, "cache_clear", None)
    if clear is not None:
        clear()


def _difference(values: np.ndarray, reference: np.ndarray) -> float:
    if values.shape != reference.shape:
        return float("inf")
    return float(np.max(np.abs(values - reference) / np.maximum(np.abs(reference), 1e-300), initial=0.0))


def _load(load: tuple[float, float, float]) -> str:
    return "/".join(f"{value:.2f}" for value in load)


if __name__ == "__main__":
    main()
