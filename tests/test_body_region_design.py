"""Designing for a human body region (``constraints.body_region``): the approach held within the region's
ISO/TS 15066 permissible speed at every sample, checked against the exact effective mass, on all samples and on
active sets; the shipped study's front; bad regions refused at their line.

The exact check inverts ``M_f + diag(N^2 J)`` per sample (NumPy), where the NLP carries a direction variable per
sample instead: agreement checks the reformulation as well as the code.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

import collision_reflex as cr
from collision_reflex.errors import StudyFileError
from collision_reflex.model.contact import permissible_speed
from collision_reflex.model.effective import finger_mass_matrix
from collision_reflex.optimize.active_set import solve_active_set
from collision_reflex.study.body_regions import load_body_regions
from collision_reflex.study.load import parse_study
from collision_reflex.study.safety import speed_map

STUDY = Path(__file__).resolve().parents[1] / "studies" / "ur5_human_contact.yaml"
LEG = load_body_regions()["lower_leg"]  # 60 N/mm, 75 kg, 260 N: heavy enough that the robot's mass matters
TIGHT = {"ipopt.tol": 1e-10, "ipopt.constr_viol_tol": 1e-10, "ipopt.acceptable_tol": 1e-8}


def exact_speeds(samples: cr.ContactSamples, design) -> np.ndarray:
    """The permissible speed against ``LEG`` per sample, the robot mass ``1 / (w^T (M_f + diag(N^2 J))^-1 w)``."""
    kin = samples.kinematics
    index = samples.config_index
    matrix = finger_mass_matrix(
        kin.mass_matrix[index],
        kin.motor_mass_influence[index],
        design.actuator_mass,
        design.reflected_inertia,
    )
    w = samples.joint_moment_arms
    mass = 1 / np.einsum("si,si->s", w, np.linalg.solve(matrix, w[..., None])[..., 0])
    return permissible_speed(LEG.transient_force, mass, LEG.stiffness, LEG.mass)


@pytest.fixture(scope="module")
def builder(panda_case):
    arm, samples, space, technology, constraints = panda_case(40)  # 160 samples: active sets pay

    def build(region, chosen=samples):
        limited = cr.Constraints(
            payload=constraints.payload,
            safety_factor=constraints.safety_factor,
            threshold_floor=constraints.threshold_floor,
            body_region=region,
        )
        return cr.build_problem(arm, chosen, space, technology, "approach_velocity", limited)

    return build, samples


def test_the_fastest_approach_sits_on_the_region_s_exact_permissible_speed(builder):
    """Free, the Panda approaches at its 1 m/s bound, over twice the lower leg's permissible speed; held to the
    region it approaches exactly at the slowest sample's exact permissible speed (to 1e-6)."""
    build, samples = builder
    free = cr.solve(build(None), ipopt_options=TIGHT)
    held = cr.solve(build(LEG), ipopt_options=TIGHT)
    assert free.success and held.success
    assert free.design.approach_velocity > 2 * exact_speeds(samples, free.design).min()
    slowest = exact_speeds(samples, held.design).min()
    assert held.design.approach_velocity == pytest.approx(slowest, rel=1e-6)


def test_an_active_set_solve_keeps_every_sample_within_the_region(builder):
    """On active sets the samples the region limits are added like those the worst case needs: started from
    the 16 samples it limits least, the design is the all-sample one (approach to 1e-6) and no sample's exact
    permissible speed is below its approach."""
    build, samples = builder
    every = cr.solve(build(LEG), ipopt_options=TIGHT)
    least = np.argsort(exact_speeds(samples, every.design))[-16:]
    active = solve_active_set(lambda chosen: build(LEG, chosen), samples, ipopt_options=TIGHT, initial=least)
    assert len(active.rounds) > 1  # samples were added
    assert active.design.approach_velocity == pytest.approx(every.design.approach_velocity, rel=1e-6)
    assert np.all(exact_speeds(samples, active.design) >= active.design.approach_velocity * (1 - 1e-6))


def test_the_shipped_study_trades_permissible_speed_against_actuator_mass_or_says_what_caps_it(smoke_runs):
    """``studies/ur5_human_contact.yaml``: its front spans at least 10 % in actuator mass, and in approach speed
    either 10 % or the verdict says what caps it: at the slowest fresh pose the links' own mass, whose speed is
    the most any actuators could permit there. The recommended design's approach is within the thigh's permissible speed at every
    sample (as ``crx safety`` computes it from the folder), and the report names the constraint with its source."""
    folder = smoke_runs["ur5_human_contact"]
    results = json.loads((folder / "designs.json").read_text())
    points = results["pareto"]["points"]
    spans = {}
    for name in ("approach_velocity", "actuator_mass"):
        values = [p["objectives"][name] for p in points]
        spans[name] = (max(values) - min(values)) / max(values)  # over the largest: the stricter span
    assert spans["actuator_mass"] >= 0.10
    held = results["human_contact"]["held_to"]
    assert held["region"] == "thigh_knee" and held["fresh_samples"] > 0
    assert held["link_mass"] <= held["robot_mass"] and held["links_speed"] >= held["slowest"]
    if spans["approach_velocity"] < 0.10:
        front = next(line for line in results["verdict"] if line.startswith("Front of"))
        assert "What caps the speed" in front and "no actuators gain more" in front
    speeds = speed_map(folder, load_body_regions()["thigh_knee"])
    assert speeds.masses.approach_velocity <= speeds.speed.min() * (1 + 1e-6)
    row = next(r for r in results["human_contact"]["regions"] if r["region"] == "thigh_knee")
    assert row["above_approach"] == 0
    report = (folder / "report.html").read_text()
    assert "thigh_knee" in report and "ISO/TS 15066" in report


@pytest.mark.parametrize(
    ("region", "words"),
    [("elbow", "one of neck, back_shoulders"), ("face", "permits no transient contact")],
)
def test_a_region_the_standard_does_not_permit_or_name_is_refused_at_its_line(tmp_path, region, words):
    text = STUDY.read_text().replace("body_region: thigh_knee", f"body_region: {region}")
    with pytest.raises(StudyFileError, match=words) as refused:
        parse_study(text, "study.yaml", tmp_path)
    assert "constraints.body_region" in str(refused.value)
