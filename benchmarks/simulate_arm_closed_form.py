"""Arm-level simulation against the arm-level closed form on the planar two-link arm.

For a few configurations and collision directions and approach velocities from 0.1 v* to 3 v*, prints the
relative difference between the simulated impulse (elastic joints, Pinocchio forward dynamics, compliant
wall) and the closed form with the effective parameters of :func:`collision_reflex.effective_parameters`.
Run: ``PYTHONPATH=src python benchmarks/simulate_arm_closed_form.py`` (about half a minute).
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np

import collision_reflex as cr
from collision_reflex.simulate import simulate_arm_collision

URDF = Path(__file__).resolve().parents[1] / "designs" / "planar_two_link.urdf"
JOINTS = dict(mechanical_stiffness=50.0, reflected_inertia=2.2e-3, torque_limit=1.3)
CASES = [
    ([0.3, 1.2], 0.0),
    ([0.3, 1.2], 2.0),
    ([-0.5, 2.0], 0.0),
    ([-0.5, 2.0], 2.0),
    ([0.0, np.pi / 2], 0.0),
]
RATIOS = (0.1, 0.3, 1.0, 3.0)


def main() -> None:
    arm = cr.Arm.from_urdf(URDF, "tip")
    print("planar two-link arm, joint springs 50 N m/rad, rotor 2.2e-3 kg m^2, 1.3 N m, threshold 3 N")
    print(f"{'q [rad]':>16}{'u angle':>9}{'v* [m/s]':>10}" + "".join(f"{f'{r} v*':>10}" for r in RATIOS))
    worst: dict[float, float] = dict.fromkeys(RATIOS, 0.0)
    start = time.perf_counter()
    count = 0
    for q, angle in CASES:
        u = np.array([np.cos(angle), np.sin(angle)])
        eff = simulate_arm_collision(arm, q, u, 0.1, 3.0, **JOINTS).effective
        v_star = float(cr.optimal_velocity(eff["m_f"], eff["k"], 3.0))
        cells = []
        for ratio in RATIOS:
            difference = simulate_arm_collision(arm, q, u, ratio * v_star, 3.0, **JOINTS).relative_difference
            worst[ratio] = max(worst[ratio], abs(difference))
            cells.append(f"{100 * difference:>+9.1f}%")
            count += 1
        print(
            f"{np.array2string(np.asarray(q), precision=2):>16}{angle:>9.2f}{v_star:>10.3g}" + "".join(cells)
        )
    print(
        "largest |I_sim / I_closed - 1|: " + ", ".join(f"{100 * w:.1f} % at {r} v*" for r, w in worst.items())
    )
    print(f"{1e3 * (time.perf_counter() - start) / count:.0f} ms per simulation")


if __name__ == "__main__":
    main()
