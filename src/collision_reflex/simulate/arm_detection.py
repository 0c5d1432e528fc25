"""How the simulated arm detects the contact: the schemes and the quantity each compares with its threshold.

Each scheme gives a force-equivalent along the wall normal ``n`` that is compared with the force threshold
``F_s`` [N], so that one threshold means the same contact force for all of them in the quasi-static limit:

- ``"force"``: a force sensor at the contact (the closed form's meaning of ``F_s``). Like the 1D simulator's,
  it measures its own deflection: the contact's elastic force ``k_c d`` (depth ``d``). The damper's part
  ``c_c d'`` is left out: in the Kelvin-Voigt contact it jumps at each touch, and the finger's small rebound
  off a stiff contact after the impact would trip a sensor at once at the re-touch (much of the sensing impulse
  then missing), an artefact of the contact model, not a force a sensor spring could follow. Against a soft,
  damped object the viscous part is a real share of the force
  (:func:`collision_reflex.simulate.validity.damper_share`): there the object is not the closed form's
  elastic one.
- ``"observer"``: the external-force estimate of a generalized-momentum observer from the joint torques, as
  collaborative arms use it: ``r = K (p(t) - p(0) - int (tau + C^T q' - g + r) dt)`` with ``p = M(q) q'`` and
  ``tau`` the joint spring torques; ``r' = K (tau_ext - r)``, a first-order lag of the external joint torque
  ``tau_ext = -J^T n f`` with the gain ``K`` [1/s]. The force is ``f_est = -(J^T n) . r / |J^T n|^2``.
- ``"spring_torque"``: the same projection of the joint spring torques themselves (an ideal joint-torque
  sensor without the inertia correction: it carries the links' inertial torques).
- ``"position"``: the contact point's position error along ``n`` against the path the motors command,
  ``e = n . (p(theta_ref(t)) - p(q))`` (the reference joint angles through the forward kinematics: the motors
  follow a straight line in joint space, which curves in space), times the closed form's lumped stiffness:
  ``F = k e`` (``F_s = k e_th``). (A first version took the straight line ``p0 + n v0 t`` as the command: on a
  soft object, whose deflection ``F_s / k_c`` is a sizeable share of the links, the curvature of the real
  command read as a tracking error.)
- ``"current"``: the residual motor torques, ``B theta'' + K_m (theta - q)`` (current times torque constant,
  output side) less the torque the arm's model expects for the motion, ``C(q, q') q'`` (Pinocchio's RNEA at
  zero acceleration: the reference runs at constant joint rates, and gravity is left out), as real drives
  threshold the current over the model's. Each joint has its own threshold torque; the first joint to reach
  it detects. The default thresholds are ``F_s |J(q0)^T n|`` (every joint reaches its own at the contact force
  ``F_s`` statically) on the joints that carry at least a tenth of the largest lever; the others are left
  out (their threshold would sit at the level of their links' inertial torques, and they would trip on the
  motion).

A detector may be sampled at ``sample_rate`` [Hz]: it detects at the first sample at or after the continuous
crossing (exact while the estimate rises monotonically across the threshold within a sample period).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from .arm_dynamics import ArmDynamics

DETECTIONS: tuple[str, ...] = ("spring_torque", "force", "observer", "position", "current")
"""The arm simulator's detection schemes (see the module docstring)."""


def detection_margin(dynamics: ArmDynamics, t: float, y: np.ndarray, threshold: float) -> float:
    """The detector's force-equivalent minus the threshold [N]: it detects where this crosses zero upward.

    Parameters
    ----------
    dynamics: the arm collision's dynamics (its ``detection`` names the scheme).
    t: time since the impact [s].
    y: the state ``(q, q', theta, theta', s, impulse)``.
    threshold: the force threshold ``F_s`` [N].
    """
    scheme = dynamics.detection
    qs = y[: dynamics.nv]
    if scheme == "force":
        return dynamics.contact_stiffness * max(dynamics.penetration(y), 0.0) - threshold
    if scheme == "spring_torque":
        return dynamics.force_estimate(t, y) - threshold
    if scheme == "observer":
        _, jac = dynamics.contact_kinematics(qs)
        lever = jac.T @ dynamics.normal
        return float(-(lever @ dynamics.observer_residual(y)) / (lever @ lever)) - threshold
    if scheme == "position":
        return dynamics.lumped_stiffness * dynamics.position_error(t, y) - threshold
    # "current": the first joint at its threshold torque, scaled to a force so that the margin is in N.
    ratio = np.abs(dynamics.residual_motor_torque(t, y)) / dynamics.current_threshold
    return threshold * (float(np.max(ratio)) - 1.0)


def next_sample(t: float, sample_rate: float | None) -> float:
    """The first detector sample at or after ``t`` [s] (``t`` itself for a continuous detector)."""
    if sample_rate is None:
        return t
    return math.ceil(t * sample_rate - 1e-9) / sample_rate
