"""Duty cycles: spline derivatives against an analytic motion, the generated trapezoidal motion against its
limits and via points, trajectory files with units, and every bad input with its located error."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from collision_reflex.arm.duty_cycle import COARSE_TOLERANCE, MIN_SAMPLES, DutyCycle, Payload, TrajectoryError
from collision_reflex.errors import InvalidParameter, TraceError

NAMES = ("shoulder", "elbow")
AMPLITUDE = np.array([0.8, 0.5])  # [rad]
OMEGA = np.array([2 * np.pi, 3 * np.pi])  # [rad/s]


def _sines(t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    angle = OMEGA * t[:, None]
    return (
        AMPLITUDE * np.sin(angle),
        AMPLITUDE * OMEGA * np.cos(angle),
        -AMPLITUDE * OMEGA**2 * np.sin(angle),
    )


def test_spline_derivatives_match_analytic_motion():
    t = np.linspace(0.0, 2.0, 81)
    h = t[1] - t[0]
    q, qd, qdd = _sines(t)
    cycle = DutyCycle.from_positions(t, q, NAMES)
    # A quintic interpolating spline's r-th derivative errs by at most C h^(6-r) max|q^(6)|, here
    # max|q^(6)| = A w^6; C <= 1 on a uniform grid (observed ~0.25 for r = 2 and ~0.05 for r = 1, ends
    # included). Relative to the peaks A w and A w^2: (w h)^5 and (w h)^4.
    wh = OMEGA * h
    velocity_tol, acceleration_tol = wh**5, wh**4
    assert np.all(velocity_tol < 0.01) and np.all(acceleration_tol < 0.05)  # a 10 % error is caught
    np.testing.assert_array_less(np.max(np.abs(cycle.qd - qd), axis=0), velocity_tol * AMPLITUDE * OMEGA)
    np.testing.assert_array_less(
        np.max(np.abs(cycle.qdd - qdd), axis=0), acceleration_tol * AMPLITUDE * OMEGA**2
    )
    np.testing.assert_allclose(cycle.q, q, rtol=0, atol=1e-15)
    # A derivative off by 10 % would fail these bounds.
    assert np.all(np.max(np.abs(1.1 * cycle.qdd - qdd), axis=0) > acceleration_tol * AMPLITUDE * OMEGA**2)
    assert np.all(np.max(np.abs(1.1 * cycle.qd - qd), axis=0) > velocity_tol * AMPLITUDE * OMEGA)


def test_spline_error_shrinks_with_the_fourth_power_of_the_step():
    errors = []
    for n in (81, 161):
        t = np.linspace(0.0, 2.0, n)
        q, _, qdd = _sines(t)
        errors.append(np.max(np.abs(DutyCycle.from_positions(t, q, NAMES).qdd - qdd)))
    assert errors[0] / errors[1] > 2**4 * 0.8  # order 4 (not 2, as a cubic spline's accelerations)


def _write(path: Path, text: str) -> Path:
    path.write_text(text)
    return path


def _csv(t: np.ndarray, q: np.ndarray, header: str = "time [ms],shoulder [deg],elbow [rad]") -> str:
    rows = [header] + [
        f"{1000 * ti:.17g},{np.degrees(a):.17g},{b:.17g}" for ti, (a, b) in zip(t, q, strict=True)
    ]
    return "\n".join(rows) + "\n"


def test_csv_with_units(tmp_path):
    t = np.linspace(0.0, 2.0, 81)
    q = _sines(t)[0]
    path = _write(tmp_path / "cycle.csv", "# a pick and place\n" + _csv(t, q).replace("\n", ",ignored\n", 1))
    cycle = DutyCycle.from_csv(path, NAMES, payload=Payload(1.0))
    np.testing.assert_allclose(cycle.t, t, rtol=1e-15, atol=1e-15)
    np.testing.assert_allclose(cycle.q, q, rtol=1e-14, atol=1e-15)
    np.testing.assert_allclose(cycle.qd, DutyCycle.from_positions(t, q, NAMES).qd, rtol=1e-9, atol=1e-9)
    assert cycle.payload is not None and cycle.payload.mass == 1.0


def test_csv_prismatic_joint_in_millimetres(tmp_path):
    t = np.linspace(0.0, 1.0, 41)
    slide = 0.1 * np.sin(2 * np.pi * t)
    rows = ["t,slide [mm]"] + [f"{a:.17g},{1000 * b:.17g}" for a, b in zip(t, slide, strict=True)]
    cycle = DutyCycle.from_csv(_write(tmp_path / "s.csv", "\n".join(rows)), ["slide"], prismatic=["slide"])
    np.testing.assert_allclose(cycle.q[:, 0], slide, rtol=1e-14, atol=1e-15)


def _failure(tmp_path: Path, text: str, **options) -> TrajectoryError:
    path = _write(tmp_path / "bad.csv", text)
    with pytest.raises(TrajectoryError) as caught:
        DutyCycle.from_csv(path, NAMES, **options)
    assert str(path) in str(caught.value)
    assert isinstance(caught.value, TraceError) and isinstance(caught.value, ValueError)
    return caught.value


GOOD_T = np.linspace(0.0, 2.0, 81)
GOOD_Q = _sines(GOOD_T)[0]


def test_missing_joint_column(tmp_path):
    error = _failure(tmp_path, _csv(GOOD_T, GOOD_Q, "time [s],shoulder [deg],wrist [rad]"))
    assert error.line == 1 and "elbow" in error.reason


def test_missing_time_column(tmp_path):
    error = _failure(tmp_path, "# comment\n" + _csv(GOOD_T, GOOD_Q, "clock [s],shoulder [deg],elbow [rad]"))
    assert error.line == 2 and "time" in error.reason


@pytest.mark.parametrize(
    "header",
    [
        "time [s],shoulder [N*m],elbow [rad]",
        "time [kg],shoulder [deg],elbow [rad]",
        "time [s],shoulder [furlong_x],elbow",
    ],
)
def test_wrong_units(tmp_path, header):
    error = _failure(tmp_path, _csv(GOOD_T, GOOD_Q, header))
    assert error.line == 1 and "unit" in error.reason


def test_non_increasing_and_repeated_time(tmp_path):
    t = GOOD_T.copy()
    t[10] = t[9]  # repeated: the 11th sample, file line 12
    assert _failure(tmp_path, _csv(t, GOOD_Q)).line == 12
    t = GOOD_T.copy()
    t[20] = t[18]
    error = _failure(tmp_path, _csv(t, GOOD_Q))
    assert error.line == 22 and "increas" in error.reason


def test_nan_and_non_numeric_values(tmp_path):
    text = _csv(GOOD_T, GOOD_Q).splitlines()
    text[5] = text[5].split(",")[0] + ",nan,0.1"
    assert _failure(tmp_path, "\n".join(text)).line == 6
    text = _csv(GOOD_T, GOOD_Q).splitlines()
    text[7] = "abc," + ",".join(text[7].split(",")[1:])
    error = _failure(tmp_path, "\n".join(text))
    assert error.line == 8 and "time" in error.reason
    text = _csv(GOOD_T, GOOD_Q).splitlines()
    text.insert(4, "")  # a blank line inside the data is a missing sample
    assert _failure(tmp_path, "\n".join(text)).line == 5


def test_too_few_samples(tmp_path):
    error = _failure(tmp_path, _csv(GOOD_T[: MIN_SAMPLES - 1], GOOD_Q[: MIN_SAMPLES - 1]))
    assert "too few samples" in error.reason and str(MIN_SAMPLES) in error.reason


def test_sampling_too_coarse(tmp_path):
    t = np.linspace(0.0, 2.0, 13)  # 6 samples per period of the shoulder, 4 of the elbow
    error = _failure(tmp_path, _csv(t, _sines(t)[0]))
    assert "too coarse" in error.reason and error.line is not None and 2 <= error.line <= 14
    # The criterion's threshold is what it says: 10 samples per period pass.
    t = np.linspace(0.0, 2.0, 31)
    DutyCycle.from_csv(_write(tmp_path / "fine.csv", _csv(t, _sines(t)[0])), NAMES)
    assert COARSE_TOLERANCE == 0.1


def test_a_joint_held_still_is_not_sampled_too_coarsely(tmp_path):
    """A joint at a constant 0.5236 rad has round-off accelerations only; it was refused as sampled too coarsely."""
    t = np.linspace(0.0, 2.0, 201)
    q = _sines(t)[0]
    q[:, 0] = 0.5236
    cycle = DutyCycle.from_csv(_write(tmp_path / "held.csv", _csv(t, q)), NAMES)
    assert np.all(np.abs(cycle.qd[:, 0]) < 1e-9)


def test_time_steps_too_short_for_the_derivatives_are_located(tmp_path, recwarn):
    """Times of 1e-302 s gave NumPy overflow warnings and an unlocated 'qdd = array ... containing nan'."""
    t = np.linspace(0.0, 2.0, 201)
    error = _failure(tmp_path, _csv(t * 1e-300, _sines(t)[0]))
    assert "float64 range" in error.reason and error.line == 2
    assert not [w for w in recwarn if issubclass(w.category, RuntimeWarning)]


def test_error_survives_pickling(tmp_path):
    import pickle

    error = _failure(tmp_path, _csv(GOOD_T[:3], GOOD_Q[:3]))
    copy = pickle.loads(pickle.dumps(error))
    assert str(copy) == str(error) and copy.line == error.line


def test_trajectory_error_is_one_class_in_errors():
    from collision_reflex import errors

    assert TrajectoryError is errors.TrajectoryError
    assert issubclass(TrajectoryError, errors.TraceError) and issubclass(TrajectoryError, ValueError)


def test_unreadable_and_empty_files(tmp_path):
    with pytest.raises(TrajectoryError, match="cannot read"):
        DutyCycle.from_csv(tmp_path / "absent.csv", NAMES)
    _failure(tmp_path, "# only a comment\n")


def test_array_errors_name_the_sample():
    t = GOOD_T.copy()
    t[3] = np.nan
    with pytest.raises(TrajectoryError, match="sample 3") as caught:
        DutyCycle.from_positions(t, GOOD_Q, NAMES)
    assert caught.value.line is None
    with pytest.raises(InvalidParameter, match="shape"):
        DutyCycle.from_positions(GOOD_T, GOOD_Q[:, :1], NAMES)
    with pytest.raises(InvalidParameter, match="distinct"):
        DutyCycle.from_positions(GOOD_T, GOOD_Q, ("a", "a"))


def test_generated_motion_respects_limits_and_hits_via_points():
    via = np.array([[0.0, 0.0, 0.0], [1.2, -0.4, 0.3], [1.2, -0.4, 0.3], [-0.5, 0.6, 0.0], [0.0, 0.0, 0.0]])
    v_max, a_max = np.array([1.5, 1.0, 2.0]), np.array([4.0, 2.0, 8.0])
    cycle = DutyCycle.through_via_points(
        via, ("a", "b", "c"), v_max, a_max, rate=200.0, dwell=[0.2, 0.5, 0, 0.3, 0.1]
    )
    assert np.all(np.abs(cycle.qd) <= v_max * (1 + 1e-12))
    assert np.all(np.abs(cycle.qdd) <= a_max * (1 + 1e-12))
    # Each segment has one joint at its acceleration limit (and here also at its speed limit or not).
    assert np.isclose(np.max(np.abs(cycle.qdd) / a_max), 1.0, rtol=1e-12)
    # At rest at both ends; every via point is passed at rest.
    np.testing.assert_array_equal(cycle.qd[[0, -1]], 0.0)
    np.testing.assert_array_equal(cycle.qdd[-1], 0.0)
    at_rest = np.all(cycle.qd == 0, axis=1)
    for point in via:
        hits = np.all(np.abs(cycle.q - point) < 1e-12, axis=1)
        assert np.any(hits & at_rest), point
    np.testing.assert_array_equal(cycle.q[0], via[0])
    np.testing.assert_allclose(cycle.q[-1], via[-1], atol=1e-15)
    # Analytic derivatives agree with finite differences of the positions (central, O(h^2) ~ a_max h^2).
    h = 1 / 200.0
    uniform = np.abs(np.diff(cycle.t) - h) < 1e-9
    inner = np.flatnonzero(uniform[:-1] & uniform[1:]) + 1
    central = (cycle.q[inner + 1] - cycle.q[inner - 1]) / (2 * h)
    np.testing.assert_allclose(central, cycle.qd[inner], rtol=0, atol=np.max(a_max) * h)
    # The path between via points is straight in joint space.
    first = (cycle.t > 0.2) & (cycle.t < 0.2 + 1.0)
    direction = (via[1] - via[0]) / np.linalg.norm(via[1] - via[0])
    offsets = cycle.q[first] - via[0]
    np.testing.assert_allclose(offsets - np.outer(offsets @ direction, direction), 0.0, atol=1e-14)


def test_generated_triangular_profile():
    # 4 rad at 1 rad/s^2 with a 10 rad/s limit: never cruises; 2 s up, 2 s down, peak sqrt(D a) = 2 rad/s.
    cycle = DutyCycle.through_via_points([[0.0], [4.0]], ("a",), 10.0, 1.0, rate=10.0)
    assert cycle.duration == pytest.approx(4.0, rel=1e-14)
    assert np.max(cycle.qd) == pytest.approx(2.0, rel=1e-14)


@pytest.mark.parametrize(
    ("options", "name"),
    [
        ({"max_velocity": 0.0}, "max_velocity"),
        ({"max_acceleration": [1.0, np.nan]}, "max_acceleration"),
        ({"rate": -1.0}, "rate"),
        ({"dwell": -0.1}, "dwell"),
        ({"via_points": [[0.0, 0.0]]}, "via_points"),
        ({"via_points": [[0.0, 0.0], [0.0, 0.0]]}, "via_points"),
    ],
)
def test_generated_motion_bad_input(options, name):
    arguments = {
        "via_points": [[0.0, 0.0], [1.0, 1.0]],
        "max_velocity": 1.0,
        "max_acceleration": 1.0,
        **options,
    }
    with pytest.raises(InvalidParameter) as caught:
        DutyCycle.through_via_points(joint_names=NAMES, **arguments)
    assert caught.value.name == name


@pytest.mark.parametrize(
    ("mass", "inertia"),
    [
        (0.0, None),
        (np.nan, None),
        (1.0, np.ones((2, 2))),
        (1.0, [[1, 0.5, 0], [0, 1, 0], [0, 0, 1]]),
        (1.0, -np.eye(3)),
    ],
)
def test_payload_bad_input(mass, inertia):
    with pytest.raises(InvalidParameter):
        Payload(mass) if inertia is None else Payload(mass, inertia)


@pytest.mark.parametrize(
    "header", ["time [s],j1 [deg],j1 [deg],j2 [deg]", "time [s],j1 [deg],j1 [rad],j2 [deg]"]
)
def test_a_header_naming_a_joint_twice_is_located(tmp_path, header) -> None:
    """Pandas renamed the repeated column, which then matched no header pattern: an AttributeError before."""
    path = tmp_path / "cycle.csv"
    path.write_text(header + "\n" + "".join(f"{t * 0.1},{t},{t},{t}\n" for t in range(20)))
    with pytest.raises(TrajectoryError, match=r"line 1: the header names the column 'j1.*' twice"):
        DutyCycle.from_csv(path, ["j1", "j2"])


def test_a_cycle_with_absurd_joint_speeds_or_too_many_samples_is_refused() -> None:
    """2.5e300 rad/s validated before (a wrong unit, never a motion); a million samples grew a run past 10 GB."""
    from collision_reflex.arm.duty_cycle import MAX_CYCLE_SAMPLES, MAX_JOINT_SPEED

    t = np.linspace(0.0, 1.0, 11)
    q = np.zeros((11, 1))
    qd = np.zeros((11, 1))
    qd[5, 0] = 2.5e300
    with pytest.raises(InvalidParameter, match="joint speeds of at most"):
        DutyCycle(("j1",), t, q, qd, np.zeros((11, 1)))
    qd[5, 0] = MAX_JOINT_SPEED  # at the bound: a (very fast) motion
    DutyCycle(("j1",), t, q, qd, np.zeros((11, 1)))
    n = MAX_CYCLE_SAMPLES + 1
    with pytest.raises(InvalidParameter, match="resample the cycle"):
        DutyCycle(("j1",), np.linspace(0.0, 1.0, n), np.zeros((n, 1)), np.zeros((n, 1)), np.zeros((n, 1)))
