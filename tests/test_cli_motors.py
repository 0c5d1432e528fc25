"""`crx motors`, `crx motors scale` and `crx sweep`: output, files and one-line errors with exit status 2."""

from __future__ import annotations

import re

import pandas as pd
import pytest

from collision_reflex.cli import main


def test_motors_lists_catalogue(capsys):
    assert main(["motors"]) == 0
    out = capsys.readouterr().out
    assert "OPN-060-013-A" in out and "assumption" in out


def test_motors_list_shows_max_speed(tmp_path, capsys):
    assert main(["motors"]) == 0
    row = next(line for line in capsys.readouterr().out.splitlines() if line.startswith("OPN-060-013-A"))
    assert row.split()[-2:] == ["492.6", "4704"]  # rad/s and rpm: 492.6 * 60 / (2 pi) = 4703.98
    catalogue = tmp_path / "motors.yaml"
    catalogue.write_text(
        "motors:\n  bare:\n    stator_diameter: 30 mm\n    stack_length: 10 mm\n    rotor_inertia: 1e-6\n"
        "    peak_torque: 0.4\n    continuous_torque: 0.2\n    mass: 0.08\n    source: a test entry\n"
    )
    assert main(["motors", "--catalogue", str(catalogue)]) == 0
    row = next(line for line in capsys.readouterr().out.splitlines() if line.startswith("bare"))
    assert row.split()[-2:] == ["unknown", "unknown"]


def test_motors_scale_shows_scaled_max_speed(capsys):
    assert main(["motors", "scale"]) == 0
    out = capsys.readouterr().out
    speed_row = next(line for line in out.splitlines() if line.startswith("Max. speed"))
    # Constant surface speed: omega0 * 60 mm / r for r = 10, 60, 100 mm; printed to 4 significant figures,
    # so within half a unit of the 4th figure (at most 0.5 / 2956 = 1.7e-4 relative for these values).
    assert [float(x) for x in speed_row.split()[-3:]] == pytest.approx([2955.6, 492.6, 295.56], rel=2e-4)
    assert "(r/r0)^-1" in out and "surface speed" in out


def test_motors_scale_reproduces_tab_motor_params(capsys):
    assert main(["motors", "scale"]) == 0
    out = capsys.readouterr().out
    gear_row = next(line for line in out.splitlines() if line.startswith("Gear ratio"))
    assert gear_row.split()[-3:] == ["88.18", "1", "1"]  # the paper's N for M1, M2, M3
    inertia_row = next(line for line in out.splitlines() if line.startswith("Inertia (N^2 J_m)"))
    assert [float(x) for x in inertia_row.split()[-3:]] == pytest.approx(
        [1.33e-4, 2.21e-5, 1.71e-4], rel=0.01
    )


def test_sweep_radius_velocity_writes_files(tmp_path, capsys):
    figure, table = tmp_path / "rv.svg", tmp_path / "rv.csv"
    argv = ["sweep", "radius-velocity", "--stator-diameters", "0.01:0.15:9", "--velocities", "0.05:2:7"]
    assert main([*argv, "--plot", str(figure), "--csv", str(table)]) == 0
    out = capsys.readouterr().out
    for assumption in ("lever L [m]", "finger mass [kg]", "reflected inertia in"):
        assert assumption in out  # every unstated assumption is printed with the result
    assert re.search(r"optimum: stator diameter 60 mm", out)
    assert figure.stat().st_size > 0 and "<svg" in figure.read_text()[:500]
    assert len(pd.read_csv(table, comment="#")) == 63


def test_sweep_stiffness_writes_files(tmp_path, capsys):
    figure, table = tmp_path / "k.png", tmp_path / "k.csv"
    argv = [
        "sweep",
        "stiffness",
        "--mech-stiffnesses",
        "100:1e4:5",
        "--plot",
        str(figure),
        "--csv",
        str(table),
    ]
    assert main(argv) == 0
    frame = pd.read_csv(table, comment="#")
    assert frame["force_threshold_impulse_N_s"].is_monotonic_decreasing
    assert frame["position_threshold_impulse_N_s"].is_monotonic_increasing
    assert figure.read_bytes()[:4] == b"\x89PNG"


# Errors from the model (one line on stderr, exit status 2) ...
BAD = {
    "unknown-motor": (["motors", "scale", "--motor", "OPN-999"], "OPN-999"),
    "gear-below-one": (
        ["sweep", "stiffness", "--gear-ratio", "0.5", "--plot", "x.png", "--csv", "x.csv"],
        "gear_ratio",
    ),
    "bad-figure-name": (["sweep", "radius-velocity", "--plot", "x.txt"], "figure file"),
    "bad-csv-name": (["sweep", "radius-velocity", "--csv", "x.txt"], "--csv"),
    "missing-catalogue": (["motors", "--catalogue", "nope.yaml"], "nope.yaml"),
    "one-velocity-heat-map": (["sweep", "radius-velocity", "--velocities", "0.1"], "velocities"),
}


@pytest.mark.parametrize("argv, words", BAD.values(), ids=BAD.keys())
def test_bad_input_is_one_line_exit_2(argv, words, capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and words in err
    assert not list(tmp_path.iterdir())  # refused before writing anything


# ... and from argparse (one error line, exit status 2).
ARGPARSE_BAD = {
    "zero-diameter": (["motors", "scale", "--stator-diameters", "0.0,0.06"], "0.0"),
    "unknown-law": (["motors", "scale", "--law", "cubic"], "cubic"),
    "unknown-placement": (["sweep", "radius-velocity", "--reflected-inertia-in", "rotor"], "rotor"),
}


@pytest.mark.parametrize("argv, words", ARGPARSE_BAD.values(), ids=ARGPARSE_BAD.keys())
def test_bad_arguments_exit_2(argv, words, capsys):
    assert main(argv) == 2
    last = capsys.readouterr().err.strip().splitlines()[-1]
    assert "error:" in last and words in last


def test_motors_lists_gearbox_catalogue_too(capsys):
    assert main(["motors", "--gearboxes"]) == 0
    out = capsys.readouterr().out
    assert "OPN-060-013-A" in out  # the motor catalogue first
    row = next(line for line in out.splitlines() if line.startswith("NPS015-MF-1"))
    assert row.split()[1:6] == ["planetary", "3,4,5,7,8,10", "17", "32", "1.8"]
    assert "NPS015-MF-1: Beckhoff AG3300" in out
    per_ratio = next(line for line in out.splitlines() if line.startswith("NPS015-MF-1 (N: "))
    assert "3: 17/32 N m, 2.5e-05 kg m^2;" in per_ratio and per_ratio.endswith(
        "10: 19/35 N m, 1.3e-05 kg m^2"
    )
    assert main(["motors"]) == 0
    assert "NPS015" not in capsys.readouterr().out  # gearboxes only when asked


def test_gearbox_rows_show_a_ratio_range_and_unknown_efficiency(capsys):
    from collision_reflex.cli.motors import _print_gearboxes
    from collision_reflex.hardware.gearboxes import CatalogueGearbox

    harmonic = CatalogueGearbox("hd", "harmonic", (50.0, 160.0), True, 10.0, 20.0, 0.1, 1e-6, "a test entry")
    _print_gearboxes({"hd": harmonic})
    row = next(line for line in capsys.readouterr().out.splitlines() if line.startswith("hd"))
    assert row.split()[1:3] == ["harmonic", "50..160"] and row.split()[-1] == "unknown"
