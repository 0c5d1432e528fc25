"""Hostile study files and catalogues: each gives one located line per problem, at once, never a traceback or a hang.

Each case is a reproduction of a file that used to hang, exhaust memory or raise from deep inside, followed by
the wanted behaviour: a :class:`StudyFileError` (or :class:`CatalogueError`) naming the file, line and field,
in a message of bounded length that quotes at most an excerpt of the bad value.
"""

from __future__ import annotations

import json
import math
import textwrap
import time
from pathlib import Path

import pytest

from collision_reflex.cli import main
from collision_reflex.errors import CatalogueError, StudyFileError, StudyProblem
from collision_reflex.hardware.catalogue import read_entries
from collision_reflex.study import load_study, parse_study
from collision_reflex.study.prepare import describe_study

ROOT = Path(__file__).resolve().parents[1]

# Fast to check (a two-joint model); each case replaces one line.
BASE = textwrap.dedent(
    """\
    name: hostile
    robot:
      example_robot_data: double_pendulum
      locked_joints: []
    actuators:
      mechanical_stiffness: 1000 N*m/rad
      software_stiffness: 100
      gear_ratio: 10
    sensing: {scheme: force, threshold: 3 N}
    approach_velocity: 50 cm/s
    samples:
      configurations: {random: {count: 4, seed: 1}}
      directions: {circle: 8}
    execution: {executor: serial, workers: 2}
    """
)

# A message line stays short whatever the file holds: the longest expected text is a list of names.
MAX_MESSAGE = 600
# Refusing a file is immediate; a generous bound for a loaded CI machine, far below the old minutes.
MAX_SECONDS = 2.0


def _replaced(old: str, new: str, text: str = BASE) -> str:
    assert old in text, old
    return text.replace(old, new)


def _only_problem(text: str, load_robot: bool = True) -> StudyProblem:
    """The one problem of ``text`` (parsed as ``hostile.yaml``), found within :data:`MAX_SECONDS`."""
    start = time.perf_counter()
    with pytest.raises(StudyFileError) as caught:
        loaded = parse_study(text, "hostile.yaml", ROOT / "studies")
        describe_study(loaded, load_robot=load_robot)
    assert time.perf_counter() - start < MAX_SECONDS
    problems = caught.value.problems
    assert len(problems) == 1, problems
    problem = problems[0]
    message = str(problem)
    assert "\n" not in message and message.isprintable() and len(message) < MAX_MESSAGE, message
    assert message.startswith(f"hostile.yaml:{problem.line}:{problem.column}:")
    assert 1 <= problem.line <= text.count("\n") + 1
    return problem


def _bomb(levels: int = 9) -> str:
    """A billion-laughs document: ``levels`` levels of 9 aliases each (9**levels strings)."""
    lines = ['a0: &a0 ["lol", "lol", "lol", "lol", "lol", "lol", "lol", "lol", "lol"]']
    for level in range(1, levels):
        aliases = ", ".join([f"*a{level - 1}"] * 9)
        lines.append(f"a{level}: &a{level} [{aliases}]")
    return "\n".join(lines) + "\n"


# --- hangs and memory ---------------------------------------------------------------------------------------


def test_an_alias_bomb_is_refused_at_once_at_its_line():
    text = BASE + _bomb() + "description: *a8\n"
    problem = _only_problem(text, load_robot=False)
    assert "aliases that expand to" in problem.found
    # Located where the repetition is written (an anchor line of the bomb), not at line 1.
    assert problem.line > BASE.count("\n")


def test_a_few_aliases_are_still_read():
    text = BASE.replace("  gear_ratio: 10\n", "  gear_ratio: &ratio 10\n") + "design: {gear_ratio: *ratio}\n"
    loaded = parse_study(text, "hostile.yaml")
    assert loaded.study.design.gear_ratio.bounds == (10.0, 10.0)


def test_a_recursive_alias_is_refused():
    problem = _only_problem(BASE + "description: &loop [*loop]\n", load_robot=False)
    assert "recursive alias" in problem.found


@pytest.mark.parametrize("nested", ["[" * 100_000 + "]" * 100_000, "- " * 200_000 + "x"])
def test_a_deeply_nested_value_is_refused_not_a_crash(nested):
    """libyaml's composer recursed in C on 100,000 levels: a segmentation fault, not even a RecursionError.

    Refused at its line: by our depth limit, or by PyYAML's own where it has one (6.0.4 stops a flow
    collection 1,000 levels deep while scanning ahead, before our count of its events reaches 200).
    """
    problem = _only_problem(BASE + "description:\n  " + nested + "\n", load_robot=False)
    assert "nested deeper than" in problem.found or "nesting depth" in problem.found, problem.found
    assert problem.line == BASE.count("\n") + 2


@pytest.mark.parametrize(
    ("line", "replacement", "path"),
    [
        ("approach_velocity: 50 cm/s", "approach_velocity: 9**9**9 m/s", "approach_velocity"),
        ("  gear_ratio: 10", "  gear_ratio: '10**10**10'", "actuators.gear_ratio"),
        ("  gear_ratio: 10", "  gear_ratio: 10 m^(9**9**9)", "actuators.gear_ratio"),
        ("approach_velocity: 50 cm/s", "approach_velocity: 1/0 m/s", "approach_velocity"),
        ("approach_velocity: 50 cm/s", "approach_velocity: 1 m/s" + " * m/m" * 1500, "approach_velocity"),
        ("approach_velocity: 50 cm/s", "approach_velocity: " + "1" * 9000 + " m/s", "approach_velocity"),
    ],
    ids=["tower-with-unit", "tower-bare", "tower-in-power", "division", "9k-unit", "9k-number"],
)
def test_quantity_expressions_are_refused_at_once(line, replacement, path):
    problem = _only_problem(_replaced(line, replacement), load_robot=False)
    assert problem.path == path
    assert "a number and a unit" in problem.expected
    # The message quotes an excerpt of the value, not the value.
    assert len(problem.found) <= 60


def test_a_long_value_is_refused_before_it_is_read():
    problem = _only_problem(BASE + "description: " + "x" * 20_000 + "\n", load_robot=False)
    assert "20000 characters" in problem.found and problem.path == "description"


# --- tracebacks in `crx validate` -----------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("line", "replacement", "path", "words"),
    [
        (
            "{random: {count: 4, seed: 1}}",
            "{random: {count: 24, seed: -1}}",
            "samples.configurations.random.seed",
            "greater than or equal to 0",
        ),
        (
            "{random: {count: 4, seed: 1}}",
            "{random: {count: 2000000000, seed: 1}}",
            "samples.configurations.random.count",
            "less than or equal to 10000",
        ),
        (
            "{random: {count: 4, seed: 1}}",
            "{random: {count: 1e30, seed: 1}}",
            "samples.configurations.random.count",
            "integer",
        ),
        ("{circle: 8}", "{sphere: 3000000000}", "samples.directions.sphere", "less than or equal to 10000"),
        (
            "  locked_joints: []",
            "  locked_joints: [joint1, joint1]",
            "robot.locked_joints",
            "each joint once",
        ),
        ("  locked_joints: []", "  locked_joints: [joint1, joint2]", "robot", "at least one joint"),
        # libyaml refuses the escape itself (no field path yet); PyYAML's own parser lets us name the field.
        ("  locked_joints: []", '  contact_frame: "\\ud800"', None, "Unicode"),
        ("  example_robot_data: double_pendulum", '  urdf: "a\\0b.urdf"', "robot.urdf", "NUL"),
    ],
    ids=[
        "negative-seed",
        "huge-count",
        "float-count",
        "huge-sphere",
        "duplicate-locked",
        "all-locked",
        "surrogate-frame",
        "nul-path",
    ],
)
def test_bad_values_are_located_not_raised(line, replacement, path, words):
    text = _replaced(line, replacement)
    problem = _only_problem(text)
    if path is None:
        assert problem.line == text.splitlines().index(replacement) + 1
        assert problem.path in ("", "robot.contact_frame")
    else:
        assert problem.path == path
    assert words.lower() in str(problem).lower()


def test_an_unreadable_urdf_is_located():
    # /proc/self/mem is a regular file to stat() but reading it fails with EIO.
    if not Path("/proc/self/mem").is_file():
        pytest.skip("no /proc")
    text = _replaced("  example_robot_data: double_pendulum", "  urdf: /proc/self/mem\n  contact_frame: tip")
    problem = _only_problem(text)
    assert problem.path == "robot.urdf" and "cannot be read" in problem.found


def test_a_path_too_long_for_the_system_is_no_such_file():
    text = _replaced(
        "  example_robot_data: double_pendulum", f"  urdf: {'d' * 5000}.urdf\n  contact_frame: tip"
    )
    problem = _only_problem(text)
    assert problem.path == "robot.urdf" and "no such file" in problem.found


def test_validation_counts_random_samples_without_drawing_them(monkeypatch):
    from collision_reflex.arm import Arm

    def refuse(*args, **kwargs):
        raise AssertionError("validation drew the random configurations")

    monkeypatch.setattr(Arm, "sample_configurations", refuse)
    text = _replaced("{random: {count: 4, seed: 1}}", "{random: {count: 10000, seed: 1}}")
    summary = describe_study(parse_study(_replaced("{circle: 8}", "{circle: 10000}", text), "hostile.yaml"))
    assert "10000 configurations x 10000 directions" in summary


# --- what validates also runs: physical ranges --------------------------------------------------------------


ACTUATOR = (ROOT / "studies" / "direct_drive_vs_geared.yaml").read_text()


@pytest.mark.parametrize(
    ("text", "path", "words"),
    [
        (_replaced("workers: 2}", "workers: 100000000000}"), "execution.workers", "256"),
        (_replaced("lever: 114.3 mm", "lever: 1e-300 mm", ACTUATOR), "load.lever", "from 0.001 to 10 m"),
        (
            _replaced("finger_mass: 0.1 kg", "finger_mass: 1e300 kg", ACTUATOR),
            "load.finger_mass",
            "to 1000 kg",
        ),
        (
            _replaced("contact_stiffness: 2e7 ", "contact_stiffness: 1e-300 ", ACTUATOR),
            "load.contact_stiffness",
            "from 1 to 1e+12 N/m",
        ),
        (_replaced("  gear_ratio: 10", "  gear_ratio: 1e300"), "actuators.gear_ratio", "from 1 to 10000"),
        (
            BASE + "design: {stator_diameter: {min: 1e-300 m, max: 1e300 m}}\n",
            "design.stator_diameter.min",
            "from 0.001 to 1 m",
        ),
    ],
    ids=["workers", "lever", "finger-mass", "contact-stiffness", "gear-ratio", "stator-diameter"],
)
def test_unphysical_values_are_refused_with_the_range(text, path, words):
    problems = []
    with pytest.raises(StudyFileError) as caught:
        parse_study(text, "hostile.yaml", ROOT / "studies")
    problems = [p for p in caught.value.problems if p.path == path]
    assert problems and words in str(problems[0]), caught.value.problems


@pytest.mark.parametrize("edge", ["low", "high"])
def test_an_actuator_study_at_the_edges_of_every_range_runs(tmp_path, edge, capsys):
    """The smoke run of a study at the ends of the schema's ranges finishes with finite results."""
    low = edge == "low"
    edges = {
        "lever: 114.3 mm": "lever: 1 mm" if low else "lever: 10 m",
        "finger_mass: 0.1 kg": "finger_mass: 1e-6 kg" if low else "finger_mass: 1000 kg",
        "contact_stiffness: 2e7 ": "contact_stiffness: 1 " if low else "contact_stiffness: 1e12 ",
        "gear_ratio: 9": "gear_ratio: 1" if low else "gear_ratio: 1e4",
        "motor_torque: 0.343 N*m": "motor_torque: 1e-6 N*m" if low else "motor_torque: 1e4 N*m",
        "approach_velocity: 0.1 m/s": "approach_velocity: 1e-6 m/s" if low else "approach_velocity: 10 m/s",
        "velocities: {min: 0.01 m/s, max: 2 m/s, count: 60}": "velocities: {min: 1e-6 m/s, max: 10 m/s}",
    }
    text = ACTUATOR
    for old, new in edges.items():
        text = _replaced(old, new, text)
    text = text.replace("stator_diameter: 80 mm", "stator_diameter: 1 mm" if low else "stator_diameter: 1 m")
    text = text.replace("1e4 N*m/rad", "1e-3 N*m/rad" if low else "1e9 N*m/rad")
    text = text.replace("5.75 N*m/rad", "1e-3 N*m/rad" if low else "1e9 N*m/rad")
    study = tmp_path / "edge.yaml"
    study.write_text(text)
    assert main(["run", str(study), "--smoke", "--out", str(tmp_path / "out")]) == 0, capsys.readouterr().err
    designs = json.loads((tmp_path / "out" / "designs.json").read_text())

    def numbers(value):
        if isinstance(value, dict):
            return [n for item in value.values() for n in numbers(item)]
        if isinstance(value, list):
            return [n for item in value for n in numbers(item)]
        return [value] if isinstance(value, float) else []

    values = numbers(designs)
    assert values and all(math.isfinite(v) for v in values)


# --- located, one line each ---------------------------------------------------------------------------------


def test_a_byte_that_is_not_utf8_is_located_by_line_and_column(tmp_path):
    path = tmp_path / "bad.yaml"
    path.write_bytes(BASE.encode().replace(b"approach_velocity: 50", b"approach_velocity: \xe9 50"))
    with pytest.raises(StudyFileError) as caught:
        load_study(path)
    (problem,) = caught.value.problems
    assert (problem.line, problem.column) == (10, 20)
    assert "0xe9" in problem.found


def test_a_key_with_a_line_break_is_printed_on_one_line(tmp_path, capsys):
    path = tmp_path / "key.yaml"
    path.write_text(BASE + '"colour\\nred": 1\n')
    assert main(["validate", "--schema-only", str(path)]) == 2
    (line,) = capsys.readouterr().err.strip().splitlines()
    assert line.startswith(f"{path}:15:1: colour\\nred: found unknown key 'colour\\nred'")


@pytest.mark.parametrize(
    ("csv", "csv_line", "words"),
    [
        ('joint1,joint2\n0,0\n"1,2\n', 3, "not a CSV table"),
        ("# comment\n\njoint1,joint2\n0,0\n1,2,3\n", 5, "not a CSV table"),
        ("joint1,joint2\n0,0\n1,2,3,4\n", 3, "not a CSV table"),
        ("# comment\njoint1 [rad],joint2 [rad]\n0,0\n0.1,x\n", 4, "not a finite number"),
        ("joint1,joint2 [deg]\n0,0\n", 1, "without a unit"),
    ],
    ids=["open-quote", "too-many-fields-after-comments", "too-many-fields", "not-a-number", "bare-angle"],
)
def test_a_bad_trajectory_csv_is_one_line_with_its_csv_line(tmp_path, csv, csv_line, words):
    (tmp_path / "traj.csv").write_text(csv)
    text = _replaced("{random: {count: 4, seed: 1}}", "{trajectory: {file: traj.csv}}")
    with pytest.raises(StudyFileError) as caught:
        describe_study(parse_study(text, "hostile.yaml", tmp_path))
    (problem,) = caught.value.problems
    assert problem.line == 12 and problem.path == "samples.configurations.trajectory.file"
    assert "\n" not in str(problem)
    assert problem.found.startswith("traj.csv:") and words in problem.found
    assert problem.found.startswith(f"traj.csv:{csv_line}:")


# --- catalogues ---------------------------------------------------------------------------------------------


MOTOR = textwrap.dedent(
    """\
    motors:
      small:
        stator_diameter: 30 mm
        stack_length: 10 mm
        rotor_inertia: 1e-6
        peak_torque: 0.5
        continuous_torque: 0.2
        mass: 80 g
        source: a test entry
    """
)


def _catalogue_error(tmp_path: Path, text: str) -> CatalogueError:
    path = tmp_path / "motors.yaml"
    path.write_text(text)
    start = time.perf_counter()
    with pytest.raises(CatalogueError) as caught:
        read_entries(path, "motors")
    assert time.perf_counter() - start < MAX_SECONDS
    message = str(caught.value)
    assert "\n" not in message and len(message) < MAX_MESSAGE
    assert message.startswith(f"{path}:{caught.value.line}: ")
    return caught.value


@pytest.mark.parametrize(
    ("old", "new", "line", "field", "words"),
    [
        (
            "rotor_inertia: 1e-6",
            "rotor_inertia: !!python/name:os.system",
            5,
            "motors.small.rotor_inertia",
            "tag",
        ),
        ("  small:", "  !!python/name:os.system small:", 2, "motors.small", "tag"),
        (
            "stator_diameter: 30 mm",
            'stator_diameter: "10**10**10 mm"',
            3,
            "motors.small.stator_diameter",
            "not a quantity",
        ),
        (
            "stator_diameter: 30 mm",
            "stator_diameter: 30 mm" + " * m/m" * 1500,
            3,
            "motors.small.stator_diameter",
            "not a quantity",
        ),
        ("mass: 80 g", "mass: 2001-02-30", 8, "motors.small.mass", "number"),
    ],
    ids=["tag-value", "tag-name", "tower", "9k-unit", "impossible-date"],
)
def test_catalogue_tags_and_expressions_are_located(tmp_path, old, new, line, field, words):
    error = _catalogue_error(tmp_path, _replaced(old, new, MOTOR))
    assert error.line == line and error.field == field
    assert words in error.reason


def test_a_catalogue_alias_bomb_is_refused(tmp_path):
    error = _catalogue_error(tmp_path, MOTOR + _bomb())
    assert "aliases that expand to" in error.reason


def test_a_deeply_nested_catalogue_is_refused_not_a_crash(tmp_path):
    """A catalogue nested 100,000 levels deep crashed the interpreter in libyaml's composer."""
    error = _catalogue_error(tmp_path, MOTOR + "extra: " + "{a: " * 100_000 + "1" + "}" * 100_000 + "\n")
    assert "nested deeper than" in error.reason


def test_a_catalogue_quantity_is_read_by_the_study_grammar(tmp_path):
    """One parser for both: the same text gives the same SI number in a catalogue and in a study."""
    path = tmp_path / "motors.yaml"
    path.write_text(_replaced("rotor_inertia: 1e-6", "rotor_inertia: 0.25 kg*cm^2", MOTOR))
    inertia = read_entries(path, "motors")["small"].fields["rotor_inertia"]
    assert inertia == pytest.approx(0.25e-4, rel=1e-12)  # 1 cm^2 = 1e-4 m^2


def test_a_unit_tower_in_a_trajectory_header_is_refused_at_once(tmp_path):
    """Units in CSV headers go through the same bounded grammar (pint alone ran for minutes on this)."""
    rows = "\n".join(f"{0.01 * i:.2f}, 0, 0" for i in range(200))
    (tmp_path / "cycle.csv").write_text("time [s**9**9**9], joint1 [rad], joint2 [rad]\n" + rows + "\n")
    text = BASE + "duty_cycle: {file: cycle.csv}\n"
    start = time.perf_counter()
    with pytest.raises(StudyFileError) as caught:
        describe_study(parse_study(text, "hostile.yaml", tmp_path))
    assert time.perf_counter() - start < MAX_SECONDS
    (problem,) = caught.value.problems
    assert problem.path == "duty_cycle.file" and problem.line == text.count("\n")
    assert problem.found.startswith("cycle.csv:1:") and "unit" in problem.found


def test_a_catalogue_byte_that_is_not_utf8_is_located(tmp_path):
    path = tmp_path / "motors.yaml"
    path.write_bytes(MOTOR.encode().replace(b"mass: 80 g", b"mass: 80 \xff"))
    with pytest.raises(CatalogueError) as caught:
        read_entries(path, "motors")
    assert caught.value.line == 8 and "0xff" in caught.value.reason


def test_catalogue_messages_escape_what_cannot_be_printed(tmp_path):
    # A zero-width no-break space inside a field name (invisible in an editor) is shown, escaped.
    error = _catalogue_error(
        tmp_path, _replaced("    mass: 80 g", "    mass: 80 g\n    ma\ufeffss: 80 g", MOTOR)
    )
    assert error.line == 9 and error.field == "motors.small.ma\\ufeffss" and "unknown field" in error.reason


@pytest.mark.parametrize(
    ("text", "unit", "si"),
    [
        ("60 mm", "m", 0.06),
        ("60mm", "m", 0.06),
        (".5 m", "m", 0.5),
        ("1.3 N·m", "N*m", 1.3),
        ("1 N m/rad", "N*m/rad", 1.0),
        ("45 deg", "rad", math.pi / 4),
        ("300 deg/s^2", "rad/s^2", 300 * math.pi / 180),
        ("3000 rpm", "rad/s", 3000 * 2 * math.pi / 60),
        ("2.21e-5 kg*m**2", "kg*m^2", 2.21e-5),
        ("0.25 kg*cm^2", "kg*m^2", 0.25e-4),
        ("1 m^-1", "1/m", 1.0),
        ("2e7", "N/m", 2e7),
    ],
)
def test_the_quantity_grammar_reads_what_designers_write(text, unit, si):
    from collision_reflex._units import parse_quantity

    assert parse_quantity(text, unit) == pytest.approx(si, rel=1e-12)


@pytest.mark.parametrize(
    ("text", "kind"),
    [
        ("1 m 2", "syntax"),
        ("m", "syntax"),
        ("2 * 3 m", "syntax"),
        ("1 m^100", "syntax"),
        ("1 furlong_per_fortnight", "unit"),
        ("3 kg", "dimension"),
        ("1e308 km", "value"),
    ],
)
def test_the_quantity_grammar_refuses_the_rest(text, kind):
    from collision_reflex._units import QuantityError, parse_quantity

    with pytest.raises(QuantityError) as caught:
        parse_quantity(text, "m")
    assert caught.value.kind == kind


# --- joint limits ------------------------------------------------------------------------------------------


PANDA = (ROOT / "studies" / "panda.yaml").read_text().replace("fresh: 57344", "fresh: 0")
PANDA_RANDOM = "configurations: {random: {count: 48, seed: 11}}"


def test_a_listed_configuration_outside_the_joint_limits_is_refused_at_its_line():
    """The Panda's joint 4 is limited to [-176 deg, -4 deg] (its URDF): +90 deg was accepted before."""
    text = _replaced(
        PANDA_RANDOM,
        "configurations: {list: [[0 deg, 0 deg, 0 deg, -90 deg, 0 deg, 90 deg, 0 deg],"
        " [0 deg, 0 deg, 0 deg, 90 deg, 0 deg, 90 deg, 0 deg]]}",
        PANDA,
    )
    with pytest.raises(StudyFileError) as caught:
        describe_study(parse_study(text, "panda.yaml", ROOT / "studies"))
    (problem,) = caught.value.problems
    assert problem.path == "samples.configurations.list[1]"
    assert "panda_joint4 at 1.5708 rad, outside its limits" in problem.found and "-3.0718 to -0.0698" in str(
        problem
    )


def test_a_trajectory_row_outside_the_joint_limits_is_refused_at_its_csv_line(tmp_path):
    header = ",".join(f"panda_joint{i} [deg]" for i in range(1, 8))
    rows = ["0,0,0,-90,0,90,0", "0,10,0,-80,0,90,0", "0,10,0,90,0,90,0"]
    (tmp_path / "traj.csv").write_text("\n".join([header, *rows]) + "\n")
    text = _replaced(PANDA_RANDOM, "configurations: {trajectory: {file: traj.csv}}", PANDA)
    text = text.replace("studies/", "")
    with pytest.raises(StudyFileError) as caught:
        describe_study(parse_study(text, "panda.yaml", tmp_path))
    problem = caught.value.problems[0]
    assert problem.found.startswith("traj.csv:4: panda_joint4 at 1.5708 rad, outside its limits")


def test_a_catalogue_of_400_000_short_lines_is_refused_at_once(tmp_path):
    """200,000 repeated two-line entries (1.4 MB) took 6 s to compose before the repeated key was reported."""
    error = _catalogue_error(tmp_path, "motors:\n" + "  A:\n    mass: 1 kg\n" * 200_000)
    assert "more than 100000 values" in error.reason
