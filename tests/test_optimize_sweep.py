"""Pareto sweeps: solvers shared per problem, warm-started epsilon points, bounded lexicographic steps, and
the solver attempts kept in the sweep's records."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import casadi as ca
import numpy as np
import pytest

import collision_reflex as cr
from collision_reflex.arm import Arm
from collision_reflex.errors import SolverFailed
from collision_reflex.optimize import epsilon
from collision_reflex.optimize.derivatives import derivative_functions
from collision_reflex.optimize.dominance import MERGE_TOLERANCE
from collision_reflex.optimize.epsilon import anchor_start, epsilon_grid, solve_anchor
from collision_reflex.optimize.ipopt import DEFAULT_IPOPT_OPTIONS, Attempt
from collision_reflex.optimize.optimum import OPTIMUM_STARTS, known_optima, single_optimum
from collision_reflex.optimize.pareto import pareto_front
from collision_reflex.optimize.pieces import built_problem
from collision_reflex.optimize.results import SweepPoint, result_record
from collision_reflex.report.outputs import split_timings

TWO_LINK = Path(__file__).resolve().parents[1] / "designs" / "planar_two_link.urdf"
NAMES = ("worst_case_impulse", "actuator_mass")
AGREEMENT = 1e-6
"""Relative agreement of one optimum reached from two starts: IPOPT stops at ``tol = 1e-8`` on its scaled
optimality error, which repeats objective values to about 1e-7 (see ``dominance.MERGE_TOLERANCE``)."""


@pytest.fixture(scope="module")
def build():
    arm = Arm.from_urdf(TWO_LINK, "tip")
    rng = np.random.default_rng(0)
    angles = np.linspace(0, 2 * np.pi, 4, endpoint=False) + 0.3
    samples = cr.ContactSamples.grid(
        arm.kinematics(arm.sample_configurations(3, rng)), np.c_[np.cos(angles), np.sin(angles)]
    )
    space = cr.DesignSpace(
        stator_diameter=(0.02, 0.12),
        gear_ratio=(1, 30),
        software_stiffness=(5, 500),
        threshold=(1, 10),
        approach_velocity=0.3,
    )
    # The reflected inertia on the finger trades impulse against motor mass: a front, not a point.
    technology = cr.ActuatorTechnology(
        cr.reference_motor(), mechanical_stiffness=200.0, reflected_inertia_in="finger"
    )
    constraints = cr.Constraints(torque_required=[3.0, 1.5], safety_factor=1.2)

    def build(objective, bounded):
        return cr.build_problem(arm, samples, space, technology, objective, constraints, bounded)

    return build


def test_solvers_share_one_structured_nlp_and_match_casadis_own(build):
    problem = build("worst_case_impulse", ("actuator_mass",))
    shared = problem.solver(DEFAULT_IPOPT_OPTIONS)
    structured = problem._structured
    problem.solver({**DEFAULT_IPOPT_OPTIONS, "ipopt.mu_strategy": "adaptive"})
    assert problem._structured is structured and len(problem._solvers) == 2
    # Independent: CasADi expanding the NLP as built, with the same derivative functions.
    own = ca.nlpsol(
        "own",
        "ipopt",
        problem.nlp,
        {**DEFAULT_IPOPT_OPTIONS, **derivative_functions(problem.graph.structure)},
    )
    bounds = dict(lbx=problem.lbx, ubx=problem.ubx, lbg=problem.lbg, ubg=problem.ubg, p=problem.parameters())
    a, b = shared(x0=problem.x0, **bounds), own(x0=problem.x0, **bounds)
    # The same values up to rounding (~1e-16, another order of operations), so the same path and optimum: the
    # objective to 3e-15 here (1e-12 allowed); a variable to within IPOPT's tol 1e-8 scaled by how weakly it
    # is pinned (a sample's auxiliary that does not set the worst case only by the 1e-3 tie-break pull: 4e-8
    # here without IPOPT's residual checks; AGREEMENT allowed). A wrong value or derivative changes the path
    # and the optimum.
    assert shared.stats()["iter_count"] == own.stats()["iter_count"]
    assert float(a["f"]) == pytest.approx(float(b["f"]), rel=1e-12)
    np.testing.assert_allclose(np.asarray(a["x"]), np.asarray(b["x"]), rtol=AGREEMENT, atol=1e-12)


def test_epsilon_points_start_from_the_anchor_and_match_cold_solves(build):
    front = pareto_front(build, NAMES, points=6)
    assert not front.failed
    problem = built_problem(build, NAMES[0], NAMES[1:])
    warm = cold = 0
    for result, label in zip(front.points, front.labels, strict=True):
        if not label.startswith("epsilon"):
            continue
        # One IPOPT run per point: warm-started, no retry needed.
        assert [a.name for a in result.attempts] == ["requested"]
        again = cr.solve(problem, epsilon=result.epsilon)
        for name in NAMES:
            assert result.numpy_objectives[name] == pytest.approx(again.numpy_objectives[name], rel=AGREEMENT)
        warm, cold = warm + result.iterations, cold + again.iterations
    assert warm < cold  # the anchor's point and multipliers are a better start than the problem's own


def test_a_lexicographic_step_at_its_cap_is_recorded_and_keeps_the_anchor(build, monkeypatch):
    monkeypatch.setattr(
        epsilon, "LEXICOGRAPHIC_OPTIONS", {**epsilon.LEXICOGRAPHIC_OPTIONS, "ipopt.max_iter": 1}
    )
    built_problem.cache_clear()  # fresh problems: the capped solver is built for this test
    try:
        front = pareto_front(build, NAMES, points=3)
    finally:
        built_problem.cache_clear()
    assert sorted(f.objective for f in front.failed) == sorted(NAMES)
    assert {f.status for f in front.failed} == {"Maximum_Iterations_Exceeded"}
    # Each anchor is its first solve's result, which the capped step did not replace.
    for name in NAMES:
        alone = cr.solve(build(name, tuple(n for n in NAMES if n != name)))
        anchor = [
            r
            for r, label in zip(
                front.points + front.dominated, front.labels + front.dominated_labels, strict=True
            )
            if label == f"anchor: {name}"
        ]
        assert len(anchor) == 1
        assert anchor[0].numpy_objectives[name] == pytest.approx(alone.numpy_objectives[name], rel=AGREEMENT)


def test_solve_without_retries_raises_its_status(build):
    problem = build("worst_case_impulse", ())
    with pytest.raises(SolverFailed) as raised:
        cr.solve(problem, ipopt_options={"ipopt.max_iter": 2}, retry=False)
    assert raised.value.status == "Maximum_Iterations_Exceeded"
    assert [a[0] for a in raised.value.attempts] == ["requested"]


def test_sweep_records_keep_every_attempt_and_the_multipliers(build):
    problem = build("worst_case_impulse", ())
    result = cr.solve(problem)
    retried = (Attempt("requested", "Infeasible_Problem_Detected", 104, 0.5), *result.attempts)
    result = dataclasses.replace(result, attempts=retried)
    point = SweepPoint("anchor: worst_case_impulse", result, start=result)
    back = SweepPoint.from_json(point.to_json())
    assert back.result is not None and back.start is not None
    assert back.result.attempts == retried
    assert back.result.multipliers is not None and result.multipliers is not None
    for saved, kept in zip(back.result.multipliers, result.multipliers, strict=True):
        assert np.array_equal(saved, kept)
    record = result_record(result, "optimum")
    assert [a["status"] for a in record["solver"]["attempts"]] == [a.status for a in retried]
    # Wall times go to timings.json, so the result files stay the same bytes across runs.
    numbers, timings = split_timings(record)
    assert all("solve_time" not in a for a in numbers["solver"]["attempts"])
    assert timings["solver/attempts/0/solve_time"] == 0.5


def _anchor(**objectives):
    return type("Anchor", (), {"numpy_objectives": objectives})()


def test_a_front_that_collapses_to_a_point_has_no_epsilon_points():
    # Masses equal within the merge tolerance: every bound between them repeats an anchor.
    same = {
        "worst_case_impulse": _anchor(worst_case_impulse=0.2, actuator_mass=0.4, approach_velocity=0.3),
        "actuator_mass": _anchor(
            worst_case_impulse=0.3, actuator_mass=0.4 * (1 - 1e-7), approach_velocity=0.5
        ),
    }
    assert epsilon_grid(same, ("actuator_mass",), 6) == []
    # With a third objective that does span a front, only it is bounded.
    grid = epsilon_grid(same, ("actuator_mass", "approach_velocity"), 3)
    assert [set(g) for g in grid] == [{"approach_velocity"}] * 3
    assert [g["approach_velocity"] for g in grid] == pytest.approx([0.35, 0.4, 0.45], rel=1e-12)


def test_an_anchor_takes_a_known_optimum_as_its_first_solve(build, monkeypatch):
    optimum, _ = single_optimum(build, NAMES[0], starts=2)
    own = pareto_front(build, NAMES, points=5)
    first_solves = []
    solve_with = epsilon.solve_with  # as the anchors call it

    def counted(build, objective, bounded, active_set, epsilon=None, **kwargs):
        if not epsilon:
            first_solves.append(objective)
        return solve_with(build, objective, bounded, active_set, epsilon, **kwargs)

    monkeypatch.setattr(epsilon, "solve_with", counted)
    front = pareto_front(build, NAMES, points=5, known={NAMES[0]: optimum})
    assert first_solves == [NAMES[1]]  # the known objective's anchor did not solve again
    assert not front.failed and len(front.points) == len(own.points)
    # The same front as the anchor's own solve found (this problem has one optimum): equal as the sweep merges
    # designs (MERGE_TOLERANCE, 1e-5; the anchors' masses here differ by 2e-6, as an anchor holds its impulse
    # within ANCHOR_SLACK of an optimum itself known to ~1e-8).
    for mine, theirs in zip(front.points, own.points, strict=True):
        for name in NAMES:
            assert mine.numpy_objectives[name] == pytest.approx(
                theirs.numpy_objectives[name], rel=MERGE_TOLERANCE
            )
    # The optimum's multipliers carried to the anchor's problem by row: its objective bound (loose at the
    # anchor) at zero, every other row the optimum's own.
    source, target = build(NAMES[0], ()), built_problem(build, NAMES[0], NAMES[1:])
    carried = anchor_start(build, NAMES[0], NAMES[1:], optimum)
    assert carried is not None and carried.multipliers is not None and optimum.multipliers is not None
    assert np.array_equal(carried.x, optimum.x)
    lam_x, lam_g = carried.multipliers
    assert lam_x.size == target.x0.size and lam_g.size == target.lbg.size == source.lbg.size + 1
    rows = dict(zip(source.constraint_labels, optimum.multipliers[1], strict=True))
    for label, value in zip(target.constraint_labels, lam_g, strict=True):
        assert value == rows.get(label, 0.0)
    assert sum(label not in rows for label in target.constraint_labels) == 1


def test_a_known_optimum_of_other_variables_is_solved_again(build):
    # Bounding the worst case adds its epigraph variable: the mass optimum is not a point of that problem.
    optimum = cr.solve(build("actuator_mass", ()))
    assert anchor_start(build, "actuator_mass", ("worst_case_impulse",), optimum) is None
    point = solve_anchor(build, "actuator_mass", NAMES, None, known=optimum)
    assert point.result is not None and not point.failures
    assert point.result.x.size == built_problem(build, "actuator_mass", NAMES[:1]).x0.size


def test_a_study_optimum_is_known_to_its_anchor_only_when_it_is_one_of_them():
    optimum = object()
    assert known_optima("mean_impulse", optimum, 1) == {"mean_impulse": optimum}
    assert known_optima("mean_impulse", optimum, OPTIMUM_STARTS) == {"mean_impulse": optimum}
    # More starts asked of the anchors than the optimum had, or a weighted objective: the anchors solve.
    assert known_optima("mean_impulse", optimum, OPTIMUM_STARTS + 1) == {}
    assert known_optima((("actuator_mass", 0.1), ("worst_case_impulse", 1.0)), optimum, 1) == {}


def test_a_numpy_path_that_disagrees_with_casadi_is_warned_of(build, monkeypatch):
    from collision_reflex.optimize import design_result as solving

    problem = build("worst_case_impulse", ())
    agreeing = cr.solve(problem)
    # The NumPy path 1e-5 off (10 x AGREEMENT_TOLERANCE) in every impulse: every impulse objective is named.
    original = solving.evaluate_design
    monkeypatch.setattr(solving, "evaluate_design", lambda p, d: original(p, d) * (1 + 1e-5))
    with pytest.warns(RuntimeWarning, match="evaluations of (worst_case|mean|cvar)_impulse differ") as caught:
        cr.solve(problem, x0=agreeing.x)
    assert {str(w.message).split()[5] for w in caught} == {
        "worst_case_impulse",
        "mean_impulse",
        "cvar_impulse",
    }


def test_a_known_optimum_of_another_problem_is_refused(build):
    # A result whose objectives are not this problem's at its point, as another problem's would be (its
    # recorded mass doubled here): refused, not taken as the anchor.
    optimum = cr.solve(build("worst_case_impulse", ()))
    stranger = dataclasses.replace(
        optimum, objectives={**optimum.objectives, "actuator_mass": 2 * optimum.objectives["actuator_mass"]}
    )
    with pytest.raises(cr.InvalidParameter, match="known optimum of worst_case_impulse"):
        anchor_start(build, NAMES[0], NAMES[1:], stranger)
    assert anchor_start(build, NAMES[0], NAMES[1:], optimum) is not None
