"""Active sets in the sweeps and studies: the same fronts as the full NLP, the method recorded, resumable."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

import collision_reflex as cr
from collision_reflex.errors import InvalidParameter
from collision_reflex.optimize import active_set
from collision_reflex.optimize.active_set_result import ActiveSetResult
from collision_reflex.optimize.epsilon import anchor_start, solve_anchor, solve_point
from collision_reflex.optimize.optimum import single_optimum
from collision_reflex.optimize.pieces import subset_problem
from collision_reflex.optimize.results import SweepPoint, result_from_json, result_record, result_to_json
from collision_reflex.optimize.subsets import sample_subset
from collision_reflex.study.runner import run_study

pytestmark = pytest.mark.xdist_group("test_active_set_sweeps")  # one pytest-xdist worker: set-ups made once

ROOT = Path(__file__).resolve().parents[1]
NAMES = ("worst_case_impulse", "actuator_mass")
# As tests/test_active_set.py: both methods to a KKT tolerance far below the comparison's.
TIGHT = {"ipopt.tol": 1e-12, "ipopt.constr_viol_tol": 1e-12, "ipopt.acceptable_tol": 1e-10}
OBJECTIVE_TOLERANCE = 1e-6
"""Relative agreement of a point's minimised objective with the full NLP's under the same bounds: the scheme is
exact, this covers the solves' accuracy (1e-10) and the tie-break's pull toward the active samples' mean, which
tests/test_active_set.py measures below 1e-9 in the objective; a lexicographic anchor's bound holds the first
objective only within epsilon.ANCHOR_SLACK (1e-6), along which the second moves by up to ~1e-3 relative on this
flat front, so the anchors are compared at their own recorded bounds."""


@pytest.fixture(scope="module")
def panda(panda_case):
    arm, samples, space, technology, constraints = panda_case(32)

    def build(objective, bounded, chosen=samples):
        return cr.build_problem(arm, chosen, space, technology, objective, constraints, bounded)

    return samples, build


@pytest.fixture(scope="module")
def active_front(panda):
    _, build = panda
    return cr.pareto_front(build, NAMES, points=5, ipopt_options=TIGHT, active_set="always")


def test_the_active_set_front_is_the_full_nlp_front(panda, active_front):
    samples, build = panda
    front = active_front
    assert not front.failed and len(front.points) + front.merged + len(front.dominated) == 5
    for result, label in zip(front.points, front.labels, strict=True):
        assert isinstance(result, ActiveSetResult) and result.method == "active set", label
        assert result.active_samples.size < samples.size / 2 and result.impulses.shape == (samples.size,)
        # The full NLP under the same bounds, solved cold: its optimum is the point's.
        (minimised,) = [name for name in NAMES if name not in result.epsilon]
        problem = build(minimised, tuple(result.epsilon))
        full = cr.solve(problem, result.epsilon, ipopt_options=TIGHT)
        ours, theirs = result.numpy_objectives[minimised], full.numpy_objectives[minimised]
        assert abs(ours - theirs) <= OBJECTIVE_TOLERANCE * theirs, (label, ours, theirs)
        for name, bound in result.epsilon.items():  # and within the point's bounds on every sample
            assert result.numpy_objectives[name] <= bound * (1 + 1e-8), (label, name)


def test_an_epsilon_point_warm_started_from_the_anchors_last_nlp_is_the_cold_point(panda):
    _, build = panda
    anchor = solve_anchor(build, NAMES[0], NAMES, TIGHT, 1, "always")
    start = anchor.start
    assert isinstance(start, ActiveSetResult) and start.last_round is not None
    assert start.last_round.multipliers is not None
    # The mass bound halfway to the lightest design's: a binding bound.
    epsilon = {"actuator_mass": 0.6 * start.numpy_objectives["actuator_mass"]}
    args = (build, NAMES, epsilon)
    warm = solve_point(*args, start, TIGHT, "always", start.active_samples).result
    cold = solve_point(*args, start.x, TIGHT, "always", start.active_samples).result
    assert isinstance(warm, ActiveSetResult) and isinstance(cold, ActiveSetResult)
    assert set(start.active_samples) <= set(warm.active_samples)
    worst = "worst_case_impulse"
    assert (
        abs(warm.numpy_objectives[worst] - cold.numpy_objectives[worst])
        <= 1e-9 * cold.numpy_objectives[worst]
    )
    assert warm.numpy_objectives["actuator_mass"] <= epsilon["actuator_mass"] * (1 + 1e-8)


def test_a_known_optimum_on_active_sets_is_carried_to_its_anchor_with_its_last_nlp(panda):
    samples, build = panda
    optimum, _ = single_optimum(build, NAMES[0], TIGHT, starts=1, active_set="always")
    assert isinstance(optimum, ActiveSetResult) and optimum.last_round is not None
    carried = anchor_start(build, NAMES[0], NAMES[1:], optimum)
    assert isinstance(carried, ActiveSetResult) and carried.last_round is not None
    assert np.array_equal(carried.x, optimum.x)
    assert np.array_equal(carried.active_samples, optimum.active_samples)
    # The last NLP's multipliers, by row label, on the anchor's problem of the same samples (one more row: the
    # mass bound, loose at the anchor, at zero).
    subset = sample_subset(samples, optimum.active_samples)
    source = subset_problem(build, NAMES[0], (), subset)
    target = subset_problem(build, NAMES[0], NAMES[1:], subset)
    assert optimum.last_round.multipliers is not None and carried.last_round.multipliers is not None
    rows = dict(zip(source.constraint_labels, optimum.last_round.multipliers[1], strict=True))
    lam_g = carried.last_round.multipliers[1]
    assert lam_g.size == target.lbg.size == source.lbg.size + 1
    assert [rows.get(label, 0.0) for label in target.constraint_labels] == list(lam_g)
    # An epsilon point warm-started from it is the point warm-started from the anchor's own solve.
    own = solve_anchor(build, NAMES[0], NAMES, TIGHT, 1, "always").start
    epsilon = {"actuator_mass": 0.6 * optimum.numpy_objectives["actuator_mass"]}
    points = [
        solve_point(build, NAMES, epsilon, start, TIGHT, "always", start.active_samples).result
        for start in (carried, own)
    ]
    worst = [point.numpy_objectives["worst_case_impulse"] for point in points]
    assert abs(worst[0] - worst[1]) <= OBJECTIVE_TOLERANCE * worst[1]


def test_an_active_set_result_round_trips_and_its_record_says_how_it_was_solved(active_front):
    result = active_front.points[0]
    assert isinstance(result, ActiveSetResult)
    again = result_from_json(json.loads(json.dumps(result_to_json(result))))
    assert isinstance(again, ActiveSetResult) and again.method == result.method
    np.testing.assert_array_equal(again.active_samples, result.active_samples)
    assert len(again.rounds) == len(result.rounds)
    for a, b in zip(again.rounds, result.rounds, strict=True):
        assert (a.samples, a.iterations, a.worst_active, a.worst_all) == (
            b.samples,
            b.iterations,
            b.worst_active,
            b.worst_all,
        )
        np.testing.assert_array_equal(a.added, b.added)
    np.testing.assert_array_equal(again.x, result.x)
    point = SweepPoint.from_json(json.loads(json.dumps(SweepPoint("anchor", result).to_json())))
    assert isinstance(point.result, ActiveSetResult)
    record = result_record(result, "p")["solver"]
    assert record["method"] == "active set" and record["active_samples"] == result.active_samples.size


def test_the_full_nlp_below_the_threshold_and_bad_choices_refused(panda):
    samples, build = panda
    few = sample_subset(samples, np.arange(active_set.ACTIVE_SET_THRESHOLD // 2))

    def build_few(objective, bounded, chosen=few):
        return build(objective, bounded, chosen)

    result, _ = single_optimum(build_few, "worst_case_impulse", starts=1)  # auto: the full NLP
    assert not isinstance(result, ActiveSetResult)
    assert result_record(result, "p")["solver"]["method"] == "full NLP"
    # From the threshold on, auto solves on active sets.
    assert samples.size >= active_set.ACTIVE_SET_THRESHOLD
    result, _ = single_optimum(build, "worst_case_impulse", starts=1)
    assert isinstance(result, ActiveSetResult) and result.method == "active set"
    with pytest.raises(InvalidParameter, match="active_set"):
        cr.pareto_front(build, NAMES, active_set="sometimes")

    def without_samples(objective, bounded):
        return build(objective, bounded)

    with pytest.raises(InvalidParameter, match="builder taking the samples"):
        single_optimum(without_samples, "worst_case_impulse", active_set="always")


def test_the_threshold_in_the_study_schema_is_the_optimisers():
    from collision_reflex.study.run_specs import OptimizerSpec

    described = OptimizerSpec.model_fields["active_set"].description
    assert f"from {active_set.ACTIVE_SET_THRESHOLD} samples" in described


MANY_SAMPLES_STUDY = """\
name: two-link-many-samples
robot:
  urdf: {urdf}
  contact_frame: tip
actuators:
  motor: {{reference: "OPN-060-013-A", scaling_law: haddadin, stator_diameter: 60 mm}}
  gear_ratio: 1
  mechanical_stiffness: 1000 N*m/rad
  software_stiffness: 100 N*m/rad
sensing: {{scheme: force, threshold: 3 N}}
approach_velocity: 0.5 m/s
samples:
  configurations: {{random: {{count: {count}, seed: 3}}}}
  directions: {{circle: 8}}
design:
  stator_diameter: {{min: 10 mm, max: 100 mm}}
  gear_ratio: {{min: 1, max: 100}}
  software_stiffness: {{min: 10 N*m/rad, max: 1000 N*m/rad}}
objective: worst_case_impulse
constraints: {{torque_required: [1.3 N*m, 1.3 N*m], safety_factor: 1.0, threshold_floor: 0.5 N}}
pareto: {{objectives: [worst_case_impulse, actuator_mass], points: 4}}
optimizer: {{active_set: {choice}}}
catalogue: {{snap: false}}
outputs: {{figures: [png], pdf: false}}
"""


def _study(tmp_path: Path, choice: str, count: int = 160) -> Path:
    """The study with ``count`` configurations x 8 directions, solved as ``choice`` says."""
    path = tmp_path / f"many-{choice}.yaml"
    urdf = (ROOT / "designs" / "planar_two_link.urdf").as_posix()
    path.write_text(MANY_SAMPLES_STUDY.format(urdf=urdf, choice=choice, count=count))
    return path


def _designs(folder: Path) -> list[dict]:
    results = json.loads((folder / "designs.json").read_text())
    return [results["chosen"], *results["pareto"]["points"]]


def test_a_study_with_many_samples_runs_on_active_sets_and_resumes(tmp_path):
    study = _study(tmp_path, "auto")  # 160 x 8 = 1,280 samples, those in the domain: above the threshold
    folder = tmp_path / "out"
    run_study(study, folder, quiet=True, figures=False, executor="serial")
    designs = _designs(folder)
    results = json.loads((folder / "designs.json").read_text())
    count = len(results["samples"]["config_index"])  # drawn in the domain, and those the searches added
    assert 1000 < count - results["domain"]["searched_samples"] <= 1280
    for design in designs:
        assert design["solver"]["method"] == "active set", design["label"]
        assert 0 < design["solver"]["active_samples"] < count / 4
        # Reported over every sample (all in the domain at the study's one approach velocity): the worst case
        # is the largest of all impulses.
        assert len(design["impulses"]) == count
        assert design["objectives"]["worst_case_impulse"] == pytest.approx(max(design["impulses"]), rel=1e-12)
    again = run_study(study, folder, quiet=True, figures=False, executor="serial")
    assert again.resumed and again.computed == 0
    assert _designs(folder) == designs


def test_an_unknown_active_set_choice_is_located_in_the_study_file(tmp_path, capsys):
    from collision_reflex.cli import main

    study = _study(tmp_path, "sometimes")
    assert main(["validate", str(study)]) == 2
    err = capsys.readouterr().err
    line = MANY_SAMPLES_STUDY.splitlines().index("optimizer: {{active_set: {choice}}}") + 1
    assert f"{study}:{line}:" in err and "'auto'" in err and "'never'" in err, err
    assert "Traceback" not in err


def test_the_study_json_schema_documents_the_choice():
    from collision_reflex.study.jsonschema import study_json_schema

    text = json.dumps(study_json_schema())
    assert '"OptimizerSpec"' in text and "active sets of the contact samples" in text
