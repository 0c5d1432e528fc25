"""The actuator-design NLP as built: :class:`DesignProblem`, its start, bounds and scales, and its CasADi graph.

:func:`.build.build_problem` makes one; the graph (:mod:`.nlp`) is built on first use. Besides the NLP, a
problem evaluates its designs by the NumPy path (:meth:`DesignProblem.numpy_impulses`,
:meth:`DesignProblem.objective_value`) and sets its auxiliary variables to their exact values
(:meth:`DesignProblem.exact_point`).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

import casadi as ca
import numpy as np

from ..errors import InvalidParameter
from ..model import effective as formulas
from .constraints import Constraints
from .derivatives import derivative_functions, structured_nlp
from .design import layout_design
from .duty import DutyRequirement
from .evaluate import sample_impulses
from .layout import DesignLayout, design_quantities
from .nlp import NlpGraph, NlpInputs, nlp_graph
from .objectives import (
    CVAR_LEVEL,
    OBJECTIVES,
    TIE_BREAK_WEIGHT,
    mean_weights,
    objective_values,
    value_at_risk,
)
from .samples import (
    ContactSamples,
    finger_mass_directions,
    kinematic_term,
    loaded_joints,
    reaction_compliance,
)
from .space import DesignSpace
from .technology import ActuatorTechnology


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
    coupled_index: slice | None
    coupled_scale: np.ndarray | None
    build_time: float
    duty: DutyRequirement | None
    slowest_bound: float
    _joint_numbers: ca.Function = field(repr=False)
    _nlp_inputs: NlpInputs = field(repr=False)
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
            self._graph = nlp_graph(self, self._nlp_inputs)
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
    def requirement(self) -> str:
        """What sizes the actuators: ``"static (gravity only)"``, given torques, or the duty cycle's."""
        return self.constraints.requirement

    def exact_point(self, x: np.ndarray, impulses: np.ndarray | None = None) -> np.ndarray:
        """Give ``x`` with the auxiliary variables set to their exact values for the design in ``x``.

        The auxiliaries are the finger- and coupled-mass directions, reaction compliances and the epigraph ``t``;
        evaluating at the result gives the model's values to machine precision. ``impulses``: the design's
        impulses [N*s] (:meth:`numpy_impulses`) when known, not evaluated again.
        """
        x = np.array(x, dtype=float)
        masses, torques, finger, reflected = (np.asarray(v).ravel() for v in self._joint_numbers(x))
        x[self.direction_index] = (
            finger_mass_directions(self.samples, masses, finger) / self.direction_scale[:, None]
        ).ravel()
        if self.coupled_index is not None and self.coupled_scale is not None:
            x[self.coupled_index] = (
                finger_mass_directions(self.samples, masses, reflected) / self.coupled_scale[:, None]
            ).ravel()
        x[self.compliance_index] = np.log(reaction_compliance(self.samples, torques))
        if self.epigraph_index is not None or self.tail_index is not None:
            values = self.numpy_impulses(x) if impulses is None else impulses
            if self.epigraph_index is not None:
                x[self.epigraph_index] = _epigraph_value(
                    values, self.samples, self.slowest_bound, self.objective_scale
                )
            if self.tail_index is not None:
                x[self.tail_index] = _tail_values(values, self.samples, self.objective_scale)
        return x

    def numpy_impulses(self, x: np.ndarray) -> np.ndarray:
        """The impulse [N*s] of every sample at the design in ``x`` (its design part), by the NumPy path."""
        return numpy_impulses(self.layout, self.technology, self.joint_names, self.samples, x)

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
            impulse, *_ = self.graph.sample_function(
                design_column, direction, compliance, ca.DM(self._nlp_inputs.data[:, s_index]), ca.DM.zeros(n)
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
                        structured_nlp(self.graph.structure),
                        derivative_functions(self.graph.structure),
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

    def row_excess(self, x: np.ndarray, parameters: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """How far each constraint row ``g`` at ``x`` lies below its lower and above its upper bound [-, scaled].

        0 where within; ``parameters`` are the NLP's (:meth:`parameters`). The rows' function is built once.
        """
        key = "constraint rows"
        rows = self._solvers.get(key)
        if rows is None:
            rows = self._solvers[key] = ca.Function("rows", [self.nlp["x"], self.nlp["p"]], [self.nlp["g"]])
        g = np.asarray(rows(x, parameters)).ravel()
        below = np.maximum(np.where(np.isfinite(self.lbg), self.lbg - g, 0.0), 0.0)
        above = np.maximum(np.where(np.isfinite(self.ubg), g - self.ubg, 0.0), 0.0)
        return below, above


def numpy_impulses(
    layout: DesignLayout,
    technology: ActuatorTechnology,
    joint_names: tuple[str, ...],
    samples: ContactSamples,
    x: np.ndarray,
) -> np.ndarray:
    """The impulse [N*s] of every sample at the design in ``x`` (its design part), by the NumPy path."""
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
