"""Study files: schema, units, located errors (all at once), resolved form, JSON Schema, `crx validate`/`schema`."""

from __future__ import annotations

import json
import re
import textwrap
from pathlib import Path

import pytest
import yaml

from collision_reflex.cli import main
from collision_reflex.errors import CollisionReflexError, StudyFileError
from collision_reflex.study import (
    ArmStudy,
    load_study,
    parse_study,
    resolved_study,
    resolved_yaml,
    study_json_schema,
)

STUDIES = sorted((Path(__file__).resolve().parents[1] / "studies").glob("*.yaml"))

MINIMAL = textwrap.dedent(
    """\
    name: minimal
    robot:
      example_robot_data: double_pendulum
    actuators:
      mechanical_stiffness: 1000 N*m/rad
      software_stiffness: 100
    sensing: {scheme: force, threshold: 3 N}
    approach_velocity: 50 cm/s
    samples:
      configurations: {random: {count: 4, seed: 1}}
      directions: {circle: 8}
    """
)


def _problems(text: str) -> list:
    with pytest.raises(StudyFileError) as caught:
        parse_study(text, "study.yaml")
    return list(caught.value.problems)


@pytest.mark.parametrize("path", STUDIES, ids=[p.stem for p in STUDIES])
def test_example_studies_are_valid_and_resolve_idempotently(path):
    loaded = load_study(path)
    resolved = resolved_study(loaded)
    # The resolved study is itself a valid study that resolves to the same data: every default and unit is
    # explicit in it, so nothing is left to interpretation.
    again = parse_study(resolved_yaml(loaded), "resolved.yaml", path.parent)
    assert resolved_study(again) == resolved


def test_quantities_with_units_become_si():
    study = parse_study(MINIMAL).study
    assert isinstance(study, ArmStudy)
    assert study.approach_velocity == pytest.approx(0.5)  # 50 cm/s, exact conversion
    assert study.actuators.software_stiffness == 100.0  # a plain number is already SI
    assert study.sensing.threshold == 3.0
    text = (
        MINIMAL.replace("1000 N*m/rad", "1 kN*m/rad")
        + "design:\n  stator_diameter: {min: 2 cm, max: 0.1 m}\n"
    )
    study = parse_study(text).study
    assert study.actuators.mechanical_stiffness == pytest.approx(1000.0)
    assert study.design.stator_diameter.bounds == pytest.approx((0.02, 0.1))


def test_defaults_are_explicit_in_the_resolved_study():
    resolved = resolved_study(parse_study(MINIMAL))
    assert resolved["objective"] == {"worst_case_impulse": 1.0}
    assert resolved["actuators"]["motor"] == {
        "reference": "OPN-060-013-A",
        "scaling_law": "haddadin",
        "stator_diameter": None,
        "stack_length": None,
    }
    assert resolved["constraints"] == {
        "payload": 0.0,
        "safety_factor": 1.0,
        "threshold_floor": 0.0,
        "torque_required": None,
        "body_region": None,
    }
    assert resolved["execution"] == {"executor": "serial", "workers": 2, "scheduler": None}
    assert resolved["robot"]["contact_offset"] is None  # the robot's default contact point


@pytest.mark.parametrize(
    ("line", "replacement", "path", "words"),
    [
        (
            "  mechanical_stiffness: 1000 N*m/rad",
            "  mechanical_stiffness: 3 kg",
            "actuators.mechanical_stiffness",
            ["'3 kg'", "[mass]", "N*m/rad"],
        ),
        ("approach_velocity: 50 cm/s", "approach_velocity: 2 s", "approach_velocity", ["m/s", "[time]"]),
        ("approach_velocity: 50 cm/s", "approach_velocity: fast", "approach_velocity", ["'fast'", "m/s"]),
        (
            "approach_velocity: 50 cm/s",
            "approach_velocity: -1",
            "approach_velocity",
            ["-1", "from 1e-06 to 10 m/s"],
        ),
        ("approach_velocity: 50 cm/s", "approach_velocity: .nan", "approach_velocity", ["finite"]),
        (
            "  directions: {circle: 8}",
            "  directions: {circle: 8, sphere: 4}",
            "samples.directions",
            ["exactly one"],
        ),
        (
            "  directions: {circle: 8}",
            "  directions: {circle: 8}\noutputs: {figure: [png]}",
            "outputs.figure",
            ["'figures'?", "pdf"],
        ),
    ],
    ids=[
        "mass-for-stiffness",
        "time-for-velocity",
        "not-a-quantity",
        "negative",
        "nan",
        "two-sources",
        "typo",
    ],
)
def test_each_problem_names_line_field_found_and_expected(line, replacement, path, words):
    assert line in MINIMAL
    text = MINIMAL.replace(line, replacement)
    (problem,) = _problems(text)
    assert problem.line == text.splitlines().index(replacement.splitlines()[-1]) + 1
    assert problem.path == path
    message = str(problem)
    assert message.startswith(f"study.yaml:{problem.line}:")
    for word in words:
        assert word in message


def test_all_problems_are_reported_at_once():
    text = textwrap.dedent(
        """\
        name: two problems and more
        robot:
          example_robot_data: double_pendulum
          colour: red
        actuators:
          mechanical_stiffness: 3 kg
          software_stiffness: 100
        sensing: {scheme: force, error: 1 mm}
        approach_velocity: 0.5
        samples:
          configurations: {random: {count: 0}}
          directions: {circle: 8}
        design:
          gear_ratio: {min: 50, max: 10}
        """
    )
    problems = _problems(text)
    by_path = {p.path: p.line for p in problems}
    assert by_path == {
        "name": 1,
        "robot.colour": 4,
        "actuators.mechanical_stiffness": 6,
        "sensing": 8,
        "samples.configurations.random.count": 11,
        "design.gear_ratio": 14,
    }
    error = StudyFileError("study.yaml", problems)
    assert str(error).startswith("6 problems in study.yaml")
    assert isinstance(error, CollisionReflexError) and isinstance(error, ValueError)


@pytest.mark.parametrize(
    ("text", "line", "words"),
    [
        ("name: x\nrobot: {example_robot_data: ur5\n", 3, ["invalid YAML"]),
        ("name: x\n  bad: indentation\n", 2, ["invalid YAML"]),
        ("", 1, ["an empty file"]),
        ("- a\n- b\n", 1, ["a list", "mapping"]),
        ("kind: hand\nname: x\n", 1, ["'hand'", "'arm'", "'actuator'"]),
        ("name: a\nname: b\n", 2, ["more than once"]),
        ("name: !!python/object:os.system x\n", 1, ["invalid YAML"]),
    ],
    ids=[
        "unclosed-flow",
        "bad-indent",
        "empty",
        "not-a-mapping",
        "unknown-kind",
        "duplicate-key",
        "unsafe-tag",
    ],
)
def test_unreadable_documents_are_located(text, line, words):
    problems = _problems(text)
    located = [p for p in problems if words[0] in str(p)]
    assert located and located[0].line == line
    for word in words:
        assert any(word in str(p) for p in located), problems


def test_missing_file(tmp_path):
    with pytest.raises(StudyFileError, match="no such file"):
        load_study(tmp_path / "absent.yaml")


def test_cross_field_checks(tmp_path):
    text = MINIMAL.replace("{scheme: force, threshold: 3 N}", "{scheme: position, error: 1 mm}")
    text += "design:\n  threshold: {min: 1 N, max: 5 N}\ninvalid_after: 1\n"
    problems = _problems(text.replace("invalid_after: 1\n", ""))
    assert [(p.path, p.line) for p in problems] == [("design.threshold", 13)]
    assert "position_error" in problems[0].expected
    # Files named by the study are looked up relative to it.
    text = MINIMAL.replace("example_robot_data: double_pendulum", "urdf: arms/missing.urdf")
    (problem,) = _problems(text)
    assert problem.path == "robot.urdf" and "no such file" in problem.found


def test_per_joint_overrides_and_bare_values_fix_a_variable():
    text = MINIMAL + textwrap.dedent(
        """\
        design:
          gear_ratio: {min: 1, max: 50, joints: {joint2: 9}}
          approach_velocity: 0.2 m/s
        """
    )
    design = parse_study(text).study.design
    assert design.gear_ratio.bounds == (1.0, 50.0)
    assert design.gear_ratio.joints["joint2"].bounds == (9.0, 9.0)
    assert design.approach_velocity.bounds == pytest.approx((0.2, 0.2))


def test_json_schema_accepts_the_examples_and_rejects_unknown_keys():
    jsonschema = pytest.importorskip("jsonschema")
    schema = study_json_schema()
    jsonschema.Draft202012Validator.check_schema(schema)
    validator = jsonschema.Draft202012Validator(schema)
    for path in STUDIES:
        data = yaml.safe_load(path.read_text())
        assert not list(validator.iter_errors(data)), path.name
    bad = yaml.safe_load(MINIMAL)
    bad["robot"]["colour"] = "red"
    assert list(validator.iter_errors(bad))


def test_cli_schema_prints_json(capsys):
    assert main(["schema"]) == 0
    assert json.loads(capsys.readouterr().out)["title"] == "collision-reflex design study"


def test_cli_validate_reports_each_problem_and_exits_2(tmp_path, capsys):
    good = tmp_path / "good.yaml"
    good.write_text(MINIMAL)
    bad = tmp_path / "bad.yaml"
    bad.write_text(MINIMAL.replace("1000 N*m/rad", "3 kg").replace("circle: 8", "circle: 8, sphere: 4"))
    assert main(["validate", "--schema-only", str(good)]) == 0
    assert "valid" in capsys.readouterr().out
    assert main(["validate", "--schema-only", str(good), str(bad)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 2
    assert err[0].startswith(f"{bad}:5:3: actuators.mechanical_stiffness: found '3 kg'")
    assert err[1].startswith(f"{bad}:11:")


def test_readme_annotated_study_is_valid():
    readme = Path(__file__).resolve().parents[1] / "README.md"
    blocks = [b for b in re.findall(r"```yaml\n(.*?)```", readme.read_text(), flags=re.S) if "name:" in b]
    assert blocks, "the README has no annotated study"
    # It lives in studies/ as far as its relative paths are concerned.
    study = parse_study(blocks[0], "README.md", STUDIES[0].parent).study
    assert isinstance(study, ArmStudy) and study.pareto is not None


def test_multi_start_anchors_are_validated_and_in_the_json_schema():
    pareto = "pareto: {objectives: [worst_case_impulse, actuator_mass], points: 6, anchor_starts: 3}\n"
    study = parse_study(MINIMAL + pareto).study
    assert isinstance(study, ArmStudy) and study.pareto is not None and study.pareto.anchor_starts == 3
    default = parse_study(MINIMAL + pareto.replace(", anchor_starts: 3", "")).study
    assert isinstance(default, ArmStudy) and default.pareto is not None and default.pareto.anchor_starts == 1
    for bad, words in (("0", ["anchor_starts", "greater than or equal to 1"]), ("2.5", ["anchor_starts"])):
        text = MINIMAL + pareto.replace("anchor_starts: 3", f"anchor_starts: {bad}")
        (problem,) = _problems(text)
        assert problem.line == len(text.splitlines()) and problem.path == "pareto.anchor_starts"
        for word in words:
            assert word in str(problem)
    properties = study_json_schema()["$defs"]["ParetoSpec"]["properties"]
    assert properties["anchor_starts"]["minimum"] == 1 and properties["anchor_starts"]["default"] == 1
