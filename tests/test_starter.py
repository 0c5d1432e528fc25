"""`crx robots` and `crx init`: the robots a study can name, and a study to start from for each of them.

Checked against the robots' own models: every example-robot-data name is listed; the chain a study actuates
is the revolute joints from the base to the contact frame (walked here through the model's parents); the
written study validates for every robot listed as startable, stays within the joint limits, and runs for a
representative two (a serial arm; an arm without effort limits in its URDF).
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
import yaml

from collision_reflex.cli import main
from collision_reflex.study import load_study, parse_study
from collision_reflex.study.prepare import describe_study
from collision_reflex.study.starter import SAFETY_FACTOR, robot_entries, starter_study

ROOT = Path(__file__).resolve().parents[1]
ENTRIES = robot_entries()
STARTABLE = [entry for entry in ENTRIES if entry.startable]
# A six-joint arm with defaults, and a pendulum whose URDF has no effort or velocity limits (every startable
# robot is run by benchmarks/init_all_robots.py).
RUN = ["ur5", "double_pendulum"]


def test_every_robot_is_listed_with_what_a_study_needs(capsys):
    from example_robot_data.robots_loader import ROBOTS

    assert [entry.name for entry in ENTRIES] == sorted(ROBOTS)
    by_name = {entry.name: entry for entry in ENTRIES}
    assert by_name["ur5"].contact_frame == "tool0" and len(by_name["ur5"].chain) == 6
    assert by_name["panda"].contact_frame == "panda_hand_tcp" and len(by_name["panda"].chain) == 7
    assert by_name["solo12"].base == "floating" and not by_name["solo12"].startable
    assert len(STARTABLE) >= 20
    for entry in STARTABLE:
        assert entry.base == "fixed" and len(entry.chain) >= 2, entry
    assert main(["robots"]) == 0
    listed = capsys.readouterr().out.splitlines()
    assert sum(1 for line in listed if line.endswith("yes")) == len(STARTABLE)
    assert main(["robots", "--all"]) == 0
    assert len(capsys.readouterr().out.splitlines()) == len(ENTRIES) + 1  # a header, a line each


def test_the_chain_is_the_revolute_joints_from_the_base_to_the_contact_frame():
    import pinocchio as pin

    from collision_reflex.arm.robots import example_robot

    model = example_robot("panda")[0]
    frame = model.getFrameId("panda_hand_tcp")
    joint, walked = model.frames[frame].parentJoint, []
    while joint > 0:
        walked.append(model.names[joint])
        joint = model.parents[joint]
    by_name = {entry.name: entry for entry in ENTRIES}
    assert by_name["panda"].chain == tuple(reversed(walked))  # the fingers hang off the hand: not on it
    assert all(name.startswith("panda_joint") for name in by_name["panda"].chain)
    del pin


@pytest.mark.parametrize("entry", STARTABLE, ids=[entry.name for entry in STARTABLE])
def test_the_written_study_validates_within_the_joint_limits(entry, tmp_path):
    out = tmp_path / f"{entry.name}.yaml"
    text = starter_study(entry.name, out)
    loaded = parse_study(text, str(out), tmp_path)
    describe_study(loaded)  # the robot, frame, joints and duty cycle checked (via points within the limits)
    study = loaded.study
    assert study.robot.contact_frame == entry.contact_frame
    actuated = [name for name in entry.chain if name not in study.robot.locked_joints]
    assert len(actuated) == len(entry.chain)
    assert len(study.duty_cycle.via[0]) == len(entry.chain)
    assert study.constraints.safety_factor == SAFETY_FACTOR
    assert "ESTIMATE" in text or "SET" in text  # what is not the robot's own figure says so


@pytest.mark.parametrize("name", RUN)
def test_crx_init_writes_a_study_that_runs(name, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert main(["init", name]) == 0
    study = tmp_path / f"{name}.yaml"
    assert main(["validate", str(study)]) == 0
    out = tmp_path / "out"
    assert main(["run", str(study), "--smoke", "--quiet", "--executor", "serial", "--out", str(out)]) == 0
    designs = json.loads((out / "designs.json").read_text())
    joints = designs["recommended"]["joints"]
    assert len(joints) == len(yaml.safe_load(study.read_text())["duty_cycle"]["via"][0])
    assert all(joint["required_torque"] > 0 and joint["torque_margin"] >= -1e-6 for joint in joints)


def test_the_payload_is_what_the_effort_limits_hold(tmp_path):
    """UR5: the rated payload written is held by the URDF's effort limits with the safety factor, on other poses.

    The estimate takes half of what 256 poses allow: on 200 other poses twice the payload may exceed the limits
    only by what the sampling misses (a few per cent), the payload itself not at all.
    """
    import pinocchio as pin

    import collision_reflex as cr

    text = starter_study("ur5", tmp_path / "ur5.yaml")
    payload = yaml.safe_load(text)["rating"]["payload"]
    mass = float(payload.split()[0])
    assert 1.0 <= mass <= 5.0  # the UR5 is rated for 5 kg (Universal Robots, UR5 technical specifications)
    arm = cr.Arm.from_example_robot_data("ur5")
    model, data = arm.model, arm.model.createData()
    frame = model.getFrameId("tool0")
    rng = np.random.default_rng(1)  # other poses than the estimate's
    low, high = arm.joint_limits()
    worst = {1: 0.0, 2: 0.0}
    for angles in rng.uniform(low, high, (200, 6)):
        q = arm.configuration(angles)
        gravity = pin.computeGeneralizedGravity(model, data, q)
        jacobian = pin.computeFrameJacobian(model, data, q, frame, pin.LOCAL_WORLD_ALIGNED)[:3]
        for times in worst:
            tau = np.abs(gravity + jacobian.T @ np.array([0.0, 0.0, 9.81 * times * mass]))
            worst[times] = max(worst[times], float(np.max(SAFETY_FACTOR * tau / model.effortLimit)))
    assert worst[1] <= 1.0 and worst[2] <= 1.1, worst
    assert not math.isnan(worst[2])


def test_own_urdf_and_bad_input(tmp_path, capsys):
    urdf = ROOT / "designs" / "planar_two_link.urdf"
    out = tmp_path / "studies" / "mine.yaml"
    assert main(["init", str(urdf), "--out", str(out)]) == 0
    data = yaml.safe_load(out.read_text())
    assert Path(data["robot"]["urdf"]).resolve() == urdf.resolve() and data["robot"]["contact_frame"] == "tip"
    load_study(out)
    capsys.readouterr()
    assert main(["init", str(urdf), "--out", str(out)]) == 2  # never overwritten unasked
    assert "--force" in capsys.readouterr().err
    assert main(["init", "no_such_robot", "--out", str(tmp_path / "x.yaml")]) == 2
    assert "crx robots" in capsys.readouterr().err
    assert main(["init", "solo12", "--out", str(tmp_path / "y.yaml")]) == 2
    assert "floating base" in capsys.readouterr().err
    assert main(["init", "ur5", "--frame", "nowhere", "--out", str(tmp_path / "z.yaml")]) == 2
    assert "nowhere" in capsys.readouterr().err
    assert not (tmp_path / "x.yaml").exists() and not (tmp_path / "z.yaml").exists()
