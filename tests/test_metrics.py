"""Transparency metrics: inertia and manipulability ellipsoids, effective mass, impact mitigation factor.

Tolerances: 1e-12 for the same arithmetic in another order; 1e-10 to 1e-9 for other algorithms (explicit
inverses, another Pinocchio model) on small, well-conditioned matrices.
"""

from __future__ import annotations

import itertools
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

from collision_reflex.arm import Arm, effective_parameters
from collision_reflex.arm.directions import circle_directions, sphere_directions
from collision_reflex.arm.metrics import (
    dynamic_manipulability_ellipsoid,
    effective_mass,
    ellipsoid_of_gyration,
    generalized_inertia_ellipsoid,
    impact_mitigation_factor,
)
from collision_reflex.arm.robots import example_robot
from collision_reflex.errors import FrameNotFound, InvalidParameter

TWO_LINK = Path(__file__).resolve().parents[1] / "designs" / "planar_two_link.urdf"
ROTOR = np.array([2e-3, 1e-3])  # reflected rotor inertia of the two joints [kg m^2]


@pytest.fixture(scope="module")
def two_link_samples():
    arm = Arm.from_urdf(TWO_LINK, "tip")
    return arm.kinematics(np.array([[0.3, 1.1], [-0.5, 2.0]]))


def test_generalized_inertia_is_j_inverse_transpose_m_j_inverse(two_link_samples):
    ellipsoid = generalized_inertia_ellipsoid(two_link_samples, ROTOR)
    for s in range(2):
        inverse = np.linalg.inv(two_link_samples.jacobian[s])
        full = two_link_samples.mass_matrix[s] + np.diag(ROTOR)
        # The paper's J^-T M J^-1 for a square Jacobian; a different route to the same 2x2 matrix.
        np.testing.assert_allclose(ellipsoid.matrix[s], inverse.T @ full @ inverse, rtol=1e-10)
    gyration = ellipsoid_of_gyration(two_link_samples, ROTOR)
    np.testing.assert_allclose(
        gyration.matrix @ ellipsoid.matrix, np.broadcast_to(np.eye(2), (2, 2, 2)), atol=1e-10
    )


def test_dynamic_manipulability(two_link_samples):
    ellipsoid = dynamic_manipulability_ellipsoid(two_link_samples, ROTOR)
    for s in range(2):
        jac, full = two_link_samples.jacobian[s], two_link_samples.mass_matrix[s] + np.diag(ROTOR)
        expected = jac @ np.linalg.inv(full.T @ full) @ jac.T
        np.testing.assert_allclose(ellipsoid.matrix[s], expected, rtol=1e-10)
    # Semi-axes are the square roots of the eigenvalues: the largest reachable task accelerations per N m.
    assert np.all(ellipsoid.semi_axes > 0)


def test_effective_mass_is_the_finger_mass_without_rotors(two_link_samples):
    u = circle_directions(12)
    structure_only = effective_mass(two_link_samples, u)
    params = effective_parameters(two_link_samples, u, 1.0, 1.0, 1.0, 1.0)
    np.testing.assert_allclose(structure_only, params.m_f, rtol=1e-12)
    # Adding rotor inertia can only make the arm heavier in every direction.
    assert np.all(effective_mass(two_link_samples, u, ROTOR) > structure_only)


def test_singular_configuration():
    arm = Arm.from_urdf(TWO_LINK, "tip")
    samples = arm.kinematics(np.array([[0.0, 0.0]]))
    masses = effective_mass(samples, [[1.0, 0.0], [0.0, 1.0]])
    assert masses[0, 0] == np.inf and np.isfinite(masses[0, 1])
    assert np.all(np.isfinite(ellipsoid_of_gyration(samples).matrix))
    with pytest.raises(InvalidParameter, match="ellipsoid_of_gyration"):
        generalized_inertia_ellipsoid(samples)


def test_redundant_arm_ellipsoids():
    panda = Arm.from_example_robot_data("panda")
    samples = panda.kinematics(panda.sample_configurations(3, np.random.default_rng(8)))
    ellipsoid = generalized_inertia_ellipsoid(samples, 0.1)
    u = sphere_directions(10)
    # u^T Lambda_0^-1 u is the inverse effective mass: two routes, one answer.
    np.testing.assert_allclose(
        1 / ellipsoid_of_gyration(samples, 0.1).along(u), effective_mass(samples, u, 0.1), rtol=1e-12
    )
    assert ellipsoid.matrix.shape == (3, 3, 3)


@pytest.mark.parametrize("robot", ["solo12", "a1"], ids=str)
def test_impact_mitigation_against_a_locked_model(robot):
    result = impact_mitigation_factor(robot, 0.01)
    # Independent locked system: Pinocchio's reduced model with every actuated joint locked (one rigid body).
    model = example_robot(robot)[0]
    locked = pin.buildReducedModel(model, list(range(2, model.njoints)), result.q)
    data = locked.createData()
    q_base = result.q[:7]
    mass = pin.crba(locked, data, q_base)
    jac = pin.computeFrameJacobian(
        locked, data, q_base, locked.getFrameId(result.contact_frame), pin.LOCAL_WORLD_ALIGNED
    )[:3]
    expected_locked = np.linalg.inv(jac @ np.linalg.inv(mass) @ jac.T)
    np.testing.assert_allclose(result.locked_inertia, expected_locked, rtol=1e-9)
    assert 0.0 < result.factor < 1.0


def test_impact_mitigation_decreases_with_rotor_inertia():
    factors = [impact_mitigation_factor("solo12", inertia).factor for inertia in (0.0, 1e-3, 1e-2, 1e-1, 1e2)]
    assert all(b < a for a, b in itertools.pairwise(factors)), factors
    # Huge reflected inertia behaves as locked joints: the factor tends to 0.
    assert factors[-1] < 1e-3


def test_impact_mitigation_errors():
    with pytest.raises(FrameNotFound):
        impact_mitigation_factor("solo12", 0.01, contact_frame="paw")
    with pytest.raises(InvalidParameter, match="floating-base"):
        impact_mitigation_factor("ur5", 0.01, contact_frame="tool0")
