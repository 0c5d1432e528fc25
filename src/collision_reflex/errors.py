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


class TraceError(CollisionReflexError, ValueError):
    """A force-time trace cannot be used: unreadable, malformed, or without a usable contact.

    Attributes
    ----------
    source: the file the trace came from (``""`` for an in-memory trace).
    trial: the trial's name within that file (``""`` if the file holds one trial).
    reason: what is wrong, in a short phrase (e.g. ``"no contact: ..."``).
    line: the file line (1-based) where the problem is, or ``None`` when it is not one line.
    """

    def __init__(self, source: str, trial: str, reason: str, line: int | None = None) -> None:
        self.source = source
        self.trial = trial
        self.reason = reason
        self.line = line
        where = source or "trace"
        if line is not None:
            where += f", line {line}"
        if trial:
            where += f" (trial {trial!r})"
        super().__init__(f"{where}: {reason}")


class FitFailed(CollisionReflexError):
    """A least-squares fit did not converge or its result is not usable.

    Attributes
    ----------
    what: which fit (e.g. ``"one-shot fit"``).
    reason: the solver's message or the check that failed.
    """

    def __init__(self, what: str, reason: str) -> None:
        self.what = what
        self.reason = reason
        super().__init__(f"{what} failed: {reason}")
