"""Pieces of the study runner checked on their own: direction samplings, executors, dominance filter, smoke
shrinking, the run folder, the actuator-study lever mapping and the report's number format."""

from __future__ import annotations

import itertools
import math
from concurrent.futures import Future
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from collision_reflex.model.impulse import phase_impulses, series_stiffness
from collision_reflex.optimize.dominance import non_dominated
from collision_reflex.optimize.epsilon import epsilon_grid
from collision_reflex.report.wording import number
from collision_reflex.study.actuator_specs import SensingSpec
from collision_reflex.study.actuator_study import sensing_scheme
from collision_reflex.study.executors import SerialExecutor, open_executor
from collision_reflex.study.resolve import smoke_study
from collision_reflex.study.store import OutputFolderInUse, RunFolder


def _square(x: float) -> float:
    return x * x


@pytest.mark.parametrize("kind", ["serial", "processes"], ids=["serial", "processes"])
def test_executors_run_tasks(kind):
    with open_executor(kind, workers=2) as pool:
        assert list(pool.map(_square, range(5))) == [0, 1, 4, 9, 16]


def _imported(module: str) -> bool:
    import sys

    return module in sys.modules


def test_a_pool_starts_every_worker_at_once_and_warms_it():
    """Both workers exist before any piece is submitted, and each has imported the robot models' library
    (which nothing a piece's unpickling imports) before its first piece."""
    import multiprocessing

    with open_executor("processes", workers=2) as pool:
        assert len(multiprocessing.active_children()) >= 2
        assert all(pool.map(_imported, ["pinocchio"] * 4))


def test_serial_executor_delivers_errors_through_the_future():
    future: Future = SerialExecutor().submit(math.sqrt, -1.0)
    with pytest.raises(ValueError):
        future.result()


def test_open_executor_refuses_unknown_kinds():
    with pytest.raises(ValueError, match="executor"), open_executor("threads"):
        pass


def _result(**objectives: float) -> SimpleNamespace:
    """A stand-in for a DesignResult: the sweep's helpers read its NumPy objectives only."""
    return SimpleNamespace(numpy_objectives=objectives)


def test_non_dominated_matches_brute_force():
    rng = np.random.default_rng(3)
    records = [
        _result(worst_case_impulse=float(a), actuator_mass=float(b))
        for a, b in rng.uniform(0, 1, size=(60, 2))
    ]
    front, dropped = non_dominated(records, ("worst_case_impulse", "actuator_mass"))
    values = [
        (r.numpy_objectives["worst_case_impulse"], r.numpy_objectives["actuator_mass"]) for r in records
    ]
    expected = {v for v in values if not any(o[0] <= v[0] and o[1] <= v[1] and o != v for o in values)}
    assert {
        (r.numpy_objectives["worst_case_impulse"], r.numpy_objectives["actuator_mass"]) for r in front
    } == expected
    assert len(front) + len(dropped) == len(records)
    first = [r.numpy_objectives["worst_case_impulse"] for r in front]
    assert first == sorted(first)
    # A maximised objective (approach velocity) counts as better when larger.
    fast = [_result(worst_case_impulse=1.0, approach_velocity=v) for v in (0.1, 0.5)]
    front, _ = non_dominated(fast, ("worst_case_impulse", "approach_velocity"))
    assert [r.numpy_objectives["approach_velocity"] for r in front] == [0.5]


def test_epsilon_grid_spreads_bounds_between_saved_anchors():
    anchors = {
        "worst_case_impulse": _result(worst_case_impulse=0.2, actuator_mass=1.0),
        "actuator_mass": _result(worst_case_impulse=0.5, actuator_mass=0.1),
    }
    grid = epsilon_grid(anchors, ("actuator_mass",), 3)
    # Interior points only, evenly spaced from the loosest mass bound (1.0) to the tightest (0.1).
    assert [g["actuator_mass"] for g in grid] == pytest.approx([0.775, 0.55, 0.325], rel=1e-12)


def test_smoke_study_shrinks_counts():
    data = {
        "kind": "arm",
        "samples": {
            "configurations": {"random": {"count": 64, "seed": 1}, "list": None, "trajectory": None},
            "directions": {"circle": None, "sphere": 32, "named": None, "list": None},
        },
        "pareto": {"objectives": ["worst_case_impulse", "actuator_mass"], "points": 20},
    }
    small = smoke_study(data)
    assert small["samples"]["configurations"]["random"] == {"count": 3, "seed": 1}
    assert small["samples"]["directions"]["sphere"] == 6
    assert small["pareto"]["points"] == 4
    assert data["pareto"]["points"] == 20  # the original is left alone


def test_run_folder_refuses_another_studys_folder(tmp_path):
    folder = RunFolder(tmp_path / "out")
    assert folder.claim("abc", "name: x\n", {"study": "x"}) is False
    folder.save("point-000", {"value": 1.5})
    assert folder.claim("abc", "name: x\n", {"study": "x"}) is True  # same study: resume
    assert folder.finished("point-000") == {"value": 1.5}
    assert folder.finished("point-001") is None
    with pytest.raises(OutputFolderInUse, match="--out"):
        folder.claim("def", "name: y\n", {"study": "y"})
    (tmp_path / "other").mkdir()
    (tmp_path / "other" / "notes.txt").write_text("mine")
    with pytest.raises(OutputFolderInUse, match="not a study's output folder"):
        RunFolder(tmp_path / "other").claim("abc", "name: x\n", {})


@pytest.mark.parametrize("reaction", ["at_rest", "moving"], ids=["at-rest", "moving"])
def test_lever_mapping_equals_the_rotary_collision(reaction):
    """A joint seen at lever L (m = J/L^2, k = k_rot/L^2, F = tau/L) transfers, at the contact, the angular
    impulse of the same collision written in joint coordinates divided by L: the 1D model is the same in any
    linear coordinate, so the two must agree to rounding."""
    lever, finger_inertia, reflected, k_mech, k_soft, tau_s, tau_peak, omega = (
        0.1143,
        1.3e-3,
        1.2e-2,
        1e4,
        5.75,
        0.343,
        27.0,
        0.9,
    )
    k_rot = series_stiffness(k_mech, k_soft)
    angular = phase_impulses(finger_inertia, k_rot, k_mech, tau_s, tau_peak / reflected, omega, reaction)
    contact = phase_impulses(
        finger_inertia / lever**2,
        k_rot / lever**2,
        k_mech / lever**2,
        tau_s / lever,
        (tau_peak / lever) / (reflected / lever**2),
        omega * lever,
        reaction,
    )
    for phase in ("initial", "sensing", "reaction"):
        assert getattr(contact, phase) == pytest.approx(getattr(angular, phase) / lever, rel=1e-12)


def test_sensing_schemes_map_to_the_contact():
    from collision_reflex.hardware.actuators import Actuator
    from collision_reflex.hardware.motors import reference_motor

    lever = 0.1143
    motor = reference_motor()
    for spec, expected in [
        (SensingSpec(scheme="force", threshold="3 N"), lambda act: 3.0),
        # A contact position error e is a joint error e / L: detection at (k / L^2) e at the contact.
        (SensingSpec(scheme="position", error="2 mm"), lambda act: act.stiffness / lever**2 * 0.002),
        # Motor side of a 9:1 transmission: the joint sees 9 x the motor torque, the contact that / L.
        (SensingSpec(scheme="current", motor_torque="0.343 N*m"), lambda act: 9 * 0.343 / lever),
    ]:
        actuator = Actuator(
            motor,
            gear_ratio=9.0,
            mechanical_stiffness=1e4,
            software_stiffness=5.75,
            sensing=sensing_scheme(spec, lever),
        )
        params = actuator.contact_parameters(lever, 0.1)
        assert params.F_s == pytest.approx(expected(actuator), rel=1e-12), spec.scheme


@pytest.mark.parametrize(
    ("value", "text"),
    [
        (0.123456, "0.1235"),
        (12345.0, "1.234e+04"),
        (math.inf, "∞"),
        (None, "–"),
        ("Solve_Succeeded", "Solve_Succeeded"),
        (3, "3"),
    ],
    ids=["small", "large", "inf", "none", "text", "int"],
)
def test_report_number_format(value, text):
    assert number(value) == text


def test_every_pair_of_objectives_is_a_valid_pareto_spec():
    from collision_reflex.study.run_specs import ParetoSpec
    from collision_reflex.vocabulary import OBJECTIVE_NAMES

    for pair in itertools.combinations(OBJECTIVE_NAMES, 2):
        assert ParetoSpec(objectives=list(pair)).points == 20
    with pytest.raises(ValueError, match="different"):
        ParetoSpec(objectives=["mean_impulse", "mean_impulse"])


def test_wrong_dimension_message_names_the_value():
    """The message shows the text that was given (pydantic fills plain {name} fields only)."""
    from pydantic_core import PydanticCustomError

    from collision_reflex.study.quantities import to_si

    with pytest.raises(PydanticCustomError) as caught:
        to_si("3 N", "kg", "a mass", "0.5 kg")
    assert "'3 N' is [mass] * [length] / [time] ** 2, not [mass]" in str(caught.value)


# --- the unit registry: the part of pint's definitions datasheets use ------------------------------------------


@pytest.fixture(scope="module")
def registries():
    """The package's registry and pint's whole default one."""
    import pint

    from collision_reflex._units import unit_registry

    return unit_registry(), pint.UnitRegistry()


def test_the_registry_is_the_smaller_one(registries):
    from collision_reflex._units import registry_definitions

    ours, default = registries
    assert registry_definitions() is not None  # the installed pint's file holds every kept name
    assert len(ours._units) < len(default._units) / 2


def test_every_name_of_pints_default_registry_is_read_identically_or_refused(registries):
    """Every unit name, symbol and alias of pint's default registry, bare, plural and with every prefix: what the
    package's registry reads, the default one reads as the same unit (or one of the same value), so a dropped
    unit ("ct", "kt", "pt") is refused, never taken for a prefix and another unit ("c"+"t", "k"+"t")."""
    ours, default = registries
    spellings = {name for p in default._prefixes.values() for name in (p.name, p.symbol, *p.aliases) if name}
    prefixes = ["", *sorted(spellings)]
    read = 0
    for prefix in prefixes:
        for name in default._units:
            for text in (prefix + name, prefix + name + "s"):
                candidates = ours.parse_unit_name(text)
                if not candidates:
                    continue
                read += 1
                expected = default.parse_unit_name(text)
                assert expected, f"{text!r} is read here but not by pint's default registry"
                if candidates[0] != expected[0]:  # another spelling of one unit (fm: femto-meter, fermi)?
                    mine, theirs = ours.Quantity(1.0, text), default.Quantity(1.0, text)
                    assert mine.dimensionality == theirs.dimensionality, text
                    assert mine.to_root_units().magnitude == pytest.approx(
                        theirs.to_root_units().magnitude, rel=1e-12
                    ), text
    assert read > 10_000  # SI with its prefixes, at least


# Datasheet units with their SI values from their definitions: the inch is 0.0254 m and the pound
# 0.45359237 kg exactly (international yard and pound agreement, 1959), standard gravity 9.80665 m/s^2 (3rd
# CGPM, 1901), the mechanical horsepower 550 ft*lbf/s.
_IN, _LB, _G0 = 0.0254, 0.45359237, 9.80665
DATASHEET_UNITS = [
    ("1 mm", "m", 1e-3),
    ("1 µm", "m", 1e-6),
    ("1 um", "m", 1e-6),
    ("1 in", "m", _IN),
    ("1 inch", "m", _IN),
    ("1 ft", "m", 12 * _IN),
    ("1 thou", "m", 1e-3 * _IN),
    ("1 mi", "m", 63360 * _IN),
    ("1 g", "kg", 1e-3),
    ("1 lb", "kg", _LB),
    ("1 oz", "kg", _LB / 16),
    ("1 t", "kg", 1e3),
    ("1 lbf", "N", _LB * _G0),
    ("1 ozf", "N", _LB / 16 * _G0),
    ("1 kgf", "N", _G0),
    ("1 gf", "N", 1e-3 * _G0),
    ("1 kN", "N", 1e3),
    ("1 mN*m", "N*m", 1e-3),
    ("1 ozf*in", "N*m", _LB / 16 * _G0 * _IN),
    ("1 lbf*ft", "N*m", _LB * _G0 * 12 * _IN),
    ("1 lbf*in", "N*m", _LB * _G0 * _IN),
    ("1 kgf*cm", "N*m", _G0 * 1e-2),
    ("1 ft_lb", "N*m", _LB * _G0 * 12 * _IN),
    ("1 oz*in^2", "kg*m^2", _LB / 16 * _IN**2),
    ("1 lb*ft^2", "kg*m^2", _LB * (12 * _IN) ** 2),
    ("1 g*cm^2", "kg*m^2", 1e-7),
    ("1 kg*cm^2", "kg*m^2", 1e-4),
    ("1 lbf/in", "N/m", _LB * _G0 / _IN),
    ("1 N*m/deg", "N*m/rad", 180 / math.pi),
    ("1 rpm", "rad/s", 2 * math.pi / 60),
    ("1 krpm", "rad/s", 2e3 * math.pi / 60),
    ("1 rps", "rad/s", 2 * math.pi),
    ("1 deg/s", "rad/s", math.pi / 180),
    ("1 turn", "rad", 2 * math.pi),
    ("1 deg", "rad", math.pi / 180),
    ("1 °", "rad", math.pi / 180),
    ("1 arcmin", "rad", math.pi / 180 / 60),
    ("1 V/krpm", "V*s/rad", 60 / (2e3 * math.pi)),
    ("1 N*m/A", "N*m/A", 1.0),
    ("1 mH", "H", 1e-3),
    ("1 mΩ", "ohm", 1e-3),
    ("1 mohm", "ohm", 1e-3),
    ("1 kW", "W", 1e3),
    ("1 hp", "W", 550 * 12 * _IN * _LB * _G0),
    ("1 psi", "Pa", _LB * _G0 / _IN**2),
    ("1 bar", "Pa", 1e5),
    ("1 K/W", "K/W", 1.0),
    ("20 degC", "K", 293.15),
    ("68 degF", "K", 293.15),
    ("1 ms", "s", 1e-3),
    ("1 min", "s", 60.0),
    ("1 h", "s", 3600.0),
    ("1 kHz", "Hz", 1e3),
    ("1 mph", "m/s", 63360 * _IN / 3600),
    ("1 km/h", "m/s", 1 / 3.6),
    ("1 ft/s", "m/s", 12 * _IN),
    ("1 mA", "A", 1e-3),
    ("1 A*h", "C", 3600.0),
    ("1 percent", "", 0.01),
]


@pytest.mark.parametrize(("text", "unit", "si"), DATASHEET_UNITS, ids=[t for t, _, _ in DATASHEET_UNITS])
def test_datasheet_units_read_their_defined_value_as_pints_default_registry_does(registries, text, unit, si):
    from collision_reflex._units import parse_quantity

    _, default = registries
    assert parse_quantity(text, unit) == pytest.approx(si, rel=1e-12)
    number, name = text.split(" ", 1)
    in_default = default.Quantity(float(number), name.replace("^", "**")).to(unit or "dimensionless")
    assert parse_quantity(text, unit) == pytest.approx(float(in_default.magnitude), rel=1e-14)


def test_rev_is_a_turn():
    # Not a name of pint's own registry; datasheets write it ("4096 counts/rev", "5 mm/rev").
    from collision_reflex._units import parse_quantity

    assert parse_quantity("1 rev", "rad") == pytest.approx(2 * math.pi, rel=1e-15)
    assert parse_quantity("5 mm/rev", "m/rad") == pytest.approx(5e-3 / (2 * math.pi), rel=1e-15)


@pytest.mark.parametrize("text", ["1 statvolt", "1 kcal", "1 Btu", "1 ly", "1 eV", "1 gauss"])
def test_a_dropped_unit_is_refused_as_unknown(text):
    from collision_reflex._units import QuantityError, parse_quantity

    with pytest.raises(QuantityError) as caught:
        parse_quantity(text, "kg")
    assert caught.value.kind == "unit"


@pytest.mark.parametrize(("text", "unit", "si"), DATASHEET_UNITS, ids=[t for t, _, _ in DATASHEET_UNITS])
def test_a_number_converts_to_the_bit_as_pint_converts_it(registries, text, unit, si):
    # The package multiplies by the unit's cached factor (an offset unit, degC, goes through pint each time):
    # the same float as pint's conversion of the number, for numbers of any size and sign.
    from collision_reflex._units import parse_quantity

    _, default = registries
    name = text.split(" ", 1)[1]
    for value in np.random.default_rng(7).normal(0.0, 1.0, 20) * 10.0 ** np.arange(-9, 11):
        expected = float(default.Quantity(float(value), name.replace("^", "**")).to(unit or "").magnitude)
        assert parse_quantity(f"{float(value)!r} {name}", unit) == expected, (value, name)


# --- joint positions: never a bare number -------------------------------------------------------------------

PAPER_STUDY = Path(__file__).resolve().parents[1] / "studies" / "two_link_paper.yaml"


def _paper_text(old: str, new: str) -> str:
    text = PAPER_STUDY.read_text()
    assert old in text
    return text.replace(old, new).replace("../designs/", f"{PAPER_STUDY.parents[1] / 'designs'}/")


@pytest.mark.parametrize("bare", ["45", "0.785"])
def test_a_bare_joint_position_is_refused_at_its_line_with_the_fix(bare):
    from collision_reflex.errors import StudyFileError
    from collision_reflex.study import parse_study

    text = _paper_text("- [0 deg, 45 deg]", f"- [0 deg, {bare}]")
    line = text.splitlines().index(f"      - [0 deg, {bare}]") + 1
    with pytest.raises(StudyFileError) as caught:
        parse_study(text, "paper.yaml", PAPER_STUDY.parent)
    (problem,) = caught.value.problems
    assert (problem.line, problem.path) == (line, "samples.configurations.list[1][1]")
    assert "'30 deg'" in problem.expected and "'0.5 rad'" in problem.expected  # the fix, in the message
    assert str(problem).startswith(f"paper.yaml:{line}:")


def test_a_length_for_a_revolute_joint_is_refused_against_the_robot():
    from collision_reflex.errors import StudyFileError
    from collision_reflex.study import parse_study
    from collision_reflex.study.prepare import describe_study

    loaded = parse_study(
        _paper_text("- [0 deg, 45 deg]", "- [0 deg, 0.1 m]"), "paper.yaml", PAPER_STUDY.parent
    )
    with pytest.raises(StudyFileError, match=r"found '0.1 m' for joint joint2; expected an angle"):
        describe_study(loaded)


def test_the_resolved_study_writes_joint_positions_with_their_units():
    import yaml

    from collision_reflex.study import parse_study, resolved_yaml

    loaded = parse_study(
        _paper_text("- [0 deg, 45 deg]", "- [0.5 rad, 45 deg]"), "paper.yaml", PAPER_STUDY.parent
    )
    text = resolved_yaml(loaded)
    rows = yaml.safe_load(text)["samples"]["configurations"]["list"]
    assert rows[1] == [f"{0.5!r} rad", f"{math.radians(45)!r} rad"]
    again = parse_study(text, "resolved.yaml", PAPER_STUDY.parent)  # a resolved study is a valid study
    assert again.study.samples.configurations.list == loaded.study.samples.configurations.list
