"""Where the reflected rotor inertia acts in the impact, per joint: given, or from the transmission's stiffness."""

from __future__ import annotations

import numpy as np
import pytest
import yaml

import collision_reflex as cr
from collision_reflex.arm import Arm
from collision_reflex.errors import InvalidParameter
from collision_reflex.optimize.design import design_at
from collision_reflex.optimize.evaluate import collision_parameters
from collision_reflex.optimize.technology import PLACEMENT_STIFFNESS_RATIO, placements_from_stiffness
from collision_reflex.study.load import load_study
from test_snap import OBJECTIVE, ROOT, TWO_LINK, _two_link_inputs, _two_link_samples


def _finger_masses(placement):
    """The finger mass at every sample of the two-link problem's start design, for one placement."""
    arm = Arm.from_urdf(TWO_LINK, "tip")
    samples = _two_link_samples(arm, 3, 6, seed=0)
    space, technology, constraints = _two_link_inputs()
    technology = cr.ActuatorTechnology(cr.reference_motor(), 1000.0, reflected_inertia_in=placement)
    problem = cr.build_problem(arm, samples, space, technology, OBJECTIVE, constraints)
    design = design_at(problem, problem.x0)
    params, _ = collision_parameters(samples, technology, design)
    return samples, design, params.m_f


@pytest.mark.parametrize("placement", [("finger", "robot"), ("robot", "finger"), "finger", "robot"])
def test_the_finger_mass_holds_the_rotors_of_the_joints_placed_in_the_impact(placement):
    # Independent of the code's path: m_f = 1 / (w^T M^-1 w), w = J^T u, M the joint-space inertia with the
    # actuator masses carried and N^2 J added on the diagonal of the joints placed in the impact.
    samples, design, finger = _finger_masses(placement)
    mask = np.array([p == "finger" for p in ((placement,) * 2 if isinstance(placement, str) else placement)])
    with_motors = samples.kinematics.structure_mass_matrix(design.actuator_mass)
    w = samples.joint_moment_arms
    for s in range(samples.size):
        matrix = with_motors[samples.config_index[s]] + np.diag(mask * design.reflected_inertia)
        expected = 1 / (w[s] @ np.linalg.solve(matrix, w[s]))
        assert finger[s] == pytest.approx(expected, rel=1e-9)
    # Mixed placements lie between none and both, and differ from either.
    _, _, none = _finger_masses("robot")
    _, _, both = _finger_masses("finger")
    assert np.all(none <= finger * (1 + 1e-12)) and np.all(finger <= both * (1 + 1e-12))
    if not isinstance(placement, str):
        assert np.any(finger > none * (1 + 1e-3)) and np.any(finger < both * (1 - 1e-3))


def test_per_joint_placements_must_be_one_per_joint():
    technology = cr.ActuatorTechnology(cr.reference_motor(), 1000.0, reflected_inertia_in=("finger",) * 3)
    with pytest.raises(InvalidParameter, match="reflected_inertia_in"):
        technology.finger_joints(2)
    with pytest.raises(InvalidParameter, match=r"reflected_inertia_in\[1\]"):
        cr.ActuatorTechnology(cr.reference_motor(), 1000.0, reflected_inertia_in=("finger", "rotor"))


def test_the_stiffness_rule_compares_the_transmission_with_the_contact_seen_at_the_joint():
    # Joint 1: moment arm 0.5 m along u, joint 2: 0.1 m; k_c = 1e5 N/m gives 25,000 and 1,000 N m/rad.
    arms = np.array([[0.5, 0.1], [-0.5, -0.1], [0.5, 0.1]])
    placements, ratios = placements_from_stiffness(arms, np.array([2.5e6, 50.0]), 1e5)
    np.testing.assert_allclose(ratios, [0.01, 20.0])
    assert placements == ("finger", "robot")
    # At exactly 1 / PLACEMENT_STIFFNESS_RATIO the transmission counts as the stiff side.
    edge, _ = placements_from_stiffness(arms, np.array([25_000 * PLACEMENT_STIFFNESS_RATIO, 1e9]), 1e5)
    assert edge == ("finger", "finger")


def _study(tmp_path, **changes):
    study = yaml.safe_load((ROOT / "studies" / "two_link_paper.yaml").read_text())
    study["robot"]["urdf"] = str(TWO_LINK)
    for key, value in changes.items():
        study[key] = value
    path = tmp_path / "study.yaml"
    path.write_text(yaml.safe_dump(study))
    return path


def test_a_study_places_each_rotor_by_the_rule_and_a_joint_may_say_otherwise(tmp_path):
    from collision_reflex.study.arm_setup import arm_setup
    from collision_reflex.study.setup_notes import placement_sentences

    study = yaml.safe_load((ROOT / "studies" / "two_link_paper.yaml").read_text())
    actuators = study["actuators"]
    # A stiff first joint and a compliant second one against a 2e4 N/m contact (the planar arm's links are
    # about 0.3 m long: some 1e3 N m/rad seen at the joints).
    actuators["joints"] = {
        "joint1": {"mechanical_stiffness": "1e6 N*m/rad"},
        "joint2": {"mechanical_stiffness": "10 N*m/rad"},
    }
    setup = arm_setup(
        load_study(
            _study(tmp_path, actuators=actuators, reflected_inertia_in={"contact_stiffness": "2e4 N/m"})
        )
    )
    assert setup.technology.reflected_inertia_in == ("finger", "robot")
    assert setup.placement_ratios[0] < 0.1 < 10 < setup.placement_ratios[1]
    line, caveat = placement_sentences(setup)
    assert "upper estimate" in caveat  # the closed form against a softer object (the simulator's finding)
    assert (
        "in the impact (a stiff transmission) at joint1" in line
        and "joint spring (a compliant joint) at joint2" in line
    )
    # A joint's own placement stands against the rule.
    actuators["joints"]["joint2"]["reflected_inertia_in"] = "finger"
    (tmp_path / "own").mkdir()
    setup = arm_setup(
        load_study(
            _study(
                tmp_path / "own", actuators=actuators, reflected_inertia_in={"contact_stiffness": "2e4 N/m"}
            )
        )
    )
    assert setup.technology.reflected_inertia_in == ("finger", "finger")


def test_a_contact_as_stiff_as_the_transmission_is_warned_about(tmp_path):
    from collision_reflex.study.arm_setup import arm_setup
    from collision_reflex.study.setup_notes import placement_sentences

    setup = arm_setup(load_study(_study(tmp_path, reflected_inertia_in={"contact_stiffness": "2e4 N/m"})))
    ratios = setup.placement_ratios
    lines = placement_sentences(setup)
    between = [j for j, r in zip(("joint1", "joint2"), ratios, strict=True) if 0.1 < r < 10]
    assert bool(between) == any(line.startswith("Warning:") for line in lines), ratios


def test_behind_compliant_joints_the_rotors_take_no_part_in_a_hard_impact():
    # The time-domain simulator (an independent model: rotors behind the joint springs, a stiff wall 1000 times
    # the joints' stiffness along u) at 10 v*, where the impact carries the impulse: the closed form with the
    # rotors behind the springs (robot) is the closer, the one with them in the impact (finger) overestimates.
    # The UR5 with representative harmonic-drive joints (benchmarks/validity_map.py; measured 7.2 % and -10.5 %).
    from collision_reflex.simulate.design_closed_form import JointDesign
    from collision_reflex.simulate.validity import validity_map

    arm = Arm.from_example_robot_data("ur5")
    k = np.array([5000, 5000, 3000, 800, 800, 800.0])
    joints = JointDesign(
        mechanical_stiffness=k,
        reflected_inertia=[0.2, 0.2, 0.1, 0.03, 0.03, 0.03],
        torque_limit=[150, 150, 150, 28, 28, 28],
        threshold=20.0,
        software_stiffness=4 * k,
    )
    table = validity_map(
        arm,
        joints,
        [[0.0, -1.2, 1.5, -1.9, -1.57, 0.0]],
        [[1, 0, 0]],
        velocity_ratios=[10.0],
        stiffness_ratios=[1000.0],
        detections=["spring_torque"],
        reaction="at_rest",
    )
    constant = table[table.reaction_model == "constant"].set_index("placement")["difference"]
    assert abs(constant["robot"]) < 0.1 < abs(constant["finger"])
    assert constant["finger"] < 0  # the closed form with the rotors in the impact gives too much impulse
