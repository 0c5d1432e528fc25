"""Phase breakdown of collision impulses: impact, sensing and reaction as stacked bars.

There is one bar per design or actuator.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np

from . import FigurePath, new_figure, save_figure

PHASES = (("initial", "I impact"), ("sensing", "II sensing"), ("reaction", "III reaction"))


def plot_phase_breakdown(
    path: FigurePath,
    labels: Sequence[str],
    initial: Sequence[float],
    sensing: Sequence[float],
    reaction: Sequence[float],
    title: str = "",
) -> Path:
    """Stacked bars of the three phase impulses [N*s] for each label."""
    values = {
        "initial": np.asarray(initial, float),
        "sensing": np.asarray(sensing, float),
        "reaction": np.asarray(reaction, float),
    }
    fig, ax = new_figure(figsize=(max(4.5, 0.55 * len(labels) + 2.5), 3.8))
    position = np.arange(len(labels))
    bottom = np.zeros(len(labels))
    for key, name in PHASES:
        ax.bar(position, values[key], bottom=bottom, label=name, width=0.7)
        bottom += values[key]
    ax.set_xticks(
        position,
        list(labels),
        rotation=45 if len(labels) > 4 else 0,
        ha="right" if len(labels) > 4 else "center",
        fontsize=8,
    )
    ax.set_ylabel("impulse [N*s]")
    ax.set_title(title or "impulse by phase", fontsize=10)
    ax.legend(fontsize=8)
    ax.grid(True, axis="y", alpha=0.3)
    return save_figure(fig, path)
