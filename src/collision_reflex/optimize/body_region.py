"""The approach held within a human body region's permissible transient contact force at every sample.

ISO/TS 15066 (Annex A) permits the transient force ``F_T`` against a body region of stiffness ``k_c`` and
effective mass ``m_H``; a robot mass ``m_R`` meeting it at ``v`` reaches ``v sqrt(mu k_c)``
(:mod:`collision_reflex.model.contact`), so the design's approach velocity must satisfy, per sample,
``v0^2 k_c mu_s <= F_T^2`` with ``mu_s = m_s m_H / (m_s + m_H)``. The robot mass ``m_s`` is the coupled one
(every rotor on the links): exact for a region not 100 times stiffer than the joints along the direction, an
upper bound otherwise. As the finger mass, it is ``min y^T (M_f + diag(N^2 J)) y`` over ``y`` with ``w^T y = 1``:
each sample has its own coupled-mass direction ``y_s`` (the finger mass's ``x_s`` minimises another form), and at
any ``y_s`` the form is at least the true mass, so a design the rows admit is admitted by the exact masses too.

Rows are in logarithms, ``2 log v0 + log(k_c / F_T^2) + log m_s - log(1 + m_s / m_H) <= 0``, which keeps them
O(1) over the masses' orders of magnitude. A sample whose speed cap lies below the slowest approach of the
solve is outside every design's contact domain: its row is relaxed as the worst case's is.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import casadi as ca
import numpy as np

from .._backend import solve_vector
from ..model.contact import BodyRegion, permissible_speed
from ..model.effective import finger_mass_matrix
from .constraints import ConstraintList
from .objectives import RELAXED_ROW
from .samples import SPEED_CAP_TOLERANCE, ContactSamples, kinematic_term

if TYPE_CHECKING:
    from .design import Design


def add_body_region_constraints(
    g: ConstraintList,
    region: BodyRegion,
    approach_velocity: ca.MX,
    coupled_masses: ca.MX,
    normalisation: ca.MX,
    samples: ContactSamples,
    slowest: ca.MX | float,
) -> None:
    """Add two rows per sample: ``w^T y = 1``, and the approach within ``region``'s permissible speed.

    ``coupled_masses`` (1 x n_samples) [kg] are ``y^T (M_f + diag(N^2 J)) y`` and ``normalisation`` ``w^T y``
    at the samples' coupled-mass directions ``y`` (see the module docstring); ``slowest`` [m/s] the least
    approach velocity the solve allows.
    """
    g.add(ca.transpose(normalisation), 1.0, 1.0, [f"w^T y = 1 at sample {s}" for s in range(samples.size)])
    assert region.transient_force is not None  # checked where the constraint is set
    log_mass = ca.log(coupled_masses)
    if math.isfinite(region.mass):
        log_mass = log_mass - ca.log1p(coupled_masses / region.mass)
    rows = ca.transpose(
        2 * ca.log(approach_velocity) + math.log(region.stiffness / region.transient_force**2) + log_mass
    )
    caps = np.asarray(samples.speed_cap, dtype=float)
    finite = np.isfinite(caps)
    if np.any(finite):
        capped = ca.DM(np.where(finite, caps, 0.0))
        rows = rows - RELAXED_ROW * ca.DM(finite.astype(float)) * (
            slowest * (1 - SPEED_CAP_TOLERANCE) > capped
        )
    g.add(
        rows,
        -np.inf,
        0.0,
        [
            f"approach within the permissible speed of the {region.name} at sample {s}"
            for s in range(samples.size)
        ],
    )


def coupled_mass_matrix(
    mass_matrix: np.ndarray, motor_mass_influence: np.ndarray, design: Design
) -> np.ndarray:
    """``M_f + diag(N^2 J)`` [kg m^2] per configuration: the links, the actuator masses they carry and the rotors.

    ``mass_matrix`` (n, nv, nv) and ``motor_mass_influence`` (n, nv, nv, nv): the configurations' kinematic terms.
    """
    return np.asarray(
        finger_mass_matrix(mass_matrix, motor_mass_influence, design.actuator_mass, design.reflected_inertia)
    )


def region_speeds(samples: ContactSamples, design: Design, region: BodyRegion) -> np.ndarray:
    """The permissible approach speed [m/s] against ``region`` at each sample, (n_samples,), as the rows take it.

    The robot mass is the exact coupled one, ``1 / (w^T (M_f + diag(N^2 J))^-1 w)`` (the NumPy path); the NLP's
    rows bound it from above, so a design they admit has these speeds at least its approach velocity.
    """
    index = samples.config_index
    matrix = coupled_mass_matrix(
        samples.kinematics.mass_matrix[index], kinematic_term(samples, "motor_mass_influence")[index], design
    )
    w = samples.joint_moment_arms
    mass = 1 / np.einsum("si,si->s", w, solve_vector(matrix, w))
    assert region.transient_force is not None
    return np.asarray(permissible_speed(region.transient_force, mass, region.stiffness, region.mass))


def region_violations(
    samples: ContactSamples, design: Design, region: BodyRegion, slowest: float, tolerance: float
) -> np.ndarray:
    """Which samples' rows ``design`` violates by more than the relative ``tolerance``, (n_samples,) bool.

    Only samples whose speed cap reaches ``slowest`` [m/s] (the least approach velocity of the solve) have rows.
    """
    having_rows = np.asarray(samples.speed_cap) >= slowest * (1 - SPEED_CAP_TOLERANCE)
    return having_rows & (design.approach_velocity > region_speeds(samples, design, region) * (1 + tolerance))
