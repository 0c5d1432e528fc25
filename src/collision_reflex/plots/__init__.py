"""Figures. Each module draws one kind of figure; all save through :func:`save_figure`."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any, TypeAlias

from .._io import atomic_path
from ..errors import InvalidParameter

FIGURE_FORMATS = (".png", ".svg", ".pdf")

FigurePath: TypeAlias = str | os.PathLike[str] | tuple[str | os.PathLike[str], ...]
"""A figure file, or several files of one figure (its PNG and SVG, say): the figure is drawn and laid out once."""


def margin_text(margin: float) -> str:
    """A margin ``available / required - 1`` as a designer reads it.

    ``0 %`` where the limit is met exactly, ``+25 %`` or ``−9 %`` below twice the requirement, a plain multiple
    (``3.7×``, ``838×``) above.
    """
    if margin == 0:
        return "0 %"
    ratio = 1 + margin
    if ratio >= 2:
        return f"{ratio:,.0f}×" if ratio >= 100 else f"{ratio:.3g}×"
    return f"{100 * margin:+.3g} %".replace("-", "−")


def check_figure_path(path: str | os.PathLike[str]) -> Path:
    """Return ``path`` as a Path if its suffix is a supported figure format, else raise."""
    target = Path(path)
    if target.suffix.lower() not in FIGURE_FORMATS:
        raise InvalidParameter("figure file", str(path), "a name ending in " + ", ".join(FIGURE_FORMATS))
    return target


def figure_paths(path: FigurePath) -> tuple[Path, ...]:
    """The files of a :data:`FigurePath`, each checked by :func:`check_figure_path`."""
    paths = path if isinstance(path, tuple) else (path,)
    if not paths:
        raise InvalidParameter("figure file", "no file", "at least one file name")
    return tuple(check_figure_path(p) for p in paths)


def save_figure(figure: Any, path: FigurePath, dpi: int = 150, crop: bool = True) -> Path:
    """Write a matplotlib figure atomically to each file of ``path`` (format from the suffix), close it.

    Cropped to the figure's tight bounding box, found once at ``dpi`` (a second file costs one more drawing,
    not another layout pass); ``crop=False`` saves the whole figure, for a figure laid out to fit inside it
    (no measuring pass at all). Returns the first file.
    """
    import matplotlib.pyplot as plt

    targets = figure_paths(path)
    try:
        if not crop:
            bbox = None
        elif len(targets) > 1:
            bbox = _tight_bbox(figure, dpi)
        else:
            bbox = "tight"
        for target in targets:
            with atomic_path(target) as tmp:
                figure.savefig(tmp, dpi=dpi, bbox_inches=bbox)
    finally:
        plt.close(figure)
    return targets[0]


def _tight_bbox(figure: Any, dpi: int) -> Any:
    """The bounding box [in] that ``savefig(bbox_inches="tight")`` crops to at ``dpi`` (its padding included).

    Measured with the Agg renderer at ``dpi`` as a PNG's ``savefig`` measures it, without its extra drawing
    pass: the figures are laid out before they are saved (the report's PNGs are the same pixels).
    """
    import matplotlib

    saved = figure.dpi
    figure.set_dpi(dpi)
    try:
        bbox = figure.get_tightbbox(figure.canvas.get_renderer())
    finally:
        figure.set_dpi(saved)
    return bbox.padded(matplotlib.rcParams["savefig.pad_inches"])


def new_figure(*args: Any, **kwargs: Any) -> Any:
    """``plt.subplots`` on the non-interactive Agg backend (no display is needed)."""
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    return plt.subplots(*args, **kwargs)
