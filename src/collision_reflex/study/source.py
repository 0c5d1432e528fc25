"""Reading a study file's YAML with the position of every node, so that any problem can name its line.

PyYAML's composer gives the node tree with start marks; the same safe loader then constructs plain Python data
from it, once the tree is known to be of bounded size (:func:`collision_reflex._yaml.check_nodes`: no alias bomb,
no tags, no huge values). :class:`StudySource` keeps both and maps a field path (keys and list indices) to a
line and column. Every problem is one line of printable text, whatever the file holds.
"""

from __future__ import annotations

import os
import reprlib
from collections.abc import Hashable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import yaml

from .._yaml import LOADER, NodeProblem, check_depth, check_nodes, one_line
from ..errors import StudyFileError, StudyProblem

PathKey = tuple[Hashable, ...]
"""A field path in a study: mapping keys (as YAML constructs them) and list indices."""

MAX_FILE_SIZE = 1 << 20
"""Largest study file read [bytes]: the shipped studies are a few kB."""

_FOUND_LENGTH = 160


@dataclass(frozen=True)
class StudySource:
    """A study's YAML: the constructed data and the position of every node.

    Attributes
    ----------
    file: the file name used in messages.
    directory: the directory paths in the study are relative to [absolute].
    data: the document as plain Python data (``None`` for an empty file).
    positions: ``(line, column)`` (1-based) of each node by its path; a mapping entry's position is its key's.
    duplicate_keys: paths of keys that appear more than once in the same mapping (YAML keeps the last).
    """

    file: str
    directory: Path
    data: Any
    positions: dict[PathKey, tuple[int, int]] = field(repr=False)
    duplicate_keys: tuple[PathKey, ...] = ()

    def locate(self, path: Sequence[Hashable]) -> tuple[int, int]:
        """Line and column of ``path``, or of its nearest ancestor that exists in the file."""
        path = tuple(path)
        while path and path not in self.positions:
            path = path[:-1]
        return self.positions.get(path, (1, 1))

    def resolve_path(self, path: Sequence[Hashable]) -> PathKey:
        """``path`` with the components that do not exist in the file dropped.

        Validators insert the names of union branches or wrapper functions into error locations.
        """
        kept: list[Hashable] = []
        node = self.data
        for key in path:
            if isinstance(node, dict) and key in node:
                node = node[key]
                kept.append(key)
            elif isinstance(node, list) and isinstance(key, int) and 0 <= key < len(node):
                node = node[key]
                kept.append(key)
            elif isinstance(node, (dict, list)) and not _looks_internal(key):
                kept.append(key)  # a missing field or key: still part of the path, with no further node
                node = None
            # else: an internal location component (union branch, validator name); skip it
        return tuple(kept)

    def problem(self, path: Sequence[Hashable], found: str, expected: str) -> StudyProblem:
        """A :class:`StudyProblem` at ``path`` (a path in the file's data)."""
        line, column = self.locate(path)
        return problem_at(self.file, line, column, format_path(path), found, expected)


def excerpt(value: Any, limit: int = 60) -> str:
    """A short description of a value found in the file: its repr, cut to ``limit`` characters.

    reprlib looks at a few items of each level only, so describing a huge value costs no more than a small one.
    """
    text = _EXCERPT.repr(value)
    return text if len(text) <= limit else text[: limit - 3] + "..."


_EXCERPT = reprlib.Repr()
_EXCERPT.maxlevel, _EXCERPT.maxdict, _EXCERPT.maxlist, _EXCERPT.maxtuple = 3, 4, 4, 4
_EXCERPT.maxstring = _EXCERPT.maxother = 60


def problem_at(file: str, line: int, column: int, path: str, found: str, expected: str) -> StudyProblem:
    """A :class:`StudyProblem` whose texts are each one line of printable characters (others escaped)."""
    found = one_line(found)
    if len(found) > _FOUND_LENGTH:  # what the file holds, quoted as a short excerpt
        found = found[: _FOUND_LENGTH - 3] + "..."
    return StudyProblem(one_line(file), line, column, one_line(path), found, one_line(expected))


def _looks_internal(key: Hashable) -> bool:
    text = str(key)
    return "[" in text or ("-" in text and not text.startswith(("+", "-")))


def format_path(path: Sequence[Hashable]) -> str:
    """A location path as dotted text, list indices as ``[i]``.

    ``("actuators", "joints", "j2", "gear_ratio")`` -> ``"actuators.joints.j2.gear_ratio"``.
    """
    text = ""
    for key in path:
        if isinstance(key, int):
            text += f"[{key}]"
        else:
            text += ("." if text else "") + str(key)
    return text


def read_study_source(path: str | os.PathLike[str]) -> StudySource:
    """Read a study file.

    A missing or unreadable file, one over :data:`MAX_FILE_SIZE`, text that is not UTF-8, or YAML that does
    not parse raises :class:`~collision_reflex.errors.StudyFileError` with the line.
    """
    name = str(path)

    def fail(line: int, column: int, found: str, expected: str) -> StudyFileError:
        return StudyFileError(name, [problem_at(name, line, column, "", found, expected)])

    file = Path(path)
    try:
        if file.exists() and not file.is_file():
            raise fail(0, 0, "not a regular file", "the path of a study file (YAML)")
        with file.open("rb") as stream:
            data = stream.read(MAX_FILE_SIZE + 1)
    except FileNotFoundError:
        raise fail(0, 0, "no such file", "the path of a study file (YAML)") from None
    except (OSError, ValueError) as error:  # ValueError: a NUL byte in the path
        reason = getattr(error, "strerror", None) or str(error)
        raise fail(0, 0, f"a file that cannot be read ({reason})", "a UTF-8 YAML file") from None
    if len(data) > MAX_FILE_SIZE:
        raise fail(0, 0, f"a file over {MAX_FILE_SIZE >> 20} MiB", "a study file (a few kB of YAML)")
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as error:
        start = data.rfind(b"\n", 0, error.start) + 1
        line = data.count(b"\n", 0, error.start) + 1
        column = len(data[start : error.start].decode("utf-8", "replace")) + 1
        raise fail(
            line, column, f"the byte 0x{data[error.start]:02x}, not UTF-8 text", "a UTF-8 file"
        ) from None
    return parse_study_source(text, name, file.resolve().parent)


def parse_study_source(text: str, file: str = "<string>", directory: Path | None = None) -> StudySource:
    """Parse YAML text into a :class:`StudySource`; errors as for :func:`read_study_source`."""
    directory = directory if directory is not None else Path.cwd()
    try:
        loader = _LOADER(text)
    except UnicodeEncodeError as error:  # a lone surrogate in text given directly (a file's text has none)
        line = text.count("\n", 0, error.start) + 1
        column = error.start - (text.rfind("\n", 0, error.start) + 1) + 1
        found = "a lone surrogate (not a Unicode character)"
        raise StudyFileError(file, [problem_at(file, line, column, "", found, "text")]) from None
    try:
        check_depth(text)  # libyaml's composer recurses in C: a deep file would crash it
        node = loader.get_single_node()
        if node is not None:
            check_nodes(node)  # before constructing: an alias bomb or a tag is refused here
        data = loader.construct_document(node) if node is not None else None
    except yaml.reader.ReaderError as error:  # a character YAML does not allow
        line = text.count("\n", 0, error.position) + 1
        column = error.position - (text.rfind("\n", 0, error.position) + 1) + 1
        character = error.character if isinstance(error.character, str) else chr(error.character)
        found = f"the character {character!r}"
        raise StudyFileError(file, [problem_at(file, line, column, "", found, "printable text")]) from None
    except NodeProblem as error:
        found = f"invalid YAML ({error.reason})"
        where = format_path(error.path)
        problem = problem_at(file, error.line, error.column, where, found, "well-formed YAML of plain values")
        raise StudyFileError(file, [problem]) from None
    except yaml.MarkedYAMLError as error:
        mark = error.problem_mark or error.context_mark
        line, column = (mark.line + 1, mark.column + 1) if mark is not None else (1, 1)
        last = text.count("\n") + 1
        if line > last:  # libyaml marks the end of a file without a final line break on a line after it
            line, column = last, len(text) - (text.rfind("\n") + 1) + 1
        what = " ".join(part for part in (error.context, error.problem) if part)
        raise StudyFileError(
            file, [problem_at(file, line, column, "", f"invalid YAML ({what})", "well-formed YAML")]
        ) from None
    except (yaml.YAMLError, ValueError, OverflowError, RecursionError) as error:
        # The safe constructor can still fail on odd scalars (e.g. an impossible date): report it at the start.
        found = f"YAML that cannot be read ({error})"
        raise StudyFileError(file, [problem_at(file, 1, 1, "", found, "well-formed YAML")]) from None
    finally:
        loader.dispose()
    positions: dict[PathKey, tuple[int, int]] = {}
    duplicates: list[PathKey] = []
    if node is not None:
        _index(node, (), positions, duplicates, set())
    return StudySource(file, directory, data, positions, tuple(duplicates))


def _index(
    node: yaml.Node,
    path: PathKey,
    positions: dict[PathKey, tuple[int, int]],
    duplicates: list[PathKey],
    active: set[int],
) -> None:
    """Record the position of ``node`` and its children; ``active`` guards against recursive aliases."""
    positions.setdefault(path, (node.start_mark.line + 1, node.start_mark.column + 1))
    if id(node) in active:
        return
    active = active | {id(node)}
    if isinstance(node, yaml.MappingNode):
        seen: set[Any] = set()
        for key_node, value_node in node.value:
            key = key_node.value if isinstance(key_node, yaml.ScalarNode) else id(key_node)
            key = _constructed_key(key_node, key)
            if key in seen:
                duplicates.append((*path, key))
            seen.add(key)
            _index(value_node, (*path, key), positions, duplicates, active)
            # An entry is located at its key, where a reader looks for it.
            positions[(*path, key)] = (key_node.start_mark.line + 1, key_node.start_mark.column + 1)
    elif isinstance(node, yaml.SequenceNode):
        for index, item in enumerate(node.value):
            _index(item, (*path, index), positions, duplicates, active)


def _constructed_key(key_node: yaml.Node, raw: Any) -> Any:
    """The key as the safe loader constructs it (``1`` for ``1``, ``True`` for ``yes``...).

    So that paths from the data and from the node tree agree.
    """
    if not isinstance(key_node, yaml.ScalarNode):
        return raw
    try:
        return _KEY_CONSTRUCTOR.construct_document(key_node)
    except (yaml.YAMLError, ValueError, OverflowError):
        return raw


_LOADER = LOADER

_KEY_CONSTRUCTOR = yaml.SafeLoader("")
"""Constructs single key nodes (a loader over no text: only its constructor is used)."""
