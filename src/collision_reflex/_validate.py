"""Input checks shared by the model functions.

Numeric inputs (floats, NumPy arrays) are checked; CasADi symbols cannot be checked and pass through, since
the optimiser imposes bounds on them instead.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ._backend import is_symbolic
from .errors import InvalidParameter


def positive(name: str, value: Any, *, allow_inf: bool = False) -> Any:
    """Return ``value`` if every element is a number > 0 (finite unless ``allow_inf``), else raise."""
    return _check(
        name, value, lambda a: a > 0, "a finite number > 0" if not allow_inf else "a number > 0", allow_inf
    )


def non_negative(name: str, value: Any) -> Any:
    """Return ``value`` if every element is a finite number >= 0, else raise."""
    return _check(name, value, lambda a: a >= 0, "a finite number >= 0", False)


def _check(name: str, value: Any, ok: Any, allowed: str, allow_inf: bool) -> Any:
    if is_symbolic(value):
        return value
    try:
        array = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise InvalidParameter(name, value, allowed) from None
    finite = np.isfinite(array) | (allow_inf & np.isposinf(array))
    if not np.all(finite & ok(np.where(np.isnan(array), 0.0, array))):
        raise InvalidParameter(name, value, allowed)
    return value


def choice(name: str, value: str, allowed: tuple[str, ...]) -> str:
    """Return ``value`` if it is one of ``allowed``, else raise listing the options."""
    if value not in allowed:
        raise InvalidParameter(name, value, "one of " + ", ".join(repr(a) for a in allowed))
    return value
