"""Input files are read bounded: a device, a pipe or a huge file is refused before it is read (never a hang or a
full memory), and a run record nested too deeply to parse is damaged, not a traceback."""

from __future__ import annotations

import os
import shutil

import pytest

from collision_reflex._io import INPUT_LIMIT, read_limited
from collision_reflex.cli import main


def _error(argv: list[str], capsys: pytest.CaptureFixture[str]) -> str:
    """Run ``crx`` expecting exit status 2; its last line of stderr."""
    assert main(argv) == 2
    return capsys.readouterr().err.strip().splitlines()[-1]


@pytest.mark.skipif(not os.path.exists("/dev/zero"), reason="needs /dev/zero")
@pytest.mark.parametrize(
    "argv",
    [
        ["motors", "--catalogue", "/dev/zero"],
        ["fit", "/dev/zero"],
        ["safety", "--regions", "/dev/zero", "--list-regions"],
    ],
)
def test_a_device_is_refused_before_it_is_read(argv, capsys):
    assert main(argv) == 2
    assert "not a regular file" in capsys.readouterr().err


def test_a_pipe_is_refused_without_waiting_for_a_writer(tmp_path):
    pipe = tmp_path / "pipe.csv"
    os.mkfifo(pipe)
    with pytest.raises(OSError, match="not a regular file"):
        read_limited(pipe)


def test_a_file_beyond_the_limit_is_refused_unread(tmp_path, capsys):
    """A sparse 100 MB file: its size decides, not its content (reading it would take 100 MB)."""
    big = tmp_path / "big.yaml"
    with open(big, "wb") as handle:
        handle.truncate(100 * 2**20)
    assert 100 * 2**20 > INPUT_LIMIT
    with pytest.raises(OSError, match="larger than"):
        read_limited(big)
    assert "larger than 4 MiB" in _error(["motors", "--catalogue", str(big)], capsys)
    small = tmp_path / "small.txt"
    small.write_bytes(b"12345")
    assert read_limited(small, limit=5) == b"12345"
    with pytest.raises(OSError, match="larger than"):
        read_limited(small, limit=4)


@pytest.mark.parametrize("command", ["report", "export", "safety"])
def test_a_run_record_nested_too_deeply_is_damaged_not_a_traceback(smoke_runs, tmp_path, capsys, command):
    run = tmp_path / "run"
    shutil.copytree(smoke_runs["two_link_paper"], run)
    (run / "designs.json").write_text("[" * 50_000 + "]" * 50_000)
    extra = {
        "report": [],
        "export": ["--format", "urdf", "--out", str(tmp_path / "x.urdf")],
        "safety": ["--region", "chest"],
    }
    line = _error([command, str(run), *extra[command]], capsys)
    assert "nested too deeply" in line and "run the study again" in line


@pytest.mark.parametrize("constant", ["NaN", "Infinity", "-Infinity"])
def test_a_nan_anywhere_in_a_run_record_is_damage_located_not_a_number(
    smoke_runs, tmp_path, capsys, constant
):
    """The package never writes NaN (``allow_nan=False``): one in designs.json, even in a field the record's
    types leave open (the resolved study's objective weight here), is refused with its field, never reported as
    "worst-case impulse nan N·s"."""
    run = tmp_path / "run"
    shutil.copytree(smoke_runs["two_link_paper"], run)
    text = (run / "designs.json").read_text()
    field = '"worst_case_impulse": '
    start = text.index(field) + len(field)
    end = min(text.index(c, start) for c in ",\n}")
    (run / "designs.json").write_text(text[:start] + constant + text[end:])
    line = _error(["report", str(run)], capsys)
    assert "'resolved.objective.worst_case_impulse'" in line and "expected a finite number" in line


@pytest.mark.parametrize(
    ("field", "value", "words"),
    [
        ("peak_torque", -5.0, "a number above 0"),
        ("motor_mass", 0.0, "a number above 0"),
        ("gearbox_efficiency", 1.5, "a number of at most 1"),
        ("rotor_inertia", -1e-6, "a number of at least 0"),
    ],
)
def test_a_tampered_design_is_refused_by_its_physical_range(
    smoke_runs, tmp_path, capsys, field, value, words
):
    """designs.json is input like a study: a negative torque, a massless motor or an efficiency above 1 is not
    exported as if valid."""
    import json

    run = tmp_path / "run"
    shutil.copytree(smoke_runs["two_link_paper"], run)
    data = json.loads((run / "designs.json").read_text())
    data["recommended"]["joints"][0][field] = value
    (run / "designs.json").write_text(json.dumps(data))
    line = _error(["export", str(run), "--format", "urdf", "--out", str(tmp_path / "x.urdf")], capsys)
    assert f"'recommended.joints[0].{field}'" in line and words in line


def test_export_from_mutated_run_folders_is_a_model_or_one_line(smoke_runs, tmp_path, capsys):
    """40 seeded mutations of designs.json (numbers made negative, zero, huge, NaN, text; names made hostile
    XML): each export is a well-formed model with no injected element, or exit 2 with one line."""
    import json
    import random
    import xml.etree.ElementTree as ET

    source = smoke_runs["two_link_paper"]
    base = json.loads((source / "designs.json").read_text())
    rng = random.Random(33)
    hostile: list[object] = [
        -1.0,
        0.0,
        1e308,
        float("nan"),
        "x",
        10**400,
        True,
        None,
        '--><link name="X"/><!--',
    ]

    def leaves(node, path=()):
        if isinstance(node, dict):
            for key, value in node.items():
                yield from leaves(value, (*path, key))
        elif isinstance(node, list):
            for i, value in enumerate(node):
                yield from leaves(value, (*path, i))
        else:
            yield path

    paths = [p for p in leaves(base["recommended"]) if p and p[0] == "joints"]
    run = tmp_path / "run"
    shutil.copytree(source, run)
    for trial in range(40):
        data = json.loads(json.dumps(base))
        path = rng.choice(paths)
        target = data["recommended"]
        for key in path[:-1]:
            target = target[key]
        target[path[-1]] = rng.choice(hostile)
        text = json.dumps(data, allow_nan=True) if not isinstance(target[path[-1]], int) else json.dumps(data)
        (run / "designs.json").write_text(text)
        out = tmp_path / f"m{trial}.urdf"
        status = main(["export", str(run), "--format", "urdf", "--out", str(out)])
        captured = capsys.readouterr()
        if status == 0:
            root = ET.parse(out).getroot()  # well-formed
            assert not [e for e in root.iter() if e.get("name") == "X"], path
        else:
            assert status == 2 and len(captured.err.strip().splitlines()) == 1, (path, captured.err)
