"""Where the closed form's plastic impact holds against a rebounding contact: the validity map over restitution.

The closed form takes the object as rigid and the impact as plastic. Against a contact that rebounds (a
Kelvin-Voigt wall 1000 times stiffer than the joints along the direction, damped for a coefficient of restitution
e of the finger alone), the time-domain simulation (:func:`collision_reflex.simulate.simulate_arm_collision`)
is compared with the closed form (robot placement, the sprung reaction) over e in {0.02, 0.1, 0.3, 0.5} and
v0 from 0.1 to 73 v* (the range the shipped designs use), for the planar arm and the UR5 of
``benchmarks/validity_map.py``, with force-threshold and spring-torque detection. It prints the largest
|I_sim / I_closed - 1| per restitution and velocity ratio, the failures, the timings and the machine's load.

Run: ``PYTHONPATH=src python benchmarks/restitution_validity.py``.
"""

from __future__ import annotations

import importlib.util
import os
import time
from pathlib import Path

import numpy as np

from collision_reflex.simulate.validity import validity_map

RESTITUTIONS = (0.02, 0.1, 0.3, 0.5)
VELOCITY_RATIOS = (0.1, 0.3, 1.0, 3.0, 10.0, 30.0, 73.0)
DETECTIONS = ("force", "spring_torque")


def _arms() -> dict:
    """The planar arm's and the UR5's set-ups of the validity-map benchmark."""
    path = Path(__file__).with_name("validity_map.py")
    spec = importlib.util.spec_from_file_location("validity_map_benchmark", path)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return {"planar two-link": module._planar, "UR5": module._ur5}


def main() -> None:
    print(
        f"machine load (1, 5, 15 min): {', '.join(f'{x:.1f}' for x in os.getloadavg())} on {os.cpu_count()} cores"
    )
    for name, make in _arms().items():
        arm, joints, configurations, directions = make()
        start, cpu = time.perf_counter(), time.process_time()
        table = validity_map(
            arm,
            joints,
            configurations,
            directions,
            velocity_ratios=VELOCITY_RATIOS,
            stiffness_ratios=(1000.0,),
            detections=DETECTIONS,
            placements=("robot",),
            restitutions=RESTITUTIONS,
        )
        table = table[table["reaction_model"] == "sprung"]
        failed = table[table["error"] != ""]
        print(
            f"\n{name}: {len(configurations)} configuration(s) x {len(directions)} directions, {len(table)} "
            f"simulations ({len(failed)} refused or failed) in {time.perf_counter() - start:.1f} s wall, "
            f"{time.process_time() - cpu:.1f} s CPU"
        )
        for message, count in failed["error"].value_counts().items():
            print(f"  {count} x {message[:150]}")
        for detection in DETECTIONS:
            chosen = table[table["detection"] == detection]
            worst = chosen.pivot_table(
                index="restitution",
                columns="velocity_ratio",
                values="difference",
                aggfunc=lambda d: np.max(np.abs(d)),
            )
            worst.index = [f"e = {e:.2f}" for e in worst.index]
            worst.columns = [f"{r:g} v*" for r in worst.columns]
            print(f"largest |I_sim / I_closed - 1| [%], detection {detection}:")
            print((100 * worst).round(1).to_string())
    print(f"\nmachine load (1, 5, 15 min): {', '.join(f'{x:.1f}' for x in os.getloadavg())}")


if __name__ == "__main__":
    main()
