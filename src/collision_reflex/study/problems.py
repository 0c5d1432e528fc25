"""The design problems of a resolved study, built in any process from the study itself.

:class:`StudyProblems` is the builder the optimiser's sweeps call (:class:`collision_reflex.optimize.pareto.
ProblemBuilder`): it holds the :class:`~.resolve.ResolvedStudy` and the samples a worst-case search added,
crosses process boundaries as it is (a pool's or a Dask cluster's workers receive the validated study, not its
text), and builds the study's setup once per process (:func:`study_setup`).
"""

from __future__ import annotations

import functools
import json
import os
from collections.abc import Hashable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ..errors import InvalidParameter, StudyFileError
from ..optimize import ContactSamples, DesignProblem, build_problem
from ..optimize.pieces import built_problem
from .arm_setup import ArmSetup, ExtraSamples, arm_setup, with_extra_samples
from .checks import located_refusal, torque_out_of_reach
from .load import LoadedStudy, load_study
from .resolve import ResolvedStudy
from .schema import ArmStudy
from .store import DESIGNS, RESOLVED

IPOPT_OPTIONS = {"ipopt.max_iter": 400}
"""Options over the optimiser's defaults for study runs (a cap keeps a hopeless Pareto point from stalling a run)."""


@functools.lru_cache(maxsize=4)
def study_setup(study: ResolvedStudy, extra: ExtraSamples = ()) -> ArmSetup:
    """The setup of a resolved study with the searched samples ``extra``, built once per process."""
    if extra:
        return with_extra_samples(study_setup(study), extra)
    return arm_setup(study.loaded)


def objective_key(objective: Mapping[str, float] | Mapping[Any, float]) -> Hashable:
    """A hashable form of a study's objective.

    Its name alone when it is a single unweighted objective, else sorted ``(name, weight)`` pairs.
    """
    if len(objective) == 1 and next(iter(objective.values())) == 1.0:
        return next(iter(objective))
    return tuple(sorted((str(k), float(v)) for k, v in objective.items()))


@dataclass(frozen=True)
class StudyProblems:
    """The design problems of a resolved study, built in any process.

    Called as :func:`collision_reflex.optimize.pareto.pareto_front` builds them:
    ``StudyProblems(study)(objective, bounded)``, or on some of the samples (an active set)
    ``StudyProblems(study)(objective, bounded, samples)``. ``extra``: samples a worst-case search added to the
    study's (the exchange method). Hashable and picklable: the problems are cached per process by it.
    """

    study: ResolvedStudy
    extra: ExtraSamples = ()

    @classmethod
    def of_run(cls, folder: str | os.PathLike[str]) -> StudyProblems:
        """The problems a finished run solved last: its resolved study and the samples its searches added.

        Read from the run folder's ``study.resolved.yaml`` and ``designs.json`` (``domain.searched``).
        """
        path = Path(folder)
        results = json.loads((path / DESIGNS).read_text(encoding="utf-8"))
        extra = tuple((tuple(q), tuple(u)) for q, u in results["domain"]["searched"])
        return cls(ResolvedStudy.of(load_study(path / RESOLVED)), extra)

    def __call__(
        self, objective: Hashable, bounded: tuple[str, ...] = (), samples: ContactSamples | None = None
    ) -> DesignProblem:
        """The design problem for ``objective`` (an :func:`objective_key`), on ``samples`` (default all).

        The objectives named in ``bounded`` can be bounded per solve (epsilon-constraint Pareto sweeps).
        """
        setup = self.setup
        weighted: Any = objective if isinstance(objective, str) else dict(objective)  # type: ignore[call-overload]
        return build_problem(
            setup.arm,
            setup.samples if samples is None else samples,
            setup.space,
            setup.technology,
            weighted,
            setup.constraints,
            bounded,
        )

    @property
    def setup(self) -> ArmSetup:
        """The study's setup (built once per process)."""
        return study_setup(self.study, self.extra)

    @property
    def objective(self) -> Hashable:
        """The study's own objective (for :func:`collision_reflex.optimize.pieces.built_problem`)."""
        return objective_key(self.setup.study.objective)

    @property
    def active_set(self) -> str:
        """How the study's problems are solved: on active sets of the samples or not (``optimizer.active_set``)."""
        return self.setup.study.optimizer.active_set


def checked_setup(loaded: LoadedStudy, study: ResolvedStudy) -> ArmSetup:
    """The setup of a study, with its problem built once.

    Every input problem (robot, frames, samples on which the arm cannot move, impossible bounds) is raised
    here, located in ``loaded`` (the study file as written), before a run writes anything; the problem is built
    from ``study`` (what the run solves).
    """
    assert isinstance(loaded.study, ArmStudy)
    setup = arm_setup(loaded)  # located errors for the robot, motors and names
    unreachable = torque_out_of_reach(loaded, setup)
    if unreachable:
        raise StudyFileError(loaded.source.file, unreachable)
    try:
        problems = StudyProblems(study)
        built_problem(problems, problems.objective)
    except InvalidParameter as error:
        raise located_refusal(loaded, error) from None
    return setup
