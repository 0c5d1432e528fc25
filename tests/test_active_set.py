"""The active-set solve against the full solve of the same problem, on a Panda with a few hundred samples."""

from __future__ import annotations

import numpy as np
import pytest

import collision_reflex as cr
from collision_reflex.arm import Arm
from collision_reflex.errors import InvalidParameter, SolverFailed
from collision_reflex.optimize import active_samples
from collision_reflex.optimize.active_set import solve_active_set
from collision_reflex.optimize.active_set_result import ActiveSetResult
from collision_reflex.optimize.evaluate import design_collision_parameters
from collision_reflex.optimize.subsets import sample_subset

pytestmark = pytest.mark.xdist_group("test_active_set")  # one pytest-xdist worker: set-ups made once

# Both solves to a KKT tolerance far below the comparison's: at IPOPT's default 1e-8 the worst case of these
# flat problems (set by the link inertia, the motors trade little against it) is only fixed to ~3e-7 relative,
# by either solve.
TIGHT = {"ipopt.tol": 1e-12, "ipopt.constr_viol_tol": 1e-12, "ipopt.acceptable_tol": 1e-10}
OBJECTIVE_TOLERANCE = 1e-7
"""Relative agreement of the objectives: the scheme is exact, the tolerance covers the solves' accuracy
(measured: 1e-10) and the tie-break's pull toward the active samples' mean (measured: below 1e-11 in the worst
case, 1e-9 in the full NLP's objective)."""


@pytest.fixture(scope="module")
def panda(panda_case):
    arm, samples, space, technology, constraints = panda_case(64)

    def builder(objective, given=constraints, bounded=()):
        return lambda chosen: cr.build_problem(arm, chosen, space, technology, objective, given, bounded)

    return samples, builder


@pytest.fixture(scope="module")
def full_solve(panda):
    samples, builder = panda
    problem = builder("worst_case_impulse")(samples)
    return problem, cr.solve(problem, ipopt_options=TIGHT)


def _relative(a, b):
    return abs(a - b) / abs(b)


def test_the_active_set_optimum_is_the_full_optimum_on_fewer_samples(panda, full_solve):
    samples, builder = panda
    problem, full = full_solve
    result = solve_active_set(builder("worst_case_impulse"), samples, ipopt_options=TIGHT)
    assert isinstance(result, ActiveSetResult) and result.method == "active set"
    assert result.rounds[-1].samples == result.active_samples.size < samples.size / 3
    # The full NLP's objective (worst case and tie-break on every sample) at both designs, and the worst case.
    assert _relative(problem.objective_value(result.x), problem.objective_value(full.x)) < OBJECTIVE_TOLERANCE
    worst_case = "worst_case_impulse"
    assert (
        _relative(result.numpy_objectives[worst_case], full.numpy_objectives[worst_case])
        < OBJECTIVE_TOLERANCE
    )
    # The mean is the tie-break's: on the active samples it pulls the undetermined variables elsewhere (1e-6
    # relative in the mean here), never below the full solve's, which minimises it among the worst-case optima.
    mean = "mean_impulse"
    assert full.numpy_objectives[mean] * (1 - 1e-9) <= result.numpy_objectives[mean]
    assert _relative(result.numpy_objectives[mean], full.numpy_objectives[mean]) < 1e-4
    # The design: the worst case is flat in the motor sizes (3e-5 relative change in them is 1e-11 in it).
    for name in ("stator_diameter", "gear_ratio", "software_stiffness"):
        np.testing.assert_allclose(getattr(result.design, name), getattr(full.design, name), rtol=1e-3)
    # Reported over every sample: the impulses are the NumPy path's of all samples, the worst the full one's.
    assert result.impulses.shape == (samples.size,)
    assert result.worst_sample == full.worst_sample
    np.testing.assert_allclose(result.impulses, full.impulses, rtol=1e-3)
    assert result.iterations == sum(r.iterations for r in result.rounds)


def test_a_sample_left_out_that_binds_is_added_and_the_optimum_is_unchanged(panda, full_solve):
    samples, builder = panda
    # Given torques (the full solve's requirement): no sample carries a torque row, so the first active set is
    # exactly the one given, here without the worst sample.
    given = cr.Constraints(torque_required=full_solve[1].required_torque, threshold_floor=5.0)
    build = builder("worst_case_impulse", given)
    problem = build(samples)
    full = cr.solve(problem, ipopt_options=TIGHT)
    worst = full.worst_sample
    initial = np.setdiff1d(np.arange(0, samples.size, 8), [worst])
    result = solve_active_set(build, samples, ipopt_options=TIGHT, initial=initial)
    assert result.rounds[0].samples == initial.size
    assert len(result.rounds) >= 2 and worst in result.rounds[0].added and worst in result.active_samples
    # Without it the first round's worst case is below the full optimum: a relaxation.
    assert result.rounds[0].worst_active < full.objectives["worst_case_impulse"] * (1 - 1e-3)
    assert result.rounds[-1].added.size == 0
    assert _relative(problem.objective_value(result.x), problem.objective_value(full.x)) < OBJECTIVE_TOLERANCE
    assert _relative(result.objectives["worst_case_impulse"], full.objectives["worst_case_impulse"]) < 1e-7


def test_the_torque_requirement_is_every_configurations(panda, full_solve):
    samples, builder = panda
    problem, full = full_solve
    # One sample: its configuration's gravity torque alone would size the joints.
    result = solve_active_set(
        builder("worst_case_impulse"), samples, ipopt_options=TIGHT, initial=np.array([5])
    )
    required = np.asarray(problem.required_torque_function(result.design.actuator_mass)).ravel()
    np.testing.assert_allclose(result.required_torque, required, rtol=1e-9)
    assert np.all(result.design.driving_peak_torque >= required * (1 - 1e-7))
    np.testing.assert_allclose(result.required_torque, full.required_torque, rtol=1e-3)


def test_a_bounded_worst_case_adds_the_samples_above_the_bound(panda):
    samples, builder = panda
    few = sample_subset(samples, np.arange(0, samples.size, 2))
    build = builder("actuator_mass", bounded=("worst_case_impulse",))
    # The lightest design's worst case is 0.843 N*s on all samples: a bound below it binds.
    epsilon = {"worst_case_impulse": 0.84}
    problem = build(few)
    full = cr.solve(problem, epsilon, ipopt_options=TIGHT)
    result = solve_active_set(build, few, epsilon, TIGHT, start_samples=8)
    assert full.numpy_objectives["worst_case_impulse"] == pytest.approx(0.84, rel=1e-8)
    assert result.numpy_objectives["worst_case_impulse"] <= 0.84 * (1 + 1e-8)
    assert result.active_samples.size < few.size / 2
    mass = "actuator_mass"
    assert _relative(result.numpy_objectives[mass], full.numpy_objectives[mass]) < OBJECTIVE_TOLERANCE
    assert _relative(problem.objective_value(result.x), problem.objective_value(full.x)) < OBJECTIVE_TOLERANCE


def test_a_design_that_misses_a_row_of_the_full_problem_is_refused(panda, monkeypatch):
    samples, builder = panda
    # Without the torque check, one sample's configuration sizes the joints: the full problem's rows catch it.
    monkeypatch.setattr(active_samples, "_torque_violated", lambda *args: np.empty(0, dtype=int))
    with pytest.raises(SolverFailed, match="peak torque of") as raised:
        solve_active_set(builder("worst_case_impulse"), samples, initial=np.array([5]))
    assert raised.value.status == "Active_Set_Inconsistent"


def test_samples_below_the_noise_floor_are_added(panda):
    samples, _ = panda
    few = sample_subset(samples, np.arange(0, samples.size, 2))
    arm = Arm.from_example_robot_data("panda")
    # Position sensing: each sample's force threshold is k_s e_th [N], the floor binds where k_s is smallest.
    space = cr.DesignSpace(
        stator_diameter=(0.02, 0.15),
        gear_ratio=(1.0, 100.0),
        software_stiffness=(100.0, 1e4),
        threshold=(1e-4, 0.05),
        approach_velocity=(0.05, 1.0),
    )
    technology = cr.ActuatorTechnology(
        cr.reference_motor(), mechanical_stiffness=5000.0, reflected_inertia_in="finger", sensing="position"
    )
    floor = 5.0
    constraints = cr.Constraints(payload=1.0, safety_factor=1.5, threshold_floor=floor)

    def build(chosen):
        return cr.build_problem(arm, chosen, space, technology, "worst_case_impulse", constraints)

    problem = build(few)
    result = solve_active_set(build, few, ipopt_options=TIGHT, start_samples=4)
    _, thresholds = design_collision_parameters(problem, result.design)
    assert result.rounds[0].added.size > 0
    assert thresholds.min() >= floor * (1 - 1e-8)
    full = cr.solve(problem, ipopt_options=TIGHT)
    assert _relative(problem.objective_value(result.x), problem.objective_value(full.x)) < OBJECTIVE_TOLERANCE


def test_multi_start_is_never_worse_and_reproducible(panda, full_solve):
    samples, builder = panda
    problem, _ = full_solve
    build = builder("worst_case_impulse")
    single = solve_active_set(build, samples)
    multi = solve_active_set(build, samples, starts=3)
    assert problem.objective_value(multi.x) <= problem.objective_value(single.x) * (1 + 1e-12)
    again = solve_active_set(build, samples, starts=3)
    np.testing.assert_array_equal(again.x, multi.x)


def test_a_mean_impulse_objective_is_solved_on_every_sample(panda):
    samples, builder = panda
    few = sample_subset(samples, np.arange(0, samples.size, 4))
    build = builder({"mean_impulse": 1.0, "worst_case_impulse": 1.0})
    result = solve_active_set(build, few)
    assert result.method.startswith("all samples") and "mean impulse" in result.method
    assert result.active_samples.size == few.size and len(result.rounds) == 1
    direct = cr.solve(build(few))
    assert _relative(result.numpy_objectives["mean_impulse"], direct.numpy_objectives["mean_impulse"]) < 1e-12


def test_sample_subset_keeps_every_configuration():
    arm = cr.Arm.from_example_robot_data("double_pendulum")
    kinematics = arm.kinematics(np.array([[0.1, 0.2], [0.3, 0.4], [0.5, 0.6]]))
    samples = cr.ContactSamples.grid(kinematics, np.array([[1.0, 0.0], [0.0, 1.0]]))
    subset = sample_subset(samples, np.array([5, 0]))
    assert subset.kinematics is samples.kinematics
    np.testing.assert_array_equal(subset.config_index, [2, 0])
    np.testing.assert_allclose(subset.joint_moment_arms, samples.joint_moment_arms[[5, 0]])


@pytest.mark.parametrize(
    "keyword, value",
    [
        ("start_samples", 0),
        ("tolerance", -1e-3),
        ("max_rounds", 0),
        ("initial", np.array([10_000])),
        ("starts", 0),
    ],
)
def test_bad_settings_are_clear_errors(panda, keyword, value):
    samples, builder = panda
    with pytest.raises(InvalidParameter, match=keyword):
        solve_active_set(builder("worst_case_impulse"), samples, **{keyword: value})
