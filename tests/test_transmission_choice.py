"""The transmission as a design choice: a study's gearbox options, one per module or joint, chosen by the run."""

from __future__ import annotations

import json

import pytest
import yaml

from collision_reflex.errors import StudyFileError
from collision_reflex.optimize.catalogue_search import objective_value
from collision_reflex.optimize.optimum import single_optimum
from collision_reflex.optimize.pieces import built_problem
from collision_reflex.study.load import load_study
from collision_reflex.study.problems import StudyProblems
from collision_reflex.study.resolve import resolve_study
from collision_reflex.study.runner import run_study
from test_snap import ROOT, TWO_LINK

OPTIONS = ["NPS015-MF-1", "SP060-MF-1"]  # two planetary units of the catalogue: light and strong


def _study(tmp_path, gearbox, name="study.yaml", **changes):
    study = yaml.safe_load((ROOT / "studies" / "two_link_planetary.yaml").read_text())
    study["robot"]["urdf"] = str(TWO_LINK)
    study["actuators"]["gearbox"] = gearbox
    study.pop("pareto")
    study.update(changes)
    path = tmp_path / name
    path.write_text(yaml.safe_dump(study))
    return path


def _objective(path):
    problems = StudyProblems(resolve_study(load_study(path)))
    optimum, _ = single_optimum(problems, problems.objective, starts=1)
    return objective_value(built_problem(problems, problems.objective), optimum.numpy_objectives)


def test_the_run_goes_on_with_the_best_gearbox_per_joint(tmp_path):
    result = run_study(
        _study(tmp_path, OPTIONS), tmp_path / "out", quiet=True, executor="serial", figures=False
    )
    results = json.loads((result.folder / "designs.json").read_text())
    tried = results["transmission_choice"]
    assert len(tried) == 4  # two options at each of two joints
    chosen = next(t for t in tried if t["chosen"])
    assert chosen["objective"] == min(t["objective"] for t in tried if t["objective"] is not None)
    # Independently: the study with the chosen gearbox at each joint, solved on its own, gives that objective.
    joints = {j: {"gearbox": option} for j, option in chosen["assignment"].items()}  # one joint per group
    alone = _study(tmp_path, None, "alone.yaml")
    fixed = yaml.safe_load(alone.read_text())
    fixed["actuators"]["joints"] = joints
    alone.write_text(yaml.safe_dump(fixed))
    assert _objective(alone) == pytest.approx(chosen["objective"], rel=1e-6)
    # The run's resolved study is the chosen one, and the report says what was tried.
    resolved = yaml.safe_load((result.folder / "study.resolved.yaml").read_text())
    assert resolved["actuators"]["gearbox"] is None
    assert {j: s["gearbox"] for j, s in resolved["actuators"]["joints"].items()} == {
        j: s["gearbox"] for j, s in joints.items()
    }
    assert any(line.startswith("Transmission: ") for line in results["verdict"])
    # Run again: the same choice, so the run resumes from its finished work.
    again = run_study(
        _study(tmp_path, OPTIONS), tmp_path / "out", quiet=True, executor="serial", figures=False
    )
    assert again.resumed and again.computed == 0


def test_too_many_assignments_are_refused_at_the_gearbox_line(tmp_path, monkeypatch):
    from collision_reflex.study import transmission_choice

    monkeypatch.setattr(transmission_choice, "MAX_ASSIGNMENTS", 3)
    with pytest.raises(
        StudyFileError, match=r"actuators\.gearbox: found 2 gearbox options for 2 modules or joints"
    ):
        run_study(_study(tmp_path, OPTIONS), tmp_path / "out", quiet=True, executor="serial", figures=False)
    assert not (tmp_path / "out").exists()


def test_options_of_which_none_can_carry_the_study_are_refused(tmp_path):
    # 400 kg at the tip accelerated hard: no planetary unit of the catalogue carries it.
    path = _study(tmp_path, OPTIONS, rating={"payload": "400 kg", "joint_accelerations": "300 deg/s^2"})
    with pytest.raises(StudyFileError, match=r"actuators\.gearbox.*best margin reachable"):
        run_study(path, tmp_path / "out", quiet=True, executor="serial", figures=False)
    assert not (tmp_path / "out").exists()


def test_an_option_that_cannot_carry_the_study_is_passed_over(tmp_path):
    # 20 kg accelerated at 300 deg/s^2 at the 0.55 m tip asks the shoulder some 20 x 0.55^2 x 5.2 x 1.5 = 47 N m:
    # beyond the NPS015's 32 N m repeated peak, within the SP100's 282 N m.
    path = _study(
        tmp_path,
        ["NPS015-MF-1", "SP100-MF-1"],
        rating={"payload": "20 kg", "joint_accelerations": "300 deg/s^2"},
    )
    result = run_study(path, tmp_path / "out", quiet=True, executor="serial", figures=False)
    tried = json.loads((result.folder / "designs.json").read_text())["transmission_choice"]
    refused = [t for t in tried if t["objective"] is None]
    assert refused and all(t["assignment"]["joint1"] == "NPS015-MF-1" for t in refused)
    assert all(t["status"].startswith("refused:") for t in refused)
    chosen = next(t for t in tried if t["chosen"])
    assert chosen["assignment"]["joint1"] == "SP100-MF-1"


def test_direct_drive_is_an_option_at_a_gear_ratio_of_one(tmp_path):
    # A light cycle (0.2 kg) that a direct-drive motor within the design's 120 mm can carry.
    light = {
        "duty_cycle": {
            **yaml.safe_load((ROOT / "studies" / "two_link_planetary.yaml").read_text())["duty_cycle"]
        }
    }
    light["duty_cycle"]["payload"] = {"mass": "0.2 kg"}
    path = _study(tmp_path, ["direct_drive", "NPS015-MF-1"], **light)
    result = run_study(path, tmp_path / "out", quiet=True, executor="serial", figures=False)
    results = json.loads((result.folder / "designs.json").read_text())
    tried = {tuple(t["assignment"].values()): t for t in results["transmission_choice"]}
    assert set(tried) == {
        (a, b) for a in ("direct drive", "NPS015-MF-1") for b in ("direct drive", "NPS015-MF-1")
    }
    both = tried[("direct drive", "direct drive")]
    assert both["objective"] is not None
    # Independently: the study written by hand with no gearbox and N fixed at 1 gives that objective.
    alone = _study(tmp_path, None, "alone.yaml", **light)
    fixed = yaml.safe_load(alone.read_text())
    fixed["actuators"]["gear_ratio"] = 1
    fixed["design"]["gear_ratio"] = 1
    alone.write_text(yaml.safe_dump(fixed))
    assert _objective(alone) == pytest.approx(both["objective"], rel=1e-6)
    # Where the run chose direct drive, the design has N = 1 and no gearbox mass.
    chosen = next(t for t in results["transmission_choice"] if t["chosen"])
    records = {record["joint"]: record for record in results["recommended"]["joints"]}
    for joint, option in chosen["assignment"].items():
        direct = option == "direct drive"
        assert (records[joint]["gear_ratio"] == 1 and not records[joint]["gearbox_mass"]) == direct


def test_direct_drive_twice_or_alone_is_refused_with_what_to_write(tmp_path):
    with pytest.raises(StudyFileError, match="listed twice"):
        load_study(_study(tmp_path, ["direct_drive", "direct_drive"]))
    with pytest.raises(StudyFileError, match=r"gearbox: null.*gear_ratio: 1"):
        load_study(_study(tmp_path, "direct_drive"))
