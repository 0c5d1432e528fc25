"""Physical quantities in study files: plain SI numbers or strings with units, read with pint.

``60 mm``, ``"1.3 N*m"``, ``0.2 m/s`` and ``0.06`` (metres, as a plain number is SI) all give a float in the
field's SI unit. A string whose dimension differs from the field's (``"3 kg"`` for a stiffness) is refused with a
message naming both. The field types here are ``typing.Annotated`` floats for pydantic; their JSON Schema
accepts a number or a string.
"""

from __future__ import annotations

import functools
import math
from typing import TYPE_CHECKING, Annotated, Any

from pydantic import BeforeValidator, WithJsonSchema
from pydantic_core import PydanticCustomError

from .._units import unit_registry

if TYPE_CHECKING:
    import pint


def to_si(value: Any, unit: str, what: str, example: str) -> float:
    """``value`` (a number in ``unit``, or a string with units of the same dimension) as a float in ``unit``.

    Raises ``PydanticCustomError`` (turned into a located :class:`~collision_reflex.errors.StudyProblem`).
    """
    expected = f"{what} in {unit}: a number (SI) or a string with units such as {example!r}"
    if isinstance(value, bool) or not isinstance(value, (int, float, str)):
        raise PydanticCustomError("quantity", "{expected}", {"expected": expected})
    if isinstance(value, str):
        try:
            # YAML 1.1 reads "2e7" (no dot) as a string: a number written as text is still a plain SI number.
            magnitude = float(value)
        except ValueError:
            magnitude = _parse(value, unit, what, expected)
    else:
        try:
            magnitude = float(value)
        except OverflowError:
            magnitude = math.inf
    if not math.isfinite(magnitude):
        raise PydanticCustomError("quantity", "{expected}", {"expected": "a finite " + expected})
    return magnitude


def _parse(text: str, unit: str, what: str, expected: str) -> float:
    registry = unit_registry()
    try:
        quantity: pint.Quantity = registry.Quantity(text.strip())
        target = registry.Quantity(1.0, unit)
    except Exception:  # pint's parser raises many kinds of errors on arbitrary text; any is "not a quantity"
        raise PydanticCustomError("quantity", "{expected}", {"expected": expected}) from None
    if quantity.dimensionality != target.dimensionality:
        raise PydanticCustomError(
            "quantity_dimension",
            "{expected} ({found} is {found_dimension}, not {dimension})",
            {
                "expected": expected,
                "found": repr(text),  # pydantic fills {name} only, without format specs
                "found_dimension": _dimension(quantity),
                "dimension": _dimension(target),
            },
        )
    try:
        magnitude = quantity.to(unit).magnitude
        return float(magnitude)
    except Exception:  # offset units (degC), complex magnitudes, ...: not a plain quantity
        raise PydanticCustomError("quantity", "{expected}", {"expected": expected}) from None


def _dimension(quantity: Any) -> str:
    text = str(quantity.dimensionality)
    return "dimensionless" if text in ("", "dimensionless") else text


def quantity_type(unit: str, what: str, example: str) -> Any:
    """An ``Annotated[float, ...]`` field type holding a quantity converted to ``unit``."""
    return Annotated[
        float,
        BeforeValidator(functools.partial(_validate, unit=unit, what=what, example=example)),
        WithJsonSchema(
            {
                "anyOf": [{"type": "number"}, {"type": "string"}],
                "description": f"{what} [{unit}]: a number in {unit} or a string with units, e.g. {example!r}",
            }
        ),
    ]


def _validate(value: Any, unit: str, what: str, example: str) -> float:
    return to_si(value, unit, what, example)


# Field types of the study schema, by what they measure. Angles are dimensionless to pint (rad = 1), so a
# rotary stiffness may be written "N*m/rad" or "N*m".
Length = quantity_type("m", "a length", "60 mm")
Mass = quantity_type("kg", "a mass", "0.5 kg")
Force = quantity_type("N", "a force", "3 N")
Torque = quantity_type("N*m", "a torque", "1.3 N*m")
Velocity = quantity_type("m/s", "a velocity", "0.5 m/s")
Angle = quantity_type("rad", "an angle", "45 deg")
RotaryStiffness = quantity_type("N*m/rad", "a rotary stiffness", "1000 N*m/rad")
LinearStiffness = quantity_type("N/m", "a linear stiffness", "2e7 N/m")
Inertia = quantity_type("kg*m^2", "a moment of inertia", "2.21e-5 kg*m^2")
Ratio = quantity_type("", "a dimensionless number", "9")
