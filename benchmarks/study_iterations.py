"""IPOPT iterations and CPU time of the shipped studies' optimum and Pareto sweep, solve by solve.

    PYTHONPATH=src python benchmarks/study_iterations.py [STUDY ...] [--stages optimum,pareto]

By default ``studies/panda.yaml`` and ``studies/ur5.yaml``. In this process, serially, each study's problems are
built first (as a run's workers build them), then the stage "optimum" (the multi-start of ``crx run``:
``optimum.single_optimum`` from ``OPTIMUM_STARTS`` starts) and the stage "pareto" (``pareto.pareto_front``, the
anchor of the study's objective taking the optimum when the optimum stage ran) run as ``crx run`` runs them. It
prints per stage the IPOPT iterations of every run (retries and the multi-start's screening runs included), their
sum, the CPU time, and the optimum's scaled objective or the front's objective values, with the load average
before and after: the figures to compare when a change is to leave the answers alone and cut the iterations.
"""

from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

from collision_reflex.optimize.optimum import OPTIMUM_STARTS, known_optima, single_optimum
from collision_reflex.optimize.pareto import pareto_front
from collision_reflex.optimize.pieces import built_problem
from collision_reflex.study.load import load_study
from collision_reflex.study.problems import IPOPT_OPTIONS, StudyProblems
from collision_reflex.study.resolve import resolve_study

ROOT = Path(__file__).resolve().parents[1]
DEFAULT_STUDIES = (ROOT / "studies" / "panda.yaml", ROOT / "studies" / "ur5.yaml")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("studies", nargs="*", default=[str(p) for p in DEFAULT_STUDIES])
    parser.add_argument("--stages", default="optimum,pareto", help="comma-separated: optimum, pareto")
    args = parser.parse_args()
    stages = args.stages.split(",")
    runs = _record_runs()
    for study in args.studies:
        problems = StudyProblems(resolve_study(load_study(Path(study))))
        setup = problems.setup
        print(f"{Path(study).name}: load average {os.getloadavg()[0]:.2f}", flush=True)
        names = tuple(setup.study.pareto.objectives) if setup.study.pareto is not None else ()
        built_problem(problems, problems.objective, ())
        for name in names:
            built_problem(problems, name, tuple(other for other in names if other != name))
        result = None
        if "optimum" in stages:
            runs.clear()
            cpu = time.process_time()
            result, _ = single_optimum(
                problems,
                problems.objective,
                IPOPT_OPTIONS,
                starts=OPTIMUM_STARTS,
                active_set=problems.active_set,
            )
            cpu = time.process_time() - cpu
            value = built_problem(problems, problems.objective, ()).objective_value(result.x)
            _print_stage("optimum", runs, cpu, f"scaled objective {value:.10g}")
        if "pareto" in stages and setup.study.pareto is not None:
            runs.clear()
            cpu = time.process_time()
            front = pareto_front(
                problems,
                names,
                setup.study.pareto.points,
                IPOPT_OPTIONS,
                anchor_starts=setup.study.pareto.anchor_starts,
                active_set=problems.active_set,
                known=None
                if result is None
                else known_optima(problems.objective, result, setup.study.pareto.anchor_starts),
            )
            cpu = time.process_time() - cpu
            values = "; ".join(", ".join(f"{v:.9g}" for v in row) for row in front.values())
            _print_stage(
                "pareto", runs, cpu, f"{len(front.points)} points, {len(front.failed)} failed: {values}"
            )
        print(f"  load average after: {os.getloadavg()[0]:.2f}", flush=True)


def _record_runs() -> list[tuple[str, str, int]]:
    """Record every IPOPT run of :func:`collision_reflex.optimize.solve.solve` (name, status, iterations)."""
    from collision_reflex.optimize.ipopt import IpoptRuns

    runs: list[tuple[str, str, int]] = []
    original = IpoptRuns.run

    def run(self, name, options, start, warm=None):  # type: ignore[no-untyped-def]
        found = original(self, name, options, start, warm)
        record = self.records[-1]
        runs.append((record.name, record.status, record.iterations))
        return found

    IpoptRuns.run = run  # type: ignore[method-assign]
    return runs


def _print_stage(stage: str, runs: list[tuple[str, str, int]], cpu: float, answer: str) -> None:
    iterations = ", ".join(
        f"{n}" + ("" if status == "Solve_Succeeded" else f" ({name}: {status})") for name, status, n in runs
    )
    print(f"  {stage}: {sum(n for _, _, n in runs)} iterations in {len(runs)} runs [{iterations}]")
    print(f"    CPU {cpu:.2f} s; {answer}", flush=True)


if __name__ == "__main__":
    main()
