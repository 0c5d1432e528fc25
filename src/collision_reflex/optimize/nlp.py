"""The actuator-design NLP's CasADi graph: per-sample terms, constraint rows, objective and their split.

Structure (see the guide's "Optimisation and Pareto fronts"):

- Design variables, all positive, are optimised as their logarithms (:mod:`.layout`): per joint the stator
  diameter (and optionally stack length) of a motor scaled from a reference motor, the gear ratio and the
  software stiffness; globally the sensing threshold and the approach velocity.
- Per contact sample ``s`` (configuration, direction ``u``) the effective parameters of the paper's "Collision Reflex in Higher Dimensions"
  are formed from the numeric Pinocchio data (``M_bb0``, motor-mass influence matrices, ``w = J^T u``) and the symbolic
  actuator quantities, and the 1D impulse of :mod:`collision_reflex.model.impulse` is applied. One SX function per
  sample (:mod:`.samples`) is mapped over all samples inside an MX NLP.
- The reaction capacity ``F_a = min_i tau_i / |w_i|`` is a minimum over joints (non-smooth). Each sample gets a
  variable ``g_s = log(1/F_a)`` with ``g_s >= log|w_si| - log tau_i`` for every joint its direction loads --
  linear in the log design variables -- and the impulse is evaluated with ``F_a = exp(-g_s)``. The impulse grows
  with ``g_s``, so at an optimum ``g_s`` sits on the largest ratio, i.e. ``F_a`` on the minimum: exact, smooth,
  and the 1D impulse is evaluated once per sample.
- The finger mass ``m_f = 1 / (w^T M_f^-1 w)`` has the actuator masses (motor and gearbox, carried at the
  joints) and optionally the reflected inertias inside
  ``M_f``. It is also ``min x^T M_f x`` over ``x`` with ``w^T x = 1`` (attained at ``x = M_f^-1 w / w^T M_f^-1
  w``). The impulse grows with ``m_f``, so each sample gets a variable ``x_s`` with the linear constraint
  ``w_s^T x_s = 1`` and uses ``x_s^T M_f x_s``: minimising over the design and ``x`` together is exact, and
  avoids both a symbolic inverse and a badly conditioned bilinear equality.
- The worst case is an epigraph ``t >= I_s``.
- Objectives (:mod:`.objectives`) can be bounded (``f_k <= eps_k``) through NLP parameters, so one solver serves
  a whole epsilon-constraint Pareto sweep.
- The constraint rows (:mod:`.constraints`) each carry a label.
- IPOPT gets the NLP's values, gradient, Jacobian and Hessian assembled per sample (:mod:`.derivatives`),
  which :meth:`.problem.DesignProblem.solver` builds once and shares between all the problem's solvers.

:func:`.build.build_problem` sets up the variables, bounds, start and scales in NumPy; the graph is built
from them on first use (:func:`nlp_graph`).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, NamedTuple

import casadi as ca
import numpy as np

from .._interrupt import interruptible
from .body_region import add_body_region_constraints
from .constraints import (
    ConstraintList,
    ModelTerms,
    TorqueDemands,
    add_gearbox_peak_constraints,
    add_model_constraints,
)
from .derivatives import SampleStructure, dense_dm
from .duty import add_duty_constraints, add_gearbox_duty_constraints
from .layout import DesignQuantities
from .objectives import add_epigraph, add_objective_bounds, add_tail, objective_expression, objective_terms
from .samples import ContactSamples, sample_function
from .technology import ActuatorTechnology

if TYPE_CHECKING:
    from .problem import DesignProblem


class NlpInputs(NamedTuple):
    """What the NLP's graph is built from besides the fields of its :class:`.problem.DesignProblem`.

    ``x`` and ``p`` are the NLP's variables and parameters, ``design`` the design quantities of ``x``'s design
    part, ``data`` the samples' data columns (:func:`.samples.sample_data`), ``torque_demands`` the binding
    demands of the static hold (or the given torques), ``duty_rows`` the duty cycle's binding peak rows (none
    without one) and ``torque_scale`` [N m] the requirement at the start, by which the torque rows are scaled.
    """

    x: ca.MX
    p: ca.MX
    design: DesignQuantities
    data: np.ndarray
    torque_demands: list[TorqueDemands]
    duty_rows: list[tuple[np.ndarray, np.ndarray, np.ndarray]]
    torque_scale: np.ndarray


class NlpGraph(NamedTuple):
    """The CasADi side of a :class:`DesignProblem`, built on first use.

    ``nlp`` is CasADi's ``{"x", "f", "g", "p"}``, ``lbg``/``ubg`` the rows' bounds and ``constraint_labels``
    their names; ``evaluate`` gives the quantities :class:`DesignProblem` describes; ``sample_function`` is the
    per-sample model and ``structure`` the NLP's split for its derivatives (:mod:`.derivatives`).
    """

    nlp: dict[str, ca.MX]
    lbg: np.ndarray
    ubg: np.ndarray
    constraint_labels: list[str]
    evaluate: ca.Function
    sample_function: ca.Function
    structure: SampleStructure


@interruptible()  # a Ctrl-C that CasADi's C++ swallowed while building ends in KeyboardInterrupt
def nlp_graph(problem: DesignProblem, inputs: NlpInputs) -> NlpGraph:
    """The NLP's CasADi side: the per-sample terms, the rows, the objective and their split."""
    x, design, samples, technology = inputs.x, inputs.design, problem.samples, problem.technology
    compliance_index, direction_index = problem.compliance_index, problem.direction_index
    coupled_index, coupled_scale = problem.coupled_index, problem.coupled_scale
    per_sample = _sample_terms(
        x[direction_index],
        x[compliance_index],
        None if coupled_index is None or coupled_scale is None else (x[coupled_index], coupled_scale),
        design,
        samples,
        technology,
        inputs.data,
        problem.direction_scale,
    )
    impulses, actuator_mass = per_sample.impulses, ca.sum1(design.actuator_mass)
    required_torque, duty = problem.required_torque_function, problem.duty
    required_expression = (
        required_torque(design.actuator_mass)
        if duty is None
        else required_torque(design.actuator_mass, design.reflected_inertia)
    )
    evaluate = _evaluate_function(x, design, per_sample, actuator_mass, required_expression)
    expressions = objective_terms(impulses, actuator_mass, design.values["approach_velocity"], samples)
    g = ConstraintList()
    _add_worst_case_terms(g, expressions, problem, inputs, impulses)
    terms = _model_terms(x[compliance_index], design, per_sample)
    constraints, joint_names, demands = problem.constraints, problem.joint_names, inputs.torque_demands
    add_model_constraints(
        g, terms, inputs.torque_scale, demands, samples, technology, constraints, joint_names
    )
    add_gearbox_peak_constraints(g, terms, demands, technology, joint_names)
    if duty is not None:
        add_duty_constraints(g, duty, design, inputs.duty_rows, inputs.torque_scale, joint_names)
        add_gearbox_duty_constraints(g, duty, design, inputs.duty_rows, technology, joint_names)
    region = constraints.body_region
    if region is not None:
        velocity = design.values["approach_velocity"]
        slowest = _slowest_approach(problem, inputs.p)
        masses, normalisation = per_sample.coupled_masses, per_sample.coupled_normalisation
        add_body_region_constraints(g, region, velocity, masses, normalisation, samples, slowest)
    split = per_sample.split(region is not None)
    scale = problem.objective_scale
    add_objective_bounds(g, problem.bounded_objectives, expressions, scale, inputs.p)
    nlp = {
        "x": x,
        "f": objective_expression(problem.objective, expressions, scale),
        "g": ca.vertcat(*g.parts),
        "p": inputs.p,
    }
    return NlpGraph(
        nlp,
        np.concatenate(g.lower),
        np.concatenate(g.upper),
        g.labels,
        evaluate,
        per_sample.function,
        _sample_structure(nlp, problem, design, per_sample, split),
    )


def _add_worst_case_terms(
    g: ConstraintList,
    expressions: dict[str, ca.MX],
    problem: DesignProblem,
    inputs: NlpInputs,
    impulses: ca.MX,
) -> None:
    """The worst case's epigraph and the CVaR's tail, their rows in ``g`` and their terms in ``expressions``.

    Each only where the problem has its variables (an objective or a bound names it).
    """
    x, scale, samples = inputs.x, problem.objective_scale, problem.samples
    if problem.epigraph_index is not None:
        slowest = _slowest_approach(problem, inputs.p)
        expressions["worst_case_impulse"] = add_epigraph(
            g, x, problem.epigraph_index, impulses, scale, samples, slowest
        )
    if problem.tail_index is not None:
        expressions["cvar_impulse"] = add_tail(g, x, problem.tail_index, impulses, scale, samples)


def _slowest_approach(problem: DesignProblem, p: ca.MX) -> ca.MX | float:
    """The least approach velocity a solve allows [m/s]: its lower bound, or its epsilon bound (an NLP parameter)."""
    bounded = problem.bounded_objectives
    if "approach_velocity" not in bounded:
        return problem.slowest_bound
    bound = -p[bounded.index("approach_velocity")] * problem.objective_scale["approach_velocity"]
    return ca.fmax(problem.slowest_bound, bound)


class _SampleTerms(NamedTuple):
    """The per-sample part of the NLP (see :func:`_sample_terms`)."""

    function: ca.Function
    data: np.ndarray
    direction_scale: np.ndarray
    impulses: ca.MX
    thresholds: ca.MX
    normalisation: ca.MX
    parameters: ca.MX
    coupled_masses: ca.MX
    coupled_normalisation: ca.MX

    def split(self, body_region: bool) -> list[ca.MX]:
        """The outputs the outer part takes from each sample (see :func:`_sample_structure`)."""
        outputs = [self.impulses, self.thresholds, self.normalisation]
        return [*outputs, self.coupled_masses, self.coupled_normalisation] if body_region else outputs


def _sample_terms(
    scaled_directions: ca.MX,
    log_compliance: ca.MX,
    coupled: tuple[ca.MX, np.ndarray] | None,
    design: DesignQuantities,
    samples: ContactSamples,
    technology: ActuatorTechnology,
    data: np.ndarray,
    direction_scale: np.ndarray,
) -> _SampleTerms:
    """The per-sample function mapped over all samples, on the NLP's auxiliaries of every sample.

    ``scaled_directions`` are the finger-mass directions ``x_s`` (n_joints * n_samples) divided by their size
    at the start, ``direction_scale`` (across samples they span orders of magnitude). ``log_compliance`` is
    ``log(1/F_a)`` per sample; ``coupled`` the coupled-mass directions ``y_s`` so scaled and their scales (None
    without a body region: the coupled outputs are then those of ``y = 0``, unused); ``data`` the samples' data
    columns (:func:`.samples.sample_data`).
    """
    n_samples = samples.size
    n_joints = int(scaled_directions.numel()) // n_samples
    function = sample_function(
        n_joints, technology.sensing, technology.reaction, technology.finger_joints(n_joints)
    )
    directions = ca.reshape(scaled_directions, n_joints, n_samples) * dense_dm(
        np.tile(direction_scale, (n_joints, 1))
    )
    compliance = ca.exp(ca.transpose(log_compliance))
    if coupled is None:
        coupled_directions = ca.MX.zeros(n_joints, n_samples)
    else:
        scaled, coupled_scale = coupled
        coupled_directions = ca.reshape(scaled, n_joints, n_samples) * dense_dm(
            np.tile(coupled_scale, (n_joints, 1))
        )
    outputs = function.map(n_samples)(
        design.design_column, directions, compliance, dense_dm(data), coupled_directions
    )
    return _SampleTerms(function, data, direction_scale, *outputs)


def _sample_structure(
    nlp: dict[str, ca.MX],
    problem: DesignProblem,
    design: DesignQuantities,
    per_sample: _SampleTerms,
    replaced: list[ca.MX],
) -> SampleStructure:
    """The NLP split into the per-sample function and the outer part (see :mod:`.derivatives`).

    A sample's variables are the design's log values, its ``log(1/F_a)``, its scaled finger-mass direction and
    (with a body region) its scaled coupled-mass direction; its outputs ``replaced``
    (:meth:`_SampleTerms.split`), the per-sample terms ``f`` and ``g`` use. ``design`` holds the NLP's design
    quantities (functions of the design part of ``nlp["x"]``).
    """
    compliance_index, direction_index, coupled_index = (
        problem.compliance_index,
        problem.direction_index,
        problem.coupled_index,
    )
    n_design, n_samples = problem.layout.size, per_sample.data.shape[1]
    n_joints = (direction_index.stop - direction_index.start) // n_samples
    n_directions = n_joints * (1 if coupled_index is None else 2)
    # The NLP's own design column, taken as a function of x (only its design part enters): not built again.
    design_column = ca.Function("design_column", [nlp["x"]], [design.design_column]).expand()
    local = ca.SX.sym("v", n_design + 1 + n_directions)
    # Data the same for every sample (most motor-mass influence entries are zero) become constants: fewer
    # operations in the per-sample Hessian.
    varying = np.flatnonzero(np.any(per_sample.data != per_sample.data[:, :1], axis=1))
    data = ca.SX.sym("data", varying.size)
    column_data = ca.SX(ca.DM(per_sample.data[:, 0]))
    for position, row in enumerate(varying):
        column_data[int(row)] = data[position]
    scale = ca.SX.sym("scale", n_directions)
    column = design_column(ca.vertcat(local[:n_design], ca.SX.zeros(nlp["x"].numel() - n_design)))
    scaled = local[n_design + 1 :] * scale
    coupled = ca.SX.zeros(n_joints) if coupled_index is None else scaled[n_joints:]
    outputs = per_sample.function(column, scaled[:n_joints], ca.exp(local[n_design]), column_data, coupled)
    impulse, threshold, normalisation, _, coupled_mass, coupled_normalisation = outputs
    kept = [impulse, threshold, normalisation, coupled_mass, coupled_normalisation][: len(replaced)]
    sample = ca.Function("sample", [local, data, scale], [ca.vertcat(*kept)])

    y = ca.MX.sym("Y", len(replaced), n_samples)
    f, g = ca.graph_substitute([nlp["f"], nlp["g"]], replaced, [y[i, :] for i in range(len(replaced))])
    outer = ca.Function("outer", [nlp["x"], y, nlp["p"]], [f, g]).expand()
    samples = np.arange(n_samples)
    rows = [
        np.repeat(np.arange(n_design)[:, None], n_samples, axis=1),
        compliance_index.start + samples[None, :],
        direction_index.start + n_joints * samples[None, :] + np.arange(n_joints)[:, None],
    ]
    scales = [np.tile(per_sample.direction_scale, (n_joints, 1))]
    if coupled_index is not None and problem.coupled_scale is not None:
        rows.append(coupled_index.start + n_joints * samples[None, :] + np.arange(n_joints)[:, None])
        scales.append(np.tile(problem.coupled_scale, (n_joints, 1)))
    variables = np.vstack(rows)
    return SampleStructure(outer, sample, variables, per_sample.data[varying], np.vstack(scales))


def _model_terms(log_compliance: ca.MX, design: DesignQuantities, per_sample: _SampleTerms) -> ModelTerms:
    """The symbolic quantities the model's constraints bound; ``log_compliance``: ``log(1/F_a)`` in ``x``."""
    return ModelTerms(
        log_compliance,
        design.peak_torque,
        per_sample.normalisation,
        per_sample.thresholds,
        design.actuator_mass,
        design.driving_peak_torque,
    )


def _evaluate_function(
    x: ca.MX,
    design: DesignQuantities,
    per_sample: _SampleTerms,
    actuator_mass: ca.MX,
    required_torque: ca.MX,
) -> ca.Function:
    """CasADi function of the NLP's ``x`` giving the quantities :class:`DesignProblem` reports, by name."""
    outputs = {
        "impulses": per_sample.impulses,
        "actuator_mass": actuator_mass,
        "approach_velocity": design.values["approach_velocity"],
        "thresholds": per_sample.thresholds,
        "required_torque": required_torque,
        "peak_torque": design.peak_torque,
        "parameters": per_sample.parameters,
    }
    return ca.Function("evaluate", [x], list(outputs.values()), ["x"], list(outputs))
