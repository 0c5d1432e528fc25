"""The required peak torque per joint as a CasADi function of the design's actuator masses (and inertias).

The static hold's (or the given torques, :func:`.constraints.required_torque_function`), with a duty cycle the
larger of it and the cycle's peak, and within a module the largest of its joints'.
"""

from __future__ import annotations

import casadi as ca
import numpy as np

from .constraints import TorqueDemands, required_torque_function


def peak_requirement(
    demands: list[TorqueDemands],
    duty_rows: list[tuple[np.ndarray, np.ndarray, np.ndarray]] | None,
    owner: list[int],
) -> tuple[ca.Function, ca.Function]:
    """The static hold's requirement and the requirement that sizes each joint, as CasADi functions.

    ``demands``: the static hold's binding demands (or the given torques); ``duty_rows``: the duty cycle's
    binding peak rows, None without a duty cycle; ``owner``: per joint its module's first joint. Both take the
    actuator masses [kg]; with a duty cycle the second also takes the reflected inertias ``N^2 (J_m + J_g)``
    [kg m^2].
    """
    n_joints = len(owner)
    static = required_torque_function(demands, n_joints)
    required = (
        static
        if duty_rows is None
        else _envelope_required_torque(static, _duty_required_torque(duty_rows, n_joints), n_joints)
    )
    return static, _module_required_torque(required, owner)


def _duty_required_torque(
    rows: list[tuple[np.ndarray, np.ndarray, np.ndarray]], n_joints: int
) -> ca.Function:
    """CasADi function: actuator masses [kg], ``N^2 (J_m + J_g)`` [kg m^2] -> the peak requirement per joint [N m]."""
    masses = ca.MX.sym("actuator_mass", n_joints)
    reflected = ca.MX.sym("reflected_inertia", n_joints)
    required = [
        ca.mmax(ca.mtimes(ca.DM(joint_rows), ca.vertcat(1.0, masses, reflected[j])))
        for j, (joint_rows, _, _) in enumerate(rows)
    ]
    return ca.Function("required_torque", [masses, reflected], [ca.vertcat(*required)])


def _envelope_required_torque(static: ca.Function, duty: ca.Function, n_joints: int) -> ca.Function:
    """CasADi function: actuator masses [kg], ``N^2 (J_m + J_g)`` [kg m^2] -> peak requirement per joint [N m].

    The larger of the static hold's and the duty cycle's.
    """
    masses = ca.MX.sym("actuator_mass", n_joints)
    reflected = ca.MX.sym("reflected_inertia", n_joints)
    envelope = ca.fmax(static(masses), duty(masses, reflected))
    return ca.Function("required_torque", [masses, reflected], [envelope])


def _module_required_torque(required: ca.Function, owner: list[int]) -> ca.Function:
    """``required`` with each module's joints given the largest requirement of the module.

    ``owner``: per joint its module's first joint (:meth:`DesignSpace.module_of`); one actuator must do the
    work of any of its joints.
    """
    if owner == list(range(len(owner))):
        return required
    inputs = [ca.MX.sym(required.name_in(i), required.size1_in(i)) for i in range(required.n_in())]
    own = required(*inputs)
    modules = {k: [j for j, o in enumerate(owner) if o == k] for k in set(owner)}
    envelope = ca.vertcat(*(ca.mmax(own[modules[owner[j]]]) for j in range(len(owner))))
    return ca.Function("required_torque", inputs, [envelope])
