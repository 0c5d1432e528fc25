"""Where holding still is hardest: each joint's worst static pose within the joint limits.

The static hold (the arm, its actuators and its payload held still) must hold wherever the arm can go, not only
at the sampled configurations; as the worst-case impulse is searched beyond its samples, the gravity torque of
each joint is maximised over the joint-limit box, and the static-hold rows gain those poses.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from .robot import Arm
    from .samples import ArmSamples, GravityTerms

HOLD_CANDIDATES = 2048
"""Configurations drawn uniformly within the joint limits to start each joint's search from."""
HOLD_STARTS = 3
"""Local searches per joint, from the candidates where its gravity torque is largest."""


def hold_torques(
    kinematics: ArmSamples | GravityTerms, payload: float, actuator_mass: np.ndarray
) -> np.ndarray:
    """Joint torques [N m] that hold the arm still, (n, nv): structure, actuators [kg] and payload [kg]."""
    assert kinematics.gravity is not None and kinematics.motor_gravity is not None
    assert kinematics.contact_gravity is not None
    motors = np.einsum("sij,i->sj", kinematics.motor_gravity, np.asarray(actuator_mass, dtype=float))
    return kinematics.gravity + payload * kinematics.contact_gravity + motors


def worst_hold_poses(
    arm: Arm, payload: float, actuator_mass: np.ndarray, rng: np.random.Generator
) -> np.ndarray:
    """Per joint the configuration within the joint limits that needs the most holding torque of it, (nv, nq).

    For actuators of ``actuator_mass`` [kg] and the ``payload`` [kg] at the contact point: the largest ``|tau_j|``
    of :data:`HOLD_CANDIDATES` uniform draws, refined by a bounded local search (L-BFGS-B on the joint
    coordinates) from the :data:`HOLD_STARTS` best. The torque is affine in the actuator masses, so a pose found
    for these masses is a row of the requirement for every design; the design is checked on fresh
    configurations besides.
    """
    from scipy.optimize import minimize

    lower, upper = arm.joint_limits()
    candidates = arm.sample_configurations(HOLD_CANDIDATES, rng)
    torques = np.abs(hold_torques(arm.kinematics(candidates), payload, actuator_mass))
    poses = []
    for j in range(arm.nv):

        def negative(angles: np.ndarray, j: int = j) -> float:
            q = arm.configuration(np.clip(angles, lower, upper)[None])
            return -float(abs(hold_torques(arm.gravity_terms(q), payload, actuator_mass)[0, j]))

        starts = np.argsort(-torques[:, j], kind="stable")[:HOLD_STARTS]
        best_angles, best = arm.joint_coordinates(candidates[starts[0]][None])[0], -np.inf
        for start in starts:
            found = minimize(
                negative,
                arm.joint_coordinates(candidates[start][None])[0],
                method="L-BFGS-B",
                bounds=list(zip(lower, upper, strict=True)),
                options={"maxiter": 50},
            )
            if -found.fun > best:
                best_angles, best = found.x, -found.fun
        poses.append(arm.configuration(np.clip(best_angles, lower, upper)[None])[0])
    return np.array(poses)
