"""One reference motor per joint: a catalogue motor at its own size gives its datasheet figures (scale one)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import collision_reflex as cr
from collision_reflex.arm import Arm
from collision_reflex.optimize.design import design_at

TWO_LINK = Path(__file__).resolve().parents[1] / "designs" / "planar_two_link.urdf"
SMALL = cr.Motor("small", 0.03, 0.01, 3e-6, 0.3, 0.1, 0.08, source="test motor")
LARGE = cr.Motor("large", 0.09, 0.02, 2e-4, 6.0, 2.2, 0.9, source="test motor")


@pytest.fixture(scope="module")
def samples():
    arm = Arm.from_urdf(TWO_LINK, "tip")
    kin = arm.kinematics(arm.sample_configurations(3, np.random.default_rng(0)))
    angles = np.linspace(0, 2 * np.pi, 4, endpoint=False) + 0.3
    return arm, cr.ContactSamples.grid(kin, np.c_[np.cos(angles), np.sin(angles)])


def _space(**kwargs):
    base = dict(
        stator_diameter=(0.02, 0.12),
        gear_ratio=(1, 30),
        software_stiffness=(5, 500),
        threshold=(1, 10),
        approach_velocity=(0.05, 1.0),
    )
    return cr.DesignSpace(**{**base, **kwargs})


def test_catalogue_motors_at_their_own_size_keep_their_figures(samples):
    arm, contact = samples
    technology = cr.ActuatorTechnology((LARGE, SMALL), mechanical_stiffness=200.0)
    space = _space(stator_diameter=[0.09, 0.03], stack_length=None)
    problem = cr.build_problem(
        arm, contact, space, technology, constraints=cr.Constraints(torque_required=[2, 1])
    )
    design = design_at(problem, problem.x0)
    np.testing.assert_allclose(design.motor_mass, [0.9, 0.08], rtol=1e-12)
    np.testing.assert_allclose(design.stack_length, [0.02, 0.01], rtol=1e-12)
    np.testing.assert_allclose(design.reflected_inertia, design.gear_ratio**2 * [2e-4, 3e-6], rtol=1e-12)
    np.testing.assert_allclose(design.motor_peak_torque, [6.0, 0.3], rtol=1e-12)


def test_a_tuple_of_one_motor_equals_the_single_reference(samples):
    arm, contact = samples
    constraints = cr.Constraints(torque_required=[2, 1])
    one = cr.build_problem(
        arm, contact, _space(), cr.ActuatorTechnology(LARGE, 200.0), constraints=constraints
    )
    two = cr.build_problem(
        arm, contact, _space(), cr.ActuatorTechnology((LARGE, LARGE), 200.0), constraints=constraints
    )
    a, b = cr.solve(one), cr.solve(two)
    assert b.success and a.success
    assert b.objectives["worst_case_impulse"] == pytest.approx(a.objectives["worst_case_impulse"], rel=1e-7)
    np.testing.assert_allclose(b.design.stator_diameter, a.design.stator_diameter, rtol=1e-7)


def test_a_wrong_number_of_joint_motors_is_refused(samples):
    arm, contact = samples
    with pytest.raises(cr.InvalidParameter, match="reference_motor"):
        cr.build_problem(arm, contact, _space(), cr.ActuatorTechnology((LARGE, SMALL, SMALL), 200.0))
    with pytest.raises(cr.InvalidParameter, match="reference_motor"):
        cr.ActuatorTechnology(("not a motor",), 200.0)
