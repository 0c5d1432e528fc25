"""The design optimiser against finite differences, brute-force grids and the properties of Pareto sets."""

from __future__ import annotations

import itertools
from pathlib import Path

import numpy as np
import pytest

import collision_reflex as cr
from collision_reflex.arm import Arm
from collision_reflex.optimize import hypervolume
from collision_reflex.optimize.design import design_at
from collision_reflex.optimize.evaluate import collision_parameters, evaluate_design
from collision_reflex.optimize.objectives import TIE_BREAK_WEIGHT
from collision_reflex.optimize.results import undecided_variables
from collision_reflex.optimize.sweep import Runner

TWO_LINK = Path(__file__).resolve().parents[1] / "designs" / "planar_two_link.urdf"


@pytest.fixture(scope="module")
def arm():
    return Arm.from_urdf(TWO_LINK, "tip")


def _samples(arm, n_config=3, n_direction=4, seed=0):
    rng = np.random.default_rng(seed)
    kin = arm.kinematics(arm.sample_configurations(n_config, rng))
    angles = np.linspace(0, 2 * np.pi, n_direction, endpoint=False) + 0.3
    return cr.ContactSamples.grid(kin, np.c_[np.cos(angles), np.sin(angles)])


FREE_SPACE = cr.DesignSpace(
    stator_diameter=(0.02, 0.12),
    gear_ratio=(1, 30),
    software_stiffness=(5, 500),
    threshold=(1, 10),
    approach_velocity=(0.05, 1.0),
)


def _technology(**kwargs):
    return cr.ActuatorTechnology(cr.reference_motor(), mechanical_stiffness=200.0, **kwargs)


def _numpy_impulses(problem, z):
    x = np.zeros(problem.layout.size)
    x[:] = z
    return evaluate_design(problem, design_at(problem, x))


@pytest.mark.parametrize(
    "technology",
    [
        dict(reflected_inertia_in="robot"),
        dict(reflected_inertia_in="finger"),
        dict(sensing="position", reaction="moving"),
    ],
    ids=["robot", "finger", "position-moving"],
)
def test_casadi_derivatives_match_numpy_finite_differences(arm, technology):
    space = FREE_SPACE
    if technology.get("sensing") == "position":
        space = cr.DesignSpace(**{**FREE_SPACE.__dict__, "threshold": (1e-3, 2e-2)})
    problem = cr.build_problem(
        arm,
        _samples(arm, 2, 3),
        space,
        _technology(**technology),
        constraints=cr.Constraints(torque_required=[2.0, 1.0]),
    )
    function = problem.impulse_function()
    z0 = problem.x0[: problem.layout.size] + 0.05  # off the bound midpoints
    weights = np.random.default_rng(1).uniform(0.5, 1.5, problem.samples.size)

    value = float(function(z0) @ weights)
    assert value == pytest.approx(_numpy_impulses(problem, z0) @ weights, rel=1e-12)

    import casadi as ca

    z = ca.MX.sym("z", z0.size)
    objective = ca.mtimes(function(z), ca.DM(weights))
    hessian, gradient = ca.hessian(objective, z)
    derivatives = ca.Function("d", [z], [gradient, hessian])
    grad, hess = (np.asarray(v) for v in derivatives(z0))

    def numpy_objective(point):
        return float(_numpy_impulses(problem, point) @ weights)

    # Central differences in the log design variables. Gradient: truncation ~h^2 f''' ~ 1e-10 and rounding
    # ~eps f / h ~ 1e-11 (relative), so 1e-6 relative is safe. Hessian: second differences with h = 1e-4
    # have truncation and rounding errors near 1e-8 relative to f; 1e-4 relative to the largest entry.
    h = 1e-5
    eye = np.eye(z0.size)
    fd_grad = np.array([(numpy_objective(z0 + h * e) - numpy_objective(z0 - h * e)) / (2 * h) for e in eye])
    np.testing.assert_allclose(grad.ravel(), fd_grad, rtol=1e-6, atol=1e-9 * abs(value))
    h2 = 1e-4
    fd_hess = np.empty((z0.size, z0.size))
    for i, j in itertools.product(range(z0.size), repeat=2):
        ei, ej = h2 * eye[i], h2 * eye[j]
        fd_hess[i, j] = (
            numpy_objective(z0 + ei + ej)
            - numpy_objective(z0 + ei - ej)
            - numpy_objective(z0 - ei + ej)
            + numpy_objective(z0 - ei - ej)
        ) / (4 * h2**2)
    np.testing.assert_allclose(hess, fd_hess, rtol=0, atol=1e-4 * np.abs(fd_hess).max())


@pytest.mark.parametrize(
    ("technology", "objective", "bounded"),
    [
        (dict(reflected_inertia_in="finger"), "worst_case_impulse", ()),
        (
            dict(reflected_inertia_in="robot"),
            {"mean_impulse": 1.0, "actuator_mass": 0.5},
            ("worst_case_impulse",),
        ),
        (
            dict(sensing="position", reaction="moving"),
            "actuator_mass",
            ("worst_case_impulse", "mean_impulse"),
        ),
    ],
    ids=["finger-worst", "robot-weighted-bounded", "position-mass-bounded"],
)
def test_per_sample_derivatives_equal_casadis_of_the_whole_nlp(arm, technology, objective, bounded):
    import casadi as ca

    from collision_reflex.optimize.derivatives import derivative_functions, structured_nlp

    space = FREE_SPACE
    if technology.get("sensing") == "position":
        space = cr.DesignSpace(**{**FREE_SPACE.__dict__, "threshold": (1e-3, 2e-2)})
    problem = cr.build_problem(
        arm,
        _samples(arm, 3, 4),
        space,
        _technology(**technology),
        objective,
        cr.Constraints(payload=0.5, safety_factor=1.5),
        bounded,
    )
    nlp, rng = problem.nlp, np.random.default_rng(4)
    sigma, lam = ca.MX.sym("sigma"), ca.MX.sym("lam", problem.lbg.size)
    lagrangian = sigma * nlp["f"] + ca.dot(lam, nlp["g"])
    whole = ca.Function(
        "whole",
        [nlp["x"], nlp["p"], sigma, lam],
        [
            ca.gradient(nlp["f"], nlp["x"]),
            ca.jacobian(nlp["g"], nlp["x"]),
            ca.hessian(lagrangian, nlp["x"])[0],
        ],
    )
    ours = derivative_functions(problem.graph.structure)
    split = structured_nlp(problem.graph.structure)
    values = ca.Function("values", [split["x"], split["p"]], [split["f"], split["g"]])
    original = ca.Function("original", [nlp["x"], nlp["p"]], [nlp["f"], nlp["g"]])
    for _ in range(3):  # random points: off the start, and random multipliers
        x = problem.exact_point(problem.x0) + rng.normal(0.0, 0.1, problem.x0.size)
        p = rng.uniform(0.5, 2.0, problem.parameters().size)
        weights = (rng.uniform(0.5, 2.0), rng.normal(size=problem.lbg.size))
        # The NLP's values as the per-sample map and the outer part: the same operations, so to rounding.
        for mine, theirs in zip(values(x, p), original(x, p), strict=True):
            theirs = np.asarray(theirs)
            np.testing.assert_allclose(np.asarray(mine), theirs, rtol=0, atol=1e-12 * np.abs(theirs).max())
        grad, jac, hess = (np.asarray(ca.DM(v)) for v in whole(x, p, *weights))
        # Both are exact derivatives of the same expressions, in another order of operations: they agree to
        # rounding, ~1e-15 relative to the largest entry; 1e-10 leaves room without hiding a wrong term.
        for mine, theirs in [
            (ours["grad_f"](x, p)[1], grad),
            (ours["jac_g"](x, p)[1], jac),
            (ours["hess_lag"](x, p, *weights), np.triu(hess)),
        ]:
            mine = np.asarray(ca.DM(mine))
            np.testing.assert_allclose(mine, theirs, rtol=0, atol=1e-10 * np.abs(theirs).max())
    assert np.abs(np.tril(np.asarray(ca.DM(ours["hess_lag"](x, p, *weights))), -1)).max() == 0.0


def test_per_sample_derivatives_of_an_outer_part_nonlinear_in_the_sample_outputs():
    """The chain rule's general case, which the model's outer part (linear in Y) does not reach: weights on Y
    that depend on Y, and an outer Hessian with Y-terms, against CasADi differentiating the whole NLP."""
    import casadi as ca

    from collision_reflex.optimize.derivatives import (
        SampleStructure,
        derivative_functions,
        structured_nlp,
    )

    n_x, n_samples = 5, 4
    v, data, scale = ca.SX.sym("v", 3), ca.SX.sym("data", 1), ca.SX.sym("scale", 1)
    outputs = ca.vertcat(ca.sin(v[0]) * ca.exp(v[1] * data) + scale * v[2] ** 2, v[0] * v[1] * v[2])
    sample = ca.Function("sample", [v, data, scale], [outputs])
    xo, yo, po = ca.SX.sym("x", n_x), ca.SX.sym("Y", 2, n_samples), ca.SX.sym("p", 1)
    fo = ca.sumsqr(yo[0, :]) + xo[0] * ca.sum2(yo[1, :]) + po * xo[1] ** 2
    go = ca.vertcat(ca.transpose(yo[0, :] * yo[1, :]), xo[0] + yo[1, 0] ** 3)
    outer = ca.Function("outer", [xo, yo, po], [fo, go])
    # Every sample shares x0 and x1 (as the design variables) and has one of x2..x4 (as its auxiliaries).
    variables = np.array([[0] * n_samples, [1] * n_samples, [2, 3, 4, 2]])
    rng = np.random.default_rng(2)
    structure = SampleStructure(
        outer, sample, variables, rng.uniform(0.5, 1.5, (1, n_samples)), rng.uniform(0.5, 1.5, (1, n_samples))
    )

    x, p = ca.MX.sym("x", n_x), ca.MX.sym("p", 1)
    columns = ca.horzcat(
        *[
            sample(x[variables[:, s].tolist()], structure.data[:, s], structure.direction_scale[:, s])
            for s in range(n_samples)
        ]
    )
    f, g = outer(x, columns, p)
    sigma, lam = ca.MX.sym("sigma"), ca.MX.sym("lam", g.shape[0])
    whole = ca.Function(
        "whole",
        [x, p, sigma, lam],
        [f, g, ca.gradient(f, x), ca.jacobian(g, x), ca.hessian(sigma * f + ca.dot(lam, g), x)[0]],
    )
    ours = derivative_functions(structure)
    split = structured_nlp(structure)
    values = ca.Function("values", [split["x"], split["p"]], [split["f"], split["g"]])
    point, parameter = rng.normal(size=n_x), [0.7]
    weights = (1.3, rng.normal(size=g.shape[0]))
    f_value, g_value, grad, jac, hess = (np.asarray(ca.DM(e)) for e in whole(point, parameter, *weights))
    # The same derivatives in another order of operations: they agree to rounding.
    for mine, theirs in [
        (values(point, parameter)[0], f_value),
        (values(point, parameter)[1], g_value),
        (ours["grad_f"](point, parameter)[1], grad),
        (ours["jac_g"](point, parameter)[1], jac),
        (ours["hess_lag"](point, parameter, *weights), np.triu(hess)),
    ]:
        theirs = np.asarray(theirs)
        np.testing.assert_allclose(np.asarray(ca.DM(mine)), theirs, rtol=0, atol=1e-12 * np.abs(theirs).max())


def test_scattered_sample_entries_sum_into_the_nlp_matrix_as_a_dense_accumulation():
    """The per-sample entries' pattern and summing matrix against a brute-force dense sum, repeated entries
    (shared design variables) and empty columns included; and the sample data converted to CasADi unchanged."""
    import casadi as ca

    from collision_reflex.optimize.derivatives import _scatter, dense_dm

    rng = np.random.default_rng(5)
    shape = (7, 9)
    rows, cols = rng.integers(0, shape[0], 60), rng.integers(0, 6, 60)  # columns 6..8 stay empty
    values = rng.normal(size=rows.size)
    pattern, summing = _scatter(rows, cols, shape)
    expected = np.zeros(shape)
    np.add.at(expected, (rows, cols), values)
    summed = ca.DM(pattern, ca.mtimes(summing, ca.DM(values)))
    np.testing.assert_allclose(np.asarray(summed), expected, rtol=0, atol=1e-12 * np.abs(expected).max())
    entries = set(zip(rows.tolist(), cols.tolist(), strict=True))
    assert pattern.nnz() == len(entries)
    assert set(zip(*pattern.get_triplet(), strict=True)) == entries
    assert summing.shape == (len(entries), rows.size) and np.all(np.asarray(ca.sum1(summing)) == 1)

    data = rng.normal(size=(4, 3))
    data[1] = 0.0  # zeros stay structural entries, as in ca.DM(array)
    for array in (data, data[:, 0]):
        converted, reference = dense_dm(array), ca.DM(array)
        assert converted.sparsity() == reference.sparsity()
        assert np.array_equal(np.asarray(converted), np.asarray(reference))


def test_every_solver_of_a_problem_shares_one_set_of_derivatives_and_the_optimum_is_unchanged(
    arm, monkeypatch
):
    from collision_reflex.optimize import problem as problem_module
    from collision_reflex.optimize.ipopt import DEFAULT_IPOPT_OPTIONS

    built = []
    original = problem_module.derivative_functions

    def counting(structure):
        built.append(structure)
        return original(structure)

    monkeypatch.setattr(problem_module, "derivative_functions", counting)
    problem = cr.build_problem(
        arm, _samples(arm, 3, 4), FREE_SPACE, _technology(), constraints=cr.Constraints(payload=0.5)
    )
    first = cr.solve(problem)
    cr.solve(problem, x0=first)  # the warm-start option set: a second solver
    cr.solve(problem, ipopt_options={"ipopt.mu_strategy": "adaptive"})  # the retries' option set: a third
    assert len(problem._solvers) == 3 and len(built) == 1

    # CasADi's own differentiation of the whole NLP reaches the same optimum in about the same iterations: the
    # same start and the same derivatives up to rounding (~1e-15), so the same path to IPOPT's tol 1e-8.
    runs = []
    for structural in (True, False):
        solver = problem.solver(DEFAULT_IPOPT_OPTIONS, structural=structural)
        solution = solver(x0=problem.x0, lbx=problem.lbx, ubx=problem.ubx, lbg=problem.lbg, ubg=problem.ubg)
        runs.append((float(solution["f"]), int(solver.stats()["iter_count"])))
    (ours, our_iterations), (whole, whole_iterations) = runs
    assert ours == pytest.approx(whole, rel=1e-8)
    assert our_iterations == first.iterations and abs(our_iterations - whole_iterations) <= 2


def _brute_force_problem(arm, objective, n_config=2, n_direction=3):
    space = cr.DesignSpace(
        stator_diameter=(0.02, 0.12),
        gear_ratio=5.0,
        software_stiffness=100.0,
        threshold=3.0,
        approach_velocity=(0.05, 1.0),
    )
    technology = _technology(reflected_inertia_in="finger")
    constraints = cr.Constraints(torque_required=[3.0, 1.5])
    samples = _samples(arm, n_config, n_direction)
    return cr.build_problem(arm, samples, space, technology, objective, constraints)


@pytest.mark.parametrize("objective", ["mean_impulse", "worst_case_impulse", "cvar_impulse"])
def test_optimum_agrees_with_brute_force_grid(arm, objective):
    # The CVaR on 40 samples: its 5 % tail is 2 samples, neither the worst case nor the mean.
    problem = _brute_force_problem(arm, objective, *((8, 5) if objective == "cvar_impulse" else (2, 3)))
    result = cr.solve(problem)
    assert result.success

    # 25 log-spaced values per free variable (two diameters, the velocity): every design on the grid.
    lower, upper, _ = problem.layout.log_bounds()
    axes = [np.linspace(lo, hi, 25) for lo, hi in zip(lower, upper, strict=True)]
    assert problem.layout.slices["approach_velocity"] == [2]  # the last axis
    velocities = np.exp(axes[2])
    best_value, best_point = np.inf, None
    for diameters in itertools.product(*axes[:2]):
        design = design_at(problem, np.array([*diameters, axes[2][0]]))
        if np.any(design.peak_torque < np.array([3.0, 1.5])):
            continue  # infeasible: not enough torque
        # The velocity enters the impulse only at the end: the collision parameters once per pair of diameters,
        # the impulses at every velocity of the axis at once (evaluate_design's total_impulse, broadcast).
        params, threshold = collision_parameters(problem.samples, problem.technology, design)
        impulses = np.asarray(
            cr.total_impulse(
                *(x[:, None] for x in (params.m_f, params.k, params.k_m, threshold, params.a)),
                velocities[None, :],
                problem.technology.reaction,
            )
        )  # (samples, velocities)
        # The CVaR written out here: the mean of the 2 largest of 40 equally weighted impulses.
        values = {
            "mean_impulse": impulses.mean(axis=0),
            "worst_case_impulse": impulses.max(axis=0),
            "cvar_impulse": np.sort(impulses, axis=0)[-2:].mean(axis=0),
        }[objective]
        if values.min() < best_value:
            best_value, best_point = values.min(), np.array([*diameters, axes[2][values.argmin()]])
    # The broadcast evaluation is evaluate_design's at the best point.
    best_design = design_at(problem, best_point)
    best_impulses = evaluate_design(problem, best_design)
    assert {"mean_impulse": best_impulses.mean, "worst_case_impulse": best_impulses.max}.get(
        objective, lambda: np.sort(best_impulses)[-2:].mean()
    )() == pytest.approx(best_value, rel=1e-12)
    found = result.numpy_objectives[objective]
    # No grid point beats the optimum. The mean objective is exact; the worst case carries the tie-break pull
    # toward a lower mean, which may cost up to about TIE_BREAK_WEIGHT of the worst case.
    slack = 1e-9 if objective == "mean_impulse" else 2 * TIE_BREAK_WEIGHT
    assert found <= best_value * (1 + slack)
    # ... and the optimum lies within one grid step of the best grid point in every variable.
    step = np.array([axis[1] - axis[0] for axis in axes])
    z_found = result.x[: problem.layout.size]
    assert np.all(np.abs(z_found - best_point) <= 1.0 * step + 1e-9), (z_found, best_point, step)


def test_pareto_front_is_non_dominated_feasible_and_consistent(arm, tmp_path):
    samples = _samples(arm, 3, 4)
    technology = _technology(reflected_inertia_in="finger")
    constraints = cr.Constraints(torque_required=[3.0, 1.5], safety_factor=1.2)
    space = cr.DesignSpace(
        stator_diameter=(0.02, 0.12),
        gear_ratio=(1, 30),
        software_stiffness=(5, 500),
        threshold=(1, 10),
        approach_velocity=0.3,
    )

    def build(objective, bounded):
        return cr.build_problem(arm, samples, space, technology, objective, constraints, bounded)

    pareto = cr.pareto_front(build, ("worst_case_impulse", "actuator_mass"), points=6)
    values = pareto.values()
    assert len(pareto.points) >= 4
    for i, j in itertools.permutations(range(len(values)), 2):
        dominates = np.all(values[i] <= values[j]) and np.any(values[i] < values[j] * (1 - 1e-9))
        assert not dominates, (values[i], values[j])
    for result in pareto.points:
        assert np.all(result.torque_margin >= -1e-6)  # peak torque covers 1.2 x the requirement
        np.testing.assert_allclose(result.required_torque, [3.6, 1.8], rtol=1e-12)
        for name in ("worst_case_impulse", "actuator_mass"):
            assert result.objectives[name] == pytest.approx(result.numpy_objectives[name], rel=1e-6)
        for name, bound in result.epsilon.items():
            assert result.numpy_objectives[name] <= bound * (1 + 1e-5)
        d = result.design
        assert np.all((d.stator_diameter >= 0.02 - 1e-9) & (d.stator_diameter <= 0.12 + 1e-9))
        assert np.all(d.gear_ratio >= 1 - 1e-9)
    # The front spans a real trade-off: lighter designs give larger impulses.
    assert values[0, 1] > values[-1, 1] and values[0, 0] < values[-1, 0]

    frame = pareto.to_frame()
    assert len(frame) == len(pareto.points)
    # Every number carries its unit in its column name; the threshold's is the force sensing's newton.
    unitless = {"point", "label", "status", "iterations"}
    assert all(c.endswith("]") and " [" in c for c in frame.columns if c not in unitless), list(frame.columns)
    assert "threshold [N]" in frame and "gear_ratio[joint1] [-]" in frame
    np.testing.assert_array_equal(frame["actuator_mass [kg]"], values[:, 1])
    assert list(frame["label"][:1]) == ["anchor: worst_case_impulse"]
    pareto.to_csv(tmp_path / "pareto.csv")
    assert (tmp_path / "pareto.csv").read_text().count("\n") == len(pareto.points) + 1
    pareto.plot(tmp_path / "front.svg")
    assert (tmp_path / "front.svg").stat().st_size > 1000


def test_hypervolume_against_hand_computation():
    # Staircase of (1,3), (2,2), (3,1) to reference (4,4): 3*1 + 2*1 + 1*1 = 6.
    assert hypervolume(np.array([[1, 3], [2, 2], [3, 1]]), np.array([4, 4])) == pytest.approx(6.0)
    assert hypervolume(np.array([[1, 3], [2, 2], [3, 1], [3, 3]]), np.array([4, 4])) == pytest.approx(6.0)
    # 3D: one box (1,1,1)-(2,2,2) -> 1; two overlapping boxes -> union.
    assert hypervolume(np.array([[1.0, 1.0, 1.0]]), np.array([2.0, 2.0, 2.0])) == pytest.approx(1.0)
    points = np.array([[0.0, 1.0, 1.0], [1.0, 0.0, 1.0]])
    assert hypervolume(points, np.array([2.0, 2.0, 2.0])) == pytest.approx(2 + 2 - 1)


def test_infeasible_torque_requirement_names_the_constraint(arm):
    space = cr.DesignSpace(
        stator_diameter=(0.02, 0.04),
        gear_ratio=(1, 2),
        software_stiffness=100.0,
        threshold=3.0,
        approach_velocity=0.3,
    )
    problem = cr.build_problem(
        arm,
        _samples(arm, 2, 2),
        space,
        _technology(),
        constraints=cr.Constraints(torque_required=[50.0, 1.0]),
    )
    with pytest.raises(cr.errors.SolverFailed) as info:
        cr.solve(problem, ipopt_options={"ipopt.max_iter": 200})
    assert "peak torque of joint1" in str(info.value)
    assert info.value.violated and info.value.violated[0][0].startswith("peak torque of joint1")
    assert info.value.stats["iter_count"] > 0


@pytest.mark.parametrize(
    ("space_change", "message"),
    [
        (dict(stator_diameter=(0.1, 0.02)), "lower <= upper"),
        (dict(gear_ratio=(0.5, 10)), "gear ratio >= 1"),
        (dict(threshold=(-1.0, 3.0)), "finite number > 0"),
        (dict(approach_velocity=(0.1, float("nan"))), "finite number > 0"),
    ],
    ids=["swapped", "gear<1", "negative", "nan"],
)
def test_bad_bounds_are_clear_errors(space_change, message):
    # Refused when the space is made, before any problem is built.
    with pytest.raises(cr.InvalidParameter, match=message):
        cr.DesignSpace(**{**FREE_SPACE.__dict__, **space_change})


def test_kinematics_without_the_motor_terms_are_a_clear_error(arm):
    # Arm.kinematics(q, full=False) leaves the gravity and motor-mass terms out; the problem needs them.
    q = arm.sample_configurations(1, np.random.default_rng(0))
    partial = cr.ContactSamples.grid(arm.kinematics(q, full=False), np.array([[1.0, 0.0]]))
    with pytest.raises(cr.InvalidParameter, match=r"gravity = None .* full kinematics"):
        cr.build_problem(arm, partial, FREE_SPACE, _technology())
    # A given torque requirement needs no gravity terms, but the finger mass needs the motor-mass influence.
    given = cr.Constraints(torque_required=[1.0, 1.0])
    with pytest.raises(cr.InvalidParameter, match=r"motor_mass_influence = None .* full kinematics"):
        cr.build_problem(arm, partial, FREE_SPACE, _technology(), constraints=given)


def test_bad_objective_and_floor(arm):
    with pytest.raises(cr.InvalidParameter, match="objective"):
        cr.build_problem(arm, _samples(arm, 1, 2), FREE_SPACE, _technology(), "fastest")
    with pytest.raises(cr.InvalidParameter, match="noise floor"):
        cr.build_problem(
            arm,
            _samples(arm, 1, 2),
            FREE_SPACE,
            _technology(),
            constraints=cr.Constraints(threshold_floor=50.0),
        )
    with pytest.raises(cr.InvalidParameter, match="mechanical_stiffness"):
        _technology().__class__(cr.reference_motor(), mechanical_stiffness=float("inf"))


def test_threshold_floor_and_bounds_are_respected(arm):
    problem = cr.build_problem(
        arm,
        _samples(arm, 2, 3),
        FREE_SPACE,
        _technology(),
        constraints=cr.Constraints(torque_required=[2.0, 1.0], threshold_floor=4.0),
    )
    result = cr.solve(problem)
    assert result.design.threshold >= 4.0 * (1 - 1e-9)
    # Lower thresholds lower the impulse (sensing and reaction phases), so the floor binds; an interior-point
    # solution sits a few 1e-6 (relative) inside an active bound.
    assert result.design.threshold == pytest.approx(4.0, rel=1e-5)


def test_multi_start_is_never_worse_and_reproducible(arm):
    problem = cr.build_problem(
        arm,
        _samples(arm, 3, 4),
        FREE_SPACE,
        _technology(),
        constraints=cr.Constraints(torque_required=[2.0, 1.0]),
    )
    single = cr.solve(problem)
    multi = cr.solve(problem, starts=4, rng=np.random.default_rng(3))
    again = cr.solve(problem, starts=4, rng=np.random.default_rng(3))
    # The best of several local optima includes the single start's own.
    assert problem.objective_value(multi.x) <= problem.objective_value(single.x) * (1 + 1e-9)
    np.testing.assert_array_equal(multi.x, again.x)
    with pytest.raises(cr.InvalidParameter, match="starts"):
        cr.solve(problem, starts=0)


def test_multi_start_returns_the_best_of_its_starts_each_solved_alone():
    # Brute force against the screened multi-start: each of its starts (the default one and those drawn
    # log-uniformly within the bounds by the seeded generator) solved alone to the full tolerance. On the
    # README's double pendulum the first joint's direction is flat and the starts reach local optima 0.2 %
    # apart, so a screening that dropped the best start's path would miss it by far more than the tolerance.
    arm = cr.Arm.from_example_robot_data("double_pendulum")
    kin = arm.kinematics(arm.sample_configurations(8, np.random.default_rng(1)))
    samples = cr.ContactSamples.grid(kin, cr.arm.circle_directions(8))
    space = cr.DesignSpace(
        stator_diameter=(0.02, 0.12),
        gear_ratio=(1, 50),
        software_stiffness=(5, 500),
        threshold=(1, 10),
        approach_velocity=(0.05, 1.0),
    )
    technology = cr.ActuatorTechnology(cr.reference_motor(), mechanical_stiffness=500.0)
    constraints = cr.Constraints(payload=0.2, safety_factor=1.5, threshold_floor=2.0)
    problem = cr.build_problem(arm, samples, space, technology, "worst_case_impulse", constraints)
    rng, n = np.random.default_rng(0), problem.layout.size
    starts = [problem.x0]
    for _ in range(4):
        drawn = problem.x0.copy()
        drawn[:n] = rng.uniform(problem.lbx[:n], problem.ubx[:n])
        starts.append(problem.exact_point(drawn))
    alone = [problem.objective_value(cr.solve(problem, x0=start).x) for start in starts]
    assert max(alone) > min(alone) * (1 + 1e-3)  # the starts do reach different optima
    multi = problem.objective_value(cr.solve(problem, starts=5).x)
    # IPOPT's tol = 1e-8 repeats an optimum's objective to about 1e-7 relative (MERGE_TOLERANCE's reasoning).
    assert multi <= min(alone) * (1 + 1e-6)


def test_solver_failed_message_and_pickling():
    import pickle

    error = cr.errors.SolverFailed(
        "could not meet x", "Infeasible_Problem_Detected", {"iter_count": 3}, [("x", 1.0)], problem=object()
    )
    assert str(error) == "could not meet x"
    copy = pickle.loads(pickle.dumps(error))
    assert (str(copy), copy.status, copy.violated, copy.problem) == (
        str(error),
        error.status,
        error.violated,
        None,
    )


def test_a_sweep_point_round_trips_through_json_bitwise(arm):
    import json

    from collision_reflex.optimize.results import SweepPoint, result_to_json

    samples = _samples(arm, 2, 3)
    problem = cr.build_problem(arm, samples, FREE_SPACE, _technology(), "worst_case_impulse")
    result = cr.solve(problem)
    point = SweepPoint("optimum", result)
    again = SweepPoint.from_json(json.loads(json.dumps(point.to_json())))
    assert again.label == "optimum" and again.failures == ()
    assert result_to_json(again.result) == result_to_json(result)  # every float the same, to the last bit
    np.testing.assert_array_equal(again.result.design.gear_ratio, result.design.gear_ratio)
    np.testing.assert_array_equal(again.result.x, result.x)


def test_dominating_matches_brute_force_dominance():
    from types import SimpleNamespace

    from collision_reflex.optimize.pareto import ParetoSet

    names = ("worst_case_impulse", "approach_velocity")  # approach velocity is maximised
    rng = np.random.default_rng(5)
    front_values = rng.uniform(0.1, 1.0, size=(8, 2))
    front = ParetoSet(
        names,
        tuple(SimpleNamespace(numpy_objectives=dict(zip(names, v, strict=True))) for v in front_values),
    )
    for candidate in rng.uniform(0.1, 1.0, size=(200, 2)):
        beats = [
            i
            for i, (impulse, velocity) in enumerate(front_values)
            if impulse <= candidate[0]
            and velocity >= candidate[1]
            and (impulse < candidate[0] or velocity > candidate[1])
        ]
        found = front.dominating(dict(zip(names, candidate, strict=True)))
        assert found == (beats[0] if beats else None), (candidate, beats, found)
    # Worse by less than the dominance tolerance (1e-9 relative) is a tie, not domination; by 1e-6 it is.
    single = ParetoSet(names, (SimpleNamespace(numpy_objectives={names[0]: 1.0, names[1]: 0.5}),))
    assert single.dominating({names[0]: 1.0 + 1e-12, names[1]: 0.5}) is None
    assert single.dominating({names[0]: 1.0 + 1e-6, names[1]: 0.5}) == 0
    assert single.dominating({names[0]: 1.0, names[1]: 0.5 - 1e-6}) == 0


def test_failed_solves_are_recorded_in_one_vocabulary(arm, monkeypatch):
    from collision_reflex.errors import SolverFailed
    from collision_reflex.optimize import pieces
    from collision_reflex.optimize.pareto import pareto_front
    from collision_reflex.optimize.results import PointFailure

    samples = _samples(arm, 2, 3)
    space = cr.DesignSpace(
        stator_diameter=(0.02, 0.12),
        gear_ratio=(1, 30),
        software_stiffness=(5, 500),
        threshold=(1, 10),
        approach_velocity=0.3,
    )
    technology, names = _technology(), ("worst_case_impulse", "actuator_mass")

    def build(objective, bounded):
        return cr.build_problem(arm, samples, space, technology, objective, cr.Constraints(), bounded)

    original, calls = pieces.solve, []

    def fail_some(problem, epsilon=None, *args, **kwargs):
        calls.append(dict(epsilon or {}))
        # The worst-case anchor's lexicographic step (mass minimised, impulse held), and the second point.
        if (epsilon and problem.objective == {"actuator_mass": 1.0} and "worst_case_impulse" in epsilon) or (
            len(calls) == 6
        ):
            raise SolverFailed("no way", "Infeasible_Problem_Detected", {}, [])
        return original(problem, epsilon, *args, **kwargs)

    monkeypatch.setattr(pieces, "solve", fail_some)
    front = pareto_front(build, names, points=5)
    lexicographic, point = front.failed
    assert lexicographic == PointFailure(
        "actuator_mass", calls[1], "Infeasible_Problem_Detected", "no way"
    ) and set(calls[1]) == {"worst_case_impulse"}
    assert point == PointFailure("worst_case_impulse", calls[5], "Infeasible_Problem_Detected", "no way")
    # The anchor found before its failed step is kept (front or dominated); the failed point is in neither.
    labels = front.labels + front.dominated_labels
    assert "anchor: worst_case_impulse" in labels and len(labels) == 2 + 3 - 1
    assert not any(r.epsilon == calls[5] for r in (*front.points, *front.dominated))


@pytest.mark.parametrize(
    ("keyword", "value"),
    [
        ("points", 1),
        ("anchor_starts", 0),
        ("anchor_starts", 1.5),
        ("runner", Runner(in_flight=0)),
        ("objectives", ("mass",)),
    ],
)
def test_pareto_front_refuses_bad_settings_before_building(keyword, value):
    from collision_reflex.errors import InvalidParameter

    def build(objective, bounded):
        raise AssertionError("nothing is built for bad settings")

    with pytest.raises(InvalidParameter):
        cr.pareto_front(build, **{keyword: value})


def test_a_single_contact_sample_is_a_problem_like_any_other():
    """One configuration and one direction: the CasADi and NumPy paths agree (a 1x1 expression once broke the
    reaction-capacity rows with a dimension error)."""
    arm = cr.Arm.from_example_robot_data("double_pendulum")
    samples = cr.ContactSamples.grid(arm.kinematics(np.array([[0.3, 0.5]])), np.array([[1.0, 0.0]]))
    space = cr.DesignSpace(
        stator_diameter=(0.02, 0.12),
        gear_ratio=(1, 30),
        software_stiffness=300.0,
        threshold=(3, 20),
        approach_velocity=(0.02, 2.0),
    )
    technology = cr.ActuatorTechnology(cr.reference_motor(), mechanical_stiffness=[600.0, 400.0])
    problem = cr.build_problem(
        arm, samples, space, technology, "worst_case_impulse", cr.Constraints(payload=0.5, safety_factor=1.5)
    )
    result = cr.solve(problem)
    assert result.objectives["worst_case_impulse"] == pytest.approx(
        result.numpy_objectives["worst_case_impulse"], rel=1e-6
    )


def test_undecided_variables_are_the_ones_no_impulse_or_mass_depends_on(arm):
    """Contact forces along link 2 through the tip exert no torque about joint 2: its gear ratio and software
    stiffness change no impulse (and not the mass) anywhere in their bounds, and only they are undecided. Checked
    against values the probes never try, and against every other free variable moving some impulse."""
    q = np.array([[0.4, 0.9]])
    along = np.array([np.cos(1.3), np.sin(1.3)])  # link 2's direction at q1 + q2 = 1.3 rad
    samples = cr.ContactSamples.grid(arm.kinematics(q), np.stack([along, -along, [0.0, 1.0]]))
    constraints = cr.Constraints(torque_required=[1.0, 0.5], threshold_floor=0.5)
    problem = cr.build_problem(arm, samples, FREE_SPACE, _technology(), "worst_case_impulse", constraints)
    result = cr.solve(problem)
    # The third direction loads joint 2: nothing is undecided.
    assert undecided_variables(problem, result.x) == []

    radial = cr.ContactSamples.grid(arm.kinematics(q), np.stack([along, -along]))
    assert np.abs(radial.joint_moment_arms[:, 1]).max() < 1e-12 * np.abs(radial.joint_moment_arms).max()
    problem = cr.build_problem(arm, radial, FREE_SPACE, _technology(), "worst_case_impulse", constraints)
    result = cr.solve(problem)
    found = undecided_variables(problem, result.x)
    assert found == [("gear_ratio", 1), ("software_stiffness", 1)]

    base = _numpy_impulses(problem, result.x[: problem.layout.size])
    rng = np.random.default_rng(7)
    for name, joint in found:
        k = problem.layout.slices[name][joint]
        for value in rng.uniform(problem.lbx[k], problem.ubx[k], 3):
            z = result.x[: problem.layout.size].copy()
            z[k] = value
            np.testing.assert_allclose(_numpy_impulses(problem, z), base, rtol=1e-12)
    for name, indices in problem.layout.slices.items():
        for joint, k in enumerate(indices):
            if k is None or (name, joint) in found or problem.lbx[k] == problem.ubx[k]:
                continue
            changes = []
            for value in (problem.lbx[k], problem.ubx[k]):
                z = result.x[: problem.layout.size].copy()
                z[k] = value
                changes.append(np.max(np.abs(_numpy_impulses(problem, z) / base - 1)))
            assert max(changes) > 1e-6, (name, joint)
