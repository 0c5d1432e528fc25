"""The design problem's numeric per-sample data and torque demands against direct computations.

The references are written out here from their definitions (the paper's "Collision Reflex in Higher Dimensions"): the finger
mass ``1 / (w^T M_f^-1 w)`` by a linear solve, the reaction compliance ``max_i |w_i| / tau_i`` by a loop, the required torque as the largest
``|gravity torque|`` over the sampled configurations (Panda: the planar two-link arm has no gravity torques).
Both sides are a few floating-point operations on the same arrays, so they agree to rounding: tolerance 1e-12
relative (the sampled two-link mass matrices have condition numbers below 50). A missing motor mass, a dropped
demand or a wrong sign moves them by orders of magnitude more.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import collision_reflex as cr
from collision_reflex.arm import Arm
from collision_reflex.optimize.constraints import (
    binding_rows,
    binding_torque_demands,
    required_torque_function,
    torque_requirement_rows,
    undominated_rows,
)
from collision_reflex.optimize.samples import finger_mass_directions, reaction_compliance

TWO_LINK = Path(__file__).resolve().parents[1] / "designs" / "planar_two_link.urdf"
RTOL = 1e-12


@pytest.fixture(scope="module")
def samples():
    arm = Arm.from_urdf(TWO_LINK, "tip")
    kinematics = arm.kinematics(arm.sample_configurations(6, np.random.default_rng(3)))
    angles = np.linspace(0, 2 * np.pi, 5, endpoint=False) + 0.1
    return cr.ContactSamples.grid(kinematics, np.c_[np.cos(angles), np.sin(angles)])


def test_finger_mass_directions_are_the_constrained_minimisers(samples):
    motor_mass = np.array([0.8, 0.3])  # [kg]
    finger_inertia = np.array([0.02, 0.005])  # [kg m^2]
    x = finger_mass_directions(samples, motor_mass, finger_inertia)
    kin, w = samples.kinematics, samples.joint_moment_arms
    for s, config in enumerate(samples.config_index):
        influence = kin.motor_mass_influence[config]
        m_f = kin.mass_matrix[config] + motor_mass[0] * influence[0] + motor_mass[1] * influence[1]
        m_f = m_f + np.diag(finger_inertia)
        finger_mass = 1 / (w[s] @ np.linalg.solve(m_f, w[s]))
        assert w[s] @ x[s] == pytest.approx(1.0, rel=RTOL)
        assert x[s] @ m_f @ x[s] == pytest.approx(finger_mass, rel=RTOL)


def test_reaction_compliance_is_the_largest_torque_fraction(samples):
    peak_torque = np.array([12.0, 3.0])  # [N m]
    expected = [
        max(abs(w_i) / tau for w_i, tau in zip(w, peak_torque, strict=True))
        for w in samples.joint_moment_arms
    ]
    np.testing.assert_allclose(reaction_compliance(samples, peak_torque), expected, rtol=RTOL)


def test_binding_torque_demands_drop_only_demands_that_never_bind():
    # The planar two-link arm moves in a horizontal plane (no gravity torque): the Panda has them.
    arm = Arm.from_example_robot_data("panda")
    kinematics = arm.kinematics(arm.sample_configurations(8, np.random.default_rng(3)))
    samples = cr.ContactSamples.grid(kinematics, np.array([[1.0, 0.0, 0.0]]))
    constraints = cr.Constraints(payload=0.4, safety_factor=1.5)
    names, n = tuple(arm.joint_names), arm.nv
    low, high = np.full(n, 0.1), np.full(n, 2.0)  # box of motor masses [kg]
    demands = binding_torque_demands(samples, constraints, names, low, high)
    rows, _ = torque_requirement_rows(samples, constraints, names)
    assert sum(len(bases) for bases, _, _ in demands) < n * len(rows)  # the reduction does drop demands
    required = required_torque_function(demands, n)
    kin = samples.kinematics
    configs = np.unique(samples.config_index)
    for masses in np.random.default_rng(5).uniform(low, high, size=(20, n)):
        gravity = [
            kin.gravity[c] + constraints.payload * kin.contact_gravity[c] + kin.motor_gravity[c].T @ masses
            for c in configs
        ]
        expected = constraints.safety_factor * np.max(np.abs(gravity), axis=0)
        np.testing.assert_allclose(np.asarray(required(masses)).ravel(), expected, rtol=RTOL)


def _box_corners(low: np.ndarray, high: np.ndarray) -> np.ndarray:
    """All 2^k corners of the box ``[low, high]``, (2^k, k)."""
    pick = (np.arange(2**low.size)[:, None] >> np.arange(low.size)[None, :]) & 1
    return np.where(pick == 1, high, low)


def test_undominated_rows_keep_the_maximum_and_drop_only_covered_rows():
    # A sampled smooth motion's rows: neighbours nearly equal, a few cross over the box (the duty-cycle case).
    rng = np.random.default_rng(11)
    k, n = 4, 400
    time = np.linspace(0.0, 1.0, n)[:, None]
    slopes = np.sin(2 * np.pi * time * rng.uniform(0.5, 3.0, k) + rng.uniform(0, 6, k)) * rng.uniform(1, 5, k)
    bases = 3.0 * np.cos(2 * np.pi * time[:, 0] + 0.4)
    bases, slopes = np.concatenate([bases, -bases]), np.vstack([slopes, -slopes])
    bases[7], slopes[7] = bases[3], slopes[3]  # an exact duplicate: one of the pair must stay
    low, high = np.full(k, 0.1), np.array([2.0, 1.0, 3.0, 0.5])
    rows = np.column_stack([bases, slopes])
    box_test = binding_rows(bases, slopes, low, high)
    keep = undominated_rows(rows, np.r_[1.0, low], np.r_[1.0, high])
    assert not np.any(keep & ~box_test)  # a row the box test drops is dominated
    assert 0 < keep.sum() < box_test.sum() / 3  # pairwise dominance removes most of what the box test keeps
    assert keep[3] != keep[7] or not keep[3]
    # Independent check: a linear function is >= 0 on a box iff it is at every corner, so at each corner and
    # at random points the kept rows' maximum is the maximum of all rows.
    points = np.vstack([_box_corners(low, high), rng.uniform(low, high, size=(2000, k))])
    every = (bases[None, :] + points @ slopes.T).max(axis=1)
    kept = (bases[keep][None, :] + points @ slopes[keep].T).max(axis=1)
    np.testing.assert_allclose(kept, every, rtol=RTOL, atol=0)
    # and each dropped row is covered at every corner by one kept row (dominance, not just the maximum).
    corner_values = bases[None, :] + _box_corners(low, high) @ slopes.T
    for row in np.flatnonzero(~keep):
        margin = corner_values[:, keep] - corner_values[:, [row]]
        assert np.any(np.all(margin >= -1e-12 * np.abs(corner_values).max(), axis=0))
