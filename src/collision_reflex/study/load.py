"""Loading and validating study files: YAML → schema → cross-field checks, every problem reported at once.

:func:`load_study` reads a file and returns a validated :data:`~.schema.Study` (or raises
:class:`~collision_reflex.errors.StudyFileError` listing every problem with its line). The checks across fields
are in :mod:`.checks`; those that need the robot model (frames, joint names, configuration sizes) are in
:mod:`.robot` and run when a study is prepared.
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
from .checks import cross_checks
from .schema import STUDY_KINDS, Study
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


def study_from_data(
    data: Any, file: str = "<data>", directory: str | os.PathLike[str] | None = None
) -> LoadedStudy:
    """Validate a study given as plain data (as :func:`parse_study`, without YAML).

    For a study derived from a validated one (shrunk for a smoke run, a gearbox option assigned): its problems
    are told at ``file`` without a line.
    """
    return _validated(StudySource(file, Path(directory) if directory is not None else Path.cwd(), data, {}))


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
    problems += cross_checks(loaded)
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
