"""The NLP's derivatives assembled per contact sample (gradient, constraint Jacobian, Hessian of the Lagrangian).

The NLP is ``f, g = outer(x, Y(x), p)``, where column ``s`` of ``Y`` (impulse, force threshold, ``w^T x``) is the
per-sample function of the sample's own variables ``v_s`` (the design's log values, ``log(1/F_a)`` and the
finger-mass direction: about 30 entries). Differentiating the whole expanded NLP symbolically is slow (the
Hessian's graph grows with every sample); here each sample's Jacobian and Hessian are
differentiated once in SX over ``v_s``, mapped over the samples, and combined with the outer part's derivatives
by the chain rule::

    grad f = f_x + J^T f_Y,    jac g = g_x + g_Y J,
    hess L = T^T hess(outer L) T + sum_s P_s^T (sum_k ybar_sk hess y_sk) P_s,   T = [I; J],

with ``J = dY/dx`` (block-sparse), ``ybar = sigma f_Y + g_Y^T lambda`` and ``P_s`` the selection of ``v_s``.
IPOPT gets the NLP's values the same way (:func:`structured_nlp`): expanding the whole NLP to SX and building a
solver on it is slower than the per-sample differentiation.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import casadi as ca
import numpy as np

__all__ = ["SampleStructure", "dense_dm", "derivative_functions", "structured_nlp"]


@dataclass(frozen=True)
class SampleStructure:
    """How the NLP splits into per-sample functions and an outer part (see the module docstring).

    ``outer`` maps ``(x, Y, p)`` to ``(f, g)`` with ``Y`` of shape (n_outputs, n_samples); ``sample`` maps a
    sample's variables ``v_s``, its data column and its direction scale to its column of ``Y``; ``variables``
    (n_local, n_samples) holds the index in ``x`` of each entry of ``v_s``.
    """

    outer: ca.Function
    sample: ca.Function
    variables: np.ndarray
    data: np.ndarray
    direction_scale: np.ndarray

    @functools.cached_property
    def constants(self) -> tuple[ca.DM, ca.DM]:
        """``data`` and ``direction_scale`` as CasADi matrices, converted once for all the NLP's functions."""
        return dense_dm(self.data), dense_dm(self.direction_scale)


def _scatter(rows: np.ndarray, cols: np.ndarray, shape: tuple[int, int]) -> tuple[ca.Sparsity, ca.DM]:
    """Sparsity of the entries ``(rows, cols)`` and the 0/1 matrix summing values given in that order into it."""
    keys = cols.astype(np.int64) * shape[0] + rows
    unique, position = np.unique(keys, return_inverse=True)
    # Built column-compressed: the sorted keys are already in CasADi's (column-major) order and the summing
    # matrix has one entry per column, so nothing is sorted again (faster than building them from triplets).
    pattern = ca.Sparsity(
        shape[0],
        shape[1],
        np.searchsorted(unique // shape[0], np.arange(shape[1] + 1)).tolist(),
        (unique % shape[0]).tolist(),
    )
    summing = ca.DM(
        ca.Sparsity(unique.size, keys.size, list(range(keys.size + 1)), position.ravel().tolist()), 1.0
    )
    return pattern, summing


def dense_dm(values: np.ndarray) -> ca.DM:
    """``ca.DM(values)`` for a 2-D array, every entry a structural nonzero, built from a flat list.

    The same matrix, faster than CasADi's conversion of a NumPy array.
    """
    values = np.asarray(values, dtype=float)
    if values.ndim == 1:
        values = values[:, None]
    return ca.DM(ca.Sparsity.dense(*values.shape), values.ravel(order="F").tolist())


def _nonzeros(matrix: ca.SX) -> ca.SX:
    """The structural nonzeros of ``matrix`` as a column, in CasADi's (column-major) order."""
    return ca.sparsity_cast(matrix, ca.Sparsity.dense(matrix.nnz(), 1))


def _sample_inputs(structure: SampleStructure, x: ca.MX) -> tuple[ca.MX, tuple[ca.DM, ca.DM]]:
    """Every sample's variables ``v_s`` taken from ``x`` (n_local, n_samples), and its data and direction scale."""
    n_local, n_samples = structure.variables.shape
    variables = ca.reshape(x[structure.variables.ravel(order="F").tolist()], n_local, n_samples)
    return variables, structure.constants


def structured_nlp(structure: SampleStructure) -> dict[str, ca.MX]:
    """The NLP ``{"x", "p", "f", "g"}`` as the per-sample function mapped over the samples and the outer part.

    The same values as the NLP it was split from, as a few calls of SX functions: nothing to expand, and
    ``f`` and ``g`` each evaluate only what they need.
    """
    outer = structure.outer
    x, p = ca.MX.sym("x", outer.size1_in(0)), ca.MX.sym("p", outer.size1_in(2))
    xo, yo, po = (ca.SX.sym(name, outer.sparsity_in(i)) for i, name in enumerate(("x", "Y", "p")))
    fo, go = outer(xo, yo, po)
    n_samples = structure.variables.shape[1]
    variables, constants = _sample_inputs(structure, x)
    y = structure.sample.map(n_samples)(variables, *constants)
    f = ca.Function("outer_value_f", [xo, yo, po], [fo])(x, y, p)
    g = ca.Function("outer_value_g", [xo, yo, po], [go])(x, y, p)
    return {"x": x, "p": p, "f": f, "g": g}


def derivative_functions(structure: SampleStructure) -> dict[str, ca.Function]:
    """IPOPT's ``grad_f``, ``jac_g`` and ``hess_lag`` functions for CasADi's ``nlpsol``, assembled per sample."""
    outer, sample = structure.outer, structure.sample
    n_x, n_p = outer.size1_in(0), outer.size1_in(2)
    n_y, n_samples = outer.size_in(1)
    n_local = structure.variables.shape[0]
    n_g = outer.size1_out(1)

    # Per sample, in SX: its outputs with their Jacobian, and the upper triangle of the weighted Hessian, over
    # its own variables; only their structural nonzeros go into the NLP's (a denser KKT matrix costs MUMPS).
    v = ca.SX.sym("v", n_local)
    data = ca.SX.sym("data", sample.size1_in(1))
    scale = ca.SX.sym("scale", sample.size1_in(2))
    weights = ca.SX.sym("ybar", n_y)
    y = sample(v, data, scale)
    jacobian = ca.jacobian(y, v)
    hessian = ca.triu(ca.hessian(ca.dot(weights, y), v)[0])
    # Common subexpressions merged: fewer operations in the Hessian, the same values.
    first = ca.Function("sample_jacobian", [v, data, scale], [y, _nonzeros(jacobian)], {"cse": True})
    second = ca.Function("sample_hessian", [v, data, scale, weights], [_nonzeros(hessian)], {"cse": True})

    x, p = ca.MX.sym("x", n_x), ca.MX.sym("p", n_p)
    lam_f, lam_g = ca.MX.sym("lam_f"), ca.MX.sym("lam_g", n_g)
    variables, constants = _sample_inputs(structure, x)
    y_values, jac_blocks = first.map(n_samples)(variables, *constants)
    # J = dY/dx: sample s's block sits in rows n_y*s..n_y*s+n_y-1 and the columns of its variables.
    local_rows, local_cols = (np.array(i) for i in jacobian.sparsity().get_triplet())
    rows = (local_rows[:, None] + n_y * np.arange(n_samples)[None, :]).ravel(order="F")
    jac_pattern, jac_sum = _scatter(
        rows, structure.variables[local_cols].ravel(order="F"), (n_y * n_samples, n_x)
    )
    jac_y = ca.sparsity_cast(ca.mtimes(jac_sum, ca.vec(jac_blocks)), jac_pattern)

    # The outer part in (x, vec Y): its value and first derivatives, and the Hessian of its Lagrangian.
    xo, yo, po = ca.SX.sym("x", n_x), ca.SX.sym("Y", n_y, n_samples), ca.SX.sym("p", n_p)
    so, lo = ca.SX.sym("sigma"), ca.SX.sym("lambda", n_g)
    fo, go = outer(xo, yo, po)
    both = ca.vertcat(xo, ca.vec(yo))
    lagrangian = so * fo + ca.dot(lo, go)
    outer_f = ca.Function("outer_f", [xo, yo, po], [fo, ca.gradient(fo, both)])
    outer_g = ca.Function("outer_g", [xo, yo, po], [go, ca.jacobian(go, both)])
    # The Hessian comes with the gradient it differentiates: its Y part is ybar (not differentiated again).
    hess_expression, gradient = ca.hessian(lagrangian, both)
    ybar_expression = gradient[n_x:]
    outer_second = ca.Function("outer_second", [xo, yo, po, so, lo], [ybar_expression, hess_expression])

    f, grad = outer_f(x, y_values, p)
    grad_f = grad[:n_x] + ca.mtimes(ca.transpose(jac_y), grad[n_x:])
    g, jac = outer_g(x, y_values, p)
    jac_g = jac[:, :n_x] + ca.mtimes(jac[:, n_x:], jac_y)

    # The Hessian needs Y only through the outer part, and then the outputs alone: an outer part linear in Y
    # (the usual case) needs no per-sample evaluation besides the Hessians (an evaluation of the samples saved).
    y_second: ca.MX | ca.DM = ca.DM.zeros(n_y, n_samples)
    if any(ca.depends_on(e, ca.vec(yo)) for e in (ybar_expression, hess_expression)):
        y_second = sample.map(n_samples)(variables, *constants)
    ybar, hess = outer_second(x, y_second, p, lam_f, lam_g)
    hess_blocks = second.map(n_samples)(variables, *constants, ca.reshape(ybar, n_y, n_samples))
    if np.all(np.array(outer_second.sparsity_out(1).get_triplet()) < n_x):
        outer_part = hess[:n_x, :n_x]  # the outer part is linear in Y (the usual case): no product needed
    else:
        through = ca.vertcat(ca.MX.eye(n_x), jac_y)
        outer_part = ca.mtimes(ca.transpose(through), ca.mtimes(hess, through))
    # Each sample's Hessian nonzeros (upper triangle), summed into the NLP's Hessian.
    local_rows, local_cols = (np.array(i) for i in hessian.sparsity().get_triplet())
    global_rows, global_cols = structure.variables[local_rows], structure.variables[local_cols]
    top, bottom = np.minimum(global_rows, global_cols), np.maximum(global_rows, global_cols)
    hess_pattern, hess_sum = _scatter(top.ravel(order="F"), bottom.ravel(order="F"), (n_x, n_x))
    summed = ca.sparsity_cast(ca.mtimes(hess_sum, ca.vec(hess_blocks)), hess_pattern)
    hess_l = ca.triu(outer_part) + summed
    return {
        "grad_f": ca.Function("nlp_grad_f", [x, p], [f, grad_f], ["x", "p"], ["f", "grad_f_x"]),
        "jac_g": ca.Function("nlp_jac_g", [x, p], [g, jac_g], ["x", "p"], ["g", "jac_g_x"]),
        "hess_lag": ca.Function(
            "nlp_hess_l", [x, p, lam_f, lam_g], [hess_l], ["x", "p", "lam_f", "lam_g"], ["hess_gamma_x_x"]
        ),
    }
