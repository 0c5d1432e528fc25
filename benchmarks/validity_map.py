"""Where the arm closed form holds: the validity map of the planar arm, the UR5 and the Panda.

For each arm, a few configurations x directions x v0 in {0.1, 0.3, 1, 3, 10} v* x a compliant contact (0.1 of
the joints' stiffness along u: a stiff transmission hitting a soft object) and a stiff one (10 times: compliant
joints hitting a hard object), it simulates the collision in the time domain
(:func:`collision_reflex.simulate.simulate_arm_collision`) and compares it with the arm closed form for both
placements of the reflected inertia; it prints the largest |I_sim / I_closed - 1| and the share of cases within
5 %, per detection scheme, placement and stiffness ratio, with the timings and the machine's load.

Run: ``PYTHONPATH=src python benchmarks/validity_map.py [FIGURE.png]`` (about a minute on an idle machine).
The joint parameters of the UR5 and the Panda are representative harmonic-drive joints, not the makers' data.
"""

from __future__ import annotations

import os
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

import collision_reflex as cr
from collision_reflex.plots import new_figure, save_figure
from collision_reflex.simulate.validity import (
    PLACEMENTS,
    JointDesign,
    validity_map,
    worst_difference,
)

URDF = Path(__file__).resolve().parents[1] / "designs" / "planar_two_link.urdf"


def _planar() -> tuple[Any, JointDesign, list[list[float]], list[list[float]]]:
    arm = cr.Arm.from_urdf(URDF, "tip")
    joints = JointDesign(mechanical_stiffness=50.0, reflected_inertia=2.2e-3, torque_limit=1.3, threshold=3.0)
    directions = [[np.cos(angle), np.sin(angle)] for angle in (0.0, 2.0)]
    return arm, joints, [[0.3, 1.2], [-0.5, 2.0]], directions


def _ur5() -> tuple[Any, JointDesign, list[list[float]], list[list[float]]]:
    arm = cr.Arm.from_example_robot_data("ur5")
    joints = JointDesign(
        mechanical_stiffness=[5000, 5000, 3000, 800, 800, 800],
        reflected_inertia=[0.2, 0.2, 0.1, 0.03, 0.03, 0.03],
        torque_limit=[150, 150, 150, 28, 28, 28],
        threshold=20.0,
    )
    return arm, joints, [[0.0, -1.2, 1.5, -1.9, -1.57, 0.0]], [[1, 0, 0], [0, 0, -1]]


def _panda() -> tuple[Any, JointDesign, list[list[float]], list[list[float]]]:
    arm = cr.Arm.from_example_robot_data("panda")
    joints = JointDesign(
        mechanical_stiffness=[4000] * 4 + [1000] * 3,
        reflected_inertia=[0.1] * 4 + [0.02] * 3,
        torque_limit=[87] * 4 + [12] * 3,
        threshold=20.0,
    )
    return arm, joints, [list(arm.reference_configuration)], [[1, 0, 0], [0, 0, -1]]


ARMS = {"planar two-link": _planar, "UR5": _ur5, "Panda": _panda}


def main(figure_path: str | None) -> None:
    tables = {}
    print(
        f"machine load (1, 5, 15 min): {', '.join(f'{x:.1f}' for x in os.getloadavg())} on {os.cpu_count()} cores"
    )
    for name, build in ARMS.items():
        arm, joints, configurations, directions = build()
        start = time.perf_counter()
        table = validity_map(arm, joints, configurations, directions)
        elapsed = time.perf_counter() - start
        tables[name] = table
        simulations = len(table) // len(PLACEMENTS)
        failed = int((table["error"] != "").sum()) // len(PLACEMENTS)
        print(
            f"\n{name}: {len(configurations)} configuration(s) x {len(directions)} directions, {simulations} "
            f"simulations ({failed} refused or failed) in {elapsed:.1f} s ({1e3 * elapsed / simulations:.0f} ms each)"
        )
        worst = 100 * worst_difference(table)
        worst.columns = [f"{ratio:g} v*" for ratio in worst.columns]
        print("largest |I_sim / I_closed - 1| [%] (rows: detection, placement, k_contact / k_joint):")
        print(worst.round(1).to_string())
        print(f"within 5 %: {100 * table['valid'].mean():.0f} % of the cases")
    print(f"\nmachine load (1, 5, 15 min): {', '.join(f'{x:.1f}' for x in os.getloadavg())}")
    if figure_path:
        print(f"figure: {_figure(tables, figure_path)}")


def _figure(tables: dict[str, Any], path: str) -> Path:
    """One panel per arm: the largest |difference| per placement x stiffness ratio (rows) and v0 / v* (columns)."""
    figure, axes = new_figure(1, len(tables), figsize=(4.2 * len(tables), 3.2), constrained_layout=True)
    image = None
    for ax, (name, table) in zip(np.atleast_1d(axes), tables.items(), strict=True):
        worst = 100 * worst_difference(table)
        labels = [
            f"{detection}, {placement}, k_c/k_m={ratio:g}"
            if len(table["detection"].unique()) > 1
            else f"{placement}, k_c/k_m = {ratio:g}"
            for detection, placement, ratio in worst.index
        ]
        values = worst.to_numpy()
        image = ax.imshow(np.minimum(values, 50), cmap="RdYlGn_r", vmin=0, vmax=50, aspect="auto")
        for (row, column), value in np.ndenumerate(values):
            text = "fail" if not np.isfinite(value) else f"{value:.0f}" if value >= 10 else f"{value:.1f}"
            weight = "bold" if np.isfinite(value) and value <= 5 else "normal"
            ax.text(column, row, text, ha="center", va="center", fontsize=8, weight=weight)
        ax.set_xticks(range(values.shape[1]), [f"{r:g}" for r in worst.columns])
        ax.set_yticks(range(values.shape[0]), labels, fontsize=8)
        ax.set_xlabel("approach velocity v0 / v*")
        ax.set_title(name)
    if image is not None:
        figure.colorbar(image, ax=axes, label="largest |I_sim / I_closed - 1| [%], bold: <= 5 %")
    return save_figure(figure, path)


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else None)
