"""The contact domain: the singular-value floor and the guarded move's speed limits, against a planar 2R arm's
closed forms; drawing in it; refusing a domain that keeps (almost) nothing."""

from __future__ import annotations

import textwrap
from pathlib import Path

import numpy as np
import pytest

from collision_reflex.arm import Arm
from collision_reflex.arm.directions import circle_directions
from collision_reflex.arm.domain import (
    MIN_KEPT_FRACTION,
    ContactDomain,
    DomainTooSmall,
    smallest_singular_values,
    unit_speed_joint_rates,
)
from collision_reflex.cli import main
from collision_reflex.errors import StudyFileError
from collision_reflex.study.load import load_study
from collision_reflex.study.samples import contact_domain

ROOT = Path(__file__).resolve().parents[1]
URDF = ROOT / "designs" / "planar_two_link.urdf"
L1, L2 = 0.30, 0.25  # the URDF's link lengths [m]


@pytest.fixture(scope="module")
def arm() -> Arm:
    return Arm.from_urdf(URDF, "tip")


def _sigma_min_2r(q2: np.ndarray) -> np.ndarray:
    """Smallest singular value of a planar 2R arm's tip Jacobian: from ||J||_F^2 and det J = l1 l2 sin q2."""
    frobenius = L1**2 + 2 * L2**2 + 2 * L1 * L2 * np.cos(q2)
    det = L1 * L2 * np.sin(q2)
    return np.sqrt((frobenius - np.sqrt(frobenius**2 - 4 * det**2)) / 2)


def test_the_smallest_singular_value_is_the_2r_closed_form(arm):
    q2 = np.linspace(-3.0, 3.0, 13)
    q = arm.configuration(np.column_stack([np.full(q2.size, 0.7), q2]))
    sigma = smallest_singular_values(arm.kinematics(q, full=False).jacobian)
    np.testing.assert_allclose(sigma, _sigma_min_2r(q2), rtol=1e-9, atol=1e-12)


def test_speed_caps_are_the_inverse_jacobian_rates(arm):
    # Square Jacobian: J^+ u = J^-1 u; the cap is the speed at which the first joint reaches its limit.
    q = arm.configuration(np.array([[0.3, 1.1]]))
    jacobian = arm.kinematics(q, full=False).jacobian
    u = np.array([[0.6, -0.8]])
    rates = np.linalg.solve(jacobian[0], u[0])
    np.testing.assert_allclose(unit_speed_joint_rates(jacobian, u)[0], rates, rtol=1e-12)
    limits = np.array([2.0, 5.0])
    domain = ContactDomain(*arm.joint_limits(), 0.0, limits, 0.55)
    cap = 1 / np.max(np.abs(rates) / limits)
    np.testing.assert_allclose(domain.speed_caps(jacobian, u), [cap], rtol=1e-12)
    assert domain.contains(jacobian, u, 0.999 * cap)[0] and not domain.contains(jacobian, u, 1.001 * cap)[0]


def test_the_default_floor_is_a_tenth_of_the_reach(arm):
    domain = ContactDomain.of_arm(arm)
    # The reach of a 2R arm is l1 + l2; a sampled maximum is a little below it.
    assert (L1 + L2) * 0.995 < domain.reach <= L1 + L2 + 1e-12
    assert domain.min_singular_value == pytest.approx(0.1 * domain.reach)
    np.testing.assert_array_equal(domain.joint_speed_limit, [20.0, 20.0])  # the URDF's velocity limits


def test_a_draw_keeps_the_closed_form_share_of_the_box(arm):
    floor = 0.06
    domain = ContactDomain(*arm.joint_limits(), floor, np.array([np.inf, np.inf]), L1 + L2)
    draw = domain.draw(arm, 400, circle_directions(8), 0.5, np.random.default_rng(3))
    q2 = arm.joint_coordinates(draw.q)[:, 1]
    assert np.all(_sigma_min_2r(q2) >= floor * (1 - 1e-9))
    grid = np.linspace(-np.pi, np.pi, 200_001)
    share = np.mean(_sigma_min_2r(grid) >= floor)  # q1 does not change sigma_min
    # Binomial error of the measured share over >= 400 / share draws: 3 sigma.
    drawn = 400 / draw.configurations_kept
    assert abs(draw.configurations_kept - share) < 3 * np.sqrt(share * (1 - share) / drawn) + 2 / drawn
    assert draw.feasible.all()  # no speed limit: every direction of a kept configuration


def test_a_floor_above_every_pose_is_refused(arm):
    domain = ContactDomain(*arm.joint_limits(), 0.3, np.array([20.0, 20.0]), L1 + L2)  # sigma_min <= l2 < 0.3
    with pytest.raises(DomainTooSmall, match="min_singular_value") as error:
        domain.draw(arm, 10, circle_directions(4), 0.5, np.random.default_rng(0))
    assert error.value.configurations_kept < MIN_KEPT_FRACTION


def test_speed_limits_that_admit_no_direction_are_refused(arm):
    domain = ContactDomain(*arm.joint_limits(), 0.05, np.array([1e-3, 1e-3]), L1 + L2)
    with pytest.raises(DomainTooSmall, match="approach velocity"):
        domain.draw(arm, 10, circle_directions(4), 0.5, np.random.default_rng(0))


STUDY = textwrap.dedent(
    f"""\
    name: domain-check
    robot: {{urdf: {URDF}, contact_frame: tip}}
    actuators: {{mechanical_stiffness: 1000 N*m/rad, software_stiffness: 100}}
    sensing: {{scheme: force, threshold: 3 N}}
    approach_velocity: 0.3 m/s
    samples:
      configurations: {{random: {{count: 6, seed: 2}}}}
      directions: {{circle: 6}}
      domain: {{min_singular_value: 0.4 m}}
    """
)


def test_a_study_whose_domain_keeps_nothing_gets_a_located_error_and_writes_nothing(tmp_path, capsys):
    path = tmp_path / "study.yaml"
    path.write_text(STUDY)
    out = tmp_path / "out"
    assert main(["run", str(path), "--out", str(out), "--quiet"]) == 2
    message = capsys.readouterr().err
    assert "samples.domain" in message and "min_singular_value" in message and f"{path}:9" in message
    assert not out.exists()


def test_a_study_names_its_joint_speed_limits_by_joint(tmp_path):
    path = tmp_path / "study.yaml"
    path.write_text(
        STUDY.replace(
            "{min_singular_value: 0.4 m}", "{joint_speed_limit: {joint1: 90 deg/s, joint2: 2 rad/s}}"
        )
    )
    loaded = load_study(path)
    from collision_reflex.study.robot import load_arm

    domain = contact_domain(loaded, load_arm(loaded))
    np.testing.assert_allclose(domain.joint_speed_limit, [np.pi / 2, 2.0])
    path.write_text(STUDY.replace("{min_singular_value: 0.4 m}", "{joint_speed_limit: {joint1: 1 rad/s}}"))
    loaded = load_study(path)
    with pytest.raises(StudyFileError, match="no limit for joint2"):
        contact_domain(loaded, load_arm(loaded))
