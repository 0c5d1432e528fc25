"""The objectives of the design problem: their names and senses, scaling, epigraph and epsilon bounds.

Each objective is divided by its value at the start point, so weights compare relative changes. The worst case
is an epigraph variable ``t >= I_s``; objectives built as bounded get a row ``f_k <= eps_k`` with ``eps_k`` an
NLP parameter, so one solver serves a whole epsilon-constraint Pareto sweep.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING

import casadi as ca
import numpy as np

from .. import _validate
from ..errors import InvalidParameter
from .constraints import ConstraintList
from .samples import SPEED_CAP_TOLERANCE

if TYPE_CHECKING:
    from .samples import ContactSamples

TIE_BREAK_WEIGHT = 1e-3
"""Weight of the (start-normalised) mean impulse added to every objective.

A worst case leaves the samples that do not bind it, and the joints that do not affect it, undetermined; this
small pull toward a lower mean picks a definite design among the equals and pins the per-sample auxiliary
variables, at a cost of about this relative amount in the main objective."""


CVAR_LEVEL = 0.95
"""Level of the ``cvar_impulse`` objective: the mean impulse of the worst 5 % of the drawn samples. A 1 % tail
would be 3 of the Panda study's 288 samples, a worst case in all but name; 5 % is 14 of them."""

OBJECTIVES: dict[str, tuple[int, str, str]] = {
    # name: (sense: +1 minimise / -1 maximise, unit, description)
    "worst_case_impulse": (1, "N*s", "largest collision impulse over the samples"),
    "mean_impulse": (1, "N*s", "mean over the samples of the collision impulse"),
    "cvar_impulse": (
        1,
        "N*s",
        "mean collision impulse of the worst 5 % of the samples (conditional value at risk, CVAR_LEVEL)",
    ),
    "actuator_mass": (1, "kg", "total mass of the motors"),
    "approach_velocity": (-1, "m/s", "approach velocity (maximised: shorter cycle time)"),
}


def objective_weights(objective: str | Mapping[str, float]) -> dict[str, float]:
    """The objective as ``{name: weight}``, names and weights (> 0) checked."""
    weights = {objective: 1.0} if isinstance(objective, str) else dict(objective)
    if not weights:
        raise InvalidParameter("objective", objective, "an objective name or a non-empty {name: weight}")
    for name, weight in weights.items():
        _validate.choice("objective", name, tuple(OBJECTIVES))
        _validate.positive(f"weight of {name}", weight)
    return weights


def checked_bounded_objectives(names: Sequence[str]) -> tuple[str, ...]:
    """The objectives that may be bounded per solve, names checked."""
    for name in names:
        _validate.choice("bounded objective", name, tuple(OBJECTIVES))
    return tuple(names)


def mean_weights(samples: ContactSamples) -> np.ndarray:
    """Each sample's weight in a mean impulse, (n_samples,): equal over the drawn samples, 0 for searched ones."""
    drawn = np.asarray(samples.drawn, dtype=float)
    return drawn / drawn.sum()


def value_at_risk(values: np.ndarray, weights: np.ndarray, level: float) -> float:
    """The weighted ``level`` quantile of ``values`` (the inverted CDF).

    That is the smallest value whose weight below and at it reaches ``level`` of the total.
    """
    order = np.argsort(values)
    cumulative = np.cumsum(weights[order])
    return float(
        values[order][min(int(np.searchsorted(cumulative, level * cumulative[-1])), values.size - 1)]
    )


def conditional_value_at_risk(values: np.ndarray, weights: np.ndarray, level: float = CVAR_LEVEL) -> float:
    """The weighted mean of the worst ``1 - level`` share of ``values``: ``min_t t + E[(v - t)+] / (1 - level)``.

    The minimum is at ``t`` the value at risk (:func:`value_at_risk`), where this is the Rockafellar-Uryasev
    form the NLP optimises (:func:`add_tail`); weights need not sum to one.
    """
    values, weights = np.asarray(values, dtype=float), np.asarray(weights, dtype=float)
    weights = weights / weights.sum()
    var = value_at_risk(values, weights, level)
    return var + float(weights @ np.maximum(values - var, 0.0)) / (1 - level)


def add_tail(
    g: ConstraintList,
    x: ca.MX,
    index: slice,
    impulses: ca.MX,
    scale: Mapping[str, float],
    samples: ContactSamples,
) -> ca.MX:
    """Add the tail rows ``z_s >= I_s - t`` and give the CVaR expression [N*s] (Rockafellar-Uryasev).

    ``x[index]`` holds ``t`` (the value at risk) then one ``z_s >= 0`` per sample (their lower bound), all
    divided by the start's CVaR; the CVaR is ``t + sum_s w_s z_s / (1 - CVAR_LEVEL)`` with ``w`` the mean's
    weights (drawn samples only). At the optimum ``t`` is the value at risk and ``z_s = (I_s - t)+``.
    """
    unit = scale["cvar_impulse"]
    weights = mean_weights(samples)
    t, z = x[index.start], x[index.start + 1 : index.stop]
    rows = z - ca.transpose(impulses) / unit + t
    g.add(
        rows,
        0.0,
        np.inf,
        [f"tail slack >= impulse over the value at risk, sample {s}" for s in range(z.shape[0])],
    )
    return unit * (t + ca.mtimes(ca.DM(weights).T, z) / (1 - CVAR_LEVEL))


def objective_terms(
    impulses: ca.MX, actuator_mass: ca.MX, approach_velocity: ca.MX, samples: ContactSamples
) -> dict[str, ca.MX]:
    """The objectives as expressions, but the worst case and the CVaR (auxiliary variables).

    Those two are :func:`add_epigraph`'s and :func:`add_tail`'s.

    From the impulses [N*s] (1 x n_samples) at ``samples``, the motors' total mass [kg] and the approach
    velocity [m/s]; the mean is over the drawn samples (:func:`mean_weights`).
    """
    return {
        "mean_impulse": ca.mtimes(impulses, ca.DM(mean_weights(samples))),
        "actuator_mass": actuator_mass,
        "approach_velocity": approach_velocity,
    }


def impulse_objectives(impulses: np.ndarray, samples: ContactSamples, velocity: float) -> dict[str, float]:
    """The impulse objectives of a design's per-sample impulses [N*s] at ``samples``.

    The worst case is the largest impulse over the samples in the contact domain of a design approaching at
    ``velocity`` [m/s] (:meth:`ContactSamples.inside`); the mean and the CVaR are over the drawn samples.
    """
    values = np.asarray(impulses, dtype=float).ravel()
    weights = mean_weights(samples)
    return {
        "worst_case_impulse": float(values[samples.inside(velocity)].max()),
        "mean_impulse": float(values @ weights),
        "cvar_impulse": conditional_value_at_risk(values, weights),
    }


def objective_values(
    impulses: np.ndarray, actuator_mass: float, approach_velocity: float, samples: ContactSamples
) -> dict[str, float]:
    """Every objective of :data:`OBJECTIVES` for a design.

    From its per-sample impulses [N*s] at ``samples``, total actuator mass [kg] and approach velocity [m/s].
    """
    return {
        **impulse_objectives(impulses, samples, float(approach_velocity)),
        "actuator_mass": float(actuator_mass),
        "approach_velocity": float(approach_velocity),
    }


def add_epigraph(
    g: ConstraintList,
    x: ca.MX,
    index: int,
    impulses: ca.MX,
    scale: Mapping[str, float],
    samples: ContactSamples,
    slowest: ca.MX | float,
) -> ca.MX:
    """Add ``t >= I_s`` for every sample to ``g`` and give the worst-case bound ``t`` [N*s].

    ``x[index]`` is ``t`` divided by the start's worst case (bounded below by 0). A sample
    whose speed cap is below ``slowest`` [m/s], the least approach velocity the solve allows (its lower bound,
    or an NLP parameter's bound), is outside the contact domain of every design of the solve: its row is
    relaxed by :data:`RELAXED_ROW`.
    """
    t = x[index] * scale["worst_case_impulse"]
    rows = ca.transpose(t - impulses) / scale["worst_case_impulse"]
    caps = np.asarray(samples.speed_cap, dtype=float)
    finite = np.isfinite(caps)
    if np.any(finite):
        capped = ca.DM(np.where(finite, caps, 0.0))
        rows = rows + RELAXED_ROW * ca.DM(finite.astype(float)) * (
            slowest * (1 - SPEED_CAP_TOLERANCE) > capped
        )
    g.add(rows, 0.0, np.inf, [f"worst-case bound >= impulse of sample {s}" for s in range(impulses.shape[1])])
    return t


RELAXED_ROW = 1e9
"""Added to the (start-normalised) worst-case row of a sample outside every design's domain of a solve."""


def add_objective_bounds(
    g: ConstraintList,
    bounded: Sequence[str],
    expressions: Mapping[str, ca.MX],
    scale: Mapping[str, float],
    p: ca.MX,
) -> None:
    """Add ``f_k <= eps_k`` for each bounded objective, ``eps_k`` the NLP parameter ``p[k]`` (scaled)."""
    for k, name in enumerate(bounded):
        g.add(
            OBJECTIVES[name][0] * expressions[name] / scale[name] - p[k],
            -np.inf,
            0.0,
            [f"{name} within its bound"],
        )


def objective_expression(
    weights: Mapping[str, float], expressions: Mapping[str, ca.MX], scale: Mapping[str, float]
) -> ca.MX:
    """The NLP's objective: the weighted, start-normalised objectives plus the tie-break pull on the mean."""
    f = sum(
        weight * OBJECTIVES[name][0] * expressions[name] / scale[name] for name, weight in weights.items()
    )
    return f + TIE_BREAK_WEIGHT * expressions["mean_impulse"] / scale["mean_impulse"]
