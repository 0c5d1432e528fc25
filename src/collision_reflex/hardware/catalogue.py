"""Reading part catalogues (motors, gearboxes): YAML with line numbers, validated by pydantic, units by pint.

Kept apart from :mod:`collision_reflex.hardware.motors` so that the scaling arithmetic imports nothing heavy.

Provenance: every entry cites a ``source`` (the default source of each of its numbers); ``sources: {field:
text}`` names another source for some fields, and ``estimates: {field: method}`` marks a field that no source
gives, with the method that estimated it. :func:`read_entries` returns each field's provenance, so that every
number can be traced to a datasheet, a paper, or a stated estimate. The descriptive fields ``maker`` and, for
motors, ``construction`` (``frameless`` or ``housed``) are optional, carry no number and need no provenance.
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import yaml
from pydantic import ValidationError

from .._io import read_limited
from .._yaml import LOADER, NodeProblem, check_depth, check_nodes, one_line
from ..errors import CatalogueError
from ..vocabulary import PER_RATIO_FIELDS
from .catalogue_schema import DESCRIPTIVE_FIELDS, ENTRY_SCHEMAS, PROVENANCE_FIELDS, CitedEntry, excerpt

# A rotor cannot hold more inertia than the whole motor mass at 1.4 x the stator radius (2 ~ 1.4^2), even
# for an outer rotor: a larger value is a unit slip (kg*cm^2 written as kg*m^2) or a wrong field.
_MAX_INERTIA_PER_MASS_RADIUS2 = 2.0

CATALOGUE_LIMIT = 4 * 2**20
"""Largest catalogue file read [bytes]: the packaged ones are tens of kilobytes; a multi-megabyte one is not a
catalogue but a mistake, refused before it is parsed (parsing YAML costs far more than its size)."""

CATALOGUE_NODES = 100_000
"""Most values (scalars, mappings, lists) a catalogue file may hold: the packaged ones hold about 500."""


def packaged_catalogue_path(file: str = "motors.yaml") -> Path:
    """Return the path of a catalogue shipped with the package, ``designs/<file>``.

    Looked for inside the package (a wheel that includes the ``designs`` data) and then in the source tree
    (a checkout or an editable install).

    Parameters
    ----------
    file : str
        The catalogue's file name: ``"motors.yaml"`` or ``"gearboxes.yaml"``.
    """
    package = Path(__file__).resolve().parents[1]
    for candidate in (package / "designs" / file, package.parents[1] / "designs" / file):
        if candidate.is_file():
            return candidate
    raise CatalogueError(
        str(package.parents[1] / "designs" / file),
        None,
        "",
        f"the packaged catalogue {file} is missing; reinstall collision-reflex or pass a catalogue file",
    )


@dataclass(frozen=True)
class CatalogueEntry:
    """One validated catalogue entry.

    Parameters
    ----------
    fields : dict
        The part's fields, numbers in SI units, with ``source`` (the default source).
    provenance : dict
        Field -> where its value comes from: ``"source: ..."`` or ``"ESTIMATE: <method>"``, for every field
        the entry gives.
    line : int
        1-based line of the entry's name in its file.
    description : dict
        The descriptive fields the entry gives (``maker``, ``construction``), text only.
    """

    fields: dict[str, Any]
    provenance: dict[str, str]
    line: int
    description: dict[str, str]


def read_catalogue(path: Path) -> dict[str, dict[str, Any]]:
    """Return the entries of a motor catalogue file, each a dict of ``Motor`` fields (SI).

    Parameters
    ----------
    path : Path
        The YAML file, with a top-level ``motors`` mapping.
    """
    return {
        name: {key: value for key, value in entry.fields.items() if key not in ("sources", "estimates")}
        for name, entry in read_entries(path, "motors").items()
    }


def read_entries(path: Path, kind: str = "motors") -> dict[str, CatalogueEntry]:
    """Return the validated entries of a catalogue file, with each field's provenance.

    Parameters
    ----------
    path : Path
        The YAML file.
    kind : str
        ``"motors"``, ``"gearboxes"`` or ``"body_regions"``: the file's one top-level key and the entries'
        schema.

    Raises
    ------
    CatalogueError
        Naming the file, the line and the field: bad YAML, a missing, unknown or mistyped field, a unit of
        the wrong dimension, a non-physical value, or an entry without a source.
    """
    try:
        data = _file_bytes(path)
        key = (str(path), kind, hashlib.sha256(data).digest())
        if key not in _READ:
            _READ[key] = _parsed_entries(str(path), data, kind)
    except CatalogueError as error:
        texts = (str(error.path), error.field, error.reason)
        if all(text.isprintable() for text in texts):
            raise
        # A message quotes field names and values of the file: escape what would break or hide its line.
        path_text, field, reason = map(one_line, texts)
        raise CatalogueError(path_text, error.line, field, reason) from None
    return dict(_READ[key])


# A study reads its catalogues once per problem it builds: the validated entries of a file are kept, keyed by
# its content (entries are frozen; callers copy their fields).
_READ: dict[tuple[str, str, bytes], dict[str, CatalogueEntry]] = {}


def _file_bytes(path: Path) -> bytes:
    """The file's bytes, or a :class:`CatalogueError` saying why they cannot be read."""
    try:
        return read_limited(path, CATALOGUE_LIMIT)
    except (OSError, ValueError) as error:  # ValueError: a NUL byte in the path
        reason = getattr(error, "strerror", None) or str(error)
        raise CatalogueError(str(path), None, "", f"cannot read the file ({reason})") from None


def _parsed_entries(name: str, data: bytes, kind: str) -> dict[str, CatalogueEntry]:
    """The validated entries of file ``name``'s ``data`` (see :func:`read_entries`)."""
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as error:
        at = data.count(b"\n", 0, error.start) + 1
        raise CatalogueError(name, at, "", f"the byte 0x{data[error.start]:02x} is not UTF-8 text") from None
    try:
        check_depth(text, CATALOGUE_NODES)  # libyaml's composer recurses in C: a deep file would crash it
        root = yaml.compose(text, Loader=LOADER)
        if root is not None:
            check_nodes(root)  # before constructing any value: tags, alias bombs, huge values
    except NodeProblem as error:
        field = ".".join(map(str, error.path))
        raise CatalogueError(name, error.line, field, f"not valid YAML: {error.reason}") from None
    except yaml.reader.ReaderError as error:  # a character YAML does not allow
        at = text.count("\n", 0, error.position) + 1
        raise CatalogueError(name, at, "", f"not valid YAML: {' '.join(error.reason.split())}") from None
    except yaml.YAMLError as error:
        mark = getattr(error, "problem_mark", None)
        line = mark.line + 1 if mark is not None else None
        problem = getattr(error, "problem", None) or str(error)
        raise CatalogueError(name, line, "", f"not valid YAML: {' '.join(problem.split())}") from None
    except RecursionError:
        raise CatalogueError(name, None, "", "not valid YAML: nesting too deep") from None
    if not isinstance(root, yaml.MappingNode):
        line = _line(root) if root is not None else 1  # None: an empty file
        raise CatalogueError(name, line, "", f"expected a mapping with a top-level {kind!r} key")
    top = _mapping(root, name, "")
    if kind not in top:
        raise CatalogueError(name, 1, kind, f"missing: the file needs a top-level {kind!r} mapping")
    unknown = sorted(set(top) - {kind})
    if unknown:
        key_node, _ = top[unknown[0]]
        raise CatalogueError(
            name, _line(key_node), unknown[0], f"unknown top-level key; only {kind!r} is allowed"
        )
    _, parts_node = top[kind]
    if not isinstance(parts_node, yaml.MappingNode):
        raise CatalogueError(name, _line(parts_node), kind, "expected a mapping from part name to entry")
    for key_node, _ in parts_node.value:
        part = key_node.value if isinstance(key_node, yaml.ScalarNode) else None
        if not isinstance(part, str) or not part.isprintable():
            shown = excerpt(part) if isinstance(part, str) else "a mapping or list"
            raise CatalogueError(
                name, _line(key_node), kind, f"a part name must be text on one line, got {shown}"
            )
    return {
        part: _entry(name, kind, part, key_node, entry_node)
        for part, (key_node, entry_node) in _mapping(parts_node, name, kind).items()
    }


def _entry(file: str, kind: str, part: str, key_node: Any, entry_node: Any) -> CatalogueEntry:
    """One entry validated, or a located :class:`CatalogueError`."""
    model, required, optional = ENTRY_SCHEMAS[kind]
    allowed = ", ".join(required) + ", and optionally " + ", ".join(optional)
    where = f"{kind}.{part}"
    if not isinstance(entry_node, yaml.MappingNode):
        raise CatalogueError(file, _line(key_node), where, "expected a mapping of the part's fields")
    fields = _mapping(entry_node, file, where)
    raw = {key: _plain(value_node) for key, (_, value_node) in fields.items()}
    try:
        entry = model.model_validate(raw)
    except ValidationError as error:
        first = error.errors()[0]
        field = str(first["loc"][0]) if first["loc"] else ""
        if first["type"] == "missing":
            line = _line(key_node)
            reason = f"missing (an entry needs {allowed})"
        elif first["type"] == "extra_forbidden":
            line = _line(fields[field][0])
            reason = f"unknown field (allowed: {allowed})"
        else:
            line = _line(fields[field][1]) if field in fields else _line(key_node)
            reason = f"{first['msg']} (got {excerpt(raw.get(field))})"
        raise CatalogueError(file, line, f"{where}.{field}", reason) from None

    def refuse(field: str, reason: str) -> CatalogueError:
        return CatalogueError(file, _line(fields[field][1]), f"{where}.{field}", reason)

    values = entry.model_dump()
    if kind == "gearboxes":
        _check_ratios(values, fields, refuse, file, key_node, where)
    for at, figures in _figures_at_each_ratio(values):
        for lower, upper in (("continuous_torque", "peak_torque"), ("rated_torque", "peak_torque")):
            if figures.get(lower) is not None and figures[lower] > figures[upper]:
                raise refuse(
                    lower, f"{figures[lower]:g} N m exceeds the peak torque {figures[upper]:g} N m{at}"
                )
        if (
            figures.get("momentary_torque") is not None
            and figures["momentary_torque"] < figures["peak_torque"]
        ):
            raise refuse("momentary_torque", f"is below the (repeated) peak torque{at}")
    if kind == "motors":
        _check_inertia(values, refuse)
    elif (
        kind == "body_regions"
        and values["transient_force"] is not None
        and values["transient_force"] < values["quasi_static_force"]
    ):
        raise refuse(
            "transient_force",
            f"{values['transient_force']:g} N is below the quasi-static force {values['quasi_static_force']:g} N "
            "(ISO/TS 15066 allows a transient contact at least the quasi-static force)",
        )
    description = {key: values.pop(key) for key in DESCRIPTIVE_FIELDS if key in values}
    description = {key: text for key, text in description.items() if text is not None}
    given = [key for key in fields if key not in (*PROVENANCE_FIELDS, *DESCRIPTIVE_FIELDS)]
    return CatalogueEntry(
        values, _provenance(file, where, fields, entry, given), _line(key_node), description
    )


def _check_inertia(values: dict[str, Any], refuse: Any) -> None:
    """Refuse a rotor inertia [kg m^2] that no motor of that mass [kg] and stator diameter [m] can have."""
    bound = _MAX_INERTIA_PER_MASS_RADIUS2 * values["mass"] * (values["stator_diameter"] / 2) ** 2
    if values["rotor_inertia"] > bound:
        raise refuse(
            "rotor_inertia",
            f"{values['rotor_inertia']:g} kg m^2 exceeds {_MAX_INERTIA_PER_MASS_RADIUS2:g} x mass x (stator "
            f"diameter / 2)^2 = {bound:g} kg m^2, more than the whole motor could hold: check the unit "
            "(kg*cm^2 or g*cm^2 written as kg*m^2?)",
        )


def _check_ratios(
    values: dict[str, Any], fields: dict[str, Any], refuse: Any, file: str, key: Any, where: str
) -> None:
    """A gearbox gives exactly one of ``ratios`` (a list) and ``ratio_range`` (min, max, not inverted)."""
    if (values["ratios"] is None) == (values["ratio_range"] is None):
        raise CatalogueError(
            file,
            _line(key),
            f"{where}.ratios",
            "give exactly one of 'ratios' (a list) or 'ratio_range' [min, max]",
        )
    low_high = values["ratio_range"]
    if low_high is not None and (len(low_high) != 2 or low_high[0] > low_high[1]):
        raise refuse("ratio_range", f"expected [min, max] with min <= max, got {low_high!r}")
    listed = values["ratios"]
    for field in PER_RATIO_FIELDS:
        if not isinstance(values[field], dict):
            continue
        if listed is None:
            raise refuse(
                field,
                "a figure per ratio needs the list 'ratios', not a 'ratio_range' (any ratio between): "
                "give one number",
            )
        offered = ", ".join(f"{r:g}" for r in listed)
        seen: set[float] = set()
        for ratio_node, _ in fields[field][1].value:
            ratio, text = _plain(ratio_node), str(ratio_node.value)
            if ratio in seen:  # YAML keeps one of two equal keys (3 and 3.0): one figure would be lost
                raise CatalogueError(
                    file, _line(ratio_node), f"{where}.{field}.{text}", f"ratio {ratio:g} given twice"
                )
            seen.add(ratio)
            if ratio not in listed:
                raise CatalogueError(
                    file,
                    _line(ratio_node),
                    f"{where}.{field}.{text}",
                    f"not one of the ratios offered ({offered}): one figure per ratio of 'ratios'",
                )
        missing = [r for r in listed if r not in values[field]]
        if missing:
            raise refuse(
                field,
                f"no figure for ratio {', '.join(f'{r:g}' for r in missing)}: give one for every ratio of "
                f"'ratios' ({offered}), or one number for all",
            )


def _figures_at_each_ratio(values: dict[str, Any]) -> list[tuple[str, dict[str, Any]]]:
    """``(" at ratio N", figures)`` for each ratio of an entry with per-ratio figures; else ``[("", values)]``."""
    per_ratio = [field for field in PER_RATIO_FIELDS if isinstance(values.get(field), dict)]
    if not per_ratio:
        return [("", values)]
    return [
        (f" at ratio {ratio:g}", {**values, **{field: values[field][ratio] for field in per_ratio}})
        for ratio in values["ratios"]
    ]


def _provenance(
    file: str, where: str, fields: dict[str, Any], entry: CitedEntry, given: list[str]
) -> dict[str, str]:
    """Field -> its source or estimate; per-field keys must name given fields, and not both at once."""
    for table in ("sources", "estimates"):
        if table not in fields:
            continue
        for key, (key_node, value_node) in _mapping(fields[table][1], file, f"{where}.{table}").items():
            text = _plain(value_node)
            if key not in given:
                raise CatalogueError(
                    file,
                    _line(key_node),
                    f"{where}.{table}.{key}",
                    f"names no field of this entry ({', '.join(given)})",
                )
            if not str(text).strip():
                raise CatalogueError(
                    file, _line(key_node), f"{where}.{table}.{key}", "empty: say where or how"
                )
    both = sorted(set(entry.sources) & set(entry.estimates))
    if both:
        key_node = next(k for k, _ in fields["estimates"][1].value if k.value == both[0])
        raise CatalogueError(
            file,
            _line(key_node),
            f"{where}.estimates.{both[0]}",
            "also has a source: a field is sourced or estimated",
        )
    return {
        field: f"ESTIMATE: {entry.estimates[field]}"
        if field in entry.estimates
        else f"source: {entry.sources.get(field, entry.source)}"
        for field in given
    }


def _mapping(node: Any, file: str, where: str) -> dict[str, tuple[Any, Any]]:
    """Key -> (key node, value node) of a YAML mapping node (keys as text); a repeated key is refused.

    YAML keeps the last of two equal keys: a part or field written twice would silently lose one of them.
    """
    items: dict[str, tuple[Any, Any]] = {}
    for key, value in node.value:
        text = str(key.value)
        if text in items:
            first = _line(items[text][0])
            raise CatalogueError(
                file, _line(key), f"{where}.{text}".lstrip("."), f"given twice (first on line {first})"
            )
        items[text] = (key, value)
    return items


def _line(node: Any) -> int:
    return int(node.start_mark.line) + 1


def _plain(node: Any) -> Any:
    """A scalar node as Python (int/float/str/bool/None); other nodes as their constructed value.

    A value the safe loader cannot construct (an impossible date, an integer of 5,000 digits) is returned as
    its text, which validation then refuses at its line.
    """
    try:
        return yaml.SafeLoader("").construct_document(node)
    except (yaml.YAMLError, ValueError, OverflowError):
        return node.value if isinstance(node, yaml.ScalarNode) else None
