"""The package's one pint unit registry, and the one reader of quantity strings (``"60 mm"``, ``"1.3 N*m"``).

Building a registry takes a while, and quantities from two registries cannot be combined.

Quantity strings come from files a user may not have written (study files, catalogues), so they are read with
a bounded grammar: a number, then a unit expression of unit names joined by ``*``, ``/``, ``·`` or spaces, each
name with an optional small integer power (``^2``, ``**-1``). pint only sees text of that form. Its own parser
evaluates arbitrary expressions: ``10**10**10`` would be a big-integer computation that never ends, and its
time grows with the square of the text's length.
"""

from __future__ import annotations

import functools
import math
import re
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    import pint

MAX_QUANTITY_LENGTH = 100
"""Longest quantity string read [characters]; ``"2.21e-5 kg*m^2"`` is 14."""

_NUMBER = r"[+-]?(?:\d+(?:\.\d*)?|\.\d+)(?:[eE][+-]?\d{1,4})?"
_NAME = r"(?:[^\W\d_]\w*|°)"
_POWER = r"(?:\^|\*\*)\s*(?:[+-]?\d{1,2}|\(\s*[+-]?\d{1,2}\s*\))"
_FACTOR = rf"{_NAME}(?:\s*{_POWER})?"
_UNIT = rf"{_FACTOR}(?:\s*[*/·]\s*{_FACTOR}|\s+{_FACTOR})*"
_QUANTITY = re.compile(rf"\s*(?P<number>{_NUMBER})\s*(?P<unit>{_UNIT})?\s*")
_GRAMMAR = "a number and a unit, e.g. '60 mm', '1.3 N*m' or '2.21e-5 kg*m^2'"


class QuantityError(ValueError):
    """A quantity string that cannot be used; ``reason`` says why in a short phrase.

    Attributes
    ----------
    kind: ``"syntax"`` (not a number and a unit), ``"unit"`` (an unknown unit name), ``"dimension"`` (a unit of
        another kind than the one asked for), ``"angle"`` (an angular speed without an angle unit) or
        ``"value"`` (not finite once converted).
    reason: what is wrong, without quoting the text.
    found_dimension, dimension: the text's dimension and the one asked for (``kind == "dimension"``).
    """

    def __init__(self, kind: str, reason: str, found_dimension: str = "", dimension: str = "") -> None:
        super().__init__(reason)
        self.kind = kind
        self.reason = reason
        self.found_dimension = found_dimension
        self.dimension = dimension


@functools.cache
def unit_registry() -> pint.UnitRegistry:
    """The registry every unit string of the package is read with: study files, catalogues, traces."""
    import pint

    # Not pint's on-disk cache (0.1 s faster): the package writes nothing outside the folders it is given.
    return pint.UnitRegistry()


@functools.lru_cache(maxsize=4096)  # files repeat their units; a pint conversion costs ~0.2 ms
def parse_quantity(text: str, unit: str, *, angle_explicit: bool = False) -> float:
    """The quantity ``text`` (e.g. ``"60 mm"``, or a bare number taken in ``unit``) as a float in ``unit``.

    Parameters
    ----------
    text : str
        A number with an optional unit expression, at most :data:`MAX_QUANTITY_LENGTH` characters.
    unit : str
        The unit of the result (pint syntax, e.g. ``"N*m/rad"``); it also fixes the dimension asked for.
    angle_explicit : bool
        Refuse a text whose power of the angle differs from ``unit``'s: pint takes angles as dimensionless,
        so ``"50 Hz"`` would pass as 50 rad/s, though a datasheet may mean 50 rev/s.

    Raises
    ------
    QuantityError
        Saying why the text is not a quantity of ``unit``'s dimension.
    """
    if len(text) > MAX_QUANTITY_LENGTH:
        raise QuantityError(
            "syntax",
            f"a text of {len(text)} characters; expected {_GRAMMAR}, at most "
            f"{MAX_QUANTITY_LENGTH} characters",
        )
    match = _QUANTITY.fullmatch(text)
    if match is None:
        raise QuantityError("syntax", f"not {_GRAMMAR}")
    number = float(match["number"])
    if match["unit"] is None:
        magnitude = number
    else:
        magnitude = _converted(number, match["unit"], unit, angle_explicit)
    if not math.isfinite(magnitude):
        raise QuantityError("value", f"not a finite number once converted to {unit}")
    return magnitude


@functools.cache
def si_scale(unit: str) -> float:
    """The factor from ``unit`` (the package's own unit text, never a file's) to SI base units."""
    return float(unit_registry().Quantity(1.0, unit).to_base_units().magnitude)


def _converted(number: float, text: str, unit: str, angle_explicit: bool) -> float:
    """``number`` in the unit ``text`` (already of the bounded grammar), converted to ``unit``."""
    import pint

    registry = unit_registry()
    try:
        given = registry.Quantity(1.0, text.replace("^", "**"))
    except (pint.PintError, AttributeError, ValueError, TypeError, SyntaxError):
        raise QuantityError("unit", f"an unknown unit; expected {_GRAMMAR}") from None
    target = registry.Quantity(1.0, unit)
    if given.dimensionality != target.dimensionality:
        raise QuantityError(
            "dimension",
            f"a unit of {_dimension(given)}, not {_dimension(target)} ({unit})",
            _dimension(given),
            _dimension(target),
        )
    if angle_explicit and _radian_power(given) != _radian_power(target):
        raise QuantityError(
            "angle", f"no angle unit; give an angle per time, e.g. '3000 rpm' or '314 {unit}'"
        )
    try:
        with_number = registry.Quantity(number, text.replace("^", "**"))
        return float(with_number.to(unit).magnitude)
    except (pint.PintError, OverflowError, ValueError, TypeError):  # offset units (degC) in a product, ...
        raise QuantityError("unit", f"a unit that cannot be converted to {unit}") from None


def _dimension(quantity: pint.Quantity) -> str:
    text = str(quantity.dimensionality)
    return "dimensionless" if text in ("", "dimensionless") else text


def _radian_power(quantity: Any) -> int:
    """The power of the angle (radian) in ``quantity``'s unit: 1 for ``rpm`` and ``rad/s``, 0 for ``Hz``."""
    return int(dict(quantity.to_root_units().unit_items()).get("radian", 0))
