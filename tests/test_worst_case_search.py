"""The worst-case search: it finds a narrow impulse peak between the samples, checked by brute force."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from collision_reflex.arm.domain import ContactDomain, smallest_singular_values
from collision_reflex.optimize.evaluate import sample_impulses
from collision_reflex.optimize.pareto import built_problem
from collision_reflex.optimize.samples import ContactSamples
from collision_reflex.optimize.solve import design_at
from collision_reflex.optimize.worst_case import search_worst_case
from collision_reflex.study.arm_setup import StudyProblems
from collision_reflex.study.load import load_study
from collision_reflex.study.resolve import resolved_yaml

ROOT = Path(__file__).resolve().parents[1]
FLOOR = 0.01  # [m]: near the folded pose the finger mass along the singular direction grows as 1/sigma^2


@pytest.fixture(scope="module")
def case():
    problems = StudyProblems(resolved_yaml(load_study(ROOT / "studies" / "two_link_paper.yaml")))
    setup = problems.setup
    problem = built_problem(problems, problems.objective)
    design = design_at(problem, problem.x0)
    domain = ContactDomain(*setup.arm.joint_limits(), FLOOR, setup.arm.joint_speed_limit, 0.55)
    return setup.arm, setup.technology, design, domain


def _grid_max(arm, technology, design, domain, q1, q2, angles) -> float:
    """The largest impulse over a grid of q2 and directions (q1 fixed), inside the domain."""
    q = arm.configuration(np.column_stack([np.full(q2.size, q1), q2]))
    kinematics = arm.kinematics(q)
    u = np.column_stack([np.cos(angles), np.sin(angles)])
    ci, di = np.repeat(np.arange(q2.size), angles.size), np.tile(np.arange(angles.size), q2.size)
    inside = domain.contains(kinematics.jacobian[ci], u[di], design.approach_velocity)
    samples = ContactSamples(kinematics, u[di][inside], ci[inside])
    return float(sample_impulses(samples, technology, design).max())


def test_the_search_finds_a_narrow_peak_the_samples_miss(case):
    arm, technology, design, domain = case
    directions = np.column_stack([np.cos(a := np.arange(8) * np.pi / 4), np.sin(a)])
    draw = domain.draw(arm, 6, directions, design.approach_velocity, np.random.default_rng(0))
    config, direction = np.nonzero(draw.feasible)
    coarse = sample_impulses(
        ContactSamples(arm.kinematics(draw.q), directions[direction], config), technology, design
    )
    worst = np.argsort(coarse)[::-1][:3]
    found = search_worst_case(
        arm,
        domain,
        technology,
        design,
        draw.q[config[worst]],
        directions[direction[worst]],
        random_starts=3,
        rng=np.random.default_rng(1),
    )
    # The peak lies between the samples: the 48 samples see a small fraction of it.
    assert coarse.max() < 0.2 * found.impulse
    # Its point is inside the domain, on its boundary: the finger mass grows toward the singular pose until the
    # singular-value floor or a joint's speed limit stops it (here the speed: 0.5 m/s at 20 rad/s).
    jacobian = arm.kinematics(found.q[None], full=False).jacobian
    sigma = smallest_singular_values(jacobian)[0]
    speed = domain.speed_margin(jacobian, found.direction[None], design.approach_velocity)[0]
    assert sigma >= FLOOR * (1 - 1e-6) and np.all(speed >= -1e-6)
    assert sigma < 1.01 * FLOOR or speed.min() < 0.01
    # Brute force: a coarse grid over every pose and direction (q1 does not change a planar arm's impulse), and
    # a fine grid around the searched point; the search is within its 0.5 % tolerance of the larger.
    q1, q2 = arm.joint_coordinates(found.q[None])[0]
    heading = np.arctan2(found.direction[1], found.direction[0])
    everywhere = _grid_max(
        arm, technology, design, domain, 0.0, np.linspace(-np.pi, np.pi, 721), np.linspace(0, 2 * np.pi, 360)
    )
    nearby = _grid_max(
        arm,
        technology,
        design,
        domain,
        q1,
        q2 + np.linspace(-0.02, 0.02, 401),
        heading + np.radians(np.linspace(-2, 2, 201)),
    )
    assert found.impulse >= 0.995 * max(everywhere, nearby)
    assert found.impulse <= 1.0001 * max(
        everywhere, nearby
    )  # a point of the domain: no value above the grids'
    assert found.maxima_impulse[0] == found.impulse and np.all(np.diff(found.maxima_impulse) <= 0)


def test_the_search_is_deterministic(case):
    arm, technology, design, domain = case
    q = arm.configuration(np.array([[0.2, 2.0], [1.0, -1.0]]))
    u = np.array([[1.0, 0.0], [0.0, 1.0]])
    runs = [
        search_worst_case(
            arm, domain, technology, design, q, u, random_starts=2, rng=np.random.default_rng(4)
        )
        for _ in range(2)
    ]
    assert runs[0].impulse == runs[1].impulse
    np.testing.assert_array_equal(runs[0].maxima_q, runs[1].maxima_q)
