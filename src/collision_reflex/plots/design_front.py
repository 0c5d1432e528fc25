"""Pareto front of saved design records (objective values as arrays, as read back from a run's results)."""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from . import FigurePath, new_figure, save_figure

FLAT_MARGIN = 0.05
"""Half-width of a flat objective's axis (or colour scale) as a fraction of its value, at least."""

POINT_ID = "front-point-{}"
"""SVG id (matplotlib ``gid``) of Pareto design ``i``'s marker: the HTML report's hover cards find it by it."""

HIT_WIDTH = 8.0
"""Width [pt] of a design marker's transparent edge: the area around the dot that still hovers it."""


def objective_span(values: np.ndarray) -> float:
    """An objective's span over the designs, (max - min) / |min|, in %.

    Against the largest magnitude where the minimum is 0; 0 where every value is 0.
    """
    values = np.asarray(values, dtype=float)
    low, high = float(values.min()), float(values.max())
    scale = abs(low) or float(np.abs(values).max())
    return 0.0 if scale == 0 else 100.0 * (high - low) / scale


def flat_limits(values: np.ndarray, marks: Sequence[float] = ()) -> tuple[float, float]:
    """Limits of a flat objective's axis: centred on its values, ±:data:`FLAT_MARGIN` of their magnitude at least.

    Widened (still centred) to keep ``marks`` (the chosen or recommended design) in view.
    """
    values = np.asarray(values, dtype=float)
    centre = 0.5 * (float(values.min()) + float(values.max()))
    half = max(
        FLAT_MARGIN * abs(centre),
        0.55 * float(values.max() - values.min()),
        *(1.1 * abs(float(mark) - centre) for mark in marks),
    )
    if half == 0:  # all zero: no magnitude to take a fraction of
        half = 1.0
    return centre - half, centre + half


def _flat_note(span: float) -> str:
    """The label's note on a flat objective: its span [%] to 2 significant digits, without an exponent."""
    if span == 0:
        return "flat: all designs within 0 %"
    rounded = float(f"{span:.2g}")
    decimals = max(0, 1 - math.floor(math.log10(rounded)))
    return f"flat: all designs within {rounded:.{decimals}f} %"


def _draw_designs(ax: Any, values: np.ndarray, colours: Sequence[Any]) -> None:
    """One marker per design, numbered, with the SVG id :data:`POINT_ID` (see :func:`plot_design_front`)."""
    for index, ((x, y), point_colour) in enumerate(zip(values[:, :2], colours, strict=True)):
        # One artist per design: matplotlib writes it as its own <g id="front-point-i"> in the SVG.
        # Above the chosen star and the recommended ring, so that they do not hide it from the pointer; a wide
        # transparent edge makes it easier to hover (the dot looks as a marker of its edge's size would).
        ax.plot(
            [x],
            [y],
            "o",
            ms=5 if values.shape[1] == 2 else 6,
            mfc=point_colour,
            mec=(0.0, 0.0, 0.0, 0.0),
            mew=HIT_WIDTH,
            zorder=3,
            gid=POINT_ID.format(index),
        )
        ax.annotate(str(index), (x, y), textcoords="offset points", xytext=(4, 4), fontsize=7)


def plot_design_front(
    path: FigurePath,
    names: Sequence[str],
    units: Sequence[str],
    values: np.ndarray,
    chosen: Sequence[float] | None = None,
    recommended: Sequence[float] | None = None,
    flat_span: float = 1.0,
) -> Path:
    """Draw a front of 2 objectives (line through the points) or 3 (scatter coloured by the third).

    Each design's marker is its own artist with the SVG id ``front-point-{i}`` (:data:`POINT_ID`, ``i`` its
    row of ``values``: its Pareto design number), for the HTML report's hover cards.

    An objective whose span over the designs (:func:`objective_span`) is below ``flat_span`` is flat: its axis
    (or colour scale) is not stretched to the span but centred on the values at ±5 % of them at least
    (:func:`flat_limits`), and its label says how flat it is, so that numerical noise does not look like a
    trade-off.

    Parameters
    ----------
    path
        Figure file(s).
    names, units
        The objectives' names and units, one per column of ``values``.
    values
        (n_points, len(names)) objective values in ``units``.
    chosen
        The chosen design's values (the single-objective optimum as solved), marked with a star.
    recommended
        The recommended design's values, circled.
    flat_span
        Span [%] below which an objective is drawn flat.

    Returns
    -------
    Path
        The first figure file.
    """
    import matplotlib  # lazy: matplotlib
    from matplotlib.lines import Line2D

    values = np.asarray(values, dtype=float)
    labels = [f"{name.replace('_', ' ')} [{unit}]" for name, unit in zip(names, units, strict=True)]
    spans = [objective_span(values[:, k]) for k in range(values.shape[1])]
    flat = [span < flat_span for span in spans]
    labels = [
        f"{label}\n{_flat_note(span)}" if is_flat else label
        for label, span, is_flat in zip(labels, spans, flat, strict=True)
    ]
    fig, ax = new_figure(figsize=(6.0, 4.2))
    colour = "tab:blue"
    handles: list[Any] = []
    if values.shape[1] == 2:
        order = np.argsort(values[:, 0])
        ax.plot(values[order, 0], values[order, 1], "-", color=colour)
        colours = [colour] * len(values)
        handles.append(Line2D([], [], color=colour, marker="o", ms=4, label="Pareto designs"))
    else:
        norm = matplotlib.colors.Normalize(
            *(flat_limits(values[:, 2]) if flat[2] else (values[:, 2].min(), values[:, 2].max()))
        )
        cmap = matplotlib.colormaps["viridis"]
        colours = [cmap(norm(z)) for z in values[:, 2]]
        fig.colorbar(matplotlib.cm.ScalarMappable(norm=norm, cmap=cmap), ax=ax, label=labels[2])
    _draw_designs(ax, values, colours)
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
    marks = [mark for mark in (chosen, recommended) if mark is not None]
    if flat[0]:
        ax.set_xlim(*flat_limits(values[:, 0], [mark[0] for mark in marks]))
    if flat[1]:
        ax.set_ylim(*flat_limits(values[:, 1], [mark[1] for mark in marks]))
    ax.set_xlabel(labels[0])
    ax.set_ylabel(labels[1])
    count = values.shape[0]
    ax.set_title(f"Pareto front: {count} design{'' if count == 1 else 's'}", fontsize=10)
    ax.grid(True, alpha=0.3)
    handles += ax.get_legend_handles_labels()[0]
    if handles:
        ax.legend(handles=handles, fontsize=8)
    return save_figure(fig, path)
