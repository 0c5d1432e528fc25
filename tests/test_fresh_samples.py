"""Fresh samples: drawn apart from the optimised ones, inside the domain, and each design's check on them."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

from collision_reflex.optimize.design import design_at
from collision_reflex.optimize.evaluate import sample_impulses
from collision_reflex.optimize.pieces import built_problem
from collision_reflex.optimize.samples import ContactSamples
from collision_reflex.study.fresh import fresh_draw, fresh_impulses, fresh_record
from collision_reflex.study.load import load_study
from collision_reflex.study.problems import StudyProblems
from collision_reflex.study.resolve import resolve_study

ROOT = Path(__file__).resolve().parents[1]


STUDY = """\
name: fresh
robot: {{urdf: {urdf}, contact_frame: tip}}
actuators:
  motor: {{reference: "OPN-060-013-A", scaling_law: haddadin, stator_diameter: 60 mm}}
  mechanical_stiffness: 1000 N*m/rad
  software_stiffness: 100 N*m/rad
sensing: {{scheme: force, threshold: 3 N}}
approach_velocity: 0.3 m/s
samples:
  configurations: {{random: {{count: 40, seed: 4}}}}
  directions: {{circle: 8}}
  domain: {{min_singular_value: 0.02 m, joint_speed_limit: 2 rad/s}}
design:
  stator_diameter: {{min: 10 mm, max: 100 mm}}
  approach_velocity: {{min: 0.05 m/s, max: 0.6 m/s}}
objective: worst_case_impulse
constraints: {{torque_required: [1.3 N*m, 1.3 N*m], safety_factor: 1.0}}
"""


@pytest.fixture(scope="module")
def two_link(tmp_path_factory):
    """A planar 2R study with random configurations and joint speed limits that bind in part of its domain."""
    study = tmp_path_factory.mktemp("fresh") / "fresh.yaml"
    study.write_text(STUDY.format(urdf=(ROOT / "designs" / "planar_two_link.urdf").as_posix()))
    problems = StudyProblems(resolve_study(load_study(study)))
    setup = problems.setup
    problem = built_problem(problems, problems.objective)
    return setup, design_at(problem, problem.x0)


def _samples(setup, draw):
    """The fresh pairs of ``draw`` as contact samples, built here from its configurations and feasibility."""
    config, direction = np.nonzero(draw.feasible)
    return ContactSamples(setup.arm.kinematics(draw.q), setup.directions[direction], config)


def test_fresh_samples_are_new_configurations_inside_the_domain(two_link):
    setup, _ = two_link
    draw = fresh_draw(setup)
    assert draw is not None
    q = draw.q
    assert q.shape[0] == setup.study.samples.fresh
    # Another stream than the optimised samples': no configuration in common.
    distance = np.abs(q[:, None, :] - setup.configurations[None, :, :]).max(axis=2)
    assert distance.min() > 1e-6
    # Every pair meets the floor and is feasible at the slowest approach; its speed cap is the fastest approach
    # the domain allows along it.
    fresh = _samples(setup, draw)
    jacobian = fresh.kinematics.jacobian[fresh.config_index]
    assert np.all(setup.domain.configuration_margin(jacobian) >= 0)
    slowest = setup.space.global_bounds("approach_velocity").lower
    assert np.all(setup.domain.contains(jacobian, fresh.directions, slowest))
    caps = draw.speed_cap[draw.feasible]
    # At its cap the guarded move's fastest joint runs at exactly its limit (J^+ u v0, computed here).
    rates = np.abs(np.einsum("sjd,sd->sj", np.linalg.pinv(jacobian), fresh.directions))
    limits = setup.domain.joint_speed_limit
    np.testing.assert_allclose((rates * caps[:, None] / limits).max(axis=1), 1.0, rtol=1e-9)
    fastest = setup.space.global_bounds("approach_velocity").upper
    assert 0.05 < np.mean(caps < fastest) < 0.95  # the limits bind in part of the domain, not all
    # Deterministic: the same study draws the same fresh samples.
    np.testing.assert_array_equal(fresh_draw(setup).q, q)


def test_no_fresh_samples_when_switched_off(two_link):
    setup, _ = two_link
    samples = setup.study.samples.model_copy(update={"fresh": 0})
    off = dataclasses.replace(setup, study=setup.study.model_copy(update={"samples": samples}))
    assert fresh_draw(off) is None


def test_a_design_s_fresh_check_is_its_impulses_inside_its_own_domain(two_link):
    setup, design = two_link
    draw = fresh_draw(setup)
    fresh = _samples(setup, draw)
    inside = setup.domain.contains(
        fresh.kinematics.jacobian[fresh.config_index], fresh.directions, design.approach_velocity
    )
    impulses = sample_impulses(
        ContactSamples(fresh.kinematics, fresh.directions[inside], fresh.config_index[inside]),
        setup.technology,
        design,
    )
    assert (
        0.05 < 1 - inside.mean() < 0.95
    )  # the design's approach velocity excludes part of the fresh samples
    slow = dataclasses.replace(design, approach_velocity=setup.space.global_bounds("approach_velocity").lower)
    with pytest.MonkeyPatch.context() as patch:  # two chunks, the second partial
        patch.setattr("collision_reflex.study.fresh.CHUNK_CONFIGURATIONS", int(0.7 * draw.q.shape[0]))
        found, everywhere = fresh_impulses(setup, draw, [design, slow])
    assert everywhere.impulses.size == fresh.size  # the slowest design's domain holds every fresh sample
    np.testing.assert_allclose(np.sort(found.impulses), np.sort(impulses), rtol=1e-12)
    record = fresh_record(found, worst_case=impulses.max(), tolerance=0.005, statistics=True)
    assert record["samples"] == inside.sum()
    assert record["configurations"] == np.unique(fresh.config_index[inside]).size
    assert record["largest"] == pytest.approx(impulses.max(), rel=1e-12)
    assert record["mean"] == pytest.approx(impulses.mean(), rel=1e-12)
    assert not record["exceeds"]
    # Where the largest occurs: that configuration and direction give it again.
    at = ContactSamples(setup.arm.kinematics(np.array([record["q"]])), np.array([record["direction"]]), [0])
    assert sample_impulses(at, setup.technology, design)[0] == pytest.approx(record["largest"], rel=1e-9)
    stats = record["statistics"]
    assert stats["mean_impulse"]["low"] <= record["mean"] <= stats["mean_impulse"]["high"]
    # A reported worst case 1 % below the fresh maximum is exceeded (beyond the 0.5 % tolerance).
    assert fresh_record(found, impulses.max() / 1.01, 0.005)["exceeds"]
    assert "statistics" not in fresh_record(found, impulses.max(), 0.005)
