"""`crx surface`: figures, the per-direction table, and exit codes for bad input."""

from __future__ import annotations

import csv
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from collision_reflex.arm import Arm
from collision_reflex.arm.surfaces import reflex_surface
from collision_reflex.cli import main
from collision_reflex.hardware.actuators import ForceThreshold

REPO = Path(__file__).resolve().parents[1]
TWO_LINK = REPO / "designs" / "planar_two_link.urdf"
# Small sweeps keep the test fast; the defaults draw 360 directions per cell.
FAST = [
    "--directions",
    "24",
    "--q2-values",
    "45deg,0deg",
    "--stator-diameters",
    "0.01,0.06",
    "--velocities",
    "0.1,1",
]


@pytest.mark.parametrize("suffix", [".png", ".svg"], ids=["png", "svg"])
def test_planar_grid_figure_and_table(tmp_path, capsys, suffix):
    figure, table = tmp_path / f"grid{suffix}", tmp_path / "surface.csv"
    code = main(["surface", "--urdf", str(TWO_LINK), "--plot", str(figure), "--csv", str(table), *FAST])
    assert code == 0
    assert figure.stat().st_size > 1000
    out = capsys.readouterr().out
    assert "planar_two_link" in out and "smallest impulse" in out
    with open(table, newline="") as handle:
        rows = list(csv.DictReader(handle))
    assert len(rows) == 24
    # The table is the baseline surface: q2 = 45 deg, 60 mm Omni+ geared to the URDF's 1.3 N m, v0 = 0.5 m/s.
    arm = Arm.from_urdf(TWO_LINK, "tip").with_scaled_motors(
        0.060, mechanical_stiffness=250.0, sensing=ForceThreshold(3.0)
    )
    expected = reflex_surface(arm, [0.0, math.radians(45)], 0.5, directions=24, task_stiffness=100.0)
    totals = np.array([float(row["impulse_total_Ns"]) for row in rows])
    np.testing.assert_allclose(totals, expected.impulse, rtol=1e-8)  # the table keeps 9 digits


def test_spatial_figure(tmp_path, capsys):
    figure = tmp_path / "ur5.png"
    assert main(["surface", "--robot", "ur5", "--directions", "60", "--plot", str(figure)]) == 0
    assert figure.stat().st_size > 1000
    assert "ur5" in capsys.readouterr().out


@pytest.mark.parametrize(
    "arguments, message",
    [
        (["--urdf", "missing.urdf"], "no such file"),
        (["--urdf", str(TWO_LINK), "--frame", "gripper"], "tip_joint, tip"),
        (["--robot", "double_pendulum"], "--torque"),
        (["--urdf", str(TWO_LINK), "--q", "10deg"], "2 joint positions"),
        (["--urdf", str(TWO_LINK), "--q", "10", "20"], "a bare number could be either"),
        (["--urdf", str(TWO_LINK), "--q2-values", "45,0"], "has no unit"),
        (["--urdf", str(TWO_LINK), "--plot", "figure.txt"], ".png"),
    ],
    ids=["missing-urdf", "unknown-frame", "no-torque", "wrong-q", "bare-q", "bare-q2", "bad-figure-name"],
)
def test_bad_input_is_one_line_and_status_2(tmp_path, monkeypatch, capsys, arguments, message):
    monkeypatch.chdir(tmp_path)
    output = [] if "--plot" in arguments else ["--plot", str(tmp_path / "f.png")]
    assert main(["surface", *arguments, *output]) == 2
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("crx surface: error:") and message in lines[0], lines


def test_command_line_error_has_no_traceback(tmp_path):
    result = subprocess.run(
        [sys.executable, "-m", "collision_reflex", "surface", "--urdf", "missing.urdf", "--plot", "f.png"],
        capture_output=True,
        text=True,
        cwd=tmp_path,
        env={"PYTHONPATH": str(REPO / "src"), "PATH": "/usr/bin:/bin"},
        check=False,
    )
    assert result.returncode == 2 and "Traceback" not in result.stderr
    assert result.stderr.strip().startswith("crx surface: error: cannot load URDF missing.urdf: no such file")
