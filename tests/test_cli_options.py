"""The command line's one name and one unit per quantity: every subcommand's help names a unit for every physical
option; unit strings give the SI numbers; a unit of the wrong dimension is one line and exit status 2; the
spellings of before the first release are refused (the CHANGELOG lists them)."""

from __future__ import annotations

import argparse
import re
from pathlib import Path

import numpy as np
import pytest

import collision_reflex as cr
from collision_reflex.cli import build_parser, main
from collision_reflex.cli.options import LENGTH, QuantityParser

REPO = Path(__file__).resolve().parents[1]
TWO_LINK = str(REPO / "designs" / "planar_two_link.urdf")
TRACE = REPO / "studies" / "traces" / "u8_soft" / "u8_soft_v50mm.csv"
SURFACE_FAST = [
    "--urdf",
    TWO_LINK,
    "--directions",
    "12",
    "--q2-values",
    "45deg,0deg",
    "--velocities",
    "0.1,1",
]

SUBCOMMANDS = [
    ["impulse"],
    ["motors"],
    ["motors", "scale"],
    ["sweep", "radius-velocity"],
    ["sweep", "stiffness"],
    ["surface"],
    ["fit"],
    ["simulate"],
    ["validate"],
    ["schema"],
    ["run"],
    ["report"],
]
# Options whose value is not a physical quantity: files, folders, names, choices, counts.
NOT_PHYSICAL = {
    "--catalogue",
    "--motor",
    "--urdf",
    "--robot",
    "--frame",
    "--package-dir",
    "--lock",
    "--directions",
    "--count",
    "--plot",
    "--trace-plot",
    "--csv",
    "--json",
    "--out",
    "--system",
    "--time-unit",
    "--force-unit",
    "--scheduler",
    "--workers",
}


def _help_entries(text: str) -> dict[str, str]:
    """``{flag: help paragraph}`` for the options of an argparse help text that take a value (not a choice)."""
    body = text.split("options:", 1)[1]
    entries: dict[str, str] = {}
    current = None
    for line in body.splitlines():
        if line.startswith("  -"):
            head, _, words = line.strip().partition("  ")
            flag, *metavar = head.split(", ")[-1].split()
            current = flag if metavar and not metavar[0].startswith("{") else None
            if current is not None:
                entries[current] = words.strip()
        elif current is not None and line.startswith("   "):
            entries[current] += " " + line.strip()
        else:
            current = None
    return entries


def _missing_units(text: str) -> list[str]:
    return [
        flag
        for flag, words in _help_entries(text).items()
        if flag not in NOT_PHYSICAL and not re.search(r"\[[^\]\s]+\]", words)
    ]


def test_help_check_finds_a_missing_unit():
    text = (
        "options:\n  -h, --help            show this help message and exit\n"
        "  --finger-mass KG      finger mass [kg] (default\n                        0.1)\n"
        "  --lever M             joint axis to contact distance (default 0.1)\n"
        "  --law {a,b}           scaling law\n"
    )
    assert _missing_units(text) == ["--lever"]


@pytest.mark.parametrize("command", SUBCOMMANDS, ids=[" ".join(c) for c in SUBCOMMANDS])
def test_help_names_a_unit_for_every_physical_option(command, capsys):
    assert main([*command, "--help"]) == 0
    text = capsys.readouterr().out
    assert _missing_units(text) == []


def _values(namespace: argparse.Namespace) -> dict:
    return {key: value for key, value in vars(namespace).items() if key != "run"}


def _assert_same_values(first: dict, second: dict) -> None:
    assert first.keys() == second.keys()
    for key, value in first.items():
        if isinstance(value, (float, np.ndarray)) or isinstance(second[key], (float, np.ndarray)):
            np.testing.assert_allclose(second[key], value, rtol=1e-12, err_msg=key)
        elif isinstance(value, list) and value and isinstance(value[0], float):
            np.testing.assert_allclose(second[key], value, rtol=1e-12, err_msg=key)
        else:
            assert second[key] == value, key


# (command, spelling removed before the first release): each is refused like any unknown option.
REMOVED = {
    "motors-diameters": (["motors", "scale"], ["--diameters", "0.01,0.06"]),
    "rv-diameters": (["sweep", "radius-velocity"], ["--diameters", "0.01:0.1:4"]),
    "rv-k-m": (["sweep", "radius-velocity"], ["--k-m", "2000"]),
    "rv-k-s": (["sweep", "radius-velocity"], ["--k-s", "50"]),
    "stiffness-stiffnesses": (["sweep", "stiffness"], ["--stiffnesses", "100:1e4:5"]),
    "surface-motor-size": (["surface"], ["--motor-size", "30"]),
    "surface-motor-sizes": (["surface"], ["--motor-sizes", "10,60"]),
    "surface-mech-stiffness": (["surface"], ["--mech-stiffness", "300"]),
    "surface-soft-stiffness": (["surface"], ["--soft-stiffness", "1e3"]),
    "surface-output": (["surface"], ["--output", "grid.svg"]),
    "surface-o": (["surface"], ["-o", "grid.svg"]),
    "surface-table": (["surface"], ["--table", "s.csv"]),
    "fit-k-m": (["fit", "traces"], ["--k-m", "1e7"]),
    "simulate-trace": (["simulate"], ["--trace", "t.svg"]),
    "schema-out": (["schema"], ["--out", "s.json"]),
}


@pytest.mark.parametrize("command, removed", REMOVED.values(), ids=REMOVED.keys())
def test_a_removed_spelling_is_refused_as_an_unknown_option(command, removed, capsys):
    with pytest.raises(SystemExit) as exit_:
        build_parser().parse_args([*command, *removed])
    assert exit_.value.code == 2
    error = capsys.readouterr().err.strip().splitlines()[-1]
    assert removed[0] in error and ("unrecognized arguments" in error or "ambiguous option" in error)


def _run(argv: list[str], folder: Path, capsys, monkeypatch) -> str:
    """stdout of ``crx argv`` run in ``folder`` (relative output names, so the outputs compare equal)."""
    folder.mkdir()
    monkeypatch.chdir(folder)
    assert main(argv) == 0, capsys.readouterr().err
    return capsys.readouterr().out


def _trace_without_stiffness(folder: Path) -> None:
    """The shipped trace without its sensor stiffness, so that the command line's k_m is the one fitted."""
    folder.mkdir(parents=True)
    lines = TRACE.read_text().splitlines(keepends=True)
    (folder / TRACE.name).write_text("".join(line for line in lines if "sensor stiffness" not in line))


# (SI numbers, the same with units) of whole runs: the same printed numbers and files.
RUNS = {
    "motors scale": (
        ["motors", "scale", "--stator-diameters", "0.01,0.06"],
        ["motors", "scale", "--stator-diameters", "1cm,6cm"],
    ),
    "sweep radius-velocity": (
        [
            "sweep",
            "radius-velocity",
            "--stator-diameters",
            "0.01:0.1:4",
            "--velocities",
            "0.05:1:3",
            "--mech-stiffness",
            "2000",
        ],
        [
            "sweep",
            "radius-velocity",
            "--stator-diameters",
            "10mm:100mm:4",
            "--velocities",
            "0.05:1:3",
            "--mech-stiffness",
            "2 N/mm",
        ],
    ),
    "sweep stiffness": (
        ["sweep", "stiffness", "--mech-stiffnesses", "100:1e4:5", "--soft-stiffness", "1e4"],
        ["sweep", "stiffness", "--mech-stiffnesses", "0.1 N/mm:10 N/mm:5", "--soft-stiffness", "10 kN/m"],
    ),
    "surface": (
        [
            "surface",
            *SURFACE_FAST,
            "--stator-diameter",
            "0.03",
            "--stator-diameters",
            "10mm,60mm",
            "--joint-mech-stiffness",
            "300",
            "--plot",
            "grid.png",
            "--csv",
            "s.csv",
        ],
        [
            "surface",
            *SURFACE_FAST,
            "--stator-diameter",
            "30mm",
            "--stator-diameters",
            "0.01,0.06",
            "--joint-mech-stiffness",
            "300 N*m/rad",
            "--plot",
            "grid.png",
            "--csv",
            "s.csv",
        ],
    ),
    "fit": (["fit", "traces", "--mech-stiffness", "1e7"], ["fit", "traces", "--mech-stiffness", "1e4 N/mm"]),
    "simulate": (
        ["simulate", "--count", "2", "--delays", "0,0.01", "--trace-plot", "t.svg"],
        ["simulate", "--count", "2", "--delays", "0ms,10ms", "--trace-plot", "t.svg"],
    ),
}


@pytest.mark.parametrize("old, new", RUNS.values(), ids=RUNS.keys())
def test_si_and_unit_spellings_print_the_same_numbers(old, new, tmp_path, capsys, monkeypatch):
    for side in ("old", "new"):
        if old[0] == "fit":
            _trace_without_stiffness(tmp_path / side / "traces")
        else:
            (tmp_path / side).mkdir()
    printed = {}
    for side, argv in (("old", old), ("new", new)):
        monkeypatch.chdir(tmp_path / side)
        assert main(argv) == 0, capsys.readouterr().err
        captured = capsys.readouterr()
        printed[side] = captured.out
        assert "warning" not in captured.err
    assert printed["old"] == printed["new"]
    written = sorted(p.name for p in (tmp_path / "new").iterdir())
    assert written == sorted(p.name for p in (tmp_path / "old").iterdir())


# (command, SI numbers, the same with units): each subcommand parses unit strings to the same values.
UNITS = {
    "impulse": (
        ["impulse"],
        [
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
            "--velocities",
            "0.01:1:3",
        ],
        [
            "--finger-mass",
            "200 g",
            "--mech-stiffness",
            "1 kN/m",
            "--soft-stiffness",
            "0.1 N/mm",
            "--threshold",
            "3000mN",
            "--accel",
            "20 m/s^2",
            "--velocity",
            "10 cm/s",
            "--velocities",
            "1cm/s:1m/s:3",
        ],
    ),
    "motors scale": (
        ["motors", "scale"],
        ["--stator-diameters", "0.01,0.06", "--stack-length", "0.0125", "--torque", "1.3"],
        ["--stator-diameters", "10mm,6cm", "--stack-length", "12.5mm", "--torque", "1300 N*mm"],
    ),
    "sweep radius-velocity": (
        ["sweep", "radius-velocity"],
        ["--stator-diameters", "0.01:0.1:4", "--lever", "0.2", "--finger-mass", "0.1", "--robot-mass", "0.5"],
        [
            "--stator-diameters",
            "1cm:10cm:4",
            "--lever",
            "20cm",
            "--finger-mass",
            "100g",
            "--robot-mass",
            "0.5kg",
        ],
    ),
    "sweep stiffness": (
        ["sweep", "stiffness"],
        ["--mech-stiffnesses", "100:1e4:5", "--position-error", "0.003", "--velocity", "0.1"],
        ["--mech-stiffnesses", "0.1 N/mm:10 N/mm:5", "--position-error", "3mm", "--velocity", "100 mm/s"],
    ),
    "surface": (
        ["surface"],
        [
            "--stator-diameter",
            "0.06",
            "--joint-mech-stiffness",
            "250",
            "--task-stiffness",
            "100",
            "--q2-values",
            "45deg,0deg",
            "--offset",
            "0.01",
            "0",
            "-0.02",
            "--torque",
            "1.3",
            "2",
        ],
        [
            "--stator-diameter",
            "60mm",
            "--joint-mech-stiffness",
            "250 N*m/rad",
            "--task-stiffness",
            "0.1 N/mm",
            "--q2-values",
            "0.7853981633974483rad,0rad",
            "--offset",
            "1cm",
            "0m",
            "-2 cm",
            "--torque",
            "1.3 N*m",
            "2000 N*mm",
        ],
    ),
    "fit": (
        ["fit", "traces"],
        ["--mech-stiffness", "2e7", "--bandwidth", "1000", "--velocity", "0.05"],
        ["--mech-stiffness", "2e4 N/mm", "--bandwidth", "1 kHz", "--velocity", "5 cm/s"],
    ),
    "simulate": (
        ["simulate"],
        [
            "--finger-mass",
            "0.2",
            "--delays",
            "0,0.01",
            "--control-rate",
            "1000",
            "--backlash",
            "0.001",
            "--soft-damping",
            "5",
            "--position-error",
            "0.003",
        ],
        [
            "--finger-mass",
            "200g",
            "--delays",
            "0ms,10ms",
            "--control-rate",
            "1kHz",
            "--backlash",
            "1mm",
            "--soft-damping",
            "5 N*s/m",
            "--position-error",
            "3 mm",
        ],
    ),
}


@pytest.mark.parametrize("command, si, with_units", UNITS.values(), ids=UNITS.keys())
def test_unit_strings_give_the_si_values(command, si, with_units):
    parser = build_parser()
    expected = _values(parser.parse_args([*command, *si]))
    _assert_same_values(expected, _values(parser.parse_args([*command, *with_units])))


def test_unit_strings_give_the_same_impulse(capsys):
    """End to end: ``200 g``, ``1 kN/m``... print the impulse of the SI numbers, which the model confirms."""
    command, si, with_units = UNITS["impulse"]
    assert main([*command, *with_units]) == 0
    out = capsys.readouterr().out
    assert main([*command, *si]) == 0
    assert capsys.readouterr().out == out
    total = cr.total_impulse(0.2, cr.model.series_stiffness(1000.0, 100.0), 1000.0, 3.0, 20.0, 0.1)
    assert f"{total:.6g}" in out


def test_surface_stator_diameter_in_mm_matches_metres(tmp_path, capsys, monkeypatch):
    """The motor size that used to be a bare number in mm: ``30mm`` == 0.03."""
    argv = ["surface", *SURFACE_FAST, "--stator-diameters", "0.01,0.06", "--plot", "g.png", "--csv", "s.csv"]
    outputs = []
    for i, size in enumerate((["--stator-diameter", "0.03"], ["--stator-diameter", "30mm"])):
        (tmp_path / str(i)).mkdir()
        monkeypatch.chdir(tmp_path / str(i))
        assert main([*argv, *size]) == 0
        outputs.append((capsys.readouterr().out, (tmp_path / str(i) / "s.csv").read_text()))
    assert outputs[0] == outputs[1]
    smallest = float(re.search(r"smallest impulse (\S+)", outputs[0][0]).group(1))
    assert main([*argv[:-4], "--stator-diameter", "60mm", "--plot", str(tmp_path / "h.png")]) == 0
    larger_motor = float(re.search(r"smallest impulse (\S+)", capsys.readouterr().out).group(1))
    assert larger_motor != pytest.approx(smallest, rel=1e-3)  # the size reaches the model


# (argv, option, value, expected unit): a unit of the wrong dimension, one per subcommand.
WRONG_DIMENSION = {
    "impulse": (["impulse", "--finger-mass", "3 N"], "--finger-mass", "3 N", "kg"),
    "motors scale": (
        ["motors", "scale", "--stator-diameters", "10kg,20kg"],
        "--stator-diameters",
        "10kg",
        "m",
    ),
    "sweep radius-velocity": (["sweep", "radius-velocity", "--torque", "2 N"], "--torque", "2 N", "N*m"),
    "sweep stiffness": (["sweep", "stiffness", "--position-error", "3 N"], "--position-error", "3 N", "m"),
    "surface joint": (
        ["surface", "--joint-mech-stiffness", "1000 N/m"],
        "--joint-mech-stiffness",
        "1000 N/m",
        "N*m/rad",
    ),
    "surface size": (["surface", "--stator-diameter", "60 N"], "--stator-diameter", "60 N", "m"),
    "fit": (["fit", "x.csv", "--mech-stiffness", "250 N*m/rad"], "--mech-stiffness", "250 N*m/rad", "N/m"),
    "simulate": (["simulate", "--delay", "3 m"], "--delay", "3 m", "s"),
}


@pytest.mark.parametrize("argv, option, value, unit", WRONG_DIMENSION.values(), ids=WRONG_DIMENSION.keys())
def test_wrong_dimension_is_one_line_and_exit_2(argv, option, value, unit, capsys):
    assert main(argv) == 2
    captured = capsys.readouterr()
    lines = captured.err.strip().splitlines()
    assert len(lines) == 1 and captured.out == ""
    assert "error:" in lines[0] and option in lines[0] and repr(value) in lines[0]
    assert f"in {unit}," in lines[0]


def test_simulate_position_error_is_metres_and_threshold_newtons(capsys):
    """The detection threshold's unit no longer depends on --detection: F_s = k e_th from --position-error."""
    assert main(["simulate", "--count", "2", "--position-error", "3mm"]) == 0
    k = cr.model.series_stiffness(1000.0, 100.0)
    assert f"(F_s = {k * 0.003:g} N)" in capsys.readouterr().out
    assert main(["simulate", "--count", "2", "--detection", "position", "--threshold", "0.003"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--position-error [m]" in err[0]
    assert main(["simulate", "--count", "2", "--detection", "position"]) == 2
    assert "--position-error" in capsys.readouterr().err
    assert main(["simulate", "--count", "2", "--detection", "force", "--position-error", "1mm"]) == 2


PARSE = {
    "bare metres": ("0.06", 0.06),
    "millimetres": ("60mm", 0.06),
    "spaced": ("0.06 m", 0.06),
    "centimetres": ("6cm", 0.06),
    "range": ("10mm:100mm:3", np.geomspace(0.01, 0.1, 3)),
    "list": ("1cm,6cm", np.array([0.01, 0.06])),
}


@pytest.mark.parametrize("text, expected", PARSE.values(), ids=PARSE.keys())
def test_length_parser(text, expected):
    parse = QuantityParser(LENGTH, form="range" if ":" in text or "," in text else "one")
    np.testing.assert_allclose(parse(text), expected, rtol=1e-12)


BAD_TEXT = {
    "mixed units": ("10,60,100mm", "range", "give a unit on every value or on none"),
    "not a quantity": ("sixty", "one", "is not a quantity"),
    "zero": ("0mm", "one", "is not a finite number > 0"),
    "inf": ("inf", "one", "is not a finite number > 0"),
}


@pytest.mark.parametrize("text, form, message", BAD_TEXT.values(), ids=BAD_TEXT.keys())
def test_length_parser_refuses(text, form, message):
    with pytest.raises(argparse.ArgumentTypeError, match=message):
        QuantityParser(LENGTH, form=form)(text)


def test_main_returns_exit_status(capsys):
    assert main(["--version"]) == 0
    assert main(["impulse", "--help"]) == 0
    assert main([]) == 2
    assert len(capsys.readouterr().err.strip().splitlines()) == 1
