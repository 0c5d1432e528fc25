"""Solve a design problem with many contact samples on an active set of them: exact for the worst case.

With thousands of samples the worst-case impulse is set by a few of them; the others never bind. The active-set
scheme solves the NLP on a subset of the samples, evaluates the design found on every sample through the NumPy
path (:func:`collision_reflex.optimize.evaluate.evaluate_design`), adds the samples whose impulse exceeds the
subset's worst case (or the worst case's epsilon bound) by more than a relative ``tolerance`` or whose contact
threshold is below the noise floor, and solves again from the last design, until no sample is added.

Why it is exact: the subset's NLP is a relaxation of the full one (fewer rows ``t >= I_s``), so its optimum is
no worse than the full optimum; a subset optimum at which every sample is within the subset's worst case is
feasible for the full NLP with the same objective, hence optimal for it. With the ``tolerance`` the worst case
found is within that relative amount of the full problem's (the same local optimum). The torque requirement is
built per sampled configuration: a configuration whose gravity demand exceeds a joint's driving torque at the
design found is a violation too, and its worst sample is added (the first active set holds, per joint, the
configuration of the largest demand at the start). With a duty cycle, the sample of each joint's largest
approach rate, which sets the motor-speed row, is in every active set. A last check evaluates every constraint
row of the full NLP at the design found, up to :data:`FULL_ROW_CHECK_SAMPLES` samples; beyond them the full
NLP is never built (its start, bounds and scales are NumPy), and the NumPy checks on every sample decide.

Sweeps, optima and studies solve on active sets through :func:`collision_reflex.optimize.pareto.solve_with`
(``active_set="auto"`` from :data:`ACTIVE_SET_THRESHOLD` samples, ``"always"``, ``"never"``; a study's
``optimizer.active_set``); a result says how it was solved (:func:`solve_method`).

Two things depend on all samples and are handled as follows, never silently:

- A mean-impulse or CVaR objective or bound needs every sample: the problem is then solved on all samples
  (``ActiveSetResult.method`` says so).
- The tie-break pull toward a lower mean impulse (:data:`collision_reflex.optimize.objectives.TIE_BREAK_WEIGHT`,
  1e-3 of the objective) acts on the active samples' mean: it picks among designs of equal worst case, and may
  place the undetermined variables elsewhere than the full solve does (the worst case is the same, the mean
  impulse over all samples may be a little higher).
"""

from __future__ import annotations

import time
from collections import OrderedDict
from collections.abc import Callable, Hashable, Mapping
from dataclasses import dataclass, field, fields
from typing import TYPE_CHECKING, NamedTuple

import casadi as ca
import numpy as np

from ..errors import InvalidParameter, SolverFailed
from .constraints import torque_requirement_rows
from .evaluate import design_collision_parameters, evaluate_design
from .objectives import IMPULSE_OBJECTIVES, impulse_objectives
from .samples import ContactSamples
from .solve import DesignResult, IpoptOptions, check_agreement, design_at, solve

if TYPE_CHECKING:
    from .problem import DesignProblem
    from .solve import Design

__all__ = [
    "ACTIVE_SET_CHOICES",
    "ACTIVE_SET_THRESHOLD",
    "ActiveSetResult",
    "ActiveSetRound",
    "sample_subset",
    "solve_active_set",
    "solve_method",
    "uses_active_set",
    "with_active_set",
]

ACTIVE_SET_THRESHOLD = 128
"""Number of samples from which ``active_set="auto"`` solves a problem on active sets.

Chosen from one solve of each method, each in a fresh process, on the Panda benchmark problem and on
``studies/ur5.yaml`` (duty cycle, weighted objective) at sample counts around it
(``benchmarks/optimize_samples_scaling.py --threshold`` measures them): with few samples the two are alike (the
active set then holds most samples), with more the full NLP's cost grows much faster than the active set's."""

ACTIVE_SET_CHOICES = ("auto", "always", "never")
"""How a problem's samples are solved: ``auto`` on an active set from :data:`ACTIVE_SET_THRESHOLD` samples,
``always`` on an active set, ``never`` all at once (the full NLP)."""

FULL_PROBLEM_TOLERANCE = 1e-6
"""Largest violation of a row of the full NLP (rows are scaled to order one) allowed at the design found."""


@dataclass(frozen=True)
class ActiveSetRound:
    """One NLP of the active-set scheme.

    samples: active samples in the NLP; added: indices (into all samples) of the samples found violated at its
        design and added for the next;
    iterations: IPOPT iterations; solve_time: problem build, solver construction and IPOPT [s];
    worst_active, worst_all: the worst-case impulse over the active samples and over all samples at its design
    [N*s] (NumPy path).
    """

    samples: int
    added: np.ndarray
    iterations: int
    solve_time: float
    worst_active: float
    worst_all: float


@dataclass(frozen=True)
class ActiveSetResult(DesignResult):
    """A :class:`DesignResult` over all samples, found on an active set of them.

    Its impulses, objectives and NumPy objectives are those of every sample; ``x`` is the full problem's point
    (auxiliaries at their exact values) and ``multipliers`` None (they belong to the last subset's NLP).
    ``iterations`` add up the rounds of the start kept, ``solve_time`` [s] is the whole solve's (every start,
    the problem builds and the evaluations on all samples); ``status`` and ``attempts`` are the last round's.

    active_samples: indices (into all samples) of the samples in the last NLP.
    rounds: every NLP solved (:class:`ActiveSetRound`), in order.
    method: ``"active set"``, or why all samples were solved at once.
    last_round: the last NLP's own result (its point and multipliers), which warm-starts a solve of a problem
        of the same variables and rows on the same samples (``solve_active_set(warm=...)``); None when all
        samples were solved at once.
    """

    active_samples: np.ndarray = field(default_factory=lambda: np.empty(0, dtype=int))
    rounds: tuple[ActiveSetRound, ...] = ()
    method: str = "active set"
    last_round: DesignResult | None = None

    def active_set_json(self) -> dict[str, object]:
        """What the active set adds to a result, as JSON types (:func:`with_active_set` reads it back)."""
        return {
            "method": self.method,
            "active_samples": [int(i) for i in self.active_samples],
            "rounds": [
                {
                    "samples": r.samples,
                    "added": [int(i) for i in r.added],
                    "iterations": r.iterations,
                    "solve_time": r.solve_time,
                    "worst_active": r.worst_active,
                    "worst_all": r.worst_all,
                }
                for r in self.rounds
            ],
        }


def with_active_set(
    result: DesignResult, data: Mapping[str, object], last_round: DesignResult | None = None
) -> ActiveSetResult:
    """``result`` with the active set written by :meth:`ActiveSetResult.active_set_json` (and its last NLP's)."""
    rounds = data["rounds"]
    assert isinstance(rounds, list)
    return ActiveSetResult(
        **_replace(result),  # type: ignore[arg-type]
        active_samples=np.asarray(data["active_samples"], dtype=int),
        rounds=tuple(
            ActiveSetRound(
                int(r["samples"]),
                np.asarray(r["added"], dtype=int),
                int(r["iterations"]),
                float(r["solve_time"]),
                float(r["worst_active"]),
                float(r["worst_all"]),
            )
            for r in rounds
        ),
        method=str(data["method"]),
        last_round=last_round,
    )


def solve_method(result: DesignResult) -> tuple[str, int]:
    """How ``result`` was solved and on how many samples its last NLP was: ``("active set", 72)``."""
    if isinstance(result, ActiveSetResult):
        return result.method, int(result.active_samples.size)
    return "full NLP", int(np.asarray(result.impulses).size)


def uses_active_set(n_samples: int, choice: str) -> bool:
    """Whether a problem of ``n_samples`` samples is solved on an active set under ``choice``.

    ``choice``: one of :data:`ACTIVE_SET_CHOICES`.
    """
    if choice not in ACTIVE_SET_CHOICES:
        raise InvalidParameter("active_set", choice, "one of " + ", ".join(map(repr, ACTIVE_SET_CHOICES)))
    return choice == "always" or (choice == "auto" and n_samples >= ACTIVE_SET_THRESHOLD)


def sample_subset(samples: ContactSamples, index: np.ndarray) -> ContactSamples:
    """The samples at ``index`` (integer indices), with every configuration's kinematics kept.

    A subset of searched samples alone (none drawn) takes its mean over them.
    """
    index = np.asarray(index, dtype=int)
    assert samples.speed_cap is not None and samples.drawn is not None  # set by ContactSamples
    drawn = samples.drawn[index]
    return ContactSamples(
        samples.kinematics,
        samples.directions[index],
        samples.config_index[index],
        tuple(samples.labels[i] for i in index) if samples.labels else (),
        samples.speed_cap[index],
        drawn if np.any(drawn) else None,
    )


SUBSET_PROBLEMS = 4
"""Problems on subsets of the samples kept per process (with their solvers), the last used kept longest: every
epsilon point's first active set is the first anchor's, and every catalogue combination of a snap warm-starts
from the continuous problem on the optimum's last active samples, so each is built once per process."""
_SUBSETS: OrderedDict[tuple[Hashable, ...], tuple[object, DesignProblem]] = OrderedDict()


def release_subsets() -> None:
    """Drop the kept subset problems (:func:`kept_problem`)."""
    _SUBSETS.clear()


def kept_problem(
    key: tuple[Hashable, ...],
    samples: ContactSamples,
    build: Callable[[], DesignProblem],
    holds: object = None,
) -> DesignProblem:
    """``build()``, a problem on ``samples``, built once per process for ``key`` and those samples.

    The last :data:`SUBSET_PROBLEMS` are kept. ``holds``: an object that ``key`` names by its ``id``, kept with
    the problem so that its id is not another object's while the entry lives.
    """
    full_key = (*key, samples.config_index.tobytes(), samples.directions.tobytes())
    kept = _SUBSETS.get(full_key)
    if kept is None or kept[0] is not holds:
        kept = _SUBSETS[full_key] = (holds, build())
        while len(_SUBSETS) > SUBSET_PROBLEMS:
            _SUBSETS.popitem(last=False)
    _SUBSETS.move_to_end(full_key)
    return kept[1]


def solve_active_set(
    build: Callable[[ContactSamples], DesignProblem],
    samples: ContactSamples,
    epsilon: Mapping[str, float] | None = None,
    ipopt_options: IpoptOptions | None = None,
    start_samples: int = 64,
    tolerance: float = 1e-8,
    max_rounds: int = 20,
    initial: np.ndarray | None = None,
    starts: int = 1,
    rng: np.random.Generator | None = None,
    *,
    x0: np.ndarray | None = None,
    retry: bool = True,
    full: DesignProblem | None = None,
    warm: ActiveSetResult | None = None,
) -> ActiveSetResult:
    """Solve the problem ``build(samples)`` on an active set of its samples (see the module's description).

    Parameters
    ----------
    build: makes the design problem on given samples, e.g. ``lambda s: build_problem(arm, s, space,
        technology, objective, constraints)``; called once with all samples (built, never solved, unless the
        objective needs every sample) and once per round with the active ones.
    samples: all contact samples.
    epsilon: bounds on objectives built as bounded [their units], as :func:`collision_reflex.optimize.solve`.
    ipopt_options: as :func:`collision_reflex.optimize.solve`, for every round.
    start_samples: size of the first active set: half the samples worst at the start design, half spread
        evenly over the samples (plus those that set the torque and speed requirements).
    tolerance: relative amount [-] by which a sample may exceed the active worst case (or the worst case's
        bound) before it is added; the worst case found is within it of the full problem's.
    max_rounds: most NLPs solved before giving up.
    initial: indices of the first active samples instead of ``start_samples`` chosen ones (e.g. the active set
        of an earlier solve); those that set the torque and speed requirements at the start are added.
    starts: start designs (multi-start, as :func:`collision_reflex.optimize.solve`): the problem's start and
        ``starts - 1`` drawn log-uniformly within the bounds by ``rng`` (default
        ``numpy.random.default_rng(0)``); each settles its own active set, the best on the full NLP's
        objective is returned (its rounds).
    x0: start point of the full problem (its design variables are used: the per-sample auxiliaries of a subset
        start at their exact values); default the problem's start.
    retry: as :func:`collision_reflex.optimize.solve` for every round (False: a failed round raises).
    full: ``build(samples)`` when it is already built (it is not built again).
    warm: an earlier result of a problem with the same variables and rows (e.g. a Pareto anchor's, for the
        epsilon points of its sweep): the first start's first round is on its ``active_samples`` (``initial``
        ignored) from its ``last_round`` (point and multipliers, as :func:`collision_reflex.optimize.solve`
        warm-starts a neighbouring result); its design replaces ``x0``.

    Raises
    ------
    InvalidParameter: bad ``start_samples``, ``tolerance``, ``max_rounds``, ``initial`` or ``starts``.
    SolverFailed: as :func:`collision_reflex.optimize.solve` for a round; status ``"Active_Set_Not_Settled"``
        when samples are still added after ``max_rounds``, ``"Active_Set_Inconsistent"`` when the design found
        violates a row of the full NLP (a modelling bug).
    """
    _check_settings(start_samples, tolerance, max_rounds, starts)
    started = time.perf_counter()
    full = build(samples) if full is None else full
    if full.samples.size != samples.size:
        raise InvalidParameter(
            "build", f"a problem on {full.samples.size} samples", f"{samples.size} samples"
        )
    needs_all = _needs_every_sample(full)
    if needs_all is not None:
        result = solve(full, epsilon, x0, ipopt_options, starts, rng, retry=retry)
        record = ActiveSetRound(
            samples.size,
            np.empty(0, dtype=int),
            result.iterations,
            time.perf_counter() - started,
            *[result.impulses.max()] * 2,
        )
        return _with_rounds(result, result.impulses, np.arange(samples.size), (record,), needs_all)

    n_design = full.layout.size
    generator = rng or np.random.default_rng(0)
    first = full.x0 if x0 is None else np.asarray(x0, dtype=float)
    if warm is not None:
        first = warm.x
    designs = [first[:n_design]] + [
        generator.uniform(full.lbx[:n_design], full.ubx[:n_design]) for _ in range(starts - 1)
    ]
    best: _Settled | None = None
    failure: SolverFailed | None = None
    for index, design in enumerate(designs):
        # A warm start's samples were settled at its design (every row of the full NLP checked): kept as they are.
        resumed = warm is not None and warm.last_round is not None and index == 0
        active = (
            warm.active_samples
            if resumed and warm is not None
            else _first_active_set(full, start_samples, initial, design)
        )
        try:
            settled = _settle(
                build,
                full,
                active,
                design,
                epsilon,
                ipopt_options,
                tolerance,
                max_rounds,
                retry,
                warm.last_round if resumed and warm is not None else None,
            )
        except SolverFailed as error:
            if starts == 1 or error.confirmed_infeasible:
                raise
            failure = error  # another start may settle
            continue
        if best is None or settled.value < best.value:
            best = settled
    if best is None:
        assert failure is not None  # every start failed
        raise failure
    final = _full_result(full, best.result, best.x, best.impulses)
    return _with_rounds(
        final,
        best.impulses,
        best.active,
        best.rounds,
        "active set",
        time.perf_counter() - started,
        best.result,
    )


class _Settled(NamedTuple):
    """An active set from which no sample is added: the last subset's result and its full-problem figures.

    ``x`` is the full problem's point, ``impulses`` [N*s] every sample's (NumPy path), ``value`` the full NLP's
    objective at ``x``.
    """

    result: DesignResult
    x: np.ndarray
    impulses: np.ndarray
    active: np.ndarray
    rounds: tuple[ActiveSetRound, ...]
    value: float


def _settle(
    build: Callable[[ContactSamples], DesignProblem],
    full: DesignProblem,
    active: np.ndarray,
    x_design: np.ndarray,
    epsilon: Mapping[str, float] | None,
    ipopt_options: IpoptOptions | None,
    tolerance: float,
    max_rounds: int,
    retry: bool,
    warm: DesignResult | None = None,
) -> _Settled:
    """Solve on ``active`` from the design ``x_design`` (log values), add the violated samples, repeat.

    ``warm``: a result of the first round's NLP (same samples) to start it from, point and multipliers.

    Raises
    ------
    SolverFailed: a round's solve failed; ``"Active_Set_Not_Settled"`` after ``max_rounds``;
        ``"Active_Set_Inconsistent"`` (see :func:`_check_full_rows`).
    """
    n_design = full.layout.size
    rounds: list[ActiveSetRound] = []
    while True:
        round_started = time.perf_counter()
        problem = build(sample_subset(full.samples, active))
        start: np.ndarray | DesignResult = problem.exact_point(
            np.concatenate([x_design, problem.x0[n_design:]])
        )
        if warm is not None and not rounds and warm.x.size == problem.x0.size:
            start = warm
        result = solve(problem, epsilon, start, ipopt_options, retry=retry)
        impulses = evaluate_design(full, result.design)
        added = _violated(full, result.design, impulses, active, epsilon, tolerance)
        rounds.append(
            ActiveSetRound(
                active.size,
                added,
                result.iterations,
                time.perf_counter() - round_started,
                float(impulses[active].max()),
                float(impulses.max()),
            )
        )
        x_design = result.x[:n_design]
        if added.size == 0:
            break
        if len(rounds) == max_rounds:
            raise SolverFailed(
                f"the active set did not settle in {max_rounds} rounds ({added.size} samples still exceed the "
                f"worst case of {active.size}); raise max_rounds or start_samples",
                "Active_Set_Not_Settled",
                {},
                [],
                problem,
                result.attempts,
            )
        active = np.union1d(active, added)
    x = full.exact_point(np.concatenate([x_design, full.x0[n_design:]]))
    if checks_full_rows(full):
        _check_full_rows(full, x, problem, result.x, epsilon)
    return _Settled(result, x, impulses, active, tuple(rounds), full.objective_value(x))


def _check_settings(start_samples: int, tolerance: float, max_rounds: int, starts: int) -> None:
    """Refuse settings that cannot work, with what they must be."""
    if not isinstance(starts, int) or starts < 1:
        raise InvalidParameter("starts", starts, "an integer >= 1")
    if not isinstance(start_samples, int) or start_samples < 1:
        raise InvalidParameter("start_samples", start_samples, "an integer >= 1")
    if not (np.isfinite(tolerance) and tolerance >= 0):
        raise InvalidParameter("tolerance", tolerance, "a finite relative tolerance >= 0")
    if not isinstance(max_rounds, int) or max_rounds < 1:
        raise InvalidParameter("max_rounds", max_rounds, "an integer >= 1")


def _needs_every_sample(problem: DesignProblem) -> str | None:
    """Why the problem must be solved on all samples at once (a mean impulse), or None."""
    for name in ("mean_impulse", "cvar_impulse"):
        if name in problem.objective or name in problem.bounded_objectives:
            return f"all samples: the {name.replace('_', ' ')} (objective or bound) needs every sample"
    return None


def _first_active_set(
    full: DesignProblem, size: int, initial: np.ndarray | None, x_design: np.ndarray
) -> np.ndarray:
    """The first active samples: ``initial`` or the worst at the start and a spread, and the requirement's.

    ``x_design`` is the start design (log values, the first ``layout.size`` entries of ``x``).
    """
    n = full.samples.size
    start = design_at(full, x_design)
    impulses = evaluate_design(full, start)
    if initial is not None:
        chosen = np.asarray(initial).ravel()
        if (
            chosen.size == 0
            or not np.issubdtype(chosen.dtype, np.integer)
            or chosen.min() < 0
            or chosen.max() >= n
        ):
            raise InvalidParameter("initial", initial, f"sample indices in [0, {n})")
    elif size >= n:
        return np.arange(n)
    else:
        worst = np.argsort(impulses)[::-1][: max(size // 2, 1)]
        chosen = np.concatenate([worst, np.linspace(0, n - 1, size - worst.size).round().astype(int)])
    return np.unique(np.concatenate([chosen, _requirement_samples(full, start, impulses)]))


def _requirement_samples(full: DesignProblem, start: Design, impulses: np.ndarray) -> np.ndarray:
    """Samples that carry the requirement rows of the start design: the first active set's torque and speed.

    The static hold: per joint the configuration of the largest gravity demand at the start design (its worst
    sample at the start); more are added when they bind (:func:`_torque_violated`). With a duty cycle also, per
    joint, the sample of the largest approach joint rate, which sets the motor-speed row for every design.
    """
    static = _torque_violated(full, start, impulses, np.inf)
    if full.duty is not None:
        return np.union1d(np.abs(full.duty.approach_rates).argmax(axis=0), static)
    return static


def _torque_violated(
    full: DesignProblem, design: Design, impulses: np.ndarray, tolerance: float
) -> np.ndarray:
    """Per configuration whose gravity demand exceeds a joint's driving torque, its worst sample.

    The static hold's torque rows (with or without a duty cycle) are per sampled configuration (plus and minus
    the gravity torque, :func:`collision_reflex.optimize.constraints.torque_requirement_rows`): a configuration
    missing from the active samples has no row. A demand above ``(1 + tolerance)`` times the driving peak torque
    [N m] of ``design`` flags its configuration; ``tolerance=inf`` flags, per joint, the configuration of the
    largest demand instead. Given torques do not depend on the configurations: nothing is flagged.
    """
    samples = full.samples
    if full.constraints.torque_required is not None:
        return np.empty(0, dtype=int)
    rows, _ = torque_requirement_rows(samples, full.constraints, full.joint_names)
    configurations = np.repeat(np.unique(samples.config_index), 2)  # a + and a - row per configuration
    # The rows of the searched hold poses follow; every active set's problem has them.
    demands = np.array(
        [base + per_motor @ design.actuator_mass for base, per_motor in rows[: configurations.size]]
    )  # (rows, joints)
    if np.isinf(tolerance):
        flagged = configurations[demands.argmax(axis=0)]
    else:
        flagged = configurations[np.any(demands > (1 + tolerance) * design.driving_peak_torque, axis=1)]
    picked = []
    for configuration in np.unique(flagged):
        of_configuration = np.flatnonzero(samples.config_index == configuration)
        picked.append(int(of_configuration[np.argmax(impulses[of_configuration])]))
    return np.array(picked, dtype=int)


def _violated(
    full: DesignProblem,
    design: Design,
    impulses: np.ndarray,
    active: np.ndarray,
    epsilon: Mapping[str, float] | None,
    tolerance: float,
) -> np.ndarray:
    """Samples outside ``active`` that ``design`` violates, by more than the relative ``tolerance``.

    A sample is violated when its impulse [N*s] exceeds the active worst case (or the worst case's bound), its
    contact threshold is below the noise floor, or its configuration's gravity demand exceeds a joint's driving
    torque.
    """
    inside = full.samples.inside(design.approach_velocity)  # samples in the design's contact domain
    levels = []
    if "worst_case_impulse" in full.objective:
        levels.append(impulses[active][inside[active]].max(initial=0.0))
    bound = (epsilon or {}).get("worst_case_impulse")
    if bound is not None:
        levels.append(bound)
    bad = np.zeros(impulses.size, dtype=bool)
    if levels:
        bad |= impulses > min(levels) * (1 + tolerance)
    floor = full.constraints.threshold_floor
    if full.technology.sensing == "position" and floor > 0:
        _, thresholds = design_collision_parameters(full, design)
        bad |= thresholds < floor * (1 - tolerance)
    bad &= inside
    bad[_torque_violated(full, design, impulses, tolerance)] = True
    bad[active] = False
    return np.flatnonzero(bad)


FULL_ROW_CHECK_SAMPLES = 2048
"""Most samples for which the full NLP's graph is built to check every row at an active set's design (and
its objectives evaluated by CasADi beside NumPy). Beyond it building that graph costs more than the active set
saves: the design is checked on every sample by the NumPy rules that add samples (:func:`_violated`), and
the subset NLPs' own CasADi and NumPy values are compared at each solve."""


def checks_full_rows(full: DesignProblem) -> bool:
    """Whether the active set checks the full NLP's rows and objectives by CasADi (:data:`FULL_ROW_CHECK_SAMPLES`)."""
    return full.samples.size <= FULL_ROW_CHECK_SAMPLES


def _check_full_rows(
    full: DesignProblem,
    x: np.ndarray,
    last: DesignProblem,
    last_x: np.ndarray,
    epsilon: Mapping[str, float] | None,
) -> None:
    """Raise when a row of the full NLP at ``x`` is violated by more than the last subset's NLP at ``last_x``.

    The rows are scaled to order one; the allowance is :data:`FULL_PROBLEM_TOLERANCE` or the last solve's own
    largest violation (a point kept at IPOPT's acceptable level), whichever is larger.
    """
    violation = _row_violation(full, x, epsilon)
    allowed = max(
        FULL_PROBLEM_TOLERANCE, 1.01 * float(_row_violation(last, last_x, epsilon).max(initial=0.0))
    )
    bad = np.flatnonzero(violation > allowed)
    if bad.size:
        worst = bad[np.argsort(violation[bad])[::-1][:3]]
        raise SolverFailed(
            "the active-set design violates rows of the full problem: "
            + "; ".join(f"{full.constraint_labels[i]} by {violation[i]:.3g}" for i in worst),
            "Active_Set_Inconsistent",
            {},
            [(full.constraint_labels[i], float(violation[i])) for i in worst],
            full,
        )


def _row_violation(problem: DesignProblem, x: np.ndarray, epsilon: Mapping[str, float] | None) -> np.ndarray:
    """How far each constraint row of ``problem`` is outside its bounds at ``x`` (0 or less: within)."""
    rows = ca.Function("rows", [problem.nlp["x"], problem.nlp["p"]], [problem.nlp["g"]])
    g = np.asarray(rows(x, problem.parameters(epsilon))).ravel()
    return np.asarray(np.maximum(problem.lbg - g, g - problem.ubg))


def _full_result(
    full: DesignProblem, last: DesignResult, x: np.ndarray, impulses: np.ndarray
) -> dict[str, object]:
    """The fields of ``last`` (the last subset's result) with the objectives of every sample at ``x``.

    ``x`` is the full problem's point, ``impulses`` [N*s] the NumPy path's of every sample.
    """
    velocity = last.design.approach_velocity
    numpy_objectives = {**last.numpy_objectives, **impulse_objectives(impulses, full.samples, velocity)}
    objectives = numpy_objectives  # beyond FULL_ROW_CHECK_SAMPLES the full NLP is not built
    if checks_full_rows(full):
        objectives = {**last.objectives, **impulse_objectives(full.evaluate(x)[0], full.samples, velocity)}
        check_agreement(objectives, numpy_objectives, IMPULSE_OBJECTIVES)
    return _replace(last, objectives=objectives, numpy_objectives=numpy_objectives, x=x, multipliers=None)


def _replace(result: DesignResult, **changes: object) -> dict[str, object]:
    """The fields of ``result`` as keywords, with ``changes``."""
    return {**{f.name: getattr(result, f.name) for f in fields(DesignResult)}, **changes}


def _with_rounds(
    result: DesignResult | dict[str, object],
    impulses: np.ndarray,
    active: np.ndarray,
    rounds: tuple[ActiveSetRound, ...],
    method: str,
    total_time: float | None = None,
    last_round: DesignResult | None = None,
) -> ActiveSetResult:
    """The :class:`ActiveSetResult` of ``result`` (a result or its fields) with the rounds' totals."""
    values = result if isinstance(result, dict) else _replace(result)
    values.update(
        impulses=impulses,
        iterations=sum(r.iterations for r in rounds),
        solve_time=sum(r.solve_time for r in rounds) if total_time is None else total_time,
    )
    return ActiveSetResult(
        **values,  # type: ignore[arg-type]
        active_samples=active,
        rounds=rounds,
        method=method,
        last_round=last_round,
    )
