"""The pose and contact direction of a design's worst case over its contact domain."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from . import FigurePath, new_figure, save_figure


def plot_worst_pose(
    path: FigurePath,
    joint_positions: np.ndarray,
    contact_position: np.ndarray,
    direction: np.ndarray,
    title: str,
) -> Path:
    """Draw the arm as the chain of its joint origins [m] to the contact point, and the contact direction.

    Three views (top, front, side) of world positions: joints (nv, 3), the contact point (3,); the direction
    (3,) is a unit vector, drawn as an arrow a quarter of the arm's extent long from the contact point.
    """
    chain = np.vstack([np.zeros(3), np.asarray(joint_positions, dtype=float), contact_position])
    extent = float(np.max(np.linalg.norm(chain - chain[0], axis=1))) or 1.0
    arrow = 0.25 * extent * np.asarray(direction, dtype=float)
    fig, axes = new_figure(1, 3, figsize=(9.0, 3.3))
    for ax, (a, b), name in zip(
        axes, ((0, 1), (0, 2), (1, 2)), ("top (x, y)", "front (x, z)", "side (y, z)"), strict=True
    ):
        ax.plot(chain[:, a], chain[:, b], "-", color="0.35", lw=3, solid_capstyle="round")
        ax.plot(chain[1:-1, a], chain[1:-1, b], "o", color="0.15", ms=4)
        ax.plot(chain[:1, a], chain[:1, b], "s", color="0.15", ms=6)
        ax.annotate(
            "",
            xy=(contact_position[a] + arrow[a], contact_position[b] + arrow[b]),
            xytext=(contact_position[a], contact_position[b]),
            arrowprops={"arrowstyle": "->", "color": "tab:red", "lw": 1.8},
        )
        ax.plot(contact_position[a], contact_position[b], "o", color="tab:red", ms=4)
        ax.set_aspect("equal", adjustable="datalim")
        ax.set_title(name, fontsize=9)
        ax.set_xlabel("xyz"[a] + " [m]")
        ax.set_ylabel("xyz"[b] + " [m]")
        ax.grid(alpha=0.3)
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    return save_figure(fig, path)
