"""Pareto front of saved design records (objective values as arrays, as read back from a run's results)."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np

from . import FigurePath, new_figure, save_figure


def plot_design_front(
    path: FigurePath,
    names: Sequence[str],
    units: Sequence[str],
    values: np.ndarray,
    chosen: Sequence[float] | None = None,
    recommended: Sequence[float] | None = None,
) -> Path:
    """Draw a front of 2 objectives (line through the points) or 3 (scatter coloured by the third).

    values: (n_points, len(names)) objective values in ``units``; chosen: the chosen design's values (the
    single-objective optimum as solved), marked; recommended: the recommended design's values, circled.
    """
    values = np.asarray(values, dtype=float)
    labels = [f"{name.replace('_', ' ')} [{unit}]" for name, unit in zip(names, units, strict=True)]
    fig, ax = new_figure(figsize=(6.0, 4.2))
    if values.shape[1] == 2:
        order = np.argsort(values[:, 0])
        ax.plot(values[order, 0], values[order, 1], "-o", ms=4, label="Pareto designs")
    else:
        scatter = ax.scatter(values[:, 0], values[:, 1], c=values[:, 2], cmap="viridis", s=25)
        fig.colorbar(scatter, ax=ax, label=labels[2])
    for index, (x, y) in enumerate(values[:, :2]):
        ax.annotate(str(index), (x, y), textcoords="offset points", xytext=(4, 4), fontsize=7)
    if chosen is not None:
        ax.plot([chosen[0]], [chosen[1]], "*", ms=12, color="tab:red", label="single-objective optimum")
    if recommended is not None:
        ax.plot(
            [recommended[0]],
            [recommended[1]],
            "o",
            ms=14,
            mfc="none",
            mew=1.8,
            color="tab:green",
            label="recommended design",
        )
    ax.set_xlabel(labels[0])
    ax.set_ylabel(labels[1])
    ax.set_title(f"Pareto front: {values.shape[0]} designs", fontsize=10)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    return save_figure(fig, path)
