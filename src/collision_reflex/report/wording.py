"""How the report words names, units and numbers: one place for the verdict, the tables and the front's cards."""

from __future__ import annotations

import math
import re
from collections.abc import Mapping, Sequence
from pathlib import PurePath
from typing import Any

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


def general(value: float, digits: int = 4) -> str:
    """``value`` to ``digits`` significant digits in Python's general format (``{:.4g}``), as sentences say it."""
    return f"{value:.{digits}g}"


def percent(value: float) -> str:
    """A percentage to 3 significant digits, without exponents (``< 0.001``, ``0.354``, ``12.3``, ``1,750``)."""
    if value < 1e-3:
        return "< 0.001" if value > 0 else "0"
    return f"{value:,.0f}" if value >= 100 else f"{value:.3g}"


def joint_runs(named: Sequence[tuple[str, str]]) -> list[tuple[list[str], str]]:
    """``(joint, text)`` pairs with consecutive joints of the same text gathered: ``([joints], text)``."""
    runs: list[tuple[list[str], str]] = []
    for name, text in named:
        if runs and runs[-1][1] == text and name and runs[-1][0]:
            runs[-1][0].append(name)
        else:
            runs.append(([name] if name else [], text))
    return runs


def grouped(joints: Sequence[Mapping[str, Any]], text: Any) -> str:
    """``text(joint)`` per run of consecutive joints that it describes alike, named by :func:`group_name`."""
    runs = joint_runs([(joint["joint"], text(joint)) for joint in joints])
    return "; ".join(f"{group_name(names)}: {said}" for names, said in runs)


def objective_unit(name: str) -> str:
    """The unit of an optimiser objective (from :data:`collision_reflex.optimize.OBJECTIVES`)."""
    from ..optimize import OBJECTIVES  # lazy: casadi

    return OBJECTIVES[name][1]
