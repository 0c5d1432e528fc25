"""What the seeded API fuzz tests share: the random extremes they add to their hostile values, and the real
numbers of a result they check (``tests/test_api_fuzz.py``, ``tests/test_arm_api_fuzz.py``)."""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Iterator
from typing import Any

import numpy as np


def hostile_values(fixed: tuple[Any, ...], rng: np.random.Generator, extremes: int) -> list[Any]:
    """``fixed`` and ``extremes`` random numbers of either sign and magnitude 1e-300 to 1e300."""
    signs, exponents = rng.choice([-1.0, 1.0], extremes), rng.uniform(-300, 300, extremes)
    return [*fixed, *(float(s * 10.0**e) for s, e in zip(signs, exponents, strict=True))]


def result_floats(value: Any, nan_fields: tuple[str, ...] = ()) -> Iterator[float]:
    """Every number of a result as a float: NaN for a complex or object one (not a real number: a finding).

    Flags, strings and None are skipped; so is a dataclass field of ``nan_fields`` that holds NaN (documented
    there as "not given").
    """
    if isinstance(value, (bool, str, bytes, type(None))):
        return
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        for field in dataclasses.fields(value):
            item = getattr(value, field.name)
            if field.name not in nan_fields or not (isinstance(item, float) and math.isnan(item)):
                yield from result_floats(item)
        return
    if isinstance(value, (tuple, list)):
        for item in value:
            yield from result_floats(item, nan_fields)
        return
    if isinstance(value, (int, float, complex, np.number, np.ndarray)):
        array = np.asarray(value)
        if array.dtype.kind in "iuf":
            yield from array.astype(np.float64).ravel().tolist()
        elif array.dtype.kind != "b":  # flags are not numbers
            yield math.nan
