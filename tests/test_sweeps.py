"""The paper's 1D sweeps: optimum against brute force, the shape of fig:motor_scale_modeling, and the two
sensing schemes of fig:stiff-sensing-impulse."""

from __future__ import annotations

import numpy as np
import pytest

import collision_reflex as cr
from collision_reflex.hardware.sweeps import (
    SWEEP_DEFAULTS,
    radius_velocity_sweep,
    stiffness_sweep,
)

LEVER, FINGER = 0.1143, 0.1  # the documented defaults


def _hand_impulse(diameter, velocity, placement="finger"):
    """fig:motor_scale_modeling written out by hand: Haddadin law from the Omni+ (60 mm, 2.21e-5 kg m^2,
    1.3 N m), N = max(1, 1.3/tau_p), reflected N^2 J_m / L^2, k_m = 1000, k_s = 100 N/m, F_s = 3 N."""
    ratio = diameter / 0.060
    inertia, torque = 2.21e-5 * ratio**4, 1.3 * ratio**2.5
    gear = np.maximum(1.0, 1.3 / torque)
    reflected = gear**2 * inertia / LEVER**2
    m_f = FINGER + (reflected if placement == "finger" else 0.0)
    a = gear * torque / LEVER / reflected
    return cr.total_impulse(m_f, 1000 * 100 / 1100, 1000.0, 3.0, a, velocity)


@pytest.mark.parametrize("placement", ["finger", "robot"], ids=["finger", "robot"])
def test_grid_matches_hand_model(placement):
    d, v = np.geomspace(0.005, 0.2, 7), np.geomspace(0.01, 3, 5)
    sweep = radius_velocity_sweep(d, v, reflected_inertia_in=placement)
    expected = _hand_impulse(d[:, None], v[None, :], placement)
    np.testing.assert_allclose(sweep.impulse, expected, rtol=1e-12)  # same arithmetic, different route


def test_optimum_against_brute_force_fine_grid():
    sweep = radius_velocity_sweep(np.geomspace(0.005, 0.2, 25), np.geomspace(0.01, 3, 25))
    fine_d, fine_v = np.geomspace(0.005, 0.2, 1501), np.geomspace(0.01, 3, 1501)
    brute = _hand_impulse(fine_d[:, None], fine_v[None, :])
    i, j = np.unravel_index(np.argmin(brute), brute.shape)
    # The refined optimum may not be worse than any fine-grid point (1e-9: rounding), and the fine grid comes
    # within its spacing of it: a step of 0.25% in d and 0.4% in v changes I by < 1e-4 relative near the minimum.
    assert sweep.best_impulse <= brute.min() * (1 + 1e-9)
    assert sweep.best_impulse == pytest.approx(brute.min(), rel=1e-4)
    assert sweep.best_diameter == pytest.approx(fine_d[i], rel=5e-3)  # two fine-grid steps
    assert sweep.best_velocity == pytest.approx(fine_v[j], rel=1e-2)  # I is flat in v at the optimum
    # With 1.3 N m required from the Omni+, the optimum is the direct-drive motor that just meets it: 60 mm.
    assert sweep.best_diameter == pytest.approx(0.060, rel=1e-6)


def test_default_sweep_shape():
    sweep = radius_velocity_sweep(np.geomspace(0.005, 0.2, 41), np.geomspace(0.01, 3, 41))
    best = sweep.minimum_impulse
    low = int(np.argmin(best))
    # High at small diameters (large N) and large diameters, a low region between (the paper's three ranges).
    assert 0 < low < best.size - 1
    assert best[0] > 1.1 * best[low] and best[-1] > 1.3 * best[low]
    assert np.all(np.diff(best[: low + 1]) < 0) and np.all(np.diff(best[low:]) > 0)
    assert np.all(sweep.gear_ratio[:low] > 1)  # the falling branch is the geared one
    # Along velocity: I(v) = A v + B/v + C, high at both ends of the velocity range for every diameter.
    inner = sweep.impulse[:, 1:-1].min(axis=1)
    assert np.all(sweep.impulse[:, 0] > inner) and np.all(sweep.impulse[:, -1] > inner)


def test_reflected_inertia_placement_matters_only_in_the_finger():
    d, v = np.geomspace(0.005, 0.06, 9), [0.7]
    robot = radius_velocity_sweep(d, v, reflected_inertia_in="robot").minimum_impulse
    finger = radius_velocity_sweep(d, v, reflected_inertia_in="finger").minimum_impulse
    assert np.all(finger > robot)
    # Behind the compliance the 500:1 geared motor changes I* by < 5%; at the contact by > 10%.
    assert robot[0] / robot[-1] < 1.05 and finger[0] / finger[-1] > 1.1


def test_stiffness_sweep_sensing_trends():
    sweep = stiffness_sweep(np.geomspace(100, 1e5, 15))
    assert np.all(np.diff(sweep.force_threshold_impulse) < 0)  # fixed F_s: phases II and III shrink with k
    assert np.all(np.diff(sweep.position_threshold_impulse) > 0)  # F_s = k e_th grows with k
    np.testing.assert_allclose(sweep.force_threshold, 3.0)
    np.testing.assert_allclose(
        sweep.position_threshold,
        sweep.stiffnesses * sweep.assumptions["position-error threshold e_th at the contact [m]"],
        rtol=1e-12,
    )


def test_csv_round_trip(tmp_path):
    import pandas as pd

    sweep = radius_velocity_sweep([0.01, 0.06], [0.1, 0.5, 1.0])
    table = pd.read_csv(sweep.to_csv(tmp_path / "grid.csv"), comment="#")
    assert len(table) == 6
    np.testing.assert_allclose(table["impulse_N_s"], sweep.impulse.ravel(), rtol=1e-8)  # 9 digits written


@pytest.mark.parametrize(
    "kwargs, name",
    [
        (dict(diameters=[0.01, 0.0]), "diameters"),
        (dict(velocities=[-1.0]), "velocities"),
        (dict(lever=0.0), "lever"),
        (dict(reflected_inertia_in="rotor"), "reflected_inertia_in"),
        (dict(law="cubic"), "law"),
    ],
    ids=["zero-diameter", "negative-velocity", "zero-lever", "bad-placement", "bad-law"],
)
def test_bad_sweep_input(kwargs, name):
    args = {"diameters": [0.01, 0.06], "velocities": [0.1], **kwargs}
    with pytest.raises(cr.InvalidParameter, match=name):
        radius_velocity_sweep(args.pop("diameters"), args.pop("velocities"), **args)


def test_optional_gearbox_inertia_against_hand_computation():
    # A harmonic drive (figures of a test unit: 50 mm, J_g = 1e-6 kg m^2 at the input) scaled to each geared
    # motor's diameter: J_g(r) = 1e-6 (r/0.05)^4 at its own length, reflected N^2 (J_m + J_g) in the finger.
    gearbox = cr.hardware.Gearbox(
        "harmonic", diameter=0.05, length=0.03, mass=0.2, inertia=1e-6, rated_torque=30.0
    )
    d, v = np.array([0.01, 0.03, 0.08]), np.array([0.5])
    with_box = radius_velocity_sweep(d, v, gearbox=gearbox)
    ratio = d / 0.060
    gear = np.maximum(1.0, 1.3 / (1.3 * ratio**2.5))
    box = np.where(gear > 1, 1e-6 * (d / 0.05) ** 4, 0.0)  # direct drive (80 mm) has no gearbox
    np.testing.assert_allclose(with_box.reflected_inertia, gear**2 * (2.21e-5 * ratio**4 + box), rtol=1e-12)
    without = radius_velocity_sweep(d, v)
    assert np.all(with_box.impulse[:2] > without.impulse[:2]) and with_box.impulse[2] == without.impulse[2]


def test_the_contact_keywords_reach_the_radius_velocity_model():
    d, v = [0.01, 0.06], [0.2, 0.8]
    new = radius_velocity_sweep(d, v, k_m=2000.0, k_s=50.0, F_s=5.0, m_f=0.2, m_r=0.05)
    # Every contact keyword reaches the model: the settings differ from the defaults by factors >= 2.
    assert not np.allclose(new.impulse, radius_velocity_sweep(d, v).impulse, rtol=0.1)
    np.testing.assert_allclose(new.F_s, 5.0)
    np.testing.assert_allclose(new.m_r - new.reflected_inertia / LEVER**2, 0.05, rtol=1e-12)


def test_the_default_keys_are_the_paper_symbols():
    assert (
        SWEEP_DEFAULTS["F_s"] == 3.0 and SWEEP_DEFAULTS["m_f"] == 0.1
    )  # fig:motor_scale_modeling, tab:one_shot
    with pytest.raises(KeyError):  # an old spelling is no key
        SWEEP_DEFAULTS["threshold"]


def test_the_keywords_reach_the_stiffness_sweep():
    k = np.geomspace(100, 1e4, 4)
    new = stiffness_sweep(k, v0=0.3, F_s=4.0, e_th=0.01, k_s=1e4, m_f=0.2, m_r=0.1)
    np.testing.assert_allclose(new.force_threshold, 4.0)
    # F_s = k e_th with k the series of k_m and k_s = 1e4 N/m.
    np.testing.assert_allclose(new.position_threshold, k * 1e4 / (k + 1e4) * 0.01, rtol=1e-12)


def test_an_empty_grid_is_invalid_parameter():
    """An empty array of diameters or stiffnesses raised IndexError or 'argmin of an empty sequence'."""
    with pytest.raises(cr.InvalidParameter, match=r"^stiffnesses ="):
        cr.hardware.sweeps.stiffness_sweep(np.array([]))
    with pytest.raises(cr.InvalidParameter, match=r"^diameters ="):
        cr.hardware.sweeps.radius_velocity_sweep(np.array([]), np.array([0.1]))
