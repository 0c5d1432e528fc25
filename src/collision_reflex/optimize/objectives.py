"""The objectives of the design problem: their names and senses, scaling, epigraph and epsilon bounds.

Each objective is divided by its value at the start point, so weights compare relative changes. The worst case
is an epigraph variable ``t >= I_s``; objectives built as bounded get a row ``f_k <= eps_k`` with ``eps_k`` an
NLP parameter, so one solver serves a whole epsilon-constraint Pareto sweep.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import casadi as ca
import numpy as np

from .. import _validate
from ..errors import InvalidParameter
from .constraints import ConstraintList

TIE_BREAK_WEIGHT = 1e-3
"""Weight of the (start-normalised) mean impulse added to every objective.

A worst case leaves the samples that do not bind it, and the joints that do not affect it, undetermined; this
small pull toward a lower mean picks a definite design among the equals and pins the per-sample auxiliary
variables, at a cost of about this relative amount in the main objective."""

IMPULSE_OBJECTIVES = ("worst_case_impulse", "mean_impulse")
"""The objectives that are statistics of the per-sample collision impulses (:func:`impulse_objectives`)."""

OBJECTIVES: dict[str, tuple[int, str, str]] = {
    # name: (sense: +1 minimise / -1 maximise, unit, description)
    "worst_case_impulse": (1, "N*s", "largest collision impulse over the samples"),
    "mean_impulse": (1, "N*s", "mean over the samples of the collision impulse"),
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


def objective_terms(impulses: ca.MX, actuator_mass: ca.MX, approach_velocity: ca.MX) -> dict[str, ca.MX]:
    """The objectives as expressions, but the worst case (an epigraph variable, see :func:`add_epigraph`).

    From the impulses [N*s] (1 x n_samples), the motors' total mass [kg] and the approach velocity [m/s].
    """
    return {
        "mean_impulse": ca.sum2(impulses) / impulses.shape[1],
        "actuator_mass": actuator_mass,
        "approach_velocity": approach_velocity,
    }


def impulse_objectives(impulses: np.ndarray) -> dict[str, float]:
    """The impulse objectives of a design's per-sample impulses [N*s]: the largest and the mean."""
    values = np.asarray(impulses, dtype=float).ravel()
    return {"worst_case_impulse": float(values.max()), "mean_impulse": float(values.mean())}


def objective_values(
    impulses: np.ndarray, actuator_mass: float, approach_velocity: float
) -> dict[str, float]:
    """Every objective of :data:`OBJECTIVES` for a design.

    From its per-sample impulses [N*s], total actuator mass [kg] and approach velocity [m/s].
    """
    return {
        **impulse_objectives(impulses),
        "actuator_mass": float(actuator_mass),
        "approach_velocity": float(approach_velocity),
    }


def objective_scale(start_impulses: np.ndarray, start_mass: np.ndarray, velocity: float) -> dict[str, float]:
    """Each objective's value at the start (impulses [N*s], motor masses [kg], approach velocity [m/s])."""
    return objective_values(start_impulses, float(np.sum(start_mass)), velocity)


def add_epigraph(
    g: ConstraintList,
    x: ca.MX,
    index: int,
    impulses: ca.MX,
    scale: Mapping[str, float],
    x0: np.ndarray,
    lbx: np.ndarray,
) -> ca.MX:
    """Add ``t >= I_s`` for every sample to ``g`` and give the worst-case bound ``t`` [N*s].

    ``x[index]`` is ``t`` divided by the start's worst case; it starts at 1 and is bounded below by 0.
    """
    t = x[index] * scale["worst_case_impulse"]
    x0[index] = 1.0
    lbx[index] = 0.0
    g.add(
        ca.transpose(t - impulses) / scale["worst_case_impulse"],
        0.0,
        np.inf,
        [f"worst-case bound >= impulse of sample {s}" for s in range(impulses.shape[1])],
    )
    return t


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
