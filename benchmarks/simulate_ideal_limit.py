"""Largest relative difference between the simulated impulse in the ideal limit and the closed form.

Sweeps v0 over 0.1 v* to 10 v* (41 log-spaced values) for the closed form's reaction variants, each in the
limit where it holds (see :mod:`collision_reflex.simulate`), and prints the largest |I_sim / I_closed - 1|
and the time per simulation. Run: ``PYTHONPATH=src python benchmarks/simulate_ideal_limit.py``.
"""

from __future__ import annotations

import math
import time

import numpy as np

import collision_reflex as cr
from collision_reflex.simulate import CollisionSetup, Detection, simulate

M_F, F_S, A, ROBOT_MASS = 0.2, 3.0, 20.0, 1e6

VARIANTS = {
    "at_rest (k_s << k_m)": (100.0, 1e7, "at_rest", False),
    "moving, v_r = v0 (k_s = inf)": (math.inf, 1000.0, "moving", False),
    "moving, v_r = v0 k/k_m (k_s = 100, k_m = 1000)": (100.0, 1000.0, "moving", True),
}


def main() -> None:
    print(
        f"m_f = {M_F} kg, F_s = {F_S} N, a = {A} m/s^2, m_r = {ROBOT_MASS:g} kg (F_a = m_r a), rigid plastic wall"
    )
    for name, (k_s, k_m, reaction, consistent) in VARIANTS.items():
        k = cr.model.series_stiffness(k_m, k_s)
        v_star = float(cr.optimal_velocity(M_F, k, F_S))
        worst, worst_at, elapsed = 0.0, 0.0, []
        for ratio in np.geomspace(0.1, 10.0, 41):
            setup = CollisionSetup(
                M_F, ROBOT_MASS, k_m, k_s, ROBOT_MASS * A, ratio * v_star, Detection("force", F_S)
            )
            start = time.perf_counter()
            result = simulate(setup)
            elapsed.append(time.perf_counter() - start)
            closed = setup.closed_form(reaction, setup.detection_robot_velocity if consistent else None).total
            error = abs(result.impulse / closed - 1)
            if error > worst:
                worst, worst_at = error, ratio
        print(
            f"{name:<50} largest |I_sim/I_closed - 1| = {worst:.2e} (at v0 = {worst_at:.3g} v*), "
            f"{1e3 * np.median(elapsed):.1f} ms per simulation"
        )


if __name__ == "__main__":
    main()
