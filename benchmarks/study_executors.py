"""Wall time of a study's Pareto front through each executor, and whether they agree.

    PYTHONPATH=src python benchmarks/study_executors.py [STUDY] [--points 20] [--repeats 3] [--workers 2]
    PYTHONPATH=src python benchmarks/study_executors.py [STUDY] --runs [--smoke]

By default: the study's front (the paper's two-link study unless another is named) with ``--points`` points,
solved serially, on a local process pool and on a local Dask cluster of ``--workers`` processes, ``--repeats``
times each, executors interleaved. It prints the median wall time of each (the executor's start-up included:
spawning the workers, importing the package, building each problem once per worker), its speed-up over serial,
the load average before and after, and the largest relative difference of the front's objectives from the
serial front (0 expected: every point is a pure function of the problem and its bounds). Target: >= 1.5x on 2
workers for a 20-point front, on a quiet machine.

``--runs``: whole ``crx run`` runs instead (optimum, front, result files; no figures), once per executor.
"""

from __future__ import annotations

import argparse
import os
import statistics
import tempfile
import time
from pathlib import Path

import numpy as np
import pandas as pd
import yaml

ROOT = Path(__file__).resolve().parents[1]
EXECUTORS = ("serial", "processes", "dask")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("study", nargs="?", default=str(ROOT / "studies" / "two_link_paper.yaml"))
    parser.add_argument("--points", type=int, default=20)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--runs", action="store_true", help="whole study runs, once per executor")
    parser.add_argument("--smoke", action="store_true", help="with --runs: small sample counts")
    args = parser.parse_args()
    if args.runs:
        compare_runs(args.study, args.smoke, args.workers)
    else:
        compare_fronts(args.study, args.points, args.repeats, args.workers)


def compare_fronts(study: str, points: int, repeats: int, workers: int) -> None:
    """Median wall time of the study's front through each executor, with the load and the agreement."""
    from collision_reflex.optimize.pareto import pareto_front
    from collision_reflex.study.arm_setup import IPOPT_OPTIONS, StudyProblems
    from collision_reflex.study.executors import open_executor
    from collision_reflex.study.load import load_study
    from collision_reflex.study.resolve import resolved_study

    resolved = resolved_study(load_study(study))
    resolved["pareto"]["points"] = points
    problems = StudyProblems(yaml.safe_dump(resolved, sort_keys=False))
    objectives = tuple(resolved["pareto"]["objectives"])
    times: dict[str, list[float]] = {kind: [] for kind in EXECUTORS}
    fronts: dict[str, np.ndarray] = {}
    load_before = os.getloadavg()
    for _ in range(repeats):
        for kind in EXECUTORS:
            started = time.perf_counter()
            with open_executor(kind, workers) as executor:
                front = pareto_front(
                    problems,
                    objectives,
                    points,
                    IPOPT_OPTIONS,
                    executor=None if kind == "serial" else executor,
                )
            times[kind].append(time.perf_counter() - started)
            fronts.setdefault(kind, front.values(numpy_path=True))
            if kind == "serial":
                _clear_solver_cache()  # serial repeats build their problems again, as each pool does
    load_after = os.getloadavg()
    serial = statistics.median(times["serial"])
    print(
        f"{Path(study).name}: {points}-point front of {objectives[0]} against {', '.join(objectives[1:])}, "
        f"{workers} workers, median of {repeats}; load average (1, 5, 15 min) "
        f"{_load(load_before)} before, {_load(load_after)} after"
    )
    print(
        f"{'executor':<10}{'median [s]':>12}{'all runs [s]':>24}{'speed-up':>10}{'points':>8}{'max rel. diff':>15}"
    )
    for kind in EXECUTORS:
        values = fronts[kind]
        diff = _difference(values, fronts["serial"])
        runs = " ".join(f"{t:.1f}" for t in times[kind])
        median = statistics.median(times[kind])
        print(f"{kind:<10}{median:>12.2f}{runs:>24}{serial / median:>9.2f}x{len(values):>8}{diff:>15.2e}")


def compare_runs(study: str, smoke: bool, workers: int) -> None:
    """One whole study run per executor (no figures): wall time and agreement of ``pareto.csv``."""
    from collision_reflex.study.runner import run_study

    reference = None
    print(f"load average {_load(os.getloadavg())}")
    print(f"{'executor':<10}{'wall time [s]':>15}{'points':>8}{'max rel. diff':>15}")
    with tempfile.TemporaryDirectory() as tmp:
        for executor in EXECUTORS:
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
    from collision_reflex.optimize.pareto import built_problem

    built_problem.cache_clear()


def _difference(values: np.ndarray, reference: np.ndarray) -> float:
    if values.shape != reference.shape:
        return float("inf")
    return float(np.max(np.abs(values - reference) / np.maximum(np.abs(reference), 1e-300), initial=0.0))


def _load(load: tuple[float, float, float]) -> str:
    return "/".join(f"{value:.2f}" for value in load)


if __name__ == "__main__":
    main()
