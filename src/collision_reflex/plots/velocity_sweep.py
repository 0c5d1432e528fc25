"""Collision impulse against approach velocity for several actuators, with each optimal velocity marked."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np

from . import FigurePath, new_figure, save_figure


def plot_velocity_sweep(
    path: FigurePath,
    velocities: Sequence[float],
    totals: dict[str, Sequence[float]],
    optimal: dict[str, tuple[float, float]],
) -> Path:
    """Log-log curves of impulse [N*s] over velocity [m/s]; ``optimal[name] = (v*, I*)`` marks each minimum."""
    fig, ax = new_figure(figsize=(6.0, 4.0))
    v = np.asarray(velocities, dtype=float)
    for name, total in totals.items():
        (line,) = ax.loglog(v, np.asarray(total, dtype=float), label=name)
        if name in optimal:
            v_star, i_star = optimal[name]
            ax.plot([v_star], [i_star], "o", color=line.get_color(), ms=6)
    ax.set_xlabel("approach velocity v0 [m/s]")
    ax.set_ylabel("collision impulse [N*s]")
    ax.set_title("impulse over approach velocity (dots: v*, I*)", fontsize=10)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    return save_figure(fig, path)
