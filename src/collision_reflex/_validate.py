"""Input checks shared by the model functions.

Numeric inputs (numbers, sequences of numbers, NumPy arrays) are checked and converted to float64 at the
edge, so that an integer array cannot overflow in a power and a complex number cannot slip through; CasADi
symbols cannot be checked and pass through, since the optimiser imposes bounds on them instead.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from ._backend import is_symbolic
from .errors import InvalidParameter


def positive(name: str, value: Any, *, allow_inf: bool = False) -> Any:
    """``value`` as float64 (a float, or an array) if every element is > 0 (finite unless ``allow_inf``).

    Raises :class:`InvalidParameter` naming ``name`` otherwise, or if ``value`` is not real numbers.
    """
    allowed = "a finite number > 0" if not allow_inf else "a number > 0"
    return _check(name, value, lambda a: a > 0, allowed, allow_inf)


def non_negative(name: str, value: Any) -> Any:
    """``value`` as float64 (a float, or an array) if every element is a finite number >= 0, else raise."""
    return _check(name, value, lambda a: a >= 0, "a finite number >= 0", False)


def finite(name: str, value: Any) -> Any:
    """``value`` as float64 (a float, or an array) if every element is a finite number, of any sign, else raise."""
    return _check(name, value, lambda a: a == a, "a finite number", False)


def real(name: str, value: Any, allowed: str) -> np.ndarray:
    """``value`` as a float64 array; :class:`InvalidParameter` (saying ``allowed``) if it is not real numbers.

    Strings, booleans, complex numbers, ragged or nested-object sequences and other objects are refused.
    """
    if isinstance(value, (str, bytes, bool, np.bool_)):
        raise InvalidParameter(name, value, allowed)
    try:
        array = np.asarray(value)
    except (TypeError, ValueError, OverflowError):
        raise InvalidParameter(name, value, allowed) from None
    if array.dtype.kind not in "iuf":  # complex, bool, strings, objects (ragged or not numbers)
        raise InvalidParameter(name, value, allowed + (" (not complex)" if array.dtype.kind == "c" else ""))
    return array.astype(np.float64)


def _check(name: str, value: Any, ok: Callable[[np.ndarray], Any], allowed: str, allow_inf: bool) -> Any:
    if is_symbolic(value):
        return value
    array = real(name, value, allowed)
    finite = np.isfinite(array) | (allow_inf & np.isposinf(array))
    if not np.all(finite & ok(np.where(np.isnan(array), 0.0, array))):
        raise InvalidParameter(name, value, allowed)
    return array if array.ndim else float(array)


def choice(name: str, value: str, allowed: tuple[str, ...]) -> str:
    """Return ``value`` if it is one of ``allowed``, else raise listing the options."""
    if not isinstance(value, str) or value not in allowed:
        raise InvalidParameter(name, value, "one of " + ", ".join(repr(a) for a in allowed))
    return value
