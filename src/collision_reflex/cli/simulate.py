"""``crx simulate``: the time-domain simulation against the closed form.

Swept over approach velocity, and optionally over delay or backlash.
"""

from __future__ import annotations

import argparse
import math
from typing import TYPE_CHECKING

import numpy as np

from .._io import atomic_open
from ..errors import InvalidParameter
from ..model.impulse import optimal_velocity, total_impulse
from ..plots import check_figure_path
from ..plots.simulation import plot_sweep, plot_trace
from ..simulate import CollisionSetup, Detection, contact_damping_for_restitution, simulate, sweep
from ..vocabulary import CONTROLLED_DRIVES, REACTION_MODES, SENSING_SCHEMES
from . import options

if TYPE_CHECKING:
    from ..simulate import Sweep

# Defaults: a light direct-drive finger (the getting-started example) whose robot mass the spring does push back.
_DEFAULTS = {"m_f": 0.2, "m_r": 0.5, "k_m": 1000.0, "k_s": 100.0, "F_s": 3.0, "F_a": 10.0}


_HELP = "time-domain simulation against the closed form, over approach velocity"
_DESCRIPTION = """
Simulate the finger-spring-robot collision in time (event-driven integration) over a range of approach
velocities, optionally also over delays or backlash, and compare the impulse with the closed form; points
where they part by more than --tolerance are marked. The ideal drive with a rigid wall and no delay is the
closed form's own idealisation.
"""


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add ``crx simulate`` and its options to ``subparsers``."""
    parser = options.add_subcommand(subparsers, "simulate", _HELP, _DESCRIPTION)
    add = parser.add_argument
    options.FINGER_MASS.add(parser, _DEFAULTS["m_f"])
    options.ROBOT_MASS.add(parser, _DEFAULTS["m_r"], note="with the reflected rotor inertia")
    options.MECH_STIFFNESS.add(parser, _DEFAULTS["k_m"])
    options.SOFT_STIFFNESS.add(parser, _DEFAULTS["k_s"], note="inf: an ideally velocity-controlled robot")
    options.SOFT_DAMPING.add(parser, 0.0, note="--drive impedance only")
    options.FORCE_LIMIT.add(parser, _DEFAULTS["F_a"])
    add(
        "--detection",
        choices=SENSING_SCHEMES,  # what the simulator's detector can watch (simulate.DETECTION_KINDS)
        default=None,
        help="what the detector watches (default: position with --position-error, force otherwise)",
    )
    options.THRESHOLD.add(parser, note="force and current detection", shown=f"{_DEFAULTS['F_s']:g}")
    options.POSITION_ERROR.add(parser, note="position detection")
    add(
        "--drive",
        choices=CONTROLLED_DRIVES,
        default="ideal",
        help="ideal velocity-controlled robot (the closed form's) or a physical impedance controller "
        "(default %(default)s)",
    )
    options.APPROACH_VELOCITIES.add(parser, shown="0.1 v* to 10 v*")
    add(
        "--count",
        type=int,
        default=13,
        metavar="N",
        help="number of velocities of the default range (default %(default)s)",
    )
    options.DELAY.add(parser, 0.0)
    options.DELAYS.add(parser, note="swept as well, one curve each")
    options.BACKLASH.add(parser, 0.0)
    options.BACKLASHES.add(parser, note="swept as well, one curve each; half of it open at impact")
    options.CONTROL_RATE.add(parser, shown="continuous")
    options.CONTACT_STIFFNESS.add(parser, math.inf)
    options.RESTITUTION.add(parser, note="of a compliant contact", shown="undamped, 1")
    options.COULOMB.add(parser, 0.0)
    options.VISCOUS.add(parser, 0.0)
    add(
        "--reaction",
        choices=(*REACTION_MODES, "detected"),
        default="at_rest",
        help="closed-form variant to compare with: at_rest (the paper's), moving (robot at v0), or detected "
        "(moving at the robot's velocity at detection, v0 k/k_m) (default %(default)s)",
    )
    options.TOLERANCE.add(parser, 0.05)
    options.add_plot(parser, what="the comparison")
    options.add_csv(parser)
    options.add_plot(
        parser,
        what="one simulated force trace over the closed form's profile",
        flag="--trace-plot",
    )
    options.TRACE_VELOCITY.add(parser, shown="v*")
    parser.set_defaults(run=run)


def _detection(args: argparse.Namespace) -> Detection:
    """The detector: a force threshold [N] (force, current) or a position-error threshold [m] (position)."""
    kind = args.detection or ("position" if args.e_th is not None else "force")
    if kind == "position":
        if args.F_s is not None:
            raise InvalidParameter(
                "--threshold",
                args.F_s,
                "a force threshold [N], for force or current detection",
                "a position-error threshold is --position-error [m]",
            )
        if args.e_th is None:
            raise InvalidParameter(
                "--position-error", None, "a position-error threshold [m] for position detection"
            )
        return Detection(kind, args.e_th)
    if args.e_th is not None:
        raise InvalidParameter(
            "--position-error", args.e_th, f"no position-error threshold for {kind} detection"
        )
    return Detection(kind, args.F_s if args.F_s is not None else _DEFAULTS["F_s"])


def _setup(args: argparse.Namespace) -> CollisionSetup:
    """The simulated collision at a unit approach velocity (the sweep sets the velocity)."""
    contact_damping = 0.0
    if args.restitution is not None:
        if math.isinf(args.contact_stiffness):
            raise InvalidParameter(
                "--restitution",
                args.restitution,
                "given with a finite --contact-stiffness",
                "a rigid wall is perfectly plastic",
            )
        contact_damping = contact_damping_for_restitution(args.restitution, args.m_f, args.contact_stiffness)
    return CollisionSetup(
        m_f=args.m_f,
        m_r=args.m_r,
        k_m=args.k_m,
        k_s=args.k_s,
        F_a=args.F_a,
        v0=1.0,
        detection=_detection(args),
        drive=args.drive,
        software_damping=args.d_s,
        delay=args.delay,
        control_rate=args.control_rate,
        contact_stiffness=args.contact_stiffness,
        contact_damping=contact_damping,
        coulomb_friction=args.coulomb,
        viscous_friction=args.viscous,
        backlash=args.backlash,
    )


def run(args: argparse.Namespace) -> int:
    """Run ``crx simulate`` with parsed ``args``; return the exit status."""
    for figure in (args.plot, args.trace_plot):
        if figure is not None:
            check_figure_path(figure)  # refuse a bad name before doing any work
    if args.delays is not None and args.backlashes is not None:
        raise InvalidParameter(
            "--delays, --backlashes", "both", "one of them", "sweep one parameter at a time"
        )
    if args.count < 2:
        raise InvalidParameter("--count", args.count, "at least 2")
    setup = _setup(args)
    k, F_s = setup.lumped_stiffness, setup.equivalent_threshold
    if F_s <= 0:
        flag = "--position-error" if setup.detection.kind == "position" else "--threshold"
        raise InvalidParameter(
            flag, setup.detection.threshold, "above the play and the friction it must overcome"
        )
    v_star = float(optimal_velocity(args.m_f, k, F_s))
    velocities = (
        args.velocities if args.velocities is not None else np.geomspace(0.1, 10, args.count) * v_star
    )
    reaction, v_r = (args.reaction, None) if args.reaction != "detected" else ("moving", "detected")
    parameter, values = None, None
    if args.delays is not None:
        parameter, values = "delay", args.delays
    elif args.backlashes is not None:
        parameter, values = "backlash", args.backlashes

    result = sweep(setup, velocities, parameter, values, reaction, v_r, args.tolerance)
    threshold_unit = "m" if setup.detection.kind == "position" else "N"
    print(
        f"m_f = {args.m_f:g} kg, m_r = {args.m_r:g} kg, k_m = {args.k_m:g} N/m, k_s = {args.k_s:g} N/m "
        f"(k = {k:g} N/m), F_a = {args.F_a:g} N (a = {setup.acceleration:g} m/s^2), {setup.detection.kind} "
        f"threshold {setup.detection.threshold:g} {threshold_unit} (F_s = {F_s:g} N), drive {args.drive}"
    )
    print(
        f"v* = {v_star:.6g} m/s; closed form: {result.reaction}; parting tolerance {100 * args.tolerance:g} %"
    )
    rows = _print_table(result, parameter, v_star, args.tolerance)
    if args.csv is not None:
        _write_csv(args.csv, parameter, rows)
    if args.plot is not None:
        dense = np.geomspace(result.velocities.min(), result.velocities.max(), 200)
        if args.reaction == "detected":
            curve = total_impulse(
                args.m_f, k, args.k_m, F_s, setup.acceleration, dense, "moving", dense * k / args.k_m
            )
        else:
            curve = total_impulse(args.m_f, k, args.k_m, F_s, setup.acceleration, dense, reaction)
        path = plot_sweep(args.plot, result, (dense, curve))
        print(f"wrote {path}")
    if args.trace_plot is not None:
        from dataclasses import replace

        changes: dict = {"v0": args.trace_velocity or v_star}
        if parameter is not None:
            changes[parameter] = float(result.values[0])
        traced = simulate(replace(setup, **changes))
        robot_velocity = traced.setup.detection_robot_velocity if v_r == "detected" else None
        path = plot_trace(args.trace_plot, traced, reaction, robot_velocity)
        print(f"wrote {path}")
    return 0


def _print_table(result: Sweep, parameter: str | None, v_star: float, tolerance: float) -> list[tuple]:
    """Print one line per simulated point and return the rows (v0, level, simulated, closed, difference, parted)."""
    print()
    header = f"{'v0 [m/s]':>12}{'v0/v*':>9}"
    if parameter is not None:
        header += f"{parameter + (' [s]' if parameter == 'delay' else ' [m]'):>14}"
    header += f"{'simulated [N*s]':>18}{'closed [N*s]':>16}{'difference':>12}"
    print(header)
    rows = []
    difference, parted = result.relative_difference, result.parted
    for i, value in enumerate(result.values):
        for j, v0 in enumerate(result.velocities):
            line = f"{v0:>12.5g}{v0 / v_star:>9.3g}"
            if parameter is not None:
                line += f"{value:>14.5g}"
            mark = "  parted" if parted[i, j] else ""
            line += f"{result.simulated[i, j]:>18.6g}{result.closed_form[i, j]:>16.6g}{100 * difference[i, j]:>11.3g}%{mark}"
            print(line)
            rows.append(
                (v0, value, result.simulated[i, j], result.closed_form[i, j], difference[i, j], parted[i, j])
            )
    worst = np.unravel_index(np.argmax(np.abs(difference)), difference.shape)
    print(
        f"\nlargest difference {100 * difference[worst]:.3g} % at v0 = {result.velocities[worst[1]]:.4g} m/s; "
        f"{int(parted.sum())} of {parted.size} points part by more than {100 * tolerance:g} %"
    )
    return rows


def _write_csv(path: str, parameter: str | None, rows: list[tuple]) -> None:
    with atomic_open(path, newline="") as handle:
        handle.write(
            f"v0_m_per_s,{parameter or 'none'},impulse_simulated_Ns,impulse_closed_form_Ns,relative_difference,parted\n"
        )
        for v0, value, sim, closed, diff, part in rows:
            level = "" if value is None else f"{value:.9g}"
            handle.write(f"{v0:.9g},{level},{sim:.12g},{closed:.12g},{diff:.6g},{int(part)}\n")
    print(f"wrote {path}")
