"""The NLP's variables: where each sits in ``x``, their bounds, and the start design.

The design variables' bounds are their log bounds (:meth:`.layout.DesignLayout.log_bounds`); the start is the
log-midpoint of the bounds with the free gear ratios raised until the driving peak torque covers the
requirement (static hold, or the duty cycle's peak) with 10 % to spare. Each sample's ``log(1/F_a)`` is bounded
by its values at the strongest and the weakest actuators allowed; the other auxiliaries are unbounded.
"""

from __future__ import annotations

import math

import casadi as ca
import numpy as np

from .constraints import Constraints, torque_requirement_rows
from .duty import DutyRequirement, check_reachable, peak_rows
from .layout import DesignLayout, DesignQuantities
from .samples import ContactSamples, reaction_compliance
from .technology import ActuatorTechnology


def variable_slices(
    n_design: int, n_samples: int, n_joints: int, named: set[str], with_region: bool
) -> tuple[int | None, slice | None, slice, slice, slice | None]:
    """Where the auxiliaries sit in ``x``: epigraph, CVaR's value at risk and slacks, ``g``, directions.

    ``g = log(1/F_a)`` per sample, ``x_s`` the finger-mass directions, ``y_s`` the coupled-mass directions
    (the rotors on the links, for a body region's rows: :mod:`.body_region`).

    The layout is: design (log values) | epigraph ``t`` (if needed) | value at risk and one slack per sample
    (if needed) | ``g`` (n_samples) | finger-mass directions (n_joints * n_samples) | coupled-mass directions
    (n_joints * n_samples, if needed). ``named``: the objectives named as objective or bound (the worst case
    needs the epigraph, the CVaR the tail).
    """
    with_epigraph, with_tail = "worst_case_impulse" in named, "cvar_impulse" in named
    epigraph_index = n_design if with_epigraph else None
    tail_start = n_design + (epigraph_index is not None)
    tail_index = slice(tail_start, tail_start + 1 + n_samples) if with_tail else None
    compliance_start = tail_start if tail_index is None else tail_index.stop
    compliance_index = slice(compliance_start, compliance_start + n_samples)
    direction_index = slice(compliance_index.stop, compliance_index.stop + n_joints * n_samples)
    coupled_index = (
        slice(direction_index.stop, direction_index.stop + n_joints * n_samples) if with_region else None
    )
    return epigraph_index, tail_index, compliance_index, direction_index, coupled_index


def bounds_and_start(
    x: ca.MX,
    design: DesignQuantities,
    joint_numbers: ca.Function,
    slices: tuple[int | None, slice | None, slice, slice, slice | None],
    layout: DesignLayout,
    samples: ContactSamples,
    constraints: Constraints,
    technology: ActuatorTechnology,
    joint_names: tuple[str, ...],
    duty: DutyRequirement | None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, list[tuple[np.ndarray, np.ndarray, np.ndarray]]]:
    """Bounds ``lbx``, ``ubx`` and start ``x0`` of ``x``, and the duty cycle's binding peak rows (none without).

    ``slices``: where the auxiliaries sit (:func:`variable_slices`). The design part starts at the log-midpoint
    of its bounds with the gear ratios raised to a torque-feasible start (the static hold's, then the duty
    cycle's peak); the auxiliaries start at 0, the epigraph and the CVaR's slacks bounded below by 0 and each
    ``log(1/F_a)`` by :func:`compliance_bounds`, the others unbounded.
    """
    epigraph_index, tail_index, compliance_index, *_ = slices
    lbx, ubx, x0 = (np.full(x.shape[0], value) for value in (-np.inf, np.inf, 0.0))
    lbx[: layout.size], ubx[: layout.size], x0[: layout.size] = layout.log_bounds()
    efficiency = technology.gearbox_figures(len(joint_names)).efficiency
    _feasible_gear_start(x0, layout, joint_numbers, samples, constraints, joint_names, efficiency)
    duty_rows: list[tuple[np.ndarray, np.ndarray, np.ndarray]] = []
    if duty is not None:
        duty_rows = _duty_peak_rows(duty, x, x0, lbx, ubx, design, layout, technology, joint_names)
    lbx[compliance_index], ubx[compliance_index] = compliance_bounds(samples, joint_numbers, lbx, ubx)
    if epigraph_index is not None:
        lbx[epigraph_index] = 0.0
    if tail_index is not None:
        lbx[tail_index.start + 1 : tail_index.stop] = 0.0
    return lbx, ubx, x0, duty_rows


def compliance_bounds(
    samples: ContactSamples, joint_numbers: ca.Function, lbx: np.ndarray, ubx: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Bounds of ``log(1/F_a)`` per sample: its values at the strongest and the weakest actuators allowed."""
    weakest, strongest = (np.asarray(joint_numbers(bound)[1]).ravel() for bound in (lbx, ubx))
    return np.log(reaction_compliance(samples, strongest)), np.log(reaction_compliance(samples, weakest))


def _feasible_gear_start(
    x0: np.ndarray,
    layout: DesignLayout,
    joint_numbers: ca.Function,
    samples: ContactSamples,
    constraints: Constraints,
    joint_names: tuple[str, ...],
    efficiency: np.ndarray,
) -> None:
    """Move the start's free gear ratios up to where the driving peak torque covers the requirement, in place.

    With 10 % to spare and within their bounds: IPOPT converges much faster from a torque-feasible start.
    ``efficiency`` is each joint's gearbox efficiency [-].
    """
    masses, peak, *_ = (np.asarray(v).ravel() for v in joint_numbers(x0))
    torques = efficiency * peak
    rows, _ = torque_requirement_rows(samples, constraints, joint_names)
    required = np.max([base + per_motor @ masses for base, per_motor in rows], axis=0)
    _raise_gear_ratios(x0, layout, required, torques)


def _duty_peak_rows(
    duty: DutyRequirement,
    x: ca.MX,
    x0: np.ndarray,
    lbx: np.ndarray,
    ubx: np.ndarray,
    design: DesignQuantities,
    layout: DesignLayout,
    technology: ActuatorTechnology,
    joint_names: tuple[str, ...],
) -> list[tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """The duty cycle's binding peak rows; refuses an unreachable requirement and raises the start's gears.

    Motor masses and reflected inertias grow with the motor size and the gear ratio, so their ranges are their
    values at the lower and the upper bounds. The start's free gear ratios go up (within their bounds) to where
    the peak torque covers the peak demand at the start with 10 % to spare, as for the static requirement.
    """
    numbers = ca.Function(
        "duty_numbers", [x], [design.actuator_mass, design.reflected_inertia, design.driving_peak_torque]
    )
    (mass_low, reflected_low, _), (mass_high, reflected_high, _) = (
        [np.asarray(v).ravel() for v in numbers(bound)] for bound in (lbx, ubx)
    )
    check_reachable(duty, layout, technology, mass_low, mass_high, joint_names)
    n = len(joint_names)
    x_low = np.column_stack([np.ones(n), np.tile(mass_low, (n, 1)), reflected_low])
    x_high = np.column_stack([np.ones(n), np.tile(mass_high, (n, 1)), reflected_high])
    rows = peak_rows(duty, x_low, x_high)
    masses, reflected, torques = (np.asarray(v).ravel() for v in numbers(x0))
    required = np.array(
        [np.max(rows[j][0] @ np.concatenate([[1.0], masses, [reflected[j]]])) for j in range(n)]
    )
    _raise_gear_ratios(x0, layout, required, torques)
    return rows


def _raise_gear_ratios(
    x0: np.ndarray, layout: DesignLayout, required: np.ndarray, torques: np.ndarray
) -> None:
    """Raise the start's gear ratios (log values in ``x0``) to 1.1 x what the ``required`` torques [N m] need.

    ``torques``: the start's driving peak torques [N m]; a ratio shared by a module is raised for the most
    demanding of its joints. Within the ratios' upper bounds.
    """
    start = x0.copy()
    for joint, index in enumerate(layout.slices["gear_ratio"]):
        if index is not None and required[joint] > torques[joint]:
            raised = start[index] + math.log(1.1 * required[joint] / torques[joint])
            upper = math.log(layout.bounds["gear_ratio"][joint].upper)
            x0[index] = max(x0[index], min(raised, upper))


def start_reflected_inertia(
    layout: DesignLayout, x0: np.ndarray, technology: ActuatorTechnology
) -> np.ndarray:
    """Reflected inertias ``N^2 (J_m + J_g)`` [kg m^2] of the start design."""
    values = layout.values(x0[: layout.size])
    joint = technology.joint_quantities(
        values["stator_diameter"], values["stack_length"], values["gear_ratio"]
    )
    return np.asarray(joint.reflected_inertia, dtype=float)
