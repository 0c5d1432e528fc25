"""Simulated impulse against the closed form over approach velocity, with the points where they part marked."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import numpy as np

from ..model.impulse import force_profile
from . import new_figure, save_figure


def plot_sweep(path: str | os.PathLike[str], result: Any, closed_form_curve: Any = None) -> Path:
    """Draw a :class:`collision_reflex.simulate.Sweep`: simulated impulses against the closed form.

    The simulated impulses are markers (one series per value of the swept parameter), the closed form is a
    line, and the points whose relative difference exceeds the tolerance are circled in red.
    ``closed_form_curve`` is an optional ``(velocities, impulses)`` pair drawn as a smooth line; otherwise the
    closed form at the simulated velocities is drawn.
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


def plot_trace(path: str | os.PathLike[str], result: Any, reaction: str = "at_rest", v_r: Any = None) -> Path:
    """Draw a simulated force trace over the closed form's force profile for the same setup.

    The trace is a :class:`collision_reflex.simulate.SimulationResult` and the profile is
    :func:`collision_reflex.model.force_profile`; the detection, reaction and contact-end times are marked and the
    rigid impacts' impulses noted.
    """
    setup = result.setup
    end = float(result.contact_end) if np.isfinite(result.contact_end) else float(result.t[-1])
    fig, ax = new_figure(figsize=(7, 3.6))
    ax.plot(result.t, result.contact_force, color="tab:blue", lw=1.2, label="simulated contact force")
    t = np.linspace(0.0, 1.3 * end, 800)
    closed = force_profile(
        t,
        setup.m_f,
        setup.lumped_stiffness,
        setup.k_m,
        setup.equivalent_threshold,
        setup.acceleration,
        setup.v0,
        reaction,
        v_r,
    )
    ax.plot(t, closed, color="black", lw=1.0, ls="--", label=f"closed form ({reaction})")
    for height, (name, time, style) in enumerate(
        (
            ("detection", result.detection_time, ":"),
            ("reaction", result.reaction_time, "-."),
            ("contact ends", result.contact_end, "-"),
        )
    ):
        if np.isfinite(time):
            ax.axvline(time, color="gray", ls=style, lw=0.8)
            # Staggered so that labels of close events do not overprint.
            ax.annotate(
                name,
                (time, 0.03 + 0.08 * height),
                xycoords=("data", "axes fraction"),
                xytext=(3, 0),
                textcoords="offset points",
                color="gray",
                fontsize=8,
            )
    impacts = sum(impulse for _, impulse in result.impacts)
    note = f"I = {result.impulse:.4g} N·s"
    if impacts:
        note += f" (rigid impacts {impacts:.3g} N·s, not drawn)"
    ax.set_title(f"Simulated collision at v0 = {setup.v0:.3g} m/s: {note}", fontsize=10)
    ax.set_xlabel("time since impact [s]")
    ax.set_ylabel("contact force [N]")
    spring_peak = float(np.max(result.spring_force)) if result.spring_force.size else 0.0
    top = max(spring_peak, float(np.max(closed[t > 1e-3 * end])) if np.any(t > 1e-3 * end) else 0.0)
    if result.peak_force > 3 * max(top, 1e-12):
        ax.set_ylim(0.0, 1.5 * top)  # clip a brief, tall impact pulse so the rest shows
    else:
        ax.set_ylim(bottom=0.0)
    ax.set_xlim(-0.02 * end, 1.3 * end)
    ax.legend(fontsize=8, loc="upper right")
    return save_figure(fig, path)
