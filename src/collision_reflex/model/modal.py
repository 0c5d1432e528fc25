"""Undamped modes driven by a constant and a ramp, solved exactly.

Their state, a force read from them, its integral and its first crossing of a level. The joint-space collision
(:mod:`collision_reflex.model.joint_space`) writes each of its phases this way. Its crossings are found by
sampling at a 32nd of the shortest period and refining with Brent's method.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from .. import _validate
from ..errors import InvalidParameter

SAMPLES_PER_PERIOD = 32
"""Samples per shortest period of a crossing search (peaks to 0.5 %)."""
MAX_SAMPLES = 20_000_000
"""A crossing search longer than this many samples is refused (widely separated time scales): bounded run time."""
_FREE_MODE = 1e-9
"""A mode with ``w^2`` below this fraction of the largest is free (``w = 0``): rounding of a zero eigenvalue."""


@dataclass(frozen=True)
class Modes:
    """Undamped modes ``zeta_j'' + w_j^2 zeta_j = p_j + p1_j t``, ``zeta(0) = z0``, ``zeta'(0) = dz0``.

    The contact force is ``h0 + h1 t + h . zeta(t)`` [N]. A mode with ``w = 0`` moves freely.
    """

    w: np.ndarray
    z0: np.ndarray
    dz0: np.ndarray
    p: np.ndarray
    p1: np.ndarray
    h: np.ndarray
    h1: float = 0.0

    def _parts(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        tt = np.asarray(t, dtype=float)[..., None]
        free = self.w == 0
        w = np.where(free, 1.0, self.w)
        mean = np.where(free, 0.0, self.p / w**2)
        slope = np.where(free, 0.0, self.p1 / w**2)
        return tt, w, self.z0 - mean, self.dz0 - slope

    def state(self, t: Any) -> tuple[np.ndarray, np.ndarray]:
        """``zeta(t)`` and ``zeta'(t)`` at a time [s] or an array of times (modes last)."""
        tt, w, c, s = self._parts(np.asarray(t))
        free = self.w == 0
        wt = w * tt
        osc = (self.p + self.p1 * tt) / w**2 + c * np.cos(wt) + s * np.sin(wt) / w
        dosc = self.p1 / w**2 - c * w * np.sin(wt) + s * np.cos(wt)
        poly = self.z0 + self.dz0 * tt + self.p * tt**2 / 2 + self.p1 * tt**3 / 6
        dpoly = self.dz0 + self.p * tt + self.p1 * tt**2 / 2
        return np.where(free, poly, osc), np.where(free, dpoly, dosc)

    def force(self, t: Any) -> Any:
        """The contact force at ``t`` [N] (array in, array out)."""
        tt, w, c, s = self._parts(t)
        free = self.w == 0
        wt = w * tt
        osc = (self.p + self.p1 * tt) / w**2 + c * np.cos(wt) + s * np.sin(wt) / w
        poly = self.z0 + self.dz0 * tt + self.p * tt**2 / 2 + self.p1 * tt**3 / 6
        return self.h1 * tt[..., 0] + np.where(free, poly, osc) @ self.h

    def impulse(self, t: float) -> float:
        """``integral_0^t force`` [N*s], exact."""
        tt, w, c, s = self._parts(np.asarray(t))
        free = self.w == 0
        wt = w * tt
        osc = (self.p * tt + self.p1 * tt**2 / 2) / w**2 + c * np.sin(wt) / w + s * (1 - np.cos(wt)) / w**2
        poly = self.z0 * tt + self.dz0 * tt**2 / 2 + self.p * tt**3 / 6 + self.p1 * tt**4 / 24
        return float(self.h1 * t**2 / 2 + np.where(free, poly, osc) @ self.h)

    def shortest_period(self) -> float:
        """The period of the fastest moving mode [s] (``inf`` if none moves)."""
        moving = self.w[self.w > 0]
        return float(2 * np.pi / moving.max()) if moving.size else math.inf

    def longest_period(self) -> float:
        """The period of the slowest moving mode the force reads [s] (0 if none)."""
        moving = self.w[(self.w > 0) & (np.abs(self.h) > 0)]
        return float(2 * np.pi / moving.min()) if moving.size else 0.0


def normal_modes(mass: np.ndarray, stiffness: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Frequencies [rad/s] and mass-normalised mode shapes (``Phi^T mass Phi = I``) of ``mass, stiffness``."""
    from scipy.linalg import eigh  # lazy: scipy

    mass = _validate.arrays("mass", mass, ndim=2, square=True)
    stiffness = _validate.arrays("stiffness", stiffness, ndim=2, square=True)
    if mass.ndim != 2 or stiffness.shape != mass.shape:
        raise InvalidParameter(
            "mass, stiffness", (mass.shape, stiffness.shape), "two square matrices of one shape"
        )
    if mass.shape[0] == 0:
        return np.zeros(0), np.zeros((0, 0))
    w2, shapes = eigh(stiffness, mass)
    w2 = np.where(w2 <= _FREE_MODE * max(float(np.max(np.abs(w2))), 1e-300), 0.0, w2)
    return np.sqrt(w2), shapes


def first_crossing(modes: Modes, level: float, horizon: float, rising: bool, what: str) -> float:
    """The first time in ``(0, horizon]`` [s] where the force crosses ``level`` [N] (upward if ``rising``)."""
    from scipy.optimize import brentq  # lazy: scipy

    if not isinstance(modes, Modes):
        raise InvalidParameter("modes", modes, "a Modes (the collision's modal solution)")
    level, horizon = _validate.finite("level", level), _validate.positive("horizon", horizon)
    step = min(modes.shortest_period(), horizon) / SAMPLES_PER_PERIOD
    count = math.ceil(horizon / step)
    if count > MAX_SAMPLES:
        raise InvalidParameter(
            what,
            f"{count:.3g} samples",
            f"at most {MAX_SAMPLES:.3g} samples of the shortest period",
            "the arm's periods and the collision's duration are too far apart for this model",
        )
    chunk = 8192
    for start in range(0, count, chunk):
        times = np.arange(start, min(start + chunk, count) + 1) * step
        margin = modes.force(times) - level
        hits = (margin[:-1] < 0) & (margin[1:] >= 0) if rising else (margin[:-1] > 0) & (margin[1:] <= 0)
        found = np.flatnonzero(hits)
        if found.size:
            i = int(found[0])
            return float(
                brentq(
                    lambda t: float(modes.force(np.array([t]))[0]) - level, times[i], times[i + 1], xtol=1e-16
                )
            )
    raise InvalidParameter(what, horizon, "a crossing within the searched horizon [s]")
