"""Effective 1D collision parameters of an arm along a contact direction ``u``, written once.

The formulas are those of the paper's "Collision Reflex in Higher Dimensions".

The formulas are plain arithmetic on the functions of :mod:`collision_reflex._backend`, so they serve the NumPy
path (:func:`collision_reflex.arm.effective_parameters`, batched over configurations and directions) and the
CasADi problem (:mod:`collision_reflex.optimize.problem`, symbolic in the design) alike.

Shapes: ``jacobian`` is the contact Jacobian ``J`` (..., m, nv) [m/rad] -- for one direction it may be the row
``u^T J`` (1, nv), i.e. the moment arms ``w = J^T u`` as a row -- and task matrices are (..., m, m); joint
vectors are (nv,) or, for NumPy, (..., nv). The effective quantities along ``u`` are the reciprocals of the
quadratic forms ``u^T G u`` of these task matrices:

- finger mass ``m_f = 1 / (u^T J M_f^-1 J^T u)`` (``eq:eff_mf``), ``M_f`` the structure's mass matrix with the
  motor masses, and the reflected inertia too where it acts in the finger (:func:`finger_mass_matrix`);
- robot mass ``m_r = 1 / (u^T J M_jj^-1 J^T u)``, ``M_jj = diag(N^2 J_m)``;
- stiffnesses ``k``, ``k_m = 1 / (u^T J K^-1 J^T u)`` (the compliance form of ``eq:eff_k``);
- reaction force ``F_a = min_i tau_i / |w_i|`` and acceleration ``a = F_a / m_r`` (``eq:eff_a``).

Numeric arguments are checked at the edge (:mod:`collision_reflex._validate`): real, finite (or as each
function says), of the documented shapes; CasADi values pass unchecked, as the optimiser bounds them instead.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from .. import _validate
from .._backend import (
    absolute,
    diagonal_matrix,
    divide_columns,
    dot,
    is_symbolic,
    largest,
    matmul,
    quadratic_form,
    solve,
    solve_vector,
    transpose,
    weighted_sum,
)
from ..errors import InvalidParameter


def reflected_inertia(gear_ratio: Any, rotor_inertia: Any) -> Any:
    """Rotor inertia seen at the joint through the transmission, ``N^2 J_m`` [kg m^2].

    Parameters
    ----------
    gear_ratio: transmission ratio ``N`` [-].
    rotor_inertia: the motor's rotor inertia ``J_m`` [kg m^2].
    """
    gear_ratio = _validate.positive("gear_ratio", gear_ratio)
    rotor_inertia = _validate.non_negative("rotor_inertia", rotor_inertia)
    with _validate.combining(gear_ratio=gear_ratio, rotor_inertia=rotor_inertia):
        return gear_ratio**2 * rotor_inertia


def finger_inertia(joint_reflected_inertia: Any, in_finger: Any) -> Any:
    """The part of the reflected inertia [kg m^2] that acts rigidly on the link side during the impact.

    ``in_finger``: per joint (or for all) 1 (or True) where the rotor takes part in the impact (a stiff transmission with
    the compliance at the contact: ``reflected_inertia_in: finger``), 0 where it sits behind the joint spring
    (the paper's arm model: ``robot``).
    """
    joint_reflected_inertia = _validate.non_negative("joint_reflected_inertia", joint_reflected_inertia)
    if isinstance(in_finger, bool) or (isinstance(in_finger, np.ndarray) and in_finger.dtype == bool):
        in_finger = np.asarray(in_finger, dtype=float)  # flags: True is 1
    in_finger = _validate.unit_interval("in_finger", in_finger)
    with _validate.combining(joint_reflected_inertia=joint_reflected_inertia, in_finger=in_finger):
        return joint_reflected_inertia * in_finger


def finger_mass_matrix(
    structure_mass_matrix: Any,
    motor_mass_influence: Any = None,
    motor_mass: Any = None,
    joint_finger_inertia: Any = None,
) -> Any:
    """``M_f = M_bb0 + sum_i m_i A_i + diag(J_f)``: the joint-space mass matrix the impact sees.

    Parameters
    ----------
    structure_mass_matrix: ``M_bb0`` of the links [kg m^2], (..., nv, nv).
    motor_mass_influence: ``A_i``, the mass matrix per kilogram of motor ``i`` at its joint [m^2], (..., nv, nv,
        nv) for NumPy (axis -3 is ``i``), a sequence of nv matrices for CasADi; None without motor masses.
    motor_mass: motor mass per joint ``m_i`` [kg], (nv,); None for none.
    joint_finger_inertia: inertia per joint acting on the finger [kg m^2], (nv,) (:func:`finger_inertia`); None
        for none.
    """
    matrix = _validate.arrays("structure_mass_matrix", structure_mass_matrix, ndim=2, square=True)
    with _validate.combining(
        structure_mass_matrix=matrix, motor_mass=motor_mass, joint_finger_inertia=joint_finger_inertia
    ):
        if motor_mass is not None:
            influence = _validate.arrays("motor_mass_influence", motor_mass_influence, ndim=3, square=True)
            matrix = matrix + weighted_sum(_validate.non_negative("motor_mass", motor_mass), influence)
        if joint_finger_inertia is not None:
            inertia = _validate.arrays("joint_finger_inertia", joint_finger_inertia)
            matrix = matrix + diagonal_matrix(_validate.non_negative("joint_finger_inertia", inertia))
    return matrix


def task_inverse_inertia(jacobian: Any, mass_matrix: Any) -> Any:
    """``J M^-1 J^T`` [1/kg]: the inverse task-space inertia (the ellipsoid of gyration).

    It is that of a joint-space mass matrix ``M`` [kg m^2] (..., nv, nv) seen through the contact Jacobian
    ``J`` [m/rad] (..., m, nv).
    """
    jacobian = _validate.arrays("jacobian", jacobian, ndim=2)
    mass_matrix = _validate.arrays("mass_matrix", mass_matrix, ndim=2, square=True)
    with _validate.combining(jacobian=jacobian, mass_matrix=mass_matrix):
        return matmul(jacobian, solve(mass_matrix, transpose(jacobian)))


def task_compliance(jacobian: Any, joint_values: Any) -> Any:
    """``J X^-1 J^T`` for a diagonal joint-space ``X = diag(joint_values)``.

    A task compliance [m/N] from joint stiffnesses [N m/rad], or an inverse task inertia [1/kg] from joint
    inertias [kg m^2]. Infinite joint values contribute nothing.
    """
    jacobian = _validate.arrays("jacobian", jacobian, ndim=2)
    joint_values = _validate.positive("joint_values", joint_values, allow_inf=True)
    with _validate.combining(jacobian=jacobian, joint_values=joint_values):
        return matmul(divide_columns(jacobian, joint_values), transpose(jacobian))


def torque_fractions(moment_arms: Any, torque_limit: Any) -> Any:
    """``w_i / tau_i`` [1/N]: the fraction of each joint's torque a unit contact force along ``u`` takes.

    Parameters
    ----------
    moment_arms: ``w = J^T u`` [m/rad], joints on the last axis (NumPy) or a CasADi vector. The map is linear,
        so applied to the Jacobian ``J`` (joints on its last axis) it gives ``J diag(1/tau)``, whose product with
        ``u`` is the fractions along ``u``.
    torque_limit: largest output torque per joint ``tau_i`` [N m] (or a joint torque threshold), broadcast
        against ``moment_arms``.
    """
    moment_arms = _validate.arrays("moment_arms", moment_arms)
    torque_limit = _validate.positive("torque_limit", torque_limit, allow_inf=True)
    with _validate.combining(moment_arms=moment_arms, torque_limit=torque_limit):
        return moment_arms / torque_limit


def reaction_compliance(fractions: Any, joint_axis: int = -1) -> Any:
    """``1 / F_a = max_i |w_i| / tau_i`` [1/N] from the :func:`torque_fractions`.

    The inverse of the largest contact force the joints can push back with along ``-u`` before the first one
    saturates (with threshold torques instead of limits: the inverse of the contact force at which the first
    joint reaches its threshold).

    ``joint_axis`` is the axis of ``fractions`` that holds the joints (NumPy; -2 lets a batch keep its
    directions on the last, contiguous axis).
    """
    fractions = _validate.arrays("fractions", fractions)
    if is_symbolic(fractions):
        return largest(absolute(fractions))
    if (
        not isinstance(joint_axis, int)
        or isinstance(joint_axis, bool)
        or not -fractions.ndim <= joint_axis < fractions.ndim
    ):
        raise InvalidParameter(
            "joint_axis",
            joint_axis,
            f"an axis of fractions, an integer in [{-fractions.ndim}, {fractions.ndim})",
        )
    if fractions.shape[joint_axis] == 0:
        raise InvalidParameter("fractions", fractions, "at least one joint along joint_axis")
    return largest(absolute(fractions), joint_axis)


def reaction_acceleration(robot_compliance: Any, reaction_compliance_: Any) -> Any:
    """``a = F_a / m_r`` [m/s^2] from ``1 / m_r = u^T J M_jj^-1 J^T u`` [1/kg] and ``1 / F_a`` [1/N]."""
    robot_compliance = _validate.positive("robot_compliance", robot_compliance)
    reaction_compliance_ = _validate.positive("reaction_compliance_", reaction_compliance_)
    with _validate.combining(robot_compliance=robot_compliance, reaction_compliance_=reaction_compliance_):
        return robot_compliance / reaction_compliance_


def finger_mass_direction(moment_arms: Any, mass_matrix: Any) -> Any:
    """``x = M_f^-1 w / (w^T M_f^-1 w)``: the minimiser of ``x^T M_f x`` subject to ``w^T x = 1``.

    The minimum is the finger mass (see :func:`finger_mass`).

    Parameters
    ----------
    moment_arms: ``w = J^T u`` [m/rad], (..., nv) for NumPy, a column for CasADi.
    mass_matrix: ``M_f`` [kg m^2], (..., nv, nv) (:func:`finger_mass_matrix`).
    """
    moment_arms = _validate.arrays("moment_arms", moment_arms)
    mass_matrix = _validate.arrays("mass_matrix", mass_matrix, ndim=2, square=True)
    with _validate.combining(moment_arms=moment_arms, mass_matrix=mass_matrix):
        y = solve_vector(mass_matrix, moment_arms)
        with np.errstate(divide="ignore", invalid="ignore"):  # 0/0 at w = 0: refused below
            direction = y / dot(moment_arms, y, keepdims=True)
    if not is_symbolic(direction) and not np.isfinite(direction).all():
        # w = 0 (no joint moves the contact point along u) or an indefinite M_f: no unit-force direction.
        raise InvalidParameter(
            "moment_arms",
            moment_arms,
            "moment arms w = J^T u, not all zero, and a positive-definite mass_matrix",
        )
    return direction


def finger_mass(direction: Any, mass_matrix: Any) -> Any:
    """Effective finger mass ``m_f = x^T M_f x`` [kg] at the direction ``x`` of :func:`finger_mass_direction`.

    There it equals ``1 / (w^T M_f^-1 w)``; at any other ``x`` with ``w^T x = 1`` it is larger, which lets an
    optimiser treat ``x`` as a variable instead of inverting ``M_f`` symbolically.

    Parameters
    ----------
    direction: ``x`` [rad/m], (..., nv) for NumPy, a column for CasADi.
    mass_matrix: ``M_f`` [kg m^2], (..., nv, nv).
    """
    direction = _validate.arrays("direction", direction)
    mass_matrix = _validate.arrays("mass_matrix", mass_matrix, ndim=2, square=True)
    with _validate.combining(direction=direction, mass_matrix=mass_matrix):
        return quadratic_form(mass_matrix, direction)
