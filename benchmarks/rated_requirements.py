"""How do a run's required joint torques compare with the real robot's, and is its design buildable?

    PYTHONPATH=src python benchmarks/rated_requirements.py RUN_FOLDER ROBOT

Reads the run's ``designs.json`` and prints, per joint of the recommended design, the required peak torque
(safety factor included), what sets it, the real robot's joint torque and their ratio; the actuator mass; the
catalogue design's parts, or why there is none; the span of each objective over the front. ROBOT is ``ur5`` or
``panda``: the real joint torques are Universal Robots' ROS description (ur5 joint_limits.yaml: 150, 150, 150,
28, 28, 28 N m) and Franka's interface specifications (tau_j_max: 87 N m on joints 1-4, 12 N m on 5-7).
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

REAL_TORQUES = {"ur5": [150, 150, 150, 28, 28, 28], "panda": [87, 87, 87, 87, 12, 12, 12]}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("run", type=Path)
    parser.add_argument("robot", choices=sorted(REAL_TORQUES))
    args = parser.parse_args()
    results = json.loads((args.run / "designs.json").read_text())
    design = results["recommended"]
    print("| joint | required [N m] | set by | real [N m] | required / real | module |")
    print("|---|---|---|---|---|---|")
    for joint, real in zip(design["joints"], REAL_TORQUES[args.robot], strict=True):
        module = "yes" if joint.get("module") else "no"
        print(
            f"| {joint['joint']} | {joint['required_torque']:.1f} | {joint['required_by']} | {real} | "
            f"{joint['required_torque'] / real:.2f} | {module} |"
        )
    mass = sum(j["motor_mass"] + (j.get("gearbox_mass") or 0.0) for j in design["joints"])
    print(
        f"\nactuator mass {design['objectives']['actuator_mass']:.2f} kg (motors and gearboxes {mass:.2f} kg)"
    )
    catalogue = results.get("catalogue") or {}
    if catalogue.get("design"):
        print(f"catalogue design ({catalogue['method']}):")
        for joint in catalogue["joints"]:
            print(f"  {joint['joint']}: {joint['part']}")
        changes = catalogue["relative_difference"]
        print(
            "  against the continuous design: "
            + ", ".join(f"{k} {100 * v:+.1f} %" for k, v in changes.items())
        )
    else:
        print("no catalogue design: " + "; ".join(catalogue.get("warnings", ["not snapped"])))
    points = results["pareto"]["points"]
    for name in results["pareto"]["objectives"]:
        values = [p["objectives"][name] for p in points]
        if values and min(values) > 0:
            print(
                f"front span in {name}: {100 * (max(values) / min(values) - 1):.1f} % over {len(values)} designs"
            )


if __name__ == "__main__":
    main()
