"""Pareto front of actuator designs."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import numpy as np

from . import new_figure, save_figure


def plot_pareto(pareto: Any, path: str | os.PathLike[str]) -> Path:
    """Draw a :class:`collision_reflex.optimize.ParetoSet`: 2 objectives as a front line with the anchors
    marked, 3 as a scatter of the first two coloured by the third.
    """
    from ..optimize.problem import OBJECTIVES

    values = pareto.values()
    labels = [f"{name.replace('_', ' ')} [{OBJECTIVES[name][1]}]" for name in pareto.objectives]
    fig, ax = new_figure(figsize=(6, 4.2))
    if values.shape[1] == 2:
        order = np.argsort(values[:, 0])
        ax.plot(values[order, 0], values[order, 1], "-o", color="tab:blue", ms=4, label="Pareto designs")
        ax.plot(
            values[order[[0, -1]], 0],
            values[order[[0, -1]], 1],
            "s",
            color="tab:orange",
            ms=7,
            label="anchors",
        )
        ax.legend(fontsize=8)
    else:
        scatter = ax.scatter(values[:, 0], values[:, 1], c=values[:, 2], cmap="viridis", s=25)
        fig.colorbar(scatter, ax=ax, label=labels[2])
    ax.set_xlabel(labels[0])
    ax.set_ylabel(labels[1])
    ax.set_title(f"Pareto front: {len(pareto.points)} designs")
    ax.grid(True, alpha=0.3)
    return save_figure(fig, path)
