"""``crx motors``: list a motor catalogue; ``crx motors scale``: the paper's ``tab:motor_params`` for any sizes."""

from __future__ import annotations

import argparse
import math
from collections.abc import Sequence

from ..hardware.actuators import Actuator, gear_ratio_for
from ..hardware.gearboxes import CatalogueGearbox, load_gearbox_catalogue
from ..hardware.motors import (
    DEFAULT_SCALING_LAW,
    REFERENCE_MOTOR_NAME,
    SCALING_LAWS,
    Motor,
    get_motor,
    load_catalogue,
    scaling_law,
)
from . import options

_HELP = "list the motor catalogue; 'motors scale' scales a motor (the paper's motor-parameter table)"
_DESCRIPTION = """
List the motors of a catalogue (default: the packaged one, with the paper's reference motor, Celera Motion
Omni+ OPN-060-013-A). Quantities in SI units.
"""
_SCALE_HELP = "scale a motor to other stator diameters and gear it to a torque requirement"
_SCALE_DESCRIPTION = """
Scale a catalogue motor to other stator diameters (and stack length) by a scaling law of the paper's table
of scaling laws, and pick the gear ratio N = max(1, tau_req / tau_p) that meets a torque requirement. The
defaults reproduce the paper's table of motor parameters (M1, M2, M3): the Omni+ scaled to 10, 60 and 100
mm by the Haddadin law with 1.3 N m required.
"""


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add ``crx motors`` and its options to ``subparsers``."""
    parser = options.add_subcommand(subparsers, "motors", _HELP, _DESCRIPTION)
    options.add_catalogue(parser)
    parser.add_argument(
        "--gearboxes",
        action="store_true",
        help="also list the packaged gearbox catalogue, designs/gearboxes.yaml",
    )
    parser.set_defaults(run=run_list)
    actions = parser.add_subparsers(dest="motors_command", metavar="ACTION")
    scale = options.add_subcommand(actions, "scale", _SCALE_HELP, _SCALE_DESCRIPTION)
    options.add_catalogue(scale)
    scale.add_argument(
        "--motor",
        default=REFERENCE_MOTOR_NAME,
        help="catalogue motor to scale from (default %(default)s)",
    )
    options.STATOR_DIAMETERS.add(scale, "10mm,60mm,100mm")
    options.STACK_LENGTH.add(scale, shown="the motor's own")
    scale.add_argument(
        "--law",
        choices=tuple(SCALING_LAWS),
        default=DEFAULT_SCALING_LAW,
        help="motor scaling law (default %(default)s, the paper's choice)",
    )
    options.TORQUE_REQUIRED.add(scale, 1.3)
    scale.set_defaults(run=run_scale)


def run_list(args: argparse.Namespace) -> int:
    """Run ``crx motors list``: print the catalogue; return the exit status."""
    catalogue = load_catalogue(args.catalogue)
    header = (
        f"{'name':<18}{'stator OD [mm]':>15}{'stack [mm]':>11}{'J_m [kg m^2]':>14}"
        f"{'tau_p [N m]':>12}{'tau_c [N m]':>12}{'mass [kg]':>10}{'max speed [rad/s]':>19}{'[rpm]':>8}"
    )
    print(header)
    for name, motor in catalogue.items():
        print(
            f"{name:<18}{motor.stator_diameter * 1e3:>15.4g}{motor.stack_length * 1e3:>11.4g}"
            f"{motor.rotor_inertia:>14.4g}{motor.peak_torque:>12.4g}{motor.continuous_torque:>12.4g}"
            f"{motor.mass:>10.4g}{_speed(motor, 1.0):>19}{_speed(motor, _RPM_PER_RAD_S):>8}"
        )
    print()
    for name, motor in catalogue.items():
        print(f"{name}: {motor.source}")
    if args.gearboxes:
        print()
        _print_gearboxes(load_gearbox_catalogue())
    return 0


def _print_gearboxes(gearboxes: dict[str, CatalogueGearbox]) -> None:
    """Print a gearbox catalogue: one row per gearbox, then each one's source."""
    print(
        f"{'gearbox':<14}{'kind':<11}{'ratios':<22}{'rated [N m]':>12}{'peak [N m]':>11}{'mass [kg]':>10}"
        f"{'J_in [kg m^2]':>14}{'efficiency':>11}"
    )
    for name, gearbox in gearboxes.items():
        low, high = gearbox.ratio_range
        ratios = (
            f"{low:g}..{high:g}" if gearbox.continuous_ratio else ",".join(f"{r:g}" for r in gearbox.ratios)
        )
        efficiency = "unknown" if gearbox.efficiency is None else f"{gearbox.efficiency:.3g}"
        print(
            f"{name:<14}{gearbox.kind:<11}{ratios:<22}{gearbox.rated_torque:>12.4g}{gearbox.peak_torque:>11.4g}"
            f"{gearbox.mass:>10.4g}{gearbox.inertia:>14.4g}{efficiency:>11}"
        )
    per_ratio = {name: gearbox.per_ratio for name, gearbox in gearboxes.items() if gearbox.per_ratio}
    if per_ratio:
        print("\nFigures per ratio (the rows above show the least favourable):")
    for name, figures in per_ratio.items():
        each = "; ".join(
            f"{f.ratio:g}: {f.rated_torque:.4g}/{f.peak_torque:.4g} N m, {f.inertia:.4g} kg m^2"
            for f in figures
        )
        print(f"{name} (N: rated/peak torque, J_in): {each}")
    print()
    for name, gearbox in gearboxes.items():
        print(f"{name}: {gearbox.source}")


_RPM_PER_RAD_S = 60 / (2 * math.pi)


def _speed(motor: Motor, factor: float) -> str:
    """The motor's maximum speed times ``factor`` (4 significant figures), or "unknown"."""
    return "unknown" if motor.max_speed is None else f"{motor.max_speed * factor:.4g}"


def run_scale(args: argparse.Namespace) -> int:
    """Run ``crx motors scale`` (the reference scaled to each diameter); return the exit status."""
    reference = get_motor(args.motor, args.catalogue)
    motors = [reference.scaled(float(d), args.stack_length, args.law) for d in args.stator_diameters]
    actuators = [Actuator(m, float(gear_ratio_for(args.torque, m.peak_torque))) for m in motors]
    rows: list[tuple[str, str, Sequence[float | str]]] = [
        ("Stator OD (r_m)", "mm", [m.stator_diameter * 1e3 for m in motors]),
        ("Stack height (l)", "mm", [m.stack_length * 1e3 for m in motors]),
        ("Rotor inertia (J_m)", "kg m^2", [m.rotor_inertia for m in motors]),
        ("Cont. torque (tau_c)", "N m", [m.continuous_torque for m in motors]),
        ("Peak torque (tau_p)", "N m", [m.peak_torque for m in motors]),
        ("Mass", "kg", [m.mass for m in motors]),
        ("Max. speed (omega_max)", "rad/s", [_speed(m, 1.0) for m in motors]),
        ("Gear ratio (N)", "-", [a.gear_ratio for a in actuators]),
        ("Inertia (N^2 J_m)", "kg m^2", [a.reflected_inertia for a in actuators]),
        ("Peak torque out (N tau_p)", "N m", [a.peak_torque for a in actuators]),
    ]
    print(
        f"{reference.name} scaled by the {args.law} law, output torque requirement {args.torque:g} N m "
        "(gearbox inertia ignored, as in the paper)"
    )
    print(f"{'parameter':<27}{'unit':<8}" + "".join(f"{f'M{i + 1}':>12}" for i in range(len(motors))))
    for label, unit, values in rows:
        print(
            f"{label:<27}{unit:<8}"
            + "".join(f"{v:>12}" if isinstance(v, str) else f"{v:>12.4g}" for v in values)
        )
    print(f"\nmass of {reference.name}: {reference.mass:g} kg ({reference.source})")
    speed = scaling_law(args.law).speed
    print(
        f"maximum speed scaled as omega_max = omega0 (l/l0)^{speed.length_exponent:g} "
        f"(r/r0)^{speed.diameter_exponent:g}: {speed.source}"
    )
    return 0
