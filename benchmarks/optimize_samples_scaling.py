"""Benchmark of the design optimiser's cost in the number of contact samples, full NLP against active set.

Problem: the Panda of ``benchmarks/optimize_panda.py`` (7 joints, 23 design variables, worst-case impulse, 1 kg
payload, safety factor 1.5, reflected inertia on the finger) with 64, 256 and 1,024 random configurations x 4
random directions = 256, 1,024 and 4,096 samples.

For each size it prints, as medians over ``--repeats`` runs (one for a run over 30 s) each in a fresh process (so that the peak resident
memory is the run's own), with the load average before and after:

- the full NLP: build, first solve (solver construction included), IPOPT iterations, peak memory; a run that
  does not finish within ``--budget`` seconds is stopped and reported as such;
- the active-set solve (:func:`collision_reflex.optimize.active_set.solve_active_set`): the same figures with
  the rounds and the size of the last active set, and the worst case's agreement with the full solve's.

Targets (issue 14, item 6): a 4,096-sample solve <= 20 s (aim 10 s) and <= 1 GB. Run:
``python benchmarks/optimize_samples_scaling.py`` (``--quick``: 256 and 1,024 samples, one repeat, full NLP
with a 60 s budget).

``--threshold`` measures where the active set starts to pay (``ACTIVE_SET_THRESHOLD``): one solve of each
method at 64 to 1,024 samples, on this Panda problem and on ``studies/ur5.yaml`` (its duty cycle and
weighted objective) with the study's configuration count scaled (14 directions each), in fresh processes.

``--front`` prints a 20-point Pareto front (worst-case impulse against actuator mass) of the Panda at 4,096
samples with every anchor and point on active sets (:func:`collision_reflex.optimize.pareto.pareto_front`,
``active_set="always"``), in a fresh process: wall time, peak memory, failed points, and per point the samples
of its last NLP and its rounds.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

import collision_reflex as cr
from collision_reflex.arm import Arm
from collision_reflex.optimize.active_set import solve_active_set

DIRECTIONS = 4
LONG_RUN = 30.0
"""A run longer than this [s] is not repeated."""


def panda_builder(n_config: int):
    """All samples of ``n_config`` Panda configurations x 4 directions, and the problem on given samples."""
    rng = np.random.default_rng(7)
    arm = Arm.from_example_robot_data("panda")
    kinematics = arm.kinematics(arm.sample_configurations(n_config, rng))
    samples = cr.ContactSamples.grid(kinematics, rng.normal(size=(DIRECTIONS, 3)))
    space = cr.DesignSpace(
        stator_diameter=(0.02, 0.15),
        gear_ratio=(1.0, 100.0),
        software_stiffness=(100.0, 1e4),
        threshold=(5.0, 40.0),
        approach_velocity=(0.05, 1.0),
    )
    constraints = cr.Constraints(payload=1.0, safety_factor=1.5, threshold_floor=5.0)
    technology = cr.ActuatorTechnology(
        cr.reference_motor(), mechanical_stiffness=5000.0, reflected_inertia_in="finger"
    )

    def build(chosen: cr.ContactSamples) -> cr.DesignProblem:
        return cr.build_problem(arm, chosen, space, technology, "worst_case_impulse", constraints)

    def build_front(objective: str, bounded: tuple[str, ...], chosen: cr.ContactSamples = samples):
        return cr.build_problem(arm, chosen, space, technology, objective, constraints, bounded)

    return samples, build, build_front


UR5_STUDY = Path(__file__).resolve().parents[1] / "studies" / "ur5.yaml"
UR5_DIRECTIONS = 14
"""Directions per configuration of ``studies/ur5.yaml`` (``sphere: 14``)."""


def ur5_builder(n_config: int):
    """``studies/ur5.yaml`` with ``n_config`` random configurations: all samples and the problem on given ones."""
    from collision_reflex.study.load import parse_study
    from collision_reflex.study.problems import StudyProblems
    from collision_reflex.study.resolve import resolve_study

    text = UR5_STUDY.read_text().replace("count: 24, seed: 5", f"count: {n_config}, seed: 5")
    problems = StudyProblems(resolve_study(parse_study(text, str(UR5_STUDY), UR5_STUDY.parent)))

    def build(chosen: cr.ContactSamples) -> cr.DesignProblem:
        return problems(problems.objective, (), chosen)

    return problems.setup.samples, build


def run_case(n_config: int, method: str, robot: str = "panda") -> dict[str, float | int | str]:
    """One solve in this process: times [s], iterations, worst case [N*s] and peak resident memory [MB]."""
    samples, build = ur5_builder(n_config) if robot == "ur5" else panda_builder(n_config)[:2]
    started, cpu = time.perf_counter(), time.process_time()
    if method == "full":
        problem = build(samples)
        built = time.perf_counter() - started
        result = cr.solve(problem)
        extra: dict[str, float | int | str] = {"build": built, "rounds": 1, "active": samples.size}
    else:
        result = solve_active_set(build, samples)
        extra = {"rounds": len(result.rounds), "active": int(result.active_samples.size)}
    total = time.perf_counter() - started
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024  # kB on Linux
    return {
        "total": total,
        "cpu": time.process_time() - cpu,
        "iterations": result.iterations,
        "worst": result.numpy_objectives["worst_case_impulse"],
        "peak_mb": peak,
        "samples": samples.size,
        **extra,
    }


def run_front(n_config: int, points: int) -> dict[str, object]:
    """A Pareto front on active sets in this process: wall time [s], peak memory [MB], points and failures."""
    _, _, build_front = panda_builder(n_config)
    started, cpu = time.perf_counter(), time.process_time()
    front = cr.pareto_front(build_front, points=points, active_set="always")
    total = time.perf_counter() - started
    return {
        "total": total,
        "cpu": time.process_time() - cpu,
        "peak_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024,
        "points": len(front.points),
        "merged": front.merged,
        "dominated": len(front.dominated),
        "failed": [f"{f.objective} {f.epsilon}: {f.status}" for f in front.failed],
        "per_point": [
            (label, int(r.active_samples.size), len(r.rounds), r.iterations, r.numpy_objectives)  # type: ignore[attr-defined]
            for r, label in zip(front.points, front.labels, strict=True)
        ],
    }


def measured(
    n_config: int, method: str, budget: float, robot: str = "panda"
) -> dict[str, float | int | str] | None:
    """``run_case`` in a fresh process; None when it does not finish within ``budget`` seconds."""
    command = [sys.executable, __file__, "--case", str(n_config), method, robot]
    try:
        done = subprocess.run(command, capture_output=True, text=True, timeout=budget)
    except subprocess.TimeoutExpired:
        return None
    if done.returncode != 0:
        raise RuntimeError(f"{' '.join(command[1:])} failed:\n{done.stderr[-2000:]}")
    figures: dict[str, float | int | str] = json.loads(done.stdout.strip().splitlines()[-1])
    return figures


def summary(runs: list[dict[str, float | int | str]], name: str) -> float:
    """Median of the runs' figure ``name``."""
    return statistics.median(float(run[name]) for run in runs)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="256 and 1,024 samples, one repeat, 60 s budget")
    parser.add_argument("--repeats", type=int, default=3, help="runs per size and method (median)")
    parser.add_argument("--budget", type=float, default=300.0, help="time limit of one full-NLP run [s]")
    parser.add_argument("--threshold", action="store_true", help="only: 64 to 1,024 samples, Panda and UR5")
    parser.add_argument("--front", action="store_true", help="only: a 20-point front at 4,096 samples")
    parser.add_argument("--points", type=int, default=20, help="points of the --front front")
    parser.add_argument("--case", nargs=3, metavar=("N_CONFIG", "METHOD", "ROBOT"), help=argparse.SUPPRESS)
    parser.add_argument("--front-case", nargs=2, metavar=("N_CONFIG", "POINTS"), help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.case:
        print(json.dumps(run_case(int(args.case[0]), args.case[1], args.case[2])))
        return
    if args.front_case:
        print(json.dumps(run_front(int(args.front_case[0]), int(args.front_case[1]))))
        return
    if args.threshold:
        threshold(args.budget)
        return
    if args.front:
        front_at_4096(args.points, 10 * args.budget)
        return
    sizes, repeats, budget = (
        ((64, 256), 1, 60.0) if args.quick else ((64, 256, 1024), args.repeats, args.budget)
    )
    print(
        f"Panda, worst-case impulse, {DIRECTIONS} directions per configuration; medians of {repeats} run(s)"
    )
    for n_config in sizes:
        load = os.getloadavg()[0]
        figures: dict[str, list[dict[str, float | int | str]]] = {}
        for method in ("full", "active"):
            runs: list[dict[str, float | int | str]] = []
            for _ in range(repeats):
                run = measured(n_config, method, budget if method == "full" else 10 * budget)
                if run is None:
                    break  # one run over the budget: the others would be too
                runs.append(run)
                if float(run["total"]) > LONG_RUN:
                    break  # a long run is its own median
            figures[method] = runs
        print(
            f"{DIRECTIONS * n_config} samples (load average {load:.2f} before, {os.getloadavg()[0]:.2f} after):"
        )
        for method, label in (("full", "full NLP"), ("active", "active set")):
            runs = figures[method]
            if not runs:
                print(f"  {label}: not finished within {budget:.0f} s")
                continue
            print(
                f"  {label} ({len(runs)} run(s)): {summary(runs, 'total'):.2f} s, {int(summary(runs, 'iterations'))} iterations, "
                f"peak {summary(runs, 'peak_mb'):.0f} MB; {int(summary(runs, 'rounds'))} round(s), "
                f"{int(summary(runs, 'active'))} samples in the last NLP; worst case {summary(runs, 'worst'):.6f} N*s"
            )
        if figures["full"] and figures["active"]:
            full, active = summary(figures["full"], "worst"), summary(figures["active"], "worst")
            print(f"  worst case: active set {(active - full) / full:+.1e} relative to the full NLP")


def threshold(budget: float) -> None:
    """One solve per method at about 64 to 1,024 samples, Panda and UR5 study, fresh processes."""
    print(f"Where the active set pays: one solve per method and size (full NLP budget {budget:.0f} s)")
    cases = [("panda", n, DIRECTIONS) for n in (16, 32, 64, 128, 256)]
    cases += [("ur5", n, UR5_DIRECTIONS) for n in (5, 9, 18, 24, 36, 73)]
    for robot, n_config, directions in cases:
        load = os.getloadavg()[0]
        line = []
        for method in ("full", "active"):
            run = measured(n_config, method, budget if method == "full" else 10 * budget, robot)
            if run is None:
                line.append(f"{method}: not finished within {budget:.0f} s")
                continue
            line.append(
                f"{method}: {float(run['total']):.2f} s ({float(run['cpu']):.2f} s CPU), {run['iterations']} iterations, "
                f"{float(run['peak_mb']):.0f} MB, {run['active']} samples in the last NLP"
            )
        print(
            f"  {robot} {n_config * directions} samples (load {load:.2f} before, {os.getloadavg()[0]:.2f} "
            f"after): " + "; ".join(line)
        )


def front_at_4096(points: int, budget: float) -> None:
    """A ``points``-point Panda front at 4,096 samples on active sets, in a fresh process."""
    load = os.getloadavg()[0]
    command = [sys.executable, __file__, "--front-case", "1024", str(points)]
    try:
        done = subprocess.run(command, capture_output=True, text=True, timeout=budget)
    except subprocess.TimeoutExpired:
        print(f"{points}-point front at 4,096 samples: not finished within {budget:.0f} s")
        return
    if done.returncode != 0:
        raise RuntimeError(f"the front failed:\n{done.stderr[-2000:]}")
    figures = json.loads(done.stdout.strip().splitlines()[-1])
    print(
        f"{points}-point Panda front at 4,096 samples on active sets (load {load:.2f} before, "
        f"{os.getloadavg()[0]:.2f} after): {figures['total']:.1f} s wall ({figures['cpu']:.1f} s CPU), peak {figures['peak_mb']:.0f} MB, "
        f"{figures['points']} points ({figures['merged']} merged, {figures['dominated']} dominated), "
        f"{len(figures['failed'])} failed" + "".join(f"\n  failed: {f}" for f in figures["failed"])
    )
    for label, active, rounds, iterations, objectives in figures["per_point"]:
        print(
            f"  {label}: worst case {objectives['worst_case_impulse']:.6f} N*s, mass "
            f"{objectives['actuator_mass']:.4f} kg; {active} samples, {rounds} round(s), {iterations} iterations"
        )


if __name__ == "__main__":
    main()
