"""Benchmark of the actuator-design optimiser on a Panda arm.

Problem: 7 joints, each with a free motor diameter (scaled from the Omni+ reference), gear ratio and software
stiffness; a global free force threshold and approach velocity; 64 random configurations x 4 random directions
= 256 contact samples; torque requirement from gravity with a 1 kg payload and a safety factor of 1.5.

Prints: the build and solve times and iterations of one solve (target: solve < 5 s), a 20-point Pareto front of
worst-case impulse against total motor mass (median of 3 with the load; target: <= 12 s, no failed point), once
as one NLP on all samples (a builder of objective and bounds) and once on active sets (a builder that also takes
the samples, as studies build them: ``active_set="auto"`` from ``ACTIVE_SET_THRESHOLD`` samples), with the
difference of the two fronts at the same mass, and
the hypervolume of that front against pymoo's
NSGA-II (population 100, 200 generations) on the same problem and the same reference point (target: at least
NSGA-II's), and the sweep's warm start of its epsilon points (the first anchor's point and multipliers) against
a start from the anchor's point alone. Run: ``python benchmarks/optimize_panda.py`` (``--quick`` for 5 Pareto points and a short GA).

It first prints the solver construction with the derivatives assembled per sample against CasADi's
differentiation of the whole NLP (median of 3 repeats, fresh problems, with the load average before and after,
and the CPU time of construction and IPOPT, steadier under load; target: construction <= 0.8 s, one solve
including construction <= 1.5 s, the same optimum to 1e-8);
``--construction`` prints only that, ``--front`` only the front.

With ``--duty`` it prints only the problem size (variables, constraint rows, peak-torque rows kept) and the build
and solve times of one solve with the static (gravity) requirement and with a duty cycle through four via
configurations (about 200 samples, 1 kg payload) sizing peak torque, RMS torque and motor speed.

The reflected rotor inertia is placed on the finger (``reflected_inertia_in="finger"``: a stiff transmission,
the regime of the paper's geared A8): with the paper's arm model, where it acts in the reaction phase only, the
worst-case impulse of a Panda is set by its link inertia and the motors cannot trade against it, so the front
collapses to a point; the script reports that front's size too.
"""

from __future__ import annotations

import argparse
import os
import time

import numpy as np

import collision_reflex as cr
from collision_reflex.arm import Arm
from collision_reflex.optimize import hypervolume
from collision_reflex.optimize.epsilon import epsilon_grid, solve_anchor, solve_point
from collision_reflex.optimize.nsga import nsga2_front
from collision_reflex.optimize.pieces import built_problem


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="5 Pareto points, NSGA-II 40 x 30")
    parser.add_argument("--duty", action="store_true", help="only: one solve without and with a duty cycle")
    parser.add_argument("--construction", action="store_true", help="only: solver construction, both ways")
    parser.add_argument("--front", action="store_true", help="only: the 20-point front (median of 3)")
    args = parser.parse_args()
    points, population, generations = (5, 40, 30) if args.quick else (20, 100, 200)

    rng = np.random.default_rng(7)
    arm = Arm.from_example_robot_data("panda")
    kinematics = arm.kinematics(arm.sample_configurations(64, rng))
    directions = rng.normal(size=(4, 3))
    samples = cr.ContactSamples.grid(kinematics, directions)
    space = cr.DesignSpace(
        stator_diameter=(0.02, 0.15),
        gear_ratio=(1.0, 100.0),
        software_stiffness=(100.0, 1e4),
        threshold=(5.0, 40.0),
        approach_velocity=(0.05, 1.0),
    )
    constraints = cr.Constraints(payload=1.0, safety_factor=1.5, threshold_floor=5.0)

    def technology(place: str) -> cr.ActuatorTechnology:
        return cr.ActuatorTechnology(
            cr.reference_motor(), mechanical_stiffness=5000.0, reflected_inertia_in=place
        )

    def builder(place: str):
        def build(objective: str, bounded: tuple[str, ...]) -> cr.DesignProblem:
            return cr.build_problem(arm, samples, space, technology(place), objective, constraints, bounded)

        return build

    def sample_builder(place: str):
        """The builder taking the samples: ``pareto_front`` then solves on active sets (``active_set="auto"``)."""

        def build(objective: str, bounded: tuple[str, ...], chosen=samples) -> cr.DesignProblem:
            return cr.build_problem(arm, chosen, space, technology(place), objective, constraints, bounded)

        return build

    print(f"Panda: {arm.nv} joints, {samples.size} samples, {3 * arm.nv + 2} design variables")
    if args.duty:
        compare_duty_cycle(arm, samples, space, technology("finger"), constraints)
        return
    if args.front:
        full = timed_front(builder("finger"), points, "full NLP")
        active = timed_front(sample_builder("finger"), points, "active sets")
        compare_fronts(full, active)
        return
    compare_construction(builder("finger"))
    if args.construction:
        return

    started = time.perf_counter()
    problem = builder("finger")("worst_case_impulse", ())
    built = time.perf_counter() - started
    started = time.perf_counter()
    first = cr.solve(problem)
    first_total = time.perf_counter() - started
    second = cr.solve(
        problem
    )  # the solver is cached on the problem: a second solve excludes its construction
    print(
        f"one solve: build {built:.2f} s, first solve {first_total:.2f} s (IPOPT {first.solve_time:.2f} s, "
        f"{first.iterations} iterations, including solver construction), repeat solve {second.solve_time:.2f} s"
    )
    print(
        f"  worst-case impulse {first.objectives['worst_case_impulse']:.4f} N*s (NumPy path "
        f"{first.numpy_objectives['worst_case_impulse']:.4f}), motor mass {first.objectives['actuator_mass']:.3f} kg"
    )

    front = timed_front(builder("finger"), points, "full NLP")
    compare_fronts(front, timed_front(sample_builder("finger"), points, "active sets"))

    compare_warm_starts(builder("finger"), ("worst_case_impulse", "actuator_mass"), points)

    started = time.perf_counter()
    genetic = nsga2_front(problem, ("worst_case_impulse", "actuator_mass"), population, generations, seed=1)
    print(
        f"NSGA-II ({population} x {generations}): {len(genetic.values)} non-dominated designs, "
        f"{genetic.evaluations} evaluations in {time.perf_counter() - started:.1f} s"
    )

    ours = front.values()
    reference = 1.05 * np.maximum(ours.max(axis=0), genetic.values.max(axis=0))
    hv_ours, hv_genetic = hypervolume(ours, reference), hypervolume(genetic.values, reference)
    print(
        f"hypervolume (reference {reference[0]:.4f} N*s, {reference[1]:.4f} kg): epsilon-constraint "
        f"{hv_ours:.5f}, NSGA-II {hv_genetic:.5f}, ratio {hv_ours / hv_genetic:.3f}"
    )

    robot = cr.pareto_front(builder("robot"), ("worst_case_impulse", "actuator_mass"), points=5)
    spread = robot.values()
    print(
        f"paper's arm model (reflected inertia in the reaction only): {len(robot.points)} non-dominated "
        f"point(s); worst-case impulse {spread[:, 0].min():.4f}-{spread[:, 0].max():.4f} N*s"
    )


def timed_front(build, points: int, label: str, repeats: int = 3) -> cr.ParetoSet:
    """The front of worst-case impulse against actuator mass, fresh problems each time; median wall time.

    ``label`` names how ``build`` is solved: a builder of (objective, bounds) is one NLP on all samples; one
    that also takes the samples is solved on active sets (from ``ACTIVE_SET_THRESHOLD`` samples).
    """
    times, cpus, load = [], [], os.getloadavg()[0]
    for _ in range(repeats):
        built_problem.cache_clear()  # each repeat builds its problems and solvers
        started, cpu = time.perf_counter(), time.process_time()
        front = cr.pareto_front(build, ("worst_case_impulse", "actuator_mass"), points=points)
        times.append(time.perf_counter() - started)
        cpus.append(time.process_time() - cpu)
    iterations = [r.iterations for r in front.points]
    print(
        f"Pareto front, {label}: {len(front.points)} non-dominated of {points} requested, median "
        f"{np.median(times):.1f} s of {repeats} ({', '.join(f'{t:.1f}' for t in times)} s; CPU median "
        f"{np.median(cpus):.1f} s; load average {load:.2f} before, "
        f"{os.getloadavg()[0]:.2f} after; target <= 12 s); {len(front.failed)} failed "
        f"({', '.join(f.status for f in front.failed) or 'none'}), {len(front.dominated)} dominated, {front.merged} merged; "
        f"iterations per point: median {int(np.median(iterations))}, max {max(iterations)}, total "
        f"{sum(a.iterations for r in front.points + front.dominated for a in r.attempts)}"
    )
    return front


def compare_fronts(full: cr.ParetoSet, active: cr.ParetoSet) -> None:
    """How far the active-set front lies from the full NLP's: each active point's worst case against the full
    front's, interpolated at the same actuator mass (both fronts sorted by mass)."""
    a, b = full.values(), active.values()
    a, b = a[np.argsort(a[:, 1])], b[np.argsort(b[:, 1])]
    inside = (b[:, 1] >= a[0, 1]) & (b[:, 1] <= a[-1, 1])
    at_mass = np.interp(b[inside, 1], a[:, 1], a[:, 0])
    difference = (b[inside, 0] - at_mass) / at_mass
    print(
        f"  active-set front against the full NLP's at the same mass ({int(inside.sum())} points within its "
        f"mass range): worst case {difference.min():+.1e} to {difference.max():+.1e} relative"
    )


def compare_construction(build, repeats: int = 3) -> None:
    """Solver construction and one IPOPT run, derivatives per sample against the whole NLP's; medians."""
    from collision_reflex.optimize.blas import single_threaded_blas
    from collision_reflex.optimize.ipopt import DEFAULT_IPOPT_OPTIONS

    def timed(structural: bool) -> tuple[float, float, int, float, float]:
        """Construction and IPOPT wall times, iterations, objective, CPU time; everything freed on return, so
        that no earlier solver is destroyed inside the timed part (a whole-NLP solver takes a while)."""
        problem = build("worst_case_impulse", ())
        started, cpu = time.perf_counter(), time.process_time()
        solver = problem.solver(DEFAULT_IPOPT_OPTIONS, structural=structural)
        constructed = time.perf_counter() - started
        started = time.perf_counter()
        with single_threaded_blas():  # as solve() runs IPOPT
            solution = solver(
                x0=problem.x0, lbx=problem.lbx, ubx=problem.ubx, lbg=problem.lbg, ubg=problem.ubg, p=[]
            )
        solved, cpu = time.perf_counter() - started, time.process_time() - cpu
        return constructed, solved, int(solver.stats()["iter_count"]), float(solution["f"]), cpu

    load = os.getloadavg()[0]
    figures: dict[bool, list[tuple[float, float, int, float, float]]] = {True: [], False: []}
    for _ in range(repeats):
        for structural in (True, False):
            figures[structural].append(timed(structural))
    medians = {key: np.median(np.array(rows), axis=0) for key, rows in figures.items()}
    objectives = {key: figures[key][0][3] for key in figures}
    for structural, label in ((False, "whole NLP differentiated"), (True, "per-sample derivatives")):
        constructed, solved, iterations, _, cpu = medians[structural]
        print(
            f"{label}: construction {constructed:.2f} s, IPOPT {solved:.2f} s, one solve "
            f"{constructed + solved:.2f} s ({int(iterations)} iterations; median of {repeats}; CPU {cpu:.2f} s)"
        )
    difference = abs(objectives[True] - objectives[False]) / abs(objectives[False])
    print(
        f"  same optimum: objective {objectives[True]:.12g} vs {objectives[False]:.12g} ({difference:.1e} "
        f"relative); load average {load:.2f} before, {os.getloadavg()[0]:.2f} after"
    )


def compare_duty_cycle(
    arm: Arm,
    samples: cr.ContactSamples,
    space: cr.DesignSpace,
    technology: cr.ActuatorTechnology,
    static: cr.Constraints,
) -> None:
    """One solve with the static requirement and one with a duty cycle: problem size, build and solve times."""
    from collision_reflex.arm.duty_cycle import DutyCycle, Payload

    home = [0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785]
    via = [home, [0.8, -0.3, 0.2, -1.8, 0.3, 1.9, 0.4], [-0.6, 0.2, -0.3, -1.5, -0.4, 1.3, 1.2], home]
    cycle = DutyCycle.through_via_points(
        via,
        arm.joint_names,
        [2.0] * 4 + [2.5] * 3,
        [8.0] * 4 + [10.0] * 3,
        rate=73.0,
        dwell=0.1,
        payload=Payload(1.0),
    )
    duty = cr.Constraints(
        safety_factor=static.safety_factor, threshold_floor=static.threshold_floor, duty_cycle=cycle
    )
    for constraints in (static, duty):
        started = time.perf_counter()
        problem = cr.build_problem(arm, samples, space, technology, "worst_case_impulse", constraints)
        built = time.perf_counter() - started
        result = cr.solve(problem)
        peak_rows = sum(label.startswith("peak torque of") for label in problem.constraint_labels)
        print(
            f"{problem.requirement}: {problem.nlp['x'].shape[0]} variables, {len(problem.constraint_labels)} "
            f"constraint rows ({peak_rows} peak-torque rows kept), build {built:.2f} s, solve "
            f"{result.solve_time:.2f} s ({result.iterations} iterations); worst-case impulse "
            f"{result.objectives['worst_case_impulse']:.4f} N*s, motor mass {result.objectives['actuator_mass']:.3f} kg"
        )
        if constraints is duty:
            print(f"  duty cycle: {cycle.t.size} samples over {cycle.duration:.2f} s")


def compare_warm_starts(build, names: tuple[str, ...], points: int) -> None:
    """Solve the same epsilon points from the first anchor's point and multipliers (the sweep's policy) and from
    its point alone (the earlier policy); print time, iterations and agreement."""
    pieces = {name: solve_anchor(build, name, names, None) for name in names}
    anchors = {name: piece.result for name, piece in pieces.items()}
    grid = epsilon_grid(anchors, names[1:], points - len(names))
    start = pieces[names[0]].start
    primary = built_problem(build, names[0], names[1:])
    started = time.perf_counter()
    warm = [solve_point(build, names, e, start, None).result for e in grid]
    warm_time = time.perf_counter() - started
    started = time.perf_counter()
    cold = [cr.solve(primary, epsilon=epsilon, x0=start.x) for epsilon in grid]
    cold_time = time.perf_counter() - started
    difference = max(
        abs(a.numpy_objectives[n] - b.numpy_objectives[n]) / abs(b.numpy_objectives[n])
        for a, b in zip(warm, cold, strict=True)
        for n in names
    )
    print(
        f"epsilon points ({len(grid)}): from the anchor's point and multipliers (adaptive barrier) "
        f"{warm_time:.1f} s, {sum(r.iterations for r in warm)} iterations; from its point alone (monotone) "
        f"{cold_time:.1f} s, {sum(r.iterations for r in cold)} iterations; objectives agree to {difference:.1e} "
        f"(relative); load average {os.getloadavg()[0]:.2f}"
    )


if __name__ == "__main__":
    main()
