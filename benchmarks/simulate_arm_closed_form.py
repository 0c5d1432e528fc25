"""Arm-level simulation against the arm-level closed form on the planar two-link arm, per detection scheme.

For a few configurations and collision directions, each detection scheme of the arm simulator and approach
velocities of 0.1, 0.3, 1 and 3 v*, prints ``I_sim / I_closed - 1`` for three closed forms: the reflected
inertia in the robot mass (``robot``, the elastic-joint arm the simulator models), the same with the sprung
reaction (:func:`collision_reflex.model.impulse.sprung_reaction`, ``robot+spring``), and the reflected inertia
in the finger (``finger``: a stiff transmission whose compliance sits at the contact; the simulated arm is
not that hardware, so this column shows how far the other placement is from it). A failed run prints
``fail`` (see the note printed after the table). Run:
``PYTHONPATH=src python benchmarks/simulate_arm_closed_form.py`` (about two minutes).
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np

import collision_reflex as cr
from collision_reflex.errors import SimulationError
from collision_reflex.simulate import ArmCollision, simulate_arm_collision
from collision_reflex.simulate.arm_detection import DETECTIONS

URDF = Path(__file__).resolve().parents[1] / "designs" / "planar_two_link.urdf"
JOINTS = dict(mechanical_stiffness=50.0, reflected_inertia=2.2e-3, torque_limit=1.3)
THRESHOLD = 3.0  # [N]
CASES = [
    ([0.3, 1.2], 0.0),
    ([0.3, 1.2], 2.0),
    ([-0.5, 2.0], 0.0),
]
RATIOS = (0.1, 0.3, 1.0, 3.0)


def finger_closed_form(arm: cr.Arm, result: ArmCollision) -> float:
    """The closed form with the reflected inertia in the finger mass [N*s], at the simulated robot velocity."""
    samples = arm.kinematics(np.asarray(result.q)[None])
    eff = cr.arm.effective_parameters(
        samples, result.direction[None], 2.2e-3, 50.0, 50.0, 1.3, finger_joint_inertia=2.2e-3
    )
    return float(
        cr.total_impulse(
            eff.m_f[0, 0],
            eff.k[0, 0],
            eff.k_m[0, 0],
            THRESHOLD,
            eff.a[0, 0],
            result.approach_velocity,
            "moving",
            result.robot_velocity,
        )
    )


def main() -> None:
    arm = cr.Arm.from_urdf(URDF, "tip")
    print(
        f"planar two-link arm, joint springs 50 N m/rad, rotor 2.2e-3 kg m^2, 1.3 N m, threshold {THRESHOLD} N"
    )
    print("I_sim / I_closed - 1 [%] for the closed forms robot / robot+spring / finger")
    header = f"{'q [rad]':>12}{'u':>5}{'detection':>15}" + "".join(f"{f'{r} v*':>22}" for r in RATIOS)
    print(header)
    start, count, failures = time.perf_counter(), 0, []
    for q, angle in CASES:
        u = np.array([np.cos(angle), np.sin(angle)])
        eff = simulate_arm_collision(arm, q, u, 0.1, THRESHOLD, detection="force", **JOINTS).effective
        v_star = float(cr.optimal_velocity(eff["m_f"], eff["k"], THRESHOLD))
        for detection in DETECTIONS:
            cells = []
            for ratio in RATIOS:
                count += 1
                try:
                    result = simulate_arm_collision(
                        arm, q, u, ratio * v_star, THRESHOLD, detection=detection, **JOINTS
                    )
                except SimulationError as error:
                    failures.append(f"{q} {angle} {detection} {ratio} v*: {error}")
                    cells.append(f"{'fail':>22}")
                    continue
                ratios = (
                    result.relative_difference,
                    result.impulse / result.closed_form_sprung - 1,
                    result.impulse / finger_closed_form(arm, result) - 1,
                )
                cells.append(f"{'/'.join(f'{100 * x:+.0f}' for x in ratios):>22}")
            label = np.array2string(np.asarray(q), precision=1)
            print(f"{label:>12}{angle:>5.1f}{detection:>15}" + "".join(cells))
    for failure in failures:
        print("fail:", failure)
    print(f"{(time.perf_counter() - start) / count:.2f} s per simulation")


if __name__ == "__main__":
    main()
