"""`crx impulse`: output, sweeps, plots, and exit codes for bad input."""

from __future__ import annotations

import subprocess
import sys

import pytest

import collision_reflex as cr
from collision_reflex.cli import main


def test_prints_phases_total_and_optimum(capsys):
    assert (
        main(
            [
                "impulse",
                "--finger-mass",
                "0.2",
                "--mech-stiffness",
                "1000",
                "--soft-stiffness",
                "100",
                "--threshold",
                "3",
                "--accel",
                "20",
                "--velocity",
                "0.1",
            ]
        )
        == 0
    )
    out = capsys.readouterr().out
    k = cr.model.series_stiffness(1000.0, 100.0)
    phases = cr.model.phase_impulses(0.2, k, 1000.0, 3.0, 20.0, 0.1)
    assert f"{phases.total:.6g}" in out
    assert f"{phases.sensing:.6g}" in out
    assert f"v* = {cr.optimal_velocity(0.2, k, 3.0):.6g}" in out
    assert f"I* = {cr.model.minimum_impulse(0.2, k, 1000.0, 3.0, 20.0):.6g}" in out


def test_velocity_sweep_table(capsys):
    assert main(["impulse", "--velocities", "0.01:1:3"]) == 0
    lines = capsys.readouterr().out.strip().splitlines()
    table = [line.split() for line in lines[-3:]]
    assert [float(row[0]) for row in table] == pytest.approx([0.01, 0.1, 1.0])
    total_at_1 = cr.total_impulse(0.1, cr.model.series_stiffness(2e7, 440.0), 2e7, 3.0, 4.7e-5, 1.0)
    assert float(table[-1][-1]) == pytest.approx(total_at_1, rel=1e-5)


@pytest.mark.parametrize("suffix", [".png", ".svg"])
def test_plot_written(tmp_path, suffix, capsys):
    target = tmp_path / f"profile{suffix}"
    assert main(["impulse", "--reaction", "moving", "--accel", "20", "--plot", str(target)]) == 0
    assert target.stat().st_size > 1000
    assert list(tmp_path.iterdir()) == [target]  # no temporary file left behind


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["impulse", "--finger-mass", "-1"], "--finger-mass: '-1' is not a finite number > 0"),
        (["impulse", "--threshold", "nan"], "--threshold: 'nan' is not a finite number > 0"),
        (["impulse", "--velocity", "0"], "--velocity: '0' is not a finite number > 0"),
        (["impulse", "--reaction", "bounce"], "invalid choice: 'bounce'"),
        (["impulse", "--velocities", "1:0.1:5"], "STOP must be greater than START"),
        (["impulse", "--plot", "out.txt"], "figure file = 'out.txt' is invalid"),
    ],
)
def test_bad_input_exits_2_with_one_clear_line(argv, message):
    done = subprocess.run([sys.executable, "-m", "collision_reflex", *argv], capture_output=True, text=True)
    assert done.returncode == 2
    assert message in done.stderr
    assert "Traceback" not in done.stderr
    assert done.stdout == ""


def test_help_names_units():
    done = subprocess.run(
        [sys.executable, "-m", "collision_reflex", "impulse", "--help"],
        capture_output=True,
        text=True,
        check=True,
    )
    for unit in ("[kg]", "[N/m]", "[N]", "[m/s^2]", "[m/s]"):
        assert unit in done.stdout
