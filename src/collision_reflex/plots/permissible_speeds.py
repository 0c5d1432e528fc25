"""A design's permissible approach speeds per human body region, beside the half-mass estimate."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np

from . import FigurePath, new_figure, save_figure


def plot_permissible_speeds(
    path: FigurePath,
    regions: Sequence[str],
    slowest: Sequence[float],
    median: Sequence[float],
    fastest: Sequence[float],
    estimate: Sequence[float],
    approach_velocity: float,
    title: str,
) -> Path:
    """One row per body region: its permissible speeds [m/s] beside the half-mass estimate.

    A bar from the slowest to the fastest over the contact samples, the median marked, the
    half-moving-mass-plus-payload estimate (a diamond), and the design's approach speed (a vertical line), on a
    logarithmic speed axis: the regions span orders of magnitude.
    """
    from matplotlib.ticker import FuncFormatter  # lazy: matplotlib

    n = len(regions)
    rows = np.arange(n)[::-1]
    fig, ax = new_figure(figsize=(6.4, 0.18 * n + 1.4))
    low, high = np.asarray(slowest, dtype=float), np.asarray(fastest, dtype=float)
    ax.hlines(rows, low, high, color="tab:blue", lw=6, alpha=0.45, label="over the contact samples")
    ax.plot(median, rows, "|", color="tab:blue", ms=12, mew=2, label="median")
    ax.plot(estimate, rows, "D", color="tab:orange", ms=5, label="M/2 + payload estimate")
    ax.axvline(
        approach_velocity, color="tab:red", lw=1.2, label=f"approach speed {approach_velocity:.3g} m/s"
    )
    ax.set_yticks(rows, [name.replace("_", " ") for name in regions], fontsize=8)
    ax.set_xscale("log")
    plain = FuncFormatter(lambda x, _: f"{x:g}")
    ax.xaxis.set_major_formatter(plain)
    ax.xaxis.set_minor_formatter(FuncFormatter(lambda x, _: f"{x:g}" if _mantissa(x) in (2, 5) else ""))
    ax.set_xlabel("permissible approach speed [m/s]")
    ax.grid(alpha=0.3, which="both", axis="x")
    ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.16), ncol=2, frameon=False)
    ax.set_title(title, fontsize=9)
    fig.tight_layout()
    return save_figure(fig, path)


def _mantissa(x: float) -> int:
    """The leading digit of ``x`` > 0 (the minor ticks labelled: 2 and 5 of each decade)."""
    return round(x / 10 ** np.floor(np.log10(x)))
