"""How the report words names, units and numbers: one place for the verdict, the tables and the front's cards."""

from __future__ import annotations

import math
import re
from collections.abc import Sequence
from pathlib import PurePath

import numpy as np


def words(name: str) -> str:
    """A field or objective name as words: ``worst_case_impulse`` as ``worst case impulse``."""
    return name.replace("_", " ")


def unit(text: str) -> str:
    """A unit as a designer reads it: ``N*m`` as ``N·m``, ``kg*m^2`` as ``kg·m²``."""
    return text.replace("**2", "²").replace("^2", "²").replace("*", "·")


def significant(value: float, digits: int) -> str:
    """``value`` to ``digits`` significant digits, trailing zeros dropped, without an exponent where readable."""
    value = float(value)
    if not math.isfinite(value):
        return str(value)
    rounded = float(f"{value:.{digits}g}")
    if rounded == 0 or 1e-4 <= abs(rounded) < 1e7:
        return np.format_float_positional(rounded, trim="-")
    return f"{rounded:.{digits}g}"


def group_name(names: Sequence[str]) -> str:
    """Joints that share a part, named by the first and last when more than two (a module: ``a … c``)."""
    if len(names) == 1:
        return names[0]
    return " and ".join(names) if len(names) == 2 else f"{names[0]} … {names[-1]}"


def number(value: object, digits: int = 4) -> str:
    """A number with ``digits`` significant digits (the precision every table of the report uses)."""
    if value is None:
        return "–"
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return str(value)
    if math.isinf(value):
        return "∞" if value > 0 else "−∞"
    return f"{value:.{digits}g}"


def mm(value: object) -> str:
    """A length in metres shown in millimetres (motor sizes), 3 significant digits."""
    return number(value * 1e3, 3) if isinstance(value, (int, float)) and not isinstance(value, bool) else "–"


def shown_path(value: str) -> str:
    """An absolute local path as its file name: a report names no folder of the machine it was made on."""
    path = PurePath(value)
    return path.name if path.is_absolute() or re.match(r"^[A-Za-z]:[\\/]", value) else value
