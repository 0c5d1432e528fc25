"""The 1D model against hand-derived values, analytic properties, quadrature and CasADi derivatives."""

from __future__ import annotations

import itertools

import casadi as ca
import numpy as np
import pytest
from scipy.integrate import quad
from scipy.optimize import minimize_scalar

import collision_reflex as cr

# A soft direct-drive finger (paper fig:motor_scale_modeling stiffnesses) and the U8 fit of tab:one_shot.
CASES = {
    "soft-dd": dict(m_f=0.2, k=1000 * 100 / 1100, k_m=1000.0, F_s=3.0, a=20.0),
    "u8-fit": dict(m_f=0.1, k=440.0, k_m=2e7, F_s=3.0, a=4.7e-5),
    "geared": dict(m_f=20.0, k=23.7e3, k_m=2e7, F_s=40.85, a=3.1e-3),
}


def test_series_stiffness_hand_values():
    assert cr.model.series_stiffness(1000.0, 100.0) == pytest.approx(1000 * 100 / 1100, rel=1e-15)
    assert cr.model.series_stiffness(np.inf, 250.0) == 250.0  # a rigid structure leaves the software spring
    assert cr.model.series_stiffness(np.inf, np.inf) == np.inf
    np.testing.assert_allclose(cr.model.series_stiffness(np.array([1.0, 2.0]), 2.0), [2 / 3, 1.0], rtol=1e-15)


def test_phases_against_hand_derivation():
    # m_f=0.5, k=200, k_m=800, F_s=4, a=2, v0=0.25:
    # I1 = 0.125; t1 = 4/(200*0.25) = 0.08, I2 = 0.5*4*0.08 = 0.16;
    # tau = sqrt(2*4/(2*800)) = sqrt(0.005); I3 = 4*tau - 800*2*tau^3/6 = (2/3)*4*tau.
    phases = cr.model.phase_impulses(0.5, 200.0, 800.0, 4.0, 2.0, 0.25)
    tau = np.sqrt(0.005)
    assert phases.initial == pytest.approx(0.125, rel=1e-15)
    assert phases.sensing == pytest.approx(0.16, rel=1e-15)
    assert phases.reaction == pytest.approx(8 / 3 * tau, rel=1e-14)
    assert phases.total == pytest.approx(0.125 + 0.16 + 8 / 3 * tau, rel=1e-14)
    t1, t2 = cr.model.collision_times(0.5, 200.0, 800.0, 4.0, 2.0, 0.25)
    assert (t1, t2) == pytest.approx((0.08, 0.08 + tau), rel=1e-14)


@pytest.mark.parametrize("case", CASES.values(), ids=CASES.keys())
def test_reaction_matches_paper_closed_form(case):
    # eq:reaction: I3 = sqrt(8 F_s^3 / (9 a k_m)); the code integrates the general moving-robot form at v_r=0.
    expected = np.sqrt(8 * case["F_s"] ** 3 / (9 * case["a"] * case["k_m"]))
    assert cr.model.phase_impulses(**case, v0=0.3).reaction == pytest.approx(expected, rel=1e-12)
    assert cr.model.phase_impulses(**case, v0=0.3, reaction="moving", v_r=0.0).reaction == pytest.approx(
        expected, rel=1e-12
    )


def test_moving_reaction_hand_value():
    # k_m=1000, F_s=2 -> x1=0.002; v_r=0.1, a=10: tau_e = (0.1 + sqrt(0.01 + 0.04))/10
    tau = (0.1 + np.sqrt(0.05)) / 10
    expected = 1000 * (0.002 * tau + 0.1 * tau**2 / 2 - 10 * tau**3 / 6)
    got = cr.model.phase_impulses(0.1, 500.0, 1000.0, 2.0, 10.0, 0.3, reaction="moving", v_r=0.1).reaction
    assert got == pytest.approx(expected, rel=1e-14)
    # default v_r is v0, and a moving robot always adds impulse
    moving = cr.model.phase_impulses(0.1, 500.0, 1000.0, 2.0, 10.0, 0.1, reaction="moving")
    assert moving.reaction == pytest.approx(got, rel=1e-14)
    assert moving.reaction > cr.model.phase_impulses(0.1, 500.0, 1000.0, 2.0, 10.0, 0.1).reaction


@pytest.mark.parametrize("case", CASES.values(), ids=CASES.keys())
def test_optimal_velocity_is_numerical_minimum(case):
    v_star = cr.optimal_velocity(case["m_f"], case["k"], case["F_s"])
    found = minimize_scalar(
        lambda log_v: cr.total_impulse(**case, v0=np.exp(log_v)),
        bracket=(np.log(v_star) - 2, np.log(v_star) + 2),
        tol=1e-12,
    )
    assert np.exp(found.x) == pytest.approx(v_star, rel=1e-6)
    assert cr.model.minimum_impulse(**case) == pytest.approx(cr.total_impulse(**case, v0=v_star), rel=1e-12)


@pytest.mark.parametrize("case", CASES.values(), ids=CASES.keys())
def test_impulse_is_convex_in_velocity(case):
    v = np.geomspace(1e-3, 1e2, 400)
    impulse = cr.total_impulse(**case, v0=v)
    # second differences on a non-uniform grid, through the exact second derivative's sign
    slope = np.diff(impulse) / np.diff(v)
    assert np.all(np.diff(slope) > 0)
    # d2I/dv0^2 = F_s^2 / (k v0^3) (paper), checked by central differences at a few points
    for v0 in (0.01, 0.1, 1.0):
        h = 1e-4 * v0
        second = (
            cr.total_impulse(**case, v0=v0 + h)
            - 2 * cr.total_impulse(**case, v0=v0)
            + cr.total_impulse(**case, v0=v0 - h)
        ) / h**2
        assert second == pytest.approx(case["F_s"] ** 2 / (case["k"] * v0**3), rel=1e-4)


def test_moving_optimum_is_below_paper_optimum_and_minimal():
    case = CASES["soft-dd"]
    v_rest = cr.optimal_velocity(case["m_f"], case["k"], case["F_s"])
    v_moving = cr.optimal_velocity(case["m_f"], case["k"], case["F_s"], "moving", case["k_m"], case["a"])
    assert 0 < v_moving < v_rest
    grid = np.linspace(0.2 * v_moving, 3 * v_moving, 20001)
    brute = grid[np.argmin(cr.total_impulse(**case, v0=grid, reaction="moving"))]
    assert v_moving == pytest.approx(brute, rel=1e-3)  # grid spacing is 1.4e-4 relative
    assert cr.model.minimum_impulse(**case, reaction="moving") <= cr.total_impulse(
        **case, v0=brute, reaction="moving"
    ) * (1 + 1e-12)


@pytest.mark.parametrize("reaction", ["at_rest", "moving"])
@pytest.mark.parametrize("case", CASES.values(), ids=CASES.keys())
def test_force_profile_integrates_to_total(case, reaction):
    v0 = 0.7 * cr.optimal_velocity(case["m_f"], case["k"], case["F_s"])
    t1, t2 = cr.model.collision_times(**case, v0=v0, reaction=reaction)
    t_impact = np.pi / 2 * np.sqrt(case["m_f"] / case["k_m"])

    def force(t):
        return float(cr.model.force_profile(t, **case, v0=v0, reaction=reaction))

    # integrate piecewise between the profile's kinks so quadrature converges to its tolerance
    breaks = sorted({0.0, min(t_impact, t2), t1, t2})
    area = sum(
        quad(force, lo, hi, epsabs=0, epsrel=1e-11, limit=200)[0] for lo, hi in itertools.pairwise(breaks)
    )
    assert area == pytest.approx(cr.total_impulse(**case, v0=v0, reaction=reaction), rel=1e-6)
    assert force(-1e-3) == 0.0 and force(t2 * 1.001) == 0.0


def test_numpy_broadcasting():
    v = np.array([[0.1], [0.2]])
    F_s = np.array([1.0, 2.0, 3.0])
    total = cr.total_impulse(0.2, 90.0, 1000.0, F_s, 20.0, v)
    assert total.shape == (2, 3)
    assert total[1, 2] == pytest.approx(cr.total_impulse(0.2, 90.0, 1000.0, 3.0, 20.0, 0.2), rel=1e-15)


@pytest.mark.parametrize("reaction", ["at_rest", "moving"])
@pytest.mark.parametrize("sym", [ca.SX, ca.MX], ids=["SX", "MX"])
def test_casadi_matches_numpy_and_finite_differences(sym, reaction):
    names = ["m_f", "k", "k_m", "F_s", "a", "v0"]
    x = sym.sym("x", 6)
    args = [x[i] for i in range(6)]
    expr = cr.total_impulse(*args, reaction=reaction)
    f = ca.Function("I", [x], [expr, ca.gradient(expr, x)])
    point = np.array([0.2, 90.0, 1000.0, 3.0, 20.0, 0.15])
    value, grad = (np.asarray(v).ravel() for v in f(point))
    assert value[0] == pytest.approx(cr.total_impulse(*point, reaction=reaction), rel=1e-13)
    for i, name in enumerate(names):
        h = 1e-6 * point[i]
        up, down = point.copy(), point.copy()
        up[i] += h
        down[i] -= h
        fd = (cr.total_impulse(*up, reaction=reaction) - cr.total_impulse(*down, reaction=reaction)) / (2 * h)
        assert grad[i] == pytest.approx(fd, rel=1e-6, abs=1e-12), name
    # the other public functions build symbolically as well
    t = sym.sym("t")
    profile = ca.Function("F", [t, x], [cr.model.force_profile(t, *args, reaction=reaction)])
    assert float(profile(0.01, point)) == pytest.approx(
        float(cr.model.force_profile(0.01, *point, reaction=reaction)), rel=1e-13
    )
    v_star = ca.Function("v", [x], [cr.optimal_velocity(args[0], args[1], args[3])])
    assert float(v_star(point)) == pytest.approx(cr.optimal_velocity(0.2, 90.0, 3.0), rel=1e-14)


def test_velocity_coefficients():
    A, B, C = cr.model.velocity_coefficients(0.2, 90.0, 1000.0, 3.0, 20.0)
    for v0 in (0.05, 0.5):
        assert A * v0 + B / v0 + C == pytest.approx(
            cr.total_impulse(0.2, 90.0, 1000.0, 3.0, 20.0, v0), rel=1e-14
        )
    assert np.sqrt(B / A) == pytest.approx(cr.optimal_velocity(0.2, 90.0, 3.0), rel=1e-14)


GOOD = dict(m_f=0.2, k=90.0, k_m=1000.0, F_s=3.0, a=20.0, v0=0.1)


@pytest.mark.parametrize(
    ("name", "value"),
    [
        ("m_f", -0.1),
        ("m_f", 0.0),
        ("k", 0.0),
        ("k_m", -5.0),
        ("F_s", 0.0),
        ("a", -1.0),
        ("v0", 0.0),
        ("v0", -0.2),
        ("m_f", np.nan),
        ("k", np.inf),
        ("F_s", np.array([1.0, np.nan])),
        ("a", "fast"),
    ],
)
def test_bad_input_names_parameter(name, value):
    with pytest.raises(cr.InvalidParameter) as info:
        cr.total_impulse(**{**GOOD, name: value})
    assert isinstance(info.value, ValueError) and isinstance(info.value, cr.CollisionReflexError)
    assert info.value.name == name
    assert name in str(info.value) and "expected" in str(info.value)


def test_bad_reaction_mode_lists_options():
    with pytest.raises(cr.InvalidParameter, match="'at_rest', 'moving'"):
        cr.model.phase_impulses(**GOOD, reaction="bounce")
    with pytest.raises(cr.InvalidParameter, match="v_r"):
        cr.model.phase_impulses(**GOOD, v_r=0.1)  # a robot velocity needs the moving reaction
    with pytest.raises(cr.InvalidParameter, match="v_r"):
        cr.model.phase_impulses(**GOOD, reaction="moving", v_r=-0.1)


IMPULSE = cr.model.impulse
HOSTILE_FORMULAS = {
    # each was a ZeroDivisionError, an inf or NaN result, or NumPy's unnamed broadcast ValueError
    "pulse_zero_mass": (IMPULSE.impact_pulse_duration, (-0.0, 0.5), "m_f"),
    "pulse_none": (IMPULSE.impact_pulse_duration, (2.0, None), "k_m"),
    "sensing_overflow": (IMPULSE.sensing_force, (1e70, 2.0, 1e300), "float64 range"),
    "sensing_none": (IMPULSE.sensing_force, (None, 10.0, 1.0), "t"),
    "sprung_overflow": (IMPULSE.sprung_reaction, (1.0, 1e-300, 2.0, 10.0), "float64 range"),
    "sprung_shapes": (IMPULSE.sprung_reaction, (np.ones(2), np.ones((3, 3)), 1.0, 1.0), "broadcast"),
    "reaction_shapes": (IMPULSE.reaction_duration, (1.0, np.ones(0), np.ones((3, 3))), "broadcast"),
    "total_shapes": (IMPULSE.total_impulse, (np.ones((3, 3)), np.ones(2), 0.5, 1.0, 1.0, 1.0), "broadcast"),
    "times_shapes": (IMPULSE.collision_times, (2.0, 3, 3, np.ones(0), 2.0, np.ones((3, 3))), "broadcast"),
    "series_shapes": (IMPULSE.series_stiffness, (np.ones(0), np.ones(2)), "broadcast"),
    "optimum_shapes": (IMPULSE.optimal_velocity, (np.ones((2, 2, 2)), 2.0, np.ones((3, 3))), "broadcast"),
}


@pytest.mark.parametrize("name", list(HOSTILE_FORMULAS), ids=list(HOSTILE_FORMULAS))
def test_impulse_formulas_refuse_hostile_numbers_with_a_named_error(name: str) -> None:
    """Zero, None, overflowing or unbroadcastable inputs raise InvalidParameter, not a crash or a silent NaN."""
    function, args, words = HOSTILE_FORMULAS[name]
    with pytest.raises(cr.InvalidParameter, match=words):
        function(*args)
