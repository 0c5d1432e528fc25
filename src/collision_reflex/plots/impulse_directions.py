"""Collision impulse by contact direction: the collision-reflex surface of one design.

It is drawn over sampled configurations: a polar curve per configuration for a planar arm, a direction map for
a spatial one.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from . import FigurePath, new_figure, save_figure


def plot_impulse_directions(
    path: FigurePath,
    directions: np.ndarray,
    config_index: np.ndarray,
    impulses: np.ndarray,
    title: str = "",
) -> Path:
    """Draw impulses [N*s] per sample.

    directions: (n_samples, 2 or 3) unit contact directions; config_index: (n_samples,) configuration of each
    sample; impulses: (n_samples,) impulse per sample.
    """
    directions = np.asarray(directions, dtype=float)
    config_index = np.asarray(config_index, dtype=int)
    impulses = np.asarray(impulses, dtype=float)
    if directions.shape[1] == 2:
        fig, ax = new_figure(figsize=(5.2, 4.6), subplot_kw={"projection": "polar"})
        angles = np.arctan2(directions[:, 1], directions[:, 0])
        for index in np.unique(config_index):
            chosen = config_index == index
            order = np.argsort(angles[chosen])
            theta = np.append(angles[chosen][order], angles[chosen][order][0])
            radius = np.append(impulses[chosen][order], impulses[chosen][order][0])
            ax.plot(theta, radius, "-o", ms=2.5, lw=1.2, label=f"configuration {index}")
        ax.set_title(title or "impulse by contact direction [N*s]", fontsize=10)
        if np.unique(config_index).size <= 8:
            ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.05, 1.0))
        return save_figure(fig, path)
    fig, ax = new_figure(figsize=(6.4, 3.8))
    azimuth = np.degrees(np.arctan2(directions[:, 1], directions[:, 0]))
    elevation = np.degrees(np.arcsin(np.clip(directions[:, 2], -1.0, 1.0)))
    # Worst configuration per direction: the surface a designer must bound.
    keys = np.round(directions, 9)
    _, group = np.unique(keys, axis=0, return_inverse=True)
    group = np.asarray(group).ravel()
    worst = np.array([impulses[group == g].max() for g in range(group.max() + 1)])
    first = np.array([np.flatnonzero(group == g)[0] for g in range(group.max() + 1)])
    scatter = ax.scatter(azimuth[first], elevation[first], c=worst, s=60, cmap="viridis")
    fig.colorbar(scatter, ax=ax, label="worst impulse over configurations [N*s]")
    ax.set_xlabel("azimuth of the contact direction [deg]")
    ax.set_ylabel("elevation [deg]")
    ax.set_xlim(-180, 180)
    ax.set_ylim(-90, 90)
    ax.grid(True, alpha=0.3)
    ax.set_title(title or "impulse by contact direction", fontsize=10)
    return save_figure(fig, path)
