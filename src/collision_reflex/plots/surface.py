"""Collision-reflex surfaces of planar and spatial arms.

For planar arms, the paper's ``fig:two_link`` grid: polar impulse surfaces drawn around the contact point, the
arm under each. For spatial arms, a 3D surface with orthogonal sections.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..arm.directions import coordinate_plane
from ..arm.surfaces import ReflexSurface
from . import new_figure, save_figure

# Impulses above this multiple of the grid's median are drawn clipped (singular directions are infinite).
_CLIP_FACTOR = 4.0


@dataclass(frozen=True)
class SurfaceRow:
    """One row of the grid: a title and one surface per column with its label."""

    title: str
    surfaces: Sequence[ReflexSurface]
    labels: Sequence[str]


def plot_planar_grid(path: str | os.PathLike[str], rows: Sequence[SurfaceRow], title: str = "") -> Path:
    """Draw rows of planar reflex surfaces, each around its contact point with the arm drawn under it.

    One length scale [m per N s] serves the whole figure so that cells compare; impulses beyond
    ``4 x`` the median are clipped (the rim is dashed there) and singular directions are marked.
    """
    surfaces = [s for row in rows for s in row.surfaces]
    finite = np.concatenate([s.impulse[np.isfinite(s.impulse)] for s in surfaces])
    cap = _CLIP_FACTOR * float(np.median(finite))
    reach = max(float(np.max(np.linalg.norm(s.to_plane(s.contact_position), axis=-1))) for s in surfaces)
    scale = 0.45 * reach / cap  # the largest drawn radius is 45 % of the arm's reach
    columns = max(len(row.surfaces) for row in rows)
    fig, axes = new_figure(len(rows), columns, figsize=(3.0 * columns, 3.0 * len(rows)), squeeze=False)
    for r, row in enumerate(rows):
        for c in range(columns):
            ax = axes[r][c]
            ax.set_axis_off()
            if c >= len(row.surfaces):
                continue
            _draw_planar_cell(ax, row.surfaces[c], scale, cap)
            ax.set_title(row.labels[c], fontsize=9)
        axes[r][0].text(
            -0.08,
            0.5,
            row.title,
            transform=axes[r][0].transAxes,
            rotation=90,
            va="center",
            ha="right",
            fontsize=10,
        )
    _equal_limits([ax for row_axes in axes for ax in row_axes if ax.has_data()])
    scale_bar = round(cap / 4, 2) or cap / 4
    fig.suptitle(
        (title + "\n" if title else "")
        + f"collision impulse I(u) drawn from the contact point: {scale_bar:g} N·s = {scale * scale_bar * 100:.3g} cm;"
        " dashed: clipped, x: singular direction (I = inf)",
        fontsize=9,
    )
    return save_figure(fig, path)


def _draw_planar_cell(ax, surface: ReflexSurface, scale: float, cap: float) -> None:
    origin = surface.to_plane(surface.contact_position)
    chain = surface.to_plane(np.vstack([surface.joint_positions, surface.contact_position]))
    ax.plot(chain[:, 0], chain[:, 1], "-", color="0.35", lw=3, solid_capstyle="round", zorder=1)
    ax.plot(chain[:-1, 0], chain[:-1, 1], "o", color="0.15", ms=5, zorder=2)
    ax.plot(*origin, "o", color="tab:red", ms=3, zorder=3)
    order = np.argsort(np.arctan2(surface.directions[:, 1], surface.directions[:, 0]))
    points = origin + surface.points(scale, cap)[order]
    points = np.vstack([points, points[:1]])
    clipped = np.append(surface.impulse[order] >= cap, surface.impulse[order][0] >= cap)
    ax.plot(points[:, 0], points[:, 1], "-", color="tab:blue", lw=1.3, zorder=4)
    if np.any(clipped):
        ax.plot(
            np.where(clipped, points[:, 0], np.nan),
            np.where(clipped, points[:, 1], np.nan),
            "--",
            color="white",
            lw=1.0,
            zorder=5,
        )
    singular = surface.parameters.singular
    if np.any(singular):
        tips = origin + surface.points(scale, cap)[singular]
        ax.plot(tips[:, 0], tips[:, 1], "x", color="tab:red", ms=6, zorder=6)
    ax.fill(points[:, 0], points[:, 1], color="tab:blue", alpha=0.12, zorder=0)
    finite = surface.impulse[np.isfinite(surface.impulse)]
    ax.text(
        0.02,
        0.02,
        f"I: {finite.min():.3g}–{finite.max():.3g} N·s" + (" (inf)" if np.any(singular) else ""),
        transform=ax.transAxes,
        fontsize=7,
        color="0.3",
    )
    ax.set_aspect("equal")


def _equal_limits(axes: list) -> None:
    """The same x and y span on every cell, so that lengths compare across the grid."""
    spans = [(ax.get_xlim(), ax.get_ylim()) for ax in axes]
    half = max(max(x[1] - x[0], y[1] - y[0]) for x, y in spans) / 2
    for ax, (x, y) in zip(axes, spans, strict=True):
        cx, cy = sum(x) / 2, sum(y) / 2
        ax.set_xlim(cx - half, cx + half)
        ax.set_ylim(cy - half, cy + half)


def plot_spatial_surface(
    path: str | os.PathLike[str], sphere: ReflexSurface, sections: dict[str, ReflexSurface], title: str = ""
) -> Path:
    """A 3D reflex surface (directions on the sphere), and polar sections in orthogonal planes.

    ``sections`` maps a coordinate plane (``"x-y"``, ``"x-z"``, ``"y-z"``) to a surface whose directions lie in
    that plane. The surface is ``I(u) u`` around the contact point, coloured by the impulse; impulses beyond
    ``4 x`` the median are clipped.
    """
    import matplotlib as mpl
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection
    from scipy.spatial import ConvexHull

    finite = sphere.impulse[np.isfinite(sphere.impulse)]
    cap = _CLIP_FACTOR * float(np.median(finite))
    fig, axes = new_figure(2, 2, figsize=(10, 9))
    axes[0][0].remove()
    ax3d = fig.add_subplot(2, 2, 1, projection="3d")
    radius = np.minimum(sphere.impulse, cap)
    points = sphere.directions * radius[:, None]
    triangles = ConvexHull(sphere.directions).simplices  # a triangulation of the sphere of directions
    norm = mpl.colors.Normalize(vmin=float(radius.min()), vmax=float(radius.max()))
    colours = mpl.colormaps["viridis"](norm(radius[triangles].mean(axis=1)))
    ax3d.add_collection3d(
        Poly3DCollection(points[triangles], facecolors=colours, edgecolor="none", alpha=0.95)
    )
    span = float(radius.max())
    for setter in (ax3d.set_xlim, ax3d.set_ylim, ax3d.set_zlim):
        setter(-span, span)
    ax3d.set_box_aspect((1, 1, 1))
    ax3d.set_xlabel("x [N·s]")
    ax3d.set_ylabel("y [N·s]")
    ax3d.set_zlabel("z [N·s]")
    ax3d.set_title("I(u) u over the sphere of directions", fontsize=9)
    fig.colorbar(
        mpl.cm.ScalarMappable(norm=norm, cmap="viridis"), ax=ax3d, shrink=0.6, pad=0.12, label="impulse [N·s]"
    )
    section_axes = [axes[0][1], axes[1][0], axes[1][1]]
    extent = 0.0
    for ax, (name, section) in zip(section_axes, sections.items(), strict=False):
        first, second = name.split("-")
        planar = section.directions @ coordinate_plane(name)
        order = np.argsort(np.arctan2(planar[:, 1], planar[:, 0]))
        values = np.minimum(section.impulse, cap)[order]
        xy = planar[order] * values[:, None]
        xy = np.vstack([xy, xy[:1]])
        extent = max(extent, float(np.abs(xy).max()))
        ax.plot(xy[:, 0], xy[:, 1], color="tab:blue")
        ax.fill(xy[:, 0], xy[:, 1], color="tab:blue", alpha=0.12)
        ax.plot(0, 0, "o", color="tab:red", ms=3)
        ax.set_xlabel(f"{first} [N·s]")
        ax.set_ylabel(f"{second} [N·s]")
        finite_section = section.impulse[np.isfinite(section.impulse)]
        singular = int(section.parameters.singular.sum())
        ax.set_title(
            f"{name} section: {finite_section.min():.3g}–{finite_section.max():.3g} N·s"
            + (f", {singular} singular" if singular else ""),
            fontsize=9,
        )
        ax.grid(alpha=0.3)
    for ax in section_axes[: len(sections)]:
        ax.set_xlim(-1.05 * extent, 1.05 * extent)
        ax.set_ylim(-1.05 * extent, 1.05 * extent)
        ax.set_aspect("equal")
    for ax in section_axes[len(sections) :]:
        ax.set_axis_off()
    fig.suptitle(title or f"collision-reflex surface of {sphere.arm_name}", fontsize=10)
    return save_figure(fig, path)
