"""Simulated impulse against the closed form over approach velocity, with the points where they part marked."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import numpy as np

from . import new_figure, save_figure


def plot_sweep(path: str | os.PathLike[str], result: Any, closed_form_curve: Any = None) -> Path:
    """Draw a :class:`collision_reflex.simulate.Sweep`: simulated impulses as markers (one series per value of
    the swept parameter), the closed form as a line, and the points whose relative difference exceeds the
    tolerance circled in red. ``closed_form_curve`` is an optional ``(velocities, impulses)`` pair drawn as a
    smooth line; otherwise the closed form at the simulated velocities is drawn.
    """
    fig, (top, bottom) = new_figure(2, 1, figsize=(7, 6), sharex=True, gridspec_kw={"height_ratios": [3, 2]})
    if closed_form_curve is not None:
        top.plot(*closed_form_curve, color="black", lw=1.4, label=f"closed form ({result.reaction})")
    else:
        top.plot(result.velocities, result.closed_form[0], color="black", lw=1.4, label="closed form")
    colours = [f"C{i}" for i in range(10)]
    parted = result.parted
    difference = result.relative_difference
    for i, value in enumerate(result.values):
        label = (
            "simulated"
            if value is None
            else f"simulated, {result.parameter} = {_format(result.parameter, value)}"
        )
        colour = colours[i % len(colours)]
        top.plot(result.velocities, result.simulated[i], "o", ms=4, color=colour, label=label)
        bottom.plot(result.velocities, 100 * difference[i], "o-", ms=3, lw=0.8, color=colour)
        if np.any(parted[i]):
            top.plot(
                result.velocities[parted[i]],
                result.simulated[i][parted[i]],
                "o",
                ms=9,
                mfc="none",
                mec="red",
                label="parted" if i == 0 or not np.any(parted[:i]) else None,
            )
    tol = 100 * result.tolerance
    bottom.axhspan(-tol, tol, color="0.9", label=f"within ±{tol:g} %")
    bottom.axhline(0.0, color="black", lw=0.8)
    for axis in (top, bottom):
        axis.set_xscale("log")
    top.set_yscale("log")
    top.set_ylabel("impulse [N·s]")
    bottom.set_ylabel("simulated / closed form - 1 [%]")
    bottom.set_xlabel("approach velocity v0 [m/s]")
    top.set_title("Time-domain simulation against the closed-form collision reflex")
    top.legend(fontsize=8)
    bottom.legend(fontsize=8, loc="best")
    return save_figure(fig, path)


def _format(parameter: str | None, value: float) -> str:
    if parameter == "delay":
        return f"{1e3 * value:g} ms"
    if parameter == "backlash":
        return f"{1e3 * value:g} mm"
    return f"{value:g}"
