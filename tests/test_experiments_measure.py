"""Sensor model, contact window and impulse quadrature against analytic integrals and brute force."""

from __future__ import annotations

import numpy as np
import pytest

import collision_reflex as cr
from collision_reflex.experiments import (
    PAPER_SYSTEMS,
    SensorModel,
    Trace,
    find_contact,
    measure_impulse,
    model_samples,
    synthetic_trace,
)

RATE = 3500.0  # Hz, the paper's sampling rate
CASES = {
    name: (truth, v0)
    for name, truth, v0 in [
        ("u8-soft", PAPER_SYSTEMS["U8 soft"], 0.08),
        ("u8-stiff", PAPER_SYSTEMS["U8 stiff"], 0.12),
        ("a8", PAPER_SYSTEMS["A8"], 0.01),
    ]
}


def _model(truth, v0):
    return (truth.m_f, truth.k, truth.k_m, truth.F_s, truth.a, v0)


@pytest.mark.parametrize(("truth", "v0"), CASES.values(), ids=CASES.keys())
def test_interval_means_match_brute_force_averaging(truth, v0):
    # Independent check of the Gauss-Legendre splitting: average force_profile over 40000 points per sample.
    # The pulse ends with a jump of m_f v0 w, so the brute-force mean itself is good to ~(jump / 40000).
    sensor = SensorModel(RATE)
    _, t2 = cr.model.collision_times(*_model(truth, v0))
    impact = 0.00337
    times = np.arange(int((impact + t2) * RATE) + 5) / RATE
    fast = model_samples(times, *_model(truth, v0), impact, sensor)
    offsets = (np.arange(40000) + 0.5) / 40000 - 0.5
    jump = truth.m_f * v0 * np.sqrt(truth.k_m / truth.m_f)
    for i in np.linspace(0, times.size - 1, 40).astype(int).tolist() + list(
        range(int(impact * RATE) - 1, int(impact * RATE) + 8)
    ):
        brute = cr.model.force_profile(times[i] - impact + offsets / RATE, *_model(truth, v0)).mean()
        assert fast[i] == pytest.approx(brute, abs=2 * jump / 40000 + 1e-9)


@pytest.mark.parametrize("bandwidth", [None, 500.0, 1500.0], ids=["unfiltered", "500Hz", "1500Hz"])
@pytest.mark.parametrize(("truth", "v0"), CASES.values(), ids=CASES.keys())
def test_samples_keep_the_model_impulse(truth, v0, bandwidth):
    # Interval means preserve area exactly and the low-pass has unit DC gain, so sum(samples) T equals the
    # model's total impulse (eq:total_impulse) once the filter has settled (0.05 s after the contact).
    sensor = SensorModel(RATE, bandwidth)
    _, t2 = cr.model.collision_times(*_model(truth, v0))
    times = np.arange(int((0.01 + t2 + 0.05) * RATE)) / RATE
    samples = model_samples(times, *_model(truth, v0), 0.01 + 0.3 / RATE, sensor)
    assert samples.sum() / RATE == pytest.approx(cr.total_impulse(*_model(truth, v0)), rel=1e-9)


@pytest.mark.parametrize(("truth", "v0"), CASES.values(), ids=CASES.keys())
def test_quadrature_of_noiseless_trace_matches_total_impulse(truth, v0):
    # Noiseless trace at 3500 Hz: the quadrature integrates an interpolant of interval means, whose only error
    # is how the few samples around the unresolved impact pulse are joined (bounded by |quad - trapezoid|,
    # part of the stated uncertainty); the trapezoid rule of interval means is exact.
    trace = synthetic_trace(truth, v0, SensorModel(RATE), np.random.default_rng(3), noise=0.0)
    window = find_contact(trace)
    estimate = measure_impulse(trace, window)
    exact = cr.total_impulse(*_model(truth, v0))
    assert estimate.trapezoid == pytest.approx(exact, rel=1e-9)
    assert abs(estimate.value - exact) <= estimate.uncertainty + 1e-12
    # The interpolant's error is confined to the one or two samples holding the impact pulse: a PCHIP cubic
    # through a one-sample spike holds up to ~15 % more area than the spike's interval mean.
    assert abs(estimate.value - exact) <= 0.2 * cr.model.phase_impulses(*_model(truth, v0)).initial


def test_quadrature_of_smooth_pulse_matches_analytic_integral():
    # F(t) = 5 sin^2(pi t / 0.05) on [0, 0.05] s has area 5 * 0.05 / 2 = 0.125 N*s. Sampled point-wise at
    # 3500 Hz (175 samples) the PCHIP interpolant's error is O(T^3) per interval: 1e-6 relative is ample.
    rate = 3500.0
    time = np.arange(-0.02 * rate, 0.08 * rate) / rate
    force = np.where((time > 0) & (time < 0.05), 5 * np.sin(np.pi * time / 0.05) ** 2, 0.0)
    trace = Trace(time, force)
    estimate = measure_impulse(trace, find_contact(trace))
    assert estimate.value == pytest.approx(0.125, rel=1e-6)
    assert estimate.trapezoid == pytest.approx(0.125, rel=1e-6)


def test_impulse_uncertainty_matches_monte_carlo_scatter():
    # 60 noise realisations of one collision: the stated noise + floor uncertainty should match the observed
    # scatter of the quadrature. With 60 draws the sample std is itself uncertain by ~1/sqrt(2*59) = 9 %, so
    # agreement within 30 % (over 3 of those) is required.
    truth, v0 = CASES["u8-stiff"]
    sensor = SensorModel(RATE, 1000.0)
    rng = np.random.default_rng(11)
    values, stated = [], []
    for _ in range(60):
        trace = synthetic_trace(truth, v0, sensor, rng, impact_time=0.02 + 0.4 / RATE)
        estimate = measure_impulse(trace, find_contact(trace))
        values.append(estimate.value)
        stated.append(np.hypot(estimate.noise, estimate.floor))
    assert np.std(values, ddof=1) == pytest.approx(np.mean(stated), rel=0.3)
    assert np.mean(values) == pytest.approx(cr.total_impulse(*_model(truth, v0)), abs=3 * np.mean(stated))


def test_contact_window_brackets_the_collision():
    truth, v0 = CASES["u8-soft"]
    trace = synthetic_trace(truth, v0, SensorModel(RATE), np.random.default_rng(5), impact_time=0.02)
    window = find_contact(trace)
    _, t2 = cr.model.collision_times(*_model(truth, v0))
    # The window opens within two samples before the impact and closes within three after the contact ends
    # (noise at the floor decides the exact sample); the floor is the noise's: sigma 0.05 N from ~70 samples.
    assert 0.02 - 2 / RATE <= trace.time[window.start] <= 0.02
    assert 0.02 + t2 <= trace.time[window.stop - 1] <= 0.02 + t2 + 3 / RATE
    assert window.floor.sigma == pytest.approx(0.05, rel=0.3)
    assert abs(window.floor.level) < 4 * 0.05 / np.sqrt(window.floor.samples)
