"""A measured trace with the fitted model and its phases (the paper's ``fig:1d_experiment``)."""

from __future__ import annotations

import os
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ..model.impulse import collision_times
from . import new_figure, save_figure

if TYPE_CHECKING:
    from ..experiments.analysis import TrialResult


def plot_trace_fit(path: str | os.PathLike[str], trial: TrialResult) -> Path:
    """Draw the floor-corrected samples, the contact window and, if fitted, the model.

    The model is drawn as the sensor reports it, with the sensing and reaction phases shaded and ``F_s``
    marked. ``path`` ends in .png, .svg or .pdf.
    """
    trace, window, impulse = trial.trace, trial.window, trial.impulse
    pad = max(10, (window.stop - window.start) // 10)
    shown = slice(max(window.start - pad, 0), min(window.stop + pad, trace.time.size))
    time = trace.time[shown]
    force = trace.force[shown] - window.floor.level
    fig, ax = new_figure(figsize=(7, 3.6))
    ax.plot(time * 1e3, force, ".", ms=2.5, color="black", label="measured (floor subtracted)")
    ax.axvspan(
        trace.time[window.start] * 1e3,
        trace.time[window.stop - 1] * 1e3,
        color="0.9",
        zorder=0,
        label=f"contact: I = {impulse.value:.4g} ± {impulse.uncertainty:.2g} N·s",
    )
    title = f"{trace.system + ': ' if trace.system else ''}{trace.label}"
    fit = trial.fit
    if fit is not None:
        model = fit.samples_at(time)
        ax.plot(time * 1e3, model, ":", color="tab:red", lw=1.5, label="model fit, as sampled")
        t1, t2 = collision_times(fit.m_f, fit.k, fit.k_m, fit.F_s, fit.a, fit.v0, fit.reaction)
        t_impact, t1_abs, t2_abs = fit.impact_time, fit.impact_time + t1, fit.impact_time + t2
        phases = fit.phases
        for start, end, color, label in (
            (t_impact, t1_abs, "tab:blue", f"sensing {phases.sensing:.3g} N·s"),
            (t1_abs, t2_abs, "tab:green", f"reaction {phases.reaction:.3g} N·s"),
        ):
            ax.axvspan(start * 1e3, end * 1e3, color=color, alpha=0.12, label=label)
        ax.axvline(t_impact * 1e3, color="tab:orange", lw=1, label=f"impact {phases.initial:.3g} N·s")
        ax.axhline(fit.F_s, color="gray", ls="--", lw=0.8)
        ax.annotate(
            "$F_s$", (time[0] * 1e3, fit.F_s), xytext=(2, 3), textcoords="offset points", color="gray"
        )
        title += f"  (m_f = {fit.m_f:.3g} kg, k_s = {fit.k_s:.3g} N/m, F_s = {fit.F_s:.3g} N, a = {fit.a:.3g} m/s²)"
    ax.set_xlabel("time [ms]")
    ax.set_ylabel("force [N]")
    ax.set_title(title, fontsize=9)
    ax.legend(loc="upper right", fontsize=7)
    # A tall, brief impact sample would flatten the rest: clip the axis above the ramp's peak if so.
    body = force[np.argsort(force)[-max(len(force) // 20, 1)]] if force.size else 1.0
    if force.max() > 3 * max(body, 1e-12):
        ax.set_ylim(min(force.min(), 0.0) * 1.1, 1.6 * body)
    return save_figure(fig, path)
