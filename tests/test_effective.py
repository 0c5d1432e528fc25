"""Effective collision parameters and impulses of arms, against independent computations.

The formulas are those of the paper's "Collision Reflex in Higher Dimensions".

Tolerances: 1e-14 to 1e-12 where the same formula is evaluated in another order (rounding only); 1e-10 to 1e-9
where a different algorithm computes the same quantity (LU solve against Pinocchio's ABA-based inverse, an
explicit inverse against the SVD) on matrices with condition numbers up to about 1e3.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

from collision_reflex.arm import Arm, JointParameters, collision_impulses, effective_parameters
from collision_reflex.arm.directions import circle_directions, sphere_directions, unit_directions
from collision_reflex.errors import InvalidParameter
from collision_reflex.model import impulse

TWO_LINK = Path(__file__).resolve().parents[1] / "designs" / "planar_two_link.urdf"

# Joint actuation for the tests: reflected inertia [kg m^2], torque limit [N m], stiffnesses [N m/rad].
PANDA_JOINTS = dict(
    reflected_inertia=np.array([0.6, 0.6, 0.5, 0.5, 0.2, 0.2, 0.1]),
    stiffness=np.array([900.0, 900.0, 700.0, 700.0, 300.0, 300.0, 200.0]),
    mechanical_stiffness=np.array([5e4, 5e4, 4e4, 4e4, 2e4, 2e4, 1e4]),
    torque_limit=np.array([87.0, 87.0, 87.0, 87.0, 12.0, 12.0, 12.0]),
)
TWO_LINK_JOINTS = dict(
    reflected_inertia=np.array([2.21e-5, 2.21e-5]),
    stiffness=np.array([50.0, 30.0]),
    mechanical_stiffness=np.array([300.0, 200.0]),
    torque_limit=np.array([1.3, 1.3]),
)


@pytest.fixture(scope="module")
def panda() -> Arm:
    return Arm.from_example_robot_data("panda")


@pytest.fixture(scope="module")
def panda_samples(panda):
    return panda.kinematics(panda.sample_configurations(6, np.random.default_rng(2)))


@pytest.fixture(scope="module")
def two_link() -> Arm:
    return Arm.from_urdf(TWO_LINK, "tip")


def _reference(arm: Arm, q: np.ndarray, u: np.ndarray, joints: dict) -> dict:
    """One (q, u) pair the plain way: Pinocchio's frame Jacobian and explicit matrix inverses."""
    model, data = arm.model.copy(), None
    model.armature = np.zeros(arm.nv)
    data = model.createData()
    frame = model.getFrameId(arm.contact_frame)
    pin.computeJointJacobians(model, data, q)
    pin.updateFramePlacements(model, data)
    jac = pin.getFrameJacobian(model, data, frame, pin.LOCAL_WORLD_ALIGNED)[:3]
    if arm.plane is not None:
        jac = arm.plane.T @ jac
    moment = jac.T @ u
    minv = pin.computeMinverse(model, data, q)
    return {
        "m_f": 1 / (moment @ minv @ moment),
        "m_r": 1 / (moment @ np.diag(1 / joints["reflected_inertia"]) @ moment),
        "k": 1 / (moment @ np.diag(1 / joints["stiffness"]) @ moment),
        "k_m": 1 / (moment @ np.diag(1 / joints["mechanical_stiffness"]) @ moment),
        "F_a": min(t / abs(c) for t, c in zip(joints["torque_limit"], moment, strict=True) if c != 0),
    }


def test_effective_mass_against_pinocchio_minverse(panda, panda_samples):
    directions = sphere_directions(16)
    params = effective_parameters(panda_samples, directions, **PANDA_JOINTS)
    assert params.shape == (6, 16) and not params.singular.any()
    for s in range(panda_samples.count):
        for d in range(16):
            expected = _reference(panda, panda_samples.q[s], directions[d], PANDA_JOINTS)
            # Cholesky/LU solve against Pinocchio's ABA-based inverse: agreement to ~1e-10 relative, well
            # within the conditioning of a 7x7 mass matrix (cond ~ 1e3).
            for name in ("m_f", "m_r", "k", "k_m", "F_a"):
                assert getattr(params, name)[s, d] == pytest.approx(expected[name], rel=1e-9), name
            assert params.a[s, d] == pytest.approx(expected["F_a"] / expected["m_r"], rel=1e-9)


def test_reaction_force_is_the_largest_feasible(panda, panda_samples):
    """Brute force: scale the force along u until a joint saturates."""
    u = sphere_directions(5)
    params = effective_parameters(panda_samples, u, **PANDA_JOINTS)
    moments = np.einsum("std,kt->skd", panda_samples.jacobian, u)
    limit = PANDA_JOINTS["torque_limit"]
    for s in range(panda_samples.count):
        for d in range(5):
            f = params.F_a[s, d]
            assert np.all(np.abs(moments[s, d] * f) <= limit * (1 + 1e-12))  # feasible, to rounding
            assert np.any(np.abs(moments[s, d] * f * (1 + 1e-9)) > limit)  # and not a bit more


def test_grid_equals_paired_equals_loop(panda, panda_samples):
    directions = sphere_directions(7)
    grid = effective_parameters(panda_samples, directions, **PANDA_JOINTS, motor_mass=np.full(7, 0.8))
    index = np.repeat(np.arange(panda_samples.count), 7)
    paired = effective_parameters(
        panda_samples,
        np.tile(directions, (panda_samples.count, 1)),
        **PANDA_JOINTS,
        motor_mass=np.full(7, 0.8),
        config_index=index,
    )
    for name in ("m_f", "m_r", "k", "k_m", "F_a", "a"):
        # Same arithmetic in another order: rounding-level agreement.
        np.testing.assert_allclose(getattr(paired, name), getattr(grid, name).ravel(), rtol=1e-12)
    for s in range(panda_samples.count):
        single = effective_parameters(
            panda_samples.take(s), directions, **PANDA_JOINTS, motor_mass=np.full(7, 0.8)
        )
        np.testing.assert_allclose(single.m_f[0], grid.m_f[s], rtol=1e-12)


def test_motor_mass_raises_the_finger_mass_only(panda, panda_samples):
    directions = sphere_directions(8)
    bare = effective_parameters(panda_samples, directions, **PANDA_JOINTS)
    heavy = effective_parameters(panda_samples, directions, **PANDA_JOINTS, motor_mass=np.full(7, 2.0))
    assert np.all(heavy.m_f >= bare.m_f * (1 - 1e-12))  # adding mass never lowers the effective mass
    assert np.any(heavy.m_f > bare.m_f * 1.01)
    np.testing.assert_array_equal(heavy.m_r, bare.m_r)


def _stretched(two_link: Arm, q2: float) -> tuple:
    samples = two_link.kinematics(np.array([[0.3, q2]]))
    along = np.array([np.cos(0.3), np.sin(0.3)])  # the arm's own line: the singular direction at q2 = 0
    across = np.array([-np.sin(0.3), np.cos(0.3)])
    return samples, np.stack([along, across])


def test_singular_direction_is_infinite_and_flagged(two_link):
    samples, directions = _stretched(two_link, 0.0)
    params = effective_parameters(samples, directions, **TWO_LINK_JOINTS)
    assert params.singular.tolist() == [[True, False]]
    for name in ("m_f", "m_r", "k", "k_m", "F_a"):
        value = getattr(params, name)
        assert value[0, 0] == np.inf and np.isfinite(value[0, 1]), name
    assert params.a[0, 0] == 0.0 and np.isfinite(params.a[0, 1])
    result = collision_impulses(params, 0.5, threshold=3.0)
    assert result.total[0, 0] == np.inf and np.isfinite(result.total[0, 1])
    for array in (result.total, result.v_star, result.threshold, params.a):
        assert not np.isnan(array).any()
    # A full sweep, including the exact singular direction, raises nothing and gives no NaN.
    # At q1 = 0 the first circle direction lies exactly along the stretched arm.
    straight = two_link.kinematics(np.array([[0.0, 0.0]]))
    sweep = collision_impulses(
        effective_parameters(straight, circle_directions(360), **TWO_LINK_JOINTS), 0.5, 3.0
    )
    assert not np.isnan(sweep.total).any()
    assert sweep.singular[0, 0] and sweep.singular[0, 180] and sweep.singular.sum() == 2


def test_near_singular_is_large_but_finite(two_link):
    samples, directions = _stretched(two_link, 1e-4)
    params = effective_parameters(samples, directions, **TWO_LINK_JOINTS)
    assert not params.singular.any()
    assert np.isfinite(params.m_f).all() and params.m_f[0, 0] > 1e4 * params.m_f[0, 1]


def test_paper_stiffness_form(two_link):
    samples = two_link.kinematics(np.array([[0.2, 0.9], [1.0, -2.0]]))
    u = circle_directions(12)
    paper = effective_parameters(samples, u, **TWO_LINK_JOINTS, stiffness_form="paper")
    compliance = effective_parameters(samples, u, **TWO_LINK_JOINTS)
    for s in range(2):
        inverse = np.linalg.inv(samples.jacobian[s])
        task = inverse.T @ np.diag(TWO_LINK_JOINTS["stiffness"]) @ inverse  # K_t of eq:eff_k
        np.testing.assert_allclose(paper.k[s], np.einsum("da,ab,db->d", u, task, u), rtol=1e-10)
    # Cauchy-Schwarz: (u^T K_t u)(u^T K_t^-1 u) >= 1, so the paper's form is never below the compliance form.
    assert np.all(paper.k >= compliance.k * (1 - 1e-12))
    with pytest.raises(InvalidParameter, match="square"):
        panda_arm = Arm.from_example_robot_data("ur5")
        effective_parameters(
            panda_arm.kinematics(np.zeros((1, 6)) + 0.3),
            sphere_directions(3),
            1.0,
            1.0,
            1.0,
            1.0,
            stiffness_form="paper",
        )


def test_paper_stiffness_at_the_singularity(two_link):
    samples, directions = _stretched(two_link, 0.0)
    paper = effective_parameters(samples, directions, **TWO_LINK_JOINTS, stiffness_form="paper")
    assert paper.k[0, 0] == np.inf and np.isfinite(paper.k[0, 1])


def test_impulses_go_through_the_1d_model(panda, panda_samples):
    u = sphere_directions(10)
    params = effective_parameters(panda_samples, u, **PANDA_JOINTS)
    result = collision_impulses(params, 0.3, threshold=5.0)
    expected = impulse.total_impulse(params.m_f, params.k, params.k_m, 5.0, params.a, 0.3)
    np.testing.assert_allclose(result.total, expected, rtol=1e-14)
    np.testing.assert_allclose(result.v_star, impulse.optimal_velocity(params.m_f, params.k, 5.0), rtol=1e-14)
    position = collision_impulses(params, 0.3, threshold=0.01, sensing="position")
    np.testing.assert_allclose(position.threshold, 0.01 * params.k, rtol=1e-14)


def test_current_threshold_is_the_first_joint_to_trip(panda, panda_samples):
    u = sphere_directions(6)
    tau_s = np.full(7, 2.0)
    params = effective_parameters(panda_samples, u, **PANDA_JOINTS, joint_threshold=tau_s)
    moments = np.abs(np.einsum("std,kt->skd", panda_samples.jacobian, u))
    np.testing.assert_allclose(params.joint_threshold_force, 2.0 / moments.max(axis=-1), rtol=1e-14)
    result = collision_impulses(params, 0.2, sensing="current")
    np.testing.assert_allclose(result.threshold, params.joint_threshold_force)
    with pytest.raises(InvalidParameter, match="joint_threshold"):
        collision_impulses(effective_parameters(panda_samples, u, **PANDA_JOINTS), 0.2, sensing="current")


@pytest.mark.parametrize("scheme", ["joint_torque", "torque"])
def test_an_unknown_sensing_scheme_is_refused(panda_samples, scheme):
    # "joint_torque" was the current scheme's name before the first release: refused like any other.
    params = effective_parameters(panda_samples, sphere_directions(4), **PANDA_JOINTS, joint_threshold=2.0)
    with pytest.raises(InvalidParameter, match="sensing"):
        collision_impulses(params, 0.2, threshold=1.0, sensing=scheme)


@pytest.mark.parametrize(
    "override, message",
    [
        ({"reflected_inertia": np.zeros(7)}, "reflected_inertia"),
        ({"torque_limit": np.full(7, np.nan)}, "pass actuators"),
        ({"stiffness": np.ones(3)}, "one per joint"),
    ],
    ids=["zero-inertia", "unknown-torque", "wrong-length"],
)
def test_bad_joint_values(panda_samples, override, message):
    with pytest.raises(InvalidParameter, match=message):
        effective_parameters(panda_samples, sphere_directions(3), **{**PANDA_JOINTS, **override})


def test_arm_uses_its_joint_parameters(two_link, panda):
    params = JointParameters(**{k: v for k, v in TWO_LINK_JOINTS.items()}, motor_mass=[0.1, 0.1])
    arm = two_link.with_actuators(params)
    samples = arm.kinematics(np.array([[0.1, 1.0]]))
    direct = effective_parameters(samples, circle_directions(4), **TWO_LINK_JOINTS, motor_mass=[0.1, 0.1])
    np.testing.assert_array_equal(arm.effective_parameters(samples, circle_directions(4)).m_f, direct.m_f)
    with pytest.raises(InvalidParameter, match="pass actuators"):
        pendulum = Arm.from_example_robot_data("double_pendulum")
        pendulum.effective_parameters(pendulum.kinematics(np.zeros((1, 2)) + 0.5), circle_directions(3))


@pytest.mark.parametrize(
    "spec, expected",
    [
        ("x", [[1, 0, 0]]),
        ("-z, y", [[0, 0, -1], [0, 1, 0]]),
        ([[1, 1, 0]], [[2**-0.5, 2**-0.5, 0]]),
    ],
    ids=["name", "list", "vector"],
)
def test_named_directions(spec, expected):
    np.testing.assert_allclose(unit_directions(spec, 3), expected, atol=1e-15)


def test_direction_sets_are_unit_and_spread():
    sphere = sphere_directions(200)
    np.testing.assert_allclose(np.linalg.norm(sphere, axis=1), 1.0, rtol=1e-14)
    # A nearly uniform set has its mean near the centre (within a few 1/count).
    assert np.linalg.norm(sphere.mean(axis=0)) < 0.02
    circle = circle_directions(8)
    np.testing.assert_allclose(circle[2], [0.0, 1.0], atol=1e-15)


def test_world_directions_project_into_the_plane():
    pendulum = Arm.from_example_robot_data("double_pendulum")  # moves in the y-z plane
    np.testing.assert_allclose(np.abs(unit_directions("down", 2, pendulum.plane)), [[0.0, 1.0]], atol=1e-15)
    with pytest.raises(InvalidParameter, match="plane"):
        unit_directions("x", 2, pendulum.plane)
