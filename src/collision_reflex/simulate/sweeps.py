"""Sweeps of the simulation over approach velocity (and a second parameter) against the closed form."""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from .. import _validate
from ..errors import InvalidParameter
from .integrator import simulate
from .setup import CollisionSetup

SWEEP_PARAMETERS: tuple[str, ...] = ("delay", "backlash")
"""Setup fields that :func:`sweep` can vary besides the velocity."""


@dataclass(frozen=True)
class Sweep:
    """Simulated impulses against the closed form over approach velocities (and optionally a second parameter).

    Arrays have shape ``(len(values), len(velocities))``; ``values`` is ``[None]`` without a second parameter.

    Attributes
    ----------
    velocities: approach velocities [m/s].
    parameter: the second parameter's name (``"delay"`` [s] or ``"backlash"`` [m]) or None.
    values: its values.
    simulated: simulated impulse [N*s].
    closed_form: the closed form's impulse for the same setup [N*s] (it knows no delay or backlash).
    reaction: the closed form's reaction variant compared against.
    tolerance: relative difference beyond which the two are said to part.
    """

    velocities: np.ndarray
    parameter: str | None
    values: tuple[Any, ...]
    simulated: np.ndarray
    closed_form: np.ndarray
    reaction: str
    tolerance: float

    @property
    def relative_difference(self) -> np.ndarray:
        """``simulated / closed_form - 1``."""
        return self.simulated / self.closed_form - 1

    @property
    def parted(self) -> np.ndarray:
        """True where ``|relative_difference| > tolerance``."""
        return np.abs(self.relative_difference) > self.tolerance


def sweep(
    setup: CollisionSetup,
    velocities: Any,
    parameter: str | None = None,
    values: Any = None,
    reaction: str = "at_rest",
    v_r: float | str | None = None,
    tolerance: float = 0.05,
) -> Sweep:
    """Simulate ``setup`` at each approach velocity (and each value of ``parameter``) against the closed form.

    The closed form (:meth:`~collision_reflex.simulate.CollisionSetup.closed_form`) is evaluated alongside.

    Parameters
    ----------
    setup: the collision; its ``v0`` (and the swept parameter) are replaced.
    velocities: approach velocities [m/s], > 0.
    parameter: ``"delay"`` [s] or ``"backlash"`` [m] to sweep as well, or None.
    values: the parameter's values (>= 0); with ``"backlash"``, half of each is open at impact unless
        ``setup.initial_play`` says otherwise (it is then capped at the backlash).
    reaction, v_r: the closed form's reaction variant, as :func:`collision_reflex.model.phase_impulses`; ``v_r`` may
        also be ``"detected"``: the robot's velocity at detection in the ideal limit, ``v0 k / k_m``, per
        velocity (with ``reaction="moving"``).
    tolerance: relative difference that counts as parting, > 0.
    """
    speeds = np.atleast_1d(np.asarray(velocities, dtype=float))
    _validate.positive("velocities", speeds)
    _validate.positive("tolerance", tolerance)
    if parameter is None:
        levels: tuple[Any, ...] = (None,)
    else:
        _validate.choice("parameter", parameter, SWEEP_PARAMETERS)
        if values is None:
            raise InvalidParameter("values", values, f"the values of {parameter} to sweep")
        array = np.atleast_1d(np.asarray(values, dtype=float))
        _validate.non_negative(parameter, array)
        levels = tuple(float(v) for v in array)
    simulated = np.empty((len(levels), speeds.size))
    closed = np.empty_like(simulated)
    for i, level in enumerate(levels):
        changes: dict[str, Any] = {}
        if parameter == "delay":
            changes["delay"] = level
        elif parameter == "backlash":
            changes["backlash"] = level
            if setup.initial_play is not None:
                changes["initial_play"] = min(setup.initial_play, level)
        for j, v0 in enumerate(speeds):
            case = replace(setup, v0=float(v0), **changes)
            simulated[i, j] = simulate(case).impulse
            robot_velocity = case.detection_robot_velocity if v_r == "detected" else v_r
            closed[i, j] = float(case.closed_form(reaction, robot_velocity).total)  # type: ignore[arg-type]
    label = "moving at v0 k/k_m" if v_r == "detected" else reaction
    return Sweep(speeds, parameter, levels, simulated, closed, label, float(tolerance))
