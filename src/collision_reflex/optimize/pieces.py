"""What a piece of a sweep runs on in its worker.

The problems built once per process (:func:`built_problem`), the solver lock (:func:`one_at_a_time`), and the
solve on all samples or on active sets of them (:func:`solve_with`).
"""

from __future__ import annotations

import functools
import inspect
import threading
import warnings
from collections.abc import Callable, Hashable, Mapping
from typing import TYPE_CHECKING, Any, ParamSpec, Protocol, TypeVar

import numpy as np

from .. import _validate
from ..errors import InvalidParameter, SolverFailed
from ..vocabulary import ACTIVE_SET_CHOICES
from .active_set import solve_active_set, uses_active_set
from .active_set_result import ActiveSetResult
from .blas import single_threaded_blas
from .design_result import DesignResult
from .ipopt import IpoptOptions
from .results import PointFailure, SweepPoint
from .solve import solve
from .subsets import kept_problem, release_subsets

if TYPE_CHECKING:
    from .problem import DesignProblem
    from .samples import ContactSamples


_P = ParamSpec("_P")
_R = TypeVar("_R")


class ProblemBuilder(Protocol):
    """``build(objective, bounded_objectives[, samples]) -> DesignProblem``.

    Hashable (the problems are cached per process by builder); picklable (a module-level function, or a frozen
    dataclass) to run through a process pool. A builder that also takes ``samples`` (a
    :class:`collision_reflex.optimize.ContactSamples`, default all of its own) can be solved on active sets
    (:mod:`collision_reflex.optimize.active_set`): ``lambda obj, bounded, s=samples: build_problem(arm, s,
    ...)``.
    """

    def __call__(self, objective: Hashable, bounded: tuple[str, ...], /) -> DesignProblem:
        """Build the problem minimising ``objective`` (a name, or a weighted one) with ``bounded`` bounded."""
        ...

    def __hash__(self) -> int: ...


_SOLVER_LOCK = threading.RLock()
"""CasADi functions, IPOPT and (sequential) MUMPS are not thread-safe: within one process the pieces run one at a
time (a Dask worker with several threads, for instance); parallelism comes from processes."""


@functools.lru_cache(maxsize=16)
def built_problem(build: Hashable, objective: Hashable, bounded: tuple[str, ...] = ()) -> DesignProblem:
    """``build(objective, bounded)``, built once per process and builder.

    Later pieces reuse its solvers; the results do not depend on which piece came first.
    """
    problem: DesignProblem = build(objective, bounded)  # type: ignore[operator]
    return problem


def release_problems() -> None:
    """Drop this process's built problems (:func:`built_problem`, the active sets' subset problems).

    For a caller that moves on to other samples (a worst-case search's exchange round): the problems on the
    samples before would otherwise stay beside the new ones, each as large as its samples.
    """
    built_problem.cache_clear()
    release_subsets()


def one_at_a_time(function: Callable[_P, _R]) -> Callable[_P, _R]:
    """Run a piece under the solver lock with single-threaded BLAS (the same numbers in every process).

    Within one process the pieces run one at a time (a Dask worker with several threads): BLAS's thread count
    is a process-wide setting, so a piece running beside another could see it changed under it.
    """

    @functools.wraps(function)
    def locked(*args: _P.args, **kwargs: _P.kwargs) -> _R:
        with _SOLVER_LOCK, single_threaded_blas():
            return function(*args, **kwargs)

    return locked


def takes_samples(build: Hashable) -> bool:
    """Whether ``build`` accepts ``build(objective, bounded, samples)`` (it can build on active sets)."""
    try:
        inspect.signature(build).bind(None, (), None)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        return False
    return True


def check_active_set(build: Hashable, active_set: str) -> None:
    """Refuse an unknown choice, and ``"always"`` with a builder that cannot build on a subset of samples."""
    _validate.choice("active_set", active_set, ACTIVE_SET_CHOICES)
    if active_set == "always" and not takes_samples(build):
        raise InvalidParameter(
            "active_set",
            active_set,
            "a builder taking the samples, build(objective, bounded, samples), to solve on active sets",
        )


def subset_problem(
    build: Hashable, objective: Hashable, bounded: tuple[str, ...], samples: ContactSamples
) -> DesignProblem:
    """``build(objective, bounded, samples)``, kept per process (:func:`~.active_set.kept_problem`)."""
    return kept_problem(
        (build, objective, bounded),
        samples,
        lambda: build(objective, bounded, samples),  # type: ignore[operator]
    )


def solve_with(
    build: ProblemBuilder,
    objective: Hashable,
    bounded: tuple[str, ...],
    active_set: str,
    epsilon: Mapping[str, float] | None = None,
    x0: np.ndarray | DesignResult | None = None,
    ipopt_options: IpoptOptions | None = None,
    starts: int = 1,
    *,
    retry: bool = True,
    initial: np.ndarray | None = None,
) -> DesignResult:
    """Solve ``build(objective, bounded)`` on all samples or on active sets of them, as ``active_set`` says.

    On active sets (:func:`collision_reflex.optimize.active_set.solve_active_set`) the solve starts from the
    design of ``x0`` and from the samples ``initial`` (indices; default its own first choice); an
    active-set result ``x0`` of the same problem also warm-starts the first round from its last NLP when that
    round has its samples. ``"auto"`` with a builder that does not take samples solves the full NLP, with a
    warning, whatever the number of samples.
    """
    problem = built_problem(build, objective, bounded)
    n_samples = problem.samples.size
    if uses_active_set(n_samples, active_set) and not takes_samples(build):
        warnings.warn(
            f"{n_samples} contact samples solved as one NLP: the problem builder does not take the samples "
            "(build(objective, bounded, samples)), so it cannot be solved on active sets",
            RuntimeWarning,
            stacklevel=2,
        )
    elif uses_active_set(n_samples, active_set):
        return solve_active_set(
            functools.partial(subset_problem, build, objective, bounded),
            problem.samples,
            epsilon,
            ipopt_options,
            initial=initial,
            starts=starts,
            x0=x0.x if isinstance(x0, DesignResult) else x0,
            retry=retry,
            full=problem,
            warm=x0 if isinstance(x0, ActiveSetResult) else None,
        )
    return solve(problem, epsilon, x0, ipopt_options, starts=starts, retry=retry)


def solved_point(
    label: str,
    build: ProblemBuilder,
    objective: Hashable,
    bounded: tuple[str, ...],
    active_set: str,
    epsilon: Mapping[str, float] | None = None,
    **options: Any,
) -> SweepPoint:
    """The sweep point ``label`` of :func:`solve_with`'s design, or of its failure (``options`` as there)."""
    try:
        result = solve_with(build, objective, bounded, active_set, epsilon, **options)
    except SolverFailed as error:
        failure = PointFailure(str(objective), dict(epsilon or {}), error.status, str(error.args[0]))
        return SweepPoint(label, None, (failure,))
    return SweepPoint(label, result)
