"""Input checks shared by the model functions.

Numeric inputs (numbers, sequences of numbers, NumPy arrays) are checked and converted to float64 at the
edge, so that an integer array cannot overflow in a power and a complex number cannot slip through; CasADi
symbols cannot be checked and pass through, since the optimiser imposes bounds on them instead.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterator
from contextlib import contextmanager
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


def unit_interval(name: str, value: Any) -> Any:
    """``value`` as float64 (a float, or an array) if every element is in [0, 1], else raise."""
    return _check(name, value, lambda a: (a >= 0) & (a <= 1), "a number in [0, 1]", False)


def finite(name: str, value: Any) -> Any:
    """``value`` as float64 (a float, or an array) if every element is a finite number, of any sign, else raise."""
    return _check(name, value, lambda a: a == a, "a finite number", False)


def arrays(name: str, value: Any, *, ndim: int = 1, square: bool = False) -> Any:
    """``value`` if it holds finite real numbers in at least ``ndim`` axes (the last two equal if ``square``).

    A NumPy float array is returned as it is, without a copy (the effective-parameter formulas check whole
    batches of matrices); CasADi values, and sequences of them, pass unchecked. Raises
    :class:`InvalidParameter` naming ``name`` otherwise.
    """
    if is_symbolic(value) or (isinstance(value, (list, tuple)) and is_symbolic(*value)):
        return value
    kind = (
        ("square matrices (..., n, n)" if square else "matrices (..., m, n)")
        if ndim == 2
        else "a vector (..., n)"
    )
    allowed = f"finite real numbers, {kind}"
    array = value if isinstance(value, np.ndarray) and value.dtype.kind == "f" else real(name, value, allowed)
    if array.ndim < ndim or (square and array.shape[-1] != array.shape[-2]) or not np.isfinite(array).all():
        raise InvalidParameter(name, value, allowed)
    return array


@contextmanager
def combining(**values: Any) -> Iterator[None]:
    """Report NumPy's errors in combining ``values`` inside the block as :class:`InvalidParameter`.

    Shapes that do not fit, a singular matrix, a result beyond the float64 range. ``values`` are the checked
    arguments the block combines, named as the caller spelled them; CasADi's own errors pass unchanged.
    """
    try:
        with np.errstate(over="raise"):
            yield
    except InvalidParameter:
        raise
    except (ValueError, np.linalg.LinAlgError, OverflowError, FloatingPointError) as error:
        if is_symbolic(*values.values()):
            raise
        shapes = ", ".join(f"{name} {np.shape(value)}" for name, value in values.items())
        if isinstance(error, (OverflowError, FloatingPointError)):
            allowed = "values whose result is below the float64 range (about 1.8e308)"
        elif isinstance(error, np.linalg.LinAlgError) and "ingular" in str(error):
            allowed = "non-singular matrices"
        else:
            allowed = "shapes that fit together"
        raise InvalidParameter(", ".join(values), shapes, allowed, f"NumPy says: {error}") from None


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
    good = ok(array)  # False at NaN: every comparison with NaN is
    if not allow_inf:
        good &= np.isfinite(array)
    if not good.all():
        raise InvalidParameter(name, value, allowed)
    return array if array.ndim else float(array)


def integer(name: str, value: Any, low: int, high: int | None = None) -> int:
    """``value`` as an int if it is a whole number (not a bool) in ``[low, high]``, else raise.

    Python and NumPy integers are accepted, and floats holding a whole number (``3.0``); NaN, infinities,
    fractions, strings and arrays are refused.
    """
    allowed = f"a whole number >= {low}" + ("" if high is None else f" and <= {high}")
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise InvalidParameter(name, value, allowed)
    if isinstance(value, (float, np.floating)) and not (math.isfinite(value) and float(value).is_integer()):
        raise InvalidParameter(name, value, allowed)
    number = int(value)
    if number < low or (high is not None and number > high):
        raise InvalidParameter(name, value, allowed)
    return number


def choice(name: str, value: str, allowed: tuple[str, ...]) -> str:
    """Return ``value`` if it is one of ``allowed``, else raise listing the options."""
    if not isinstance(value, str) or value not in allowed:
        raise InvalidParameter(name, value, "one of " + ", ".join(repr(a) for a in allowed))
    return value
