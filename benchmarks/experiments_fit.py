"""One-shot fit on synthetic traces: accuracy, calibration of the stated uncertainties, and time per fit.

For each of the paper's systems (tab:one_shot means), with an unfiltered and a 1 kHz low-pass sensor at
3500 Hz and 0.05 N noise, fits 20 traces (5 velocities x 4 repeats, random sub-sample impact) and prints the
largest relative error of each parameter and phase impulse, the standard deviation of the errors' z-scores
(error / stated stderr: 1 means calibrated uncertainties) and the time per fit (trace measurement included).

Run: ``PYTHONPATH=src python benchmarks/experiments_fit.py``
"""

from __future__ import annotations

import time

import numpy as np

import collision_reflex as cr
from collision_reflex.experiments import (
    PAPER_SYSTEMS,
    SensorModel,
    find_contact,
    fit_one_shot,
    measure_impulse,
    synthetic_trace,
)
from collision_reflex.experiments.synthetic import EXAMPLE_VELOCITIES

NAMES = ("m_f", "k_s", "F_s", "a")
PHASES = ("initial", "sensing", "reaction", "total")


def main() -> None:
    print(
        f"{'system':<10}{'filter':>8}  max |rel. error| m_f k_s F_s a   |  z-score std m_f k_s F_s a"
        "   |  max |rel. error| of phases I1 I2 I3 I   | impulse z std | s/fit mean max"
    )
    for system, truth in PAPER_SYSTEMS.items():
        for bandwidth in (None, 1000.0):
            rng = np.random.default_rng(7)
            errors, z_scores, phase_errors, impulse_z, seconds = [], [], [], [], []
            for v0 in EXAMPLE_VELOCITIES[system]:
                for _ in range(4):
                    trace = synthetic_trace(truth, v0, SensorModel(3500.0, bandwidth), rng)
                    started = time.perf_counter()
                    window = find_contact(trace)
                    impulse = measure_impulse(trace, window)
                    fit = fit_one_shot(trace, window, bandwidth=bandwidth)
                    seconds.append(time.perf_counter() - started)
                    true_values = [getattr(truth, n) for n in NAMES]
                    errors.append([(f - t) / t for f, t in zip(fit.values, true_values, strict=True)])
                    z_scores.append(
                        [
                            (f - t) / fit.stderr[n]
                            for f, t, n in zip(fit.values, true_values, NAMES, strict=True)
                        ]
                    )
                    phases = cr.model.phase_impulses(truth.m_f, truth.k, truth.k_m, truth.F_s, truth.a, v0)
                    phase_errors.append(
                        [float(getattr(fit.phases, p)) / getattr(phases, p) - 1 for p in PHASES]
                    )
                    impulse_z.append((impulse.value - phases.total) / impulse.uncertainty)
            e = np.abs(errors).max(axis=0)
            z = np.std(z_scores, axis=0)
            p = np.abs(phase_errors).max(axis=0)
            label = "none" if bandwidth is None else f"{bandwidth:g}Hz"
            print(
                f"{system:<10}{label:>8}  "
                + " ".join(f"{x:6.2%}" for x in e)
                + "  |  "
                + " ".join(f"{x:4.2f}" for x in z)
                + "  |  "
                + " ".join(f"{x:6.2%}" for x in p)
                + f"  |  {np.std(impulse_z):4.2f}  |  {np.mean(seconds):.2f} {np.max(seconds):.2f}"
            )


if __name__ == "__main__":
    main()
