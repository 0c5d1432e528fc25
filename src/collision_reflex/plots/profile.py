"""Force-time profile of one collision with its three phases shaded.

The paper's ``fig:collision_reflex_plot``, top.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from ..model.impulse import (
    collision_times,
    force_profile,
    impact_pulse_duration,
    phase_impulses,
    sensing_force,
)
from . import new_figure, save_figure


def plot_force_profile(
    path: str | os.PathLike[str],
    m_f: float,
    k: float,
    k_m: float,
    F_s: float,
    a: float,
    v0: float,
    reaction: str = "at_rest",
    v_r: float | None = None,
) -> Path:
    """Draw ``F(t)`` with the impact, sensing and reaction phases shaded and ``t1``, ``t2``, ``F_s`` marked.

    Arguments as :func:`collision_reflex.model.phase_impulses`; ``path`` ends in .png, .svg or .pdf.
    """
    t1, t2 = collision_times(m_f, k, k_m, F_s, a, v0, reaction, v_r)
    phases = phase_impulses(m_f, k, k_m, F_s, a, v0, reaction, v_r)
    t_impact = impact_pulse_duration(m_f, k_m)
    # Dense sampling in each phase so the (often very short) impact pulse is resolved too.
    t = np.unique(
        np.concatenate(
            [
                np.linspace(-0.05 * t2, 0.0, 20),
                np.linspace(0.0, t_impact, 200),
                np.linspace(0.0, t1, 400),
                np.linspace(t1, t2, 400),
                np.linspace(t2, 1.1 * t2, 20),
            ]
        )
    )
    force = force_profile(t, m_f, k, k_m, F_s, a, v0, reaction, v_r)

    fig, ax = new_figure(figsize=(7, 3.6))
    ax.plot(t, force, color="black", lw=1.4, label="F(t)")
    # Stack the shading so each area is its phase's impulse: the impact pulse sits on top of the sensing ramp.
    ramp = np.where((t >= 0) & (t < t1), sensing_force(t, k, v0), 0.0)
    shaded = (  # (where, lower curve or 0, upper curve, colour, opacity, label)
        ((t >= 0) & (t <= t_impact), ramp, force, "tab:orange", 0.4, f"I: impact  {phases.initial:.3g} N·s"),
        ((t >= 0) & (t <= t1), None, ramp, "tab:blue", 0.3, f"II: sensing  {phases.sensing:.3g} N·s"),
        ((t >= t1) & (t <= t2), None, force, "tab:green", 0.3, f"III: reaction  {phases.reaction:.3g} N·s"),
    )
    for inside, lower, upper, color, alpha, label in shaded:
        bottom = 0.0 if lower is None else lower[inside]
        ax.fill_between(t[inside], bottom, upper[inside], color=color, alpha=alpha, label=label)
    ax.axhline(F_s, color="gray", ls="--", lw=0.8)
    ax.annotate("$F_s$", (t2, F_s), xytext=(4, 3), textcoords="offset points", color="gray")
    for name, time in (("$t_1$", t1), ("$t_2$", t2)):
        ax.axvline(time, color="gray", ls=":", lw=0.8)
        ax.annotate(name, (time, 0.0), xytext=(3, 3), textcoords="offset points", color="gray")
    ax.set_xlabel("time since impact [s]")
    ax.set_ylabel("contact force [N]")
    ax.set_title(f"Collision reflex: I = {phases.total:.4g} N·s at v0 = {v0:.3g} m/s ({reaction})")
    ax.legend(loc="upper left", fontsize=8)
    peak = float(np.max(force))
    if peak > 3 * F_s:
        # A stiff structure gives a tall, brief impact pulse; clip it so the sensing and reaction phases show.
        ax.set_ylim(0.0, 1.6 * F_s)
        ax.annotate(
            f"impact pulse peaks at {peak:.3g} N (clipped)",
            (t_impact, 1.55 * F_s),
            fontsize=8,
            xytext=(6, -10),
            textcoords="offset points",
            color="tab:orange",
        )
    else:
        ax.set_ylim(bottom=0.0)
    return save_figure(fig, path)
