"""Loading and validating study files: YAML → schema → cross-field checks, every problem reported at once.

:func:`load_study` reads a file and returns a validated :data:`~.schema.Study` (or raises
:class:`~collision_reflex.errors.StudyFileError` listing every problem with its line). Checks that need the robot
model (frames, joint names, configuration sizes) are in :mod:`.robot` and run when a study is prepared.
"""

from __future__ import annotations

import difflib
import os
import types
import typing
from collections.abc import Hashable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from pydantic import BaseModel, ValidationError

from ..errors import StudyFileError, StudyProblem
from .schema import (
    STUDY_KINDS,
    ActuatorStudy,
    ArmStudy,
    Study,
)
from .source import StudySource, excerpt, parse_study_source, read_study_source

_FOUND_LIMIT = 60


@dataclass(frozen=True)
class LoadedStudy:
    """A validated study with the source it came from (for locating later problems).

    study: the validated study (:class:`~.schema.ArmStudy` or :class:`~.schema.ActuatorStudy`).
    source: the parsed YAML with node positions.
    """

    study: Study
    source: StudySource

    @property
    def directory(self) -> Path:
        """Directory that relative paths in the study are relative to."""
        return self.source.directory

    def path(self, relative: str) -> Path:
        """A path named in the study, resolved against the study file's directory."""
        return (self.directory / relative).resolve()

    def problem(self, path: Sequence[Hashable], found: str, expected: str) -> StudyProblem:
        """A problem at ``path``, located at its line in the study file."""
        return self.source.problem(path, found, expected)

    def fail(self, path: Sequence[Hashable], found: str, expected: str) -> StudyFileError:
        """A :class:`StudyFileError` with one problem at ``path`` (to raise)."""
        return StudyFileError(self.source.file, [self.problem(path, found, expected)])


def load_study(path: str | os.PathLike[str]) -> LoadedStudy:
    """Read and validate a study file (schema and cross-field checks; not the robot model)."""
    return _validated(read_study_source(path))


def parse_study(
    text: str, file: str = "<string>", directory: str | os.PathLike[str] | None = None
) -> LoadedStudy:
    """Validate study text (as :func:`load_study`).

    Relative paths resolve against ``directory`` (default: the working directory).
    """
    return _validated(parse_study_source(text, file, Path(directory) if directory is not None else None))


def _validated(source: StudySource) -> LoadedStudy:
    problems = [
        source.problem(path, f"the key {excerpt(path[-1])} more than once", "each key once in a mapping")
        for path in source.duplicate_keys
    ]
    data = source.data
    if not isinstance(data, dict):
        found = "an empty file" if data is None else f"a {type(data).__name__}"
        problems.append(source.problem((), found, "a mapping of study sections (name, robot, ...)"))
        raise StudyFileError(source.file, problems)
    kind = data.get("kind", "arm")
    model = STUDY_KINDS.get(kind) if isinstance(kind, str) else None
    if model is None:
        problems.append(
            source.problem(("kind",), _found(kind), "one of " + ", ".join(map(repr, STUDY_KINDS)))
        )
        raise StudyFileError(source.file, problems)
    try:
        study: Study = model.model_validate(data)  # type: ignore[assignment]
    except ValidationError as error:
        problems += [_problem_from_pydantic(source, model, item) for item in error.errors()]
        raise StudyFileError(source.file, problems) from None
    loaded = LoadedStudy(study, source)
    problems += _cross_checks(loaded)
    if problems:
        raise StudyFileError(source.file, problems)
    return loaded


def _problem_from_pydantic(source: StudySource, model: type[BaseModel], item: Any) -> StudyProblem:
    path = source.resolve_path(item["loc"])
    kind = item["type"]
    context = item.get("ctx") or {}
    if kind == "extra_forbidden":
        allowed = _allowed_keys(model, path[:-1])
        known = "a known key"
        if allowed:
            close = difflib.get_close_matches(str(path[-1]), allowed, n=1)
            known = (f"{close[0]!r}? " if close else "") + "one of " + ", ".join(allowed)
        return source.problem(path, f"unknown key {excerpt(path[-1])}", known)
    if kind == "missing":
        return source.problem(path, "nothing", f"the required field {path[-1]!r}" if path else "a value")
    expected: str | None = context.get("expected") if kind.startswith("quantity") else None
    if expected is None:
        expected = _lower_first(item["msg"].removeprefix("Value error, "))
    if kind == "quantity_dimension":
        expected = f"{context['expected']} — {context['found']!r} is {context['found_dimension']}"
    return source.problem(path, _found(item.get("input")), expected)


def _lower_first(text: str) -> str:
    text = text.removeprefix("Input should be ")
    return text[:1].lower() + text[1:]


def _found(value: Any) -> str:
    """A short description of a value found in the file: an excerpt, never the whole of a large value."""
    return excerpt(value, _FOUND_LIMIT)


def _allowed_keys(model: type[BaseModel], path: Sequence[Hashable]) -> list[str]:
    """Field names of the model at ``path`` below ``model`` (empty if it cannot be told)."""
    target: Any = model
    for key in path:
        target = _child_type(target, key)
        if target is None:
            return []
    models = _models_in(target)
    return sorted(models[0].model_fields) if len(models) == 1 else []


def _child_type(annotation: Any, key: Any) -> Any:
    for candidate in _unwrapped(annotation):
        if isinstance(candidate, type) and issubclass(candidate, BaseModel):
            if key in candidate.model_fields:
                return candidate.model_fields[key].annotation
            continue
        origin = typing.get_origin(candidate)
        args = typing.get_args(candidate)
        if origin is dict and len(args) == 2:
            return args[1]
        if origin in (list, tuple) and args and isinstance(key, int):
            return args[0]
    return None


def _unwrapped(annotation: Any) -> list[Any]:
    origin = typing.get_origin(annotation)
    if origin is typing.Annotated:
        return _unwrapped(typing.get_args(annotation)[0])
    if origin in (typing.Union, types.UnionType):
        return [part for arg in typing.get_args(annotation) for part in _unwrapped(arg)]
    return [annotation]


def _models_in(annotation: Any) -> list[type[BaseModel]]:
    return [c for c in _unwrapped(annotation) if isinstance(c, type) and issubclass(c, BaseModel)]


# --- checks across fields (no robot model needed) ---------------------------------------------------------------


def _cross_checks(loaded: LoadedStudy) -> list[StudyProblem]:
    study = loaded.study
    if isinstance(study, ArmStudy):
        return _arm_checks(loaded, study)
    if isinstance(study, ActuatorStudy):
        return _actuator_checks(loaded, study)
    return []  # pragma: no cover - the kinds are exhaustive


def _arm_checks(loaded: LoadedStudy, study: ArmStudy) -> list[StudyProblem]:
    problems: list[StudyProblem] = []
    scheme = study.sensing.scheme
    if scheme == "current":
        problems.append(
            loaded.problem(
                ("sensing", "scheme"),
                "'current'",
                "'force' or 'position' for an arm study: a motor-current threshold makes the contact threshold "
                "a minimum over joints, which the optimiser does not handle; compare current sensing in an "
                "actuator study (kind: actuator)",
            )
        )
    design = study.design
    if design.threshold is not None and scheme != "force":
        problems.append(
            loaded.problem(
                ("design", "threshold"),
                f"a contact-force threshold with sensing scheme {scheme!r}",
                "design.position_error for position sensing (or sensing.scheme: force)",
            )
        )
    if design.position_error is not None and scheme != "position":
        problems.append(
            loaded.problem(
                ("design", "position_error"),
                f"a position-error threshold with sensing scheme {scheme!r}",
                "design.threshold for force sensing (or sensing.scheme: position)",
            )
        )
    if study.pareto is not None:
        for index, name in enumerate(study.pareto.objectives):
            if name == "approach_velocity" and (
                design.approach_velocity is None or _fixed(design.approach_velocity)
            ):
                problems.append(
                    loaded.problem(
                        ("pareto", "objectives", index),
                        "'approach_velocity' while the velocity is fixed",
                        "free bounds design.approach_velocity: {min, max} to trade it off",
                    )
                )
    robot = study.robot
    if robot.urdf is not None and not _is_file(loaded.path(robot.urdf)):
        problems.append(
            loaded.problem(("robot", "urdf"), f"{excerpt(robot.urdf)} (no such file)", _relative_hint(loaded))
        )
    for index, directory in enumerate(robot.package_dirs):
        if not _is_dir(loaded.path(directory)):
            problems.append(
                loaded.problem(
                    ("robot", "package_dirs", index),
                    f"{excerpt(directory)} (no such directory)",
                    _relative_hint(loaded),
                )
            )
    trajectory = study.samples.configurations.trajectory
    if trajectory is not None and not _is_file(loaded.path(trajectory.file)):
        problems.append(
            loaded.problem(
                ("samples", "configurations", "trajectory", "file"),
                f"{excerpt(trajectory.file)} (no such file)",
                _relative_hint(loaded),
            )
        )
    problems += _duty_cycle_checks(loaded, study)
    lengths = {len(q) for q in study.samples.configurations.list or []}
    if len(lengths) > 1:
        problems.append(
            loaded.problem(
                ("samples", "configurations", "list"),
                f"configurations of sizes {sorted(lengths)}",
                "every configuration with the same number of joint positions",
            )
        )
    directions = study.samples.directions.list or []
    if len({len(u) for u in directions}) > 1:
        problems.append(
            loaded.problem(
                ("samples", "directions", "list"),
                "vectors of different sizes",
                "every direction with the same number of components (2 for a planar arm, else 3)",
            )
        )
    return problems


def _duty_cycle_checks(loaded: LoadedStudy, study: ArmStudy) -> list[StudyProblem]:
    """The trajectory file exists; the payload is given once (``duty_cycle.payload`` or ``constraints.payload``)."""
    cycle = study.duty_cycle
    if cycle is None:
        return []
    problems = []
    if cycle.file is not None and not _is_file(loaded.path(cycle.file)):
        problems.append(
            loaded.problem(
                ("duty_cycle", "file"), f"{excerpt(cycle.file)} (no such file)", _relative_hint(loaded)
            )
        )
    if cycle.payload is not None and study.constraints.payload != 0:
        problems.append(
            loaded.problem(
                ("constraints", "payload"),
                f"a payload of {study.constraints.payload:g} kg here and another in duty_cycle.payload",
                "the payload once: remove constraints.payload (duty_cycle.payload loads the static "
                "requirement too)",
            )
        )
    return problems


def _is_file(path: Path) -> bool:
    """Whether ``path`` is a regular file; False for a path the system refuses (too long, a NUL)."""
    try:
        return path.is_file()
    except (OSError, ValueError):
        return False


def _is_dir(path: Path) -> bool:
    """Whether ``path`` is a directory; False for a path the system refuses."""
    try:
        return path.is_dir()
    except (OSError, ValueError):
        return False


def _fixed(variable: Any) -> bool:
    lower, upper = variable.bounds
    return bool(lower == upper)


def _relative_hint(loaded: LoadedStudy) -> str:
    return "a path relative to the study file's folder"


def _actuator_checks(loaded: LoadedStudy, study: ActuatorStudy) -> list[StudyProblem]:
    problems: list[StudyProblem] = []
    if not study.velocities.min <= study.approach_velocity <= study.velocities.max:
        problems.append(
            loaded.problem(
                ("approach_velocity",),
                f"{study.approach_velocity:g} m/s",
                f"a velocity within velocities [{study.velocities.min:g}, {study.velocities.max:g}] m/s",
            )
        )
    return problems
