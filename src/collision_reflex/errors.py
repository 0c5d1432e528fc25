"""Exceptions of collision-reflex.

Every error the package raises on purpose derives from :class:`CollisionReflexError`; errors about the value
of an input also derive from :class:`ValueError`. Messages say what was received, what was expected and what
to do, so that a command-line user sees one clear line instead of a traceback.
"""

from __future__ import annotations

from typing import Any


class CollisionReflexError(Exception):
    """Base class of every error raised on purpose by collision-reflex."""


class InvalidParameter(CollisionReflexError, ValueError):
    """A parameter has a value outside its allowed range (or is NaN, or of the wrong kind).

    Attributes
    ----------
    name: the parameter's name as the caller spelled it.
    value: the value received (an array is summarised in the message).
    allowed: a short phrase saying what is allowed, e.g. ``"a finite number > 0"``.
    """

    def __init__(self, name: str, value: Any, allowed: str, hint: str = "") -> None:
        self.name = name
        self.value = value
        self.allowed = allowed
        message = f"{name} = {_describe(value)} is invalid: expected {allowed}"
        if hint:
            message += f"; {hint}"
        super().__init__(message)


def _describe(value: Any) -> str:
    """A short description of a received value, for error messages."""
    try:
        import numpy as np

        array = np.asarray(value)
        if array.ndim > 0 and array.size > 1 and array.dtype.kind in "fiu":
            bad = array[~np.isfinite(array) | (array <= 0)] if array.dtype.kind == "f" else array[array <= 0]
            shown = float(bad.flat[0] if bad.size else array.flat[0])
            return f"array of shape {array.shape} containing {shown!r}"
    except Exception:  # describing must never itself fail
        pass
    return repr(value)


class SimulationError(CollisionReflexError):
    """A time-domain simulation could not produce a result (nothing detected, the contact never ended, the
    integrator failed); the message says what happened and what to change."""
