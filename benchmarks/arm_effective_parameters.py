"""Speed of the batched effective collision parameters and impulses on the Panda arm.

Prints three times for N configurations x D directions (default 10,000 x 64):

1. a straightforward loop over every (q, u) pair: Pinocchio's mass matrix and frame Jacobian, then NumPy
   (matrix inverses, the formulas of the paper's "Collision Reflex in Higher Dimensions") and the 1D impulse per
   pair. Timed on a subset of the
   configurations and extrapolated linearly (each pair costs the same), as the output says;
2. the batched path: ``Arm.kinematics(q, full=False)`` (Pinocchio's mass matrix and contact Jacobian once per
   configuration; the gravity and motor-mass terms, which only the optimiser needs, are timed separately for
   reference) then ``effective_parameters`` and ``collision_impulses`` over the whole grid;
3. Pinocchio alone: the mass matrix and contact Jacobian of every configuration, stored into arrays.

Targets: (1) / (2) >= 50 and (2) / (3) <= 3. Run:
``PYTHONPATH=src python benchmarks/arm_effective_parameters.py [--configs N] [--directions D]``.
"""

from __future__ import annotations

import argparse
import os
import time

# One BLAS thread: the machine is shared and the per-configuration matrices are small, where threads only
# contend (set the variable before starting to override).
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")

import numpy as np
import pinocchio as pin

from collision_reflex.arm import Arm, JointParameters, collision_impulses, effective_parameters
from collision_reflex.arm.directions import sphere_directions
from collision_reflex.model import impulse

# Panda-like actuation: reflected inertia [kg m^2], torque limits (the URDF's) [N m], joint stiffness
# [N m/rad]; a 5 N force threshold and 0.25 m/s approach.
JOINTS = JointParameters(
    reflected_inertia=np.array([0.6, 0.6, 0.5, 0.5, 0.2, 0.2, 0.1]),
    torque_limit=np.array([87.0, 87.0, 87.0, 87.0, 12.0, 12.0, 12.0]),
    stiffness=np.array([900.0, 900.0, 700.0, 700.0, 300.0, 300.0, 200.0]),
    mechanical_stiffness=np.array([5e4, 5e4, 4e4, 4e4, 2e4, 2e4, 1e4]),
    motor_mass=np.zeros(7),
)
THRESHOLD, VELOCITY = 5.0, 0.25


def loop_per_pair(arm: Arm, q: np.ndarray, directions: np.ndarray) -> np.ndarray:
    """The straightforward way: everything recomputed for each (q, u) pair."""
    model = arm.model.copy()
    model.armature = np.zeros(arm.nv)
    data = model.createData()
    frame = model.getFrameId(arm.contact_frame)
    p = JOINTS
    out = np.empty((q.shape[0], directions.shape[0]))
    for s in range(q.shape[0]):
        for d, u in enumerate(directions):
            mass = pin.crba(model, data, q[s])
            jac = pin.computeFrameJacobian(model, data, q[s], frame, pin.LOCAL_WORLD_ALIGNED)[:3]
            moment = jac.T @ u
            m_f = 1 / (moment @ np.linalg.inv(mass) @ moment)
            m_r = 1 / (moment @ np.linalg.inv(np.diag(p.reflected_inertia)) @ moment)
            k = 1 / (moment @ np.linalg.inv(np.diag(p.stiffness)) @ moment)
            k_m = 1 / (moment @ np.linalg.inv(np.diag(p.mechanical_stiffness)) @ moment)
            f_a = np.min(p.torque_limit / np.abs(moment))
            out[s, d] = impulse.total_impulse(m_f, k, k_m, THRESHOLD, f_a / m_r, VELOCITY)
            impulse.optimal_velocity(m_f, k, THRESHOLD)
    return out


def batched(arm: Arm, q: np.ndarray, directions: np.ndarray) -> np.ndarray:
    # Only the mass matrices and contact Jacobians: the motor-mass and gravity terms serve the optimiser.
    samples = arm.kinematics(q, full=False)
    params = effective_parameters(
        samples,
        directions,
        JOINTS.reflected_inertia,
        JOINTS.stiffness,
        JOINTS.mechanical_stiffness,
        JOINTS.torque_limit,
    )
    return collision_impulses(params, VELOCITY, THRESHOLD).total


def pinocchio_alone(arm: Arm, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    model = arm.model.copy()
    data = model.createData()
    frame = model.getFrameId(arm.contact_frame)
    mass = np.empty((q.shape[0], arm.nv, arm.nv))
    jac = np.empty((q.shape[0], 6, arm.nv))
    for s in range(q.shape[0]):
        mass[s] = pin.crba(model, data, q[s])
        jac[s] = pin.computeFrameJacobian(model, data, q[s], frame, pin.LOCAL_WORLD_ALIGNED)
    return mass, jac


def best_of(repeats: int, function, *args):
    times, result = [], None
    for _ in range(repeats):
        start = time.perf_counter()
        result = function(*args)
        times.append(time.perf_counter() - start)
    return min(times), result


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--configs", type=int, default=10_000)
    parser.add_argument("--directions", type=int, default=64)
    parser.add_argument("--loop-configs", type=int, default=100, help="configurations timed in the loop")
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()

    arm = Arm.from_example_robot_data("panda", actuators=JOINTS)
    q = arm.sample_configurations(args.configs, np.random.default_rng(0))
    directions = sphere_directions(args.directions)
    pairs = args.configs * args.directions

    subset = q[: args.loop_configs]
    with np.errstate(divide="ignore"):  # a joint with zero moment arm gives tau / 0 = inf, as it should
        loop_time, loop_result = best_of(1, loop_per_pair, arm, subset, directions)
    loop_total = loop_time * args.configs / subset.shape[0]
    # Interleave the repeats so that both see the same load on a shared machine; keep each one's best.
    batch_time = pin_time = full_time = np.inf
    for _ in range(args.repeats):
        elapsed, batch_result = best_of(1, batched, arm, q, directions)
        batch_time = min(batch_time, elapsed)
        pin_time = min(pin_time, best_of(1, pinocchio_alone, arm, q)[0])
        full_time = min(full_time, best_of(1, lambda: arm.kinematics(q))[0])
    # The two paths must agree before their times mean anything (rounding-level differences only).
    np.testing.assert_allclose(batch_result[: subset.shape[0]], loop_result, rtol=1e-9)

    print(f"Panda, {args.configs} configurations x {args.directions} directions = {pairs} (q, u) pairs")
    print(
        f"(1) per-(q, u) loop, Pinocchio + NumPy : {loop_total:9.3f} s  "
        f"(extrapolated from {subset.shape[0]} configurations, {loop_time:.3f} s)"
    )
    print(f"(2) batched (kinematics + parameters + impulses): {batch_time:9.3f} s  (best of {args.repeats})")
    print(f"(3) Pinocchio alone, M(q) and J(q)        : {pin_time:9.3f} s  (best of {args.repeats})")
    print(f"    for reference, Arm.kinematics(q) with gravity and motor-mass terms: {full_time:.3f} s")
    print(f"loop / batched  = {loop_total / batch_time:8.1f}   (target >= 50)")
    print(f"batched / Pinocchio alone = {batch_time / pin_time:6.2f}   (target <= 3)")


if __name__ == "__main__":
    main()
