"""Where the arm closed form holds: the validity map of the planar arm, the UR5 and the Panda.

For each arm, a few configurations x directions x v0 in {0.1, 0.3, 1, 3, 10} v* x a compliant contact (0.1 of
the joints' stiffness along u: a stiff transmission hitting a soft object), a stiff one (10 times: compliant
joints hitting a hard object) and a rigid one (1000 times, the study's closed form) x the ideal and the
impedance drive x every detection scheme, it simulates the collision in the time domain
(:func:`collision_reflex.simulate.simulate_arm_collision`) and compares it with the arm closed form for both
placements of the reflected inertia and both reaction models; it prints the largest |I_sim / I_closed - 1|
and the share of cases within 5 %, the contact damper's share of the force, the failures, the timings (wall
and CPU) and the machine's load. The arms run in parallel processes.

Run: ``PYTHONPATH=src python benchmarks/validity_map.py [FIGURE.png]`` (1,200 simulations: 501 s of CPU
time, measured at a load of 2.5-8 on two cores, 10 minutes of wall time there). The joint parameters of the UR5 and the Panda are
representative harmonic-drive joints, not the makers' data.
"""

from __future__ import annotations

import os
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path
from typing import Any

import numpy as np

import collision_reflex as cr
from collision_reflex.plots import new_figure, save_figure
from collision_reflex.simulate.design_closed_form import REACTION_MODELS, JointDesign
from collision_reflex.simulate.validity import TOLERANCE, validity_map, worst_difference
from collision_reflex.vocabulary import CONTROLLED_DRIVES, REFLECTED_INERTIA_PLACEMENTS

URDF = Path(__file__).resolve().parents[1] / "designs" / "planar_two_link.urdf"


def _planar() -> tuple[Any, JointDesign, list[list[float]], list[list[float]]]:
    arm = cr.Arm.from_urdf(URDF, "tip")
    joints = JointDesign(
        mechanical_stiffness=50.0,
        reflected_inertia=2.2e-3,
        torque_limit=1.3,
        threshold=3.0,
        software_stiffness=SOFTWARE_STIFFNESS_RATIO * 50.0,
    )
    directions = [[np.cos(angle), np.sin(angle)] for angle in (0.0, 2.0)]
    return arm, joints, [[0.3, 1.2], [-0.5, 2.0]], directions


def _ur5() -> tuple[Any, JointDesign, list[list[float]], list[list[float]]]:
    arm = cr.Arm.from_example_robot_data("ur5")
    joints = JointDesign(
        mechanical_stiffness=[5000, 5000, 3000, 800, 800, 800],
        reflected_inertia=[0.2, 0.2, 0.1, 0.03, 0.03, 0.03],
        torque_limit=[150, 150, 150, 28, 28, 28],
        threshold=20.0,
        software_stiffness=SOFTWARE_STIFFNESS_RATIO * np.array([5000, 5000, 3000, 800, 800, 800]),
    )
    return arm, joints, [[0.0, -1.2, 1.5, -1.9, -1.57, 0.0]], [[1, 0, 0], [0, 0, -1]]


def _panda() -> tuple[Any, JointDesign, list[list[float]], list[list[float]]]:
    arm = cr.Arm.from_example_robot_data("panda")
    joints = JointDesign(
        mechanical_stiffness=[4000] * 4 + [1000] * 3,
        reflected_inertia=[0.1] * 4 + [0.02] * 3,
        torque_limit=[87] * 4 + [12] * 3,
        threshold=20.0,
        software_stiffness=SOFTWARE_STIFFNESS_RATIO * np.array([4000] * 4 + [1000] * 3),
    )
    return arm, joints, [list(arm.reference_configuration)], [[1, 0, 0], [0, 0, -1]]


# Software (controller) stiffness over the joint springs: an estimate of a stiff position loop, finite so that
# the impedance drive can be simulated; the ideal drive realises the same k_s as an ideal admittance.
SOFTWARE_STIFFNESS_RATIO = 4.0
# The two regimes and the study's: an object 1000 times stiffer than the joints (a rigid one).
STIFFNESS_RATIOS = (0.1, 10.0, 1000.0)
ARMS = {"planar two-link": _planar, "UR5": _ur5, "Panda": _panda}


def _run(name: str) -> tuple[Any, float, float, int, int]:
    """One arm's map: the table, its wall and CPU time [s], and its configurations and directions."""
    arm, joints, configurations, directions = ARMS[name]()
    start, cpu = time.perf_counter(), time.process_time()
    table = validity_map(
        arm, joints, configurations, directions, stiffness_ratios=STIFFNESS_RATIOS, drives=CONTROLLED_DRIVES
    )
    return (
        table,
        time.perf_counter() - start,
        time.process_time() - cpu,
        len(configurations),
        len(directions),
    )


def main(figure_path: str | None) -> None:
    print(
        f"machine load (1, 5, 15 min): {', '.join(f'{x:.1f}' for x in os.getloadavg())} on {os.cpu_count()} cores"
    )
    # The arms are independent: one process each.
    with ProcessPoolExecutor(max_workers=len(ARMS)) as pool:
        runs = dict(zip(ARMS, pool.map(_run, ARMS), strict=True))
    tables = {}
    for name, (table, elapsed, cpu, n_configurations, n_directions) in runs.items():
        tables[name] = table
        per_case = len(REFLECTED_INERTIA_PLACEMENTS) * len(REACTION_MODELS)
        simulations = len(table) // per_case
        failed = int((table["error"] != "").sum()) // per_case
        seconds = table["seconds"].to_numpy()[::per_case]
        print(
            f"\n{name}: {n_configurations} configuration(s) x {n_directions} directions, {simulations} "
            f"simulations ({failed} refused or failed) in {elapsed:.1f} s wall, {cpu:.1f} s CPU "
            f"(median {1e3 * float(np.median(seconds)):.0f} ms wall each)"
        )
        for message, count in table["error"][table["error"] != ""].value_counts().items():
            print(f"  {count // per_case} x {message[:150]}")
        worst = 100 * worst_difference(table)
        worst.columns = [f"{ratio:g} v*" for ratio in worst.columns]
        print(
            "largest |I_sim / I_closed - 1| [%] "
            "(rows: detection, drive, reaction model, placement, k_contact / k_joint, restitution):"
        )
        print(worst.round(1).to_string())
        print(f"within 5 %: {100 * table['valid'].mean():.0f} % of the cases")
        damped = table.groupby(["stiffness_ratio", "velocity_ratio"])["damper_share"].max().unstack()
        print("the contact's viscous share of the force in the sensing ramp, largest [% of F_s]:")
        print((100 * damped).round(1).to_string())
    print(f"\nmachine load (1, 5, 15 min): {', '.join(f'{x:.1f}' for x in os.getloadavg())}")
    if figure_path:
        print(f"figure: {_figure(tables, figure_path)}")


FIGURE_MODEL = "sprung"
"""The reaction model drawn (the printed tables have both)."""


def _figure(tables: dict[str, Any], path: str) -> Path:
    """A panel per detection (rows) and arm (columns): the largest |difference| per drive x placement x
    stiffness ratio (rows) and v0 / v* (columns), the sprung reaction; cells whose contact damper carries
    more than the tolerance of the force in the sensing ramp are marked (the object is not the closed form's)."""
    detections = list(next(iter(tables.values()))["detection"].unique())
    shape = (len(detections), len(tables))
    figure, axes = new_figure(*shape, figsize=(4.6 * shape[1], 3.3 * shape[0]), constrained_layout=True)
    image = None
    for row, detection in enumerate(detections):
        for column, (name, table) in enumerate(tables.items()):
            ax = np.atleast_2d(axes)[row, column]
            chosen = table[(table["detection"] == detection) & (table["reaction_model"] == FIGURE_MODEL)]
            worst = 100 * worst_difference(chosen).droplevel(["detection", "reaction_model"])
            damped = chosen.pivot_table(
                index=["drive", "placement", "stiffness_ratio", "restitution"],
                columns="velocity_ratio",
                values="damper_share",
                aggfunc="max",
            ).reindex(index=worst.index, columns=worst.columns)
            values = worst.to_numpy()
            image = ax.imshow(np.minimum(values, 50), cmap="RdYlGn_r", vmin=0, vmax=50, aspect="auto")
            for (i, j), value in np.ndenumerate(values):
                text = "fail" if not np.isfinite(value) else f"{value:.0f}" if value >= 10 else f"{value:.1f}"
                if damped.to_numpy()[i, j] > TOLERANCE:
                    text += "*"
                weight = "bold" if np.isfinite(value) and value <= 100 * TOLERANCE else "normal"
                ax.text(j, i, text, ha="center", va="center", fontsize=6, weight=weight)
            ax.set_xticks(range(values.shape[1]), [f"{r:g}" for r in worst.columns])
            labels = [f"{drive}, {placement}, {ratio:g}" for drive, placement, ratio, _ in worst.index]
            ax.set_yticks(range(values.shape[0]), labels if column == 0 else [], fontsize=6)
            ax.set_xlabel("approach velocity v0 / v*", fontsize=7)
            ax.set_title(f"{name}, detection: {detection}", fontsize=8)
    np.atleast_2d(axes)[0, 0].set_ylabel("drive, placement, k_contact / k_joint", fontsize=7)
    if image is not None:
        figure.colorbar(
            image,
            ax=axes,
            label=f"largest |I_sim / I_closed - 1| [%] ({FIGURE_MODEL} reaction); bold: <= 5 %; "
            "*: contact damper > 5 % of the force",
            shrink=0.4,
        )
    return save_figure(figure, path, dpi=100)


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else None)
