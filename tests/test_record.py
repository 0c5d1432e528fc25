"""The run record's types are the contract of ``designs.json``: every shipped study's run meets them, and a
saved record that does not (a key missing or unknown, a value of the wrong kind, a number that is not finite)
is refused in one line naming the file and the field."""

from __future__ import annotations

import json
import os
import shutil
from pathlib import Path

import pytest

from collision_reflex.cli import main
from collision_reflex.record.checked import ResultsDamaged, ResultsMissing
from collision_reflex.record.read import read_run_record, record_problem
from collision_reflex.record.run import RUN_KINDS

STUDIES = sorted(path.stem for path in (Path(__file__).resolve().parents[1] / "studies").glob("*.yaml"))


@pytest.mark.parametrize("study", STUDIES)
def test_every_shipped_study_writes_a_record_of_its_type(smoke_runs, study):
    record = read_run_record(smoke_runs[study] / "designs.json")
    assert record["kind"] in RUN_KINDS
    assert record == json.loads((smoke_runs[study] / "designs.json").read_text())  # read as written


@pytest.fixture(scope="module")
def arm(smoke_runs) -> dict:
    return json.loads((smoke_runs["two_link_paper"] / "designs.json").read_text())


@pytest.fixture(scope="module")
def actuator(smoke_runs) -> dict:
    return json.loads((smoke_runs["direct_drive_vs_geared"] / "designs.json").read_text())


def _damaged(record: dict, where: list, change) -> dict:
    damaged = json.loads(json.dumps(record))
    node = damaged
    for key in where[:-1]:
        node = node[key]
    change(node, where[-1])
    return damaged


def _drop(node, key):
    del node[key]


def _nan(node, key):
    node[key] = float("nan")


def _infinite(node, key):
    node[key] = float("inf")


def _text(node, key):
    node[key] = "NaN"


@pytest.mark.parametrize(
    ("where", "change", "words"),
    [
        (
            ["recommended", "joints", 0, "gear_ratio"],
            _drop,
            "field 'gear_ratio' is missing: recommended.joints[0] has fields joint, stator_diameter",
        ),
        (["verdict"], _drop, "field 'verdict' is missing: the record has fields kind, study"),
        (["chosen", "solver", "status"], _drop, "field 'status' is missing: chosen.solver has fields"),
        (
            ["chosen", "threshold"],
            _nan,
            "field 'chosen.threshold' holds a value of the wrong kind (NaN, expected a finite number)",
        ),
        (
            ["pareto", "points", 0, "impulses", 1],
            _infinite,
            "field 'pareto.points[0].impulses[1]' holds a value of the wrong kind (Infinity",
        ),
        (
            ["recommended", "objectives", "actuator_mass"],
            _text,
            "'recommended.objectives.actuator_mass' holds a value of the wrong kind (\"NaN\"",
        ),
        (
            ["samples", "task_dim"],
            _text,
            "field 'samples.task_dim' holds a value of the wrong kind (\"NaN\", expected a whole number)",
        ),
    ],
)
def test_a_damaged_record_is_refused_naming_the_field(arm, where, change, words):
    problem = record_problem(_damaged(arm, where, change))
    assert problem is not None and words in problem, problem


def test_an_unknown_key_is_refused_naming_it(arm, actuator):
    record = json.loads(json.dumps(arm))
    record["recommended"]["joints"][1]["colour"] = "red"
    assert record_problem(record) == "field 'colour' of recommended.joints[1] is not one a run writes"
    record = json.loads(json.dumps(actuator))
    record["candidates"][0]["contact"]["F_x"] = 1.0
    assert record_problem(record) == "field 'F_x' of candidates[0].contact is not one a run writes"


def test_optional_fields_may_be_null_or_absent_where_the_run_leaves_them(arm):
    record = json.loads(json.dumps(arm))
    record["recommended"]["joints"][0]["torque_margin"] = None
    record["recommended"]["joints"][0].pop("module", None)
    record["recommended"]["fresh"] = None
    assert record_problem(record) is None
    record["recommended"]["joints"][0]["stator_diameter"] = None
    assert (
        "field 'recommended.joints[0].stator_diameter' holds a value of the wrong kind (null"
        in record_problem(record)
    )


def test_a_designs_json_that_is_a_link_to_a_device_or_a_folder_is_not_missing(tmp_path):
    link = tmp_path / "designs.json"
    link.symlink_to(os.devnull)  # only looked at (stat), never opened
    with pytest.raises(
        ResultsDamaged, match=r"designs\.json cannot be read \(a device, not a regular file\)"
    ):
        read_run_record(link)
    link.unlink()
    link.mkdir()
    with pytest.raises(ResultsDamaged, match=r"a folder, not a file"):
        read_run_record(link)


def test_read_run_record_raises_the_run_folder_errors(arm, tmp_path):
    with pytest.raises(ResultsMissing, match=r"has no designs\.json"):
        read_run_record(tmp_path / "designs.json")
    path = tmp_path / "designs.json"
    path.write_text('{"kind": "arm", "pareto": {"poi')
    with pytest.raises(ResultsDamaged, match="cannot be read"):
        read_run_record(path)
    path.write_text(json.dumps({**arm, "kind": "leg"}))
    with pytest.raises(ResultsDamaged, match="field 'kind' is 'leg', expected one of arm, actuator"):
        read_run_record(path)
    path.write_text(json.dumps(arm).replace('"verdict": ', '"verdict": NaN, "x": ', 1))
    with pytest.raises(ResultsDamaged) as error:
        read_run_record(path)
    assert str(error.value).startswith(f"{path}: ") and str(error.value).endswith("; run the study again")


def test_crx_report_refuses_a_damaged_record_in_one_line(smoke_runs, tmp_path, capsys):
    folder = tmp_path / "damaged"
    shutil.copytree(smoke_runs["two_link_paper"], folder)
    path = folder / "designs.json"
    record = json.loads(path.read_text())
    record["chosen"]["joints"][0]["peak_torque"] = float("nan")
    path.write_text(json.dumps(record))
    capsys.readouterr()
    assert main(["report", str(folder)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    assert (
        str(path) in err[0]
        and "'chosen.joints[0].peak_torque' holds a value of the wrong kind (NaN, expected a finite number)"
        in err[0]
    )
