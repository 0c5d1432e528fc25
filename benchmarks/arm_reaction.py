"""Why the arm closed form misses the simulated arm at v* and 3 v*: each phase against each model.

On the planar two-link arm (joint springs 50 N m/rad, rotor 2.2e-3 kg m^2, 1.3 N m, F_s = 3 N, contact-force
sensor, the simulator's default wall of 1e6 N/m), for three configurations x directions and v0 in {0.1, 1, 3}
v*, it simulates the collision (:func:`collision_reflex.simulate.simulate_arm_collision`) and prints
``I_sim / I_model - 1`` [%] of the impact + sensing phases (the impulse until detection), of the reaction and
of the total, for

- ``1D``: the arm closed form, ``m_f v0 + F_s^2 / (2 k v0)`` and the paper's constant-acceleration reaction;
- ``sprung``: the same with :func:`collision_reflex.model.impulse.sprung_reaction`;
- ``joint``: :func:`collision_reflex.model.joint_space.joint_space_collision` (the links' motion along the
  wall), and ``joint+lag`` with the simulated sensor's lag ``c / k_c`` (it reads the wall's elastic force ``k_c
  d``, which lags the contact force by ``c / k_c`` on a ramp).

Then, per case, the model's threshold margin (a few % or less: the detection sits on a peak of the oscillating
force, ill-conditioned), the sliding links' pull off the wall over ``F_s`` (a few % or more: the finger leaves
the wall after the impact, which the model leaves out) and whether its linear force falls to zero before
detection; for both retreats; and the model's CPU time (median) with the machine's load.
Run: ``PYTHONPATH=src python benchmarks/arm_reaction.py`` (about a minute).
"""

from __future__ import annotations

import os
import statistics
import time
from pathlib import Path

import numpy as np

import collision_reflex as cr
from collision_reflex.model.impulse import phase_impulses, sprung_reaction
from collision_reflex.model.joint_space import joint_space_collision
from collision_reflex.simulate import simulate_arm_collision
from collision_reflex.simulate.contact import damping_from_ratio

URDF = Path(__file__).resolve().parents[1] / "designs" / "planar_two_link.urdf"
K_M, ROTOR, TAU, F_S, K_C = 50.0, 2.2e-3, 1.3, 3.0, 1e6
JOINTS = dict(mechanical_stiffness=K_M, reflected_inertia=ROTOR, torque_limit=TAU)
CASES = {
    "folded-x": ([-0.5, 2.0], 0.0),
    "elbow-up-x": ([0.3, 1.2], 0.0),
    "elbow-up-oblique": ([0.3, 1.2], 2.0),
}
RATIOS = (0.1, 1.0, 3.0)


def _percent(simulated: float, model: float) -> str:
    return f"{100 * (simulated / model - 1):+7.1f}"


def _normal_curvature(arm: cr.Arm, q: np.ndarray, u: np.ndarray, step: float = 1e-6) -> np.ndarray:
    """The Hessian of the contact point's position along ``u`` [m/rad^2], central differences of ``u^T J``."""
    rows = []
    for e in np.eye(q.size):
        ahead, behind = (arm.kinematics((q + s * step * e)[None]).jacobian[0] for s in (1, -1))
        rows.append(u @ (ahead - behind) / (2 * step))
    return np.array(rows)


def main() -> None:
    print(
        f"machine load (1, 5, 15 min): {', '.join(f'{x:.1f}' for x in os.getloadavg())} on {os.cpu_count()} cores"
    )
    arm = cr.Arm.from_urdf(URDF, "tip")
    print(
        "I_sim / I_model - 1 [%], impact+sensing / reaction / total, for the models 1D, sprung, joint, joint+lag"
    )
    cpu: list[float] = []
    for retreat in ("along_u", "saturated"):
        print(f"\nretreat: {retreat}")
        print(
            f"{'case':>17}{'v0':>6}{'1D':>24}{'sprung':>24}{'joint':>24}{'joint+lag':>24}   margin     pull  lift-off"
        )
        for name, (q, angle) in CASES.items():
            u = np.array([np.cos(angle), np.sin(angle)])
            samples = arm.kinematics(np.asarray(q, dtype=float)[None])
            mass, jac = samples.mass_matrix[0], samples.jacobian[0]
            curvature = _normal_curvature(arm, np.asarray(q, dtype=float), u)
            eff = simulate_arm_collision(arm, q, u, 0.1, F_S, detection="force", **JOINTS).effective
            v_star = float(cr.optimal_velocity(eff["m_f"], eff["k"], F_S))
            lag = damping_from_ratio(2.0, eff["m_f"], K_C) / K_C
            for ratio in RATIOS:
                v0 = ratio * v_star
                sim = simulate_arm_collision(
                    arm, q, u, v0, F_S, detection="force", retreat=retreat, contact_stiffness=K_C, **JOINTS
                )
                sim_phases = (sim.detected_impulse, sim.impulse - sim.detected_impulse, sim.impulse)
                one_d = phase_impulses(eff["m_f"], eff["k"], eff["k_m"], F_S, eff["a"], v0, "moving", v0)
                detected = float(one_d.initial + one_d.sensing)
                _, sprung = sprung_reaction(F_S, eff["k_m"], eff["F_a"], eff["m_r"], v0)
                models = [
                    (detected, float(one_d.reaction), float(one_d.total)),
                    (detected, sprung, detected + sprung),
                ]
                for delay in (0.0, lag):
                    start = time.process_time()
                    joint = joint_space_collision(
                        mass,
                        jac,
                        u,
                        K_M,
                        ROTOR,
                        TAU,
                        F_S,
                        v0,
                        retreat=retreat,
                        delay=delay,
                        normal_curvature=curvature,
                    )
                    cpu.append(time.process_time() - start)
                    models.append(
                        (joint.phases.initial + joint.phases.sensing, joint.phases.reaction, joint.total)
                    )
                cells = "".join(
                    f"{'/'.join(_percent(s, m).strip() for s, m in zip(sim_phases, model, strict=True)):>24}"
                    for model in models
                )
                print(
                    f"{name:>17}{ratio:>5g}*{cells}   {100 * joint.threshold_margin:5.1f} %"
                    f"  {100 * (joint.sliding_pull or 0.0):5.1f} %  {joint.lifted_off}"
                )
    print(
        f"\njoint_space_collision: median {1e3 * statistics.median(cpu):.1f} ms CPU per call ({len(cpu)} calls);"
        f" machine load {', '.join(f'{x:.1f}' for x in os.getloadavg())}"
    )


if __name__ == "__main__":
    main()
