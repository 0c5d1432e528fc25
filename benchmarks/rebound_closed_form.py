"""The rebound closed form against the project's 1D simulator and MuJoCo, over restitution and approach speed.

For each coefficient of restitution (the contact damped for it; MuJoCo's own restitution measured and used) and
approach speed (multiples of the plastic optimum v*), prints the closed form with the rebound's impulse where the
finger settles before detection (``settled``), and the simulator's and MuJoCo's relative differences from it and
from the plastic closed form. Beyond the settled-rebound speed no closed form follows the rebound: the columns
then compare with the plastic form only. Run: ``PYTHONPATH=src python benchmarks/rebound_closed_form.py``
(needs ``mujoco``).
"""

from __future__ import annotations

import importlib.util
import os
import time
from pathlib import Path

from collision_reflex.model import (
    optimal_velocity,
    phase_impulses,
    rebound_impulse,
    series_stiffness,
    settled_rebound_speed,
)
from collision_reflex.simulate import CollisionSetup, Detection, simulate
from collision_reflex.simulate.contact import damping_from_ratio, damping_ratio_for_restitution

# An arm-sized joint along one direction (representative, not a maker's figures), as tests/test_rebound.py.
M_F, M_R, K_M, K_S, F_A, F_S = 0.5, 2.0, 1e4, 3e3, 200.0, 10.0
K = float(series_stiffness(K_M, K_S))
RESTITUTIONS = (0.048, 0.1, 0.2, 0.3, 0.4, 0.5)  # 0.048: the simulator's default contact (damping ratio 2)
SPEEDS = (0.1, 0.3, 0.5, 1.0, 3.0, 10.0)  # multiples of v*
TIME_CONSTANT, TIMESTEP = 5e-4, 1e-5  # MuJoCo's contact [s] and step [s]


def _mujoco_case():
    path = Path(__file__).resolve().parents[1] / "tests" / "mujoco_rebound.py"
    spec = importlib.util.spec_from_file_location("mujoco_rebound", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def main() -> None:
    mujoco_case = _mujoco_case()
    print(
        f"machine load (1, 5, 15 min): {', '.join(f'{x:.1f}' for x in os.getloadavg())} on {os.cpu_count()} cores"
    )
    v_star = float(optimal_velocity(M_F, K, F_S))
    print(
        f"m_f = {M_F} kg, k = {K:.1f} N/m, k_m = {K_M:g} N/m, F_s = {F_S} N, a = {F_A / M_R} m/s^2, v* = {v_star:.4f} m/s"
    )
    print("contact 1000 k (simulator), MuJoCo solref time constant 0.5 ms; differences I / I_closed - 1 [%]")
    print(
        f"{'e':>6}{'e MuJoCo':>9}{'v0/v*':>7}{'settled':>8}{'closed':>10}{'sim':>8}{'MuJoCo':>8}{'sim pl.':>8}{'MJ pl.':>8}"
    )
    worst = [0.0, 0.0]
    start = time.perf_counter()
    for e in RESTITUTIONS:
        ratio = 2.0 if e == 0.048 else damping_ratio_for_restitution(e)
        e_mujoco = mujoco_case.measured_restitution(M_F, 0.1, TIME_CONSTANT, ratio, TIMESTEP)
        for multiple in SPEEDS:
            v0 = multiple * v_star
            plastic = float(phase_impulses(M_F, K, K_M, F_S, F_A / M_R, v0, "moving", v0 * K / K_M).total)
            setup = CollisionSetup(
                M_F,
                M_R,
                K_M,
                K_S,
                F_A,
                v0,
                Detection("force", F_S),
                contact_stiffness=1e3 * K,
                contact_damping=damping_from_ratio(ratio, M_F, 1e3 * K),
            )
            simulated = simulate(setup).impulse
            mujoco = mujoco_case.collision_impulse(
                M_F, K, K_M, F_S, F_A / M_R, v0, TIME_CONSTANT, ratio, TIMESTEP
            )
            settled = v0 <= settled_rebound_speed(M_F, K, F_S, e_mujoco)
            closed = plastic + (rebound_impulse(M_F, K, F_S, v0, e_mujoco) if settled else 0.0)
            differences = [100 * (x / closed - 1) for x in (simulated, mujoco)]
            if settled:
                worst = [max(w, abs(d)) for w, d in zip(worst, differences, strict=True)]
            print(
                f"{e:>6.3f}{e_mujoco:>9.4f}{multiple:>7.2g}{'yes' if settled else 'no':>8}{closed:>10.5f}"
                + "".join(f"{d:>8.2f}" for d in differences)
                + "".join(f"{100 * (x / plastic - 1):>8.2f}" for x in (simulated, mujoco))
            )
    print(
        f"largest |difference| where the finger settles first: simulator {worst[0]:.2f} %, MuJoCo {worst[1]:.2f} %"
    )
    print(f"{time.perf_counter() - start:.1f} s wall; load {', '.join(f'{x:.1f}' for x in os.getloadavg())}")


if __name__ == "__main__":
    main()
