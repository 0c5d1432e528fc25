"""Figures. Each module draws one kind of figure; all save through :func:`save_figure`."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

from .._io import atomic_path
from ..errors import InvalidParameter

FIGURE_FORMATS = (".png", ".svg", ".pdf")


def check_figure_path(path: str | os.PathLike[str]) -> Path:
    """Return ``path`` as a Path if its suffix is a supported figure format, else raise."""
    target = Path(path)
    if target.suffix.lower() not in FIGURE_FORMATS:
        raise InvalidParameter("figure file", str(path), "a name ending in " + ", ".join(FIGURE_FORMATS))
    return target


def save_figure(figure: Any, path: str | os.PathLike[str], dpi: int = 150) -> Path:
    """Write a matplotlib figure atomically (format from the suffix) and close it."""
    import matplotlib.pyplot as plt

    target = check_figure_path(path)
    try:
        with atomic_path(target) as tmp:
            figure.savefig(tmp, dpi=dpi, bbox_inches="tight")
    finally:
        plt.close(figure)
    return target


def new_figure(*args: Any, **kwargs: Any) -> Any:
    """``plt.subplots`` on the non-interactive Agg backend (no display is needed)."""
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    return plt.subplots(*args, **kwargs)
