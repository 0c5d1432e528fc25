"""The effective parameters are written once (collision_reflex.model.effective): the NumPy arm path and the CasADi
design problem must give the same numbers for the same design.

A design inside the bounds (off the midpoints, drawn with a fixed seed) is evaluated twice: through
:func:`collision_reflex.arm.effective_parameters` on the problem's samples, and through the problem's per-sample
CasADi expressions at that design (:meth:`DesignProblem.sample_parameters`). The two paths share the formulas but
not the arithmetic (NumPy's batched task-space forms ``u^T J X^-1 J^T u`` against CasADi's per-sample
``w^T X^-1 w`` and the variational finger mass ``x^T M_f x``), so they differ by rounding only: a few ``eps``
(measured below 3e-15 on these samples; the finger mass can lose up to ``eps * cond(M_f)``). Tolerance 1e-12
relative. A factor error in any formula (a missing motor mass, a misplaced reflected inertia, a
wrong threshold) moves a quantity by far more.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import collision_reflex as cr
from collision_reflex.arm import Arm, effective_parameters
from collision_reflex.arm.directions import circle_directions, sphere_directions
from collision_reflex.model.effective import finger_inertia
from collision_reflex.model.impulse import series_stiffness
from collision_reflex.model.sensing import threshold_force
from collision_reflex.optimize.design import design_at

TWO_LINK = Path(__file__).resolve().parents[1] / "designs" / "planar_two_link.urdf"
RTOL = 1e-12

# (arm, joint mechanical stiffness [N m/rad], force threshold bounds [N], position threshold bounds [m])
ROBOTS = {
    "panda": (lambda: Arm.from_example_robot_data("panda"), 2e4),
    "ur5": (lambda: Arm.from_example_robot_data("ur5"), 3e4),
    "two_link": (lambda: Arm.from_urdf(TWO_LINK, "tip"), 200.0),
}
THRESHOLDS = {"force": (1.0, 20.0), "position": (1e-3, 2e-2)}


@pytest.fixture(scope="module", params=sorted(ROBOTS))
def robot(request):
    load, k_mech = ROBOTS[request.param]
    arm = load()
    kinematics = arm.kinematics(arm.sample_configurations(3, np.random.default_rng(4)))
    directions = circle_directions(5, 0.2) if arm.task_dim == 2 else sphere_directions(5)
    return arm, cr.ContactSamples.grid(kinematics, directions), k_mech


def _problem(arm, samples, k_mech, sensing, placement):
    space = cr.DesignSpace(
        stator_diameter=(0.03, 0.1),
        gear_ratio=(1, 80),
        software_stiffness=(50, 5000),
        threshold=THRESHOLDS[sensing],
        approach_velocity=(0.05, 0.5),
    )
    technology = cr.ActuatorTechnology(
        cr.reference_motor(), mechanical_stiffness=k_mech, sensing=sensing, reflected_inertia_in=placement
    )
    constraints = cr.Constraints(torque_required=np.full(arm.nv, 1.0))
    return cr.build_problem(arm, samples, space, technology, constraints=constraints)


def _numpy_parameters(problem, x):
    """The NumPy path: the design's joint quantities into the batched arm formulas."""
    design = design_at(problem, x)
    samples = problem.samples
    placement = problem.technology.reflected_inertia_in
    params = effective_parameters(
        samples.kinematics,
        samples.directions,
        config_index=samples.config_index,
        reflected_inertia=design.reflected_inertia,
        stiffness=series_stiffness(design.mechanical_stiffness, design.software_stiffness),
        mechanical_stiffness=design.mechanical_stiffness,
        torque_limit=design.peak_torque,
        motor_mass=design.motor_mass,
        finger_joint_inertia=finger_inertia(design.reflected_inertia, float(placement == "finger")),
    )
    threshold = threshold_force(problem.technology.sensing, design.threshold, params.k)
    return {"m_f": params.m_f, "m_r": params.m_r, "k": params.k, "k_m": params.k_m, "a": params.a}, threshold


@pytest.mark.parametrize("placement", ["robot", "finger"])
@pytest.mark.parametrize("sensing", ["force", "position"])
def test_numpy_and_casadi_effective_parameters_agree(robot, sensing, placement):
    arm, samples, k_mech = robot
    problem = _problem(arm, samples, k_mech, sensing, placement)
    lower, upper = problem.lbx[: problem.layout.size], problem.ubx[: problem.layout.size]
    x = problem.x0.copy()
    x[: problem.layout.size] = np.random.default_rng(7).uniform(lower, upper)

    casadi_values = problem.sample_parameters(x)
    numpy_values, numpy_threshold = _numpy_parameters(problem, x)
    for name, value in numpy_values.items():
        np.testing.assert_allclose(casadi_values[name], value, rtol=RTOL, err_msg=name)
    np.testing.assert_allclose(casadi_values["F_s"], numpy_threshold, rtol=RTOL, err_msg="F_s")


def test_the_comparison_sees_a_misplaced_reflected_inertia(robot):
    """The finger placement must change m_f by far more than the tolerance, or the test above proves nothing."""
    arm, samples, k_mech = robot
    robot_problem = _problem(arm, samples, k_mech, "force", "robot")
    finger_problem = _problem(arm, samples, k_mech, "force", "finger")
    x = robot_problem.x0.copy()
    m_f_robot = robot_problem.sample_parameters(x)["m_f"]
    m_f_finger = finger_problem.sample_parameters(x)["m_f"]
    assert np.min(m_f_finger / m_f_robot - 1) > 1e3 * RTOL
