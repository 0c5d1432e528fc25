"""The few functions the model needs that differ between NumPy and CasADi.

The impulse model is written once in plain arithmetic; where an elementary function or a branch is needed it
calls these helpers, which dispatch on the argument type: CasADi ``SX``/``MX``/``DM`` go to CasADi, everything
else (floats, NumPy arrays) to NumPy.
"""

from __future__ import annotations

import sys
from types import ModuleType
from typing import Any

import numpy as np


def _symbolic_types() -> tuple[type, ...]:
    """CasADi's matrix types; none while CasADi is not imported, since then no value can be one of them.

    Looking CasADi up instead of importing it keeps the numeric path (and ``import collision_reflex``) free of
    its import time.
    """
    casadi = sys.modules.get("casadi")
    return (casadi.SX, casadi.MX, casadi.DM) if casadi is not None else ()


def _casadi() -> ModuleType:
    """The CasADi module (already imported whenever a value is symbolic)."""
    import casadi

    return casadi


def is_symbolic(*values: Any) -> bool:
    """True if any value is a CasADi object (symbolic or DM)."""
    types = _symbolic_types()
    return bool(types) and any(isinstance(v, types) for v in values)


def sqrt(x: Any) -> Any:
    return _casadi().sqrt(x) if is_symbolic(x) else np.sqrt(x)


def sin(x: Any) -> Any:
    return _casadi().sin(x) if is_symbolic(x) else np.sin(x)


def where(condition: Any, if_true: Any, if_false: Any) -> Any:
    """Element-wise choice: ``numpy.where`` or ``casadi.if_else``."""
    if is_symbolic(condition, if_true, if_false):
        return _casadi().if_else(condition, if_true, if_false)
    return np.where(condition, if_true, if_false)


def absolute(x: Any) -> Any:
    return _casadi().fabs(x) if is_symbolic(x) else np.abs(x)


def largest(x: Any, axis: int = -1) -> Any:
    """Largest entry along ``axis`` (NumPy, batched) or of a CasADi vector."""
    return _casadi().mmax(x) if is_symbolic(x) else np.max(x, axis=axis)


def dot(a: Any, b: Any, keepdims: bool = False) -> Any:
    """Inner product over the last axis (NumPy, batched and broadcast) or of two CasADi vectors.

    ``keepdims`` keeps that axis (NumPy), of length 1.
    """
    if is_symbolic(a, b):
        return _casadi().dot(a, b)
    product = np.einsum("...i,...i->...", a, b)
    return product[..., None] if keepdims else product


def quadratic_form(matrix: Any, x: Any) -> Any:
    """``x^T A x``: ``casadi.bilin``, or for NumPy stacks ``A`` (..., n, n) and ``x`` (..., n)."""
    if is_symbolic(matrix, x):
        return _casadi().bilin(matrix, x, x)
    return np.einsum("...i,...ij,...j->...", x, matrix, x)


def matmul(a: Any, b: Any) -> Any:
    """Matrix product: ``casadi.mtimes`` or NumPy's ``@`` (stacked matrices broadcast)."""
    return _casadi().mtimes(a, b) if is_symbolic(a, b) else a @ b


def transpose(a: Any) -> Any:
    """Transpose of a matrix, or of each matrix of a NumPy stack (the last two axes)."""
    return _casadi().transpose(a) if is_symbolic(a) else np.swapaxes(a, -1, -2)


def solve_vector(matrix: Any, vector: Any) -> Any:
    """``matrix^-1 vector``: CasADi (a column), or NumPy with stacked vectors on the last axis (..., n)."""
    if is_symbolic(matrix, vector):
        return _casadi().solve(matrix, vector)
    return np.linalg.solve(matrix, vector[..., None])[..., 0]


def solve(matrix: Any, rhs: Any) -> Any:
    """``matrix^-1 rhs``: ``casadi.solve`` or ``numpy.linalg.solve`` (stacked systems broadcast)."""
    return _casadi().solve(matrix, rhs) if is_symbolic(matrix, rhs) else np.linalg.solve(matrix, rhs)


def diagonal_matrix(values: Any) -> Any:
    """Diagonal matrix of a vector: ``casadi.diag``, or for NumPy (..., n) -> (..., n, n)."""
    if is_symbolic(values):
        return _casadi().diag(values)
    values = np.asarray(values)
    return values[..., :, None] * np.eye(values.shape[-1])


def divide_columns(matrix: Any, values: Any) -> Any:
    """``matrix diag(values)^-1``: column ``i`` divided by ``values[i]``.

    NumPy: ``values`` broadcast on the last axis.
    """
    if is_symbolic(matrix, values):
        return _casadi().mtimes(matrix, _casadi().diag(1 / values))
    return matrix / values


def weighted_sum(weights: Any, matrices: Any) -> Any:
    """``sum_i weights[i] matrices[..., i, :, :]``: NumPy (stacks broadcast) or CasADi.

    With CasADi, ``matrices`` is a sequence of matrices.
    """
    if is_symbolic(weights) or (len(matrices) and is_symbolic(matrices[0])):
        total = 0
        for i, matrix in enumerate(matrices):
            total = total + weights[i] * matrix
        return total
    return np.einsum("i,...ijk->...jk", weights, matrices)
