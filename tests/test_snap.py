"""Snapping a continuous optimum to catalogue motors: against brute-force enumeration, and in a study run."""

from __future__ import annotations

import dataclasses
import itertools
import json
import re
import shutil
from pathlib import Path

import numpy as np
import pytest

import collision_reflex as cr
from collision_reflex.arm import Arm
from collision_reflex.hardware.gearboxes import load_gearbox_catalogue
from collision_reflex.optimize import catalogue_search as searching
from collision_reflex.optimize import snap as snapping
from collision_reflex.optimize.active_set_result import solve_method
from collision_reflex.optimize.candidates import gearbox_options, joint_candidates, motor_distance
from collision_reflex.optimize.catalogue_search import objective_value, solve_parts
from collision_reflex.optimize.dominance import MERGE_TOLERANCE
from collision_reflex.optimize.objectives import TIE_BREAK_WEIGHT
from collision_reflex.optimize.parts import (
    catalogue_problem,
    covering_gear_ratios,
    evaluate_parts,
    matched_gear_ratio,
)
from collision_reflex.optimize.snap import snap_to_catalogue
from collision_reflex.optimize.solve import warm_start

pytestmark = pytest.mark.xdist_group("test_snap")  # one pytest-xdist worker: set-ups made once

ROOT = Path(__file__).resolve().parents[1]
TWO_LINK = ROOT / "designs" / "planar_two_link.urdf"
TWO_LINK_STUDY = ROOT / "studies" / "two_link_paper.yaml"
SOLVER_TOLERANCE = MERGE_TOLERANCE
"""Two solves of one problem from different starts agree to ~1e-7 relative (IPOPT tol 1e-8); 1e-5 is ten
times the anchor slack, the tolerance the Pareto sweep uses for "the same design"."""


OBJECTIVE = {"worst_case_impulse": 1.0, "actuator_mass": 0.05}
"""The worst case with the motors' mass: every joint's part then matters (the worst case alone hardly depends
on the proximal motor, and its pairs tie)."""


def _catalogue() -> list[cr.Motor]:
    """Six motors of different sizes, not on one scaling law (rotor inertia and mass perturbed)."""
    reference = cr.reference_motor()
    sizes = [(0.03, 0.010), (0.04, 0.012), (0.05, 0.015), (0.07, 0.012), (0.09, 0.020), (0.11, 0.030)]
    motors = []
    for i, (diameter, stack) in enumerate(sizes):
        scaled = reference.scaled(diameter, stack)
        motors.append(
            cr.Motor(
                f"M{i}",
                diameter,
                stack,
                scaled.rotor_inertia * (1 + 0.15 * i),
                scaled.peak_torque,
                scaled.continuous_torque,
                scaled.mass * (1 - 0.06 * i),
                source="test motor",
            )
        )
    return motors


def _two_link_inputs() -> tuple[cr.DesignSpace, cr.ActuatorTechnology, cr.Constraints]:
    """The two-link snap problems' design space, technology (scaled reference motor) and given torques."""
    space = cr.DesignSpace(
        stator_diameter=(0.02, 0.12),
        gear_ratio=(1, 50),
        software_stiffness=(5, 500),
        threshold=(1, 10),
        approach_velocity=(0.05, 1.0),
    )
    technology = cr.ActuatorTechnology(cr.reference_motor(), 1000.0)
    return space, technology, cr.Constraints(torque_required=[2.0, 1.0], threshold_floor=0.5)


def _two_link_samples(arm: Arm, configurations: int, directions: int, seed: int) -> cr.ContactSamples:
    """Random configurations (seeded) of the two-link arm, each with evenly spaced contact directions."""
    kinematics = arm.kinematics(arm.sample_configurations(configurations, np.random.default_rng(seed)))
    angles = np.linspace(0, 2 * np.pi, directions, endpoint=False) + 0.3
    return cr.ContactSamples.grid(kinematics, np.c_[np.cos(angles), np.sin(angles)])


def two_link_problem(**space_changes) -> tuple[Arm, cr.DesignProblem]:
    """The two-link snap problem (3 configurations x 6 directions), its design space changed as given."""
    arm = Arm.from_urdf(TWO_LINK, "tip")
    samples = _two_link_samples(arm, 3, 6, seed=0)
    space, technology, constraints = _two_link_inputs()
    space = dataclasses.replace(space, **space_changes)
    return arm, cr.build_problem(arm, samples, space, technology, OBJECTIVE, constraints)


@pytest.fixture(scope="module")
def two_link():
    arm, problem = two_link_problem()
    return arm, problem, cr.solve(problem, starts=4)


@pytest.fixture(scope="module")
def brute_force(two_link):
    """Every pair of the catalogue solved on its own: built directly, multi-started from the default start."""
    arm, problem, _ = two_link
    values = {}
    for first, second in itertools.product(_catalogue(), repeat=2):
        space = cr.DesignSpace(
            stator_diameter=[first.stator_diameter, second.stator_diameter],
            stack_length=[first.stack_length, second.stack_length],
            gear_ratio=(1, 50),
            software_stiffness=(5, 500),
            threshold=(1, 10),
            approach_velocity=(0.05, 1.0),
        )
        technology = cr.ActuatorTechnology((first, second), 1000.0)
        built = cr.build_problem(arm, problem.samples, space, technology, OBJECTIVE, problem.constraints)
        result = cr.solve(built, starts=3)
        values[(first.name, second.name)] = objective_value(problem, result.numpy_objectives)
    return values


@pytest.fixture(scope="module")
def exact(two_link):
    arm, problem, optimum = two_link
    return snap_to_catalogue(problem, optimum, _catalogue(), arm=arm, candidates=6, max_combinations=64)


def _chosen_value(problem, design) -> float:
    return objective_value(problem, design.result.numpy_objectives)


def test_snapping_a_two_joint_problem_equals_full_enumeration(two_link, brute_force, exact):
    _, problem, _ = two_link
    assert exact.method == "exact: enumerated 36 combinations"
    assert len(exact.tried) == 36
    best = min(brute_force.values())
    assert _chosen_value(problem, exact) == pytest.approx(best, rel=SOLVER_TOLERANCE)
    # The pair found is one of the best pairs (pairs within the solver tolerance are ties).
    ties = {pair for pair, value in brute_force.items() if value <= best * (1 + SOLVER_TOLERANCE)}
    assert tuple(p.motor.name for p in exact.parts) in ties
    # The worst pair is far worse: the enumeration distinguishes the parts.
    assert max(brute_force.values()) > 1.5 * best


def test_the_catalogue_design_is_the_continuous_optimum_with_more_constraints(two_link, exact):
    _, problem, optimum = two_link
    continuous = objective_value(problem, optimum.numpy_objectives)
    assert _chosen_value(problem, exact) >= continuous * (1 - SOLVER_TOLERANCE)
    for trial in exact.tried:
        assert trial.objective is None or trial.objective >= continuous * (1 - SOLVER_TOLERANCE)
    # Every objective compared, absolute and relative, against the continuous optimum's own numbers.
    for name, value in exact.objectives.items():
        assert exact.difference[name] == pytest.approx(value - optimum.numpy_objectives[name], abs=1e-15)
        assert exact.relative_difference[name] == pytest.approx(
            exact.difference[name] / optimum.numpy_objectives[name]
        )


def test_a_catalogue_motor_at_the_optimum_size_reproduces_the_continuous_optimum(two_link):
    # The optimum's own (scaled) motors, as catalogue parts: fixing them changes nothing.
    arm, problem, optimum = two_link
    design = optimum.design
    own = [
        problem.technology.motors[0].scaled(d, s)
        for d, s in zip(design.stator_diameter, design.stack_length, strict=True)
    ]
    snapped = snap_to_catalogue(problem, optimum, [*own, *_catalogue()], arm=arm, candidates=1)
    assert [p.motor.name for p in snapped.parts] == [m.name for m in own]
    assert _chosen_value(problem, snapped) == pytest.approx(
        objective_value(problem, optimum.numpy_objectives), rel=1e-6
    )


def test_the_heuristic_is_never_worse_than_the_nearest_parts(two_link, exact):
    arm, problem, optimum = two_link
    heuristic = snap_to_catalogue(problem, optimum, _catalogue(), arm=arm, candidates=6, max_combinations=1)
    assert heuristic.method.startswith("heuristic: coordinate descent")
    assert len(heuristic.tried) < 36
    nearest = solve_parts(problem, optimum, [j.parts[0] for j in heuristic.joints], arm)
    assert _chosen_value(problem, heuristic) <= objective_value(problem, nearest.numpy_objectives) * (
        1 + SOLVER_TOLERANCE
    )
    # On two joints, each pass tries every part of each joint: it finds the enumeration's best here.
    assert _chosen_value(problem, heuristic) == pytest.approx(
        _chosen_value(problem, exact), rel=SOLVER_TOLERANCE
    )


def test_candidates_are_the_nearest_within_bounds(two_link):
    _, problem, optimum = two_link
    joints = joint_candidates(problem, optimum, _catalogue(), candidates=2)
    design = optimum.design
    for j, joint in enumerate(joints):
        distances = sorted(
            motor_distance(m, design.motor_peak_torque[j], design.rotor_inertia[j]) for m in _catalogue()
        )
        assert [p.distance for p in joint.parts] == pytest.approx(distances[:2])


def test_a_catalogue_of_small_motors_for_a_big_joint_says_what_the_nearest_misses(two_link):
    arm, problem, _ = two_link
    big = cr.Constraints(torque_required=[20.0, 1.0], threshold_floor=0.5)
    needy = cr.build_problem(arm, problem.samples, problem.space, problem.technology, OBJECTIVE, big)
    optimum = cr.solve(needy, starts=2)
    small = [
        cr.Motor("tiny", 0.022, 0.01, 1e-7, 0.05, 0.02, 0.02, source="test motor"),
        cr.Motor("small", 0.025, 0.01, 2e-7, 0.08, 0.03, 0.03, source="test motor"),
    ]
    snapped = snap_to_catalogue(needy, optimum, small, arm=arm)
    assert not snapped.found and snapped.parts is None and snapped.result is None
    joint1 = snapped.joints[0]
    assert joint1.parts == () and joint1.nearest == "small"
    # 0.08 N*m x the largest ratio 50 = 4 N*m of the 20 N*m required: 16 N*m short.
    assert re.search(r"= 4 N\*m, short of the required 20 N\*m by 16 N\*m", " ".join(joint1.misses))
    assert any("joint1: no catalogue part within bounds; the nearest, small," in w for w in snapped.warnings)
    # The optimum's motor is far beyond the catalogue's small motors: warned.
    assert optimum.design.motor_peak_torque[0] > 1.1 * 0.08
    assert joint1.warning is not None and "outside the range the catalogue covers" in joint1.warning
    # The second joint (1 N*m) is covered by the small motors: no warning of its own.
    assert snapped.joints[1].parts


def test_a_motor_beyond_the_diameter_bound_is_reported_with_the_excess(two_link):
    arm, problem, optimum = two_link
    wide = [cr.Motor("too wide", 0.15, 0.03, 5e-4, 9.0, 4.0, 1.5, source="test motor")]
    snapped = snap_to_catalogue(problem, optimum, wide, arm=arm)
    for joint in snapped.joints:
        assert joint.nearest == "too wide"
        assert joint.misses == ("stator diameter 150 mm above the upper bound 120 mm by 30 mm",)


def test_bad_settings_are_refused(two_link):
    arm, problem, optimum = two_link
    with pytest.raises(cr.InvalidParameter, match="candidates"):
        snap_to_catalogue(problem, optimum, _catalogue(), arm=arm, candidates=0)
    with pytest.raises(cr.InvalidParameter, match="max_combinations"):
        snap_to_catalogue(problem, optimum, _catalogue(), arm=arm, max_combinations=0)
    with pytest.raises(cr.InvalidParameter, match="motors"):
        snap_to_catalogue(problem, optimum, [], arm=arm)


def test_ctrl_c_interrupts_the_snap(two_link, monkeypatch):
    arm, problem, optimum = two_link

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(searching, "solve_parts", interrupted)
    with pytest.raises(KeyboardInterrupt):
        snap_to_catalogue(problem, optimum, _catalogue(), arm=arm)


def test_a_study_run_snaps_reports_and_resumes_without_redoing_it(smoke_runs, tmp_path, monkeypatch):
    folder = tmp_path / "out"
    shutil.copytree(smoke_runs[TWO_LINK_STUDY.stem], folder)  # a finished smoke run
    first = json.loads((folder / "run.json").read_text())  # its pieces of work: computed and reused
    designs = json.loads((folder / "designs.json").read_text())
    catalogue = designs["catalogue"]
    assert catalogue["method"].startswith("exact: enumerated")
    assert catalogue["design"] is not None and catalogue["snapped"] == designs["recommended"]["source"]
    # Every contact sample of the two-link study loads both joints: every design variable is decided.
    assert catalogue["design"]["undecided"] == [] and designs["recommended"]["undecided"] == []
    gearboxes = load_gearbox_catalogue()
    for joint in catalogue["joints"]:
        assert joint["motor"] in cr.hardware.load_catalogue() and joint["source"]
        # The study's gearboxes are scaled units: the catalogue design takes a unit of the catalogue, at a
        # ratio it is sold with.
        assert joint["gearbox"] in gearboxes and joint["gear_ratio"] in gearboxes[joint["gearbox"]].ratios
    assert len(catalogue["pareto"]) == len(designs["pareto"]["points"])
    report = (folder / "report.html").read_text()
    assert 'id="catalogue"' in report and 'id="catalogue-objectives"' in report
    # The solver table says how each design was solved (the two-link study is small: all samples at once).
    samples = len(designs["chosen"]["impulses"])
    solved = f'<td class="text">full NLP: all {samples} samples</td>'
    assert f'<td class="text">catalogue design</td>{solved}' in report
    assert report.count(solved) == 2 + len(designs["pareto"]["points"])  # optimum, Pareto designs, catalogue
    header = (folder / "pareto.csv").read_text().splitlines()[0]
    assert "catalogue_part[joint1]" in header and "catalogue_worst_case_impulse [N*s]" in header
    assert (folder / "points" / "catalogue.json").exists()
    (sentence,) = [line for line in designs["verdict"] if line.startswith("Build from catalogue parts")]
    for joint in catalogue["joints"]:
        assert joint["joint"] in sentence and joint["part"] in sentence
        assert joint["part"].endswith(f"at N = {joint['gear_ratio']:g}")
    change = 100 * catalogue["relative_difference"]["worst_case_impulse"]
    assert f"worst case impulse +{change:.3g} %" in sentence and sentence in report

    def not_again(*args, **kwargs):
        raise AssertionError("the snap was redone on resume")

    monkeypatch.setattr(snapping, "snap_to_catalogue", not_again)
    again = cr.run_study(TWO_LINK_STUDY, folder, quiet=True, figures=False, smoke=True, executor="serial")
    assert again.resumed and again.computed == 0 and again.reused == first["computed"] + first["reused"]
    assert json.loads((folder / "designs.json").read_text())["catalogue"] == catalogue


def _harmonic(
    name: str,
    ratios: tuple[float, ...],
    peak: float,
    mass: float,
    continuous: bool = False,
    inertias: tuple[float, ...] = (),
):
    """A test gearbox; ``inertias``: its input inertia at each of ``ratios`` [kg m^2] (none: 1e-6 at every ratio)."""
    from collision_reflex.hardware.gearboxes import CatalogueGearbox, RatioFigures

    return CatalogueGearbox(
        name=name,
        kind="harmonic",
        ratios=ratios,
        continuous_ratio=continuous,
        rated_torque=peak / 2,
        peak_torque=peak,
        mass=mass,
        inertia=max(inertias, default=1e-6),  # the least favourable, as the catalogue loader makes it
        source="test figures",
        efficiency=0.8,
        per_ratio=tuple(
            RatioFigures(r, peak / 2, peak, None, j) for r, j in zip(ratios, inertias, strict=True)
        )
        if inertias
        else (),
    )


def test_a_gearbox_of_discrete_ratios_gets_an_offered_ratio(two_link):
    arm, problem, _ = two_link
    geared = cr.ActuatorTechnology(
        cr.reference_motor(),
        1000.0,
        gearboxes=(
            _harmonic("HD", (5.0, 10.0, 20.0, 40.0), 100.0, 0.3, inertias=(4e-6, 3e-6, 2e-6, 1e-6)),
            None,
        ),
    )
    inertia_at = {5.0: 4e-6, 10.0: 3e-6, 20.0: 2e-6, 40.0: 1e-6}
    # The continuous optimum may use any ratio of the gearbox's range 5-40; the catalogue design an offered one.
    continuous = dataclasses.replace(
        geared.gearboxes[0], continuous_ratio=True, ratios=(5.0, 40.0), per_ratio=()
    )
    technology = dataclasses.replace(geared, gearboxes=(continuous, None))
    built = cr.build_problem(arm, problem.samples, problem.space, technology, OBJECTIVE, problem.constraints)
    optimum = cr.solve(built, starts=2)
    discrete = cr.build_problem(arm, problem.samples, problem.space, geared, OBJECTIVE, problem.constraints)
    snapped = snap_to_catalogue(discrete, optimum, _catalogue(), arm=arm, candidates=2)
    offered = np.array([5.0, 10.0, 20.0, 40.0])
    chosen = set()
    for part in snapped.joints[0].parts:
        # The offered ratios around the one that gives this motor the continuous peak output torque.
        matched = optimum.design.peak_torque[0] / part.motor.peak_torque
        bracket = {
            offered[offered <= matched].max(initial=5.0),
            offered[offered >= matched].min(initial=40.0),
        }
        assert part.gear_ratio.is_fixed and part.gear_ratio.lower in bracket
        assert part.gearbox.inertia == inertia_at[part.gear_ratio.lower]  # the gearbox as sold at its ratio
        chosen.add(part.gear_ratio.lower)
    design = snapped.result.design
    assert design.gear_ratio[0] in chosen
    assert design.gearbox[0] == "HD"
    # Charged the inertia at its own ratio: N^2 (J_m + J_g(N)).
    assert design.gearbox_inertia[0] == inertia_at[design.gear_ratio[0]]
    expected = design.gear_ratio[0] ** 2 * (design.rotor_inertia[0] + inertia_at[design.gear_ratio[0]])
    assert design.reflected_inertia[0] == pytest.approx(expected, rel=1e-12)


def test_a_gearbox_given_by_its_figures_snaps_to_catalogue_gearboxes_of_its_kind(two_link):
    arm, problem, _ = two_link
    own = _harmonic("study figures", (1.0, 50.0), 40.0, 0.5, continuous=True)
    technology = cr.ActuatorTechnology(cr.reference_motor(), 1000.0, gearboxes=(own, None))
    built = cr.build_problem(arm, problem.samples, problem.space, technology, OBJECTIVE, problem.constraints)
    optimum = cr.solve(built, starts=2)
    catalogue = {
        g.name: g
        for g in (
            _harmonic("HD-light", (1.0, 50.0), 30.0, 0.3, continuous=True),
            _harmonic("HD-heavy", (1.0, 50.0), 60.0, 1.2, continuous=True),
            _harmonic("HD-weak", (1.0, 50.0), 1.0, 0.1, continuous=True),  # below the 2 N*m required
            dataclasses.replace(
                _harmonic("planetary", (1.0, 50.0), 40.0, 0.5, continuous=True), kind="planetary"
            ),
        )
    }
    snapped = snap_to_catalogue(built, optimum, _catalogue(), arm=arm, gearboxes=catalogue, candidates=2)
    used = {p.gearbox.name for p in snapped.joints[0].parts}
    assert used == {"HD-light", "HD-heavy"}  # the weak one misses the requirement, the planetary the kind
    assert all(p.gearbox is None for p in snapped.joints[1].parts)
    # Lighter gearbox, same motor: less mass at equal torque, so the mass-weighted objective prefers it.
    assert snapped.parts[0].gearbox.name == "HD-light"
    without = snap_to_catalogue(built, optimum, _catalogue(), arm=arm, candidates=2)
    assert {p.gearbox.name for p in without.joints[0].parts} == {"study figures"}
    assert not without.parts[0].gearbox_from_catalogue


def test_a_quick_snap_evaluates_what_a_re_solve_finds(two_link, exact):
    # Evaluated at the re-solved design's own variables, the parts give its objectives (one model, two paths).
    _, problem, _ = two_link
    evaluated = evaluate_parts(problem, exact.result.design, exact.parts)
    assert evaluated.feasible
    for name, value in exact.result.numpy_objectives.items():
        assert evaluated.objectives[name] == pytest.approx(value, rel=1e-9)
    np.testing.assert_allclose(evaluated.design.gear_ratio, exact.result.design.gear_ratio, rtol=1e-9)


def _study_with(tmp_path, catalogue: str) -> Path:
    text = TWO_LINK_STUDY.read_text().replace("../designs/", f"{ROOT / 'designs'}/")
    study = tmp_path / "study.yaml"
    study.write_text(text + f"catalogue: {catalogue}\n")
    return study


def test_a_bad_catalogue_section_is_refused_at_its_line_and_nothing_is_written(tmp_path, capsys):
    from collision_reflex.cli import main

    study = _study_with(tmp_path, "{candidates: 0}")
    assert main(["run", str(study), "--out", str(tmp_path / "out"), "--quiet", "--smoke"]) == 2
    assert re.search(r"study\.yaml:\d+:\d+: catalogue\.candidates: found 0", capsys.readouterr().err)
    study = _study_with(tmp_path, "{motors: missing.yaml}")
    assert main(["run", str(study), "--out", str(tmp_path / "out"), "--quiet", "--smoke"]) == 2
    assert "missing.yaml: cannot read the file" in capsys.readouterr().err
    assert not (tmp_path / "out").exists()


def test_a_changed_catalogue_is_snapped_again_on_resume(tmp_path):
    motors = tmp_path / "motors.yaml"
    motors.write_text((ROOT / "designs" / "motors.yaml").read_text())
    study = _study_with(tmp_path, "{motors: motors.yaml}")
    folder = tmp_path / "out"
    cr.run_study(study, folder, quiet=True, figures=False, smoke=True, executor="serial")
    first = json.loads((folder / "points" / "catalogue.json").read_text())
    assert cr.run_study(study, folder, quiet=True, figures=False, smoke=True, executor="serial").computed == 0
    motors.write_text(motors.read_text() + "# edited\n")  # the same parts, another file: snapped again
    again = cr.run_study(study, folder, quiet=True, figures=False, smoke=True, executor="serial")
    assert again.computed == 1
    second = json.loads((folder / "points" / "catalogue.json").read_text())
    assert second["key"] != first["key"] and second["joints"] == first["joints"]


def test_a_catalogue_with_no_part_within_bounds_is_reported_in_the_files(tmp_path):
    motors = tmp_path / "tiny.yaml"
    motors.write_text(
        "motors:\n"
        "  tiny:\n"
        "    stator_diameter: 20 mm\n"
        "    stack_length: 5 mm\n"
        "    rotor_inertia: 1.0e-7 kg*m^2\n"
        "    peak_torque: 0.01 N*m\n"
        "    continuous_torque: 0.004 N*m\n"
        "    mass: 0.01 kg\n"
        "    source: a test motor\n"
        "    estimates: {mass: a guess for the test}\n"
    )
    folder = tmp_path / "out"
    cr.run_study(
        _study_with(tmp_path, "{motors: tiny.yaml}"), folder, quiet=True, smoke=True, executor="serial"
    )
    catalogue = json.loads((folder / "designs.json").read_text())["catalogue"]
    # 0.01 N*m x the largest ratio 100 = 1 N*m of the 1.3 N*m every joint must give: 0.3 N*m short.
    assert catalogue["design"] is None and catalogue["method"].startswith("none: joint1: no catalogue part")
    for joint in catalogue["joints"]:
        assert joint["part"] is None and joint["nearest"] == "tiny"
        assert joint["misses"] == [
            "peak torque 0.01 N*m x the largest gear ratio 100 = 1 N*m, short of the required 1.3 N*m by 0.3 N*m"
        ]
    report = (folder / "report.html").read_text()
    assert (
        'id="catalogue-none"' in report and "no catalogue part within bounds; nearest tiny misses" in report
    )
    import pandas as pd

    table = pd.read_csv(folder / "pareto.csv")
    assert set(table["catalogue_part[joint1]"]) == {"none within bounds"}
    assert not table["catalogue_feasible"].any()


@pytest.fixture(scope="module")
def many_samples():
    """The two-link problem on 96 samples, its optimum found on an active set of a few of them."""
    from collision_reflex.optimize.active_set import solve_active_set

    arm = Arm.from_urdf(TWO_LINK, "tip")
    samples = _two_link_samples(arm, 12, 8, seed=1)
    space, technology, constraints = _two_link_inputs()

    def build(subset):
        return cr.build_problem(arm, subset, space, technology, OBJECTIVE, constraints)

    problem = build(samples)
    optimum = solve_active_set(build, samples, start_samples=8, full=problem)
    return arm, problem, optimum


def test_the_snap_on_active_sets_chooses_what_the_full_nlp_chooses(many_samples):
    arm, problem, optimum = many_samples
    assert optimum.active_samples.size < problem.samples.size / 2  # the subset is a real one
    snaps = {
        choice: snap_to_catalogue(problem, optimum, _catalogue(), arm=arm, active_set=choice)
        for choice in ("never", "always")
    }
    full, active = snaps["never"], snaps["always"]
    assert [p.label for p in active.parts] == [p.label for p in full.parts]
    # Within the tie-break's reach (below): the active sets' re-solves start warm from the optimum's last NLP,
    # the full NLP's cold (the optimum has no multipliers of it), and land 1.2e-5 apart here (the active set's
    # lower, its worst case too: 1.1e-5).
    reach = TIE_BREAK_WEIGHT * 0.05
    assert _chosen_value(problem, active) == pytest.approx(_chosen_value(problem, full), rel=reach)
    # The worst case is exact on the active set: every sample's impulse at the design found, not the subset's.
    assert active.objectives["worst_case_impulse"] == pytest.approx(
        full.objectives["worst_case_impulse"], rel=reach
    )
    assert solve_method(active.result)[0] == "active set"
    assert solve_method(active.result)[1] < problem.samples.size
    assert solve_method(full.result) == ("full NLP", problem.samples.size)
    # Every combination tried: the same feasibility, the same value to the tie-break's reach. On an active set
    # the tie-break pulls on the active samples' mean, not every sample's: between designs of nearly equal worst
    # case it moves the worst case by about TIE_BREAK_WEIGHT (1e-3) times the few per cent the mean changes
    # (measured here: up to 1.4e-5 relative, of either sign, the mean up to 0.4 %).
    for a, f in zip(active.tried, full.tried, strict=True):
        assert a.parts == f.parts
        assert (a.objective is None) == (f.objective is None)
        if a.objective is not None:
            assert a.objective == pytest.approx(f.objective, rel=reach)


def test_a_bad_active_set_choice_is_refused(two_link):
    arm, problem, optimum = two_link
    with pytest.raises(cr.InvalidParameter, match="active_set"):
        snap_to_catalogue(problem, optimum, _catalogue(), arm=arm, active_set="sometimes")


def test_a_study_on_active_sets_snaps_on_them_and_through_a_process_pool_alike(tmp_path):
    text = TWO_LINK_STUDY.read_text().replace("../designs/", f"{ROOT / 'designs'}/")
    study = tmp_path / "study.yaml"
    study.write_text(text + "optimizer: {active_set: always}\n")
    serial, pool = tmp_path / "serial", tmp_path / "pool"
    cr.run_study(study, serial, quiet=True, figures=False, smoke=True, executor="serial")
    cr.run_study(study, pool, quiet=True, figures=False, smoke=True, executor="processes", workers=2)
    records = [json.loads((folder / "designs.json").read_text()) for folder in (serial, pool)]
    entries = [record["catalogue"] for record in records]
    assert entries[0] == entries[1]
    solver = entries[0]["design"]["solver"]
    assert solver["method"] == "active set"
    assert 0 < solver["active_samples"] <= len(entries[0]["design"]["impulses"])
    # Every design of the front too: the same numbers through either executor, on active sets.
    designs = [[record["chosen"], *record["pareto"]["points"]] for record in records]
    assert all(design["solver"]["method"] == "active set" for design in designs[0])
    assert _without_times(designs[1]) == _without_times(designs[0])


def _without_times(value):
    """A record with its wall times dropped (they differ between runs; every number else must not)."""
    if isinstance(value, dict):
        return {k: _without_times(v) for k, v in value.items() if k not in ("solve_time", "build_time")}
    if isinstance(value, list):
        return [_without_times(v) for v in value]
    return value


@pytest.fixture(scope="module")
def cycle_sized(two_link):
    """The two-link problem sized by a loaded duty cycle (peak and RMS torques grow with the motors' masses and
    inertias), its optimum, and the test catalogue with maximum speeds (the cycle's speed rows need them)."""
    from collision_reflex.arm.duty_cycle import DutyCycle, Payload

    arm, problem, _ = two_link
    cycle = DutyCycle.through_via_points(
        [[0.0, 0.0], [1.2, -1.0], [0.3, 0.6]],
        arm.joint_names,
        [15.0, 20.0],
        [80.0, 100.0],
        rate=100.0,
        dwell=0.05,
        payload=Payload(2.0),
    )
    constraints = cr.Constraints(safety_factor=1.2, duty_cycle=cycle)
    built = cr.build_problem(arm, problem.samples, problem.space, problem.technology, OBJECTIVE, constraints)
    reference = cr.reference_motor()
    catalogue = [
        dataclasses.replace(m, max_speed=reference.scaled(m.stator_diameter, m.stack_length).max_speed)
        for m in _catalogue()
    ]
    return arm, built, cr.solve(built, starts=2), catalogue


def _torque_shortfalls(problem, x):
    """How far each peak- and RMS-torque row of ``problem`` at ``x`` is outside its bounds (0 when within)."""
    import casadi as ca

    g = ca.Function("g", [problem.nlp["x"], problem.nlp["p"]], [problem.nlp["g"]])(x, problem.parameters())
    rows = [i for i, label in enumerate(problem.constraint_labels) if label.startswith(("peak", "RMS"))]
    values = np.asarray(g).ravel()[rows]
    return np.maximum(np.maximum(problem.lbg[rows] - values, values - problem.ubg[rows]), 0.0)


def test_the_warm_start_meets_the_torque_requirement_of_the_parts_own_masses(cycle_sized):
    # The heaviest motor at both joints: at the matched ratios (the continuous peak torques) its mass is not
    # covered; at the covering ratios every peak-torque row of the parts' own problem holds, as CasADi builds it.
    arm, problem, optimum, catalogue = cycle_sized
    heavy = catalogue[-1]
    joints = joint_candidates(problem, optimum, [heavy], candidates=1)
    parts = [j.parts[0] for j in joints]
    built = catalogue_problem(problem, parts, arm)
    cold = searching._parts_start(problem, optimum, parts, built, raised=False)
    warm = searching._parts_start(problem, optimum, parts, built, raised=True)
    assert _torque_shortfalls(built, cold).max() > 1e-2  # the guarded case: the matched ratios fall short
    # Within what REQUIREMENT_PASSES fixed-point passes settle (the RMS row grows with N^2 J: 2e-5 here).
    assert _torque_shortfalls(built, warm).max() <= 1e-4
    matched = [matched_gear_ratio(p, optimum.design, j) for j, p in enumerate(parts)]
    assert np.all(covering_gear_ratios(problem, optimum.design, parts) >= np.array(matched))


def test_the_warm_start_carries_the_multipliers_over_by_variable_and_row(cycle_sized):
    arm, problem, optimum, catalogue = cycle_sized
    joints = joint_candidates(problem, optimum, catalogue, candidates=2)
    parts = [j.parts[1] for j in joints]
    built = catalogue_problem(problem, parts, arm)
    x0 = searching._parts_start(problem, optimum, parts, built, raised=True)
    start = warm_start(problem, built, optimum, x0)
    lam_x, lam_g = start.multipliers
    np.testing.assert_array_equal(start.x, x0)
    bounds, rows = optimum.multipliers
    for name, indices in built.layout.slices.items():  # every variable free in both keeps its multiplier
        for i, k in zip(indices, problem.layout.slices[name], strict=True):
            if i is not None:
                assert lam_x[i] == (bounds[k] if k is not None else 0.0)
    np.testing.assert_array_equal(lam_x[built.layout.size :], bounds[problem.layout.size :])
    own = dict(zip(problem.constraint_labels, rows, strict=True))
    assert set(built.constraint_labels) <= set(own)  # the catalogue problem drops rows, never adds one
    assert list(lam_g) == [own[label] for label in built.constraint_labels]


def test_a_warm_re_solve_finds_the_cold_one_in_fewer_iterations(cycle_sized):
    # Every combination of two candidates per joint: the warm start reaches the cold start's optimum (or a
    # better one) in fewer iterations in total.
    arm, problem, optimum, catalogue = cycle_sized
    joints = joint_candidates(problem, optimum, catalogue, candidates=2)
    warm_iterations = cold_iterations = 0
    for parts in itertools.product(*(j.parts for j in joints)):
        warm = solve_parts(problem, optimum, parts, arm)
        cold = solve_parts(problem, optimum, parts, arm, warm=False)
        assert objective_value(problem, warm.numpy_objectives) <= objective_value(
            problem, cold.numpy_objectives
        ) * (1 + SOLVER_TOLERANCE)
        warm_iterations, cold_iterations = (
            warm_iterations + warm.iterations,
            cold_iterations + cold.iterations,
        )
    assert warm_iterations < cold_iterations


def test_the_chosen_parts_are_never_worse_than_their_cold_re_solve(two_link, exact):
    arm, problem, optimum = two_link
    cold = solve_parts(problem, optimum, exact.parts, arm, warm=False)
    assert _chosen_value(problem, exact) <= objective_value(problem, cold.numpy_objectives)


def test_a_warm_re_solve_on_active_sets_finds_the_cold_one_in_fewer_iterations(many_samples):
    # On active sets the first round holds the optimum's last active samples and starts from its last NLP's
    # point and multipliers: every combination of two candidates per joint reaches the cold start's optimum
    # (or a better one), in fewer iterations in total.
    arm, problem, optimum = many_samples
    joints = joint_candidates(problem, optimum, _catalogue(), candidates=2)
    warm_iterations = cold_iterations = 0
    for parts in itertools.product(*(j.parts for j in joints)):
        warm = solve_parts(problem, optimum, parts, arm, active_set="always")
        cold = solve_parts(problem, optimum, parts, arm, active_set="always", warm=False)
        assert solve_method(warm)[0] == solve_method(cold)[0] == "active set"
        assert warm.rounds[0].samples == optimum.active_samples.size
        assert objective_value(problem, warm.numpy_objectives) <= objective_value(
            problem, cold.numpy_objectives
        ) * (1 + SOLVER_TOLERANCE)
        warm_iterations += warm.iterations
        cold_iterations += cold.iterations
    assert warm_iterations < cold_iterations


@pytest.mark.parametrize(
    ("gain", "moved"), [(0.3 * MERGE_TOLERANCE, False), (3 * MERGE_TOLERANCE, True)], ids=["repeat", "real"]
)
def test_the_descent_moves_only_for_a_gain_beyond_what_re_solving_repeats(monkeypatch, gain, moved):
    # Two joints of two parts each, the re-solved values by combination: from (0, 0), joint 0's second part
    # gains 10 %, then joint 1's second part gains ``gain``. A move makes another pass solve a new combination.
    from types import SimpleNamespace

    value = {(0, 0): 1.0, (1, 0): 0.9, (1, 1): 0.9 * (1 - gain), (0, 1): 1.0}
    parts = [tuple(SimpleNamespace(label=f"{j}{i}", index=i) for i in range(2)) for j in range(2)]

    def solve_many(combinations, warm=True):
        return [
            SimpleNamespace(
                numpy_objectives={"v": value[tuple(p.index for p in c)]},
                status="Solve_Succeeded",
                iterations=1,
            )
            for c in combinations
        ]

    monkeypatch.setattr(searching, "objective_value", lambda problem, objectives: objectives["v"])
    monkeypatch.setattr(searching.PartsSearch, "start", lambda self: (0, 0))
    search = searching.PartsSearch(None, None, parts, solve_many, None)
    assert search.descend() == 2
    assert search.best() == (1, 1)  # the best tried is kept either way
    assert ((0, 1) in search.tried) == moved
    # From an infeasible start (inf) a feasible part is always a move.
    value[(0, 0)] = float("inf")
    search = searching.PartsSearch(None, None, parts, solve_many, None)
    search.descend()
    assert search.best() == (1, 1)


def test_the_descent_starts_where_every_joint_meets_its_own_requirement(monkeypatch):
    # Both joints' nearest parts (index 0) miss their requirement once the other's part is chosen; no step of
    # one joint from (0, 0) is feasible, so the descent must start at (1, 1), found without solving.
    from types import SimpleNamespace

    def evaluate(problem, design, parts):
        return SimpleNamespace(shortfalls=tuple(f"j{k}: short" for k, p in enumerate(parts) if p.index == 0))

    monkeypatch.setattr(searching, "evaluate_parts", evaluate)
    parts = [tuple(SimpleNamespace(label=f"{j}{i}", index=i) for i in range(3)) for j in range(2)]
    problem = SimpleNamespace(joint_names=("j0", "j1"))
    assert searching.PartsSearch(problem, None, parts, None, None).start() == (1, 1)


@pytest.mark.parametrize(
    ("objective", "lighter_impulse", "chosen"),
    [
        ("mean_impulse", 1.0005, (1, 0)),  # 0.05 % worse, 25 % lighter: the lighter build
        ("mean_impulse", 1.002, (0, 0)),  # 0.2 % worse: beyond RESOLUTION, the least impulse stays
        ("worst_case_impulse", 1.0005, (1, 0)),
        ("actuator_mass", 1.0005, (0, 0)),  # not an impulse objective: the least value alone
    ],
    ids=["alike", "beyond", "worst-case", "mass-objective"],
)
def test_the_snap_chooses_the_lightest_combination_alike_in_impulse(
    monkeypatch, objective, lighter_impulse, chosen
):
    from types import SimpleNamespace

    from collision_reflex.optimize.recommend import RESOLUTION

    assert 1.0005 - 1 < RESOLUTION < 1.002 - 1
    # (impulse, actuator mass) by combination; the search value is the study objective's own.
    table = {(0, 0): (1.0, 2.0), (1, 0): (lighter_impulse, 1.5), (0, 1): (1.01, 1.0), (1, 1): (1.2, 3.0)}
    if objective == "actuator_mass":
        table = {c: (impulse, 2.0 if c == (0, 0) else 2.5) for c, (impulse, _) in table.items()}
    parts = [tuple(SimpleNamespace(label=f"{j}{i}", index=i) for i in range(2)) for j in range(2)]

    def solve_many(combinations, warm=True):
        out = []
        for c in combinations:
            impulse, mass = table[tuple(p.index for p in c)]
            values = {"mean_impulse": impulse, "worst_case_impulse": impulse, "actuator_mass": mass}
            out.append(SimpleNamespace(numpy_objectives=values, status="Solve_Succeeded", iterations=1))
        return out

    monkeypatch.setattr(searching, "objective_value", lambda problem, values: values[objective])
    search = searching.PartsSearch(SimpleNamespace(objective={objective: 1.0}), None, parts, solve_many, None)
    search.values_of(list(table))
    assert search.least() == (0, 0)
    assert search.best() == chosen


def test_a_motor_too_slow_at_every_ratio_strong_enough_is_no_candidate(cycle_sized):
    # Joint speed x the smallest ratio that carries the required torque is the motor speed the joint needs; a
    # motor 20 % slower than that is no candidate for it, one as fast is, and the miss says why in numbers.
    _arm, problem, optimum, catalogue = cycle_sized
    speed = problem.duty.joint_speed(float(optimum.design.approach_velocity))
    motor = catalogue[-1]
    needs = float(speed[0]) * float(optimum.required_torque[0]) / motor.peak_torque
    slow = dataclasses.replace(motor, name="slow", max_speed=0.8 * needs)
    fast = dataclasses.replace(motor, name="fast", max_speed=1.01 * needs)
    first = joint_candidates(problem, optimum, [slow], candidates=1)[0]
    assert not first.parts
    assert any("no gear ratio both strong and fast enough" in why for why in first.misses)
    kept = joint_candidates(problem, optimum, [slow, fast], candidates=2)[0]
    assert {p.motor.name for p in kept.parts} == {"fast"}


def test_a_joint_may_take_gearboxes_of_other_kinds_in_the_catalogue_design():
    # The study's own harmonic figures; the catalogue holds harmonic and planetary units. By default only the
    # harmonic ones are options; with both kinds, the nearest of each kind (count per kind) that covers 30 N m.
    own = _harmonic("study figures", (30.0, 160.0), 40.0, 0.5, continuous=True)
    planetary = dataclasses.replace(_harmonic("P-50", (20.0, 50.0), 60.0, 1.2), kind="planetary")
    weak = dataclasses.replace(_harmonic("P-weak", (20.0, 50.0), 20.0, 0.4), kind="planetary")
    catalogue = {
        g.name: g
        for g in (
            _harmonic("HD-a", (50.0, 100.0), 45.0, 0.6),
            _harmonic("HD-b", (100.0,), 90.0, 1.0),
            planetary,
            weak,
        )
    }
    ratio = cr.optimize.Bounds(1.0, 200.0)
    default, _ = gearbox_options(own, ratio, 30.0, catalogue, count=1)
    assert [g.name for g, _ in default] == ["HD-a"]
    both, _ = gearbox_options(own, ratio, 30.0, catalogue, count=1, kinds=["harmonic", "planetary"])
    assert [g.name for g, _ in both] == ["HD-a", "P-50"]  # P-weak's 20 N m does not cover 30 N m
    none, misses = gearbox_options(own, ratio, 30.0, catalogue, kinds=["cycloidal"])
    assert none == [] and misses == ("no cycloidal gearbox in the gearbox catalogue",)
