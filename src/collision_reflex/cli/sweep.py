"""``crx sweep radius-velocity`` and ``crx sweep stiffness``: the paper's 1D actuator design sweeps."""

from __future__ import annotations

import argparse
import math

from ..hardware.actuators import REFLECTED_INERTIA_PLACEMENTS
from ..hardware.motors import REFERENCE_MOTOR_NAME, SCALING_LAWS, get_motor
from ..hardware.sweeps import SWEEP_DEFAULTS
from ..model.impulse import REACTION_MODES
from ._args import non_negative_float, positive_float, value_range

_PLACEMENT_HELP = (
    "where the reflected rotor inertia N^2 J_m sits in the 1D model: 'finger' (it reaches the contact in the "
    "impact: a rigid transmission with the compliance at the contact, like the paper's geared A8 whose fitted "
    "finger mass was 20 kg; this reproduces the paper's statement that the impulse rises steeply for small "
    "geared motors) or 'robot' (behind the compliance: it only slows the reaction, and the motor size barely "
    "matters here). Default %(default)s"
)


def _common(parser: argparse.ArgumentParser) -> None:
    add = parser.add_argument
    add("--catalogue", default=None, metavar="FILE", help="a motor catalogue YAML file (default: packaged)")
    add("--motor", default=REFERENCE_MOTOR_NAME, help="catalogue motor (default %(default)s)")
    add(
        "--threshold",
        type=positive_float,
        default=SWEEP_DEFAULTS["threshold"],
        metavar="N",
        help="force threshold F_s at the contact [N] (default %(default)s)",
    )
    add(
        "--lever",
        type=positive_float,
        default=SWEEP_DEFAULTS["lever"],
        metavar="M",
        help="joint axis to contact distance L [m]; the paper does not state it: default %(default)s, the "
        "characteristic length of its 1D experiment",
    )
    add(
        "--finger-mass",
        type=non_negative_float,
        default=SWEEP_DEFAULTS["finger_mass"],
        metavar="KG",
        help="link (sprung) mass at the contact [kg]; the paper does not state it: default %(default)s, its "
        "U8 fit (tab:one_shot)",
    )
    add(
        "--robot-mass",
        type=non_negative_float,
        default=SWEEP_DEFAULTS["robot_mass"],
        metavar="KG",
        help="unsprung mass at the contact besides the reflected inertia [kg] (default %(default)s)",
    )
    add(
        "--reflected-inertia-in",
        choices=REFLECTED_INERTIA_PLACEMENTS,
        default=SWEEP_DEFAULTS["reflected_inertia_in"],
        help=_PLACEMENT_HELP,
    )


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "sweep",
        help="the paper's 1D actuator sweeps: motor size x velocity, stiffness x sensing",
        description="One-dimensional actuator design sweeps of the paper (section 'Actuator Selection').",
    )
    kinds = parser.add_subparsers(dest="sweep_command", metavar="SWEEP", required=True)

    radius = kinds.add_parser(
        "radius-velocity",
        help="impulse over motor stator diameter x approach velocity (fig:motor_scale_modeling)",
        description=(
            "Impulse of a 1D collision over motor stator diameter x approach velocity. Each motor is the "
            "reference scaled by a law and geared with N = max(1, tau_req / tau_p) to meet the torque "
            "requirement; a rotary joint drives a contact at lever L (mass J/L^2, stiffness k/L^2, force "
            "tau/L). Defaults are the paper's fig:motor_scale_modeling: k_m = 1000 N/m, k_s = 100 N/m, "
            "F_s = 3 N, Omni+ reference, Haddadin law, 1.3 N m. The lever, finger mass and the placement of "
            "the reflected inertia are assumptions the paper does not state; they are printed with the result. "
            "Writes a heat map (log axes, optimum marked) and a CSV of the grid."
        ),
    )
    _common(radius)
    add = radius.add_argument
    add(
        "--diameters",
        type=value_range,
        default=value_range("0.005:0.2:60"),
        metavar="RANGE",
        help="stator diameters [m], START:STOP:N log-spaced or a list (default 0.005:0.2:60)",
    )
    add(
        "--velocities",
        type=value_range,
        default=value_range("0.01:3:60"),
        metavar="RANGE",
        help="approach velocities [m/s], START:STOP:N log-spaced or a list (default 0.01:3:60)",
    )
    add(
        "--law",
        choices=tuple(SCALING_LAWS),
        default=SWEEP_DEFAULTS["law"],
        help="scaling law (default %(default)s)",
    )
    add(
        "--stack-length",
        type=positive_float,
        default=None,
        metavar="M",
        help="stack length [m] (default: motor's)",
    )
    add(
        "--torque",
        type=positive_float,
        default=SWEEP_DEFAULTS["torque_required"],
        metavar="N*M",
        help="output torque requirement [N m] (default %(default)s)",
    )
    add(
        "--k-m",
        type=positive_float,
        default=SWEEP_DEFAULTS["mechanical_stiffness"],
        metavar="N/M",
        help="mechanical stiffness at the contact [N/m] (default %(default)g)",
    )
    add(
        "--k-s",
        type=positive_float,
        default=SWEEP_DEFAULTS["software_stiffness"],
        metavar="N/M",
        help="software stiffness at the contact [N/m] (default %(default)g)",
    )
    add(
        "--plot",
        default="radius_velocity.png",
        metavar="FILE",
        help="figure (.png/.svg/.pdf; default %(default)s)",
    )
    add("--csv", default="radius_velocity.csv", metavar="FILE", help="grid as CSV (default %(default)s)")
    radius.set_defaults(run=run_radius_velocity)

    stiffness = kinds.add_parser(
        "stiffness",
        help="impulse over mechanical stiffness, force vs position-error threshold (fig:stiff-sensing-impulse)",
        description=(
            "Impulse over mechanical stiffness for two sensing schemes: a fixed force threshold F_s (impulse "
            "falls with stiffness) and a position-error threshold e_th, F_s = k e_th (impulse rises). The "
            "software spring is rigid by default so that the swept stiffness is the whole joint's; e_th "
            "defaults to F_s / k at the middle of the range, where both schemes detect at the same force."
        ),
    )
    _common(stiffness)
    add = stiffness.add_argument
    add(
        "--stiffnesses",
        type=value_range,
        default=value_range("100:1e5:40"),
        metavar="RANGE",
        help="mechanical stiffnesses at the contact [N/m] (default 100:1e5:40)",
    )
    add(
        "--velocity",
        type=positive_float,
        default=0.1,
        metavar="M/S",
        help="approach velocity (default %(default)s)",
    )
    add(
        "--position-error",
        type=positive_float,
        default=None,
        metavar="M",
        help="position-error threshold at the contact [m] (default: F_s / k at the middle stiffness)",
    )
    add(
        "--k-s",
        type=positive_float,
        default=math.inf,
        metavar="N/M",
        help="software stiffness at the contact [N/m] (default inf: rigid)",
    )
    add("--gear-ratio", type=positive_float, default=1.0, metavar="N", help="gear ratio N >= 1 (default 1)")
    add("--reaction", choices=REACTION_MODES, default="at_rest", help="reaction model (default %(default)s)")
    add(
        "--plot", default="stiffness.png", metavar="FILE", help="figure (.png/.svg/.pdf; default %(default)s)"
    )
    add("--csv", default="stiffness.csv", metavar="FILE", help="table as CSV (default %(default)s)")
    stiffness.set_defaults(run=run_stiffness)


def _check_outputs(args: argparse.Namespace) -> None:
    """Refuse bad output names before computing anything."""
    from ..errors import InvalidParameter
    from ..plots import check_figure_path

    check_figure_path(args.plot)
    if not str(args.csv).lower().endswith(".csv"):
        raise InvalidParameter("--csv", args.csv, "a file name ending in .csv")


def _print_assumptions(assumptions: dict) -> None:
    print("settings and assumptions:")
    for key, value in assumptions.items():
        print(f"  {key}: {value}")


def run_radius_velocity(args: argparse.Namespace) -> int:
    from ..hardware.sweeps import radius_velocity_sweep
    from ..plots.sweeps import check_heat_map_grid, plot_radius_velocity

    _check_outputs(args)
    check_heat_map_grid(args.diameters.size, args.velocities.size)
    sweep = radius_velocity_sweep(
        args.diameters,
        args.velocities,
        reference=get_motor(args.motor, args.catalogue),
        law=args.law,
        torque_required=args.torque,
        mechanical_stiffness=args.k_m,
        software_stiffness=args.k_s,
        threshold=args.threshold,
        lever=args.lever,
        finger_mass=args.finger_mass,
        robot_mass=args.robot_mass,
        reflected_inertia_in=args.reflected_inertia_in,
        stack_length=args.stack_length,
    )
    _print_assumptions(sweep.assumptions)
    print()
    print(f"{'diameter [mm]':>14}{'N':>9}{'N^2 J_m':>12}{'m_f [kg]':>11}{'v* [m/s]':>10}{'I* [N s]':>11}")
    step = max(1, sweep.diameters.size // 12)  # a readable digest; the CSV has every point
    for i in range(0, sweep.diameters.size, step):
        print(
            f"{sweep.diameters[i] * 1e3:>14.4g}{sweep.gear_ratio[i]:>9.4g}{sweep.reflected_inertia[i]:>12.4g}"
            f"{sweep.finger_mass[i]:>11.4g}{sweep.optimal_velocity[i]:>10.4g}{sweep.minimum_impulse[i]:>11.4g}"
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
    from ..hardware.sweeps import stiffness_sweep
    from ..plots.sweeps import plot_stiffness

    _check_outputs(args)
    sweep = stiffness_sweep(
        args.stiffnesses,
        velocity=args.velocity,
        threshold=args.threshold,
        position_error=args.position_error,
        software_stiffness=args.k_s,
        motor=get_motor(args.motor, args.catalogue),
        gear_ratio=args.gear_ratio,
        lever=args.lever,
        finger_mass=args.finger_mass,
        robot_mass=args.robot_mass,
        reflected_inertia_in=args.reflected_inertia_in,
        reaction=args.reaction,
    )
    _print_assumptions(sweep.assumptions)
    print()
    print(
        f"{'k_m [N/m]':>12}{'F_s force':>11}{'I force [N s]':>15}{'F_s position':>14}{'I position [N s]':>18}"
    )
    step = max(1, sweep.stiffnesses.size // 12)
    for i in range(0, sweep.stiffnesses.size, step):
        print(
            f"{sweep.stiffnesses[i]:>12.4g}{sweep.force_threshold[i]:>11.4g}{sweep.force_threshold_impulse[i]:>15.4g}"
            f"{sweep.position_threshold[i]:>14.4g}{sweep.position_threshold_impulse[i]:>18.4g}"
        )
    print(f"wrote {sweep.to_csv(args.csv)}")
    print(f"wrote {plot_stiffness(sweep, args.plot)}")
    return 0
