"""The duty cycle of a study: schema, loading against DutyCycle built directly, located errors, summaries."""

from __future__ import annotations

import json
import math
import os
import textwrap
from pathlib import Path

import numpy as np
import pytest
import yaml

from collision_reflex.arm.duty_cycle import DutyCycle, Payload
from collision_reflex.cli import main
from collision_reflex.errors import StudyFileError
from collision_reflex.study import ArmStudy, load_study, resolved_yaml, study_json_schema
from collision_reflex.study.arm_setup import arm_setup
from collision_reflex.study.duty import STATIC_REQUIREMENT, describe_duty_cycle, study_duty_cycle
from collision_reflex.study.robot import load_arm

ROOT = Path(__file__).resolve().parents[1]
JOINTS = ("joint1", "joint2")
BASE = textwrap.dedent(
    """\
    name: duty
    robot:
      example_robot_data: double_pendulum
    actuators:
      mechanical_stiffness: 1000 N*m/rad
      software_stiffness: 100
    sensing: {scheme: force, threshold: 3 N}
    approach_velocity: 50 cm/s
    samples:
      configurations: {random: {count: 2, seed: 1}}
      directions: {circle: 4}
    """
)
VIA = textwrap.dedent(
    """\
    duty_cycle:
      via: [[0 deg, 0 deg], [90 deg, -45 deg], [0 deg, 0 deg]]
      max_speed: {joint1: 90 deg/s, joint2: 2 rad/s}
      max_acceleration: 300 deg/s^2
      dwell: 0.25 s
      rate: 200 Hz
      payload: {mass: 1.5 kg, inertia: [[0.01, 0, 0], [0, 0.02, 0], [0, 0, 0.03]]}
    """
)
FILE = "duty_cycle:\n  file: cycle.csv\n"
FILE_LINE = BASE.count("\n") + 2  # the study line of `file:`


def _csv(rows: int = 60, *, time_unit: str = "s") -> str:
    """A smooth cycle (joint1 in deg, joint2 in rad) with a comment line and an extra column."""
    t = np.linspace(0.0, 2.0, rows)
    lines = ["# recorded cycle", f"time [{time_unit}], joint1 [deg], joint2 [rad], gripper [mm]"]
    lines += [
        f"{ti:.12g}, {30 * math.sin(math.pi * ti):.12g}, {0.5 * math.cos(math.pi * ti):.12g}, 5" for ti in t
    ]
    return "\n".join(lines) + "\n"


def _two_link_base() -> str:
    """BASE on the planar two-link URDF (joints joint1 and joint2, limited to +-pi)."""
    urdf = ROOT / "designs" / "planar_two_link.urdf"
    return BASE.replace("example_robot_data: double_pendulum", f"urdf: {urdf}\n  contact_frame: tip")


def _study(tmp_path: Path, section: str, csv: str | None = None, base: str = BASE) -> Path:
    path = tmp_path / "study.yaml"
    path.write_text(base + section)
    if csv is not None:
        (tmp_path / "cycle.csv").write_text(csv)
    return path


def _cycle(path: Path) -> DutyCycle | None:
    loaded = load_study(path)
    return study_duty_cycle(loaded, load_arm(loaded))


def _only_problem(error: pytest.ExceptionInfo[StudyFileError]):
    assert len(error.value.problems) == 1, error.value
    return error.value.problems[0]


# --- loading matches DutyCycle built directly ---------------------------------------------------------------


def test_via_point_cycle_is_the_directly_built_one(tmp_path):
    cycle = _cycle(_study(tmp_path, VIA))
    deg = math.pi / 180
    expected = DutyCycle.through_via_points(
        [[0, 0], [90 * deg, -45 * deg], [0, 0]],
        JOINTS,
        [90 * deg, 2.0],
        300 * deg,
        rate=200.0,
        dwell=0.25,
        payload=Payload(1.5, np.diag([0.01, 0.02, 0.03])),
    )
    assert cycle is not None
    for name in ("t", "q", "qd", "qdd"):
        np.testing.assert_array_equal(getattr(cycle, name), getattr(expected, name))
    assert cycle.payload is not None and cycle.payload.mass == 1.5
    np.testing.assert_array_equal(cycle.payload.inertia, np.diag([0.01, 0.02, 0.03]))
    # the joint-1 limit is the study's 90 deg/s, reached (the move of 90 deg is long enough to cruise)
    assert np.max(np.abs(cycle.qd[:, 0])) == pytest.approx(90 * deg, rel=1e-12)


def test_file_cycle_is_the_directly_built_one_and_ignores_extra_columns(tmp_path):
    path = _study(tmp_path, FILE, _csv())
    cycle = _cycle(path)
    expected = DutyCycle.from_csv(tmp_path / "cycle.csv", JOINTS)
    assert cycle is not None and cycle.joint_names == JOINTS
    for name in ("t", "q", "qd", "qdd"):
        np.testing.assert_array_equal(getattr(cycle, name), getattr(expected, name))
    # degrees in the header are converted: joint1's amplitude is 30 deg
    assert np.max(np.abs(cycle.q[:, 0])) == pytest.approx(math.radians(30), rel=1e-3)
    assert cycle.payload is None


def test_constraints_payload_is_the_cycles_point_mass(tmp_path):
    base = BASE + "constraints: {payload: 0.7 kg}\n"
    cycle = _cycle(_study(tmp_path, FILE, _csv(), base=base))
    assert cycle is not None and cycle.payload is not None
    assert cycle.payload.mass == 0.7
    np.testing.assert_array_equal(cycle.payload.inertia, np.zeros((3, 3)))


def test_a_duty_cycle_adds_to_the_static_hold_of_its_payload(tmp_path):
    """The optimiser gets the cycle (its RNEA torques carry the payload) and the same payload held still."""
    loaded = load_study(_study(tmp_path, VIA))
    setup = arm_setup(loaded)
    assert setup.constraints.duty_cycle is setup.duty_cycle
    assert setup.duty_cycle is not None and setup.duty_cycle.payload.mass == 1.5
    assert setup.constraints.payload == 1.5 and setup.constraints.torque_required is None
    assert not setup.static_torque_requirement and setup.constraints.requirement.startswith("duty cycle")


def test_the_rated_payload_is_the_one_held_still(tmp_path):
    """``rating.payload`` (the datasheet's) sizes the static hold; the cycle keeps carrying its own."""
    setup = arm_setup(load_study(_study(tmp_path, VIA + "rating: {payload: 4 kg}\n")))
    assert setup.constraints.payload == 4.0 and setup.duty_cycle.payload.mass == 1.5
    bad = _study(tmp_path, VIA + "rating: {payload: -1 kg}\n")
    with pytest.raises(StudyFileError, match=r"rating\.payload"):
        arm_setup(load_study(bad))


def test_given_torques_and_a_duty_cycle_are_refused_at_their_line(tmp_path):
    path = _study(tmp_path, VIA + "constraints: {torque_required: [1, 1]}\n")
    with pytest.raises(
        StudyFileError, match=r"constraints\.torque_required: found given torques with a duty"
    ):
        arm_setup(load_study(path))


def test_a_study_without_a_cycle_says_its_requirement_is_static(tmp_path, capsys):
    path = _study(tmp_path, "")
    setup = arm_setup(load_study(path))
    assert setup.duty_cycle is None and setup.static_torque_requirement
    assert main(["validate", str(path)]) == 0
    assert STATIC_REQUIREMENT in capsys.readouterr().out


def test_validate_summarises_the_cycle(tmp_path, capsys):
    path = _study(tmp_path, VIA)
    assert main(["validate", str(path)]) == 0
    out = capsys.readouterr().out
    cycle = _cycle(path)
    assert cycle is not None
    assert f"duty cycle of {cycle.duration:.4g} s, {cycle.t.size} samples" in out
    # synchronised moves: joint1 (90 deg at 90 deg/s) sets the pace, joint2 (45 deg) moves slower than its limit
    assert "peak joint speed 1.571 rad/s (joint1), payload 1.5 kg" in out
    assert STATIC_REQUIREMENT not in out


# --- schema, JSON Schema, resolved form ----------------------------------------------------------------------


def test_json_schema_describes_the_duty_cycle():
    definitions = study_json_schema()["$defs"]
    cycle = definitions["DutyCycleSpec"]
    assert set(cycle["properties"]) == {
        "file",
        "via",
        "max_speed",
        "max_acceleration",
        "dwell",
        "rate",
        "payload",
    }
    assert cycle["additionalProperties"] is False
    assert set(definitions["PayloadSpec"]["properties"]) == {"mass", "inertia"}
    assert "duty_cycle" in definitions["ArmStudy"]["properties"]


def test_resolved_study_makes_the_defaults_explicit_and_reloads(tmp_path):
    section = "duty_cycle:\n  via: [[0 rad, 0 rad], [1 rad, 1 rad]]\n  max_speed: 1\n  max_acceleration: 2\n"
    path = _study(tmp_path, section)
    text = resolved_yaml(load_study(path))
    cycle = yaml.safe_load(text)["duty_cycle"]
    assert cycle["dwell"] == 0.0 and cycle["rate"] == 1000.0 and cycle["payload"] is None
    again = tmp_path / "resolved.yaml"
    again.write_text(text)
    assert load_study(again).study == load_study(path).study


def test_resolved_file_path_is_absolute(tmp_path):
    path = _study(tmp_path, FILE, _csv())
    cycle = yaml.safe_load(resolved_yaml(load_study(path)))["duty_cycle"]
    assert cycle["file"] == str((tmp_path / "cycle.csv").resolve())
    assert cycle["dwell"] is None and cycle["rate"] is None  # via-only settings stay unset with a file


# --- bad input: the study line, and for trajectory files the CSV line -----------------------------------------


def _bad_csv(kind: str) -> tuple[str, int | None, str]:
    """A broken trajectory file, the CSV line of its problem (None: the file as a whole) and a telling word."""
    lines = _csv().splitlines()
    header = 2  # line 1 is a comment
    if kind == "missing-column":
        lines[1] = "time [s], joint1 [deg], gripper [mm]"
        lines[2:] = [",".join([*row.split(",")[:2], "5"]) for row in lines[2:]]
        return "\n".join(lines), header, "joint2"
    if kind == "non-increasing":
        lines[16] = lines[14]
        return "\n".join(lines), 17, "does not increase"
    if kind == "nan":
        lines[20] = lines[20].split(",")[0] + ", nan, 0.1, 5"
        return "\n".join(lines), 21, "non-numeric joint1"
    if kind == "wrong-unit":
        lines[1] = "time [s], joint1 [kg], joint2 [rad], gripper [mm]"
        return "\n".join(lines), header, "kg"
    if kind == "bare-angle":  # radians or degrees? The unit must be written.
        lines[1] = "time [s], joint1 [deg], joint2, gripper [mm]"
        return "\n".join(lines), header, "without a unit"
    if kind == "too-few":
        return "\n".join(lines[:6]), None, "too few samples"
    if kind == "too-coarse":
        t = np.linspace(0.0, 2.0, 8)
        rows = [f"{ti:.9g}, {30 * math.sin(3 * math.pi * ti):.9g}, 0" for ti in t]
        return "time [s], joint1 [deg], joint2 [rad]\n" + "\n".join(rows), None, "too coarse"
    raise AssertionError(kind)


@pytest.mark.parametrize(
    "kind", ["missing-column", "non-increasing", "nan", "wrong-unit", "bare-angle", "too-few", "too-coarse"]
)
def test_trajectory_file_problems_name_the_study_line_and_the_csv_line(tmp_path, kind):
    text, csv_line, word = _bad_csv(kind)
    path = _study(tmp_path, FILE, text)
    with pytest.raises(StudyFileError) as error:
        _cycle(path)
    problem = _only_problem(error)
    assert problem.line == FILE_LINE and problem.path == "duty_cycle.file"
    if csv_line is not None:
        assert problem.found.startswith(f"cycle.csv:{csv_line}: ")
    elif kind == "too-coarse":
        assert problem.found.startswith("cycle.csv:") and "between samples" in problem.found
    else:
        assert problem.found.startswith("cycle.csv: ")
    assert word in problem.found
    assert str(problem).startswith(f"{path}:{FILE_LINE}:")


def test_coarse_sampling_names_the_csv_line_of_the_later_sample(tmp_path):
    text, _, _ = _bad_csv("too-coarse")
    with pytest.raises(StudyFileError) as error:
        _cycle(_study(tmp_path, FILE, text))
    found = _only_problem(error).found
    line = int(found.split(":")[1])
    sample = int(found.split("between samples ")[1].split(" and ")[1].split(" ")[0])
    assert line == sample + 2  # header on line 1, sample 0 on line 2


BAD_STUDIES = [
    # (duty_cycle section, extra base text, study line (relative to the section's first line), words)
    ("duty_cycle:\n  file: cycle.csv\n  spline: 5\n", "", 2, ["unknown key 'spline'"]),
    ("duty_cycle:\n  file: nowhere.csv\n", "", 1, ["no such file"]),
    ("duty_cycle:\n  file: cycle.csv\n  rate: 100 Hz\n", "", 0, ["only with via points"]),
    ("duty_cycle:\n  via: [[0 rad, 0 rad], [1 rad, 1 rad]]\n  max_speed: 1\n", "", 0, ["max_acceleration"]),
    (
        "duty_cycle:\n  via: [[0 rad, 0 rad], [1 rad, 1 rad]]\n  max_speed: 1 m\n  max_acceleration: 1\n",
        "",
        2,
        ["[length]"],
    ),
    (
        "duty_cycle:\n  via: [[0 rad, 0 rad], [1 rad, 1 rad]]\n  max_speed: -1\n  max_acceleration: 1\n",
        "",
        2,
        ["> 0"],
    ),
    (
        "duty_cycle:\n  via: [[0 rad, 0 rad], [1 rad, 1 rad]]\n  max_speed: 1\n  max_acceleration: 1\n  dwell: [1 s, -2]\n",
        "",
        4,
        [">= 0 (found -2)"],
    ),
    (
        "duty_cycle:\n  via: [[0 rad, 0 rad], [1 rad, 1 rad]]\n  max_speed: 1\n  max_acceleration: 1\n  dwell: [1 s]\n",
        "",
        0,
        ["one per via point"],
    ),
    (
        "duty_cycle:\n  file: cycle.csv\n  payload: {mass: 1 kg, inertia: [[1, 2, 0], [0, 1, 0], [0, 0, 1]]}\n",
        "",
        2,
        ["symmetric"],
    ),
    (
        "duty_cycle:\n  file: cycle.csv\n  payload: {mass: 1 kg}\n",
        "constraints: {payload: 2 kg}\n",
        None,
        ["once"],
    ),
]


@pytest.mark.parametrize(
    "section, extra, offset, words",
    BAD_STUDIES,
    ids=[
        "unknown-key",
        "no-such-file",
        "via-setting-with-file",
        "missing-limit",
        "limit-of-wrong-dimension",
        "negative-limit",
        "negative-dwell",
        "dwell-count",
        "asymmetric-inertia",
        "payload-twice",
    ],
)
def test_bad_duty_cycle_sections_are_located(tmp_path, section, extra, offset, words):
    base = BASE + extra
    path = _study(tmp_path, section, _csv(), base=base)
    with pytest.raises(StudyFileError) as error:
        load_study(path)
    problem = error.value.problems[0]
    if offset is None:  # the payload given twice: at constraints.payload
        assert problem.path == "constraints.payload" and problem.line == base.count("\n")
    else:
        assert problem.line == base.count("\n") + 1 + offset
    text = str(error.value)
    for word in words:
        assert word in text


@pytest.mark.parametrize(
    ("kind", "words"),
    [
        ("folder", "a folder, not a file"),
        ("fifo", "a named pipe (FIFO), not a regular file"),
        ("device", "a device, not a regular file"),
    ],
)
def test_a_duty_cycle_path_that_is_not_a_regular_file_says_what_it_is(tmp_path, kind, words):
    path = _study(tmp_path, FILE)
    target = tmp_path / "cycle.csv"
    if kind == "folder":
        target.mkdir()
    elif kind == "fifo":
        os.mkfifo(target)
    else:
        target.symlink_to(os.devnull)  # only looked at (stat), never opened
    with pytest.raises(StudyFileError) as error:
        load_study(path)
    problem = _only_problem(error)
    assert (
        problem.path == "duty_cycle.file" and words in problem.found and "no such file" not in problem.found
    )


ROBOT_BAD = [
    # (section, path of the problem, line within the section, words)
    (
        "  via: [[0 rad, 0 rad, 0 rad], [1 rad, 1 rad]]\n  max_speed: 1\n  max_acceleration: 1\n",
        "duty_cycle.via[0]",
        1,
        ["3 joint"],
    ),
    (
        "  via: [[0 rad, 0 rad], [1 rad, 1 rad]]\n  max_speed: {joint1: 1, elbow: 1}\n  max_acceleration: 1\n",
        "duty_cycle.max_speed",
        2,
        ["joint2", "elbow"],
    ),
]


@pytest.mark.parametrize("section, field, line, words", ROBOT_BAD, ids=["via-size", "limit-names"])
def test_via_points_and_limits_are_checked_against_the_arm(tmp_path, section, field, line, words):
    path = _study(tmp_path, "duty_cycle:\n" + section)
    with pytest.raises(StudyFileError) as error:
        _cycle(path)
    problem = error.value.problems[0]
    assert problem.path.startswith(field)
    assert problem.line == BASE.count("\n") + 1 + line
    for word in words:
        assert word in str(error.value)


def test_via_points_within_the_urdf_limits(tmp_path):
    section = (
        "duty_cycle:\n  via: [[0 rad, 0 rad], [1 rad, 200 deg]]\n  max_speed: 1\n  max_acceleration: 1\n"
    )
    base = _two_link_base()
    with pytest.raises(StudyFileError) as error:  # the two-link URDF limits its joints to +-pi
        _cycle(_study(tmp_path, section, base=base))
    problem = _only_problem(error)
    assert problem.path == "duty_cycle.via[1][1]" and problem.line == base.count("\n") + 2
    assert "[-3.14159, 3.14159]" in problem.expected
    # the double pendulum's joints have no limits in its URDF: any via point is a motion it can make
    cycle = _cycle(_study(tmp_path, section))
    assert cycle is not None and cycle.q[-1, 1] == pytest.approx(math.radians(200), rel=1e-12)


def test_run_with_a_bad_trajectory_writes_nothing(tmp_path, capsys):
    text, csv_line, _ = _bad_csv("non-increasing")
    path = _study(tmp_path, FILE, text)
    out = tmp_path / "out"
    assert main(["run", str(path), "--out", str(out), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert f"{path}:{FILE_LINE}:" in err and f"cycle.csv:{csv_line}:" in err
    assert not out.exists()


def test_example_trajectory_loads_with_the_minimum_jerk_peaks(tmp_path):
    """studies/cycles/two_link_reach.csv: 60 deg minimum-jerk moves in 0.8 s, positions to 1e-6 deg."""
    section = f"duty_cycle:\n  file: {ROOT / 'studies' / 'cycles' / 'two_link_reach.csv'}\n"
    cycle = _cycle(_study(tmp_path, section, base=_two_link_base()))
    assert cycle is not None and cycle.duration == 2.0 and cycle.t.size == 201
    amplitude, move = math.radians(60), 0.8
    # minimum jerk: peak speed 15/8 A/T at mid-move, peak acceleration 10 sqrt(3)/3 A/T^2
    np.testing.assert_allclose(np.max(np.abs(cycle.qd), axis=0), 15 / 8 * amplitude / move, rtol=1e-5)
    np.testing.assert_allclose(
        np.max(np.abs(cycle.qdd), axis=0), 10 * math.sqrt(3) / 3 * amplitude / move**2, rtol=1e-3
    )


def test_cli_schema_resolved_and_schema_only_summaries(tmp_path, capsys):
    assert main(["schema"]) == 0
    assert "DutyCycleSpec" in json.loads(capsys.readouterr().out)["$defs"]
    path = _study(tmp_path, VIA)
    assert main(["validate", "--resolved", str(path)]) == 0
    resolved = yaml.safe_load(capsys.readouterr().out.split("\n", 1)[1])
    assert resolved["duty_cycle"]["rate"] == 200.0 and resolved["duty_cycle"]["dwell"] == 0.25
    assert resolved["duty_cycle"]["max_speed"] == {"joint1": pytest.approx(math.pi / 2), "joint2": 2.0}
    assert main(["validate", "--schema-only", str(path)]) == 0
    assert "duty cycle through 3 via points (not loaded)" in capsys.readouterr().out


def test_summary_gives_prismatic_speeds_in_metres_per_second(tmp_path):
    study = load_study(_study(tmp_path, "")).study
    assert isinstance(study, ArmStudy)
    cycle = DutyCycle.through_via_points([[0, 0], [0.4, 1.0]], ("slide", "hinge"), [0.2, 3.0], 10.0)
    text = describe_duty_cycle(cycle, study, prismatic=("slide",))
    # synchronised: the slide (0.4 m at 0.2 m/s) sets the pace; the hinge cruises at 1.0 / 0.4 * 0.2 rad/s
    hinge = 1.0 / 0.4 * 0.2
    assert f"peak joint speed {hinge:.4g} rad/s (hinge) and 0.2 m/s (slide), no payload" in text
