"""Speed of the joint torques over a duty cycle (``cycle_torques``) on the UR5 and the Panda.

For each robot a cycle through four via configurations is resampled to exactly N samples (default 1,000);
three times are printed, each the median of R repeats (default 7), with the machine's load average:

1. ``cycle_torques``: one Pinocchio pass per sample (RNEA of links and payload, joint Jacobians and their
   time derivative), then the unit-mass torques of every motor assembled for all samples at once;
2. Pinocchio alone: the same two calls per sample, results stored into arrays (the floor for (1));
3. the straightforward way: one RNEA per sample for the links and payload plus one per motor on a model with
   a 1 kg point mass added at that motor (``nv + 1`` RNEA per sample).

Run: ``PYTHONPATH=src python benchmarks/arm_duty_cycle.py [--samples N] [--repeats R]``.
"""

from __future__ import annotations

import argparse
import os
import statistics
import time

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")  # a shared machine; the matrices are small
os.environ.setdefault("OMP_NUM_THREADS", "1")

import numpy as np
import pinocchio as pin

from collision_reflex.arm import Arm
from collision_reflex.arm.duty_cycle import DutyCycle, Payload
from collision_reflex.arm.dynamics import cycle_torques


def cycle_of(arm: Arm, samples: int) -> DutyCycle:
    """A pick-and-place-like cycle through four via configurations, exactly ``samples`` samples long."""
    lower, upper = arm.joint_limits()
    via = np.random.default_rng(0).uniform(lower / 2, upper / 2, size=(4, arm.nv))
    via = np.vstack([via, via[:1]])
    generated = DutyCycle.through_via_points(via, arm.joint_names, 1.5, 4.0, rate=1000.0, dwell=0.2)
    rate = (samples - 1) / generated.duration
    cycle = DutyCycle.through_via_points(
        via, arm.joint_names, 1.5, 4.0, rate=rate, dwell=0.2, payload=Payload(2.0)
    )
    keep = np.linspace(0, cycle.t.size - 1, samples).round().astype(int)  # drop the switching times
    return DutyCycle(
        cycle.joint_names, cycle.t[keep], cycle.q[keep], cycle.qd[keep], cycle.qdd[keep], cycle.payload
    )


def pinocchio_alone(arm: Arm, cycle: DutyCycle) -> None:
    model = arm.model.copy()
    data = model.createData()
    q = arm.configuration(cycle.q)
    n, nv = q.shape[0], model.nv
    tau, jac, rate = np.empty((n, nv)), np.empty((n, 6, nv)), np.empty((n, 6, nv))
    for s in range(n):
        tau[s] = pin.rnea(model, data, q[s], cycle.qd[s], cycle.qdd[s])
        pin.computeJointJacobiansTimeVariation(model, data, q[s], cycle.qd[s])
        jac[s], rate[s] = data.J, data.dJ


def straightforward(arm: Arm, cycle: DutyCycle) -> np.ndarray:
    base = arm.model.copy()
    base.armature = np.zeros(base.nv)
    models = [base]
    for joint in range(1, base.njoints):
        model = base.copy()
        unit = pin.Inertia(1.0, np.zeros(3), np.zeros((3, 3)))
        model.appendBodyToJoint(base.parents[joint], unit, base.jointPlacements[joint])
        models.append(model)
    datas = [model.createData() for model in models]
    q = arm.configuration(cycle.q)
    out = np.empty((len(models), q.shape[0], base.nv))
    for s in range(q.shape[0]):
        for i, (model, data) in enumerate(zip(models, datas, strict=True)):
            out[i, s] = pin.rnea(model, data, q[s], cycle.qd[s], cycle.qdd[s])
    return out[1:] - out[0]


def median_time(function, repeats: int) -> float:
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        function()
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, default=1000)
    parser.add_argument("--repeats", type=int, default=7)
    args = parser.parse_args()
    print(f"load average before: {' '.join(f'{x:.2f}' for x in os.getloadavg())} (2 cores)")
    for name in ("ur5", "panda"):
        arm = Arm.from_example_robot_data(name)
        cycle = cycle_of(arm, args.samples)
        torques = cycle_torques(arm, cycle)
        check = straightforward(arm, cycle)
        error = float(np.max(np.abs(check - torques.per_motor_mass)))
        ours = median_time(lambda arm=arm, cycle=cycle: cycle_torques(arm, cycle), args.repeats)
        floor = median_time(lambda arm=arm, cycle=cycle: pinocchio_alone(arm, cycle), args.repeats)
        naive = median_time(lambda arm=arm, cycle=cycle: straightforward(arm, cycle), args.repeats)
        print(
            f"{name:6s} {arm.nv} joints, {cycle.t.size} samples: cycle_torques {1e3 * ours:.1f} ms, "
            f"Pinocchio alone {1e3 * floor:.1f} ms ({ours / floor:.2f}x), "
            f"nv+1 RNEA per sample {1e3 * naive:.1f} ms ({naive / ours:.1f}x slower); "
            f"unit-mass torques agree to {error:.1e} N m/kg"
        )
    print(f"load average after: {' '.join(f'{x:.2f}' for x in os.getloadavg())}")


if __name__ == "__main__":
    main()
