"""Reading a saved run record: ``designs.json`` checked against its type (:mod:`.run`), damage named in one line.

The report and the export read a run's results through :func:`read_run_record`: no key missing or unknown, every
value of its type, every number finite; the first field that is not is named (``field 'gear_ratio' is missing:
recommended.joints[0] has fields ...``, ``field 'chosen.threshold' holds a value of the wrong kind (NaN, expected a
finite number)``).
"""

from __future__ import annotations

import functools
import json
import math
import os
from pathlib import Path
from typing import TYPE_CHECKING, Any

from .._io import not_a_file, read_json
from ..errors import InvalidParameter
from ..vocabulary import DESIGN_CHOICES
from .checked import ResultsDamaged, ResultsMissing
from .design import DesignRecord
from .run import RUN_KINDS, ActuatorRunRecord, ArmRunRecord, RunRecord

if TYPE_CHECKING:
    from pydantic import TypeAdapter


def read_run_record(path: str | os.PathLike[str]) -> RunRecord:
    """The run record saved at ``path`` (a ``designs.json``), checked against its type.

    Raises
    ------
    ResultsMissing
        There is no file at ``path``.
    ResultsDamaged
        The file cannot be read, or a field is missing, unknown, of the wrong kind or a number that is not
        finite: one line naming the file and the first such field.
    """
    return checked_run_record(read_saved_record(path), path)


def read_saved_record(path: str | os.PathLike[str]) -> dict[str, Any]:
    """The JSON saved at ``path``, a record of a kind a run writes, its fields not yet checked.

    Raises :class:`ResultsMissing` and :class:`ResultsDamaged` as :func:`read_run_record`, for the file and
    its ``kind``.
    """
    path = Path(path)
    why = not_a_file(path)
    if why == "no such file":
        raise ResultsMissing(
            f"{path.parent} has no {path.name}: run the study first (crx run STUDY --out {path.parent})"
        )
    if why is not None:  # a folder, a pipe or a device (or a link to one) is there: not a missing record
        raise ResultsDamaged(f"{path} cannot be read ({why}); run the study again")
    try:
        data = read_json(path)
    except (OSError, ValueError, RecursionError) as error:  # RecursionError: nesting too deep to parse
        reason = (
            "nested too deeply" if isinstance(error, RecursionError) else getattr(error, "strerror", None)
        )
        reason = reason or str(error)
        raise ResultsDamaged(
            f"{path} cannot be read ({' '.join(reason.split())}); run the study again"
        ) from None
    kind = data.get("kind") if isinstance(data, dict) else None
    if kind not in RUN_KINDS:
        raise ResultsDamaged(
            f"{path}: field 'kind' is {kind!r}, expected one of {', '.join(RUN_KINDS)}; run the study again"
        )
    return data


def checked_run_record(data: dict[str, Any], path: str | os.PathLike[str]) -> RunRecord:
    """``data`` (read from ``path`` by :func:`read_saved_record`) checked against its type.

    Raises :class:`ResultsDamaged` naming ``path`` and the first field that is not what a run writes.
    """
    problem = record_problem(data)
    if problem is not None:
        raise ResultsDamaged(f"{path}: {problem}; run the study again")
    return data  # type: ignore[return-value]  # checked: a RunRecord


def record_problem(data: dict[str, Any]) -> str | None:
    """What is wrong with a run record (its first bad field, in words), or None when it is one."""
    from pydantic import ValidationError  # lazy: pydantic, only to read a saved run

    try:
        _adapter(str(data.get("kind"))).validate_python(data)
    except ValidationError as error:
        return _problem(error.errors()[0])
    return _non_finite(data)


def _non_finite(data: Any) -> str | None:
    """The first NaN or infinity anywhere in ``data`` (the fields the types leave open too), in words, or None.

    A run writes none (``allow_nan=False``); walked without recursion, however deep the record.
    """
    stack: list[tuple[list[Any], Any]] = [([], data)]
    while stack:
        loc, value = stack.pop()
        if isinstance(value, float) and not math.isfinite(value):
            return (
                f"field {_dotted(loc)!r} holds a value of the wrong kind ({value}, expected a finite number)"
            )
        if isinstance(value, dict):
            stack.extend(([*loc, key], item) for key, item in reversed(value.items()))
        elif isinstance(value, list):
            stack.extend(([*loc, i], item) for i, item in reversed(list(enumerate(value))))
    return None


@functools.cache
def _adapter(kind: str) -> TypeAdapter[Any]:
    """The validator of a ``kind`` of run record, built once."""
    from pydantic import TypeAdapter  # lazy: pydantic, only to read a saved run

    return TypeAdapter(ArmRunRecord if kind == "arm" else ActuatorRunRecord)


_EXPECTED = {
    "float_type": "a number",
    "finite_number": "a finite number",
    "int_type": "a whole number",
    "string_type": "text",
    "bool_type": "true or false",
    "list_type": "a list",
    "dict_type": "a mapping",
    "typed_dict_type": "a mapping",
    "none_required": "null",
}
"""What a field of each pydantic error type should hold, in words."""

_BOUNDS = {
    "greater_than": "a number above {:g}",
    "greater_than_equal": "a number of at least {:g}",
    "less_than_equal": "a number of at most {:g}",
}
"""A physical range a field holds (:mod:`.checked`), in words, with its bound."""


def _problem(error: Any) -> str:
    """One pydantic error as a sentence naming the field: ``field 'gear_ratio' is missing: recommended.joints[0] has fields ...``."""
    loc = [part for part in error["loc"] if not _union_member(part)]
    parent, key = _dotted(loc[:-1]), loc[-1] if loc else ""
    where = parent or "the record"
    if error["type"] == "missing":
        found = ", ".join(error["input"]) if isinstance(error["input"], dict) else "none"
        return f"field {key!r} is missing: {where} has fields {found}"
    if error["type"] == "extra_forbidden":
        return f"field {key!r} of {where} is not one a run writes"
    value = json.dumps(error["input"]) if _plain(error["input"]) else type(error["input"]).__name__
    expected = _EXPECTED.get(error["type"], error["msg"][0].lower() + error["msg"][1:])
    bound = _BOUNDS.get(error["type"])
    if bound is not None:  # a physical range: say it as a range
        expected = bound.format(*(error.get("ctx") or {}).values())
    if error["type"] == "float_type":
        expected = "a finite number"  # text such as "NaN" is not a number either
    return f"field {_dotted(loc)!r} holds a value of the wrong kind ({value[:40]}, expected {expected})"


def _union_member(part: object) -> bool:
    """Whether a location part names the member of a union pydantic tried (``list[float]``), not a key."""
    return isinstance(part, str) and ("[" in part or part in ("float", "str", "int", "bool"))


def _plain(value: object) -> bool:
    """Whether ``value`` is a JSON scalar (a message shows it as it is)."""
    return value is None or isinstance(value, (bool, int, float, str))


def _dotted(loc: list[Any]) -> str:
    """A location as a field path: ``recommended.torque_speed[0].rms_torque``."""
    text = ""
    for part in loc:
        text += f"[{part}]" if isinstance(part, int) else f".{part}" if text else str(part)
    return text


def pick_design(results: ArmRunRecord, design: str | int) -> tuple[str, DesignRecord]:
    """The label and record of ``design`` in a run's results.

    ``design``: ``"catalogue"`` (the recommended design built from catalogue parts), ``"recommended"``,
    ``"chosen"`` (the single-objective optimum) or the index of a Pareto design (as ``pareto.csv``'s ``point``
    column numbers them, also as text). Raises :class:`InvalidParameter` for any other, and for
    ``"catalogue"`` in a run without a catalogue design.
    """
    points = results["pareto"]["points"]
    if isinstance(design, str) and design.isdigit():
        design = int(design)
    if isinstance(design, int) and not isinstance(design, bool):
        if not 0 <= design < len(points):
            raise InvalidParameter(
                "design",
                design,
                f"a Pareto design 0 to {len(points) - 1}"
                if points
                else "'recommended' (the run has no Pareto front)",
                f"or one of {', '.join(DESIGN_CHOICES)}",
            )
        return f"Pareto design {design} ({points[design].get('label', '')})", points[design]
    if design not in DESIGN_CHOICES:
        raise InvalidParameter(
            "design", design, f"a Pareto design number or one of {', '.join(DESIGN_CHOICES)}"
        )
    if design == "catalogue":
        snapped = results.get("catalogue")
        built = snapped.get("design") if snapped else None
        if not snapped or built is None:
            raise InvalidParameter(
                "design",
                design,
                "a design of the run",
                "the run has no catalogue design (catalogue.snap off, or no part within the bounds): "
                "name 'recommended' or a Pareto design",
            )
        return f"catalogue design (from {snapped['snapped']})", built
    record = results["recommended"] if design == "recommended" else results["chosen"]
    source = record.get("source") or record.get("label", "")
    return f"{design} design ({source})" if source else f"{design} design", record
