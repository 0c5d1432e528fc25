"""Pieces of the study runner checked on their own: direction samplings, executors, dominance filter, smoke
shrinking, the run folder, the actuator-study lever mapping and the report's number format."""

from __future__ import annotations

import itertools
import math
from concurrent.futures import Future
from types import SimpleNamespace

import numpy as np
import pytest

from collision_reflex.model.impulse import phase_impulses, series_stiffness
from collision_reflex.optimize.pareto import epsilon_grid, non_dominated
from collision_reflex.report.html import number
from collision_reflex.study.actuator_study import sensing_scheme
from collision_reflex.study.executors import SerialExecutor, open_executor
from collision_reflex.study.runner import smoke_study
from collision_reflex.study.schema import SensingSpec
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
    from collision_reflex.study.schema import OBJECTIVE_NAMES, ParetoSpec

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
