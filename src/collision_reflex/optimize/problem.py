"""Build the actuator-design NLP for a URDF arm (CasADi, exact derivatives).

Structure (see the README's "Design optimisation" section):

- Design variables, all positive, are optimised as their logarithms: per joint the stator diameter (and
  optionally stack length) of a motor scaled from a reference motor, the gear ratio and the software stiffness;
  globally the sensing threshold and the approach velocity.
- Per contact sample ``s`` (configuration, direction ``u``) the effective parameters of MODEL.md §3 are formed
  from the numeric Pinocchio data (``M_bb0``, motor-mass influence matrices, ``w = J^T u``) and the symbolic
  actuator quantities, and the 1D impulse of :mod:`collision_reflex.model.impulse` is applied. One SX function per
  sample is mapped over all samples inside an MX NLP.
- The reaction capacity ``F_a = min_i tau_i / |w_i|`` is a minimum over joints (non-smooth). Each sample gets a
  variable ``g_s = log(1/F_a)`` with ``g_s >= log|w_si| - log tau_i`` for every joint its direction loads --
  linear in the log design variables -- and the impulse is evaluated with ``F_a = exp(-g_s)``. The impulse grows
  with ``g_s``, so at an optimum ``g_s`` sits on the largest ratio, i.e. ``F_a`` on the minimum: exact, smooth,
  and the 1D impulse is evaluated once per sample.
- The finger mass ``m_f = 1 / (w^T M_f^-1 w)`` has motor masses (and optionally reflected inertias) inside
  ``M_f``. It is also ``min x^T M_f x`` over ``x`` with ``w^T x = 1`` (attained at ``x = M_f^-1 w / w^T M_f^-1
  w``). The impulse grows with ``m_f``, so each sample gets a variable ``x_s`` with the linear constraint
  ``w_s^T x_s = 1`` and uses ``x_s^T M_f x_s``: minimising over the design and ``x`` together is exact, and
  avoids both a symbolic inverse and a badly conditioned bilinear equality.
- The worst case is an epigraph ``t >= I_s``.
- Objectives can be bounded (``f_k <= eps_k``) through NLP parameters, so one solver serves a whole
  epsilon-constraint Pareto sweep.
"""

from __future__ import annotations

import math
import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import casadi as ca
import numpy as np

from .. import _validate
from ..errors import InvalidParameter
from ..hardware.actuators import REFLECTED_INERTIA_PLACEMENTS
from ..hardware.motors import Motor, scaled_motor_quantities
from ..model import effective as formulas
from ..model.impulse import REACTION_MODES, phase_impulses, series_stiffness
from ..model.sensing import sensing_scheme, threshold_force
from .space import (
    GLOBAL_VARIABLES,
    OPTIMIZED_SENSING_SCHEMES,
    PER_JOINT_VARIABLES,
    Bounds,
    Constraints,
    ContactSamples,
    DesignSpace,
)

TIE_BREAK_WEIGHT = 1e-3
"""Weight of the (start-normalised) mean impulse added to every objective. A worst case leaves the samples that
do not bind it, and the joints that do not affect it, undetermined; this small pull toward a lower mean picks a
definite design among the equals and pins the per-sample auxiliary variables, at a cost of about this relative
amount in the main objective."""

OBJECTIVES: dict[str, tuple[int, str, str]] = {
    # name: (sense: +1 minimise / -1 maximise, unit, description)
    "worst_case_impulse": (1, "N*s", "largest collision impulse over the samples"),
    "mean_impulse": (1, "N*s", "mean over the samples of the collision impulse"),
    "actuator_mass": (1, "kg", "total mass of the motors"),
    "approach_velocity": (-1, "m/s", "approach velocity (maximised: shorter cycle time)"),
}


@dataclass(frozen=True)
class ActuatorTechnology:
    """The fixed choices of actuation the design varies within.

    reference_motor: motor every joint's motor is scaled from.
    scaling_law: motor scaling law name (see :data:`collision_reflex.hardware.motors.SCALING_LAWS`).
    mechanical_stiffness: joint mechanical stiffness [N m/rad], one value or one per joint, finite > 0: it is
        the only spring left in the reaction phase.
    sensing: ``"force"`` (contact-force threshold) or ``"position"`` (contact position-error threshold), see
        :data:`collision_reflex.optimize.space.OPTIMIZED_SENSING_SCHEMES`.
    reaction: reaction-phase model, ``"at_rest"`` (the paper's) or ``"moving"``.
    reflected_inertia_in: where the reflected rotor inertia ``N^2 J_m`` acts. ``"robot"`` (default, the paper's
        arm model): behind the joint springs, in the robot mass ``m_r`` of the reaction phase only.
        ``"finger"``: also rigidly on the link side, in the finger mass ``m_f`` of the impact phase -- a stiff
        transmission with the compliance at the contact, as the paper measured for its geared A8 actuator
        (fitted finger mass 20 kg against 0.12 kg direct-drive).
    """

    reference_motor: Motor
    mechanical_stiffness: float | Sequence[float]
    scaling_law: str = "haddadin"
    sensing: str = "force"
    reaction: str = "at_rest"
    reflected_inertia_in: str = "robot"

    def __post_init__(self) -> None:
        _validate.positive("mechanical_stiffness", np.asarray(self.mechanical_stiffness, dtype=float))
        object.__setattr__(self, "sensing", sensing_scheme(self.sensing, OPTIMIZED_SENSING_SCHEMES))
        _validate.choice("reaction", self.reaction, REACTION_MODES)
        _validate.choice("reflected_inertia_in", self.reflected_inertia_in, REFLECTED_INERTIA_PLACEMENTS)

    def joint_mechanical_stiffness(self, n_joints: int) -> np.ndarray:
        return np.broadcast_to(np.asarray(self.mechanical_stiffness, dtype=float), (n_joints,)).copy()


@dataclass
class _Layout:
    """Where each design variable lives: a slice of the NLP's ``x`` (log values) or a fixed value."""

    bounds: dict[str, list[Bounds]] = field(default_factory=dict)
    slices: dict[str, list[int | None]] = field(default_factory=dict)
    size: int = 0

    def add(self, name: str, bounds: list[Bounds]) -> None:
        self.bounds[name] = bounds
        indices: list[int | None] = []
        for b in bounds:
            if b.is_fixed:
                indices.append(None)
            else:
                indices.append(self.size)
                self.size += 1
        self.slices[name] = indices

    def expressions(self, x: Any) -> dict[str, Any]:
        """Each variable as an MX column (exp of its log variable, or its fixed value)."""
        out = {}
        for name, bounds in self.bounds.items():
            parts = [
                ca.exp(x[i]) if i is not None else ca.MX(b.lower)
                for i, b in zip(self.slices[name], bounds, strict=True)
            ]
            out[name] = ca.vertcat(*parts)
        return out

    def log_bounds(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        lower, upper, start = (np.empty(self.size) for _ in range(3))
        for name, bounds in self.bounds.items():
            for i, b in zip(self.slices[name], bounds, strict=True):
                if i is not None:
                    lower[i], upper[i], start[i] = math.log(b.lower), math.log(b.upper), math.log(b.midpoint)
        return lower, upper, start

    def values(self, x: np.ndarray) -> dict[str, np.ndarray]:
        """Numeric values [SI] of every variable at ``x``."""
        return {
            name: np.array(
                [
                    math.exp(x[i]) if i is not None else b.lower
                    for i, b in zip(self.slices[name], bounds, strict=True)
                ]
            )
            for name, bounds in self.bounds.items()
        }


@dataclass
class DesignProblem:
    """An actuator-design NLP, built and ready to inspect or solve.

    ``nlp`` is CasADi's ``{"x", "f", "g", "p"}``; ``lbx``/``ubx``/``x0``/``lbg``/``ubg`` its bounds and start;
    ``constraint_labels[i]`` names constraint ``g[i]``; ``objective_scale`` the value each objective is divided
    by in the NLP; ``evaluate`` a CasADi function of ``x`` giving ``impulses`` (1 x n_samples), ``actuator_mass``,
    ``approach_velocity``, ``thresholds`` (1 x n_samples), ``required_torque`` and ``peak_torque`` (n_joints),
    and ``parameters`` (5 x n_samples: ``m_f, m_r, k, k_m, a``, see :meth:`sample_parameters`); use
    :meth:`exact_point` first so that the auxiliary variables hold their exact values.
    """

    nlp: dict[str, Any]
    x0: np.ndarray
    lbx: np.ndarray
    ubx: np.ndarray
    lbg: np.ndarray
    ubg: np.ndarray
    constraint_labels: list[str]
    objective: dict[str, float]
    bounded_objectives: tuple[str, ...]
    objective_scale: dict[str, float]
    evaluate: Any
    layout: _Layout
    samples: ContactSamples
    space: DesignSpace
    technology: ActuatorTechnology
    constraints: Constraints
    joint_names: tuple[str, ...]
    required_torque_function: Any
    epigraph_index: int | None
    compliance_index: slice
    direction_index: slice
    direction_scale: np.ndarray
    build_time: float
    _joint_numbers: Any = field(repr=False, default=None)
    _sample_function: Any = field(repr=False, default=None)
    _sample_data: Any = field(repr=False, default=None)
    _solvers: dict[str, Any] = field(default_factory=dict, repr=False)
    _objective: Any = field(default=None, repr=False)

    @property
    def n_joints(self) -> int:
        return len(self.joint_names)

    def exact_point(self, x: np.ndarray) -> np.ndarray:
        """``x`` with the auxiliary variables (finger-mass directions, reaction compliances and the epigraph
        ``t``) set to their exact values for the design in ``x``, so that evaluating there gives the model's
        values to machine precision."""
        x = np.array(x, dtype=float)
        masses, torques, finger = (np.asarray(v).ravel() for v in self._joint_numbers(x))
        x[self.direction_index] = (
            finger_mass_directions(self.samples, masses, finger) / self.direction_scale[:, None]
        ).ravel()
        x[self.compliance_index] = np.log(reaction_compliance(self.samples, torques))
        if self.epigraph_index is not None:
            impulses = np.asarray(self.evaluate(x)[0]).ravel()
            x[self.epigraph_index] = impulses.max() / self.objective_scale["worst_case_impulse"]
        return x

    def sample_parameters(self, x: np.ndarray) -> dict[str, np.ndarray]:
        """The effective 1D parameters of every sample as the NLP evaluates them at the design in ``x``
        (auxiliaries at their exact values): ``m_f``, ``m_r`` [kg], ``k``, ``k_m`` [N/m], ``a`` [m/s^2] and the
        contact-force threshold ``F_s`` [N], arrays of shape (n_samples,)."""
        evaluated = self.evaluate(self.exact_point(x))
        rows = np.asarray(evaluated[6])
        out = dict(zip(("m_f", "m_r", "k", "k_m", "a"), rows, strict=True))
        out["F_s"] = np.asarray(evaluated[3]).ravel()
        return out

    def impulse_function(self) -> Any:
        """The collision impulse of every sample as a CasADi function of the design variables alone.

        Input ``z``: the design variables as optimised, ``log`` of each free variable (the first
        ``layout.size`` entries of the NLP's ``x``). Output: (1, n_samples) impulses [N*s]. The per-sample
        auxiliaries take their exact values (a symbolic solve for the finger mass, the maximum over joints for
        the reaction compliance), so this is the model the NLP optimises, with exact derivatives for
        sensitivity studies; it is slower to differentiate than the NLP itself.
        """
        n = self.n_joints
        z = ca.MX.sym("z", self.layout.size)
        _, design_column, motor_mass, peak_torque, finger_inertia = _design_quantities(
            self.layout, z, self.technology, self.technology.joint_mechanical_stiffness(n)
        )
        w = self.samples.joint_moment_arms
        kin = self.samples.kinematics
        loaded = loaded_joints(self.samples)
        impulses = []
        for s_index, config in enumerate(self.samples.config_index):
            influence = [ca.DM(kin.motor_mass_influence[config, i]) for i in range(n)]
            structure = formulas.finger_mass_matrix(
                ca.DM(kin.mass_matrix[config]), influence, motor_mass, finger_inertia
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

    def objective_value(self, x: np.ndarray) -> float:
        """The NLP's (scaled) objective at ``x``, auxiliaries at their exact values: for comparing results."""
        if self._objective is None:
            self._objective = ca.Function("objective", [self.nlp["x"]], [self.nlp["f"]])
        return float(self._objective(self.exact_point(x)))

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


def build_problem(
    arm: Any,
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
    technology: reference motor, scaling law, mechanical stiffness, sensing scheme, reaction model.
    objective: an objective name of :data:`OBJECTIVES` or a weighted sum ``{name: weight}``; each objective is
        divided by its value at the start point, so weights compare relative changes.
    constraints: torque requirement (gravity over the samples + payload, times a safety factor, or given
        values) and the threshold noise floor.
    bounded_objectives: objectives that may be bounded per solve (epsilon-constraint Pareto sweeps).
    """
    started = time.perf_counter()
    constraints = constraints or Constraints()
    weights = _objective_weights(objective)
    for name in bounded_objectives:
        _validate.choice("bounded objective", name, tuple(OBJECTIVES))
    bounded = tuple(bounded_objectives)
    n_joints = samples.kinematics.mass_matrix.shape[1]
    joint_names = tuple(getattr(arm, "joint_names", [f"joint{i + 1}" for i in range(n_joints)]))
    if len(joint_names) != n_joints:
        raise InvalidParameter("arm", len(joint_names), f"{n_joints} joint names to match the samples")

    layout = _design_layout(space, technology, constraints, n_joints)

    # Variables: design (log values) | epigraph t (if needed) | g = log(1/F_a) (n_samples) |
    # finger-mass directions x (n_joints * n_samples).
    n_samples, n_design = samples.size, layout.size
    epigraph_index = n_design if "worst_case_impulse" in set(weights) | set(bounded) else None
    compliance_start = n_design + (epigraph_index is not None)
    compliance_index = slice(compliance_start, compliance_start + n_samples)
    direction_index = slice(compliance_index.stop, compliance_index.stop + n_joints * n_samples)
    x = ca.MX.sym("x", direction_index.stop)
    p = ca.MX.sym("p", len(bounded))

    k_mech = technology.joint_mechanical_stiffness(n_joints)
    values, design_column, motor_mass, peak_torque, finger_inertia = _design_quantities(
        layout, x[:n_design], technology, k_mech
    )
    joint_numbers = ca.Function("joint_numbers", [x], [motor_mass, peak_torque, finger_inertia])

    # Start point: log-midpoints of the bounds; auxiliaries at their exact values there.
    lbx, ubx, x0 = (np.full(x.shape[0], value) for value in (-np.inf, np.inf, 0.0))
    lbx[:n_design], ubx[:n_design], x0[:n_design] = layout.log_bounds()
    _feasible_gear_start(x0, layout, joint_numbers, samples, constraints, joint_names)
    start_mass, start_torque, start_finger = (np.asarray(v).ravel() for v in joint_numbers(x0))
    # log(1/F_a) lies between its values at the weakest and the strongest actuators the bounds allow.
    weakest, strongest = (np.asarray(joint_numbers(bound)[1]).ravel() for bound in (lbx, ubx))
    lbx[compliance_index] = np.log(reaction_compliance(samples, strongest))
    ubx[compliance_index] = np.log(reaction_compliance(samples, weakest))

    data = _sample_data(samples, k_mech)
    sample_function = _sample_function(
        n_joints, technology.sensing, technology.reaction, technology.reflected_inertia_in
    )
    per_sample = sample_function.map(n_samples)
    # x_s is scaled per sample by its size at the start: across samples it spans orders of magnitude.
    start_directions = finger_mass_directions(samples, start_mass, start_finger)
    direction_scale = np.maximum(np.abs(start_directions).max(axis=1), 1e-300)
    directions = ca.reshape(x[direction_index], n_joints, n_samples) * ca.DM(
        np.tile(direction_scale, (n_joints, 1))
    )
    compliance = ca.exp(ca.transpose(x[compliance_index]))
    impulses, thresholds, normalisation, parameters = per_sample(
        design_column, directions, compliance, ca.DM(data)
    )
    actuator_mass = ca.sum1(motor_mass)
    mass_bounds = [np.asarray(joint_numbers(bound)[0]).ravel() for bound in (lbx, ubx)]
    torque_demands = _binding_torque_demands(samples, constraints, joint_names, *mass_bounds)
    required_torque = _required_torque_function(torque_demands, n_joints)
    evaluate = _evaluate_function(
        x,
        {
            "impulses": impulses,
            "actuator_mass": actuator_mass,
            "approach_velocity": values["approach_velocity"],
            "thresholds": thresholds,
            "required_torque": required_torque(motor_mass),
            "peak_torque": peak_torque,
            "parameters": parameters,
        },
    )
    x0[direction_index] = (start_directions / direction_scale[:, None]).ravel()
    x0[compliance_index] = np.log(reaction_compliance(samples, start_torque))
    start_impulses = np.asarray(evaluate(x0)[0]).ravel()
    _check_finite(start_impulses, "impulse at the start point", samples)
    velocity_start = layout.values(x0[:n_design])["approach_velocity"][0]
    scale = {
        "worst_case_impulse": float(start_impulses.max()),
        "mean_impulse": float(start_impulses.mean()),
        "actuator_mass": float(start_mass.sum()),
        "approach_velocity": float(velocity_start),
    }
    expressions: dict[str, Any] = {
        "mean_impulse": ca.sum2(impulses) / n_samples,
        "actuator_mass": actuator_mass,
        "approach_velocity": values["approach_velocity"],
    }

    g = _ConstraintList()
    add = g.add
    if epigraph_index is not None:
        t = x[epigraph_index] * scale["worst_case_impulse"]
        x0[epigraph_index] = 1.0
        lbx[epigraph_index] = 0.0
        add(
            ca.transpose(t - impulses) / scale["worst_case_impulse"],
            0.0,
            np.inf,
            [f"worst-case bound >= impulse of sample {s}" for s in range(n_samples)],
        )
        expressions["worst_case_impulse"] = t

    _add_model_constraints(
        g,
        x[compliance_index],
        peak_torque,
        normalisation,
        thresholds,
        motor_mass,
        start_mass,
        required_torque,
        torque_demands,
        samples,
        technology,
        constraints,
        joint_names,
    )

    for k, name in enumerate(bounded):
        add(
            OBJECTIVES[name][0] * expressions[name] / scale[name] - p[k],
            -np.inf,
            0.0,
            [f"{name} within its bound"],
        )

    f = sum(
        weight * OBJECTIVES[name][0] * expressions[name] / scale[name] for name, weight in weights.items()
    )
    f += TIE_BREAK_WEIGHT * expressions["mean_impulse"] / scale["mean_impulse"]
    nlp = {"x": x, "f": f, "g": ca.vertcat(*g.parts), "p": p}
    return DesignProblem(
        nlp=nlp,
        x0=x0,
        lbx=lbx,
        ubx=ubx,
        lbg=np.concatenate(g.lower),
        ubg=np.concatenate(g.upper),
        constraint_labels=g.labels,
        objective=weights,
        bounded_objectives=bounded,
        objective_scale=scale,
        evaluate=evaluate,
        layout=layout,
        samples=samples,
        space=space,
        technology=technology,
        constraints=constraints,
        joint_names=joint_names,
        required_torque_function=required_torque,
        epigraph_index=epigraph_index,
        compliance_index=compliance_index,
        direction_index=direction_index,
        direction_scale=direction_scale,
        build_time=time.perf_counter() - started,
        _joint_numbers=joint_numbers,
        _sample_function=sample_function,
        _sample_data=data,
    )


def _evaluate_function(x: Any, outputs: dict[str, Any]) -> Any:
    """CasADi function of the NLP's ``x`` giving the named ``outputs`` (see :class:`DesignProblem`)."""
    return ca.Function("evaluate", [x], list(outputs.values()), ["x"], list(outputs))


def _design_layout(
    space: DesignSpace, technology: ActuatorTechnology, constraints: Constraints, n_joints: int
) -> _Layout:
    """The design variables with their bounds: per joint, then global; with force sensing the noise floor
    bounds the threshold from below."""
    layout = _Layout()
    defaults = {"stack_length": technology.reference_motor.stack_length}
    for name in PER_JOINT_VARIABLES:
        layout.add(name, space.per_joint(name, n_joints, defaults.get(name)))
    for name in GLOBAL_VARIABLES:
        bounds = space.global_bounds(name)
        if name == "threshold" and technology.sensing == "force":
            bounds = _with_noise_floor(bounds, constraints.threshold_floor)
        layout.add(name, [bounds])
    return layout


@dataclass
class _ConstraintList:
    """The NLP's constraints ``lower <= g <= upper`` as they are added, each row with a label."""

    parts: list[Any] = field(default_factory=list)
    lower: list[np.ndarray] = field(default_factory=list)
    upper: list[np.ndarray] = field(default_factory=list)
    labels: list[str] = field(default_factory=list)

    def add(self, expression: Any, lower: float, upper: float, names: list[str]) -> None:
        self.parts.append(expression)
        self.lower.append(np.full(len(names), lower))
        self.upper.append(np.full(len(names), upper))
        self.labels.extend(names)


def _add_model_constraints(
    g: _ConstraintList,
    log_compliance: Any,
    peak_torque: Any,
    normalisation: Any,
    thresholds: Any,
    motor_mass: Any,
    start_mass: np.ndarray,
    required_torque: Any,
    torque_demands: list[tuple[np.ndarray, np.ndarray, list[str]]],
    samples: ContactSamples,
    technology: ActuatorTechnology,
    constraints: Constraints,
    joint_names: tuple[str, ...],
) -> None:
    """The constraints of the model itself: reaction capacities within the joint torques, ``w^T x = 1`` for the
    finger-mass directions, the torque requirement and the sensing noise floor (symbolic arguments: the log
    reaction compliances (n_samples), peak torques and motor masses (n_joints), per-sample ``w^T x`` and
    contact thresholds)."""
    n_samples = samples.size
    # g_s + log tau_i >= log|w_si| for every loaded (sample, joint), i.e. 1/F_a >= |w_si| / tau_i.
    loaded = loaded_joints(samples)
    pair_sample, pair_joint = np.nonzero(loaded)
    log_arm = np.log(np.abs(samples.joint_moment_arms[pair_sample, pair_joint]))
    g.add(
        log_compliance[pair_sample.tolist()] + ca.log(peak_torque)[pair_joint.tolist()] - log_arm,
        0.0,
        np.inf,
        [
            f"reaction capacity of sample {s} within the torque of {joint_names[j]}"
            for s, j in zip(pair_sample, pair_joint, strict=True)
        ],
    )

    g.add(ca.transpose(normalisation), 1.0, 1.0, [f"w^T x = 1 at sample {s}" for s in range(n_samples)])

    # Torque: peak output torque covers the requirement in every sampled configuration, as linear constraints
    # scaled by the requirement at the start; only demands that can be the largest somewhere in the box of
    # motor masses allowed by the bounds can bind, the others are dropped (exactly).
    torque_scale = np.maximum(np.asarray(required_torque(start_mass)).ravel(), 1e-3)
    for j, (bases, slopes, demand_labels) in enumerate(torque_demands):
        demand = ca.DM(bases) + ca.mtimes(ca.DM(slopes), motor_mass)
        g.add(
            (peak_torque[j] - demand) / torque_scale[j],
            0.0,
            np.inf,
            [f"peak torque of {joint_names[j]} >= {label}" for label in demand_labels],
        )

    if technology.sensing == "position" and constraints.threshold_floor > 0:
        g.add(
            ca.transpose(thresholds) / constraints.threshold_floor,
            1.0,
            np.inf,
            [f"contact threshold of sample {s} >= noise floor" for s in range(n_samples)],
        )


def _design_quantities(
    layout: _Layout, z: Any, technology: ActuatorTechnology, k_mech: np.ndarray
) -> tuple[dict[str, Any], Any, Any, Any, Any]:
    """Symbolic joint quantities of the design variables ``z`` (log values): the variables themselves, the
    per-sample function's design column, motor masses [kg], peak output torques [N m] and the reflected inertia
    acting on the finger [kg m^2] (zero unless ``reflected_inertia_in == "finger"``)."""
    values = layout.expressions(z)
    motor = scaled_motor_quantities(
        technology.reference_motor, values["stator_diameter"], values["stack_length"], technology.scaling_law
    )
    gear = values["gear_ratio"]
    reflected = formulas.reflected_inertia(gear, motor.rotor_inertia)
    design_column = ca.vertcat(
        motor.mass,
        reflected,
        series_stiffness(ca.DM(k_mech), values["software_stiffness"]),
        values["threshold"],
        values["approach_velocity"],
    )
    finger_inertia = formulas.finger_inertia(reflected, technology.reflected_inertia_in)
    return values, design_column, motor.mass, gear * motor.peak_torque, finger_inertia


def _objective_weights(objective: str | Mapping[str, float]) -> dict[str, float]:
    weights = {objective: 1.0} if isinstance(objective, str) else dict(objective)
    if not weights:
        raise InvalidParameter("objective", objective, "an objective name or a non-empty {name: weight}")
    for name, weight in weights.items():
        _validate.choice("objective", name, tuple(OBJECTIVES))
        _validate.positive(f"weight of {name}", weight)
    return weights


def _feasible_gear_start(
    x0: np.ndarray,
    layout: _Layout,
    joint_numbers: Any,
    samples: ContactSamples,
    constraints: Constraints,
    joint_names: tuple[str, ...],
) -> None:
    """Move the start's free gear ratios up to where the peak torque covers the requirement (with 10 % to
    spare), within their bounds: IPOPT converges much faster from a torque-feasible start."""
    masses, torques, _ = (np.asarray(v).ravel() for v in joint_numbers(x0))
    rows, _ = _torque_requirement_rows(samples, constraints, joint_names)
    required = np.max([base + per_motor @ masses for base, per_motor in rows], axis=0)
    for joint, index in enumerate(layout.slices["gear_ratio"]):
        if index is not None and required[joint] > torques[joint]:
            x0[index] = min(
                x0[index] + math.log(1.1 * required[joint] / torques[joint]),
                math.log(layout.bounds["gear_ratio"][joint].upper),
            )


def _with_noise_floor(bounds: Bounds, floor: float) -> Bounds:
    """With force sensing the noise floor [N] is a lower bound on the threshold variable itself."""
    if floor <= 0:
        return bounds
    if bounds.upper < floor:
        raise InvalidParameter(
            "threshold bounds",
            (bounds.lower, bounds.upper),
            f"an upper bound >= the sensing noise floor {floor} N",
            "raise the threshold's upper bound or lower the floor",
        )
    return Bounds(max(bounds.lower, floor), bounds.upper, "threshold")


def _sample_function(n_joints: int, sensing: str, reaction: str, reflected_inertia_in: str) -> Any:
    """SX function of one contact sample.

    Inputs: the design column (motor masses, reflected inertias, joint stiffnesses (n each), threshold,
    approach velocity), the finger-mass direction ``x`` (n, with ``w^T x = 1``), the reaction compliance ``c``
    (``1/F_a`` [1/N]) and the sample's data (``w = J^T u`` (n), ``M_bb0`` (n*n), motor-mass influence matrices
    (n*n*n), effective mechanical stiffness). Outputs: the impulse [N*s], the contact-force threshold [N],
    ``w^T x`` and the effective parameters ``(m_f, m_r, k, k_m, a)`` of :mod:`collision_reflex.model.effective`.
    """
    n = n_joints
    design = ca.SX.sym("design", 3 * n + 2)
    direction = ca.SX.sym("x", n)
    compliance = ca.SX.sym("c")
    data = ca.SX.sym("data", n + n * n + n**3 + 1)
    mass, inertia, stiffness = (design[i * n : (i + 1) * n] for i in range(3))
    threshold_variable, velocity = design[3 * n], design[3 * n + 1]
    w = data[:n]
    offset = n + n * n
    influence = [ca.reshape(data[offset + i * n * n : offset + (i + 1) * n * n], n, n) for i in range(n)]
    finger_matrix = formulas.finger_mass_matrix(
        ca.reshape(data[n:offset], n, n),
        influence,
        mass,
        inertia if reflected_inertia_in == "finger" else None,
    )
    # x^T M_f x: the finger mass at the optimal x (the NLP's constraint w^T x = 1 and its minimisation).
    finger_mass = formulas.finger_mass(direction, finger_matrix)
    k_mech = data[-1]

    # Effective parameters along u (MODEL.md §3), compliance forms; w^T is the Jacobian along u.
    robot_compliance = formulas.task_compliance(ca.transpose(w), inertia)
    k = 1 / formulas.task_compliance(ca.transpose(w), stiffness)
    force_threshold = threshold_force(sensing, threshold_variable, k)
    acceleration = formulas.reaction_acceleration(robot_compliance, compliance)
    impulse = phase_impulses(finger_mass, k, k_mech, force_threshold, acceleration, velocity, reaction).total
    parameters = ca.vertcat(finger_mass, 1 / robot_compliance, k, k_mech, acceleration)
    return ca.Function(
        "sample_impulse",
        [design, direction, compliance, data],
        [impulse, force_threshold, ca.dot(w, direction), parameters],
    )


def _sample_data(samples: ContactSamples, k_mech: np.ndarray) -> np.ndarray:
    """Numeric data column per sample (see :func:`_sample_function`), shape (rows, n_samples)."""
    kin = samples.kinematics
    w = samples.joint_moment_arms
    n_samples, n = w.shape
    unreachable = ~np.any(loaded_joints(samples), axis=1)
    if np.any(unreachable):
        bad = int(np.flatnonzero(unreachable)[0])
        raise InvalidParameter(
            f"sample {bad}",
            samples.directions[bad],
            "a direction the arm can move along (J^T u != 0)",
            "drop samples at singular configurations along their singular direction",
        )
    structure = kin.mass_matrix[samples.config_index].reshape(n_samples, n * n, order="F")
    influence = (
        kin.motor_mass_influence[samples.config_index].transpose(0, 1, 3, 2).reshape(n_samples, n * n * n)
    )
    k_mech_effective = 1 / formulas.task_compliance(w[:, None, :], k_mech)[:, 0, 0]
    return np.column_stack([w, structure, influence, k_mech_effective]).T


def reaction_compliance(samples: ContactSamples, peak_torque: np.ndarray) -> np.ndarray:
    """``1 / F_a = max_i |w_i| / tau_i`` per sample [1/N]: the inverse of the largest contact force the joints
    can push back with before the first saturates (MODEL.md §3)."""
    return np.asarray(
        formulas.reaction_compliance(
            formulas.torque_fractions(samples.joint_moment_arms, np.asarray(peak_torque, dtype=float))
        )
    )


def finger_mass_directions(
    samples: ContactSamples, motor_mass: np.ndarray, finger_joint_inertia: np.ndarray | None = None
) -> np.ndarray:
    """The minimiser ``x_s = M_f^-1 w_s / (w_s^T M_f^-1 w_s)`` of ``x^T M_f x`` with ``w_s^T x = 1`` for every
    sample, (n_samples, n_joints): ``M_f`` the structure mass matrix with motor masses ``m`` [kg] and, when the
    reflected inertia acts on the finger, ``diag(N^2 J_m)`` [kg m^2]."""
    kin = samples.kinematics
    index = samples.config_index
    structure = formulas.finger_mass_matrix(
        kin.mass_matrix[index], kin.motor_mass_influence[index], motor_mass, finger_joint_inertia
    )
    return np.asarray(formulas.finger_mass_direction(samples.joint_moment_arms, structure))


def loaded_joints(samples: ContactSamples) -> np.ndarray:
    """(n_samples, n_joints) True where a contact force along the sample's direction loads the joint, so its
    torque limit bounds the reaction force; ``|w_i|`` below 1e-12 of the largest counts as unloaded."""
    w = np.abs(samples.joint_moment_arms)
    return w > 1e-12 * np.maximum(w.max(axis=1, keepdims=True), 1e-300)


def _torque_requirement_rows(
    samples: ContactSamples, constraints: Constraints, joint_names: tuple[str, ...]
) -> tuple[list[tuple[np.ndarray, np.ndarray]], list[str]]:
    """Affine torque demands ``d0 + D m`` [N m] (``m``: motor masses [kg]) the peak torques must cover.

    Given torques: one demand. Otherwise, per sampled configuration, plus and minus the gravity torque of the
    structure, the motors (linear in their masses) and the payload at the contact point, all times the safety
    factor.
    """
    n = len(joint_names)
    factor = constraints.safety_factor
    if constraints.torque_required is not None:
        given = np.asarray(constraints.torque_required, dtype=float)
        if given.shape != (n,):
            raise InvalidParameter("torque_required", given.shape, f"{n} values, one per joint")
        return [(factor * given, np.zeros((n, n)))], ["the given required torque"]
    kin = samples.kinematics
    rows, labels = [], []
    for c in np.unique(samples.config_index):
        base = kin.gravity[c] + constraints.payload * kin.contact_gravity[c]
        per_motor = kin.motor_gravity[c].T  # (joint j, motor i)
        for sign, word in ((1.0, "+"), (-1.0, "-")):
            rows.append((sign * factor * base, sign * factor * per_motor))
            labels.append(f"{word}gravity torque at configuration {c}")
    return rows, labels


def _binding_torque_demands(
    samples: ContactSamples,
    constraints: Constraints,
    joint_names: tuple[str, ...],
    mass_low: np.ndarray,
    mass_high: np.ndarray,
) -> list[tuple[np.ndarray, np.ndarray, list[str]]]:
    """Per joint, the torque demands ``b + S m`` [N m] that can bind: ``(b (R,), S (R, n), labels)``.

    A demand whose largest value over the box of motor masses ``[mass_low, mass_high]`` [kg] is below another
    demand's smallest value there never sets the requirement, so it is left out: an exact reduction (on arms,
    from two rows per sampled configuration to a handful).
    """
    rows, labels = _torque_requirement_rows(samples, constraints, joint_names)
    demands = []
    for j in range(len(joint_names)):
        bases = np.array([base[j] for base, _ in rows])
        slopes = np.array([per_motor[j] for _, per_motor in rows])
        low = bases + np.minimum(slopes * mass_low, slopes * mass_high).sum(axis=1)
        high = bases + np.maximum(slopes * mass_low, slopes * mass_high).sum(axis=1)
        keep = high >= low.max() - 1e-12 * abs(low.max())
        demands.append(
            (bases[keep], slopes[keep], [label for label, k in zip(labels, keep, strict=True) if k])
        )
    return demands


def _required_torque_function(demands: list[tuple[np.ndarray, np.ndarray, list[str]]], n_joints: int) -> Any:
    """CasADi function: motor masses [kg] -> required peak torque per joint [N m], the largest binding demand
    (safety factor included), for reporting."""
    masses = ca.MX.sym("motor_mass", n_joints)
    required = [ca.mmax(ca.DM(bases) + ca.mtimes(ca.DM(slopes), masses)) for bases, slopes, _ in demands]
    return ca.Function("required_torque", [masses], [ca.vertcat(*required)])


def _check_finite(values: np.ndarray, what: str, samples: ContactSamples) -> None:
    if not np.all(np.isfinite(values)):
        bad = int(np.flatnonzero(~np.isfinite(values))[0])
        raise InvalidParameter(
            what,
            f"non-finite at sample {bad} (direction {samples.directions[bad]})",
            "finite values at every sample",
            "check the arm's mass matrix and the bounds, or drop singular samples",
        )
