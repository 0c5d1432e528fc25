"""Hostile calls to the Python API: wrong types, integer and complex arrays, extreme magnitudes, NaN starts.

Every call returns a finite value or raises :class:`InvalidParameter` naming the argument; a result that is
representable in float64 is returned, matching an independent 60-digit evaluation of the paper's formulas.
"""

from __future__ import annotations

import math
from decimal import Decimal, getcontext
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import collision_reflex as cr
from collision_reflex.arm import Arm, effective_parameters
from collision_reflex.errors import InvalidParameter

ARGS = (0.2, 90.9, 1000.0, 200.0, 20.0, 0.1)  # m_f, k, k_m, F_s, a, v0 of the issue's reproduction
FLOAT_MAX = float(np.finfo(np.float64).max)
# The logarithmic path rounds each logarithm (|ln x| <= 710) to an ulp: 710 * 2.2e-16 = 1.6e-13 per term, a
# handful of terms; 1e-11 leaves a margin and still fails a wrong formula by orders of magnitude.
LOG_PATH_RTOL = 1e-11


def reference_impulse(
    m_f: float, k: float, k_m: float, F_s: float, a: float, v0: float, v_r: float
) -> Decimal:
    """The paper's three phases in 60-digit decimals, from the textbook (not the scale-free) form."""
    getcontext().prec = 60
    getcontext().Emax, getcontext().Emin = 10**6, -(10**6)
    m_f_, k_, k_m_, F_s_, a_, v0_, v_r_ = (Decimal(x) for x in (m_f, k, k_m, F_s, a, v0, v_r))
    x1 = F_s_ / k_m_
    tau = (v_r_ + (v_r_ * v_r_ + 2 * a_ * x1).sqrt()) / a_
    reaction = k_m_ * (x1 * tau + v_r_ * tau**2 / 2 - a_ * tau**3 / 6)
    return m_f_ * v0_ + F_s_**2 / (2 * k_ * v0_) + reaction


@pytest.mark.parametrize(
    ("dtype", "value"), [(np.int16, 200), (np.uint8, 200), (np.int32, 50000), (np.int64, 200)]
)
def test_integer_arrays_give_the_float_result(dtype: type, value: int) -> None:
    # Reproduction: int16 [200] gave -1385.7 (F_s**2 wrapped around), uint8 22.4, int32 [50000] -9.9e7.
    m_f, k, k_m, _, a, v0 = ARGS
    got = cr.total_impulse(m_f, k, k_m, np.array([value], dtype), a, v0)
    expected = float(reference_impulse(m_f, k, k_m, float(value), a, v0, 0.0))
    assert got.dtype == np.float64
    assert got[0] == pytest.approx(expected, rel=1e-13)


def test_issue_value_of_the_int16_reproduction() -> None:
    got = cr.total_impulse(0.2, 90.9, 1000, np.array([200], np.int16), 20, 0.1)
    assert got[0] == pytest.approx(2219.1, abs=0.05)


@pytest.mark.parametrize("bad", ["200", b"200", [200, [1]], {"F_s": 200}, object(), True, None, 200 + 0j])
def test_wrong_types_name_the_argument(bad: object) -> None:
    m_f, k, k_m, _, a, v0 = ARGS
    for call in (
        lambda: cr.total_impulse(m_f, k, k_m, bad, a, v0),
        lambda: cr.model.phase_impulses(m_f, k, k_m, bad, a, v0),
        lambda: cr.model.collision_times(m_f, k, k_m, bad, a, v0),
        lambda: cr.model.minimum_impulse(m_f, k, k_m, bad, a),
        lambda: cr.optimal_velocity(m_f, k, bad),
        lambda: cr.simulate.CollisionSetup(
            m_f, 1.0, k_m, 100.0, 10.0, v0, cr.simulate.Detection("force", bad)
        ),
    ):
        with pytest.raises(InvalidParameter, match=r"^(F_s|detection threshold) = "):
            call()


def test_complex_input_is_refused() -> None:
    with pytest.raises(InvalidParameter, match="not complex"):
        cr.total_impulse(0.2 + 1e-3j, *ARGS[1:])
    with pytest.raises(InvalidParameter, match="v0"):
        cr.total_impulse(*ARGS[:5], np.array([0.1, 0.2], complex))


def test_setup_fields_become_floats() -> None:
    setup = cr.simulate.CollisionSetup(
        np.int16(2), 1, 1000, 100, 10, np.float32(0.25), cr.simulate.Detection("force", 3)
    )
    assert all(type(value) is float for value in (setup.m_f, setup.m_r, setup.k_m, setup.v0))
    assert type(setup.detection.threshold) is float
    with pytest.raises(InvalidParameter, match=r"^m_r = "):
        cr.simulate.CollisionSetup(0.2, [1.0, 2.0], 1000, 100, 10, 0.3, cr.simulate.Detection("force", 3))


LOG_MAGNITUDE = st.floats(-300.0, 300.0)


@settings(max_examples=1500, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.lists(LOG_MAGNITUDE, min_size=7, max_size=7), st.sampled_from(["at_rest", "moving"]))
def test_wide_range_calls_are_finite_or_refused(exponents: list[float], reaction: str) -> None:
    m_f, k, k_m, F_s, a, v0, v_r = (10.0**e for e in exponents)
    v_r_arg = v_r if reaction == "moving" else None
    reference = reference_impulse(m_f, k, k_m, F_s, a, v0, v_r if reaction == "moving" else 0.0)
    try:
        got = cr.total_impulse(m_f, k, k_m, F_s, a, v0, reaction, v_r_arg)
    except InvalidParameter:
        # Refused only where the total, or a phase of it, lies beyond float64, or the total underflows (below
        # the smallest subnormal, 4.9e-324: it would round to a silent 0).
        assert reference > Decimal(FLOAT_MAX) / 3 or reference < Decimal("4.9406564584124654e-324")
        return
    assert math.isfinite(got) and got > 0
    if reference > Decimal("1e-290"):  # well above the subnormals, where rounding is relative
        assert got == pytest.approx(float(reference), rel=LOG_PATH_RTOL)


@settings(max_examples=1500, deadline=None)
@given(st.lists(LOG_MAGNITUDE, min_size=7, max_size=7))
def test_times_minimum_and_optimum_are_finite_or_refused(exponents: list[float]) -> None:
    m_f, k, k_m, F_s, a, v0, v_r = (10.0**e for e in exponents)
    for call in (
        lambda: cr.model.collision_times(m_f, k, k_m, F_s, a, v0, "moving", v_r),
        lambda: cr.model.phase_impulses(m_f, k, k_m, F_s, a, v0),
        lambda: (cr.model.minimum_impulse(m_f, k, k_m, F_s, a),),
        lambda: (cr.optimal_velocity(m_f, k, F_s),),
    ):
        try:
            values = call()
        except InvalidParameter:
            continue
        values = (values.initial, values.sensing, values.reaction) if hasattr(values, "initial") else values
        assert all(math.isfinite(value) for value in values)


def test_optimal_velocity_beyond_double_range_is_exact() -> None:
    # 2 k m_f = 2e400 overflows, v* = F_s / sqrt(2 k m_f) = 1e100 / sqrt(2e400) does not.
    assert cr.optimal_velocity(1e200, 1e200, 1e100) == pytest.approx(1e-100 / math.sqrt(2), rel=LOG_PATH_RTOL)


def test_an_unrepresentable_result_names_the_quantity() -> None:
    with pytest.raises(InvalidParameter, match=r"the impact impulse m_f v0 = inf .*about 1e400"):
        cr.total_impulse(1e200, 1.0, 1.0, 1.0, 1.0, 1e200)


@settings(max_examples=400, deadline=None)
@given(
    st.lists(LOG_MAGNITUDE, min_size=6, max_size=6),
    st.sampled_from(["ideal", "impedance"]),
    st.sampled_from(["force", "position", "current"]),
)
def test_collision_setups_are_valid_or_refused(exponents: list[float], drive: str, kind: str) -> None:
    m_f, m_r, k_m, k_s, F_a, v0 = (10.0**e for e in exponents)
    try:
        setup = cr.simulate.CollisionSetup(
            m_f, m_r, k_m, k_s, F_a, v0, cr.simulate.Detection(kind, 1.0), drive=drive
        )
        phases = setup.closed_form()
    except InvalidParameter:
        return
    assert all(math.isfinite(value) for value in (phases.initial, phases.sensing, phases.reaction))


# ----- arm, design space and solver inputs ---------------------------------------------------------------------
TWO_LINK = Path(__file__).resolve().parents[1] / "designs" / "planar_two_link.urdf"


@pytest.fixture(scope="module")
def small_problem() -> cr.DesignProblem:
    arm = Arm.from_urdf(TWO_LINK, "tip")
    kinematics = arm.kinematics(arm.sample_configurations(2, np.random.default_rng(0)))
    angles = np.array([0.3, 0.3 + np.pi])
    samples = cr.ContactSamples.grid(kinematics, np.c_[np.cos(angles), np.sin(angles)])
    space = cr.DesignSpace(
        stator_diameter=(0.02, 0.04),
        gear_ratio=(1, 2),
        software_stiffness=100.0,
        threshold=3.0,
        approach_velocity=(0.1, 1.0),
    )
    technology = cr.ActuatorTechnology(cr.reference_motor(), mechanical_stiffness=200.0)
    return cr.build_problem(arm, samples, space, technology, bounded_objectives=("actuator_mass",))


def test_infinite_mechanical_stiffness_is_refused() -> None:
    arm = Arm.from_urdf(TWO_LINK, "tip")
    samples = arm.kinematics(arm.sample_configurations(1, np.random.default_rng(0)))
    with pytest.raises(InvalidParameter, match=r"^mechanical_stiffness = "):
        effective_parameters(samples, [[1.0, 0.0]], 1e-3, 100.0, math.inf, 10.0)
    effective_parameters(samples, [[1.0, 0.0]], 1e-3, 100.0, 1e12, 10.0)  # very stiff, finite: fine


@pytest.mark.parametrize(
    ("change", "message"),
    [
        (dict(stator_diameter=(1e-300, 1e300)), r"stator_diameter bounds .* supported range \[1e-06, 1000\]"),
        (dict(gear_ratio=[(1, 10), (1, 1e9)]), r"gear_ratio\[1\] bounds .* supported range \[1, 1e\+06\]"),
        (dict(threshold=("1", 3)), r"^threshold = "),
        (dict(approach_velocity=True), r"^approach_velocity"),
    ],
)
def test_design_space_refuses_bounds_the_model_cannot_evaluate(change: dict, message: str) -> None:
    space = dict(stator_diameter=(0.02, 0.1), gear_ratio=(1, 10), software_stiffness=100.0, threshold=3.0)
    with pytest.raises(InvalidParameter, match=message):
        cr.DesignSpace(**{"approach_velocity": (0.1, 1.0), **space, **change})


def test_solve_refuses_a_nan_start(small_problem: cr.DesignProblem) -> None:
    start = small_problem.x0.copy()
    start[0] = math.nan
    with pytest.raises(InvalidParameter, match=r"^x0 = .*finite numbers"):
        cr.solve(small_problem, x0=start)
    with pytest.raises(InvalidParameter, match=r"^x0 = "):
        cr.solve(small_problem, x0=start[:-1])


@pytest.mark.parametrize("bound", [math.nan, "2", math.inf, [1.0, 2.0]])
def test_solve_refuses_a_bad_epsilon(small_problem: cr.DesignProblem, bound: object) -> None:
    with pytest.raises(InvalidParameter, match=r"^epsilon\['actuator_mass'\] = .*a finite number"):
        cr.solve(small_problem, epsilon={"actuator_mass": bound})


@settings(max_examples=300, deadline=None)
@given(st.lists(LOG_MAGNITUDE, min_size=5, max_size=5))
def test_moving_optimum_is_finite_or_refused(exponents: list[float]) -> None:
    # Found by a bounded search on ln v0 and ln I: no overflow inside the minimiser, whatever the scale.
    m_f, k, k_m, F_s, a = (10.0**e for e in exponents)
    try:
        v_opt = cr.optimal_velocity(m_f, k, F_s, "moving", k_m, a)
        impulse = cr.model.minimum_impulse(m_f, k, k_m, F_s, a, "moving")
    except InvalidParameter:
        return
    assert 0 < v_opt <= cr.optimal_velocity(m_f, k, F_s) * (1 + 1e-12)
    assert math.isfinite(impulse) and impulse > 0


@pytest.mark.parametrize(
    ("change", "name"), [(dict(ipopt_options="max_iter=5"), "ipopt_options"), (dict(starts=True), "starts")]
)
def test_solve_refuses_wrong_types(small_problem: cr.DesignProblem, change: dict, name: str) -> None:
    with pytest.raises(InvalidParameter, match=rf"^{name} = "):
        cr.solve(small_problem, **change)


@pytest.fixture(scope="module")
def planar() -> Arm:
    return Arm.from_urdf(Path(__file__).resolve().parents[1] / "designs" / "planar_two_link.urdf", "tip")


@pytest.mark.parametrize(
    "call",
    [
        lambda arm, s: arm.kinematics(np.array([[0.3 + 1j, 1.2]])),
        lambda arm, s: cr.arm.effective_mass(s, np.array([[1.0 + 1j, 0.0]])),
        lambda arm, s: cr.arm.effective_mass(s, [[1.0, 0.0]], reflected_inertia=[1e-3 + 1j, 1e-3]),
        lambda arm, s: cr.arm.metrics.generalized_inertia_ellipsoid(s, reflected_inertia=[1e-3 + 1j, 1e-3]),
        lambda arm, s: effective_parameters(
            s,
            [[1.0 + 1j, 0.0]],
            reflected_inertia=1e-3,
            stiffness=50.0,
            mechanical_stiffness=50.0,
            torque_limit=1.0,
        ),
        lambda arm, s: cr.model.current_threshold_torque(10.0 + 1j, 0.1),
    ],
    ids=[
        "kinematics",
        "effective_mass",
        "effective_mass_inertia",
        "inertia_ellipsoid",
        "parameters",
        "current",
    ],
)
def test_complex_input_to_the_arm_functions_is_refused_not_cut_to_its_real_part(planar, call) -> None:
    """NumPy would drop the imaginary part (with a ComplexWarning) and compute on; the edge refuses it instead."""
    with pytest.raises(InvalidParameter, match="complex"):
        call(planar, planar.kinematics([[0.3, 1.2]]))


def test_a_total_that_underflows_is_refused_not_a_silent_zero() -> None:
    """m_f v0 = 1e-600 and the other phases smaller still: the impulse is positive but below 5e-324."""
    with pytest.raises(InvalidParameter, match="underflows to 0"):
        cr.total_impulse(1e-300, 1e300, 1e300, 1e-300, 1e300, 1e-300)
    assert cr.total_impulse(1e-160, 1e150, 1e150, 1e-160, 1e150, 1e-160) > 0  # 1e-320, a subnormal: kept


@pytest.mark.parametrize(
    "call",
    [
        lambda: cr.arm.Payload("x"),
        lambda: cr.arm.Payload(1 + 1j),
        lambda: cr.arm.Payload(1.0, "x"),
        lambda: cr.arm.circle_directions(1e300),
        lambda: cr.arm.sphere_directions(float("inf")),
        lambda: cr.arm.circle_directions(True),
        lambda: cr.arm.sphere_directions(1 + 1j),
        lambda: cr.model.threshold_force("position", float("nan"), 1.0),
        lambda: cr.model.threshold_force("position", 1.0, "x"),
        lambda: cr.model.threshold_force("force", "x", 1.0),
        lambda: cr.model.threshold_force("force", -3.0, 1.0),  # a negative threshold was passed on
        lambda: cr.model.threshold_force("position", -1e-3, 1e4),
        lambda: cr.simulate.contact_restitution([1.0, 2.0]),
        lambda: cr.simulate.contact_damping_for_restitution(0.5, [1.0, 2.0], 1e4),
        lambda: cr.simulate.contact_damping_for_restitution("0.5", 1.0, 1e4),
    ],
)
def test_bad_input_at_the_api_s_edges_is_invalid_parameter_not_a_traceback(call) -> None:
    """Each of these was a TypeError, ValueError or OverflowError from inside, or a NaN passed on."""
    with pytest.raises(InvalidParameter):
        call()


def test_a_very_damped_contact_takes_the_asymptotic_restitution() -> None:
    """Above a damping ratio of 1e4 the restitution is 1/(4 zeta^2) (within 1e-7 there); 1e300 overflowed."""
    assert cr.simulate.contact_restitution(2e4) == pytest.approx(1 / (4 * 4e8), rel=1e-12)
    assert cr.simulate.contact_restitution(1e300) == 0.0


def test_a_one_element_array_is_one_bound_and_bounds_hold_floats() -> None:
    """A valid input the edge refused: np.array([1.0]) is one number; np.float32 bounds become floats."""
    from collision_reflex.optimize import Bounds

    bounds = Bounds(np.array([1.0]), np.array([[2.0]]))
    assert (bounds.lower, bounds.upper) == (1.0, 2.0) and type(bounds.lower) is float
    assert type(Bounds(np.float32(1.0), 2).upper) is float
    with pytest.raises(InvalidParameter, match="lower bound"):
        Bounds(np.array([1.0, 2.0]), 3.0)
