"""`crx simulate`: table, CSV and figure agree with the simulator and the closed form; bad input exits 2."""

from __future__ import annotations

import csv
import subprocess
import sys

import pytest

import collision_reflex as cr
from collision_reflex.cli import main
from collision_reflex.simulate import CollisionSetup, Detection, simulate


def test_csv_matches_simulator_and_closed_form(tmp_path, capsys):
    target = tmp_path / "sweep.csv"
    argv = [
        "simulate",
        "--velocities",
        "0.1,0.4",
        "--delays",
        "0,0.01",
        "--tolerance",
        "0.1",
        "--csv",
        str(target),
    ]
    assert main(argv) == 0
    out = capsys.readouterr().out
    rows = list(csv.DictReader(target.open()))
    assert len(rows) == 4
    k = cr.model.series_stiffness(1000.0, 100.0)
    for row in rows:
        v0, delay = float(row["v0_m_per_s"]), float(row["delay"])
        setup = CollisionSetup(0.2, 0.5, 1000.0, 100.0, 10.0, v0, Detection("force", 3.0), delay=delay)
        assert float(row["impulse_simulated_Ns"]) == pytest.approx(simulate(setup).impulse, rel=1e-10)
        # The closed form comes from collision_reflex.model.impulse (the CLI never re-derives it).
        closed = cr.total_impulse(0.2, k, 1000.0, 3.0, 20.0, v0)
        assert float(row["impulse_closed_form_Ns"]) == pytest.approx(closed, rel=1e-10)
        difference = float(row["impulse_simulated_Ns"]) / closed - 1
        assert int(row["parted"]) == int(abs(difference) > 0.1)
    assert "largest difference" in out


@pytest.mark.parametrize("suffix", [".png", ".svg"])
def test_backlash_sweep_plot_written(tmp_path, suffix, capsys):
    target = tmp_path / f"sweep{suffix}"
    argv = [
        "simulate",
        "--count",
        "3",
        "--backlashes",
        "0,0.002",
        "--drive",
        "impedance",
        "--soft-damping",
        "5",
        "--plot",
        str(target),
    ]
    assert main(argv) == 0
    assert target.stat().st_size > 1000
    assert list(tmp_path.iterdir()) == [target]


def test_detected_variant_agrees_in_the_ideal_limit(capsys):
    """A heavy robot (F_a >> F) with the ideal drive: the moving variant at v0 k/k_m is exact."""
    argv = [
        "simulate",
        "--count",
        "3",
        "--robot-mass",
        "1e6",
        "--force-limit",
        "2e7",
        "--reaction",
        "detected",
        "--tolerance",
        "1e-5",
    ]
    assert main(argv) == 0
    out = capsys.readouterr().out
    assert "0 of 3 points part" in out


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["simulate", "--finger-mass", "-1"], "--finger-mass: '-1' is not a finite number > 0"),
        (["simulate", "--delays", "0,-1"], "every value must be a finite number >= 0"),
        (["simulate", "--delays", "0", "--backlashes", "0"], "sweep one parameter at a time"),
        (["simulate", "--restitution", "0.5"], "given with a finite --contact-stiffness"),
        (["simulate", "--drive", "impedance", "--soft-stiffness", "inf"], "use drive='ideal'"),
        (["simulate", "--plot", "out.txt"], "figure file = 'out.txt' is invalid"),
    ],
    ids=["negative-mass", "negative-delay", "two-sweeps", "restitution-rigid", "inf-impedance", "bad-figure"],
)
def test_bad_input_exits_2_with_one_clear_line(argv, message):
    done = subprocess.run([sys.executable, "-m", "collision_reflex", *argv], capture_output=True, text=True)
    assert done.returncode == 2
    assert message in done.stderr
    assert "Traceback" not in done.stderr
    # One error line (argparse prints its usage above it for malformed options).
    assert [line for line in done.stderr.splitlines() if "error" in line] == [
        done.stderr.strip().splitlines()[-1]
    ]


def test_help_names_units():
    done = subprocess.run(
        [sys.executable, "-m", "collision_reflex", "simulate", "--help"],
        capture_output=True,
        text=True,
        check=True,
    )
    for unit in ("[kg]", "[N/m]", "[N]", "[m/s]", "[s]", "[Hz]"):
        assert unit in done.stdout


def test_trace_figure_written(tmp_path, capsys):
    target = tmp_path / "trace.svg"
    argv = [
        "simulate",
        "--count",
        "2",
        "--delays",
        "0.01",
        "--trace-plot",
        str(target),
        "--trace-velocity",
        "0.3",
    ]
    assert main(argv) == 0
    assert target.stat().st_size > 1000
    assert f"wrote {target}" in capsys.readouterr().out
