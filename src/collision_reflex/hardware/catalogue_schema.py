"""The schema of a catalogue entry (motor, gearbox, body region): its fields, their units and their checks.

Every number is read in SI: a plain number is taken as SI, a quantity string (``"60 mm"``) is converted by
pint; then it must be a finite number > 0. Every entry cites its ``source`` (see
:mod:`collision_reflex.hardware.catalogue`, which reads the files and locates each problem at its line).
"""

from __future__ import annotations

from typing import Any, Literal

from pydantic import BaseModel, ConfigDict, field_validator

from .._units import QuantityError, parse_quantity
from ..vocabulary import GEARBOX_KINDS, PER_RATIO_FIELDS

# Field -> the unit a plain number is taken in (SI), and the pint dimensionality a quantity string must have.
_MOTOR_UNITS = {
    "stator_diameter": "m",
    "stack_length": "m",
    "rotor_inertia": "kg * m**2",
    "peak_torque": "N * m",
    "continuous_torque": "N * m",
    "mass": "kg",
}
# Optional fields (None when omitted), same rules.
_MOTOR_OPTIONAL_UNITS = {"max_speed": "rad/s", "torque_constant": "N * m / A"}
_GEARBOX_UNITS = {"rated_torque": "N * m", "peak_torque": "N * m", "mass": "kg", "inertia": "kg * m**2"}
_GEARBOX_OPTIONAL_UNITS = {
    "momentary_torque": "N * m",
    "max_input_speed": "rad/s",
    "diameter": "m",
    "length": "m",
}
# A human body region (ISO/TS 15066 Annex A): a spring with an effective mass, and its force limits.
_BODY_REGION_UNITS = {"stiffness": "N/m", "mass": "kg", "quasi_static_force": "N"}
_BODY_REGION_OPTIONAL_UNITS = {"transient_force": "N"}  # none where no transient contact is permitted
PROVENANCE_FIELDS = ("source", "sources", "estimates")
# Optional text fields that describe a part; returned apart from the numbers (CatalogueEntry.description).
DESCRIPTIVE_FIELDS = ("maker", "construction")


def _to_si(value: Any, unit: str) -> Any:
    """A plain number (taken as SI) or a quantity string converted to ``unit``; ValueError saying why not."""
    if isinstance(value, bool):
        raise ValueError("expected a number or a quantity with units, got a boolean")
    if isinstance(value, str):  # YAML 1.1 reads "1e-5" (no dot) as text: a plain number is still SI
        return _quantity(value, unit)
    if isinstance(value, int | float):
        return float(value)
    raise ValueError(f"expected a number (SI, {unit}) or a quantity string such as '60 mm'")


def _positive(value: float | None) -> float | None:
    if value is not None and not (value > 0 and value < float("inf")):
        raise ValueError(f"expected a finite number > 0, got {value!r}")
    return value


def _quantity_validators(
    units: dict[str, str], optional: dict[str, str], per_ratio: tuple[str, ...] = ()
) -> tuple[Any, Any]:
    """An entry's validators of its quantities: each read in SI (see ``_to_si``), then a finite number > 0.

    ``units`` and ``optional`` map each field to its unit; an ``optional`` field may be None; a ``per_ratio``
    field may also be a mapping gear ratio -> quantity (one figure per ratio), each figure read alike.
    """
    every = {**units, **optional}

    def si(cls: type, value: Any, info: Any) -> Any:
        name = info.field_name
        if value is None and name in optional:
            return None
        if isinstance(value, dict) and name in per_ratio:
            return {_ratio_key(ratio): _to_si(figure, every[name]) for ratio, figure in value.items()}
        return _to_si(value, every[name])

    def physical(cls: type, value: float | dict[float, float] | None) -> float | dict[float, float] | None:
        if isinstance(value, dict):
            for figure in value.values():
                _positive(figure)
            return value
        return _positive(value)

    return field_validator(*every, mode="before")(classmethod(si)), field_validator(*every)(
        classmethod(physical)
    )


def _ratio_key(key: Any) -> float:
    """A per-ratio mapping's key as a gear ratio [-], or ValueError saying why not."""
    if isinstance(key, bool) or not isinstance(key, int | float) or not 1 <= float(key) < float("inf"):
        raise ValueError(f"a figure per ratio is keyed by its gear ratio (a number >= 1), got {excerpt(key)}")
    return float(key)


class CitedEntry(BaseModel):
    """The provenance every entry carries: a default source, and per-field sources and estimates."""

    model_config = ConfigDict(extra="forbid", strict=False)

    source: str
    sources: dict[str, str] = {}
    estimates: dict[str, str] = {}
    maker: str | None = None

    @field_validator("source")
    @classmethod
    def _cited(cls, value: str) -> str:
        if not value.strip():
            raise ValueError("every entry must cite its source (datasheet, paper, or a stated assumption)")
        return value

    @field_validator("maker")
    @classmethod
    def _named(cls, value: str | None) -> str | None:
        if value is not None and not value.strip():
            raise ValueError("empty: name the maker, or leave the field out")
        return value


class _MotorEntry(CitedEntry):
    """One motor entry; every number in SI after validation."""

    stator_diameter: float
    stack_length: float
    rotor_inertia: float
    peak_torque: float
    continuous_torque: float
    mass: float
    max_speed: float | None = None
    torque_constant: float | None = None
    construction: Literal["frameless", "housed"] | None = None

    _si, _physical = _quantity_validators(_MOTOR_UNITS, _MOTOR_OPTIONAL_UNITS)


class _GearboxEntry(CitedEntry):
    """One gearbox entry; every number in SI after validation; a field of ``PER_RATIO_FIELDS`` may be given per ratio."""

    kind: str
    ratios: list[float] | None = None
    ratio_range: list[float] | None = None
    rated_torque: float | dict[float, float]
    peak_torque: float | dict[float, float]
    mass: float
    inertia: float | dict[float, float]
    efficiency: float | None = None
    stages: int = 1
    momentary_torque: float | dict[float, float] | None = None
    max_input_speed: float | None = None
    diameter: float | None = None
    length: float | None = None

    _si, _physical = _quantity_validators(_GEARBOX_UNITS, _GEARBOX_OPTIONAL_UNITS, PER_RATIO_FIELDS)

    @field_validator("kind")
    @classmethod
    def _known_kind(cls, value: str) -> str:
        if value not in GEARBOX_KINDS:
            raise ValueError("expected one of " + ", ".join(GEARBOX_KINDS))
        return value

    @field_validator("ratios", "ratio_range")
    @classmethod
    def _ratios(cls, value: list[float] | None) -> list[float] | None:
        if value is not None and (not value or any(not (1 <= r < float("inf")) for r in value)):
            raise ValueError(f"expected gear ratios >= 1, got {value!r}")
        return value

    @field_validator("efficiency")
    @classmethod
    def _efficiency(cls, value: float | None) -> float | None:
        if value is not None and not 0 < value <= 1:
            raise ValueError(f"expected an efficiency in (0, 1], got {value!r}")
        return value

    @field_validator("stages")
    @classmethod
    def _stages(cls, value: int) -> int:
        if value < 1:
            raise ValueError(f"expected an integer >= 1, got {value!r}")
        return value


class _BodyRegionEntry(CitedEntry):
    """One body region; every number in SI after validation."""

    stiffness: float
    mass: float
    quasi_static_force: float
    transient_force: float | None = None

    _si, _physical = _quantity_validators(_BODY_REGION_UNITS, _BODY_REGION_OPTIONAL_UNITS)


# kind -> (schema, required fields, optional fields), the last two for error messages.
ENTRY_SCHEMAS: dict[str, tuple[type[CitedEntry], list[str], list[str]]] = {
    "motors": (
        _MotorEntry,
        [*_MOTOR_UNITS, "source"],
        [*_MOTOR_OPTIONAL_UNITS, "sources", "estimates", *DESCRIPTIVE_FIELDS],
    ),
    "gearboxes": (
        _GearboxEntry,
        ["kind", "ratios or ratio_range", *_GEARBOX_UNITS, "source"],
        ["efficiency", "stages", *_GEARBOX_OPTIONAL_UNITS, "sources", "estimates", "maker"],
    ),
    "body_regions": (
        _BodyRegionEntry,
        [*_BODY_REGION_UNITS, "source"],
        [*_BODY_REGION_OPTIONAL_UNITS, "sources", "estimates"],
    ),
}


def _quantity(text: str, unit: str) -> float:
    """``text`` (e.g. ``"60 mm"``) in ``unit``, or ValueError saying why not (the bounded grammar of units)."""
    try:
        # An angular speed needs its angle unit: "50 Hz" may mean 50 rev/s.
        return parse_quantity(text, unit, angle_explicit=True)
    except QuantityError as error:
        shown = excerpt(text)
        if error.kind == "dimension":
            raise ValueError(f"{shown} cannot be converted to {unit} ({error.reason})") from None
        if error.kind == "angle":
            raise ValueError(f"{shown} has {error.reason}") from None
        raise ValueError(f"{shown} is not a quantity ({error.reason})") from None


def excerpt(value: Any, limit: int = 40) -> str:
    """``repr(value)``, cut to ``limit`` characters: a message quotes a bad value, never all of it."""
    shown = repr(value)
    return shown if len(shown) <= limit else shown[: limit - 3] + "..."
