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

Sweeps, optima and studies solve on active sets through :func:`collision_reflex.optimize.pieces.solve_with`
(``active_set="auto"`` from :data:`ACTIVE_SET_THRESHOLD` samples, ``"always"``, ``"never"``; a study's
``optimizer.active_set``); a result says how it was solved (:func:`.active_set_result.solve_method`).

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
from collections.abc import Callable, Mapping
from typing import NamedTuple

import numpy as np

from ..errors import InvalidParameter, SolverFailed
from ..vocabulary import ACTIVE_SET_CHOICES, IMPULSE_OBJECTIVES
from .active_samples import first_active_set, violated_samples
from .active_set_result import ActiveSetResult, ActiveSetRound, result_fields, with_rounds
from .design_result import DesignResult, check_agreement
from .evaluate import evaluate_design
from .ipopt import IpoptOptions
from .objectives import impulse_objectives
from .problem import DesignProblem
from .samples import ContactSamples
from .solve import solve
from .subsets import sample_subset

ACTIVE_SET_THRESHOLD = 128
"""Number of samples from which ``active_set="auto"`` solves a problem on active sets.

Chosen from one solve of each method, each in a fresh process, on the Panda benchmark problem and on
``studies/ur5.yaml`` (duty cycle, weighted objective) at sample counts around it
(``benchmarks/optimize_samples_scaling.py --threshold`` measures them): with few samples the two are alike (the
active set then holds most samples), with more the full NLP's cost grows much faster than the active set's."""


FULL_PROBLEM_TOLERANCE = 1e-6
"""Largest violation of a row of the full NLP (rows are scaled to order one) allowed at the design found."""


def uses_active_set(n_samples: int, choice: str) -> bool:
    """Whether a problem of ``n_samples`` samples is solved on an active set under ``choice``.

    ``choice``: one of :data:`ACTIVE_SET_CHOICES`.
    """
    if choice not in ACTIVE_SET_CHOICES:
        raise InvalidParameter("active_set", choice, "one of " + ", ".join(map(repr, ACTIVE_SET_CHOICES)))
    return choice == "always" or (choice == "auto" and n_samples >= ACTIVE_SET_THRESHOLD)


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
        return with_rounds(result, result.impulses, np.arange(samples.size), (record,), needs_all)

    generator = rng or np.random.default_rng(0)
    settings = _Settings(epsilon, ipopt_options, start_samples, tolerance, max_rounds, retry)
    best = _best_start(
        build, full, settings, _start_designs(full, x0, warm, starts, generator), initial, warm
    )
    final = _full_result(full, best.result, best.x, best.impulses)
    return with_rounds(
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


class _Settings(NamedTuple):
    """The settings of :func:`solve_active_set` every start settles its active set with."""

    epsilon: Mapping[str, float] | None
    ipopt_options: IpoptOptions | None
    start_samples: int
    tolerance: float
    max_rounds: int
    retry: bool


def _start_designs(
    full: DesignProblem,
    x0: np.ndarray | None,
    warm: ActiveSetResult | None,
    starts: int,
    generator: np.random.Generator,
) -> list[np.ndarray]:
    """The start designs (log values): ``warm``'s, ``x0``'s or the problem's, and ``starts - 1`` drawn ones."""
    n_design = full.layout.size
    first = full.x0 if x0 is None else np.asarray(x0, dtype=float)
    if warm is not None:
        first = warm.x
    return [first[:n_design]] + [
        generator.uniform(full.lbx[:n_design], full.ubx[:n_design]) for _ in range(starts - 1)
    ]


def _best_start(
    build: Callable[[ContactSamples], DesignProblem],
    full: DesignProblem,
    settings: _Settings,
    designs: list[np.ndarray],
    initial: np.ndarray | None,
    warm: ActiveSetResult | None,
) -> _Settled:
    """The best on the full NLP's objective of the active sets settled from each of ``designs``.

    A failed start is skipped when another may settle (not with one start, nor when infeasibility is confirmed);
    the last failure is raised when every start fails.
    """
    best: _Settled | None = None
    failure: SolverFailed | None = None
    for index, design in enumerate(designs):
        # A warm start's samples were settled at its design (every row of the full NLP checked): kept as they are.
        resumed = warm is not None and warm.last_round is not None and index == 0
        active = (
            warm.active_samples
            if resumed and warm is not None
            else first_active_set(full, settings.start_samples, initial, design)
        )
        try:
            settled = _settle(
                build,
                full,
                active,
                design,
                settings,
                warm.last_round if resumed and warm is not None else None,
            )
        except SolverFailed as error:
            if len(designs) == 1 or error.confirmed_infeasible:
                raise
            failure = error  # another start may settle
            continue
        if best is None or settled.value < best.value:
            best = settled
    if best is None:
        assert failure is not None  # every start failed
        raise failure
    return best


def _settle(
    build: Callable[[ContactSamples], DesignProblem],
    full: DesignProblem,
    active: np.ndarray,
    x_design: np.ndarray,
    settings: _Settings,
    warm: DesignResult | None = None,
) -> _Settled:
    """Solve on ``active`` from the design ``x_design`` (log values), add the violated samples, repeat.

    ``warm``: a result of the first round's NLP (same samples) to start it from, point and multipliers.

    Raises
    ------
    SolverFailed: a round's solve failed; ``"Active_Set_Not_Settled"`` after ``max_rounds``;
        ``"Active_Set_Inconsistent"`` (see :func:`_check_full_rows`).
    """
    n_design, epsilon, tolerance = full.layout.size, settings.epsilon, settings.tolerance
    rounds: list[ActiveSetRound] = []
    while True:
        round_started = time.perf_counter()
        problem = build(sample_subset(full.samples, active))
        start: np.ndarray | DesignResult = problem.exact_point(
            np.concatenate([x_design, problem.x0[n_design:]])
        )
        if warm is not None and not rounds and warm.x.size == problem.x0.size:
            start = warm
        result = solve(problem, epsilon, start, settings.ipopt_options, retry=settings.retry)
        impulses = evaluate_design(full, result.design)
        added = violated_samples(full, result.design, impulses, active, epsilon, tolerance)
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
        if len(rounds) == settings.max_rounds:
            raise SolverFailed(
                f"the active set did not settle in {settings.max_rounds} rounds ({added.size} samples still exceed the "
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


FULL_ROW_CHECK_SAMPLES = 2048
"""Most samples for which the full NLP's graph is built to check every row at an active set's design (and
its objectives evaluated by CasADi beside NumPy). Beyond it building that graph costs more than the active set
saves: the design is checked on every sample by the NumPy rules that add samples (:func:`.active_samples.violated_samples`), and
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
    violation = np.maximum(*full.row_excess(x, full.parameters(epsilon)))
    last_violation = np.maximum(*last.row_excess(last_x, last.parameters(epsilon)))
    allowed = max(FULL_PROBLEM_TOLERANCE, 1.01 * float(last_violation.max(initial=0.0)))
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
    return result_fields(
        last, objectives=objectives, numpy_objectives=numpy_objectives, x=x, multipliers=None
    )
