"""The few functions the model needs that differ between NumPy and CasADi.

The impulse model is written once in plain arithmetic; where an elementary function or a branch is needed it
calls these helpers, which dispatch on the argument type: CasADi ``SX``/``MX``/``DM`` go to CasADi, everything
else (floats, NumPy arrays) to NumPy.
"""

from __future__ import annotations

from typing import Any

import numpy as np

try:  # CasADi is a runtime dependency, but keep the numeric path importable without it.
    import casadi as _ca

    _CASADI_TYPES: tuple[type, ...] = (_ca.SX, _ca.MX, _ca.DM)
except ImportError:  # pragma: no cover - casadi is declared in pyproject
    _ca = None  # type: ignore[assignment]
    _CASADI_TYPES = ()


def is_symbolic(*values: Any) -> bool:
    """True if any value is a CasADi object (symbolic or DM)."""
    return any(isinstance(v, _CASADI_TYPES) for v in values)


def sqrt(x: Any) -> Any:
    return _ca.sqrt(x) if is_symbolic(x) else np.sqrt(x)


def sin(x: Any) -> Any:
    return _ca.sin(x) if is_symbolic(x) else np.sin(x)


def where(condition: Any, if_true: Any, if_false: Any) -> Any:
    """Element-wise choice: ``numpy.where`` or ``casadi.if_else``."""
    if is_symbolic(condition, if_true, if_false):
        return _ca.if_else(condition, if_true, if_false)
    return np.where(condition, if_true, if_false)
