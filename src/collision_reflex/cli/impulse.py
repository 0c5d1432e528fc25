"""``crx impulse``: the 1D collision reflex for parameters given on the command line."""

from __future__ import annotations

import argparse
import dataclasses

import numpy as np

from ..model.contact import rebound, rebound_impulse, settled_rebound_speed
from ..model.impulse import (
    collision_times,
    minimum_impulse,
    optimal_velocity,
    phase_impulses,
    series_stiffness,
)
from ..plots import check_figure_path
from ..plots.profile import plot_force_profile
from ..vocabulary import REACTION_MODES
from . import options

# Defaults: the paper's direct-drive U8 actuator in its soft setting (one-shot fit, tab:one_shot), against
# the ATI Mini40 sensor's stiffness.
_DEFAULTS = {"m_f": 0.1, "k_m": 2e7, "k_s": 440.0, "F_s": 3.0, "a": 4.7e-5, "v0": 0.1}


_HELP = "phase impulses, total, v* and I* of a 1D collision"
_DESCRIPTION = """
Collision reflex of a finger-spring-robot system hitting a rigid constraint: impulse of the impact,
sensing and reaction phases, their total, the optimal approach velocity v* and the minimum impulse I*.
Defaults are the paper's direct-drive U8 actuator (soft setting, the paper's one-shot fit) against a force
sensor of stiffness 2e7 N/m.
"""


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add ``crx impulse`` and its options to ``subparsers``."""
    parser = options.add_subcommand(subparsers, "impulse", _HELP, _DESCRIPTION)
    options.FINGER_MASS.add(parser, _DEFAULTS["m_f"])
    options.MECH_STIFFNESS.add(parser, _DEFAULTS["k_m"], note="the spring left during the reaction")
    options.SOFT_STIFFNESS.add(parser, _DEFAULTS["k_s"], note="in series with k_m while sensing")
    options.STIFFNESS.add(parser, note="overrides the series combination of k_m and k_s")
    options.THRESHOLD.add(parser, _DEFAULTS["F_s"])
    options.ACCEL.add(parser, _DEFAULTS["a"])
    options.APPROACH_VELOCITY.add(parser, _DEFAULTS["v0"])
    parser.add_argument(
        "--reaction",
        choices=REACTION_MODES,
        default="at_rest",
        help="reaction model: robot mass at rest at detection (the paper's) or still moving (default %(default)s)",
    )
    options.ROBOT_VELOCITY.add(parser, note="with --reaction moving", shown="v0")
    options.APPROACH_VELOCITIES.add(parser, note="also tabulate I(v0) over them")
    dataclasses.replace(options.RESTITUTION, hint="in [0, 1)").add(
        parser,
        note="of a rigid object that rebounds: adds its impulse (a finger that settles before detection)",
        shown="0, plastic",
        bound="non-negative",
    )
    options.add_plot(parser, what="the force-time profile with the phases shaded")
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    """Run ``crx impulse`` with parsed ``args``; return the exit status."""
    if args.plot is not None:
        check_figure_path(args.plot)  # refuse a bad name before doing any work
    if args.v_r is not None and args.reaction != "moving":
        args.reaction = "moving"  # giving a robot velocity only makes sense for the moving reaction
    k = args.k if args.k is not None else series_stiffness(args.k_m, args.k_s)
    common = (args.m_f, k, args.k_m, args.F_s, args.a)
    phases = phase_impulses(*common, args.v0, args.reaction, args.v_r)
    t1, t2 = collision_times(*common, args.v0, args.reaction, args.v_r)
    v_star = optimal_velocity(args.m_f, k, args.F_s, args.reaction, args.k_m, args.a)
    i_star = minimum_impulse(*common, args.reaction)
    rows = [
        ("I   impact", phases.initial),
        ("II  sensing", phases.sensing),
        ("III reaction", phases.reaction),
    ]
    total = phases.total
    if args.restitution:
        added = rebound_impulse(args.m_f, k, args.F_s, args.v0, args.restitution)
        rows.append((f"    rebound (e = {args.restitution:g})", added))
        total = total + added

    print(
        f"m_f = {args.m_f:g} kg, k = {k:g} N/m (k_m = {args.k_m:g}, "
        + (f"k_s = {args.k_s:g})" if args.k is None else "given directly)")
        + f", F_s = {args.F_s:g} N, a = {args.a:g} m/s^2, v0 = {args.v0:g} m/s, reaction: {args.reaction}"
    )
    print()
    print(f"{'phase':<22}{'impulse [N*s]':>16}{'share':>9}")
    for name, value in rows:
        print(f"{name:<22}{float(value):>16.6g}{float(value / total):>9.1%}")
    print(f"{'total I':<22}{float(total):>16.6g}")
    print()
    print(f"detection t1 = {float(t1):.6g} s, contact ends t2 = {float(t2):.6g} s")
    print(f"optimal velocity v* = {float(v_star):.6g} m/s, minimum impulse I* = {float(i_star):.6g} N*s")
    regime = "sensing-dominated: going faster lowers I" if args.v0 < v_star else "impact-dominated"
    print(f"v0 / v* = {args.v0 / float(v_star):.3g} ({regime})")

    if args.velocities is not None:
        sweep = phase_impulses(*common, args.velocities, args.reaction, args.v_r)
        v = np.asarray(args.velocities, dtype=float)
        names = ["v0 [m/s]", "I impact", "II sensing", "III reaction"]
        columns = [v, *np.broadcast_arrays(sweep.initial, sweep.sensing, sweep.reaction)]
        total = sweep.total
        if args.restitution:  # NaN where the finger still rebounds at detection: printed as "simulate"
            settled = v <= settled_rebound_speed(args.m_f, k, args.F_s, args.restitution)
            extra = np.where(settled, rebound(args.restitution).excess * args.m_f * v, np.nan)
            names.append("rebound")
            columns.append(extra)
            total = total + extra
        names.append("total I")
        columns.append(np.broadcast_to(total, v.shape))
        print()
        print(f"{names[0]:>12}" + "".join(f"{name:>14}" for name in names[1:]))
        for row in zip(*columns, strict=True):
            print("".join(_cell(x, 12 if i == 0 else 14) for i, x in enumerate(row)))
        if args.restitution and not settled.all():
            print(
                "simulate: the finger still rebounds when the contact is detected (crx simulate --restitution)"
            )

    if args.plot is not None:
        path = plot_force_profile(args.plot, *common, args.v0, args.reaction, args.v_r)
        print(f"\nwrote {path}")
    return 0


def _cell(value: float, width: int) -> str:
    """A number of the sweep's table, or ``simulate`` where the closed form has none (NaN)."""
    return f"{'simulate':>{width}}" if np.isnan(value) else f"{float(value):>{width}.6g}"
