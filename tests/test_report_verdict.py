"""The verdict an arm report opens with, decided from hand-made records: active bounds and constraints per
joint, the front's spans, flat and degenerate fronts, the lightest design near the best impulse, warnings."""

from __future__ import annotations

import pytest

from collision_reflex.report.certainty import certainty_sentences, statistics_rows, statistics_warnings
from collision_reflex.report.front_verdict import (
    flat_impulse_reason,
    front_sentences,
    lightest_near_best,
    objective_spans,
)
from collision_reflex.report.sizing import (
    ACTIVE_TOLERANCE,
    bound_position,
    bound_sentences,
    oversized_warnings,
    sized_by_sentences,
    smallest_motor_excess,
)
from collision_reflex.report.verdict import MAX_LINES, build_sentences, verdict

BOUNDS = {
    "stator_diameter": {"shoulder": [0.03, 0.14], "elbow": [0.03, 0.14]},
    "stack_length": {"shoulder": [0.0125, 0.0125], "elbow": [0.0125, 0.0125]},  # fixed
    "gear_ratio": {"shoulder": [10.0, 160.0], "elbow": [10.0, 160.0]},
    "software_stiffness": {"shoulder": [50.0, 3000.0], "elbow": [50.0, 3000.0]},
    "threshold": [1.0, 20.0],
    "approach_velocity": [0.05, 0.5],
}


def joint(name="shoulder", diameter=0.08, ratio=50.0, stiffness=500.0, margin=0.5, **extra):
    peak = 10.0
    return {
        "joint": name,
        "stator_diameter": diameter,
        "stack_length": 0.0125,
        "gear_ratio": ratio,
        "software_stiffness": stiffness,
        "peak_torque": peak,
        "required_torque": None if margin is None else peak / (1 + margin),
        "torque_margin": margin,
        "nearest_catalogue_motor": "M-80",
        **extra,
    }


def record(impulse=0.5, mass=1.0, joints=None, threshold=5.0, velocity=0.2):
    return {
        "label": "",
        "objectives": {"worst_case_impulse": impulse, "mean_impulse": impulse / 2, "actuator_mass": mass},
        "threshold": threshold,
        "sensing": "force",
        "approach_velocity": velocity,
        "joints": joints or [joint(), joint("elbow")],
    }


def pareto(points, merged=0):
    return {"objectives": ["worst_case_impulse", "actuator_mass"], "points": points, "merged": merged}


def test_bound_position_within_the_relative_tolerance():
    assert bound_position(10.0 * (1 + 0.5 * ACTIVE_TOLERANCE), [10.0, 160.0]) == "lower"
    assert bound_position(10.0 * (1 + 2 * ACTIVE_TOLERANCE), [10.0, 160.0]) is None
    assert bound_position(160.0 * (1 - 0.5 * ACTIVE_TOLERANCE), [10.0, 160.0]) == "upper"
    assert bound_position(0.0125, [0.0125, 0.0125]) == "fixed"


def test_the_bounds_that_hold_a_design_are_named_once_per_kind():
    at_bounds = joint(diameter=0.03, ratio=160.0, stiffness=50.0, margin=0.5 * ACTIVE_TOLERANCE)
    elbow = {**at_bounds, "joint": "elbow"}
    (line,) = bound_sentences(record(joints=[at_bounds, elbow], threshold=1.0), BOUNDS)
    assert line == (
        "Held by the design bounds, not the physics (widen them to see where the design settles): threshold at "
        "its lower bound (1 N); shoulder and elbow motor at its smallest size; shoulder and elbow gear ratio at "
        "its upper bound (160); shoulder and elbow software stiffness at its lower bound (50 N·m/rad)."
    )
    # Inside every bound: nothing said.
    assert bound_sentences(record(joints=[joint(), joint("elbow")]), BOUNDS) == []


def test_what_sizes_each_joint_or_module():
    shoulder = joint(margin=0.0, required_by="braking", module=["shoulder", "elbow"])
    elbow = joint("elbow", margin=0.0, required_by="braking of shoulder", module=["shoulder", "elbow"])
    (line,) = sized_by_sentences(record(joints=[shoulder, elbow]), "duty cycle (peak, RMS, speed)")
    assert line == "Sized by (duty cycle (peak, RMS, speed)): shoulder and elbow: braking of shoulder."
    cycled = joint(margin=0.3, rms_margin=0.0, speed_margin=0.2 * ACTIVE_TOLERANCE)
    (line,) = sized_by_sentences(record(joints=[cycled, joint("elbow")]), "duty cycle")
    assert line == "Sized by (duty cycle): shoulder: RMS torque, speed."
    (line,) = sized_by_sentences(record(joints=[joint(margin=None), joint("elbow", margin=None)]), "static")
    assert line.startswith("No joint has a torque requirement (static)")


def test_spans_in_percent_of_the_best():
    points = [record(0.50, 2.0), record(0.55, 0.5)]
    spans = objective_spans(points, ["worst_case_impulse", "actuator_mass"])
    assert spans["worst_case_impulse"] == pytest.approx(10.0, rel=1e-12)  # 0.05 / 0.50
    assert spans["actuator_mass"] == pytest.approx(300.0, rel=1e-12)  # 1.5 / 0.5
    # A maximised objective spans relative to its largest value.
    velocity = objective_spans(
        [{"objectives": {"approach_velocity": 0.4}}, {"objectives": {"approach_velocity": 0.5}}],
        ["approach_velocity"],
    )
    assert velocity["approach_velocity"] == pytest.approx(20.0, rel=1e-12)


def test_the_flat_front_sentence_fires_on_a_flat_front_only():
    flat = pareto([record(0.5000, 2.0), record(0.5005, 1.0), record(0.5011, 0.11)])  # 0.22 % vs 18x in mass
    lines = front_sentences(flat)
    assert (
        "Flat in worst case impulse (less than 1 % between its designs): actuator mass is the only real choice."
        in lines
    )
    trade_off = pareto([record(0.40, 2.0), record(0.46, 1.0), record(0.60, 0.2)])  # 50 % vs 900 %
    lines = front_sentences(trade_off)
    assert lines[0] == (
        "Front of 3 designs: worst case impulse 0.4–0.6 N·s (50 %), actuator mass 0.2–2 kg (900 %)."
    )
    assert not any("Flat" in line or "Degenerate" in line for line in lines)


def test_a_flat_impulse_front_says_which_phase_carries_the_impulse():
    # Phases by hand: the worst sample (1.0 + 0.05 + 0.05 N s) is 90.9 % impact; all samples 1.6 of 1.8 N s.
    phases = {"initial": [1.0, 0.4, 0.2], "sensing": [0.05, 0.05, 0.03], "reaction": [0.05, 0.01, 0.01]}
    recommended = {**record(0.5005, 1.0), "phases": phases}
    flat = pareto([record(0.5000, 2.0), recommended, record(0.5011, 0.11)])
    (line,) = flat_impulse_reason(flat, recommended, {"reflected_inertia_in": "robot"})
    assert line.startswith("Why: the impact phase m_f v0")
    assert "carries 90.9 % of the worst sample's impulse and 88.9 % of all samples'" in line
    assert "rotors sit behind the joint springs" in line
    trade_off = pareto([record(0.40, 2.0), recommended, record(0.60, 0.2)])
    assert flat_impulse_reason(trade_off, recommended, {}) == []
    # A front of one design gets the same numbers and says the lightest is the gentlest.
    (line,) = flat_impulse_reason(pareto([recommended]), recommended, {"reflected_inertia_in": "robot"})
    assert "90.9 %" in line
    assert line.endswith("the lightest actuators that meet the requirements are also the gentlest.")


def test_degenerate_fronts_are_said_in_plain_words():
    (one,) = front_sentences(pareto([record()], merged=2))
    assert one == (
        "One design on the front: worst case impulse and actuator mass do not trade off within these bounds."
    )
    same = front_sentences(pareto([record(0.5, 1.0), record(0.5001, 0.999)]))
    assert any(line.startswith("Degenerate front: every design within 1 %") for line in same)


def test_the_lightest_design_within_5_percent_of_the_best_impulse():
    points = [record(0.40, 2.0), record(0.41, 1.0), record(0.418, 0.8), record(0.43, 0.2)]
    index, sentence = lightest_near_best(pareto(points))
    assert index == 2  # 0.418 <= 1.05 * 0.40 = 0.42; 0.43 is beyond
    assert "Pareto design 2, 0.8 kg at 0.418 N·s (4.5 % above the best)" in sentence
    assert (
        lightest_near_best({"objectives": ["worst_case_impulse", "approach_velocity"], "points": points})
        is None
    )
    assert lightest_near_best(pareto(points[:1])) is None  # one design: nothing to choose


def test_oversized_joints_are_warned_unless_their_motor_is_smallest():
    big = joint(diameter=0.08, margin=2.5)
    smallest = joint("elbow", diameter=0.03, margin=25.0)
    warnings = oversized_warnings(record(joints=[big, smallest]), BOUNDS)
    assert len(warnings) == 1 and warnings[0].startswith("Warning: shoulder delivers 3.5× its required peak")
    # The smallest motor's excess is said as such, not warned about: at N = 50 it is 26x, and 26 x 10/50 = 5.2x
    # still at the lowest ratio.
    ratios = BOUNDS["gear_ratio"]["elbow"]
    assert smallest_motor_excess(smallest, ratios, 26.0) == (
        "peak torque 26× its requirement at N = 50 (5.2× at its lowest ratio, 10): even the smallest motor is "
        "more than it needs"
    )
    (line,) = bound_sentences(record(joints=[joint(), smallest]), BOUNDS)
    assert "elbow motor at its smallest size (peak torque 26× its requirement at N = 50" in line
    # At its lowest ratio already: the motor alone.
    lowest = joint("elbow", diameter=0.03, ratio=10.0, margin=25.0)
    assert smallest_motor_excess(lowest, ratios, 26.0) == (
        "peak torque 26× its requirement: even the smallest motor is more than it needs"
    )
    # 26x at N = 150 is 1.7x at N = 10: the ratio the objective chose gives the excess, not the motor.
    geared = joint("elbow", diameter=0.03, ratio=150.0, margin=25.0)
    assert smallest_motor_excess(geared, ratios, 26.0) == (
        "peak torque 26× its requirement at N = 150, the ratio the objective chose (1.73× at its lowest ratio, "
        "10): the gear ratio, not the motor, gives the excess"
    )
    # A ratio no objective decides is not called the objective's choice.
    assert smallest_motor_excess(geared, ratios, 26.0, chosen_ratio=False) == (
        "peak torque 26× its requirement at N = 150 (1.73× at its lowest ratio, 10)"
    )
    assert oversized_warnings(record(joints=[joint(margin=1.9)]), BOUNDS) == []


def test_the_verdict_opens_with_the_design_to_build_and_stays_within_ten_lines():
    recommended = {
        **record(joints=[joint(diameter=0.03, margin=0.0), joint("elbow", margin=None)], threshold=1.0),
        "source": "Pareto design 1",
        "reason": "Pareto design 1 dominates the single-objective optimum",
    }
    results = {
        "chosen": record(),
        "recommended": recommended,
        "pareto": pareto([record(0.40, 2.0), recommended]),
        "bounds": BOUNDS,
        "requirement": "static (gravity only)",
    }
    lines = verdict(results)
    assert lines[0] == (
        "Build: the continuous optimum (Pareto design 1): shoulder: 30 mm × 12.5 mm motor at N = 50; elbow: 80 mm "
        "× 12.5 mm motor at N = 50; threshold 1 N, approach velocity 0.2 m/s (worst-case impulse 0.5 N·s, mean "
        "impulse 0.25 N·s, actuator mass 1 kg). Its motors are scaled, not sold."
    )
    assert "Sized by (static (gravity only)): shoulder: peak torque." in lines
    assert any(
        line.startswith("The lightest within 5 %") or "The lightest within 5 %" in line for line in lines
    )
    # Many warnings: merged into the last line, never more than MAX_LINES.
    many = {
        **results,
        "catalogue": {
            "warnings": [f"j{i}: part {i} is far from the optimum" for i in range(12)],
            "design": None,
            "method": "exact",
        },
    }
    lines = verdict(many)
    assert len(lines) <= MAX_LINES and lines[-1].startswith("Warnings: ")
    assert all(f"j{i}: part {i}" in " ".join(lines) for i in range(12))


def test_a_catalogue_design_is_what_to_build_and_its_undecided_ratio_is_said():
    joints = [
        {"joint": "shoulder", "motor": "M-80", "gearbox": None, "gear_ratio": 40.0},
        {"joint": "elbow", "motor": "M-30", "gearbox": "HD-14", "gear_ratio": 59.85},
    ]
    catalogue = {
        "warnings": [],
        "method": "exact: enumerated 4 combinations",
        "joints": joints,
        "objectives": {"worst_case_impulse": 0.5089, "actuator_mass": 2.74},
        "relative_difference": {"worst_case_impulse": 0.0177, "actuator_mass": 1.74},
        "design": {**record(), "undecided": [{"variable": "gear_ratio", "joint": "elbow"}]},
    }
    build, continuous = build_sentences({**record(), "source": "optimum"}, catalogue)
    assert build == (
        "Build from catalogue parts: shoulder: M-80 at N = 40; elbow: M-30 + HD-14 at N = 59.85 (a ratio no "
        "objective decides: the solver's start); threshold 5 N, approach velocity 0.2 m/s: worst impulse over "
        "the samples 0.5089 N·s, actuator mass 2.74 kg (worst case impulse +1.77 %, actuator mass +174 % against "
        "the continuous optimum)."
    )
    assert continuous.startswith("Continuous optimum (optimum): shoulder and elbow: 80 mm × 12.5 mm motor")
    # Written before the field existed: no claim either way.
    del catalogue["design"]["undecided"]
    assert "no objective decides" not in build_sentences(record(), catalogue)[0]


def test_an_undecided_variable_is_said_so_instead_of_its_bound():
    undecided = {**record(threshold=1.0), "undecided": [{"variable": "threshold", "joint": None}]}
    (line,) = bound_sentences(undecided, BOUNDS)
    assert line.startswith("No objective decides threshold anywhere within the bounds")
    assert bound_sentences(record(threshold=1.0), BOUNDS)[0].endswith("threshold at its lower bound (1 N).")


def _estimate(value, error, configurations, samples, **extra):
    return {
        "value": value,
        "low": value * (1 - error),
        "high": value * (1 + error),
        "relative_error": error,
        "configurations": configurations,
        "samples": samples,
        **extra,
    }


def _fresh(largest, exceeds, mean_error=0.01, quantile_error=0.015):
    return {
        "configurations": 4096,
        "samples": 24_000,
        "largest": largest,
        "mean": 0.3,
        "exceeds": exceeds,
        "statistics": {
            "mean_impulse": _estimate(0.3, mean_error, 4096, 24_000),
            "cvar_impulse": _estimate(1.0, mean_error, 4096, 24_000),
            "quantile_impulse": _estimate(1.2, quantile_error, 4096, 24_000, quantile=0.99),
        },
    }


def test_the_fresh_check_and_its_errors_are_stated_and_warned_about():
    recommended = {
        **record(),
        "worst_case": {"domain": 2.0, "sampled": 2.0, "certified": True, "tolerance": 0.005},
        "fresh": _fresh(1.9, False),
        "statistics": {
            "mean_impulse": _estimate(0.28, 0.12, 48, 288),
            "cvar_impulse": _estimate(0.9, 0.2, 48, 288),
            "quantile_impulse": _estimate(1.1, 0.3, 48, 288, quantile=0.99),
        },
    }
    study = {"objective": "worst_case_impulse", "samples": {"error_tolerance": 0.02}}
    (searched, fresh) = certainty_sentences(recommended)
    assert searched.startswith("Worst case 2 N·s over the samples only: no search")
    assert fresh == (
        "On 4,096 fresh configurations it was not optimised on: largest 1.9 N·s, within the worst case; mean "
        "0.3 N·s (± 1 %)."
    )
    rows = statistics_rows(recommended)
    assert rows[0] == ("mean impulse", "0.3 N·s ± 1 %", "0.28 N·s ± 12 %")
    assert rows[2] == ("99th percentile", "1.2 N·s ± 1.5 %", "1.1 N·s ± 30 %")
    assert (
        statistics_warnings(recommended, study, {"points": [recommended]}) == []
    )  # the mean is no objective
    # A fresh sample above the worst case, errors over the tolerance, the mean an objective: each is said.
    recommended["fresh"] = _fresh(2.2, True, quantile_error=0.04)
    recommended["label"] = "anchor: worst_case_impulse"
    study = {
        **study,
        "objective": "mean_impulse",
        "pareto": {"objectives": ["cvar_impulse", "actuator_mass"]},
    }
    assert "WARNING: largest 2.2 N·s, 10 % above the worst case" in certainty_sentences(recommended)[1]
    lines = statistics_warnings(recommended, study, {"points": [recommended]})
    # 4 % against 2 %: four times the configurations.
    assert "about 16,384 fresh configurations (samples.fresh) would meet it" in lines[0]
    assert (
        lines[1]
        == "Warning: a fresh sample exceeds the worst case of Pareto designs anchor: worst_case_impulse."
    )
    assert lines[2].startswith("Warning: the mean impulse, an objective, is uncertain by 12 %")
    assert "about 1,728 configurations (samples.configurations.random.count)" in lines[2]
    # The CVaR, a Pareto objective, at 20 %: a hundred times the 48 configurations.
    assert lines[3].startswith("Warning: the CVaR impulse, an objective, is uncertain by 20 %")
    assert "about 4,800 configurations" in lines[3]


def test_an_uncertified_worst_case_names_the_remedy_that_applies():
    searched = {"q": [0.1, 0.2], "direction": [1.0, 0.0], "starts": 4, "evaluations": 900, "domain_kept": 0.8}
    recommended = {
        **record(),
        "worst_case": {
            "sampled": 1.0,
            "domain": 1.5,
            "certified": False,
            "searched": searched,
            "tolerance": 0.005,
        },
    }
    (exchanged,) = certainty_sentences(recommended)
    assert exchanged.startswith("Warning: worst case NOT certified: the search found 1.5 N·s, 50 % above")
    assert "more search rounds (optimizer.worst_case_search.rounds)" in exchanged
    # A study whose objectives leave the worst case alone never exchanges samples: more rounds would not help.
    (reported,) = certainty_sentences(recommended, exchanged=False)
    assert "more search rounds" not in reported
    assert "the worst case is no objective of this study" in reported
