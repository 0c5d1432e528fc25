"""Build the actuator-design NLP for a URDF arm: :func:`build_problem` (the NLP itself: :mod:`.nlp`).

The NumPy side is set up here, at once: the variables' layout, bounds and start (:mod:`.variables`), the
torque requirement (:mod:`.requirement`), the objectives' scales (their values at the start) and every check
of the inputs. The CasADi graph is built from them on first use (:class:`.problem.DesignProblem`).
"""

from __future__ import annotations

import time
from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING

import casadi as ca
import numpy as np

from .._interrupt import interruptible
from ..errors import InvalidParameter
from .constraints import Constraints, TorqueDemands, binding_torque_demands, check_gearbox_ratings
from .duty import DutyRequirement, duty_requirement
from .layout import DesignLayout, design_layout, design_quantities
from .nlp import NlpInputs
from .objectives import checked_bounded_objectives, objective_values, objective_weights
from .problem import DesignProblem, numpy_impulses
from .requirement import peak_requirement
from .samples import ContactSamples, check_finite, finger_mass_directions, sample_data
from .space import DesignSpace
from .technology import ActuatorTechnology
from .variables import (
    bounds_and_start,
    start_reflected_inertia,
    variable_slices,
)

if TYPE_CHECKING:
    from ..arm.robot import Arm


@interruptible()
def build_problem(
    arm: Arm,
    samples: ContactSamples,
    space: DesignSpace,
    technology: ActuatorTechnology,
    objective: str | Mapping[str, float] = "worst_case_impulse",
    constraints: Constraints | None = None,
    bounded_objectives: Sequence[str] = (),
) -> DesignProblem:
    """Build the NLP that chooses actuators for ``arm`` to minimise ``objective`` on ``samples``.

    Parameters
    ----------
    arm: the :class:`collision_reflex.arm.Arm` (joint names; ``samples.kinematics`` must come from it).
    samples: contact cases: configurations (with their Pinocchio data) and directions.
    space: bounds of the design variables.
    technology: reference motor, scaling law, mechanical stiffness, sensing scheme, reaction model, gearboxes.
    objective: an objective name of :data:`.objectives.OBJECTIVES` or a weighted sum ``{name: weight}``; each objective is
        divided by its value at the start point, so weights compare relative changes.
    constraints: torque requirement (gravity over the samples + payload, times a safety factor, or given
        values, or a duty cycle's peak, RMS and speed requirements: :mod:`collision_reflex.optimize.duty`), the
        threshold noise floor and a body region's permissible speed (:mod:`.body_region`).
    bounded_objectives: objectives that may be bounded per solve (epsilon-constraint Pareto sweeps).

    Raises
    ------
    InvalidParameter: bad input, a duty cycle with a reference motor of unknown maximum speed, or a duty-cycle
        requirement that no design within the bounds can meet (naming the joint, the constraint and the best
        margin reachable), a gearbox whose ratios miss the joint's gear-ratio bounds, or one whose peak rating
        is below the least static (or given) requirement of its joint.
    """
    started = time.perf_counter()
    constraints = constraints or Constraints()
    weights, bounded = objective_weights(objective), checked_bounded_objectives(bounded_objectives)
    joint_names = _joint_names(arm, samples)
    n_joints = len(joint_names)
    layout = design_layout(space, technology, constraints, n_joints, joint_names)
    duty = duty_requirement(
        arm, samples, constraints.duty_cycle, constraints.rating, technology, constraints.safety_factor
    )
    named = set(weights) | set(bounded)
    slices = variable_slices(layout.size, samples.size, n_joints, named, constraints.body_region is not None)
    epigraph_index, tail_index, compliance_index, direction_index, coupled_index = slices
    x = ca.MX.sym("x", (coupled_index or direction_index).stop)
    k_mech = technology.joint_mechanical_stiffness(n_joints)
    design = design_quantities(layout, x[: layout.size], technology, k_mech)
    joint_numbers = design.joint_function(x)
    lbx, ubx, x0, duty_rows = bounds_and_start(
        x, design, joint_numbers, slices, layout, samples, constraints, technology, joint_names, duty
    )
    demands, static_torque, required_torque, torque_scale = _torque_requirement(
        samples,
        constraints,
        technology,
        space,
        layout,
        joint_names,
        joint_numbers,
        (lbx, ubx, x0),
        duty_rows,
        duty,
    )
    direction_scale, coupled_scale, start_impulses, scale = _start_scales(
        layout, technology, joint_names, samples, joint_numbers, x0
    )
    p = ca.MX.sym("p", len(bounded))
    inputs = NlpInputs(x, p, design, sample_data(samples, k_mech), demands, duty_rows, torque_scale)
    problem = DesignProblem(
        x0=x0,
        lbx=lbx,
        ubx=ubx,
        objective=weights,
        bounded_objectives=bounded,
        objective_scale=scale,
        layout=layout,
        samples=samples,
        space=space,
        technology=technology,
        constraints=constraints,
        joint_names=joint_names,
        required_torque_function=required_torque,
        static_torque_function=static_torque,
        epigraph_index=epigraph_index,
        tail_index=tail_index,
        compliance_index=compliance_index,
        direction_index=direction_index,
        direction_scale=direction_scale,
        coupled_index=coupled_index,
        coupled_scale=coupled_scale if coupled_index is not None else None,
        build_time=0.0,
        duty=duty,
        slowest_bound=float(layout.values(lbx[: layout.size])["approach_velocity"][0]),
        _joint_numbers=joint_numbers,
        _nlp_inputs=inputs,
    )
    # The start's auxiliaries at their exact values for the start design.
    problem.x0 = problem.exact_point(x0, start_impulses)
    problem.build_time = time.perf_counter() - started
    return problem


def _joint_names(arm: Arm, samples: ContactSamples) -> tuple[str, ...]:
    """The arm's joint names, checked against the samples' joint count (generic names if the arm has none)."""
    n_joints = samples.kinematics.mass_matrix.shape[1]
    joint_names = tuple(getattr(arm, "joint_names", [f"joint{i + 1}" for i in range(n_joints)]))
    if len(joint_names) != n_joints:
        raise InvalidParameter("arm", len(joint_names), f"{n_joints} joint names to match the samples")
    return joint_names


def _torque_requirement(
    samples: ContactSamples,
    constraints: Constraints,
    technology: ActuatorTechnology,
    space: DesignSpace,
    layout: DesignLayout,
    joint_names: tuple[str, ...],
    joint_numbers: ca.Function,
    bounds_and_start: tuple[np.ndarray, np.ndarray, np.ndarray],
    duty_rows: list[tuple[np.ndarray, np.ndarray, np.ndarray]],
    duty: DutyRequirement | None,
) -> tuple[list[TorqueDemands], ca.Function, ca.Function, np.ndarray]:
    """The static hold's binding demands and requirement, the requirement that sizes each joint, its scale.

    ``bounds_and_start``: ``lbx``, ``ubx`` and the start ``x0``. The static hold (or the given torques) is
    checked against the gearboxes' peak ratings; with a duty cycle the peak requirement is the larger of both
    (:func:`.requirement.peak_requirement`). The scale [N m] of the torque rows is the requirement at the start.
    """
    lbx, ubx, x0 = bounds_and_start
    mass_range = [np.asarray(joint_numbers(bound)[0]).ravel() for bound in (lbx, ubx)]
    demands = binding_torque_demands(samples, constraints, joint_names, *mass_range)
    check_gearbox_ratings(demands, technology, joint_names, *mass_range)
    owner = space.module_of(len(joint_names))
    static, required = peak_requirement(demands, None if duty is None else duty_rows, owner)
    start_mass = np.asarray(joint_numbers(x0)[0]).ravel()
    start_required = (
        required(start_mass)
        if duty is None
        else required(start_mass, start_reflected_inertia(layout, x0, technology))
    )
    return demands, static, required, np.maximum(np.asarray(start_required).ravel(), 1e-3)


def _start_scales(
    layout: DesignLayout,
    technology: ActuatorTechnology,
    joint_names: tuple[str, ...],
    samples: ContactSamples,
    joint_numbers: ca.Function,
    x0: np.ndarray,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, dict[str, float]]:
    """The start design's finger- and coupled-mass direction scales, impulses [N*s] and objectives [their units].

    The NLP divides each objective by its value at the start ``x0``; the impulses are checked finite. The
    finger-mass directions span orders of magnitude across samples: each sample's is scaled by its largest
    entry at the start, and so are the coupled-mass directions (the rotors on the links).
    """
    start_mass, _, start_finger, start_reflected = (np.asarray(v).ravel() for v in joint_numbers(x0))
    direction_scale, coupled_scale = (
        np.maximum(np.abs(finger_mass_directions(samples, start_mass, inertia)).max(axis=1), 1e-300)
        for inertia in (start_finger, start_reflected)
    )
    start_impulses = numpy_impulses(layout, technology, joint_names, samples, x0)
    check_finite(start_impulses, "impulse at the start point", samples)
    velocity = layout.values(x0[: layout.size])["approach_velocity"][0]
    scale = objective_values(start_impulses, float(np.sum(start_mass)), velocity, samples)
    return direction_scale, coupled_scale, start_impulses, scale
