"""The n-shot fit: impulse against pre-impact velocity, ``I(v) = A v + B / v + C``.

The paper's "Effect of Actuator Selection"; ``fig:1d_experiment_nshot``.

The model predicts ``A = m_f``, ``B = F_s^2 / (2 k)`` and ``C = I3`` (:func:`collision_reflex.model.velocity_coefficients`)
and the optimal approach velocity ``v* = sqrt(B / A)``, which equals ``F_s / sqrt(2 k m_f)`` (``eq:v_star``).
The fit is linear in ``A, B, C``: weighted least squares with each impulse's uncertainty, with the physical
bounds ``A, B, C >= 0`` (``scipy.optimize.lsq_linear``). Uncertainties come from ``(X^T W X)^-1`` scaled by the
reduced chi-square when it exceeds one (scatter beyond the stated uncertainties widens them); that of ``v*`` by
first-order propagation.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import FitFailed, InvalidParameter


@dataclass(frozen=True)
class VelocityLawFit:
    """``I(v) = A v + B / v + C`` fitted to measured impulses.

    Attributes
    ----------
    A: [kg] (= N*s per m/s), the model's finger mass ``m_f``.
    B: [N*m] (= N*s times m/s), the model's ``F_s^2 / (2 k)``.
    C: [N*s], the model's reaction impulse ``I3``.
    stderr_A, stderr_B, stderr_C: one-standard-deviation uncertainties (same units).
    v_star: optimal approach velocity ``sqrt(B / A)`` [m/s]; ``inf`` if ``A = 0`` (the impulse falls with
        velocity over the whole range), ``0`` if ``B = 0``.
    stderr_v_star: its uncertainty [m/s] (``inf`` when ``v_star`` is at a bound).
    trials: number of impulses fitted.
    at_bound: names of the coefficients held at their bound 0 (their uncertainties are then not meaningful).
    """

    A: float
    B: float
    C: float
    stderr_A: float
    stderr_B: float
    stderr_C: float
    v_star: float
    stderr_v_star: float
    trials: int
    at_bound: tuple[str, ...] = ()

    def impulse(self, velocity: np.ndarray | float) -> np.ndarray | float:
        """The fitted ``I(v)`` [N*s] at ``velocity`` [m/s]."""
        return self.A * velocity + self.B / velocity + self.C

    @property
    def minimum_impulse(self) -> float:
        """``I(v*) = 2 sqrt(A B) + C`` [N*s]."""
        return 2.0 * math.sqrt(self.A * self.B) + self.C


def fit_velocity_law(
    velocity: np.ndarray, impulse: np.ndarray, uncertainty: np.ndarray | None = None
) -> VelocityLawFit:
    """Fit ``I(v) = A v + B / v + C`` to impulses measured at several velocities.

    Parameters
    ----------
    velocity: pre-impact velocities [m/s], shape (n,), > 0, at least three distinct values.
    impulse: measured impulses [N*s], shape (n,).
    uncertainty: their one-standard-deviation uncertainties [N*s], shape (n,), > 0; ``None`` for equal weights.
    """
    from scipy.optimize import lsq_linear

    v = np.asarray(velocity, dtype=float)
    y = np.asarray(impulse, dtype=float)
    if v.ndim != 1 or y.shape != v.shape:
        raise InvalidParameter("velocity, impulse", (v.shape, y.shape), "two 1-D arrays of one length")
    if not np.all(np.isfinite(v) & (v > 0)):
        raise InvalidParameter("velocity", v, "finite numbers > 0 [m/s]")
    if not np.all(np.isfinite(y)):
        raise InvalidParameter("impulse", y, "finite numbers [N*s]")
    if np.unique(v).size < 3:
        raise InvalidParameter(
            "velocity", v, "at least three distinct velocities", "A, B and C need three; measure more speeds"
        )
    if uncertainty is None:
        sigma = np.ones_like(y)
    else:
        sigma = np.asarray(uncertainty, dtype=float)
        if sigma.shape != y.shape or not np.all(np.isfinite(sigma) & (sigma > 0)):
            raise InvalidParameter("uncertainty", sigma, "finite numbers > 0 [N*s], one per impulse")
    design = np.column_stack([v, 1.0 / v, np.ones_like(v)])
    weighted = design / sigma[:, None]
    result = lsq_linear(weighted, y / sigma, bounds=(0.0, np.inf), method="bvls")
    if not result.success:
        raise FitFailed("n-shot fit of I(v) = A v + B/v + C", result.message)
    A, B, C = (float(c) for c in result.x)
    dof = v.size - 3
    chi2 = float(np.sum(((design @ result.x - y) / sigma) ** 2))
    # Without stated uncertainties the scatter is the only scale; with them, only widen, never narrow.
    scale = chi2 / dof if dof > 0 else 1.0
    if uncertainty is not None:
        scale = max(scale, 1.0)
    covariance = np.linalg.pinv(weighted.T @ weighted) * scale
    stderr = np.sqrt(np.clip(np.diag(covariance), 0.0, None))
    at_bound = tuple(name for name, value in zip("ABC", (A, B, C), strict=True) if value <= 0.0)
    if A > 0 and B > 0:
        v_star = math.sqrt(B / A)
        # d v*/dA = -v*/(2A), d v*/dB = v*/(2B)
        gradient = np.array([-v_star / (2 * A), v_star / (2 * B), 0.0])
        stderr_v_star = float(np.sqrt(max(gradient @ covariance @ gradient, 0.0)))
    else:
        v_star = math.inf if A <= 0 and B > 0 else 0.0
        stderr_v_star = math.inf
    return VelocityLawFit(
        A=A,
        B=B,
        C=C,
        stderr_A=float(stderr[0]),
        stderr_B=float(stderr[1]),
        stderr_C=float(stderr[2]),
        v_star=v_star,
        stderr_v_star=stderr_v_star,
        trials=int(v.size),
        at_bound=at_bound,
    )
