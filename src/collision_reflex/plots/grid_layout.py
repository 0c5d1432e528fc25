"""Layout of a grid of subplots computed from the sizes of the texts around them, without drawing.

``tight_layout`` finds a grid's margins by measuring every element of every subplot, each tick label of each
axis included, which costs about as much as drawing the figure; cropping the saved file to its tight bounding
box measures them all again. Around the subplots of a grid such as the torque-speed figure's there are only
texts whose sizes are known before drawing: a title at a fixed offset above each subplot (room for a top axis
is part of that offset), x tick labels and an x label below, y tick labels and a y label to the left, the
figure's title above the grid and optionally a legend below it. The margins are sums of those sizes; only the
y tick labels are formatted to be measured (their width depends on the data). Everything is placed inside the
figure, so the figure is saved whole, without a tight bounding box.
"""

from __future__ import annotations

import functools
from collections.abc import Sequence
from typing import Any

SPACE = 10.8  # pt between neighbouring texts and subplots: tight_layout's default pad (1.08 font sizes)
EDGE = 7.2  # pt of empty margin at the figure's edges, as a tight crop leaves (savefig.pad_inches 0.1 in)
# A tick label centred on the last tick may reach past the subplot's right edge by half its width: room for
# labels of up to this many digits (larger numbers are written with an offset or in scientific notation).
TICK_LABEL_DIGITS = 6


def lay_out_grid(
    fig: Any,
    axes: Sequence[Any],
    shape: tuple[int, int],
    cell: tuple[float, float],
    title_pad: float,
    suptitle: Any,
    legend_below: Any | None = None,
) -> None:
    """Place a grid's subplots, the figure's title and a legend below the grid; size the figure to fit them.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        The figure, its subplots made by ``subplots``.
    axes : sequence of matplotlib.axes.Axes
        The subplots drawn (the grid's empty cells excluded), their limits, labels and titles set.
    shape : tuple of int
        Rows and columns of the grid.
    cell : tuple of float
        Width and height of a grid cell [in]. The figure is wider only where its title, the legend or the
        subplots' titles need it, and taller by the legend below the grid.
    title_pad : float
        Offset of each subplot's title above its subplot [pt] (the ``pad`` it was set with).
    suptitle : matplotlib.text.Text
        The figure's title (from ``suptitle``), placed at the top edge.
    legend_below : matplotlib.legend.Legend, optional
        A figure legend made with ``loc="lower center"``, placed below the grid.
    """
    from matplotlib import rcParams

    rows, columns = shape
    size = functools.partial(extent, fig)  # of an artist, or of a string at a font size [pt]

    heading = size(suptitle)
    legend = (
        (size(legend_below)[0], size(legend_below)[1] + SPACE) if legend_below is not None else (0.0, 0.0)
    )

    # Vertically [pt]: the figure's title, then per row the subplot's title, the subplot, its x axis below.
    above = title_pad + max(size(ax.title)[1] for ax in axes)
    below = (
        rcParams["xtick.major.size"]
        + rcParams["xtick.major.pad"]
        + size("0123456789", rcParams["xtick.labelsize"])[1]
        + rcParams["axes.labelpad"]
        + max(size(ax.xaxis.label)[1] for ax in axes)
    )
    height = rows * cell[1] * 72 + legend[1]
    top = EDGE + heading[1] + SPACE + above
    bottom = EDGE + legend[1] + below
    gap = below + SPACE + above
    axes_height = (height - top - bottom - (rows - 1) * gap) / rows
    # The y tick labels depend on the subplots' height (how many ticks fit): placed vertically first.
    fig.set_size_inches(fig.get_size_inches()[0], height / 72)
    fig.subplots_adjust(bottom=bottom / height, top=1 - top / height, hspace=gap / axes_height)

    # Horizontally [pt]: per column the y label and tick labels, the subplot, the last x tick label's half.
    left_of = (
        max(size(ax.yaxis.label)[0] for ax in axes)
        + rcParams["axes.labelpad"]
        + max(_widest_y_tick_label(ax, size) for ax in axes)
        + rcParams["ytick.major.pad"]
        + rcParams["ytick.major.size"]
    )
    right_of = size("0" * TICK_LABEL_DIGITS, rcParams["xtick.labelsize"])[0] / 2
    nominal = columns * cell[0] * 72 - 2 * EDGE - (columns - 1) * SPACE
    axes_width = nominal / columns - left_of - right_of
    # A title wider than its subplot reaches as far into the margins on either side (centred).
    reach = max(0.0, (max(size(ax.title)[0] for ax in axes) - axes_width) / 2)
    left, right = max(left_of, reach), max(right_of, reach)
    gap = max(left_of + right_of, 2 * reach) + SPACE
    grid = left + columns * axes_width + (columns - 1) * gap + right
    width = max(grid, heading[0], legend[0]) + 2 * EDGE
    start = (width - grid) / 2 + left
    fig.set_size_inches(width / 72, height / 72)
    fig.subplots_adjust(
        left=start / width,
        right=(start + columns * axes_width + (columns - 1) * gap) / width,
        wspace=gap / axes_width,
    )
    suptitle.set_y(1 - EDGE / height)
    suptitle.set_verticalalignment("top")
    if legend_below is not None:
        legend_below.set_bbox_to_anchor((0.5, EDGE / height), transform=fig.transFigure)


def _widest_y_tick_label(ax: Any, size: Any) -> float:
    """Width [pt] of the widest major y tick label ``ax`` draws at its present limits and height."""
    from matplotlib import rcParams

    labels = ax.yaxis.get_major_formatter().format_ticks(ax.yaxis.get_majorticklocs())
    return max((size(label, rcParams["ytick.labelsize"])[0] for label in labels), default=0.0)


def extent(fig: Any, artist: Any, fontsize: Any = None) -> tuple[float, float]:
    """Width and height [pt] of ``artist`` (a text, a legend) of ``fig``, or of a string at ``fontsize``."""
    from matplotlib.text import Text

    if isinstance(artist, str):
        artist = Text(0, 0, artist, fontsize=fontsize)
        artist.set_figure(fig)
    box = artist.get_window_extent(fig.canvas.get_renderer())
    return box.width * 72 / fig.dpi, box.height * 72 / fig.dpi
