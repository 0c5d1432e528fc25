"""Measured impulse against pre-impact velocity, per system, with the fitted ``I(v)`` and ``v*``.

This is the paper's ``fig:1d_experiment_nshot``, on a log impulse axis.
"""

from __future__ import annotations

import math
import os
from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from . import new_figure, save_figure

if TYPE_CHECKING:
    from ..experiments.analysis import ExperimentResults
    from ..experiments.nshot import VelocityLawFit


def plot_impulse_velocity(
    path: str | os.PathLike[str], results: ExperimentResults, fits: Mapping[str, VelocityLawFit] | None = None
) -> Path:
    """One colour per system: measured impulses with error bars, the fitted ``A v + B/v + C`` and ``v*``.

    ``v*`` is marked when inside the plotted range. ``fits`` defaults to
    :meth:`ExperimentResults.velocity_laws`.
    """
    if fits is None:
        fits, _ = results.velocity_laws()
    fig, ax = new_figure(figsize=(6, 4))
    colours = iter(["tab:blue", "tab:orange", "tab:green", "tab:red", "tab:purple", "tab:brown", "tab:pink"])
    for system in results.systems:
        trials = [t for t in results.trials if t.trace.system == system and t.trace.v0 is not None]
        if not trials:
            continue
        colour = next(colours, "black")
        v = np.array([t.trace.v0 for t in trials], dtype=float)
        impulse = np.array([t.impulse.value for t in trials])
        error = np.array([t.impulse.uncertainty for t in trials])
        ax.errorbar(v * 1e3, impulse, yerr=error, fmt="o", ms=4, color=colour, label=system or "trials")
        fit = fits.get(system)
        if fit is None:
            continue
        grid = np.geomspace(v.min() / 1.5, v.max() * 1.5, 200)
        ax.plot(grid * 1e3, fit.impulse(grid), color=colour, lw=1.2, label=f"{system}: A v + B/v + C")
        if math.isfinite(fit.v_star) and grid[0] <= fit.v_star <= grid[-1]:
            ax.axvline(fit.v_star * 1e3, color=colour, ls=":", lw=1)
            ax.annotate(
                f"v* = {fit.v_star * 1e3:.3g} mm/s",
                (fit.v_star * 1e3, fit.minimum_impulse),
                xytext=(4, 4),
                textcoords="offset points",
                fontsize=7,
                color=colour,
            )
        elif math.isfinite(fit.v_star):
            ax.plot([], [], " ", label=f"{system}: v* = {fit.v_star * 1e3:.3g} mm/s (off the plot)")
    ax.set_yscale("log")
    ax.set_xlabel("pre-impact velocity [mm/s]")
    ax.set_ylabel("impulse [N·s]")
    ax.set_title("Collision reflex against velocity")
    ax.legend(fontsize=7)
    return save_figure(fig, path)
