"""Figures of the 1D actuator design sweeps.

Impulse over motor diameter x velocity (the paper's ``fig:motor_scale_modeling``) and over mechanical
stiffness per sensing scheme (``fig:stiff-sensing-impulse``).
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from ..errors import InvalidParameter
from ..hardware.sweeps import RadiusVelocitySweep, StiffnessSweep
from . import check_figure_path, new_figure, save_figure


def plot_radius_velocity(sweep: RadiusVelocitySweep, path: str | os.PathLike[str]) -> Path:
    """Heat map of the impulse on log axes (diameter in mm, velocity in m/s), with contour lines.

    The per-diameter optimal velocity ``v*`` and the overall optimum are marked.
    """
    from matplotlib.colors import LogNorm

    check_figure_path(path)
    check_heat_map_grid(sweep.diameters.size, sweep.velocities.size)
    fig, ax = new_figure(figsize=(7, 4.8))
    diameters_mm = sweep.diameters * 1e3
    impulse = sweep.impulse.T  # rows: velocity, columns: diameter
    norm = LogNorm(vmin=float(np.min(impulse)), vmax=float(np.max(impulse)))
    mesh = ax.pcolormesh(
        diameters_mm, sweep.velocities, impulse, norm=norm, cmap="viridis", shading="gouraud"
    )
    # Contour lines label the heat map's levels.
    levels = np.geomspace(float(np.min(impulse)) * 1.05, float(np.max(impulse)), 9)
    lines = ax.contour(diameters_mm, sweep.velocities, impulse, levels=levels, colors="white", linewidths=0.6)
    ax.clabel(lines, fmt="%.3g", fontsize=7)
    ax.plot(diameters_mm, sweep.optimal_velocity, color="white", ls="--", lw=1.0, label="v*(r) (eq:v_star)")
    geared = sweep.gear_ratio > 1
    if np.any(geared) and not np.all(geared):
        # The motor that meets the torque requirement without a gearbox (N = 1 from here on).
        boundary = float(diameters_mm[np.argmin(geared)])
        ax.axvline(boundary, color="lightgray", ls=":", lw=1.0, label="N = 1 from here")
    ax.plot(
        [sweep.best_diameter * 1e3],
        [sweep.best_velocity],
        "o",
        color="tab:orange",
        markeredgecolor="black",
        markersize=9,
        label=(
            f"optimum: {sweep.best_diameter * 1e3:.3g} mm, {sweep.best_velocity:.3g} m/s, "
            f"I = {sweep.best_impulse:.3g} N·s"
        ),
    )
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlim(diameters_mm[0], diameters_mm[-1])
    ax.set_ylim(sweep.velocities[0], sweep.velocities[-1])
    ax.set_xlabel("motor stator diameter $r_m$ [mm]")
    ax.set_ylabel("approach velocity $v_0$ [m/s]")
    ax.set_title("Collision impulse over motor size and approach velocity")
    fig.colorbar(mesh, ax=ax, label="impulse [N·s]")
    ax.legend(loc="lower left", fontsize=7, framealpha=0.8)
    return save_figure(fig, path)


def plot_stiffness(sweep: StiffnessSweep, path: str | os.PathLike[str]) -> Path:
    """Impulse over mechanical stiffness for force-threshold and position-threshold sensing (log-log)."""
    check_figure_path(path)
    fig, ax = new_figure(figsize=(6.5, 4))
    ax.plot(sweep.stiffnesses, sweep.force_threshold_impulse, "-o", ms=3, label="force threshold (F_s fixed)")
    ax.plot(
        sweep.stiffnesses,
        sweep.position_threshold_impulse,
        "-s",
        ms=3,
        label="position-error threshold (F_s = k e_th)",
    )
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("mechanical stiffness $k_m$ [N/m]")
    ax.set_ylabel("impulse [N·s]")
    ax.set_title("Collision impulse over stiffness, by sensing scheme")
    ax.grid(True, which="both", lw=0.3, alpha=0.5)
    ax.legend(fontsize=8)
    return save_figure(fig, path)


def check_heat_map_grid(n_diameters: int, n_velocities: int) -> None:
    """A heat map needs at least two values along each axis."""
    for name, count in (("diameters", n_diameters), ("velocities", n_velocities)):
        if count < 2:
            raise InvalidParameter(
                name, count, "at least 2 values for a heat map", "e.g. START:STOP:N with N >= 2"
            )
