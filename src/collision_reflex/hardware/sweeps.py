"""The paper's one-dimensional actuator design sweeps.

- :func:`radius_velocity_sweep`: the impulse over motor stator diameter x approach velocity, a motor scaled
  from a reference and geared to meet a torque requirement (``fig:motor_scale_modeling``);
- :func:`stiffness_sweep`: the impulse over mechanical stiffness for force-threshold and position-threshold
  sensing (``fig:stiff-sensing-impulse``).

Both build :class:`~collision_reflex.hardware.actuators.Actuator` objects for a rotary joint acting on a contact at a
lever ``L`` and evaluate the 1D model of :mod:`collision_reflex.model.impulse`. Stiffnesses and thresholds are given
at the contact [N/m, N] as in the paper and converted to the joint (``k L**2``) for the actuator.

Assumptions the paper does not state are parameters with documented defaults (:data:`SWEEP_DEFAULTS`):
the lever ``L`` = 114.3 mm, the characteristic length of the paper's 1D experiment; the finger (link) mass,
0.1 kg, the finger mass the paper fitted for its direct-drive U8 in that experiment (``tab:one_shot``); and
where the reflected rotor inertia sits, ``"finger"``: the paper's text says the impulse "increases
dramatically" for small motors with high gear ratios "as the reflected inertia is scaled by N^2", which happens
only if that inertia reaches the contact in the impact phase (a rigid transmission with the compliance at the
contact, like its geared A8 whose fitted finger mass was 20 kg). With ``"robot"`` (the arm model's placement)
the reflected inertia only slows the reaction, whose impulse is small here, and the impulse barely depends on
the motor size.
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike

from .. import _validate
from .._io import atomic_open
from ..errors import InvalidParameter
from ..model.impulse import minimum_impulse, optimal_velocity, phase_impulses, series_stiffness
from ..vocabulary import REACTION_MODES, REFLECTED_INERTIA_PLACEMENTS
from .actuators import Actuator, CollisionParameters, ForceThreshold, PositionThreshold, gear_ratio_for
from .gearboxes import Gearbox
from .motors import DEFAULT_SCALING_LAW, Motor, reference_motor, scaling_law

if TYPE_CHECKING:
    import pandas as pd

__all__ = [
    "SWEEP_DEFAULTS",
    "RadiusVelocitySweep",
    "StiffnessSweep",
    "radius_velocity_sweep",
    "stiffness_sweep",
]

SWEEP_DEFAULTS: dict[str, Any] = {
    "torque_required": 1.3,  # N m, tab:motor_params (the reference motor's peak torque)
    "k_m": 1000.0,  # N/m at the contact, fig:motor_scale_modeling
    "k_s": 100.0,  # N/m at the contact, fig:motor_scale_modeling
    "F_s": 3.0,  # N, fig:motor_scale_modeling
    "lever": 0.1143,  # m: ASSUMPTION, the paper's 1D experiment's characteristic length
    "m_f": 0.1,  # kg: ASSUMPTION, the paper's U8 fit in tab:one_shot
    "m_r": 0.0,  # kg: ASSUMPTION, no unsprung mass besides the reflected inertia
    "reflected_inertia_in": "finger",  # ASSUMPTION, see the module docstring
    "law": DEFAULT_SCALING_LAW,
}
"""The sweeps' default settings (contact-level ones in the paper's symbols, SI units)."""


@dataclass(frozen=True)
class RadiusVelocitySweep:
    """Impulse over a grid of stator diameter x approach velocity, with the optimum.

    Arrays are indexed ``[diameter, velocity]``; per-diameter arrays have shape ``(n_diameters,)``.
    """

    diameters: np.ndarray
    """Stator outer diameters [m]."""
    velocities: np.ndarray
    """Approach velocities [m/s]."""
    impulse: np.ndarray
    """Total impulse [N s], shape (n_diameters, n_velocities)."""
    gear_ratio: np.ndarray
    """``N = max(1, tau_req / tau_p(r))``."""
    reflected_inertia: np.ndarray
    """``N**2 J_m`` [kg m^2]."""
    m_f: np.ndarray
    """Finger (sprung) mass at the contact [kg]."""
    m_r: np.ndarray
    """Robot (unsprung) mass at the contact [kg]."""
    F_s: np.ndarray
    """Force threshold at the contact [N]."""
    optimal_velocity: np.ndarray
    """``v*`` per diameter [m/s] (``eq:v_star``)."""
    minimum_impulse: np.ndarray
    """Impulse at ``v*`` per diameter [N s]."""
    best_diameter: float
    """Stator diameter of the lowest impulse over the swept diameter range, refined between grid points [m]."""
    best_velocity: float
    """Approach velocity of the lowest impulse [m/s] (``v*`` at ``best_diameter``)."""
    best_impulse: float
    """The lowest impulse [N s]."""
    assumptions: dict[str, Any] = field(default_factory=dict)
    """Every setting used, including the assumptions the paper does not state."""

    def table(self) -> pd.DataFrame:
        """The grid as a long pandas DataFrame, one row per (diameter, velocity), SI units in the headers."""
        import pandas as pd

        n_v = self.velocities.size
        return pd.DataFrame(
            {
                "stator_diameter_m": np.repeat(self.diameters, n_v),
                "velocity_m_per_s": np.tile(self.velocities, self.diameters.size),
                "gear_ratio": np.repeat(self.gear_ratio, n_v),
                "reflected_inertia_kg_m2": np.repeat(self.reflected_inertia, n_v),
                "finger_mass_kg": np.repeat(self.m_f, n_v),
                "robot_mass_kg": np.repeat(self.m_r, n_v),
                "impulse_N_s": self.impulse.ravel(),
            }
        )

    def to_csv(self, path: str | os.PathLike[str]) -> Path:
        """Write :meth:`table` to ``path`` atomically, the settings as ``#`` comment lines on top."""
        return _write_csv(path, self.table(), self.assumptions)


def _contact_actuator(
    motor: Motor,
    gear: float,
    k_m: float,
    k_s: float,
    lever: float,
    sensing: ForceThreshold | PositionThreshold,
    gearbox: Gearbox | None = None,
) -> Actuator:
    """An actuator whose joint stiffnesses are the contact stiffnesses [N/m] moved to the joint (``k L**2``)."""
    return Actuator(
        motor,
        gear_ratio=gear,
        mechanical_stiffness=k_m * lever**2,
        software_stiffness=k_s * lever**2,
        sensing=sensing,
        gearbox=gearbox,
        gearbox_inertia=gearbox is not None,
    )


@dataclass(frozen=True)
class _MotorScaling:
    """The settings of a radius-velocity sweep that turn a stator diameter [m] into a contact."""

    reference: Motor
    law: str
    stack_length: float | None
    torque_required: float
    k_m: float
    k_s: float
    F_s: float
    lever: float
    m_f: float
    m_r: float
    reflected_inertia_in: str
    gearbox: Gearbox | None

    def actuator(self, diameter: float) -> Actuator:
        """The reference motor scaled to ``diameter`` [m], geared to meet the torque requirement."""
        motor = self.reference.scaled(diameter, self.stack_length, self.law)
        gear = float(gear_ratio_for(self.torque_required, motor.peak_torque))
        box = self.gearbox.scaled(diameter=diameter) if self.gearbox is not None and gear > 1 else None
        return _contact_actuator(motor, gear, self.k_m, self.k_s, self.lever, ForceThreshold(self.F_s), box)

    def contact(self, actuator: Actuator) -> CollisionParameters:
        """The 1D collision parameters of ``actuator`` at the sweep's lever."""
        return actuator.contact_parameters(self.lever, self.m_f, self.m_r, self.reflected_inertia_in)

    def minimum_impulse(self, diameter: float) -> float:
        """The impulse at the optimal velocity [N s] of the motor of stator ``diameter`` [m]."""
        return float(minimum_impulse(**self.contact(self.actuator(diameter)).impulse_arguments()))

    def assumptions(self) -> dict[str, Any]:
        """Every setting, labelled with its unit and whether the paper states it."""
        return {
            "reference motor": self.reference.name,
            "scaling law": self.law,
            "stack length [m]": (
                self.stack_length if self.stack_length is not None else self.reference.stack_length
            ),
            "torque requirement [N m]": self.torque_required,
            "mechanical stiffness k_m at the contact [N/m]": self.k_m,
            "software stiffness k_s at the contact [N/m]": self.k_s,
            "force threshold F_s [N]": self.F_s,
            "lever L [m] (assumed: the paper's 1D experiment length)": self.lever,
            "finger mass [kg] (assumed: the paper's one-shot fit of the U8)": self.m_f,
            "extra robot mass [kg] (assumed)": self.m_r,
            "reflected inertia in (assumed, see docs)": self.reflected_inertia_in,
            "gearbox inertia": (
                "ignored, as in the paper"
                if self.gearbox is None
                else f"{self.gearbox.kind} gearbox scaled to each geared motor's diameter, "
                f"from: {self.gearbox.source}"
            ),
            "reaction": "at_rest (the paper's)",
        }


def radius_velocity_sweep(
    diameters: ArrayLike,
    velocities: ArrayLike,
    *,
    reference: Motor | None = None,
    law: str = SWEEP_DEFAULTS["law"],
    torque_required: float = SWEEP_DEFAULTS["torque_required"],
    k_m: float = SWEEP_DEFAULTS["k_m"],
    k_s: float = SWEEP_DEFAULTS["k_s"],
    F_s: float = SWEEP_DEFAULTS["F_s"],
    lever: float = SWEEP_DEFAULTS["lever"],
    m_f: float = SWEEP_DEFAULTS["m_f"],
    m_r: float = SWEEP_DEFAULTS["m_r"],
    reflected_inertia_in: str = SWEEP_DEFAULTS["reflected_inertia_in"],
    stack_length: float | None = None,
    gearbox: Gearbox | None = None,
) -> RadiusVelocitySweep:
    """Impulse of a 1D collision over motor stator diameter x approach velocity (``fig:motor_scale_modeling``).

    Each diameter gets the reference motor scaled by ``law`` at ``stack_length`` and the gear ratio
    ``N = max(1, tau_req / tau_p(r))``; the actuator drives a contact at ``lever`` through a rotary joint.

    Parameters
    ----------
    diameters: stator outer diameters [m], > 0 (1D array).
    velocities: approach velocities [m/s], > 0 (1D array).
    reference: motor scaled from (default the Omni+ OPN-060-013-A).
    law: motor scaling law name.
    torque_required: output torque the joint must reach [N m].
    k_m: mechanical stiffness at the contact [N/m].
    k_s: software stiffness at the contact [N/m].
    F_s: force threshold at the contact [N].
    lever: distance from the joint axis to the contact [m].
    m_f: link (sprung) mass at the contact [kg].
    m_r: unsprung mass at the contact besides the reflected inertia [kg].
    reflected_inertia_in: ``"finger"`` or ``"robot"``, see :meth:`Actuator.contact_parameters`.
    stack_length: motor stack length [m], default the reference's.
    gearbox: a real gearbox to add to every geared motor (``N > 1``), scaled to the motor's stator diameter at
        its own length and stages; its reflected inertia then counts (the paper ignores it, the default).
        Direct-drive motors get none.
    """
    diameters = _grid("diameters", diameters)
    velocities = _grid("velocities", velocities)
    law_name = scaling_law(law).name
    for name, value in (("torque_required", torque_required), ("k_m", k_m), ("k_s", k_s), ("F_s", F_s)):
        _validate.positive(name, value)
    _validate.positive("lever", lever)
    _validate.choice("reflected_inertia_in", reflected_inertia_in, REFLECTED_INERTIA_PLACEMENTS)
    scaling = _MotorScaling(
        reference=reference if reference is not None else reference_motor(),
        law=law_name,
        stack_length=stack_length,
        torque_required=torque_required,
        k_m=k_m,
        k_s=k_s,
        F_s=F_s,
        lever=lever,
        m_f=m_f,
        m_r=m_r,
        reflected_inertia_in=reflected_inertia_in,
        gearbox=gearbox,
    )
    return _sweep_grid(scaling, diameters, velocities)


def _sweep_grid(scaling: _MotorScaling, diameters: np.ndarray, velocities: np.ndarray) -> RadiusVelocitySweep:
    """Evaluate the impulse over the grid, its per-diameter optimum and the refined overall optimum."""
    actuators = [scaling.actuator(float(d)) for d in diameters]
    contacts = [scaling.contact(actuator) for actuator in actuators]
    m_f, k, k_m, F_s, a = (
        np.array([getattr(c, key) for c in contacts]) for key in ("m_f", "k", "k_m", "F_s", "a")
    )
    impulse = phase_impulses(
        m_f[:, None], k[:, None], k_m[:, None], F_s[:, None], a[:, None], velocities[None, :]
    )
    v_star = optimal_velocity(m_f, k, F_s)
    i_star = minimum_impulse(m_f, k, k_m, F_s, a)

    best_diameter, best_impulse = _refine_minimum(diameters, i_star, scaling.minimum_impulse)
    best = scaling.contact(scaling.actuator(best_diameter))
    return RadiusVelocitySweep(
        diameters=diameters,
        velocities=velocities,
        impulse=np.asarray(impulse.total, dtype=float),
        gear_ratio=np.array([actuator.gear_ratio for actuator in actuators]),
        reflected_inertia=np.array([actuator.reflected_inertia for actuator in actuators]),
        m_f=m_f,
        m_r=np.array([c.m_r for c in contacts]),
        F_s=F_s,
        optimal_velocity=np.asarray(v_star, dtype=float),
        minimum_impulse=np.asarray(i_star, dtype=float),
        best_diameter=best_diameter,
        best_velocity=float(optimal_velocity(best.m_f, best.k, best.F_s)),
        best_impulse=best_impulse,
        assumptions=scaling.assumptions(),
    )


def _refine_minimum(
    grid: np.ndarray, values: np.ndarray, function: Callable[[float], float]
) -> tuple[float, float]:
    """Minimise ``function`` between the grid neighbours of the best grid point (log scale, bounded Brent)."""
    from scipy.optimize import minimize_scalar

    index = int(np.argmin(values))
    best_x, best_value = float(grid[index]), float(values[index])
    if grid.size < 2:
        return best_x, best_value
    low, high = grid[max(index - 1, 0)], grid[min(index + 1, grid.size - 1)]
    found = minimize_scalar(
        lambda log_x: function(math.exp(log_x)),
        bounds=(math.log(low), math.log(high)),
        method="bounded",
        options={"xatol": 1e-10},
    )
    if found.fun < best_value:
        return float(math.exp(found.x)), float(found.fun)
    return best_x, best_value


@dataclass(frozen=True)
class StiffnessSweep:
    """Impulse over mechanical stiffness for force- and position-threshold sensing (at a fixed velocity)."""

    stiffnesses: np.ndarray
    """Mechanical stiffness ``k_m`` at the contact [N/m]."""
    force_threshold_impulse: np.ndarray
    """Impulse with a fixed force threshold [N s]."""
    position_threshold_impulse: np.ndarray
    """Impulse with a position-error threshold, ``F_s = k e_th`` [N s]."""
    force_threshold: np.ndarray
    """``F_s`` of the force-threshold scheme [N] (constant)."""
    position_threshold: np.ndarray
    """``F_s = k e_th`` of the position-threshold scheme [N]."""
    assumptions: dict[str, Any] = field(default_factory=dict)
    """Every setting used, including the assumptions the paper does not state."""

    def table(self) -> pd.DataFrame:
        """One row per stiffness, SI units in the headers (pandas DataFrame)."""
        import pandas as pd

        return pd.DataFrame(
            {
                "mechanical_stiffness_N_per_m": self.stiffnesses,
                "force_threshold_N": self.force_threshold,
                "force_threshold_impulse_N_s": self.force_threshold_impulse,
                "position_threshold_N": self.position_threshold,
                "position_threshold_impulse_N_s": self.position_threshold_impulse,
            }
        )

    def to_csv(self, path: str | os.PathLike[str]) -> Path:
        """Write :meth:`table` to ``path`` atomically, the settings as ``#`` comment lines on top."""
        return _write_csv(path, self.table(), self.assumptions)


def stiffness_sweep(
    stiffnesses: ArrayLike,
    *,
    v0: float = 0.1,
    F_s: float = SWEEP_DEFAULTS["F_s"],
    e_th: float | None = None,
    k_s: float = math.inf,
    motor: Motor | None = None,
    gear_ratio: float = 1.0,
    lever: float = SWEEP_DEFAULTS["lever"],
    m_f: float = SWEEP_DEFAULTS["m_f"],
    m_r: float = SWEEP_DEFAULTS["m_r"],
    reflected_inertia_in: str = SWEEP_DEFAULTS["reflected_inertia_in"],
    reaction: str = "at_rest",
) -> StiffnessSweep:
    """Impulse over mechanical stiffness for two sensing schemes (``fig:stiff-sensing-impulse``).

    Parameters
    ----------
    stiffnesses: mechanical stiffnesses ``k_m`` at the contact [N/m], > 0 (1D array).
    v0: approach velocity [m/s].
    F_s: force threshold [N] of the force-threshold scheme.
    e_th: position-error threshold at the contact [m]; default ``F_s / k`` at the geometric middle of the swept
        stiffnesses, so that both schemes detect at the same force there.
    k_s: software stiffness at the contact [N/m]; default ``inf`` (rigid), so that the swept stiffness is the
        whole joint's, as the paper's figure varies a single stiffness.
    motor: the motor (default the Omni+ reference), with ``gear_ratio``.
    lever, m_f, m_r, reflected_inertia_in: as :func:`radius_velocity_sweep`.
    reaction: reaction model of :func:`collision_reflex.model.phase_impulses`.
    """
    stiffnesses = _grid("stiffnesses", stiffnesses)
    for name, value in (("v0", v0), ("F_s", F_s), ("lever", lever)):
        _validate.positive(name, value)
    _validate.positive("k_s", k_s, allow_inf=True)
    _validate.choice("reaction", reaction, REACTION_MODES)
    motor = motor if motor is not None else reference_motor()
    middle = float(np.sqrt(stiffnesses[0] * stiffnesses[-1]))
    if e_th is None:
        e_th = F_s / series_stiffness(middle, k_s)
    _validate.positive("e_th", e_th)

    def impulse(k_m: float, sensing: ForceThreshold | PositionThreshold) -> tuple[float, float]:
        actuator = _contact_actuator(motor, gear_ratio, k_m, k_s, lever, sensing)
        contact = actuator.contact_parameters(lever, m_f, m_r, reflected_inertia_in)
        total = phase_impulses(**contact.impulse_arguments(), v0=v0, reaction=reaction).total
        return float(total), contact.F_s

    # The joint position error is the contact error over the lever (small angles).
    force = [impulse(float(k), ForceThreshold(F_s)) for k in stiffnesses]
    position = [impulse(float(k), PositionThreshold(e_th / lever)) for k in stiffnesses]
    assumptions = {
        "motor": motor.name,
        "gear ratio": gear_ratio,
        "approach velocity [m/s]": v0,
        "force threshold F_s [N]": F_s,
        "position-error threshold e_th at the contact [m]": e_th,
        "software stiffness k_s at the contact [N/m]": k_s,
        "lever L [m] (assumed: the paper's 1D experiment length)": lever,
        "finger mass [kg] (assumed: the paper's one-shot fit of the U8)": m_f,
        "extra robot mass [kg] (assumed)": m_r,
        "reflected inertia in (assumed, see docs)": reflected_inertia_in,
        "reaction": reaction,
    }
    return StiffnessSweep(
        stiffnesses=stiffnesses,
        force_threshold_impulse=np.array([f[0] for f in force]),
        position_threshold_impulse=np.array([p[0] for p in position]),
        force_threshold=np.array([f[1] for f in force]),
        position_threshold=np.array([p[1] for p in position]),
        assumptions=assumptions,
    )


def _write_csv(path: str | os.PathLike[str], table: pd.DataFrame, assumptions: dict[str, Any]) -> Path:
    """Write ``table`` (a pandas DataFrame) to a ``.csv`` path atomically, ``assumptions`` as ``#`` lines."""
    if Path(path).suffix.lower() != ".csv":
        raise InvalidParameter("CSV file", str(path), "a name ending in .csv")
    with atomic_open(path, "w", newline="") as handle:
        for key, value in assumptions.items():
            handle.write(f"# {key}: {value}\n")
        table.to_csv(handle, index=False, float_format="%.9g")
    return Path(path)


def _grid(name: str, values: ArrayLike) -> np.ndarray:
    """A sorted 1D float array of positive finite values, or InvalidParameter."""
    _validate.positive(name, values)
    array = np.atleast_1d(np.asarray(values, dtype=float))
    if array.ndim != 1 or array.size == 0:
        raise InvalidParameter(name, values, "a non-empty 1D sequence of numbers > 0")
    return np.sort(array)
