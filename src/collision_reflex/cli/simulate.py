"""``crx simulate``: sweep the time-domain simulation over approach velocity (and optionally delay or backlash)
and compare it with the closed form."""

from __future__ import annotations

import argparse
import math

import numpy as np

from .._io import atomic_open
from ..errors import InvalidParameter
from ..model.impulse import REACTION_MODES, optimal_velocity, total_impulse
from ..simulate import (
    DETECTION_KINDS,
    CollisionSetup,
    Detection,
    contact_damping_for_restitution,
    sweep,
)
from ._args import non_negative_float, positive_float, value_range

# Defaults: a light direct-drive finger (the README's example) whose robot mass the spring does push back.
_DEFAULTS = {"m_f": 0.2, "m_r": 0.5, "k_m": 1000.0, "k_s": 100.0, "F_s": 3.0, "F_a": 10.0}


def _stiffness(text: str) -> float:
    """A finite number > 0, or ``inf``."""
    if text.strip().lower() in ("inf", "infinity"):
        return math.inf
    return positive_float(text)


def _non_negative_list(text: str) -> np.ndarray:
    try:
        values = np.array([float(part) for part in text.split(",")])
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a comma-separated list of numbers") from None
    if not np.all(np.isfinite(values) & (values >= 0)):
        raise argparse.ArgumentTypeError(f"{text!r}: every value must be a finite number >= 0")
    return values


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "simulate",
        help="time-domain simulation against the closed form, over approach velocity",
        description=(
            "Simulate the finger-spring-robot collision in time (event-driven integration) over a range of "
            "approach velocities, optionally also over delays or backlash, and compare the impulse with the "
            "closed form; points where they part by more than --tolerance are marked. The ideal drive with a "
            "rigid wall and no delay is the closed form's own idealisation."
        ),
    )
    add = parser.add_argument
    add(
        "--finger-mass",
        dest="m_f",
        type=positive_float,
        default=_DEFAULTS["m_f"],
        metavar="KG",
        help="finger (sprung) mass m_f [kg] (default %(default)s)",
    )
    add(
        "--robot-mass",
        dest="m_r",
        type=positive_float,
        default=_DEFAULTS["m_r"],
        metavar="KG",
        help="robot (unsprung + reflected rotor) mass m_r [kg] (default %(default)s)",
    )
    add(
        "--mech-stiffness",
        dest="k_m",
        type=positive_float,
        default=_DEFAULTS["k_m"],
        metavar="N/M",
        help="mechanical stiffness k_m [N/m] (default %(default)g)",
    )
    add(
        "--soft-stiffness",
        dest="k_s",
        type=_stiffness,
        default=_DEFAULTS["k_s"],
        metavar="N/M",
        help="software stiffness k_s [N/m], 'inf' for an ideally velocity-controlled robot (default %(default)s)",
    )
    add(
        "--soft-damping",
        dest="d_s",
        type=non_negative_float,
        default=0.0,
        metavar="N*S/M",
        help="software damping d_s [N*s/m], --drive impedance only (default %(default)s)",
    )
    add(
        "--force-limit",
        dest="F_a",
        type=positive_float,
        default=_DEFAULTS["F_a"],
        metavar="N",
        help="actuator force limit F_a [N]; the reaction acceleration is a = F_a / m_r (default %(default)s)",
    )
    add(
        "--threshold",
        dest="threshold",
        type=positive_float,
        default=_DEFAULTS["F_s"],
        metavar="VALUE",
        help="detection threshold: [N] for force and current, [m] for position (default %(default)s)",
    )
    add(
        "--detection",
        choices=DETECTION_KINDS,
        default="force",
        help="what the detector watches (default %(default)s)",
    )
    add(
        "--drive",
        choices=("ideal", "impedance"),
        default="ideal",
        help="ideal velocity-controlled robot (the closed form's) or a physical impedance controller "
        "(default %(default)s)",
    )
    add(
        "--velocities",
        type=value_range,
        default=None,
        metavar="RANGE",
        help="approach velocities [m/s]: START:STOP:N (log-spaced) or v1,v2,...; default 0.1 v* to 10 v*",
    )
    add(
        "--count",
        type=int,
        default=13,
        metavar="N",
        help="number of velocities of the default range (default %(default)s)",
    )
    add("--delay", type=non_negative_float, default=0.0, metavar="S", help="sensing delay [s] (default 0)")
    add(
        "--delays",
        type=_non_negative_list,
        default=None,
        metavar="LIST",
        help="sweep sensing delays d1,d2,... [s] as well (one curve each)",
    )
    add("--backlash", type=non_negative_float, default=0.0, metavar="M", help="backlash [m] (default 0)")
    add(
        "--backlashes",
        type=_non_negative_list,
        default=None,
        metavar="LIST",
        help="sweep backlash b1,b2,... [m] as well (one curve each; half of it open at impact)",
    )
    add(
        "--control-rate",
        type=positive_float,
        default=None,
        metavar="HZ",
        help="sampled control at this rate [Hz] (default: continuous)",
    )
    add(
        "--contact-stiffness",
        type=_stiffness,
        default=math.inf,
        metavar="N/M",
        help="wall contact stiffness [N/m] (default inf: a rigid, plastic wall)",
    )
    add(
        "--restitution",
        type=positive_float,
        default=None,
        metavar="E",
        help="coefficient of restitution of a compliant contact, in (0, 1] (default: undamped, 1)",
    )
    add(
        "--coulomb",
        type=non_negative_float,
        default=0.0,
        metavar="N",
        help="Coulomb friction on the robot mass [N]",
    )
    add(
        "--viscous",
        type=non_negative_float,
        default=0.0,
        metavar="N*S/M",
        help="viscous friction on the robot mass [N*s/m]",
    )
    add(
        "--reaction",
        choices=(*REACTION_MODES, "detected"),
        default="at_rest",
        help="closed-form variant to compare with: at_rest (the paper's), moving (robot at v0), or detected "
        "(moving at the robot's velocity at detection, v0 k/k_m) (default %(default)s)",
    )
    add(
        "--tolerance",
        type=positive_float,
        default=0.05,
        metavar="FRACTION",
        help="relative difference counted as parting (default %(default)s)",
    )
    add("--plot", default=None, metavar="FILE", help="draw the comparison to FILE (.png, .svg or .pdf)")
    add("--csv", default=None, metavar="FILE", help="write the numbers to FILE (CSV)")
    add(
        "--trace",
        default=None,
        metavar="FILE",
        help="also draw one simulated force trace over the closed form's profile to FILE (.png, .svg or .pdf)",
    )
    add(
        "--trace-velocity",
        type=positive_float,
        default=None,
        metavar="M/S",
        help="approach velocity of that trace [m/s] (default v*; first value of --delays/--backlashes)",
    )
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    for figure in (args.plot, args.trace):
        if figure is not None:
            from ..plots import check_figure_path

            check_figure_path(figure)  # refuse a bad name before doing any work
    if args.delays is not None and args.backlashes is not None:
        raise InvalidParameter(
            "--delays, --backlashes", "both", "one of them", "sweep one parameter at a time"
        )
    if args.count < 2:
        raise InvalidParameter("--count", args.count, "at least 2")
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
    setup = CollisionSetup(
        m_f=args.m_f,
        m_r=args.m_r,
        k_m=args.k_m,
        k_s=args.k_s,
        F_a=args.F_a,
        v0=1.0,
        detection=Detection(args.detection, args.threshold),
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
    k, F_s = setup.lumped_stiffness, setup.equivalent_threshold
    if F_s <= 0:
        raise InvalidParameter(
            "--threshold", args.threshold, "above the play and the friction it must overcome"
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

    print(
        f"m_f = {args.m_f:g} kg, m_r = {args.m_r:g} kg, k_m = {args.k_m:g} N/m, k_s = {args.k_s:g} N/m "
        f"(k = {k:g} N/m), F_a = {args.F_a:g} N (a = {setup.acceleration:g} m/s^2), {args.detection} "
        f"threshold {args.threshold:g} (F_s = {F_s:g} N), drive {args.drive}"
    )
    print(
        f"v* = {v_star:.6g} m/s; closed form: {result.reaction}; parting tolerance {100 * args.tolerance:g} %"
    )
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
        f"{int(parted.sum())} of {parted.size} points part by more than {100 * args.tolerance:g} %"
    )

    if args.csv is not None:
        with atomic_open(args.csv, newline="") as handle:
            handle.write(
                f"v0_m_per_s,{parameter or 'none'},impulse_simulated_Ns,impulse_closed_form_Ns,relative_difference,parted\n"
            )
            for v0, value, sim, closed, diff, part in rows:
                level = "" if value is None else f"{value:.9g}"
                handle.write(f"{v0:.9g},{level},{sim:.12g},{closed:.12g},{diff:.6g},{int(part)}\n")
        print(f"wrote {args.csv}")
    if args.plot is not None:
        from ..plots.simulation import plot_sweep

        dense = np.geomspace(result.velocities.min(), result.velocities.max(), 200)
        if args.reaction == "detected":
            curve = total_impulse(
                args.m_f, k, args.k_m, F_s, setup.acceleration, dense, "moving", dense * k / args.k_m
            )
        else:
            curve = total_impulse(args.m_f, k, args.k_m, F_s, setup.acceleration, dense, reaction)
        path = plot_sweep(args.plot, result, (dense, curve))
        print(f"wrote {path}")
    if args.trace is not None:
        from dataclasses import replace

        from ..plots.simulation import plot_trace
        from ..simulate import simulate

        changes: dict = {"v0": args.trace_velocity or v_star}
        if parameter is not None:
            changes[parameter] = float(result.values[0])
        traced = simulate(replace(setup, **changes))
        robot_velocity = traced.setup.detection_robot_velocity if v_r == "detected" else None
        path = plot_trace(args.trace, traced, reaction, robot_velocity)
        print(f"wrote {path}")
    return 0
