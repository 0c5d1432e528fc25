"""The verdict an arm report opens with, decided from hand-made records: active bounds and constraints per
joint, the front's spans, flat and degenerate fronts, the lightest design near the best impulse, warnings."""

from __future__ import annotations

import pytest

from collision_reflex.report.verdict import (
    ACTIVE_TOLERANCE,
    bound_position,
    catalogue_sentences,
    design_limits,
    flat_impulse_reason,
    front_sentences,
    joint_limits,
    lightest_near_best,
    objective_spans,
    oversized_warnings,
    statistics_sentences,
    undecided_sentence,
    verdict,
)

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


def test_active_bounds_and_constraints_per_joint():
    at_bounds = joint(diameter=0.03, ratio=160.0, stiffness=50.0, margin=0.5 * ACTIVE_TOLERANCE)
    phrases = joint_limits(at_bounds, BOUNDS, "static (gravity only)")
    assert phrases == [
        "motor at its smallest size",  # diameter at its lower bound, stack length fixed
        "gear ratio at its upper bound (160)",
        "software stiffness at its lower bound (50)",
        "sized by peak torque",
    ]
    assert joint_limits(joint(diameter=0.14), BOUNDS, "static (gravity only)") == [
        "motor at its largest size"
    ]
    # Inside every bound, with margin: nothing active.
    assert joint_limits(joint(margin=2 * ACTIVE_TOLERANCE), BOUNDS, "static (gravity only)") == []


def test_no_requirement_and_the_duty_cycle_margins():
    free = joint(margin=None)
    assert joint_limits(free, BOUNDS, "static (gravity only)") == [
        "no torque requirement: static gravity-only requirement is zero for this joint"
    ]
    assert joint_limits(free, BOUNDS, "duty cycle") == ["no torque requirement"]
    cycled = joint(margin=0.3, rms_margin=0.0, speed_margin=0.2 * ACTIVE_TOLERANCE, required_rms_torque=4.0)
    assert joint_limits(cycled, BOUNDS, "duty cycle") == ["sized by RMS torque", "sized by speed"]
    # Margins absent (a record before duty cycles) or None (no such requirement): nothing said about them.
    assert joint_limits(joint(margin=0.3, rms_margin=None), BOUNDS, "duty cycle") == []


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
        "Flat front: all designs within 0.22 % of the best worst case impulse: actuator mass is the only "
        "real choice." in lines
    )
    trade_off = pareto([record(0.40, 2.0), record(0.46, 1.0), record(0.60, 0.2)])  # 50 % vs 900 %
    lines = front_sentences(trade_off)
    assert lines[0] == "The front (3 designs) spans 50 % in worst case impulse, 900 % in actuator mass."
    assert not any("Flat" in line or "Degenerate" in line for line in lines)


def test_a_flat_impulse_front_says_which_phase_carries_the_impulse():
    # Phases by hand: the worst sample (1.0 + 0.05 + 0.05 N s) is 90.9 % impact; all samples 1.6 of 1.8 N s.
    phases = {"initial": [1.0, 0.4, 0.2], "sensing": [0.05, 0.05, 0.03], "reaction": [0.05, 0.01, 0.01]}
    recommended = {**record(0.5005, 1.0), "phases": phases}
    flat = pareto([record(0.5000, 2.0), recommended, record(0.5011, 0.11)])
    (line,) = flat_impulse_reason(flat, recommended, {"reflected_inertia_in": "robot"})
    assert line.startswith("Why the front is flat in worst case impulse:")
    assert "carries 90.9 % of the worst sample's impulse (1 of 1.1 N·s)" in line
    assert "88.9 % of all samples' together" in line and "rotors sit behind the joint springs" in line
    trade_off = pareto([record(0.40, 2.0), recommended, record(0.60, 0.2)])
    assert flat_impulse_reason(trade_off, recommended, {}) == []
    # A front of one design gets the same numbers and says the lightest is the gentlest.
    (line,) = flat_impulse_reason(pareto([recommended]), recommended, {"reflected_inertia_in": "robot"})
    assert line.startswith("Why the front is one design:") and "90.9 %" in line
    assert line.endswith("the lightest actuators that meet the requirements are also the gentlest.")


def test_degenerate_fronts_are_said_in_plain_words():
    one = front_sentences(pareto([record()], merged=2))
    assert one[0].startswith("2 solved point(s) repeated a reported design") and "merged" in one[0]
    assert one[1].startswith("Degenerate front: one design.")
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
    assert (
        "peak torque 26× its requirement at N = 50 (5.2× at its lowest ratio, 10): even the smallest motor is "
        "more than it needs" in joint_limits(smallest, BOUNDS, "static (gravity only)")
    )
    # At its lowest ratio already: the motor alone.
    lowest = joint("elbow", diameter=0.03, ratio=10.0, margin=25.0)
    assert "peak torque 26× its requirement: even the smallest motor is more than it needs" in joint_limits(
        lowest, BOUNDS, "static (gravity only)"
    )
    # 26x at N = 150 is 1.7x at N = 10: the ratio the objective chose gives the excess, not the motor.
    geared = joint("elbow", diameter=0.03, ratio=150.0, margin=25.0)
    assert (
        "peak torque 26× its requirement at N = 150, the ratio the objective chose (1.73× at its lowest ratio, "
        "10): the gear ratio, not the motor, gives the excess"
        in joint_limits(geared, BOUNDS, "static (gravity only)")
    )
    assert oversized_warnings(record(joints=[joint(margin=1.9)]), BOUNDS) == []


def test_the_verdict_opens_with_the_recommended_design():
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
    assert lines[0].startswith("Recommended design (Pareto design 1): shoulder: 30 mm × 12.5 mm motor")
    assert "at N = 50" in lines[0] and "threshold 1 N, approach velocity 0.2 m/s" in lines[0]
    assert lines[1] == "Why this design: Pareto design 1 dominates the single-objective optimum."
    assert lines[2].startswith("Torque requirement: static (gravity only).")
    from collision_reflex.report.verdict import requirement_sentence

    assert "the static hold" in requirement_sentence("duty cycle (peak, RMS, speed)")
    assert "shoulder: motor at its smallest size, sized by peak torque." in lines
    assert "elbow: no torque requirement: static gravity-only requirement is zero for this joint." in lines
    assert "Sensing and approach: threshold at its lower bound (1)." in lines
    assert any(line.startswith("Lightest design within 5 %") for line in lines)


def test_variables_no_objective_decides_are_said_so_and_not_called_a_choice():
    """A joint no sample loads (its gear ratio and software stiffness undecided): the verdict gives their values
    as the solver's start, not the objective's choice; a decided ratio keeps its sentence."""
    wrist = joint("elbow", diameter=0.03, ratio=67.0, stiffness=387.3, margin=93.4)
    recommended = {
        **record(joints=[joint(margin=0.0), wrist]),
        "source": "optimum",
        "reason": "",
        "undecided": [
            {"variable": "gear_ratio", "joint": "elbow"},
            {"variable": "software_stiffness", "joint": "elbow"},
        ],
    }
    results = {
        "chosen": record(),
        "recommended": recommended,
        "pareto": pareto([]),
        "bounds": BOUNDS,
        "requirement": "duty cycle (peak, RMS, speed)",
    }
    (line,) = [line for line in verdict(results) if line.startswith("elbow:")]
    # 94.4x at N = 67 is 14.1x at N = 10: the motor, not the ratio, is more than the joint needs.
    assert line == (
        "elbow: motor at its smallest size, peak torque 94.4× its requirement at N = 67 (14.1× at its lowest "
        "ratio, 10): even the smallest motor is more than it needs. Its gear ratio (67) and software stiffness "
        "(387.3 N·m/rad) change no impulse and not the actuator mass anywhere within their bounds, as no contact "
        "sample loads this joint: no objective decides them, and they are where the solver started; choose them "
        "on grounds this study does not model."
    )
    # An undecided ratio whose excess at its lowest ratio is small: not "the ratio the objective chose".
    geared = joint("elbow", diameter=0.03, ratio=150.0, margin=25.0)
    decided = joint_limits(geared, BOUNDS, "static (gravity only)")
    assert "the ratio the objective chose" in decided[-1]
    (undecided,) = [
        p for p in joint_limits(geared, BOUNDS, "static (gravity only)", ["gear_ratio"]) if "peak torque" in p
    ]
    assert undecided == "peak torque 26× its requirement at N = 150 (1.73× at its lowest ratio, 10)"
    assert undecided_sentence(geared, ["gear_ratio"]) == (
        "Its gear ratio (150) changes no impulse and not the actuator mass anywhere within its bounds: no "
        "objective decides it, and it is where the solver started; choose it on grounds this study does not model."
    )
    # A record written before the field existed reads as nothing undecided.
    del recommended["undecided"]
    assert not any("no objective decides" in line for line in verdict(results))


def test_a_catalogue_gear_ratio_no_objective_decides_is_said_to_be_the_start():
    joints = [
        {"joint": "shoulder", "motor": "M-80", "gearbox": None, "gear_ratio": 40.0},
        {"joint": "elbow", "motor": "M-30", "gearbox": "HD-14", "gear_ratio": 59.85},
    ]
    catalogue = {
        "warnings": [],
        "method": "exact: enumerated 4 combinations",
        "joints": joints,
        "relative_difference": {"worst_case_impulse": 0.0177, "actuator_mass": 1.74},
        "design": {"undecided": [{"variable": "gear_ratio", "joint": "elbow"}]},
    }
    (sentence,) = catalogue_sentences(catalogue)
    assert (
        "shoulder M-80 at N = 40, elbow M-30 + HD-14 at N = 59.85 (a ratio no objective decides: the solver's "
        "start); against the continuous design worst case impulse +1.77 %, actuator mass +174 %." in sentence
    )
    # Written before the field existed: no claim either way.
    del catalogue["design"]["undecided"]
    assert "no objective decides" not in catalogue_sentences(catalogue)[0]


def test_an_undecided_global_variable_is_said_so_instead_of_its_bound():
    undecided = {**record(threshold=1.0), "undecided": [{"variable": "threshold", "joint": None}]}
    assert design_limits(undecided, BOUNDS) == [
        "threshold (1) changes no objective anywhere within its bounds: no objective decides it, the value is "
        "where the solver started"
    ]
    assert design_limits(record(threshold=1.0), BOUNDS) == ["threshold at its lower bound (1)"]


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
        "worst_case": {"domain": 2.0},
        "fresh": _fresh(1.9, False),
        "statistics": {
            "mean_impulse": _estimate(0.28, 0.12, 48, 288),
            "cvar_impulse": _estimate(0.9, 0.2, 48, 288),
            "quantile_impulse": _estimate(1.1, 0.3, 48, 288, quantile=0.99),
        },
    }
    study = {"objective": "worst_case_impulse", "samples": {"error_tolerance": 0.02}}
    lines = statistics_sentences(recommended, study, {"points": [recommended]})
    assert lines[0].startswith("Checked on 4,096 fresh configurations of the domain (24,000 samples")
    assert "largest impulse 1.9 N·s, within its worst case 2 N·s" in lines[0]
    assert "mean impulse 0.3 N·s (± 1 %), mean of the worst 5 % (CVaR) 1 N·s (± 1 %)" in lines[0]
    assert "99th percentile 1.2 N·s (± 1.5 %)" in lines[0]
    assert lines[1].startswith("On the samples it was optimised on (48 configurations")
    assert len(lines) == 2  # errors within the tolerance; the mean is no objective: no warning
    # A fresh sample above the worst case, errors over the tolerance, the mean an objective: each is said.
    recommended["fresh"] = _fresh(2.2, True, quantile_error=0.04)
    recommended["label"] = "anchor: worst_case_impulse"
    study = {
        **study,
        "objective": "mean_impulse",
        "pareto": {"objectives": ["cvar_impulse", "actuator_mass"]},
    }
    lines = statistics_sentences(recommended, study, {"points": [recommended]})
    assert "WARNING: 2.2 N·s, 10 % above its worst case 2 N·s, which is therefore not a bound" in lines[0]
    # 4 % against 2 %: four times the configurations.
    assert "about 16,384 fresh configurations (samples.fresh) would meet it" in lines[1]
    assert lines[2] == "Pareto designs whose worst case a fresh sample exceeds: anchor: worst_case_impulse."
    assert lines[4].startswith("Warning: the mean impulse, an objective, is uncertain by 12 %")
    assert "about 1,728 configurations (samples.configurations.random.count)" in lines[4]
    # The CVaR, a Pareto objective, at 20 %: a hundred times the 48 configurations.
    assert lines[5].startswith("Warning: the CVaR impulse, an objective, is uncertain by 20 %")
    assert "about 4,800 configurations" in lines[5]


def test_an_uncertified_worst_case_names_the_remedy_that_applies():
    from collision_reflex.report.verdict import worst_case_sentences

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
    domain = {"min_singular_value": 0.1, "reach": 1.0}
    exchanged = worst_case_sentences(recommended, domain, {"points": []})[1]
    assert "50 % above the samples' worst case 1 N·s" in exchanged
    assert "more search rounds (optimizer.worst_case_search.rounds)" in exchanged
    # A study whose objectives leave the worst case alone never exchanges samples: more rounds would not help.
    reported = worst_case_sentences(recommended, domain, {"points": []}, exchanged=False)[1]
    assert "more search rounds" not in reported
    assert "the worst case is no objective of this study" in reported
