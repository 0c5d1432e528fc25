"""A duty cycle's peak, RMS and speed requirements in the optimiser, against NumPy grids and hand cases."""

from __future__ import annotations

import dataclasses
import json
import math
import re
from pathlib import Path

import casadi as ca
import numpy as np
import pytest

import collision_reflex as cr
from collision_reflex.arm import Arm
from collision_reflex.arm.duty_cycle import DutyCycle, Payload
from collision_reflex.arm.dynamics import peak, rms
from collision_reflex.errors import InvalidParameter
from collision_reflex.hardware.motors import scaled_motor_quantities
from collision_reflex.optimize import duty as duty_module
from collision_reflex.optimize.duty import approach_joint_rates, torque_speed_points
from collision_reflex.optimize.results import record_row, result_from_json, result_record, result_to_json

TWO_LINK = Path(__file__).resolve().parents[1] / "designs" / "planar_two_link.urdf"
SAFETY = 1.2
VELOCITY = 0.2  # approach velocity [m/s], fixed


@pytest.fixture(scope="module")
def arm():
    return Arm.from_urdf(TWO_LINK, "tip")


@pytest.fixture(scope="module")
def samples(arm):
    rng = np.random.default_rng(0)
    kinematics = arm.kinematics(arm.sample_configurations(2, rng))
    angles = np.linspace(0, 2 * np.pi, 3, endpoint=False) + 0.3
    return cr.ContactSamples.grid(kinematics, np.c_[np.cos(angles), np.sin(angles)])


@pytest.fixture(scope="module")
def cycle(arm):
    # Fast enough that the motor speed bounds the gear ratio, loaded enough that the torques bound the motor.
    return DutyCycle.through_via_points(
        [[0.0, 0.0], [1.2, -1.0], [0.3, 0.6]],
        arm.joint_names,
        [15.0, 20.0],
        [80.0, 100.0],
        rate=100.0,
        dwell=0.05,
        payload=Payload(2.0),
    )


def _space(**overrides):
    bounds = dict(
        stator_diameter=(0.02, 0.12),
        gear_ratio=(1.0, 100.0),
        software_stiffness=100.0,
        threshold=5.0,
        approach_velocity=VELOCITY,
    )
    return cr.DesignSpace(**{**bounds, **overrides})


def _technology(motor=None):
    return cr.ActuatorTechnology(motor or cr.reference_motor(), mechanical_stiffness=200.0)


@pytest.fixture(scope="module")
def lightest(arm, samples, cycle):
    constraints = cr.Constraints(safety_factor=SAFETY, duty_cycle=cycle)
    problem = cr.build_problem(arm, samples, _space(), _technology(), "actuator_mass", constraints)
    return problem, cr.solve(problem)


def _motor(diameter):
    law = _technology().scaling_law
    return scaled_motor_quantities(cr.reference_motor(), np.asarray(diameter), None, law)


def _pinv_rates(samples):
    """``J^+ u`` per sample, one ``np.linalg.pinv`` at a time."""
    jacobians = samples.kinematics.jacobian[samples.config_index]
    return np.array([np.linalg.pinv(j) @ u for j, u in zip(jacobians, samples.directions, strict=True)])


def test_lightest_design_beats_every_feasible_grid_point(lightest, samples, cycle):
    problem, result = lightest
    torques = problem.duty.torques
    diameters = np.geomspace(0.02, 0.12, 40)
    gears = np.geomspace(1.0, 100.0, 60)
    motor = _motor(diameters)
    speed = np.maximum(peak(cycle.qd.T), VELOCITY * np.abs(_pinv_rates(samples)).max(axis=0))

    def feasible(joint, other_mass):
        """(diameter, gear) grid of joint ``joint`` meeting peak, RMS and speed, the other motor's mass given."""
        masses = np.zeros(2)
        masses[1 - joint] = other_mass
        structure = torques.torque(masses)[:, joint]  # links, payload, the other motor [N m]
        reflected = gears[None, :, None] ** 2 * motor.rotor_inertia[:, None, None]
        demand = structure + reflected * cycle.qdd[:, joint]  # (diameter, gear, t)
        return (
            (gears * motor.peak_torque[:, None] >= SAFETY * peak(demand))
            & (gears * motor.continuous_torque[:, None] >= rms(demand, cycle.t))
            & (gears * speed[joint] <= motor.max_speed[:, None])
        ).any(axis=1)

    # Motor 2 loads joint 1 (it rides on link 1); motor 1 sits on the base and loads neither joint.
    joint2 = feasible(1, 0.0)
    joint1 = np.array([feasible(0, m2) for m2 in motor.mass])  # (d2, d1)
    total = motor.mass[None, :] + motor.mass[:, None]
    best = total[joint1 & joint2[:, None]].min()
    optimum = result.objectives["actuator_mass"]
    # Every grid point is evaluated exactly: a feasible one is feasible for the NLP and cannot beat its optimum
    # beyond IPOPT's tolerance.
    assert best >= optimum * (1 - 1e-6)
    # The grid's best is within the grid's reach of the optimum: at the optimal diameter the feasible gear
    # interval has closed (speed: N <= c/d; torque: N >= c' d^-2.5), it holds a grid gear once its log width
    # 1.5 log(d/d*) reaches one gear step s, i.e. d/d* = s^(2/3), plus one diameter step r; mass ~ d^2 per joint.
    step_d, step_n = diameters[1] / diameters[0], gears[1] / gears[0]
    assert best <= optimum * (step_d * step_n ** (2 / 3)) ** 2
    assert best > optimum * 1.001  # the grid does not contain the optimum: the bound above is what is tested


def test_optimum_is_feasible_by_numpy_evaluation(lightest, cycle, samples):
    problem, result = lightest
    design = result.design
    motor = _motor(design.stator_diameter)
    masses = np.asarray(motor.mass)
    demand = problem.duty.torques.torque(masses) + design.gear_ratio**2 * motor.rotor_inertia * cycle.qdd
    tolerance = 1e-6  # IPOPT's constraint tolerance, relative
    assert np.all(design.gear_ratio * motor.peak_torque >= SAFETY * peak(demand.T) * (1 - tolerance))
    assert np.all(design.gear_ratio * motor.continuous_torque >= rms(demand.T, cycle.t) * (1 - tolerance))
    joint_speed = np.maximum(peak(cycle.qd.T), VELOCITY * np.abs(_pinv_rates(samples)).max(axis=0))
    assert np.all(design.gear_ratio * joint_speed <= motor.max_speed * (1 + tolerance))
    # The cycle sizes this design: on each joint at least one requirement is active.
    margins = np.vstack([result.torque_margin, result.rms_margin, result.speed_margin])
    assert np.all(np.abs(margins).min(axis=0) < 1e-5)


def test_rotor_term_and_rms_against_direct_evaluation(lightest, cycle):
    problem, result = lightest
    design = result.design
    motor = _motor(design.stator_diameter)
    rotor = design.gear_ratio**2 * motor.rotor_inertia * cycle.qdd  # N^2 J_m qdd [N m]
    demand = problem.duty.torques.torque(np.asarray(motor.mass)) + rotor
    duration = cycle.t[-1] - cycle.t[0]
    direct_rms = np.sqrt(np.trapezoid(demand**2, cycle.t, axis=0) / duration)
    direct_peak = SAFETY * np.abs(demand).max(axis=0)
    assert np.abs(rotor).max() > 0.05 * np.abs(demand).max()  # the rotor term is far above the tolerance
    np.testing.assert_allclose(result.required_torque, direct_peak, rtol=1e-9)
    np.testing.assert_allclose(result.required_rms_torque, direct_rms, rtol=1e-9)
    # The NLP's own RMS rows: RMS^2 / (N tau_c)^2.
    rows = [i for i, label in enumerate(problem.constraint_labels) if label.startswith("RMS torque of")]
    g = np.asarray(ca.Function("g", [problem.nlp["x"]], [problem.nlp["g"]])(result.x)).ravel()[rows]
    np.testing.assert_allclose(
        g, (direct_rms / (design.gear_ratio * motor.continuous_torque)) ** 2, rtol=1e-9
    )


def test_approach_rates_are_the_pseudo_inverse(samples):
    np.testing.assert_allclose(approach_joint_rates(samples), _pinv_rates(samples), rtol=1e-12, atol=1e-14)


def _out_and_back(arm, speed, acceleration):
    """Both joints out by 1 rad and back, cruising at ``speed`` [rad/s] (reached: 1 rad > speed^2 / a)."""
    assert speed**2 / acceleration < 1.0
    return DutyCycle.through_via_points(
        [[0.0, 0.0], [1.0, 1.0], [0.0, 0.0]], arm.joint_names, speed, acceleration, rate=200.0
    )


def test_speed_margin_by_hand(arm, samples):
    # Fixed motor (60 mm: the reference, 492.6 rad/s) and gear ratio: the joint speed over the cycle is the
    # trapezoid's cruise speed, and the approach's is v0 max |J^+ u|.
    space = _space(stator_diameter=0.06, gear_ratio=[20.0, 15.0], threshold=(1.0, 10.0))
    constraints = cr.Constraints(safety_factor=1.0, duty_cycle=_out_and_back(arm, 2.0, 10.0))
    problem = cr.build_problem(arm, samples, space, _technology(), "worst_case_impulse", constraints)
    result = cr.solve(problem)
    approach = VELOCITY * np.abs(_pinv_rates(samples)).max(axis=0)
    joint_speed = np.maximum(2.0, approach)
    np.testing.assert_allclose(result.max_motor_speed, [20.0, 15.0] * joint_speed, rtol=1e-9)
    np.testing.assert_allclose(result.speed_limit, 492.6, rtol=1e-12)
    np.testing.assert_allclose(result.speed_margin, 492.6 / ([20.0, 15.0] * joint_speed) - 1, rtol=1e-9)


def test_unreachable_speed_names_joint_constraint_and_margin(arm, samples):
    # Joint 2 turns at 20 rad/s: at N >= 30 its motor turns at 600 rad/s, above the 492.6 rad/s of a 60 mm motor.
    space = _space(stator_diameter=[(0.02, 0.25), 0.06], gear_ratio=[(1.0, 100.0), (30.0, 40.0)])
    constraints = cr.Constraints(duty_cycle=_out_and_back(arm, 20.0, 450.0))
    with pytest.raises(InvalidParameter, match="joint2") as raised:
        cr.build_problem(arm, samples, space, _technology(), constraints=constraints)
    message = str(raised.value)
    assert "speed" in message
    expected = 492.6 / 600.0 - 1
    assert re.search(rf"best margin reachable {expected:+.1%}", message), message


def test_unreachable_peak_torque_names_joint_and_constraint(arm, samples):
    heavy = DutyCycle.through_via_points(
        [[0.0, 0.0], [1.0, 0.5]], arm.joint_names, 1.0, 5.0, rate=50.0, payload=Payload(1e4)
    )
    space = _space(gear_ratio=(1.0, 5.0))
    with pytest.raises(InvalidParameter) as raised:
        cr.build_problem(arm, samples, space, _technology(), constraints=cr.Constraints(duty_cycle=heavy))
    message = str(raised.value)
    assert "joint1" in message and "peak torque" in message
    margin = float(re.search(r"best margin reachable ([-+][0-9.]+)%", message).group(1)) / 100
    assert -1 < margin < -0.5  # a 10 t payload: far beyond any 120 mm motor at N = 5


def test_motor_without_speed_limit_is_refused_before_building(arm, samples, cycle):
    motor = dataclasses.replace(cr.reference_motor(), max_speed=None)
    with pytest.raises(InvalidParameter, match="max_speed") as raised:
        cr.build_problem(
            arm, samples, _space(), _technology(motor), constraints=cr.Constraints(duty_cycle=cycle)
        )
    assert "OPN-060-013-A" in str(raised.value)


def test_duty_cycle_adds_to_the_static_hold_not_to_given_torques(cycle):
    assert cr.Constraints(payload=1.0, duty_cycle=cycle).payload == 1.0  # held still besides the cycle
    with pytest.raises(InvalidParameter, match="torque_required"):
        cr.Constraints(torque_required=[1.0, 1.0], duty_cycle=cycle)


def test_static_requirement_is_named_and_has_no_duty_margins(arm, samples):
    problem = cr.build_problem(arm, samples, _space(), _technology(), constraints=cr.Constraints(payload=0.5))
    result = cr.solve(problem)
    assert problem.requirement == result.requirement == "static (gravity only)"
    assert result.required_rms_torque is None and result.speed_margin is None
    record = result_record(result, "static")
    assert record["requirement"] == "static (gravity only)"
    row = record_row(record, 0)
    assert not any("margin" in column or "speed" in column for column in row)  # the row as before
    with pytest.raises(InvalidParameter, match="duty cycle"):
        torque_speed_points(problem, result.design)


def test_duty_record_round_trips_and_names_the_requirement(lightest):
    problem, result = lightest
    assert problem.requirement == result.requirement == "duty cycle (peak, RMS, speed)"
    again = result_from_json(json.loads(json.dumps(result_to_json(result), allow_nan=False)))
    for name in ("required_rms_torque", "rms_margin", "max_motor_speed", "speed_limit", "speed_margin"):
        np.testing.assert_array_equal(getattr(again, name), getattr(result, name))
    row = record_row(result_record(result, "duty"), 0)
    assert row["speed_margin[joint2] [-]"] == pytest.approx(result.speed_margin[1], rel=1e-15)
    assert row["max_motor_speed[joint1] [rad/s]"] == pytest.approx(result.max_motor_speed[0], rel=1e-15)


def test_torque_speed_points_are_the_motor_side_cycle(lightest, cycle):
    problem, result = lightest
    design = result.design
    points = torque_speed_points(problem, design)
    for j, joint in enumerate(points):
        np.testing.assert_allclose(joint.cycle_speed, design.gear_ratio[j] * cycle.qd[:, j], rtol=1e-12)
        # Motor torque times N, times the safety factor, peaks at the required torque.
        peak_torque = SAFETY * design.gear_ratio[j] * np.abs(joint.cycle_torque).max()
        assert peak_torque == pytest.approx(result.required_torque[j], rel=1e-9)
        fastest = max(np.abs(joint.cycle_speed).max(), np.abs(joint.approach_speed).max())
        assert fastest == pytest.approx(result.max_motor_speed[j], rel=1e-12)
        assert math.isfinite(fastest)


def test_peak_rows_give_the_unreduced_peak_everywhere_in_the_box(arm, samples, cycle):
    # The kept rows' maximum against every row's: the peak requirement SF max_t |d_j(t)| at random x_j in the
    # box and at its corners (a linear function's extremes over a box are at corners).
    from collision_reflex.optimize.duty import duty_requirement, peak_rows

    duty = duty_requirement(arm, samples, cycle, None, _technology(), SAFETY)
    nv = duty.torques.nv
    # A box where the links' torques set the peak, then one where the rotor's acceleration may: the rows kept
    # for the first (a memo keeps them) do not cover the second.
    for rotor in (1e-5, 10.0):
        low = np.array([1.0, *np.full(nv, 0.05), 1e-6])
        high = np.array([1.0, *np.full(nv, 1.5), rotor])
        kept = peak_rows(duty, np.tile(low, (nv, 1)), np.tile(high, (nv, 1)))
        rng = np.random.default_rng(2)
        pick = (np.arange(2 ** (nv + 1))[:, None] >> np.arange(nv + 1)[None, :]) & 1
        corners = np.column_stack([np.ones(pick.shape[0]), np.where(pick == 1, high[1:], low[1:])])
        points = np.vstack([corners, rng.uniform(low, high, size=(500, nv + 2))])
        for j, (rows, index, sign) in enumerate(kept):
            basis = duty.torques.demand_basis(j)
            assert rows.shape[0] < basis.shape[0] / 10  # most rows go
            np.testing.assert_array_equal(rows, SAFETY * sign[:, None] * basis[index])
            expected = SAFETY * np.abs(points @ basis.T).max(axis=1)
            np.testing.assert_allclose((points @ rows.T).max(axis=1), expected, rtol=1e-12, atol=0)


def test_reachability_memo_answers_only_the_same_question(arm, samples):
    # The check's grids are kept per joint (the problems of one study repeat them); the memo must give the
    # same refusal again, and a changed bound must be checked anew, not answered from the memo.
    constraints = cr.Constraints(duty_cycle=_out_and_back(arm, 20.0, 450.0))
    refused = _space(stator_diameter=[(0.02, 0.25), 0.06], gear_ratio=[(1.0, 100.0), (30.0, 40.0)])
    duty_module._BEST_MARGINS.store.clear()
    messages = []
    for _ in range(2):
        with pytest.raises(InvalidParameter, match="joint2") as raised:
            cr.build_problem(arm, samples, refused, _technology(), constraints=constraints)
        messages.append(str(raised.value))
    kept = duty_module._BEST_MARGINS.store
    assert messages[0] == messages[1] and len(kept) == 2  # one grid per joint, found again
    # Joint 2's gear ratio may now go down to 1: 20 rad/s x 20 = 400 rad/s is within the motor's 492.6.
    allowed = _space(stator_diameter=[(0.02, 0.25), 0.06], gear_ratio=[(1.0, 100.0), (1.0, 40.0)])
    cr.build_problem(arm, samples, allowed, _technology(), constraints=constraints)
    assert len(kept) == 3  # joint 1's grid reused, joint 2's computed for its new bounds
    assert list(kept.values())[-1][2] > 0  # joint 2's best speed margin, now reachable


def test_cycle_torques_are_kept_per_arm_and_motion(arm, samples):
    # The RNEA over the cycle is kept (every problem of a study repeats it) and found again only for the same
    # arm and the same motion and payload: a payload 1 g heavier is another requirement.
    from collision_reflex.optimize.duty import duty_requirement

    def cycle(mass):
        return DutyCycle.through_via_points(
            [[0.0, 0.0], [1.0, 0.5]], arm.joint_names, 1.0, 5.0, rate=50.0, payload=Payload(mass)
        )

    first = duty_requirement(arm, samples, cycle(0.5), None, _technology(), SAFETY)
    again = duty_requirement(arm, samples, cycle(0.5), None, _technology(), SAFETY)
    heavier = duty_requirement(arm, samples, cycle(0.501), None, _technology(), SAFETY)
    assert again.torques is first.torques
    assert heavier.torques is not first.torques
    assert np.abs(heavier.torques.structure - first.torques.structure).max() > 1e-6
    # Another arm object (here the same robot loaded again) is never answered from another's torques.
    other = Arm.from_urdf(TWO_LINK, "tip")
    assert (
        duty_requirement(other, samples, cycle(0.5), None, _technology(), SAFETY).torques is not first.torques
    )
