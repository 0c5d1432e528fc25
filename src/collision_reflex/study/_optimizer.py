"""The one place where arm studies call the optimiser (:mod:`collision_reflex.optimize`), the arm and the motors.

It turns a validated arm study into the optimiser's inputs (design space, actuator technology, constraints,
contact samples), solves single points of a Pareto sweep (anchors and epsilon-bounded points) and turns each
result into a plain record (JSON types) with everything the report shows.

Workers in other processes rebuild the problem from the resolved study text; :func:`problem_for` caches the
built problems per process, so that a worker builds each objective's problem once.
"""

from __future__ import annotations

import functools
import math
import threading
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import StudyFileError, StudyProblem
from ..model.impulse import optimal_velocity, phase_impulses, series_stiffness
from .load import LoadedStudy, parse_study
from .prepare import check_motors, joint_actuators, per_joint_bounds
from .robot import load_arm
from .samples import configuration_samples, direction_samples
from .schema import PER_JOINT_DESIGN_VARIABLES, ArmStudy

_SOLVER_LOCK = threading.RLock()
"""CasADi functions, IPOPT and (sequential) MUMPS are not thread-safe: within one process the tasks below run one
at a time (a Dask worker with several threads, for instance); parallelism comes from processes."""

IPOPT_OPTIONS = {"ipopt.max_iter": 400}


def single_threaded_blas() -> Any:
    """A context with every BLAS (NumPy's, and the OpenBLAS that CasADi bundles for IPOPT and MUMPS) on one
    thread.

    A threaded BLAS sums in an order that depends on its thread count, and Dask workers pin it to one thread
    where a plain process does not; the difference moves IPOPT's iterates and so the results, within the solver
    tolerance. With one thread everywhere, every executor gives the same numbers, bitwise in practice
    (parallelism comes from the executor's processes).
    """
    import threadpoolctl

    if not _CASADI_BLAS_REGISTERED:
        threadpoolctl.register(_casadi_openblas_controller())
        _CASADI_BLAS_REGISTERED.append(True)
    return threadpoolctl.threadpool_limits(limits=1)


_CASADI_BLAS_REGISTERED: list[bool] = []


def _casadi_openblas_controller() -> Any:
    from threadpoolctl import OpenBLASController

    class CasadiOpenBLAS(OpenBLASController):
        """CasADi's bundled OpenBLAS, which threadpoolctl does not know by its file name."""

        internal_api = "casadi_openblas"
        filename_prefixes = ("libcasadi-tp-openblas",)

    return CasadiOpenBLAS


"""Options over the optimiser's defaults for study runs (a cap keeps a hopeless Pareto point from stalling a run)."""


@dataclass(frozen=True)
class ArmSetup:
    """Everything an arm study's solves need, built once per process.

    arm: the :class:`collision_reflex.arm.core.Arm`; catalogue: the motor catalogue by name; configurations: (n, nq)
    [rad]; directions: (m, task_dim) unit vectors; samples: the optimiser's contact samples (every configuration
    with every direction); space, technology, constraints: the optimiser's inputs.
    """

    study: ArmStudy
    arm: Any
    catalogue: dict[str, Any]
    configurations: np.ndarray
    directions: np.ndarray
    samples: Any
    space: Any
    technology: Any
    constraints: Any


def arm_setup(loaded: LoadedStudy) -> ArmSetup:
    """Load the robot and motors and translate the study into the optimiser's inputs; every problem located."""
    from ..optimize import ActuatorTechnology, Bounds, Constraints, ContactSamples, DesignSpace

    study = loaded.study
    assert isinstance(study, ArmStudy)
    catalogue = check_motors(loaded)
    arm = load_arm(loaded)
    joints = list(arm.joint_names)
    actuators = joint_actuators(study, joints)
    _check_supported(loaded, study)
    reference_spec = study.actuators.motor
    reference = catalogue[reference_spec.reference]

    def nominal(name: str, values: list[float]) -> list[Any]:
        spec = getattr(study.design, name)
        if spec is None:
            return [Bounds.fixed(v, f"{name}[{j}]") for v, j in zip(values, joints, strict=True)]
        return [
            Bounds(lo, hi, f"{name}[{j}]")
            for (lo, hi), j in zip(per_joint_bounds(spec, joints), joints, strict=True)
        ]

    diameters = [a.motor.stator_diameter or reference.stator_diameter for a in actuators]
    stacks = [a.motor.stack_length or reference.stack_length for a in actuators]
    scheme = study.sensing.scheme
    threshold_spec = study.design.threshold if scheme == "force" else study.design.position_error
    velocity_spec = study.design.approach_velocity
    space = DesignSpace(
        stator_diameter=nominal("stator_diameter", diameters),
        stack_length=nominal("stack_length", stacks),
        gear_ratio=nominal("gear_ratio", [a.gear_ratio for a in actuators]),
        software_stiffness=nominal("software_stiffness", [a.software_stiffness for a in actuators]),
        threshold=Bounds(*threshold_spec.bounds, "threshold") if threshold_spec else study.sensing.value,
        approach_velocity=Bounds(*velocity_spec.bounds, "approach_velocity")
        if velocity_spec
        else study.approach_velocity,
    )
    technology = ActuatorTechnology(
        reference_motor=reference,
        mechanical_stiffness=[a.mechanical_stiffness for a in actuators],
        scaling_law=reference_spec.scaling_law,
        sensing=scheme,
        reaction=study.reaction,
        reflected_inertia_in=study.reflected_inertia_in,
    )
    constraints = Constraints(
        payload=study.constraints.payload,
        safety_factor=study.constraints.safety_factor,
        torque_required=study.constraints.torque_required,
        threshold_floor=study.constraints.threshold_floor,
    )
    configurations = configuration_samples(loaded, arm)
    directions = direction_samples(loaded, arm)
    samples = ContactSamples.grid(arm.kinematics(configurations), directions)
    return ArmSetup(
        study, arm, catalogue, configurations, directions, samples, space, technology, constraints
    )


def _check_supported(loaded: LoadedStudy, study: ArmStudy) -> None:
    """Refuse, at their lines, the study features the arm optimiser does not model."""
    problems: list[StudyProblem] = []
    base = study.actuators.motor
    for joint, override in study.actuators.joints.items():
        motor = override.motor
        if motor is not None and (motor.reference != base.reference or motor.scaling_law != base.scaling_law):
            problems.append(
                loaded.problem(
                    ("actuators", "joints", joint, "motor"),
                    "a different reference motor or law",
                    "the same reference motor and scaling law for every joint (the optimiser scales one "
                    "reference); override stator_diameter or stack_length only",
                )
            )
        if override.gearbox is not None:
            problems.append(_gearbox_problem(loaded, ("actuators", "joints", joint, "gearbox")))
    if study.actuators.gearbox is not None:
        problems.append(_gearbox_problem(loaded, ("actuators", "gearbox")))
    if problems:
        raise StudyFileError(loaded.source.file, problems)


def _gearbox_problem(loaded: LoadedStudy, path: tuple[Any, ...]) -> StudyProblem:
    return loaded.problem(
        path,
        "a gearbox in an arm study",
        "null: the arm optimiser's actuator mass and inertia are the motor's (gear ratio only); "
        "compare gearboxes in an actuator study (kind: actuator)",
    )


@functools.lru_cache(maxsize=4)
def _setup_from_text(resolved_text: str) -> ArmSetup:
    with single_threaded_blas():  # the same arithmetic in every process (see single_threaded_blas)
        return arm_setup(parse_study(resolved_text, "resolved study"))


@functools.lru_cache(maxsize=16)
def problem_for(resolved_text: str, objective: str, bounded: tuple[str, ...]) -> Any:
    """The design problem minimising ``objective`` with ``bounded`` objectives, built once per process (its
    solvers are reused by later tasks; the results do not depend on which task came first).
    """
    from ..optimize import build_problem

    setup = _setup_from_text(resolved_text)
    return build_problem(
        setup.arm, setup.samples, setup.space, setup.technology, objective, setup.constraints, bounded
    )


# --- tasks (run in workers: plain data in, plain data out) -------------------------------------------------------


def _one_at_a_time(function: Any) -> Any:
    """Run a task under the solver lock; a solver failure leaves it as a plain, picklable error."""

    @functools.wraps(function)
    def locked(*args: Any, **kwargs: Any) -> Any:
        from ..errors import SolverFailed, StudyRunFailed

        with _SOLVER_LOCK, single_threaded_blas():
            try:
                return function(*args, **kwargs)
            except SolverFailed as error:
                what = function.__name__.removeprefix("solve_")
                raise StudyRunFailed(
                    f"the {what} solve failed: {error.args[0] if error.args else error}", what, error.status
                ) from None

    return locked


@_one_at_a_time
def solve_single(resolved_text: str) -> dict[str, Any]:
    """Solve the study's own objective; returns a design record."""
    from ..optimize import solve

    setup = _setup_from_text(resolved_text)
    problem = _weighted_problem(
        resolved_text, _objective_key({str(k): float(v) for k, v in setup.study.objective.items()})
    )
    return design_record(setup, problem, solve(problem, ipopt_options=IPOPT_OPTIONS), "optimum")


@functools.lru_cache(maxsize=4)
def _weighted_problem(resolved_text: str, key: Any) -> Any:
    from ..optimize import build_problem

    setup = _setup_from_text(resolved_text)
    objective = key if isinstance(key, str) else dict(key)
    return build_problem(
        setup.arm, setup.samples, setup.space, setup.technology, objective, setup.constraints
    )


@_one_at_a_time
def solve_anchor(resolved_text: str, objective: str, objectives: tuple[str, ...]) -> dict[str, Any]:
    """A Pareto anchor: ``objective`` optimised, then (lexicographically) each other objective with it held at
    its optimum, so that the anchor is not dominated. A lexicographic step the solver cannot do keeps the
    anchor found so far (the dominance filter then judges it) and is recorded in ``lexicographic_failed``.
    """
    from ..errors import SolverFailed, StudyRunFailed
    from ..optimize import solve
    from ..optimize.pareto import anchor_bound

    setup = _setup_from_text(resolved_text)
    others = tuple(o for o in objectives if o != objective)
    try:
        result = solve(problem_for(resolved_text, objective, others), ipopt_options=IPOPT_OPTIONS)
    except SolverFailed as error:
        raise StudyRunFailed(
            f"the Pareto anchor of {objective} could not be solved: {error.args[0] if error.args else error}",
            f"anchor: {objective}",
            error.status,
        ) from None
    held = anchor_bound(objective, result.objectives[objective])
    failed = []
    for other in others:
        bounded = tuple(o for o in objectives if o != other)
        try:
            result = solve(
                problem_for(resolved_text, other, bounded),
                epsilon={objective: held},
                x0=result.x,
                ipopt_options=IPOPT_OPTIONS,
            )
        except SolverFailed as error:
            failed.append({"objective": other, "status": error.status})
    record = design_record(
        setup, problem_for(resolved_text, objective, others), result, f"anchor: {objective}"
    )
    record["x"] = result.x.tolist()
    record["lexicographic_failed"] = failed
    return record


@dataclass(frozen=True)
class _Saved:
    """A saved design record seen as the optimiser's sweep helpers see a result (its NumPy objectives)."""

    record: dict[str, Any]

    @property
    def numpy_objectives(self) -> dict[str, float]:
        objectives: dict[str, float] = self.record["objectives"]
        return objectives


def epsilon_grid(
    anchors: dict[str, dict[str, Any]], objectives: tuple[str, ...], count: int
) -> list[dict[str, float]]:
    """The sweep's objective bounds between the saved anchors: the optimiser's own epsilon grid."""
    from ..optimize import pareto

    saved: dict[str, Any] = {name: _Saved(a) for name, a in anchors.items()}
    return pareto.epsilon_grid(saved, objectives[1:], count)


def non_dominated(
    records: list[dict[str, Any]], names: tuple[str, ...]
) -> tuple[list[dict[str, Any]], list[dict[str, Any]]]:
    """Saved records split by the optimiser's dominance filter into the front (sorted by the first objective)
    and the dominated rest.
    """
    from ..optimize import pareto

    if not records:
        return [], []
    saved: list[Any] = [
        _Saved(r) for r in records
    ]  # duck-typed as DesignResult: only numpy_objectives is read
    front, dropped = pareto.non_dominated(saved, names)
    return [s.record for s in front], [s.record for s in dropped]  # type: ignore[attr-defined]


@_one_at_a_time
def solve_point(
    resolved_text: str, objectives: tuple[str, ...], epsilon: dict[str, float], start: list[float]
) -> dict[str, Any]:
    """One epsilon-constraint point: the first objective minimised with the others bounded by ``epsilon``,
    started from ``start`` (the first objective's anchor, so the result does not depend on the order of work).
    """
    from ..errors import SolverFailed
    from ..optimize import solve

    setup = _setup_from_text(resolved_text)
    problem = problem_for(resolved_text, objectives[0], objectives[1:])
    try:
        result = solve(problem, epsilon=epsilon, x0=np.asarray(start), ipopt_options=IPOPT_OPTIONS)
    except SolverFailed as error:
        return {"failed": True, "epsilon": epsilon, "status": error.status, "message": str(error.args[0])}
    return design_record(
        setup, problem, result, "epsilon: " + ", ".join(_bound_text(k, v) for k, v in epsilon.items())
    )


def _bound_text(name: str, value: float) -> str:
    """``mass <= 0.1`` for a minimised objective, ``approach_velocity >= 0.4`` for a maximised one."""
    from ..optimize import OBJECTIVES

    return f"{name} {'<=' if OBJECTIVES[name][0] > 0 else '>='} {value:.4g}"


# --- records -----------------------------------------------------------------------------------------------------


def design_record(setup: ArmSetup, problem: Any, result: Any, label: str) -> dict[str, Any]:
    """A design and everything the report shows about it, as JSON types (SI units)."""
    from ..optimize.evaluate import design_collision_parameters

    design = result.design
    # The optimiser's own NumPy check (optimize.evaluate), kept here for the phases.
    params, threshold = design_collision_parameters(problem, design)
    phases = phase_impulses(
        params.m_f, params.k, params.k_m, threshold, params.a, design.approach_velocity, setup.study.reaction
    )
    v_star = optimal_velocity(params.m_f, params.k, threshold, setup.study.reaction, params.k_m, params.a)
    joints = []
    for i, name in enumerate(design.joint_names):
        joints.append(
            {
                "joint": name,
                "stator_diameter": float(design.stator_diameter[i]),
                "stack_length": float(design.stack_length[i]),
                "gear_ratio": float(design.gear_ratio[i]),
                "rotor_inertia": float(design.rotor_inertia[i]),
                "reflected_inertia": float(design.reflected_inertia[i]),
                "motor_peak_torque": float(design.motor_peak_torque[i]),
                "peak_torque": float(design.peak_torque[i]),
                "required_torque": float(result.required_torque[i]),
                # No requirement (a joint gravity does not load): a margin is meaningless, not a huge number.
                "torque_margin": (
                    float(result.torque_margin[i])
                    if result.required_torque[i] > 1e-9 * design.peak_torque[i]
                    else None
                ),
                "mechanical_stiffness": float(design.mechanical_stiffness[i]),
                "software_stiffness": float(design.software_stiffness[i]),
                "stiffness": float(
                    series_stiffness(design.mechanical_stiffness[i], design.software_stiffness[i])
                ),
                "motor_mass": float(design.motor_mass[i]),
                "nearest_catalogue_motor": nearest_catalogue_motor(
                    setup.catalogue, float(design.motor_peak_torque[i]), float(design.rotor_inertia[i])
                ),
            }
        )
    return {
        "label": label,
        "objectives": {k: float(v) for k, v in result.numpy_objectives.items()},
        "casadi_objectives": {k: float(v) for k, v in result.objectives.items()},
        "threshold": float(design.threshold),
        "sensing": design.sensing,
        "approach_velocity": float(design.approach_velocity),
        "joints": joints,
        "impulses": np.asarray(result.impulses, dtype=float).tolist(),
        "phases": {
            "initial": np.broadcast_to(phases.initial, params.m_f.shape).tolist(),
            "sensing": np.broadcast_to(phases.sensing, params.m_f.shape).tolist(),
            "reaction": np.broadcast_to(phases.reaction, params.m_f.shape).tolist(),
        },
        "optimal_velocity": np.asarray(v_star, dtype=float).tolist(),
        "solver": {
            "status": result.status,
            "iterations": int(result.iterations),
            "solve_time": float(result.solve_time),
            "build_time": float(result.build_time),
            "epsilon": {k: float(v) for k, v in result.epsilon.items()},
        },
    }


def nearest_catalogue_motor(catalogue: dict[str, Any], peak_torque: float, rotor_inertia: float) -> str:
    """The catalogue motor closest to a scaled motor in (log peak torque, log rotor inertia): the off-the-shelf
    part a designer would start from.
    """
    best, best_distance = "", math.inf
    for name, motor in catalogue.items():
        distance = math.hypot(
            math.log(motor.peak_torque / peak_torque), math.log(motor.rotor_inertia / rotor_inertia)
        )
        if distance < best_distance:
            best, best_distance = name, distance
    return best


def sample_layout(setup: ArmSetup) -> dict[str, Any]:
    """Where each sample comes from (for the report's surfaces): configuration index and direction per sample."""
    return {
        "configurations": setup.configurations.tolist(),
        "directions": setup.directions.tolist(),
        "config_index": setup.samples.config_index.tolist(),
        "sample_directions": setup.samples.directions.tolist(),
        "joint_names": list(setup.arm.joint_names),
        "task_dim": int(setup.arm.task_dim),
    }


def checked_setup(loaded: LoadedStudy, resolved_text: str) -> ArmSetup:
    """The setup of a study, with its problem built once: every input problem (robot, frames, samples on which
    the arm cannot move, impossible bounds) is raised here, located in the study file, before a run writes
    anything.
    """
    from ..errors import InvalidParameter

    setup = arm_setup(loaded)  # located errors for the robot, motors and names
    problems = _torque_out_of_reach(loaded, setup)
    if problems:
        raise StudyFileError(loaded.source.file, problems)
    try:
        _setup_from_text(resolved_text)
        objective = {str(k): float(v) for k, v in setup.study.objective.items()}
        _weighted_problem(resolved_text, _objective_key(objective))
    except InvalidParameter as error:
        raise loaded.fail(_field_of(error.name), f"{error}", "inputs the design problem accepts") from None
    return setup


def _torque_out_of_reach(loaded: LoadedStudy, setup: ArmSetup) -> list[StudyProblem]:
    """Given torque requirements no design within the bounds can meet: the largest motor at the largest gear
    ratio (torque grows with motor size under every scaling law) short of the safety factor times the need.
    """
    from ..hardware.motors import scaled_motor_quantities

    required = setup.study.constraints.torque_required
    if required is None:
        return []
    joints = list(setup.arm.joint_names)
    n = len(joints)
    reference = setup.technology.reference_motor
    diameters = setup.space.per_joint("stator_diameter", n)
    stacks = setup.space.per_joint("stack_length", n, reference.stack_length)
    gears = setup.space.per_joint("gear_ratio", n)
    factor = setup.study.constraints.safety_factor
    problems = []
    for i, joint in enumerate(joints):
        motor = scaled_motor_quantities(
            reference, diameters[i].upper, stacks[i].upper, setup.technology.scaling_law
        )
        reachable = gears[i].upper * float(motor.peak_torque)
        if factor * required[i] > reachable * (1 + 1e-9):
            problems.append(
                loaded.problem(
                    ("constraints", "torque_required", i),
                    f"{required[i]:g} N*m for {joint} (x {factor:g} safety)",
                    f"at most {reachable:.4g} N*m, the peak torque of the largest motor at the largest gear "
                    "ratio; widen design.stator_diameter or design.gear_ratio, or lower the requirement",
                )
            )
    return problems


def _field_of(name: str) -> tuple[str, ...]:
    """The study field an optimiser parameter comes from (for locating its errors)."""
    root = name.split("[")[0].split(" ")[0]
    if root in PER_JOINT_DESIGN_VARIABLES or root in ("threshold", "approach_velocity"):
        return ("design", root)
    if root in ("payload", "safety_factor", "torque_required", "threshold_floor"):
        return ("constraints", root)
    if root in ("sample", "directions", "config_index"):
        return ("samples",)
    return ()


def _objective_key(objective: dict[str, float]) -> Any:
    """A hashable key for the study's objective: its name alone when it is a single unweighted objective."""
    if len(objective) == 1 and next(iter(objective.values())) == 1.0:
        return next(iter(objective))
    return tuple(sorted(objective.items()))


def setup_from_text(resolved_text: str) -> ArmSetup:
    """The (cached) setup of a resolved study."""
    return _setup_from_text(resolved_text)
