"""Reading motor catalogue files: YAML with line numbers, validated by pydantic, units converted by pint.

Kept apart from :mod:`collision_reflex.hardware.motors` so that the scaling arithmetic imports nothing heavy.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import yaml
from pydantic import BaseModel, ConfigDict, ValidationError, field_validator

from .._units import unit_registry
from ..errors import CatalogueError

# Field -> the unit a plain number is taken in (SI), and the pint dimensionality a quantity string must have.
_UNITS = {
    "stator_diameter": "m",
    "stack_length": "m",
    "rotor_inertia": "kg * m**2",
    "peak_torque": "N * m",
    "continuous_torque": "N * m",
    "mass": "kg",
}
# Optional fields (None when omitted), same rules.
_OPTIONAL_UNITS = {"max_speed": "rad/s"}
_ALL_UNITS = {**_UNITS, **_OPTIONAL_UNITS}
_FIELDS = ", ".join([*_UNITS, "source"]) + ", and optionally " + ", ".join(_OPTIONAL_UNITS)


def packaged_catalogue_path() -> Path:
    """The catalogue shipped with the package: ``designs/motors.yaml``.

    Looked for inside the package (a wheel that includes the ``designs`` data) and then in the source tree
    (a checkout or an editable install).
    """
    package = Path(__file__).resolve().parents[1]
    for candidate in (package / "designs" / "motors.yaml", package.parents[1] / "designs" / "motors.yaml"):
        if candidate.is_file():
            return candidate
    raise CatalogueError(
        str(package.parents[1] / "designs" / "motors.yaml"),
        None,
        "",
        "the packaged motor catalogue is missing; reinstall collision-reflex or pass a catalogue file",
    )


class _Entry(BaseModel):
    """One motor entry; every number in SI after validation."""

    model_config = ConfigDict(extra="forbid", strict=False)

    stator_diameter: float
    stack_length: float
    rotor_inertia: float
    peak_torque: float
    continuous_torque: float
    mass: float
    source: str
    max_speed: float | None = None

    @field_validator(*_ALL_UNITS, mode="before")
    @classmethod
    def _to_si(cls, value: Any, info: Any) -> Any:
        unit = _ALL_UNITS[info.field_name]
        if value is None and info.field_name in _OPTIONAL_UNITS:
            return None
        if isinstance(value, bool):
            raise ValueError("expected a number or a quantity with units, got a boolean")
        if isinstance(value, str):
            try:  # YAML 1.1 reads "1e-5" (no dot) as text: a plain number is still SI
                return float(value)
            except ValueError:
                return _quantity(value, unit)
        if isinstance(value, int | float):
            return float(value)
        raise ValueError(f"expected a number (SI, {unit}) or a quantity string such as '60 mm'")

    @field_validator(*_ALL_UNITS)
    @classmethod
    def _positive(cls, value: float | None) -> float | None:
        if value is None:
            return None
        if not (value > 0 and value < float("inf")):
            raise ValueError(f"expected a finite number > 0, got {value!r}")
        return value

    @field_validator("source")
    @classmethod
    def _cited(cls, value: str) -> str:
        if not value.strip():
            raise ValueError("every entry must cite its source (datasheet, paper, or a stated assumption)")
        return value


def _quantity(text: str, unit: str) -> float:
    """``text`` (e.g. ``"60 mm"``) in ``unit``, or ValueError saying why not."""
    import pint

    registry = unit_registry()
    try:
        quantity: Any = registry.Quantity(text)
        converted = float(quantity.to(unit).magnitude)
    except pint.DimensionalityError:
        raise ValueError(f"{text!r} cannot be converted to {unit}") from None
    except Exception:
        raise ValueError(f"{text!r} is not a quantity (a number and a unit, e.g. '60 mm')") from None
    # pint takes angles as dimensionless: "50 Hz" would pass as 50 rad/s, though it may mean 50 rev/s.
    if _radian_power(registry.Quantity(1, unit)) != _radian_power(quantity):
        raise ValueError(
            f"{text!r} has no angle unit; give an angle per time, e.g. '3000 rpm' or '314 rad/s'"
        )
    return converted


def _radian_power(quantity: Any) -> int:
    """The power of the angle (radian) in ``quantity``'s unit: 1 for ``rpm`` and ``rad/s``, 0 for ``Hz``."""
    return int(dict(quantity.to_root_units().unit_items()).get("radian", 0))


def read_catalogue(path: Path) -> dict[str, dict[str, Any]]:
    """The entries of a catalogue file, each a dict of :class:`~collision_reflex.hardware.motors.Motor` fields (SI)."""
    name = str(path)
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as error:
        raise CatalogueError(name, None, "", f"cannot read the file ({error.strerror})") from None
    try:
        root = yaml.compose(text, Loader=yaml.SafeLoader)
    except yaml.YAMLError as error:
        mark = getattr(error, "problem_mark", None)
        line = mark.line + 1 if mark is not None else None
        problem = getattr(error, "problem", None) or str(error)
        raise CatalogueError(name, line, "", f"not valid YAML: {problem}") from None
    if not isinstance(root, yaml.MappingNode):
        raise CatalogueError(name, _line(root), "", "expected a mapping with a top-level 'motors' key")
    top = _mapping(root)
    if "motors" not in top:
        raise CatalogueError(name, 1, "motors", "missing: the file needs a top-level 'motors' mapping")
    unknown = sorted(set(top) - {"motors"})
    if unknown:
        key_node, _ = top[unknown[0]]
        raise CatalogueError(
            name, _line(key_node), unknown[0], "unknown top-level key; only 'motors' is allowed"
        )
    _, motors_node = top["motors"]
    if not isinstance(motors_node, yaml.MappingNode):
        raise CatalogueError(
            name, _line(motors_node), "motors", "expected a mapping from motor name to entry"
        )

    entries: dict[str, dict[str, Any]] = {}
    for motor_name, (key_node, entry_node) in _mapping(motors_node).items():
        where = f"motors.{motor_name}"
        if not isinstance(entry_node, yaml.MappingNode):
            raise CatalogueError(name, _line(key_node), where, "expected a mapping of the motor's fields")
        fields = _mapping(entry_node)
        raw = {key: _plain(value_node) for key, (_, value_node) in fields.items()}
        try:
            entry = _Entry.model_validate(raw)
        except ValidationError as error:
            first = error.errors()[0]
            field = str(first["loc"][0]) if first["loc"] else ""
            if first["type"] == "missing":
                line = _line(key_node)
                reason = f"missing (an entry needs {_FIELDS})"
            elif first["type"] == "extra_forbidden":
                line = _line(fields[field][0])
                reason = f"unknown field (allowed: {_FIELDS})"
            else:
                line = _line(fields[field][1]) if field in fields else _line(key_node)
                reason = f"{first['msg']} (got {raw.get(field)!r})"
            raise CatalogueError(name, line, f"{where}.{field}", reason) from None
        if entry.continuous_torque > entry.peak_torque:
            raise CatalogueError(
                name,
                _line(fields["continuous_torque"][1]),
                f"{where}.continuous_torque",
                f"{entry.continuous_torque:g} N m exceeds the peak torque {entry.peak_torque:g} N m",
            )
        entries[motor_name] = entry.model_dump()
    return entries


def _mapping(node: Any) -> dict[str, tuple[Any, Any]]:
    """Key -> (key node, value node) of a YAML mapping node (keys as text)."""
    return {str(key.value): (key, value) for key, value in node.value}


def _line(node: Any) -> int:
    return int(node.start_mark.line) + 1


def _plain(node: Any) -> Any:
    """A scalar node as Python (int/float/str/bool/None); other nodes as their constructed value."""
    return yaml.SafeLoader("").construct_document(node)
