"""Build the actuator-design NLP for a URDF arm (CasADi, exact derivatives).

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
  which :meth:`DesignProblem.solver` builds once and shares between all the problem's solvers.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, NamedTuple

import casadi as ca
import numpy as np

from .._interrupt import interruptible
from ..errors import InvalidParameter
from ..model import effective as formulas
from .constraints import (
    ConstraintList,
    Constraints,
    ModelTerms,
    add_gearbox_peak_constraints,
    add_model_constraints,
    binding_torque_demands,
    check_gearbox_ratings,
    required_torque_function,
    torque_requirement_rows,
)
from .derivatives import SampleStructure, dense_dm, derivative_functions, structured_nlp
from .duty import (
    DutyRequirement,
    add_duty_constraints,
    add_gearbox_duty_constraints,
    check_reachable,
    duty_requirement,
    peak_rows,
)
from .layout import DesignLayout, DesignQuantities, design_layout, design_quantities
from .objectives import (
    CVAR_LEVEL,
    OBJECTIVES,
    TIE_BREAK_WEIGHT,
    add_epigraph,
    add_objective_bounds,
    add_tail,
    checked_bounded_objectives,
    mean_weights,
    objective_expression,
    objective_terms,
    objective_values,
    objective_weights,
    value_at_risk,
)
from .samples import (
    ContactSamples,
    check_finite,
    finger_mass_directions,
    kinematic_term,
    loaded_joints,
    reaction_compliance,
    sample_data,
    sample_function,
)
from .space import DesignSpace
from .technology import ActuatorTechnology

if TYPE_CHECKING:
    from ..arm.robot import Arm

__all__ = ["OBJECTIVES", "TIE_BREAK_WEIGHT", "ActuatorTechnology", "DesignProblem", "build_problem"]


@dataclass
class DesignProblem:
    """An actuator-design NLP, built and ready to inspect or solve.

    ``nlp`` is CasADi's ``{"x", "f", "g", "p"}``; ``lbx``/``ubx``/``x0``/``lbg``/``ubg`` its bounds and start;
    ``constraint_labels[i]`` names constraint ``g[i]``; ``objective_scale`` the value each objective is divided
    by in the NLP; ``evaluate`` a CasADi function of ``x`` giving ``impulses`` (1 x n_samples), ``actuator_mass``,
    ``approach_velocity``, ``thresholds`` (1 x n_samples), ``required_torque`` and ``peak_torque`` (n_joints),
    and ``parameters`` (5 x n_samples: ``m_f, m_r, k, k_m, a``, see :meth:`sample_parameters`); use
    :meth:`exact_point` first so that the auxiliary variables hold their exact values. ``duty`` is the duty
    cycle's requirement (:class:`collision_reflex.optimize.duty.DutyRequirement`), None without one; with one,
    ``required_torque_function`` takes the actuator masses (motor and gearbox) [kg] and the reflected inertias
    ``N^2 (J_m + J_g)`` [kg m^2], without one the actuator masses alone; ``static_torque_function`` takes the
    actuator masses and gives the static hold's part of it (or the given torques).

    The CasADi graph (``nlp``, ``lbg``/``ubg``, ``constraint_labels``, ``evaluate`` and the solvers) is built
    on first use: a problem that is only evaluated in NumPy (an active set's problem on every sample, a study's
    results) never builds it. Its start, bounds and scales are there from the start, and every bad input is
    refused when the problem is built.
    """

    x0: np.ndarray
    lbx: np.ndarray
    ubx: np.ndarray
    objective: dict[str, float]
    bounded_objectives: tuple[str, ...]
    objective_scale: dict[str, float]
    layout: DesignLayout
    samples: ContactSamples
    space: DesignSpace
    technology: ActuatorTechnology
    constraints: Constraints
    joint_names: tuple[str, ...]
    required_torque_function: ca.Function
    static_torque_function: ca.Function
    epigraph_index: int | None
    tail_index: slice | None
    compliance_index: slice
    direction_index: slice
    direction_scale: np.ndarray
    build_time: float
    duty: DutyRequirement | None
    slowest_bound: float
    _joint_numbers: ca.Function = field(repr=False)
    _sample_data: np.ndarray = field(repr=False)
    _build_graph: Callable[[], NlpGraph] = field(repr=False)
    _graph: NlpGraph | None = field(default=None, repr=False)
    _solvers: dict[str, ca.Function] = field(default_factory=dict, repr=False)
    _structured: tuple[dict[str, ca.MX], dict[str, ca.Function]] | None = field(default=None, repr=False)

    @property
    def n_joints(self) -> int:
        """Number of joints."""
        return len(self.joint_names)

    @property
    def graph(self) -> NlpGraph:
        """The CasADi side of the problem, built on first use."""
        if self._graph is None:
            self._graph = self._build_graph()
        return self._graph

    @property
    def nlp(self) -> dict[str, ca.MX]:
        """CasADi's ``{"x", "f", "g", "p"}``."""
        return self.graph.nlp

    @property
    def lbg(self) -> np.ndarray:
        """Lower bounds of the constraint rows ``g``."""
        return self.graph.lbg

    @property
    def ubg(self) -> np.ndarray:
        """Upper bounds of the constraint rows ``g``."""
        return self.graph.ubg

    @property
    def constraint_labels(self) -> list[str]:
        """``constraint_labels[i]`` names constraint ``g[i]``."""
        return self.graph.constraint_labels

    @property
    def evaluate(self) -> ca.Function:
        """The CasADi function of ``x`` giving the quantities the class describes, by name."""
        return self.graph.evaluate

    @property
    def _sample_function(self) -> ca.Function:
        return self.graph.sample_function

    @property
    def _structure(self) -> SampleStructure:
        return self.graph.structure

    @property
    def requirement(self) -> str:
        """What sizes the actuators: ``"static (gravity only)"``, given torques, or the duty cycle's."""
        return self.constraints.requirement

    def exact_point(self, x: np.ndarray) -> np.ndarray:
        """Give ``x`` with the auxiliary variables set to their exact values for the design in ``x``.

        The auxiliaries are the finger-mass directions, reaction compliances and the epigraph ``t``;
        evaluating at the result gives the model's values to machine precision.
        """
        x = np.array(x, dtype=float)
        masses, torques, finger = (np.asarray(v).ravel() for v in self._joint_numbers(x))
        x[self.direction_index] = (
            finger_mass_directions(self.samples, masses, finger) / self.direction_scale[:, None]
        ).ravel()
        x[self.compliance_index] = np.log(reaction_compliance(self.samples, torques))
        if self.epigraph_index is not None or self.tail_index is not None:
            impulses = self.numpy_impulses(x)
        if self.epigraph_index is not None:
            x[self.epigraph_index] = _epigraph_value(
                impulses, self.samples, self.slowest_bound, self.objective_scale
            )
        if self.tail_index is not None:
            x[self.tail_index] = _tail_values(impulses, self.samples, self.objective_scale)
        return x

    def numpy_impulses(self, x: np.ndarray) -> np.ndarray:
        """The impulse [N*s] of every sample at the design in ``x`` (its design part), by the NumPy path."""
        return _numpy_impulses(self.layout, self.technology, self.joint_names, self.samples, x)

    def sample_parameters(self, x: np.ndarray) -> dict[str, np.ndarray]:
        """The effective 1D parameters of every sample as the NLP evaluates them at the design in ``x``.

        Auxiliaries at their exact values: ``m_f``, ``m_r`` [kg], ``k``, ``k_m`` [N/m], ``a`` [m/s^2] and the
        contact-force threshold ``F_s`` [N], arrays of shape (n_samples,).
        """
        evaluated = self.evaluate(self.exact_point(x))
        rows = np.asarray(evaluated[6])
        out = dict(zip(("m_f", "m_r", "k", "k_m", "a"), rows, strict=True))
        out["F_s"] = np.asarray(evaluated[3]).ravel()
        return out

    def impulse_function(self) -> ca.Function:
        """The collision impulse of every sample as a CasADi function of the design variables alone.

        Input ``z``: the design variables as optimised, ``log`` of each free variable (the first
        ``layout.size`` entries of the NLP's ``x``). Output: (1, n_samples) impulses [N*s]. The per-sample
        auxiliaries take their exact values (a symbolic solve for the finger mass, the maximum over joints for
        the reaction compliance), so this is the model the NLP optimises, with exact derivatives for
        sensitivity studies; it is slower to differentiate than the NLP itself.
        """
        n = self.n_joints
        z = ca.MX.sym("z", self.layout.size)
        _, design_column, actuator_mass, peak_torque, finger_inertia, *_ = design_quantities(
            self.layout, z, self.technology, self.technology.joint_mechanical_stiffness(n)
        )
        w = self.samples.joint_moment_arms
        structure_mass = self.samples.kinematics.mass_matrix
        motor_influence = kinematic_term(self.samples, "motor_mass_influence")
        loaded = loaded_joints(self.samples)
        impulses = []
        for s_index, config in enumerate(self.samples.config_index):
            influence = [ca.DM(motor_influence[config, i]) for i in range(n)]
            structure = formulas.finger_mass_matrix(
                ca.DM(structure_mass[config]), influence, actuator_mass, finger_inertia
            )
            direction = formulas.finger_mass_direction(ca.DM(w[s_index]), structure)
            joints = np.flatnonzero(loaded[s_index]).tolist()
            fractions = formulas.torque_fractions(ca.DM(w[s_index, joints]), peak_torque[joints])
            compliance = formulas.reaction_compliance(fractions)
            impulse, *_ = self._sample_function(
                design_column, direction, compliance, ca.DM(self._sample_data[:, s_index])
            )
            impulses.append(impulse)
        return ca.Function("design_impulses", [z], [ca.horzcat(*impulses)], ["z"], ["impulses"])

    def solver(self, options: Mapping[str, str | float | bool], structural: bool = True) -> ca.Function:
        """IPOPT for this NLP with ``options`` (CasADi's ``nlpsol`` options), built once per option set.

        Every solver of the problem shares the same NLP functions, assembled per sample (:mod:`.derivatives`):
        the per-sample function mapped over the samples and the outer part, their values and derivatives.
        Differentiating the whole NLP instead is most of a solver's construction, and expanding it to SX
        most of the rest; these are SX functions already, so ``"expand"`` has nothing to do.
        ``structural=False`` lets CasADi differentiate the whole NLP (for comparison).
        """
        key = repr((sorted(options.items()), structural))
        solver = self._solvers.get(key)
        if solver is None:
            if not structural:
                solver = ca.nlpsol("actuator_design", "ipopt", self.nlp, dict(options))
            else:
                if self._structured is None:
                    self._structured = (
                        structured_nlp(self._structure),
                        derivative_functions(self._structure),
                    )
                nlp, derivatives = self._structured
                solver = ca.nlpsol(
                    "actuator_design", "ipopt", nlp, {**options, **derivatives, "expand": False}
                )
            self._solvers[key] = solver
        return solver

    def objective_value(self, x: np.ndarray) -> float:
        """The NLP's (scaled) objective at ``x``, auxiliaries at their exact values: for comparing results.

        By the NumPy path: the weighted, start-normalised objectives and the tie-break pull on the mean, the
        worst case as the epigraph takes it (over the samples within reach of the slowest approach allowed).
        """
        from .solve import layout_design

        z = np.asarray(x, dtype=float)[: self.layout.size]
        design = layout_design(self.layout, self.technology, self.joint_names, z)
        impulses = self.numpy_impulses(z)
        values = objective_values(
            impulses, float(np.sum(design.actuator_mass)), design.approach_velocity, self.samples
        )
        if self.epigraph_index is not None:
            scale = self.objective_scale["worst_case_impulse"]
            values["worst_case_impulse"] = scale * _epigraph_value(
                impulses, self.samples, self.slowest_bound, self.objective_scale
            )
        return float(
            sum(
                weight * OBJECTIVES[name][0] * values[name] / self.objective_scale[name]
                for name, weight in self.objective.items()
            )
            + TIE_BREAK_WEIGHT * values["mean_impulse"] / self.objective_scale["mean_impulse"]
        )

    def parameters(self, epsilon: Mapping[str, float] | None = None) -> np.ndarray:
        """NLP parameter vector bounding the objectives in ``epsilon`` (unbounded: +inf in scaled units)."""
        epsilon = dict(epsilon or {})
        unknown = set(epsilon) - set(self.bounded_objectives)
        if unknown:
            raise InvalidParameter(
                "epsilon",
                sorted(unknown),
                f"objectives built as bounded: {list(self.bounded_objectives)}",
                "pass bounded_objectives=... to build_problem",
            )
        values = []
        for name in self.bounded_objectives:
            sense = OBJECTIVES[name][0]
            bound = epsilon.get(name)
            values.append(1e20 if bound is None else sense * bound / self.objective_scale[name])
        return np.array(values)


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
    objective: an objective name of :data:`OBJECTIVES` or a weighted sum ``{name: weight}``; each objective is
        divided by its value at the start point, so weights compare relative changes.
    constraints: torque requirement (gravity over the samples + payload, times a safety factor, or given
        values, or a duty cycle's peak, RMS and speed requirements: :mod:`collision_reflex.optimize.duty`) and
        the threshold noise floor.
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
    n_samples, n_design = samples.size, layout.size
    named = set(weights) | set(bounded)
    epigraph_index, tail_index, compliance_index, direction_index = _variable_slices(
        n_design, n_samples, n_joints, "worst_case_impulse" in named, "cvar_impulse" in named
    )
    x = ca.MX.sym("x", direction_index.stop)
    p = ca.MX.sym("p", len(bounded))

    design = design_quantities(
        layout, x[:n_design], technology, technology.joint_mechanical_stiffness(n_joints)
    )
    joint_numbers = design.joint_function(x)
    lbx, ubx, x0 = _bounds_and_start(
        x.shape[0], layout, joint_numbers, samples, constraints, joint_names, technology
    )
    duty_rows: list[tuple[np.ndarray, np.ndarray, np.ndarray]] = []
    if duty is not None:
        duty_rows = _duty_setup(duty, x, x0, lbx, ubx, design, layout, technology, joint_names)
    lbx[compliance_index], ubx[compliance_index] = _compliance_bounds(samples, joint_numbers, lbx, ubx)

    start_mass, start_torque, start_finger = (np.asarray(v).ravel() for v in joint_numbers(x0))
    mass_range = [np.asarray(joint_numbers(bound)[0]).ravel() for bound in (lbx, ubx)]
    # The static hold (or the given torques); with a duty cycle the peak requirement is the larger of both.
    torque_demands = binding_torque_demands(samples, constraints, joint_names, *mass_range)
    check_gearbox_ratings(torque_demands, technology, joint_names, *mass_range)
    static_torque = required_torque_function(torque_demands, n_joints)
    required_torque = _module_required_torque(
        static_torque
        if duty is None
        else _envelope_required_torque(static_torque, _duty_required_torque(duty_rows, n_joints), n_joints),
        space.module_of(n_joints),
    )
    data = sample_data(samples, technology.joint_mechanical_stiffness(n_joints))
    # Start point: auxiliaries at their exact values for the start design, impulses by the NumPy path.
    start_directions = finger_mass_directions(samples, start_mass, start_finger)
    direction_scale = np.maximum(np.abs(start_directions).max(axis=1), 1e-300)
    x0[direction_index] = (start_directions / direction_scale[:, None]).ravel()
    x0[compliance_index] = np.log(reaction_compliance(samples, start_torque))
    start_impulses = _numpy_impulses(layout, technology, joint_names, samples, x0)
    check_finite(start_impulses, "impulse at the start point", samples)
    velocity = layout.values(x0[:n_design])["approach_velocity"][0]
    scale = objective_values(start_impulses, float(np.sum(start_mass)), velocity, samples)
    slowest_bound = float(layout.values(lbx[:n_design])["approach_velocity"][0])
    if epigraph_index is not None:
        lbx[epigraph_index] = 0.0
        x0[epigraph_index] = _epigraph_value(start_impulses, samples, slowest_bound, scale)
    if tail_index is not None:
        lbx[tail_index.start + 1 : tail_index.stop] = 0.0
        x0[tail_index] = _tail_values(start_impulses, samples, scale)
    start_required = (
        required_torque(start_mass)
        if duty is None
        else required_torque(start_mass, _start_reflected_inertia(layout, x0, technology))
    )
    torque_scale = np.maximum(np.asarray(start_required).ravel(), 1e-3)

    @interruptible()  # a Ctrl-C that CasADi's C++ swallowed while building ends in KeyboardInterrupt
    def graph() -> NlpGraph:
        """The NLP's CasADi side: the per-sample terms, the rows, the objective and their split."""
        per_sample = _sample_terms(
            x[direction_index], x[compliance_index], design, samples, technology, data, direction_scale
        )
        impulses, actuator_mass = per_sample.impulses, ca.sum1(design.actuator_mass)
        required_expression = (
            required_torque(design.actuator_mass)
            if duty is None
            else required_torque(design.actuator_mass, design.reflected_inertia)
        )
        evaluate = _evaluate_function(x, design, per_sample, actuator_mass, required_expression)
        expressions = objective_terms(impulses, actuator_mass, design.values["approach_velocity"], samples)
        g = ConstraintList()
        if epigraph_index is not None:
            slowest: ca.MX | float = slowest_bound
            if "approach_velocity" in bounded:  # the epsilon bound on the approach velocity, an NLP parameter
                bound = -p[bounded.index("approach_velocity")] * scale["approach_velocity"]
                slowest = ca.fmax(slowest_bound, bound)
            expressions["worst_case_impulse"] = add_epigraph(
                g, x, epigraph_index, impulses, scale, samples, slowest
            )
        if tail_index is not None:
            expressions["cvar_impulse"] = add_tail(g, x, tail_index, impulses, scale, samples)
        terms = _model_terms(x[compliance_index], design, per_sample)
        add_model_constraints(
            g, terms, torque_scale, torque_demands, samples, technology, constraints, joint_names
        )
        add_gearbox_peak_constraints(g, terms, torque_demands, technology, joint_names)
        if duty is not None:
            add_duty_constraints(g, duty, design, duty_rows, torque_scale, joint_names)
            add_gearbox_duty_constraints(g, duty, design, duty_rows, technology, joint_names)
        add_objective_bounds(g, bounded, expressions, scale, p)
        nlp = {
            "x": x,
            "f": objective_expression(weights, expressions, scale),
            "g": ca.vertcat(*g.parts),
            "p": p,
        }
        return NlpGraph(
            nlp,
            np.concatenate(g.lower),
            np.concatenate(g.upper),
            g.labels,
            evaluate,
            per_sample.function,
            _sample_structure(nlp, layout, design, per_sample, compliance_index, direction_index),
        )

    return DesignProblem(
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
        build_time=time.perf_counter() - started,
        duty=duty,
        slowest_bound=slowest_bound,
        _joint_numbers=joint_numbers,
        _sample_data=data,
        _build_graph=graph,
    )


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


def _numpy_impulses(
    layout: DesignLayout,
    technology: ActuatorTechnology,
    joint_names: tuple[str, ...],
    samples: ContactSamples,
    x: np.ndarray,
) -> np.ndarray:
    """The impulse [N*s] of every sample at the design in ``x`` (its design part), by the NumPy path."""
    from .evaluate import sample_impulses
    from .solve import layout_design  # solve imports this module

    design = layout_design(layout, technology, joint_names, np.asarray(x, dtype=float)[: layout.size])
    return sample_impulses(samples, technology, design)


def _epigraph_value(
    impulses: np.ndarray, samples: ContactSamples, slowest: float, scale: Mapping[str, float]
) -> float:
    """The scaled epigraph ``t`` that meets every worst-case row any solve keeps.

    That is the largest impulse [N*s] of the samples whose speed cap reaches the slowest approach allowed
    (:func:`.objectives.add_epigraph`).
    """
    return float(np.max(impulses[samples.inside(slowest)])) / scale["worst_case_impulse"]


def _tail_values(impulses: np.ndarray, samples: ContactSamples, scale: Mapping[str, float]) -> np.ndarray:
    """The CVaR's scaled value at risk and slacks at their optimal values for ``impulses`` [N*s].

    As :func:`.objectives.add_tail` lays them out.
    """
    var = value_at_risk(impulses, mean_weights(samples), CVAR_LEVEL)
    unit = scale["cvar_impulse"]
    return np.concatenate([[var / unit], np.maximum(impulses - var, 0.0) / unit])


class _SampleTerms(NamedTuple):
    """The per-sample part of the NLP (see :func:`_sample_terms`)."""

    function: ca.Function
    data: np.ndarray
    direction_scale: np.ndarray
    impulses: ca.MX
    thresholds: ca.MX
    normalisation: ca.MX
    parameters: ca.MX


def _sample_terms(
    scaled_directions: ca.MX,
    log_compliance: ca.MX,
    design: DesignQuantities,
    samples: ContactSamples,
    technology: ActuatorTechnology,
    data: np.ndarray,
    direction_scale: np.ndarray,
) -> _SampleTerms:
    """The per-sample function mapped over all samples, on the NLP's auxiliaries of every sample.

    ``scaled_directions`` are the finger-mass directions ``x_s`` (n_joints * n_samples) divided by their size
    at the start, ``direction_scale`` (across samples they span orders of magnitude). ``log_compliance`` is
    ``log(1/F_a)`` per sample; ``data`` the samples' data columns (:func:`.samples.sample_data`).
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
    outputs = function.map(n_samples)(design.design_column, directions, compliance, dense_dm(data))
    return _SampleTerms(function, data, direction_scale, *outputs)


def _sample_structure(
    nlp: dict[str, ca.MX],
    layout: DesignLayout,
    design: DesignQuantities,
    per_sample: _SampleTerms,
    compliance_index: slice,
    direction_index: slice,
) -> SampleStructure:
    """The NLP split into the per-sample function and the outer part (see :mod:`.derivatives`).

    A sample's variables are the design's log values, its ``log(1/F_a)`` and its scaled finger-mass direction;
    its outputs the impulse, the force threshold and ``w^T x``, the per-sample terms ``f`` and ``g`` use.
    ``design`` holds the NLP's design quantities (functions of the design part of ``nlp["x"]``).
    """
    n_design, n_samples = layout.size, per_sample.data.shape[1]
    n_joints = (direction_index.stop - direction_index.start) // n_samples
    # The NLP's own design column, taken as a function of x (only its design part enters): not built again.
    design_column = ca.Function("design_column", [nlp["x"]], [design.design_column]).expand()
    local = ca.SX.sym("v", n_design + 1 + n_joints)
    # Data the same for every sample (most motor-mass influence entries are zero) become constants: fewer
    # operations in the per-sample Hessian.
    varying = np.flatnonzero(np.any(per_sample.data != per_sample.data[:, :1], axis=1))
    data = ca.SX.sym("data", varying.size)
    column_data = ca.SX(ca.DM(per_sample.data[:, 0]))
    for position, row in enumerate(varying):
        column_data[int(row)] = data[position]
    scale = ca.SX.sym("scale", n_joints)
    column = design_column(ca.vertcat(local[:n_design], ca.SX.zeros(nlp["x"].numel() - n_design)))
    outputs = per_sample.function(column, local[n_design + 1 :] * scale, ca.exp(local[n_design]), column_data)
    sample = ca.Function("sample", [local, data, scale], [ca.vertcat(*outputs[:3])])

    y = ca.MX.sym("Y", 3, n_samples)
    replaced = [per_sample.impulses, per_sample.thresholds, per_sample.normalisation]
    f, g = ca.graph_substitute([nlp["f"], nlp["g"]], replaced, [y[0, :], y[1, :], y[2, :]])
    outer = ca.Function("outer", [nlp["x"], y, nlp["p"]], [f, g]).expand()
    samples = np.arange(n_samples)
    variables = np.vstack(
        [
            np.repeat(np.arange(n_design)[:, None], n_samples, axis=1),
            compliance_index.start + samples[None, :],
            direction_index.start + n_joints * samples[None, :] + np.arange(n_joints)[:, None],
        ]
    )
    scales = np.tile(per_sample.direction_scale, (n_joints, 1))
    return SampleStructure(outer, sample, variables, per_sample.data[varying], scales)


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


def _joint_names(arm: Arm, samples: ContactSamples) -> tuple[str, ...]:
    """The arm's joint names, checked against the samples' joint count (generic names if the arm has none)."""
    n_joints = samples.kinematics.mass_matrix.shape[1]
    joint_names = tuple(getattr(arm, "joint_names", [f"joint{i + 1}" for i in range(n_joints)]))
    if len(joint_names) != n_joints:
        raise InvalidParameter("arm", len(joint_names), f"{n_joints} joint names to match the samples")
    return joint_names


def _variable_slices(
    n_design: int, n_samples: int, n_joints: int, with_epigraph: bool, with_tail: bool
) -> tuple[int | None, slice | None, slice, slice]:
    """Where the auxiliaries sit in ``x``: epigraph, CVaR's value at risk and slacks, ``g``, directions.

    ``g = log(1/F_a)`` per sample, ``x_s`` the finger-mass directions.

    The layout is: design (log values) | epigraph ``t`` (if needed) | value at risk and one slack per sample
    (if needed) | ``g`` (n_samples) | finger-mass directions (n_joints * n_samples).
    """
    epigraph_index = n_design if with_epigraph else None
    tail_start = n_design + (epigraph_index is not None)
    tail_index = slice(tail_start, tail_start + 1 + n_samples) if with_tail else None
    compliance_start = tail_start if tail_index is None else tail_index.stop
    compliance_index = slice(compliance_start, compliance_start + n_samples)
    direction_index = slice(compliance_index.stop, compliance_index.stop + n_joints * n_samples)
    return epigraph_index, tail_index, compliance_index, direction_index


def _bounds_and_start(
    size: int,
    layout: DesignLayout,
    joint_numbers: ca.Function,
    samples: ContactSamples,
    constraints: Constraints,
    joint_names: tuple[str, ...],
    technology: ActuatorTechnology,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Bounds ``lbx``, ``ubx`` and start ``x0`` of the design part of ``x`` (auxiliaries unbounded, at 0).

    The start is the log-midpoint of the bounds with the gear ratios raised to a torque-feasible start.
    """
    lbx, ubx, x0 = (np.full(size, value) for value in (-np.inf, np.inf, 0.0))
    lbx[: layout.size], ubx[: layout.size], x0[: layout.size] = layout.log_bounds()
    efficiency = technology.gearbox_figures(len(joint_names)).efficiency
    _feasible_gear_start(x0, layout, joint_numbers, samples, constraints, joint_names, efficiency)
    return lbx, ubx, x0


def _compliance_bounds(
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
    masses, peak, _ = (np.asarray(v).ravel() for v in joint_numbers(x0))
    torques = efficiency * peak
    rows, _ = torque_requirement_rows(samples, constraints, joint_names)
    required = np.max([base + per_motor @ masses for base, per_motor in rows], axis=0)
    _raise_gear_ratios(x0, layout, required, torques)


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


def _duty_setup(
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


def _start_reflected_inertia(
    layout: DesignLayout, x0: np.ndarray, technology: ActuatorTechnology
) -> np.ndarray:
    """Reflected inertias ``N^2 (J_m + J_g)`` [kg m^2] of the start design."""
    values = layout.values(x0[: layout.size])
    joint = technology.joint_quantities(
        values["stator_diameter"], values["stack_length"], values["gear_ratio"]
    )
    return np.asarray(joint.reflected_inertia, dtype=float)
