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
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from .. import _validate
from .._io import atomic_open
from ..errors import InvalidParameter
from ..model.impulse import (
    REACTION_MODES,
    minimum_impulse,
    optimal_velocity,
    phase_impulses,
    series_stiffness,
)
from .actuators import (
    REFLECTED_INERTIA_PLACEMENTS,
    Actuator,
    CollisionParameters,
    ForceThreshold,
    PositionThreshold,
    gear_ratio_for,
)
from .gearboxes import Gearbox
from .motors import DEFAULT_SCALING_LAW, Motor, reference_motor, scaling_law

__all__ = [
    "SWEEP_DEFAULTS",
    "RadiusVelocitySweep",
    "StiffnessSweep",
    "radius_velocity_sweep",
    "stiffness_sweep",
]

SWEEP_DEFAULTS: dict[str, Any] = {
    "torque_required": 1.3,  # N m, tab:motor_params (the reference motor's peak torque)
    "mechanical_stiffness": 1000.0,  # N/m at the contact, fig:motor_scale_modeling
    "software_stiffness": 100.0,  # N/m at the contact, fig:motor_scale_modeling
    "threshold": 3.0,  # N, fig:motor_scale_modeling
    "lever": 0.1143,  # m: ASSUMPTION, the paper's 1D experiment's characteristic length
    "finger_mass": 0.1,  # kg: ASSUMPTION, the paper's U8 fit in tab:one_shot
    "robot_mass": 0.0,  # kg: ASSUMPTION, no unsprung mass besides the reflected inertia
    "reflected_inertia_in": "finger",  # ASSUMPTION, see the module docstring
    "law": DEFAULT_SCALING_LAW,
}


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
    finger_mass: np.ndarray
    """``m_f`` at the contact [kg]."""
    robot_mass: np.ndarray
    """``m_r`` at the contact [kg]."""
    threshold: np.ndarray
    """``F_s`` at the contact [N]."""
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

    def table(self) -> Any:
        """The grid as a long pandas DataFrame, one row per (diameter, velocity), SI units in the headers."""
        import pandas as pd

        n_v = self.velocities.size
        return pd.DataFrame(
            {
                "stator_diameter_m": np.repeat(self.diameters, n_v),
                "velocity_m_per_s": np.tile(self.velocities, self.diameters.size),
                "gear_ratio": np.repeat(self.gear_ratio, n_v),
                "reflected_inertia_kg_m2": np.repeat(self.reflected_inertia, n_v),
                "finger_mass_kg": np.repeat(self.finger_mass, n_v),
                "robot_mass_kg": np.repeat(self.robot_mass, n_v),
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
    sensing: Any,
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


def radius_velocity_sweep(
    diameters: Any,
    velocities: Any,
    *,
    reference: Motor | None = None,
    law: str = SWEEP_DEFAULTS["law"],
    torque_required: float = SWEEP_DEFAULTS["torque_required"],
    mechanical_stiffness: float = SWEEP_DEFAULTS["mechanical_stiffness"],
    software_stiffness: float = SWEEP_DEFAULTS["software_stiffness"],
    threshold: float = SWEEP_DEFAULTS["threshold"],
    lever: float = SWEEP_DEFAULTS["lever"],
    finger_mass: float = SWEEP_DEFAULTS["finger_mass"],
    robot_mass: float = SWEEP_DEFAULTS["robot_mass"],
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
    mechanical_stiffness: ``k_m`` at the contact [N/m].
    software_stiffness: ``k_s`` at the contact [N/m].
    threshold: force threshold ``F_s`` at the contact [N].
    lever: distance from the joint axis to the contact [m].
    finger_mass: link (sprung) mass at the contact [kg].
    robot_mass: unsprung mass at the contact besides the reflected inertia [kg].
    reflected_inertia_in: ``"finger"`` or ``"robot"``, see :meth:`Actuator.contact_parameters`.
    stack_length: motor stack length [m], default the reference's.
    gearbox: a real gearbox to add to every geared motor (``N > 1``), scaled to the motor's stator diameter at
        its own length and stages; its reflected inertia then counts (the paper ignores it, the default).
        Direct-drive motors get none.
    """
    reference = reference if reference is not None else reference_motor()
    diameters = _grid("diameters", diameters)
    velocities = _grid("velocities", velocities)
    law_name = scaling_law(law).name
    for name, value in (
        ("torque_required", torque_required),
        ("mechanical_stiffness", mechanical_stiffness),
        ("software_stiffness", software_stiffness),
        ("threshold", threshold),
        ("lever", lever),
    ):
        _validate.positive(name, value)
    _validate.choice("reflected_inertia_in", reflected_inertia_in, REFLECTED_INERTIA_PLACEMENTS)

    def parameters_at(diameter: float) -> tuple[CollisionParameters, float, float]:
        motor = reference.scaled(diameter, stack_length, law_name)
        gear = float(gear_ratio_for(torque_required, motor.peak_torque))
        geared_box = gearbox.scaled(diameter=diameter) if gearbox is not None and gear > 1 else None
        actuator = _contact_actuator(
            motor,
            gear,
            mechanical_stiffness,
            software_stiffness,
            lever,
            ForceThreshold(threshold),
            geared_box,
        )
        contact = actuator.contact_parameters(lever, finger_mass, robot_mass, reflected_inertia_in)
        return contact, gear, actuator.reflected_inertia

    per_diameter = [parameters_at(float(d)) for d in diameters]
    args: dict[str, Any] = {
        key: np.array([p[0].impulse_arguments()[key] for p in per_diameter])
        for key in ("m_f", "k", "k_m", "F_s", "a")
    }
    robot_masses = np.array([p[0].m_r for p in per_diameter])
    gears = np.array([p[1] for p in per_diameter])
    reflected = np.array([p[2] for p in per_diameter])
    column: dict[str, Any] = {key: value[:, None] for key, value in args.items()}
    impulse = phase_impulses(**column, v0=velocities[None, :]).total
    v_star = optimal_velocity(args["m_f"], args["k"], args["F_s"])
    i_star = minimum_impulse(**args)

    best_diameter, best_impulse = _refine_minimum(
        diameters, i_star, lambda d: _min_impulse(parameters_at(d)[0].impulse_arguments())
    )
    best_args = parameters_at(best_diameter)[0].impulse_arguments()
    best_velocity = float(optimal_velocity(best_args["m_f"], best_args["k"], best_args["F_s"]))
    assumptions = {
        "reference motor": reference.name,
        "scaling law": law_name,
        "stack length [m]": stack_length if stack_length is not None else reference.stack_length,
        "torque requirement [N m]": torque_required,
        "mechanical stiffness k_m at the contact [N/m]": mechanical_stiffness,
        "software stiffness k_s at the contact [N/m]": software_stiffness,
        "force threshold F_s [N]": threshold,
        "lever L [m] (assumed: the paper's 1D experiment length)": lever,
        "finger mass [kg] (assumed: the paper's U8 fit, tab:one_shot)": finger_mass,
        "extra robot mass [kg] (assumed)": robot_mass,
        "reflected inertia in (assumed, see docs)": reflected_inertia_in,
        "gearbox inertia": (
            "ignored, as in the paper"
            if gearbox is None
            else f"{gearbox.kind} gearbox scaled to each geared motor's diameter, from: {gearbox.source}"
        ),
        "reaction": "at_rest (the paper's)",
    }
    return RadiusVelocitySweep(
        diameters=diameters,
        velocities=velocities,
        impulse=np.asarray(impulse, dtype=float),
        gear_ratio=gears,
        reflected_inertia=reflected,
        finger_mass=args["m_f"],
        robot_mass=robot_masses,
        threshold=args["F_s"],
        optimal_velocity=np.asarray(v_star, dtype=float),
        minimum_impulse=np.asarray(i_star, dtype=float),
        best_diameter=best_diameter,
        best_velocity=best_velocity,
        best_impulse=best_impulse,
        assumptions=assumptions,
    )


def _min_impulse(args: dict[str, Any]) -> float:
    return float(minimum_impulse(**args))


def _refine_minimum(grid: np.ndarray, values: np.ndarray, function: Any) -> tuple[float, float]:
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

    def table(self) -> Any:
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
    stiffnesses: Any,
    *,
    velocity: float = 0.1,
    threshold: float = SWEEP_DEFAULTS["threshold"],
    position_error: float | None = None,
    software_stiffness: float = math.inf,
    motor: Motor | None = None,
    gear_ratio: float = 1.0,
    lever: float = SWEEP_DEFAULTS["lever"],
    finger_mass: float = SWEEP_DEFAULTS["finger_mass"],
    robot_mass: float = SWEEP_DEFAULTS["robot_mass"],
    reflected_inertia_in: str = SWEEP_DEFAULTS["reflected_inertia_in"],
    reaction: str = "at_rest",
) -> StiffnessSweep:
    """Impulse over mechanical stiffness for two sensing schemes (``fig:stiff-sensing-impulse``).

    Parameters
    ----------
    stiffnesses: mechanical stiffnesses ``k_m`` at the contact [N/m], > 0 (1D array).
    velocity: approach velocity [m/s].
    threshold: force threshold ``F_s`` [N] of the force-threshold scheme.
    position_error: position-error threshold at the contact [m]; default ``threshold / k`` at the geometric
        middle of the swept stiffnesses, so that both schemes detect at the same force there.
    software_stiffness: ``k_s`` at the contact [N/m]; default ``inf`` (rigid), so that the swept stiffness is
        the whole joint's, as the paper's figure varies a single stiffness.
    motor: the motor (default the Omni+ reference), with ``gear_ratio``.
    lever, finger_mass, robot_mass, reflected_inertia_in: as :func:`radius_velocity_sweep`.
    reaction: reaction model of :func:`collision_reflex.phase_impulses`.
    """
    stiffnesses = _grid("stiffnesses", stiffnesses)
    for name, value in (("velocity", velocity), ("threshold", threshold), ("lever", lever)):
        _validate.positive(name, value)
    _validate.positive("software_stiffness", software_stiffness, allow_inf=True)
    _validate.choice("reaction", reaction, REACTION_MODES)
    motor = motor if motor is not None else reference_motor()
    middle = float(np.sqrt(stiffnesses[0] * stiffnesses[-1]))
    if position_error is None:
        position_error = threshold / series_stiffness(middle, software_stiffness)
    _validate.positive("position_error", position_error)

    def impulse(k_m: float, sensing: Any) -> tuple[float, float]:
        actuator = _contact_actuator(motor, gear_ratio, k_m, software_stiffness, lever, sensing)
        contact = actuator.contact_parameters(lever, finger_mass, robot_mass, reflected_inertia_in)
        total = phase_impulses(**contact.impulse_arguments(), v0=velocity, reaction=reaction).total
        return float(total), contact.F_s

    # The joint position error is the contact error over the lever (small angles).
    force = [impulse(float(k), ForceThreshold(threshold)) for k in stiffnesses]
    position = [impulse(float(k), PositionThreshold(position_error / lever)) for k in stiffnesses]
    assumptions = {
        "motor": motor.name,
        "gear ratio": gear_ratio,
        "approach velocity [m/s]": velocity,
        "force threshold F_s [N]": threshold,
        "position-error threshold e_th at the contact [m]": position_error,
        "software stiffness k_s at the contact [N/m]": software_stiffness,
        "lever L [m] (assumed: the paper's 1D experiment length)": lever,
        "finger mass [kg] (assumed: the paper's U8 fit, tab:one_shot)": finger_mass,
        "extra robot mass [kg] (assumed)": robot_mass,
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


def _write_csv(path: str | os.PathLike[str], table: Any, assumptions: dict[str, Any]) -> Path:
    if Path(path).suffix.lower() != ".csv":
        raise InvalidParameter("CSV file", str(path), "a name ending in .csv")
    with atomic_open(path, "w", newline="") as handle:
        for key, value in assumptions.items():
            handle.write(f"# {key}: {value}\n")
        table.to_csv(handle, index=False, float_format="%.9g")
    return Path(path)


def _grid(name: str, values: Any) -> np.ndarray:
    """A sorted 1D float array of positive finite values, or InvalidParameter."""
    _validate.positive(name, values)
    array = np.atleast_1d(np.asarray(values, dtype=float))
    if array.ndim != 1:
        raise InvalidParameter(name, values, "a 1D sequence of numbers > 0")
    return np.sort(array)
