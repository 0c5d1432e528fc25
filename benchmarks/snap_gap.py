"""Benchmark of the catalogue snap's heuristic against exact enumeration (``collision_reflex.optimize.snap``).

On problems small enough for both, the continuous optimum (4 starts) is snapped to the packaged motor catalogue
twice: by enumerating every combination of the ``k`` nearest candidates per joint (exact), and by the coordinate
descent forced with ``max_combinations=1`` (heuristic). Prints per problem the number of combinations, each
answer's objective (the problem's own, start-normalised), the heuristic's gap to the exact answer [%], the
combinations each solved and the wall times.

Problems: the shipped two-link study's arm (worst-case impulse, and worst case plus 5 % motor mass) with k = 3
and 4; a two-joint double pendulum under gravity with a payload; the shipped Panda study at smoke size (3
configurations, its duty cycle) with k = 2 (2^7 = 128 combinations). Run: ``python benchmarks/snap_gap.py``
(``--quick``: the two-joint problems only).
"""

from __future__ import annotations

import argparse
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

import collision_reflex as cr
from collision_reflex.optimize.catalogue_search import objective_value
from collision_reflex.optimize.snap import snap_to_catalogue

ROOT = Path(__file__).resolve().parents[1]
Case = tuple[str, Callable[[], tuple[cr.Arm, cr.DesignProblem]], int]


def two_link(objective: str | dict[str, float]) -> tuple[cr.Arm, cr.DesignProblem]:
    arm = cr.Arm.from_urdf(ROOT / "designs" / "planar_two_link.urdf", "tip")
    q = np.array([[0.0, a] for a in np.deg2rad([30, 45, 60, 90, 120])])
    samples = cr.ContactSamples.grid(arm.kinematics(q), cr.arm.circle_directions(16))
    space = cr.DesignSpace(
        stator_diameter=(0.01, 0.1),
        gear_ratio=(1, 100),
        software_stiffness=(10, 1000),
        threshold=3.0,
        approach_velocity=0.5,
    )
    technology = cr.ActuatorTechnology(cr.reference_motor(), 1000.0)
    constraints = cr.Constraints(torque_required=[1.3, 1.3], threshold_floor=0.5)
    return arm, cr.build_problem(arm, samples, space, technology, objective, constraints)


def double_pendulum() -> tuple[cr.Arm, cr.DesignProblem]:
    arm = cr.Arm.from_example_robot_data("double_pendulum")
    kinematics = arm.kinematics(arm.sample_configurations(8, np.random.default_rng(1)))
    samples = cr.ContactSamples.grid(kinematics, cr.arm.circle_directions(8))
    space = cr.DesignSpace(
        stator_diameter=(0.02, 0.12),
        gear_ratio=(1, 50),
        software_stiffness=(5, 500),
        threshold=(1, 10),
        approach_velocity=(0.05, 1.0),
    )
    technology = cr.ActuatorTechnology(cr.reference_motor(), 500.0)
    constraints = cr.Constraints(payload=0.2, safety_factor=1.5, threshold_floor=2.0)
    objective = {"worst_case_impulse": 1.0, "actuator_mass": 0.05}
    return arm, cr.build_problem(arm, samples, space, technology, objective, constraints)


def panda_smoke() -> tuple[cr.Arm, cr.DesignProblem]:
    from collision_reflex.study.problems import StudyProblems
    from collision_reflex.study.resolve import resolve_study

    problems = StudyProblems(resolve_study(cr.load_study(ROOT / "studies" / "panda.yaml"), smoke=True))
    return problems.setup.arm, problems(problems.objective)


def run(name: str, build: Callable[[], tuple[cr.Arm, cr.DesignProblem]], k: int) -> None:
    arm, problem = build()
    optimum = cr.solve(problem, starts=4)
    motors = cr.hardware.load_catalogue()
    started = time.perf_counter()
    exact = snap_to_catalogue(problem, optimum, motors, arm=arm, candidates=k, max_combinations=10**6)
    exact_time = time.perf_counter() - started
    started = time.perf_counter()
    heuristic = snap_to_catalogue(problem, optimum, motors, arm=arm, candidates=k, max_combinations=1)
    heuristic_time = time.perf_counter() - started
    if exact.result is None or heuristic.result is None:
        print(f"{name:34s} k={k}: no feasible catalogue design ({exact.warnings})")
        return
    best = objective_value(problem, exact.result.numpy_objectives)
    found = objective_value(problem, heuristic.result.numpy_objectives)
    print(
        f"{name:34s} k={k} {len(exact.tried):5d} combinations: exact {best:.6g} ({exact_time:6.2f} s), "
        f"heuristic {found:.6g} ({len(heuristic.tried)} solved, {heuristic_time:6.2f} s), "
        f"gap {100 * (found / best - 1):+.3f} %"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="the two-joint problems only")
    args = parser.parse_args()
    cases: list[Case] = [
        ("two-link, worst case", lambda: two_link("worst_case_impulse"), 3),
        ("two-link, worst case", lambda: two_link("worst_case_impulse"), 4),
        (
            "two-link, worst case + 5 % mass",
            lambda: two_link({"worst_case_impulse": 1, "actuator_mass": 0.05}),
            4,
        ),
        ("double pendulum, worst case + mass", double_pendulum, 4),
    ]
    if not args.quick:
        cases.append(("Panda (smoke size, duty cycle)", panda_smoke, 2))
    for name, build, k in cases:
        run(name, build, k)


if __name__ == "__main__":
    main()
