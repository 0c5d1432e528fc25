"""``crx sweep radius-velocity`` and ``crx sweep stiffness``: the paper's 1D actuator design sweeps."""

from __future__ import annotations

import argparse
import math
from typing import Any

from ..errors import InvalidParameter
from ..hardware.motors import REFERENCE_MOTOR_NAME, SCALING_LAWS, get_motor
from ..hardware.sweeps import SWEEP_DEFAULTS, radius_velocity_sweep, stiffness_sweep
from ..plots import check_figure_path
from ..plots.sweeps import check_heat_map_grid, plot_radius_velocity, plot_stiffness
from ..vocabulary import REACTION_MODES, REFLECTED_INERTIA_PLACEMENTS
from . import options

_PLACEMENT_HELP = (
    "where the reflected rotor inertia N^2 J_m sits in the 1D model: 'finger' (it reaches the contact in the "
    "impact: a rigid transmission with the compliance at the contact, like the paper's geared A8 whose fitted "
    "finger mass was 20 kg; this reproduces the paper's statement that the impulse rises steeply for small "
    "geared motors) or 'robot' (behind the compliance: it only slows the reaction, and the motor size barely "
    "matters here). Default %(default)s"
)


def _common(parser: argparse.ArgumentParser) -> None:
    options.add_catalogue(parser)
    parser.add_argument("--motor", default=REFERENCE_MOTOR_NAME, help="catalogue motor (default %(default)s)")
    options.THRESHOLD.add(parser, SWEEP_DEFAULTS["F_s"])
    options.LEVER.add(
        parser,
        SWEEP_DEFAULTS["lever"],
        note="the paper does not state it: the default is the characteristic length of its 1D experiment",
    )
    options.FINGER_MASS.add(
        parser,
        SWEEP_DEFAULTS["m_f"],
        bound="non-negative",
        note="the link's, besides any reflected inertia; the paper does not state it: the default is its U8 "
        "fit (the paper's table of one-shot fits)",
    )
    options.ROBOT_MASS.add(
        parser, SWEEP_DEFAULTS["m_r"], bound="non-negative", note="besides the reflected inertia"
    )
    parser.add_argument(
        "--reflected-inertia-in",
        choices=REFLECTED_INERTIA_PLACEMENTS,
        default=SWEEP_DEFAULTS["reflected_inertia_in"],
        help=_PLACEMENT_HELP,
    )


_HELP = "the paper's 1D actuator sweeps: motor size x velocity, stiffness x sensing"
_DESCRIPTION = "One-dimensional actuator design sweeps of the paper (section 'Actuator Selection')."
_RADIUS_VELOCITY_HELP = "impulse over motor stator diameter x approach velocity (fig:motor_scale_modeling)"
_RADIUS_VELOCITY_DESCRIPTION = """
Impulse of a 1D collision over motor stator diameter x approach velocity. Each motor is the reference
scaled by a law and geared with N = max(1, tau_req / tau_p) to meet the torque requirement; a rotary joint
drives a contact at lever L (mass J/L^2, stiffness k/L^2, force tau/L). Defaults are the paper's
fig:motor_scale_modeling: k_m = 1000 N/m, k_s = 100 N/m, F_s = 3 N, Omni+ reference, Haddadin law,
1.3 N m. The lever, finger mass and the placement of the reflected inertia are assumptions the paper does
not state; they are printed with the result. Writes a heat map (log axes, optimum marked) and a CSV of the
grid.
"""
_STIFFNESS_HELP = (
    "impulse over mechanical stiffness, force vs position-error threshold (fig:stiff-sensing-impulse)"
)
_STIFFNESS_DESCRIPTION = """
Impulse over mechanical stiffness for two sensing schemes: a fixed force threshold F_s (impulse falls with
stiffness) and a position-error threshold e_th, F_s = k e_th (impulse rises). The software spring is rigid
by default so that the swept stiffness is the whole joint's; e_th defaults to F_s / k at the middle of the
range, where both schemes detect at the same force.
"""


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add ``crx sweep`` and its options to ``subparsers``."""
    parser = options.add_subcommand(subparsers, "sweep", _HELP, _DESCRIPTION, units=False)
    kinds = parser.add_subparsers(dest="sweep_command", metavar="SWEEP", required=True)

    radius = options.add_subcommand(
        kinds, "radius-velocity", _RADIUS_VELOCITY_HELP, _RADIUS_VELOCITY_DESCRIPTION
    )
    _common(radius)
    options.STATOR_DIAMETERS.add(radius, "5mm:200mm:60")
    options.APPROACH_VELOCITIES.add(radius, "0.01:3:60")
    radius.add_argument(
        "--law",
        choices=tuple(SCALING_LAWS),
        default=SWEEP_DEFAULTS["law"],
        help="scaling law (default %(default)s)",
    )
    options.STACK_LENGTH.add(radius, shown="the motor's own")
    options.TORQUE_REQUIRED.add(radius, SWEEP_DEFAULTS["torque_required"])
    options.MECH_STIFFNESS.add(radius, SWEEP_DEFAULTS["k_m"])
    options.SOFT_STIFFNESS.add(radius, SWEEP_DEFAULTS["k_s"])
    options.add_plot(radius, "radius_velocity.png", what="the heat map")
    options.add_csv(radius, "radius_velocity.csv", what="the grid")
    radius.set_defaults(run=run_radius_velocity)

    stiffness = options.add_subcommand(kinds, "stiffness", _STIFFNESS_HELP, _STIFFNESS_DESCRIPTION)
    _common(stiffness)
    options.MECH_STIFFNESSES.add(stiffness, "100:1e5:40")
    options.APPROACH_VELOCITY.add(stiffness, 0.1)
    options.POSITION_ERROR.add(stiffness, shown="F_s / k at the middle stiffness")
    options.SOFT_STIFFNESS.add(stiffness, math.inf, shown="inf: rigid")
    options.GEAR_RATIO.add(stiffness, 1.0)
    stiffness.add_argument(
        "--reaction", choices=REACTION_MODES, default="at_rest", help="reaction model (default %(default)s)"
    )
    options.add_plot(stiffness, "stiffness.png")
    options.add_csv(stiffness, "stiffness.csv", what="the table")
    stiffness.set_defaults(run=run_stiffness)


def _common_values(args: argparse.Namespace) -> dict[str, Any]:
    """The values of the options :func:`_common` adds (but the motor), as the sweep functions' keywords."""
    return {
        "F_s": args.F_s,
        "lever": args.lever,
        "m_f": args.m_f,
        "m_r": args.m_r,
        "reflected_inertia_in": args.reflected_inertia_in,
    }


def _digest(size: int) -> range:
    """The rows of a sweep printed: about twelve, a readable digest (the CSV has every point)."""
    return range(0, size, max(1, size // 12))


def _check_outputs(args: argparse.Namespace) -> None:
    """Refuse bad output names before computing anything."""
    check_figure_path(args.plot)
    if not str(args.csv).lower().endswith(".csv"):
        raise InvalidParameter("--csv", args.csv, "a file name ending in .csv")


def _print_assumptions(assumptions: dict[str, object]) -> None:
    """Print every setting of a sweep, one ``key: value`` line each."""
    print("settings and assumptions:")
    for key, value in assumptions.items():
        print(f"  {key}: {value}")


def run_radius_velocity(args: argparse.Namespace) -> int:
    """Run ``crx sweep radius-velocity`` (impulse over motor size and velocity); return the exit status."""
    _check_outputs(args)
    check_heat_map_grid(args.stator_diameters.size, args.velocities.size)
    sweep = radius_velocity_sweep(
        args.stator_diameters,
        args.velocities,
        reference=get_motor(args.motor, args.catalogue),
        law=args.law,
        torque_required=args.torque,
        k_m=args.k_m,
        k_s=args.k_s,
        stack_length=args.stack_length,
        **_common_values(args),
    )
    _print_assumptions(sweep.assumptions)
    print()
    print(f"{'diameter [mm]':>14}{'N':>9}{'N^2 J_m':>12}{'m_f [kg]':>11}{'v* [m/s]':>10}{'I* [N s]':>11}")
    for i in _digest(sweep.diameters.size):
        print(
            f"{sweep.diameters[i] * 1e3:>14.4g}{sweep.gear_ratio[i]:>9.4g}{sweep.reflected_inertia[i]:>12.4g}"
            f"{sweep.m_f[i]:>11.4g}{sweep.optimal_velocity[i]:>10.4g}{sweep.minimum_impulse[i]:>11.4g}"
        )
    print()
    print(
        f"optimum: stator diameter {sweep.best_diameter * 1e3:.4g} mm, approach velocity "
        f"{sweep.best_velocity:.4g} m/s, impulse {sweep.best_impulse:.4g} N s"
    )
    print(f"wrote {sweep.to_csv(args.csv)}")
    print(f"wrote {plot_radius_velocity(sweep, args.plot)}")
    return 0


def run_stiffness(args: argparse.Namespace) -> int:
    """Run ``crx sweep stiffness``: impulse over mechanical stiffness; return the exit status."""
    _check_outputs(args)
    sweep = stiffness_sweep(
        args.k_m_values,
        v0=args.v0,
        e_th=args.e_th,
        k_s=args.k_s,
        motor=get_motor(args.motor, args.catalogue),
        gear_ratio=args.gear_ratio,
        reaction=args.reaction,
        **_common_values(args),
    )
    _print_assumptions(sweep.assumptions)
    print()
    print(
        f"{'k_m [N/m]':>12}{'F_s force':>11}{'I force [N s]':>15}{'F_s position':>14}{'I position [N s]':>18}"
    )
    for i in _digest(sweep.stiffnesses.size):
        print(
            f"{sweep.stiffnesses[i]:>12.4g}{sweep.force_threshold[i]:>11.4g}{sweep.force_threshold_impulse[i]:>15.4g}"
            f"{sweep.position_threshold[i]:>14.4g}{sweep.position_threshold_impulse[i]:>18.4g}"
        )
    print(f"wrote {sweep.to_csv(args.csv)}")
    print(f"wrote {plot_stiffness(sweep, args.plot)}")
    return 0
