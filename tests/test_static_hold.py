"""The static hold: with a duty cycle or a rated motion the joints must also hold the arm and its payload still."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from collision_reflex.arm.dynamics import peak
from collision_reflex.optimize.optimum import single_optimum
from collision_reflex.optimize.pieces import built_problem
from collision_reflex.optimize.results import design_record
from collision_reflex.study.load import load_study
from collision_reflex.study.problems import StudyProblems
from collision_reflex.study.resolve import resolve_study

pytestmark = pytest.mark.xdist_group("test_static_hold")  # one pytest-xdist worker: set-ups made once

ROOT = Path(__file__).resolve().parents[1]


def _solved(name: str):
    problems = StudyProblems(resolve_study(load_study(ROOT / "studies" / f"{name}.yaml")))
    optimum, _ = single_optimum(problems, problems.objective, starts=1)
    return problems, built_problem(problems, problems.objective), optimum


@pytest.fixture(scope="module")
def panda():
    return _solved("panda")


@pytest.fixture(scope="module", params=["panda", "ur5"])
def shipped(request):
    return _solved(request.param)


def _gravity_demand(kinematics, payload, masses):
    """|gravity torque| [N m] of the links, the payload at the contact point and the actuators, per configuration."""
    motors = np.einsum("cij,i->cj", kinematics.motor_gravity, masses)
    return np.abs(kinematics.gravity + payload * kinematics.contact_gravity + motors)


def test_the_peak_requirement_is_the_larger_of_the_static_hold_and_the_cycle(panda):
    problems, problem, optimum = panda
    setup, design = problems.setup, optimum.design
    factor = setup.constraints.safety_factor
    # Written out here: the static hold over the sampled configurations (Pinocchio's gravity terms); the
    # cycle's peak from its torques over time, rotor term included.
    # The sampled configurations and each joint's searched worst pose.
    static = factor * np.vstack(
        [
            _gravity_demand(kinematics, setup.constraints.payload, design.actuator_mass)
            for kinematics in (setup.samples.kinematics, setup.constraints.hold_poses)
        ]
    )
    demand = problem.duty.demand(design.actuator_mass, design.reflected_inertia)
    sources = np.array(problem.duty.torques.sources)
    moving = {source: factor * peak(demand[sources == source].T) for source in set(sources)}
    assert set(moving) == {
        "duty cycle",
        "rated motion",
    }  # the study's cycle and its rating (no stopping time)
    envelope = np.maximum.reduce([static.max(axis=0), *moving.values()])
    # The study builds the arm of two modules, joints 1-4 and 5-7: each meets the largest need of its joints.
    modules = [range(0, 4), range(4, 7)]
    module_of = {j: list(m) for m in modules for j in m}
    np.testing.assert_allclose(
        optimum.required_torque, [envelope[module_of[j]].max() for j in range(7)], rtol=1e-9
    )
    record = design_record(problem, optimum, "optimum")
    names = problem.joint_names
    for j, joint in enumerate(record["joints"]):
        k = max(module_of[j], key=lambda m: envelope[m])
        largest = max(
            [("static hold", static.max(axis=0)[k])] + [(s, v[k]) for s, v in moving.items()],
            key=lambda p: p[1],
        )
        assert joint["required_by"] == (largest[0] if k == j else f"{largest[0]} of {names[k]}")
        assert joint["module"] == [names[m] for m in module_of[j]]
    assert np.all(design.driving_peak_torque >= optimum.required_torque * (1 - 1e-7))


def test_the_design_holds_its_payload_still_at_fresh_configurations(shipped):
    problems, _, optimum = shipped
    setup, design = problems.setup, optimum.design
    rng = np.random.default_rng(2026)
    draw = setup.domain.draw(setup.arm, 10_000, setup.directions, design.approach_velocity, rng)
    demand = _gravity_demand(setup.arm.kinematics(draw.q), setup.constraints.payload, design.actuator_mass)
    # Without the safety factor: the sampled configurations carry it, fresh ones must at least be held.
    assert np.all(design.driving_peak_torque >= demand.max(axis=0))


@pytest.mark.parametrize("robot", ["ur5", "panda"])
def test_each_joints_worst_hold_pose_is_found(robot):
    # Brute force: 20,000 uniform configurations within the joint limits (another generator); the searched pose
    # of each joint needs at least their largest holding torque of it (within 0.1 %).
    from collision_reflex.arm import Arm
    from collision_reflex.arm.static_hold import hold_torques, worst_hold_poses

    arm = Arm.from_example_robot_data(robot)
    masses = np.linspace(2.0, 0.5, arm.nv)
    poses = worst_hold_poses(arm, 3.0, masses, np.random.default_rng(0))
    found = np.abs(hold_torques(arm.kinematics(poses), 3.0, masses)).diagonal()
    drawn = arm.sample_configurations(20_000, np.random.default_rng(7))
    brute = np.abs(hold_torques(arm.kinematics(drawn), 3.0, masses)).max(axis=0)
    assert np.all(found >= brute * (1 - 1e-3) - 1e-9), (found, brute)  # 1e-9 N m: joints gravity never loads
    # Written out for one pose: the torque is Pinocchio's gravity torque with the masses where they are.
    np.testing.assert_allclose(
        found, _gravity_demand(arm.kinematics(poses), 3.0, masses).diagonal(), rtol=1e-12
    )


def test_the_static_hold_rows_hold_the_searched_poses(panda):
    problems, problem, optimum = panda
    setup, design = problems.setup, optimum.design
    hold = setup.constraints.hold_poses
    assert hold is not None and hold.gravity.shape[0] == len(problem.joint_names)
    at_poses = setup.constraints.safety_factor * _gravity_demand(
        hold, setup.constraints.payload, design.actuator_mass
    )
    static = np.asarray(problem.static_torque_function(design.actuator_mass)).ravel()
    assert np.all(static >= at_poses.max(axis=0) * (1 - 1e-12))
    # Where a searched pose binds for the masses of the start, the problem has its row, and says so.
    assert any("worst hold pose" in label for label in problem.constraint_labels)
