"""Which samples an active-set solve works on: the first active set, and the samples a design violates.

A sample is violated when its impulse exceeds the active worst case (or the worst case's bound), its contact
threshold is below the noise floor, or its configuration's gravity demand exceeds a joint's driving torque;
the first active set holds the samples worst at the start, a spread, and those that carry the requirement rows.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from ..errors import InvalidParameter
from .body_region import region_violations
from .constraints import torque_requirement_rows
from .design import Design, design_at
from .evaluate import design_collision_parameters, evaluate_design
from .problem import DesignProblem


def first_active_set(
    full: DesignProblem, size: int, initial: np.ndarray | None, x_design: np.ndarray
) -> np.ndarray:
    """The first active samples: ``initial`` or the worst at the start and a spread, and the requirement's.

    ``x_design`` is the start design (log values, the first ``layout.size`` entries of ``x``).
    """
    n = full.samples.size
    start = design_at(full, x_design)
    impulses = evaluate_design(full, start)
    if initial is not None:
        chosen = np.asarray(initial).ravel()
        if (
            chosen.size == 0
            or not np.issubdtype(chosen.dtype, np.integer)
            or chosen.min() < 0
            or chosen.max() >= n
        ):
            raise InvalidParameter("initial", initial, f"sample indices in [0, {n})")
    elif size >= n:
        return np.arange(n)
    else:
        worst = np.argsort(impulses)[::-1][: max(size // 2, 1)]
        chosen = np.concatenate([worst, np.linspace(0, n - 1, size - worst.size).round().astype(int)])
    return np.unique(np.concatenate([chosen, _requirement_samples(full, start, impulses)]))


def _requirement_samples(full: DesignProblem, start: Design, impulses: np.ndarray) -> np.ndarray:
    """Samples that carry the requirement rows of the start design: the first active set's torque and speed.

    The static hold: per joint the configuration of the largest gravity demand at the start design (its worst
    sample at the start); more are added when they bind (:func:`_torque_violated`). With a duty cycle also, per
    joint, the sample of the largest approach joint rate, which sets the motor-speed row for every design.
    """
    static = _torque_violated(full, start, impulses, np.inf)
    if full.duty is not None:
        return np.union1d(np.abs(full.duty.approach_rates).argmax(axis=0), static)
    return static


def _torque_violated(
    full: DesignProblem, design: Design, impulses: np.ndarray, tolerance: float
) -> np.ndarray:
    """Per configuration whose gravity demand exceeds a joint's driving torque, its worst sample.

    The static hold's torque rows (with or without a duty cycle) are per sampled configuration (plus and minus
    the gravity torque, :func:`collision_reflex.optimize.constraints.torque_requirement_rows`): a configuration
    missing from the active samples has no row. A demand above ``(1 + tolerance)`` times the driving peak torque
    [N m] of ``design`` flags its configuration; ``tolerance=inf`` flags, per joint, the configuration of the
    largest demand instead. Given torques do not depend on the configurations: nothing is flagged.
    """
    samples = full.samples
    if full.constraints.torque_required is not None:
        return np.empty(0, dtype=int)
    rows, _ = torque_requirement_rows(samples, full.constraints, full.joint_names)
    configurations = np.repeat(np.unique(samples.config_index), 2)  # a + and a - row per configuration
    # The rows of the searched hold poses follow; every active set's problem has them.
    demands = np.array(
        [base + per_motor @ design.actuator_mass for base, per_motor in rows[: configurations.size]]
    )  # (rows, joints)
    if np.isinf(tolerance):
        flagged = configurations[demands.argmax(axis=0)]
    else:
        flagged = configurations[np.any(demands > (1 + tolerance) * design.driving_peak_torque, axis=1)]
    picked = []
    for configuration in np.unique(flagged):
        of_configuration = np.flatnonzero(samples.config_index == configuration)
        picked.append(int(of_configuration[np.argmax(impulses[of_configuration])]))
    return np.array(picked, dtype=int)


def violated_samples(
    full: DesignProblem,
    design: Design,
    impulses: np.ndarray,
    active: np.ndarray,
    epsilon: Mapping[str, float] | None,
    tolerance: float,
) -> np.ndarray:
    """Samples outside ``active`` that ``design`` violates, by more than the relative ``tolerance``.

    A sample is violated when its impulse [N*s] exceeds the active worst case (or the worst case's bound), its
    contact threshold is below the noise floor, the approach exceeds its permissible speed against the problem's
    body region, or its configuration's gravity demand exceeds a joint's driving torque.
    """
    inside = full.samples.inside(design.approach_velocity)  # samples in the design's contact domain
    levels = []
    if "worst_case_impulse" in full.objective:
        levels.append(impulses[active][inside[active]].max(initial=0.0))
    bound = (epsilon or {}).get("worst_case_impulse")
    if bound is not None:
        levels.append(bound)
    bad = np.zeros(impulses.size, dtype=bool)
    if levels:
        bad |= impulses > min(levels) * (1 + tolerance)
    floor = full.constraints.threshold_floor
    if full.technology.sensing == "position" and floor > 0:
        _, thresholds = design_collision_parameters(full, design)
        bad |= thresholds < floor * (1 - tolerance)
    bad &= inside
    region = full.constraints.body_region
    if region is not None:
        bad |= region_violations(full.samples, design, region, full.slowest_bound, tolerance)
    bad[_torque_violated(full, design, impulses, tolerance)] = True
    bad[active] = False
    return np.flatnonzero(bad)
