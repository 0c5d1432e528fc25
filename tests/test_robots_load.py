"""Stock robots read without their meshes equal the ones example-robot-data's loader builds."""

from __future__ import annotations

import numpy as np
import pytest

from collision_reflex.arm.robots import _kinematic_model

example_robot_data = pytest.importorskip("example_robot_data")


@pytest.mark.parametrize("name", ["panda", "ur5", "double_pendulum", "solo12"])
def test_the_model_without_meshes_equals_the_loaders(name):
    import pinocchio as pin

    fast = _kinematic_model(name)
    assert fast is not None
    model, urdf, q0 = fast
    robot = example_robot_data.load(name)
    reference = robot.model
    assert urdf == str(robot.urdf)
    assert model.nq == reference.nq and model.nv == reference.nv
    assert [j for j in model.names] == [j for j in reference.names]
    np.testing.assert_array_equal(q0, np.asarray(robot.q0))
    # Same inertial model: the mass matrix at random configurations, to float rounding.
    data, reference_data = model.createData(), reference.createData()
    for _ in range(3):
        q = pin.randomConfiguration(model, -np.ones(model.nq), np.ones(model.nq))
        np.testing.assert_allclose(
            pin.crba(model, data, q), pin.crba(reference, reference_data, q), rtol=0, atol=1e-12
        )
