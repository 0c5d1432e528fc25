"""Solve a :class:`DesignProblem` with IPOPT and return the design with every objective and margin."""

from __future__ import annotations

import time
import warnings
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, Any, NamedTuple

import numpy as np

from .. import _validate
from .._interrupt import interruptible
from ..errors import InvalidParameter, SolverFailed, Violation
from .blas import single_threaded_blas
from .constraints import STATIC_REQUIREMENT
from .duty import duty_values
from .evaluate import evaluate_design
from .feasibility import solve_feasibility
from .objectives import OBJECTIVES, objective_values
from .problem import DesignProblem

if TYPE_CHECKING:
    from .layout import DesignLayout
    from .technology import ActuatorTechnology

IpoptOptions = Mapping[str, str | float]
"""Options of CasADi's ``nlpsol`` with IPOPT (``"ipopt.<option>"`` and CasADi's own): strings, numbers, flags."""

DEFAULT_IPOPT_OPTIONS: dict[str, str | float] = {
    # For an NLP that CasADi differentiates itself (the feasibility solve): expanding its MX graph (mapped
    # per-sample functions) to SX makes every derivative evaluation much cheaper. The
    # design solvers get SX functions assembled per sample (DesignProblem.solver), nothing to expand.
    "expand": True,
    "ipopt.print_level": 0,
    "ipopt.sb": "yes",
    "print_time": False,
    "ipopt.tol": 1e-8,
    "ipopt.max_iter": 500,
    # Monotone barrier from mu = 1e-2: on arm problems (benchmarks/optimize_panda.py's) fewer iterations than
    # the adaptive strategy, to the same optimum.
    "ipopt.mu_strategy": "monotone",
    "ipopt.mu_init": 1e-2,
    "ipopt.linear_solver": "mumps",
    # No scaling of the KKT matrix by MUMPS (neither its row and column scaling nor its permuting scaling):
    # with its default (automatic) choice the KKT matrices of the UR5 study's fast points needed delayed
    # pivots, far more memory than MUMPS estimates and slow iterations; its option 8 avoids that, and without
    # scaling the iterations and optimum are those of option 8 again, in less CPU.
    "ipopt.mumps_scaling": 0,
    "ipopt.mumps_permuting_scaling": 0,
    # METIS ordering (MUMPS chose QAMD): on the Panda benchmark the same iterations and optimum in less IPOPT
    # time, most of which is MUMPS's factorizations (the inertia correction refactorizes), and on the UR5
    # study's sweep alike. Skipping the residual check of each step (fast_step_computation) saved more time on
    # the Panda but cost the UR5 sweep iterations.
    "ipopt.mumps_pivot_order": 5,
}
WARM_START_OPTIONS: dict[str, str | float] = {
    # Start from a neighbouring solution's primal and dual point, close to the central path.
    "ipopt.warm_start_init_point": "yes",
    "ipopt.warm_start_bound_push": 1e-6,
    "ipopt.warm_start_mult_bound_push": 1e-6,
    "ipopt.mu_init": 1e-4,
    # From a solution's multipliers the adaptive barrier needs fewer iterations than the monotone one (the
    # Panda benchmark's epsilon points from the anchor).
    "ipopt.mu_strategy": "adaptive",
}
AGREEMENT_TOLERANCE = 1e-6
"""Largest relative difference allowed between the CasADi and NumPy evaluations of a design's objectives:
both evaluate the same closed forms in double precision, so any larger difference is a modelling bug."""


RETRIES = (
    # Another barrier strategy from the same start: the monotone barrier's parameter can reach ~1e-9 before
    # convergence, after which IPOPT's restoration phase may wrongly report infeasibility.
    ("adaptive barrier", {"ipopt.mu_strategy": "adaptive"}, "start"),
    # The problem's own start: the log-midpoint design with the gear ratios raised to cover the torques.
    ("default start, adaptive barrier", {"ipopt.mu_strategy": "adaptive"}, "default"),
)
"""What :func:`solve` tries after a failed solve, in order: (name, options merged over the requested ones,
start). After these, an elastic feasibility solve (:mod:`.feasibility`) decides: infeasible (raised) or a
feasible point, from which a last attempt (``"feasible start, adaptive barrier"``) starts."""
CONVERGED = ("Solve_Succeeded", "Solved_To_Acceptable_Level")
"""IPOPT statuses whose point is kept; the status is kept in the result (an acceptable point is marked)."""


class Attempt(NamedTuple):
    """One IPOPT run of :func:`solve`: its name (see :data:`RETRIES`), status, iterations and time [s]."""

    name: str
    status: str
    iterations: int
    solve_time: float


@dataclass(frozen=True)
class Design:
    """An actuator design for every joint of an arm, with the quantities derived from it (SI units).

    Per joint (arrays of length n_joints): ``stator_diameter`` [m], ``stack_length`` [m], ``gear_ratio`` [-],
    ``software_stiffness`` and ``mechanical_stiffness`` [N m/rad], ``rotor_inertia`` [kg m^2],
    ``reflected_inertia`` = N^2 (J_m + J_g) [kg m^2] (``J_g`` the gearbox's input inertia where counted),
    ``motor_peak_torque`` [N m], ``peak_torque`` = N tau_p [N m], ``motor_mass`` [kg] (the motor's own).
    Global: ``threshold`` ([N] for force sensing, [m] for position sensing) and ``approach_velocity`` [m/s].
    Per joint, its gearbox: ``gearbox`` its catalogue name ("" for none), ``gearbox_mass`` [kg],
    ``gearbox_inertia`` its input-side inertia [kg m^2] (as the catalogue gives it, also when the reflected
    inertia leaves it out), ``gearbox_efficiency`` [-] (1 without a gearbox). Left out, there are none.
    """

    joint_names: tuple[str, ...]
    stator_diameter: np.ndarray
    stack_length: np.ndarray
    gear_ratio: np.ndarray
    software_stiffness: np.ndarray
    mechanical_stiffness: np.ndarray
    rotor_inertia: np.ndarray
    reflected_inertia: np.ndarray
    motor_peak_torque: np.ndarray
    peak_torque: np.ndarray
    motor_mass: np.ndarray
    threshold: float
    approach_velocity: float
    sensing: str
    gearbox: tuple[str, ...] = ()
    gearbox_mass: np.ndarray = field(default_factory=lambda: np.empty(0))
    gearbox_inertia: np.ndarray = field(default_factory=lambda: np.empty(0))
    gearbox_efficiency: np.ndarray = field(default_factory=lambda: np.empty(0))

    def __post_init__(self) -> None:
        n = len(self.joint_names)
        if not self.gearbox:
            object.__setattr__(self, "gearbox", ("",) * n)
        for name, absent in (("gearbox_mass", 0.0), ("gearbox_inertia", 0.0), ("gearbox_efficiency", 1.0)):
            value = np.asarray(getattr(self, name), dtype=float)
            object.__setattr__(self, name, np.full(n, absent) if value.size == 0 else value)

    @property
    def actuator_mass(self) -> np.ndarray:
        """Per joint the mass carried at the joint [kg]: the motor's and the gearbox's."""
        return self.motor_mass + self.gearbox_mass

    @property
    def driving_peak_torque(self) -> np.ndarray:
        """Per joint the peak output torque that drives the arm ``eta N tau_p`` [N m]."""
        return self.gearbox_efficiency * self.peak_torque

    def as_dict(self) -> dict[str, Any]:
        """Plain lists and floats, for JSON."""
        out: dict[str, Any] = {}
        for name, value in self.__dict__.items():
            out[name] = (
                value.tolist()
                if isinstance(value, np.ndarray)
                else (list(value) if isinstance(value, tuple) else value)
            )
        return out


@dataclass(frozen=True)
class DesignResult:
    """An optimised design and how it was found.

    objectives: every objective of :data:`OBJECTIVES` from the CasADi model [its unit].
    numpy_objectives: the same re-evaluated through the NumPy path; the two agree to
        :data:`AGREEMENT_TOLERANCE` (relative).
    impulses: (n_samples,) collision impulse per sample [N*s] (NumPy path).
    required_torque, torque_margin: per joint, the required peak torque [N m] (safety factor included) and
        ``eta peak_torque / required_torque - 1`` (``eta`` the gearbox efficiency, 1 without one).
    requirement: what sized the torques (:attr:`collision_reflex.optimize.Constraints.requirement`), e.g.
        ``"static (gravity only)"``.
    required_rms_torque, rms_margin: per joint, the RMS torque over the duty cycle [N m] and
        ``eta N tau_c / RMS - 1``; None without a duty cycle.
    max_motor_speed, speed_limit, speed_margin: per joint, the motor speed ``N max |qd|`` over the cycle and
        the approach [rad/s], the motor's maximum speed [rad/s] and ``limit / speed - 1``; None without a duty
        cycle.
    status, success, iterations, solve_time [s], build_time [s]: solver statistics: the status and iterations
        of the attempt kept (``"Solved_To_Acceptable_Level"`` marks a point kept at IPOPT's acceptable
        tolerance), the time of every attempt.
    attempts: every IPOPT run of the solve (:class:`Attempt`), the kept one last; more than one means retries.
    """

    design: Design
    objectives: dict[str, float]
    numpy_objectives: dict[str, float]
    impulses: np.ndarray
    required_torque: np.ndarray
    torque_margin: np.ndarray
    status: str
    success: bool
    iterations: int
    solve_time: float
    build_time: float
    epsilon: dict[str, float] = field(default_factory=dict)
    requirement: str = STATIC_REQUIREMENT
    required_rms_torque: np.ndarray | None = None
    rms_margin: np.ndarray | None = None
    max_motor_speed: np.ndarray | None = None
    speed_limit: np.ndarray | None = None
    speed_margin: np.ndarray | None = None
    x: np.ndarray = field(default_factory=lambda: np.empty(0), repr=False)
    multipliers: tuple[np.ndarray, np.ndarray] | None = field(default=None, repr=False)
    attempts: tuple[Attempt, ...] = ()

    @property
    def worst_sample(self) -> int:
        """Index of the sample with the largest impulse."""
        return int(np.argmax(self.impulses))


@interruptible()
def solve(
    problem: DesignProblem,
    epsilon: Mapping[str, float] | None = None,
    x0: np.ndarray | DesignResult | None = None,
    ipopt_options: IpoptOptions | None = None,
    starts: int = 1,
    rng: np.random.Generator | None = None,
    *,
    retry: bool = True,
) -> DesignResult:
    """Solve ``problem`` with IPOPT (exact Hessian, MUMPS).

    A failed solve (any status but those of :data:`CONVERGED`: infeasibility detected, restoration failed, the
    iteration cap, ...) is retried as :data:`RETRIES` says, then an elastic feasibility solve decides whether
    any design meets the constraints: only then is the problem reported infeasible. Each retry reuses the
    problem's solvers (one per set of options, built on first use). ``DesignResult.attempts`` lists the runs.

    Parameters
    ----------
    problem: the NLP (:func:`collision_reflex.optimize.build_problem`).
    epsilon: upper bounds on objectives built as bounded (lower bound for ``approach_velocity``) [their units].
    x0: start point in the NLP's variables, or a neighbouring :class:`DesignResult` of the same problem, whose
        point and multipliers then warm-start IPOPT; default the problem's start point.
    ipopt_options: options merged over :data:`DEFAULT_IPOPT_OPTIONS` (e.g. ``{"ipopt.max_iter": 100}``), and
        under each retry's.
    starts: number of start points (multi-start). The problem is not convex (a worst case over samples) and
        IPOPT finds a local optimum; with ``starts > 1`` it is also started from ``starts - 1`` points drawn
        log-uniformly within the bounds; every start is screened at a loose tolerance and those on distinct
        central paths are finished, the best returned (:func:`_multi_start`).
    rng: random generator for the extra starts (default ``numpy.random.default_rng(0)``, reproducible).
    retry: False: no retries and no feasibility solve; a failed solve raises :class:`SolverFailed` with its
        status (e.g. ``"Maximum_Iterations_Exceeded"``), for a step that may stop early (a lexicographic
        tie-break).

    Raises
    ------
    SolverFailed: status ``"Infeasible"`` when the feasibility solve confirms that no design within the bounds
        meets the constraints (``violated`` names them, with the shortfall in their units); otherwise the last
        attempt's status, when no attempt converged although the problem is feasible (or undecided).
    """
    warm = x0 if isinstance(x0, DesignResult) and x0.multipliers is not None else None
    epsilon = _checked_epsilon(epsilon)
    start = np.clip(_start_point(problem, x0), problem.lbx, problem.ubx)
    if isinstance(starts, bool) or not isinstance(starts, int) or starts < 1:
        raise InvalidParameter("starts", starts, "an integer >= 1")
    if ipopt_options is not None and not isinstance(ipopt_options, Mapping):
        raise InvalidParameter("ipopt_options", ipopt_options, "a mapping of IPOPT option name to value")
    if starts > 1:
        return _multi_start(
            problem, epsilon, x0, ipopt_options, starts, rng or np.random.default_rng(0), retry
        )
    requested = {**DEFAULT_IPOPT_OPTIONS, **(ipopt_options or {})}
    parameters = problem.parameters(epsilon)
    attempts = _Attempts(problem, parameters)
    found = attempts.run("requested", {**requested, **(WARM_START_OPTIONS if warm else {})}, start, warm)
    tried = set() if warm else {(repr(sorted(requested.items())), start.tobytes())}
    if found is None and not retry:
        status = attempts.records[-1].status
        raise SolverFailed(
            f"IPOPT stopped with {status} after {attempts.records[-1].iterations} iterations (a step without "
            "retries: its start is kept)",
            status,
            attempts.last_stats,
            [],
            problem,
            attempts.records,
        )
    for name, change, where in RETRIES if found is None else ():
        options = {**requested, **change}
        retry_start = start if where == "start" else np.clip(problem.x0, problem.lbx, problem.ubx)
        key = (repr(sorted(options.items())), retry_start.tobytes())
        if key not in tried:
            tried.add(key)
            found = attempts.run(name, options, retry_start)
            if found is not None:
                break
    if found is None:
        found = _decide(problem, dict(epsilon or {}), {**requested, **RETRIES[0][1]}, attempts)
    x, stats, multipliers = found
    return _result(problem, x, tuple(attempts.records), stats, dict(epsilon or {}), multipliers)


INTERRUPTED = "NonIpopt_Exception_Thrown"
"""IPOPT's status when CasADi caught an exception in a callback (Ctrl-C among them)."""

_Found = tuple[np.ndarray, dict, tuple[np.ndarray, np.ndarray]]
"""A converged attempt: the point, IPOPT's statistics, the multipliers (bounds, constraints)."""


class _Attempts:
    """The IPOPT runs of one solve: runs each (the problem's solver for its options, built once) and records it."""

    def __init__(self, problem: DesignProblem, parameters: np.ndarray) -> None:
        self.problem = problem
        self.parameters = parameters
        self.records: list[Attempt] = []
        self.last_stats: dict = {}

    def run(
        self,
        name: str,
        options: dict[str, str | float],
        start: np.ndarray,
        warm: DesignResult | None = None,
    ) -> _Found | None:
        """Run IPOPT from ``start`` (warm-started from ``warm``'s multipliers); None if it did not converge."""
        problem = self.problem
        solver = problem.solver(options)
        multipliers = (
            {"lam_x0": warm.multipliers[0], "lam_g0": warm.multipliers[1]}
            if warm is not None and warm.multipliers is not None
            else {}
        )
        started = time.perf_counter()
        with single_threaded_blas():
            solution = solver(
                x0=start,
                lbx=problem.lbx,
                ubx=problem.ubx,
                lbg=problem.lbg,
                ubg=problem.ubg,
                p=self.parameters,
                **multipliers,
            )
        stats = dict(solver.stats())
        status = str(stats.get("return_status", "unknown"))
        if status == INTERRUPTED:
            raise KeyboardInterrupt  # CasADi caught Ctrl-C: stop the solve, never retry or record it
        iterations = int(stats.get("iter_count", -1))
        self.records.append(Attempt(name, status, iterations, time.perf_counter() - started))
        self.last_stats = stats
        if status not in CONVERGED:
            return None
        lam = (np.asarray(solution["lam_x"]).ravel(), np.asarray(solution["lam_g"]).ravel())
        return np.asarray(solution["x"]).ravel(), stats, lam


def _decide(
    problem: DesignProblem, epsilon: dict[str, float], options: dict[str, str | float], attempts: _Attempts
) -> _Found:
    """After every retry failed: a feasibility solve, then either infeasible (raised) or a last attempt.

    Raises
    ------
    SolverFailed: ``"Infeasible"`` when the feasibility solve confirms it; otherwise the last attempt's
        status, the problem being feasible (or, if the feasibility solve failed too, undecided).
    """
    started = time.perf_counter()
    verdict = solve_feasibility(problem, problem.x0, attempts.parameters, options, epsilon)
    attempts.records.append(
        Attempt("feasibility", verdict.status, verdict.iterations, time.perf_counter() - started)
    )
    design_status = next(a.status for a in reversed(attempts.records) if a.name != "feasibility")
    if verdict.converged and not verdict.feasible:
        what = "; ".join(_shortfall(v) for v in verdict.violations[:3])
        raise SolverFailed(
            f"no design within the bounds meets the constraints (confirmed by a feasibility solve): {what}. "
            + _advice(verdict.violations),
            "Infeasible",
            attempts.last_stats,
            list(verdict.violations),
            problem,
            attempts.records,
        )
    if verdict.feasible:
        found = attempts.run("feasible start, adaptive barrier", options, verdict.x)
        if found is not None:
            return found
        design_status = attempts.records[-1].status
    tried = ", ".join(f"{a.name}: {a.status} after {a.iterations} iterations" for a in attempts.records)
    decided = (
        "a feasibility solve found a design that meets every constraint"
        if verdict.feasible
        else "the feasibility solve did not converge either, so feasibility is undecided"
    )
    raise SolverFailed(
        f"the optimiser did not converge ({tried}); {decided}. Raise ipopt.max_iter, try more start points "
        "(starts), or narrow the bounds.",
        design_status,
        attempts.last_stats,
        list(verdict.violations),
        problem,
        attempts.records,
    )


def _shortfall(violation: Violation) -> str:
    """``peak torque of joint1 >= the given required torque: not met by 49.1 N*m``."""
    unit = "" if violation.unit == "-" else f" {violation.unit}"
    return f"{violation.label}: not met by {violation.amount:.3g}{unit}"


ADVICE = {
    "peak torque": "raise the upper bounds of the gear ratio or the motor size, or lower the payload, the "
    "safety factor or the given torques",
    "within its bound": "relax the objective bounds",
    "noise floor": "lower the threshold floor or raise the threshold's upper bound",
    "RMS torque": "raise the upper bound of the motor size or shorten the duty cycle's loads",
    "motor speed": "lower the upper bound of the gear ratio or slow the duty cycle",
    "gearbox": "choose a gearbox of a higher torque (or speed) rating, or lower the payload, the safety factor "
    "or the given torques",
}
"""What to do about each kind of constraint that cannot be met (found in its label)."""


def _advice(violations: tuple[Violation, ...]) -> str:
    """What to change, for the kinds of constraints in ``violations``."""
    hints = [hint for key, hint in ADVICE.items() if any(key in v.label for v in violations)]
    return ("To meet them: " + "; ".join(hints) + ".") if hints else "Widen the bounds."


def _checked_epsilon(epsilon: Mapping[str, float] | None) -> dict[str, float] | None:
    """``epsilon`` with every bound a finite number; NaN, infinities and non-numbers refused."""
    if epsilon is None:
        return None
    if not isinstance(epsilon, Mapping):
        raise InvalidParameter("epsilon", epsilon, "a mapping of objective name to bound")
    checked = {}
    for name, bound in epsilon.items():
        allowed = "a finite number (leave the objective out for no bound)"
        value = _validate.real(f"epsilon[{name!r}]", bound, allowed)
        if value.ndim or not np.isfinite(value):
            raise InvalidParameter(f"epsilon[{name!r}]", bound, allowed)
        checked[name] = float(value)
    return checked


def _start_point(problem: DesignProblem, x0: np.ndarray | DesignResult | None) -> np.ndarray:
    """The start point in the NLP's variables: ``x0`` (or its point) checked, or the problem's own."""
    if x0 is None:
        return problem.x0
    point = x0.x if isinstance(x0, DesignResult) else x0
    allowed = f"{problem.x0.size} finite numbers (the NLP's variables), a DesignResult, or None"
    array = _validate.real("x0", point, allowed)
    if array.shape != problem.x0.shape or not np.all(np.isfinite(array)):
        raise InvalidParameter("x0", point, allowed)
    return array


def warm_start(
    problem: DesignProblem, built: DesignProblem, optimum: DesignResult, x0: np.ndarray
) -> DesignResult:
    """``optimum`` of ``problem`` as a warm start of ``built`` from point ``x0``.

    ``built`` has ``problem``'s samples and auxiliaries, its design variables a subset of ``problem``'s (a
    catalogue problem fixes the motors) and rows matched by label (an objective bound ``problem`` lacks, say).
    The multipliers carried over: of each design variable free in both (by name and joint), of the
    auxiliaries (in the same places after the design variables) and of each row by its label; a row or
    variable ``problem`` does not have starts at zero. Both problems are scaled from their own starts, so the
    multipliers are only near ``built``'s: measured on the shipped studies' catalogue problems, scaling them
    to ``built``'s objective and torque scales saved no iterations.
    """
    assert optimum.multipliers is not None
    bounds, rows = optimum.multipliers
    lam_x = np.zeros(built.x0.size)
    for name, indices in built.layout.slices.items():
        for i, k in zip(indices, problem.layout.slices[name], strict=True):
            if i is not None and k is not None:
                lam_x[i] = bounds[k]
    lam_x[built.layout.size :] = bounds[problem.layout.size :]
    where = {label: k for k, label in enumerate(problem.constraint_labels)}
    lam_g = np.array([rows[where[label]] if label in where else 0.0 for label in built.constraint_labels])
    return replace(optimum, x=x0, multipliers=(lam_x, lam_g))


SCREENING_TOLERANCE = 1e-4
"""IPOPT's ``tol`` for the first run of every start of a multi-start (:func:`_multi_start`): the run stops on the
central path, before the barrier's last decreases: on the 4 starts of each shipped study's optimum
(``studies/panda.yaml``, ``studies/ur5.yaml``) a screening run takes far fewer iterations than a start solved
alone to ``tol = 1e-8``, and only the starts on distinct paths are finished from their screened points. A looser ``tol`` (1e-3, 1e-2) changes little, as IPOPT also waits for its absolute complementarity
and constraint-violation tolerances (1e-4 by default). IPOPT's acceptable level at 1e-2, or a cap of 20-40
iterations, saved some of the Panda's iterations but split the UR5's merged paths (more finishes)."""
SAME_PATH_DISTANCE = 1e-3
"""Largest difference of any log design variable (0.1 % of the variable) at which two screened starts count as
one central path, so one optimum. Chosen on both shipped studies' 4 starts: the screened starts that lead to
one optimum lie well within it, and the closest pair seen that leads to different optima lies well beyond
it."""


def _multi_start(
    problem: DesignProblem,
    epsilon: Mapping[str, float] | None,
    x0: np.ndarray | DesignResult | None,
    ipopt_options: IpoptOptions | None,
    starts: int,
    rng: np.random.Generator,
    retry: bool = True,
) -> DesignResult:
    """Best optimum over the given (or default) start and ``starts - 1`` random ones.

    Every start first runs to :data:`SCREENING_TOLERANCE`. Starts that stop within
    :data:`SAME_PATH_DISTANCE` of a better screened start's design are on its central path and are not run
    further unless the finish from that better start fails (then the next of its path is finished); every
    other one is finished to the full tolerance from its screened point and multipliers (warm
    start), and the best finished one is returned. So the result is the best of the distinct optima the starts
    lead to, each solved to the full tolerance; two optima whose designs differ by less than 0.1 % count as one.
    """
    n_design = problem.layout.size
    points: list[np.ndarray | DesignResult | None] = [x0]
    for _ in range(starts - 1):
        drawn = problem.x0.copy()
        drawn[:n_design] = rng.uniform(problem.lbx[:n_design], problem.ubx[:n_design])
        points.append(problem.exact_point(drawn))
    requested_tol = float({**DEFAULT_IPOPT_OPTIONS, **(ipopt_options or {})}["ipopt.tol"])
    screening = {**(ipopt_options or {}), "ipopt.tol": max(SCREENING_TOLERANCE, requested_tol)}
    failure: SolverFailed | None = None
    screened: list[tuple[float, DesignResult]] = []
    for point in points:
        try:
            result = solve(problem, epsilon, point, screening, retry=retry)
        except SolverFailed as error:
            if error.confirmed_infeasible:  # no design meets the constraints, from any start
                raise
            failure = error
            continue
        screened.append((problem.objective_value(result.x), result))
    screened.sort(key=lambda pair: pair[0])  # stable: a tie keeps the earlier start
    paths: list[list[DesignResult]] = []  # each path's starts, the best screened first
    for _, result in screened:
        path = next(
            (
                p
                for p in paths
                if np.max(np.abs(result.x[:n_design] - p[0].x[:n_design])) <= SAME_PATH_DISTANCE
            ),
            None,
        )
        if path is None:
            paths.append([result])
        else:
            path.append(result)
    best: DesignResult | None = None
    best_value = np.inf
    for path in paths:
        for result in path:  # the path's other starts only if the finish from its best one fails
            if requested_tol < SCREENING_TOLERANCE:
                try:
                    result = solve(problem, epsilon, result, ipopt_options, retry=retry)
                except SolverFailed as error:
                    failure = error
                    continue
            value = problem.objective_value(result.x)
            if value < best_value:
                best, best_value = result, value
            break
    if best is None:
        assert failure is not None  # every start failed
        raise failure
    return best


def _result(
    problem: DesignProblem,
    x: np.ndarray,
    attempts: tuple[Attempt, ...],
    stats: dict,
    epsilon: dict[str, float],
    multipliers: tuple[np.ndarray, np.ndarray],
) -> DesignResult:
    """The result at ``x``, found by the last of ``attempts`` (IPOPT's ``stats``), all timed."""
    design = design_at(problem, x)
    evaluated = problem.evaluate(problem.exact_point(x))
    objectives = objective_values(evaluated[0], evaluated[1], evaluated[2], problem.samples)
    numpy_impulses = evaluate_design(problem, design)
    numpy_objectives = objective_values(
        numpy_impulses, design.actuator_mass.sum(), design.approach_velocity, problem.samples
    )
    check_agreement(objectives, numpy_objectives, OBJECTIVES)
    required = np.asarray(evaluated[4]).ravel()
    duty: dict[str, Any] = {}
    if problem.duty is not None:
        values = duty_values(problem.duty, design, problem.technology)
        duty = {
            "required_rms_torque": values.required_rms_torque,
            "rms_margin": _margin(values.continuous_torque, values.required_rms_torque),
            "max_motor_speed": values.max_motor_speed,
            "speed_limit": values.speed_limit,
            "speed_margin": _margin(values.speed_limit, values.max_motor_speed),
        }
    return DesignResult(
        design=design,
        objectives=objectives,
        numpy_objectives=numpy_objectives,
        impulses=numpy_impulses,
        required_torque=required,
        torque_margin=design.driving_peak_torque / np.maximum(required, 1e-300) - 1,
        status=attempts[-1].status,
        success=True,
        iterations=int(stats.get("iter_count", -1)),
        solve_time=sum(attempt.solve_time for attempt in attempts),
        build_time=problem.build_time,
        epsilon=epsilon,
        requirement=problem.requirement,
        **duty,
        x=x,
        multipliers=multipliers,
        attempts=attempts,
    )


def check_agreement(
    objectives: Mapping[str, float], numpy_objectives: Mapping[str, float], names: Iterable[str]
) -> None:
    """Warn of each objective in ``names`` whose CasADi and NumPy values differ beyond the tolerance.

    :data:`AGREEMENT_TOLERANCE` (relative): both evaluate the same closed forms, so a larger difference is a
    modelling bug.
    """
    for name in names:
        a, b = objectives[name], numpy_objectives[name]
        if abs(a - b) > AGREEMENT_TOLERANCE * max(abs(a), abs(b)):
            warnings.warn(
                f"CasADi and NumPy evaluations of {name} differ: {a!r} vs {b!r}", RuntimeWarning, stacklevel=4
            )


def _margin(capacity: np.ndarray, need: np.ndarray) -> np.ndarray:
    """``capacity / need - 1`` [-] per joint (infinite where nothing is needed; the record shows None)."""
    with np.errstate(divide="ignore"):
        return np.where(need > 0, capacity / np.where(need > 0, need, 1.0) - 1, np.inf)


def design_at(problem: DesignProblem, x: np.ndarray) -> Design:
    """The design (and its derived actuator quantities) at NLP point ``x``."""
    return layout_design(problem.layout, problem.technology, problem.joint_names, x)


def layout_design(
    layout: DesignLayout, technology: ActuatorTechnology, joint_names: tuple[str, ...], x: np.ndarray
) -> Design:
    """The design at ``x`` (its design part, log values as ``layout`` lays them out) of ``technology``."""
    values = layout.values(np.asarray(x, dtype=float))
    gear = values["gear_ratio"]
    joint = technology.joint_quantities(values["stator_diameter"], values["stack_length"], gear)
    motor = joint.motor
    gearbox = technology.gearbox_figures(len(joint_names), np.asarray(joint.peak_torque, dtype=float))
    return Design(
        joint_names=joint_names,
        stator_diameter=values["stator_diameter"],
        stack_length=values["stack_length"],
        gear_ratio=gear,
        software_stiffness=values["software_stiffness"],
        mechanical_stiffness=technology.joint_mechanical_stiffness(len(joint_names)),
        rotor_inertia=np.asarray(motor.rotor_inertia, dtype=float),
        reflected_inertia=np.asarray(joint.reflected_inertia, dtype=float),
        motor_peak_torque=np.asarray(motor.peak_torque, dtype=float),
        peak_torque=np.asarray(joint.peak_torque, dtype=float),
        motor_mass=np.asarray(motor.mass, dtype=float),
        threshold=float(values["threshold"][0]),
        approach_velocity=float(values["approach_velocity"][0]),
        sensing=technology.sensing,
        gearbox=gearbox.names,
        gearbox_mass=gearbox.mass,
        gearbox_inertia=gearbox.inertia,
        gearbox_efficiency=gearbox.efficiency,
    )
