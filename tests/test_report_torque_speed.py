"""The recommended design's torque-speed figure: saved with a duty cycle, drawn in the report, redrawn by
`crx report`, absent (and said so) without a cycle; a missing or damaged entry is one clear line."""

from __future__ import annotations

import dataclasses
import json
import shutil
from pathlib import Path

import numpy as np
import pytest

from collision_reflex.cli import main
from collision_reflex.optimize.design import Design
from collision_reflex.optimize.duty import torque_speed_points
from collision_reflex.optimize.pieces import built_problem
from collision_reflex.optimize.results import _DESIGN_ARRAYS, _GEARBOX_ARRAYS
from collision_reflex.plots.torque_speed import JointOperatingPoints
from collision_reflex.study.arm_results import SAVED_DIGITS, JointTorqueSpeed
from collision_reflex.study.problems import StudyProblems

pytestmark = pytest.mark.xdist_group(
    "test_report_torque_speed"
)  # one pytest-xdist worker: the cycle run made once

ROOT = Path(__file__).resolve().parents[1]
TWO_LINK = ROOT / "studies" / "two_link_paper.yaml"
# A short via-point cycle with a payload, in place of the paper study's given torques (the two exclude each
# other); the arm moves in the horizontal plane, so the cycle's torques are all inertial.
CYCLE = """\
constraints: {safety_factor: 1.5, threshold_floor: 0.5 N}
duty_cycle:
  via: [[0 deg, 30 deg], [60 deg, 90 deg], [0 deg, 30 deg]]
  max_speed: 2 rad/s
  max_acceleration: 10 rad/s^2
  dwell: 0.1 s
  rate: 100 Hz
  payload: {mass: 0.2 kg}
"""
# Rounding to SAVED_DIGITS significant digits is a relative error of at most half a unit in the last digit.
ROUNDING = 0.5 * 10.0 ** (1 - SAVED_DIGITS)


def _two_link(tmp_path: Path, cycle: bool) -> Path:
    text = TWO_LINK.read_text().replace("../designs/", f"{ROOT / 'designs'}/")
    lines = [line for line in text.splitlines() if not line.startswith("constraints:")]
    path = tmp_path / ("cycle.yaml" if cycle else "static.yaml")
    path.write_text("\n".join(lines) + "\n" + (CYCLE if cycle else ""))
    return path


@pytest.fixture(scope="module")
def runs(tmp_path_factory, smoke_runs):
    """The two-link study run once with a duty cycle and once with its given torques (smoke size)."""
    folder = tmp_path_factory.mktemp("cycle")
    args = ["run", str(_two_link(folder, True)), "--out", str(folder / "out"), "--quiet", "--smoke"]
    assert main([*args, "--executor", "serial"]) == 0
    return {True: folder / "out", False: smoke_runs[TWO_LINK.stem]}


def _recorded_design(record: dict) -> Design:
    """The design of a saved record (its unrounded per-joint numbers, the gearboxes' among them)."""
    joints = record["joints"]

    def per_joint(key: str) -> np.ndarray:
        return np.array([j[key] for j in joints], dtype=float)

    return Design(
        joint_names=tuple(j["joint"] for j in joints),
        **{key: per_joint(key) for key in _DESIGN_ARRAYS + _GEARBOX_ARRAYS},
        gearbox=tuple(j["gearbox"] for j in joints),
        threshold=record["threshold"],
        approach_velocity=record["approach_velocity"],
        sensing=record["sensing"],
    )


def test_saved_points_are_the_recomputed_ones_and_the_envelope_is_the_records(runs):
    folder = runs[True]
    results = json.loads((folder / "designs.json").read_text())
    recommended = results["recommended"]
    saved = recommended["torque_speed"]
    assert [entry["joint"] for entry in saved] == [j["joint"] for j in recommended["joints"]]
    # The saved layout is what the figure reads: JointOperatingPoints's fields.
    fields = {field.name for field in dataclasses.fields(JointOperatingPoints)}
    assert set(JointTorqueSpeed.__annotations__) == fields
    assert all(set(entry) == fields for entry in saved)
    problems = StudyProblems.of_run(folder)
    problem = built_problem(problems, problems.objective)
    points = torque_speed_points(problem, _recorded_design(recommended))
    factor = results["resolved"]["constraints"]["safety_factor"]
    for entry, point, joint in zip(saved, points, recommended["joints"], strict=True):
        name = entry["joint"]
        for key, expected in (
            ("speed", point.cycle_speed),
            ("torque", point.cycle_torque),
            ("approach_speed", point.approach_speed),
        ):
            assert len(entry[key]) == len(expected) > 1, (name, key)
            # 1e-6: the rounding's bound (SAVED_DIGITS = 7), with room for the recomputation's last bits.
            np.testing.assert_allclose(
                entry[key], expected, rtol=2 * ROUNDING, atol=0, err_msg=f"{name} {key}"
            )
        gear = joint["gear_ratio"]
        # Independently of the points' code path: the record's requirements are the points' extremes.
        largest = float(np.max(np.abs(entry["torque"])))
        fastest = float(np.max(np.abs(entry["speed"] + entry["approach_speed"])))
        assert factor * largest * gear == pytest.approx(joint["required_torque"], rel=2 * ROUNDING)
        assert fastest == pytest.approx(joint["max_motor_speed"], rel=2 * ROUNDING)
        # The envelope, motor side: the record's joint-side numbers divided by the gear ratio.
        assert entry["peak_torque"] == pytest.approx(joint["motor_peak_torque"], rel=ROUNDING)
        assert entry["max_speed"] == pytest.approx(joint["speed_limit"], rel=ROUNDING)
        assert entry["rms_torque"] * gear == pytest.approx(joint["required_rms_torque"], rel=ROUNDING)
        continuous = (1 + joint["rms_margin"]) * joint["required_rms_torque"] / gear
        assert entry["continuous_torque"] == pytest.approx(continuous, rel=2 * ROUNDING)
        # Compact: every saved number has at most SAVED_DIGITS significant digits.
        assert all(float(f"{v:.{SAVED_DIGITS}g}") == v for v in entry["torque"])


def test_saved_digits_keep_the_points_within_1e6():
    # The tolerance above is the rounding's; the saved data must stay that close to the computed points.
    assert 2 * ROUNDING <= 1e-6


def test_the_report_shows_the_figure_with_a_motor_side_caption(runs):
    folder = runs[True]
    assert (folder / "figures" / "torque_speed.png").is_file()
    html = (folder / "report.html").read_text()
    figure = html.index('id="torque-speed"')
    assert html.index('id="recommended"') < figure < html.index('id="confidence"')
    assert "Motor-side" in html[figure:] and "peak-torque envelope" in html[figure:]
    assert "torque-speed-none" not in html


def test_without_a_duty_cycle_nothing_is_saved_and_the_report_says_why(runs):
    folder = runs[False]
    results = json.loads((folder / "designs.json").read_text())
    assert "torque_speed" not in results["recommended"]
    assert not (folder / "figures" / "torque_speed.png").exists()
    html = (folder / "report.html").read_text()
    assert 'id="torque-speed"' not in html
    assert "the requirement has no motion to plot" in html


def test_crx_report_redraws_the_figure_from_the_saved_data(runs, tmp_path):
    folder = tmp_path / "copy"
    shutil.copytree(runs[True], folder)
    before = (folder / "report.html").read_text()
    shutil.rmtree(folder / "figures")
    (folder / "report.html").unlink()
    assert main(["report", str(folder)]) == 0
    assert (folder / "figures" / "torque_speed.png").is_file()
    assert (folder / "report.html").read_text() == before


def _remove(entry: list) -> None:
    del entry[0]["rms_torque"]


def _nan(entry: list) -> None:
    entry[1]["torque"][3] = "NaN"


def _short(entry: list) -> None:
    entry[0]["speed"] = entry[0]["speed"][:-1]


@pytest.mark.parametrize(
    ("damage", "words"),
    [
        (None, ["recommended.torque_speed is missing", "duty cycle"]),
        (_remove, ["recommended.torque_speed[0] has fields", "rms_torque"]),
        (_nan, ["recommended.torque_speed[1]", "torque", "finite"]),
        (_short, ["recommended.torque_speed[0]", "as many samples as speed"]),
    ],
    ids=["removed", "field-missing", "nan", "lengths-differ"],
)
def test_crx_report_on_a_damaged_entry_is_one_line_naming_file_and_field(
    runs, tmp_path, capsys, damage, words
):
    folder = tmp_path / "damaged"
    shutil.copytree(runs[True], folder)
    path = folder / "designs.json"
    results = json.loads(path.read_text())
    if damage is None:
        del results["recommended"]["torque_speed"]
    else:
        damage(results["recommended"]["torque_speed"])
    path.write_text(json.dumps(results))
    capsys.readouterr()
    assert main(["report", str(folder)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    assert str(path) in err[0]
    for word in words:
        assert word in err[0], (word, err[0])
