"""``crx surface``: collision-reflex surfaces of a URDF arm (the paper's ``fig:two_link``)."""

from __future__ import annotations

import argparse
import math
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from .._io import atomic_open
from ..arm import Arm
from ..arm.directions import COORDINATE_PLANES, plane_directions
from ..arm.surfaces import reflex_surface
from ..errors import InvalidParameter
from ..hardware.actuators import ForceThreshold
from ..plots import check_figure_path
from ..plots.surface import SurfaceRow, plot_planar_grid, plot_spatial_surface
from . import options

if TYPE_CHECKING:
    from ..arm.surfaces import ReflexSurface

# Defaults of the paper's two-link example (fig:two_link; fig:motor_scale_modeling for stiffness and threshold):
# Omni+ motors of 60 mm stator diameter geared to the URDF's torque limits, q2 = 45 deg, v0 = 0.5 m/s, a 3 N
# force threshold, 100 N/m Cartesian controller stiffness, joint springs of 250 N m/rad (about 1000 N/m at the
# 0.5 m reach of the two-link design).
_DEFAULT_URDF = Path("designs") / "planar_two_link.urdf"
_SECOND_JOINT = 1  # the paper's q2: the second joint of the chain
_DEFAULTS = {
    "stator_diameter": 0.060,
    "v0": 0.5,
    "F_s": 3.0,
    "task_stiffness": 100.0,
    "mechanical_stiffness": 250.0,
    "software_stiffness": math.inf,
    "q2_values": "90deg,45deg,20deg,5deg,0deg",
    "stator_diameters": "10mm,30mm,60mm,100mm",
    "velocities": "0.1,0.25,0.5,1,2",
}


_HELP = "collision-reflex surfaces of a URDF arm (impulse over contact directions)"
_DESCRIPTION = f"""
The collision impulse of a URDF arm swept over contact directions at one configuration. A planar arm gets
the paper's grid (fig:two_link): rows varying the second joint angle, the motor size and the approach
velocity, with the arm drawn under each polar surface; a spatial arm gets a 3D surface and its x-y, x-z
and y-z sections. Every joint gets the Omni+ OPN-060-013-A scaled to --stator-diameter (Haddadin law) and
geared to the joint's torque requirement (N = max(1, tau_req / tau_p)). Default arm: {_DEFAULT_URDF}
(relative to the current directory), contact frame 'tip'.
"""


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add ``crx surface`` and its options to ``subparsers``."""
    parser = options.add_subcommand(subparsers, "surface", _HELP, _DESCRIPTION)
    _add_arm_options(parser)
    _add_actuation_options(parser)
    _add_sweep_options(parser)
    options.add_plot(parser, "reflex_surface.png")
    options.add_csv(parser, what="the baseline surface, one row per direction,")
    parser.set_defaults(run=run)


def _add_arm_options(parser: argparse.ArgumentParser) -> None:
    """The arm: its URDF or robot, contact frame and offset, packages, locked joints and configuration."""
    add = parser.add_argument
    source = parser.add_mutually_exclusive_group()
    source.add_argument(
        "--urdf", type=Path, default=None, metavar="FILE", help=f"URDF file (default {_DEFAULT_URDF})"
    )
    source.add_argument(
        "--robot",
        default=None,
        metavar="NAME",
        help="an example-robot-data robot: ur5, panda, double_pendulum, ...",
    )
    add(
        "--frame",
        default=None,
        metavar="NAME",
        help="contact frame (default 'tip' for a URDF, per robot otherwise)",
    )
    options.CONTACT_OFFSET.add(parser, nargs=3, shown="the frame's origin")
    add(
        "--package-dir",
        action="append",
        default=None,
        metavar="DIR",
        help="package:// directory (repeatable)",
    )
    add(
        "--lock",
        nargs="*",
        default=None,
        metavar="JOINT",
        help="joints to lock (default: per robot, e.g. Panda fingers)",
    )
    add(
        "--q",
        type=options.joint_position,
        nargs="+",
        default=None,
        metavar="Q",
        help="joint positions [deg/rad/m], each with its unit (30deg, 0.5rad; a prismatic joint's 0.1m); default q1 = 0, "
        "q2 = 45deg for a planar arm, the robot's reference pose otherwise",
    )


def _add_actuation_options(parser: argparse.ArgumentParser) -> None:
    """The motors, joint springs, controller stiffness, threshold and approach velocity of the baseline."""
    options.STATOR_DIAMETER.add(parser, _DEFAULTS["stator_diameter"])
    options.TORQUE_REQUIRED.add(
        parser, nargs="+", note="one value or one per joint", shown="the URDF effort limits"
    )
    options.JOINT_MECH_STIFFNESS.add(parser, _DEFAULTS["mechanical_stiffness"])
    options.JOINT_SOFT_STIFFNESS.add(parser, _DEFAULTS["software_stiffness"])
    options.TASK_STIFFNESS.add(parser, _DEFAULTS["task_stiffness"])
    options.THRESHOLD.add(parser, _DEFAULTS["F_s"])
    options.APPROACH_VELOCITY.add(parser, _DEFAULTS["v0"])


def _add_sweep_options(parser: argparse.ArgumentParser) -> None:
    """The stiffness form, the directions swept and the planar grid's rows.

    The rows: second joint angles, motor sizes, approach velocities.
    """
    add = parser.add_argument
    add(
        "--stiffness-form",
        choices=("compliance", "paper"),
        default="compliance",
        help="effective stiffness form (default %(default)s)",
    )
    add(
        "--directions",
        type=int,
        default=None,
        metavar="N",
        help="directions swept (default 360 planar, 2000 spatial)",
    )
    options.SECOND_JOINT_ANGLES.add(parser, _DEFAULTS["q2_values"])
    options.STATOR_DIAMETERS.add(
        parser,
        _DEFAULTS["stator_diameters"],
        note="the grid's second row",
    )
    options.APPROACH_VELOCITIES.add(parser, _DEFAULTS["velocities"], note="the grid's third row")


def run(args: argparse.Namespace) -> int:
    """Run ``crx surface`` with parsed ``args``; return the exit status."""
    check_figure_path(args.plot)
    arm = _load_arm(args)
    q = _configuration(arm, args.q)
    _check_torque(arm, args.torque)
    settings = {
        "task_stiffness": args.task_stiffness,
        "stiffness_form": args.stiffness_form,
        "directions": args.directions,
    }
    if args.directions is not None and args.directions < 3:
        raise InvalidParameter("--directions", args.directions, "at least 3")

    base_arm = _actuated(arm, args, args.stator_diameter)
    baseline = reflex_surface(base_arm, q, args.v0, **settings)
    _print_summary(base_arm, baseline)
    if args.csv is not None:
        _write_table(args.csv, baseline)
        print(f"wrote {args.csv}")
    if arm.task_dim == 2:
        written = _plot_planar_grid(arm, base_arm, q, args, settings)
    else:
        written = _plot_spatial(base_arm, baseline, q, args, settings)
    print(f"wrote {written}")
    return 0


def _load_arm(args: argparse.Namespace) -> Arm:
    """The arm named by ``--robot``, else read from ``--urdf`` (default the paper's two-link URDF)."""
    if args.robot is not None:
        return Arm.from_example_robot_data(args.robot, args.frame, args.offset, locked_joints=args.lock)
    path = args.urdf if args.urdf is not None else _DEFAULT_URDF
    return Arm.from_urdf(
        path, args.frame or "tip", args.package_dir, args.offset, locked_joints=args.lock or ()
    )


def _check_torque(arm: Arm, torque: list[float] | None) -> None:
    """Raise :class:`InvalidParameter` unless a torque requirement [N m] is known for every joint."""
    if torque is None and np.any(np.isnan(arm.urdf_torque_limit)):
        raise InvalidParameter(
            "--torque",
            None,
            f"a torque requirement [N m] for the joints of {arm.name}",
            "its URDF gives no effort limits; pass --torque T (one value or one per joint)",
        )
    if torque is not None and len(torque) not in (1, arm.nv):
        raise InvalidParameter("--torque", torque, f"one value or {arm.nv} values [N m]")


def _actuated(arm: Arm, args: argparse.Namespace, stator_diameter: float) -> Arm:
    """``arm`` with scaled motors of ``stator_diameter`` [m], and the springs and threshold of ``args``."""
    return arm.with_scaled_motors(
        stator_diameter,
        args.torque if args.torque is None or len(args.torque) > 1 else args.torque[0],
        mechanical_stiffness=args.mechanical_stiffness,
        software_stiffness=args.software_stiffness,
        sensing=ForceThreshold(args.F_s),
    )


def _plot_planar_grid(
    arm: Arm, base_arm: Arm, q: np.ndarray, args: argparse.Namespace, settings: dict[str, Any]
) -> Path:
    """The paper's grid for a planar arm: rows over the second joint angle, the motor size and ``v0``."""
    if arm.nv < 2:
        raise InvalidParameter("arm", arm.name, "at least two joints for the grid's second-joint row")
    angle_row = []
    for angle in args.q2_values:
        varied = q.copy()
        varied[_SECOND_JOINT] = math.radians(angle)
        angle_row.append(reflex_surface(base_arm, varied, args.v0, **settings))
    motor_row = [
        reflex_surface(_actuated(arm, args, d), q, args.v0, **settings) for d in args.stator_diameters
    ]
    velocity_row = [reflex_surface(base_arm, q, v, **settings) for v in args.velocities]
    rows = [
        SurfaceRow("second joint angle", angle_row, [f"q2 = {a:g}°" for a in args.q2_values]),
        SurfaceRow("motor size", motor_row, [f"r_m = {d * 1e3:g} mm" for d in args.stator_diameters]),
        SurfaceRow("approach velocity", velocity_row, [f"v0 = {v:g} m/s" for v in args.velocities]),
    ]
    title = (
        f"{arm.name}: q2 = {math.degrees(q[_SECOND_JOINT]):g}°, r_m = {args.stator_diameter * 1e3:g} mm, "
        f"v0 = {args.v0:g} m/s unless stated; F_s = {args.F_s:g} N"
    )
    return plot_planar_grid(args.plot, rows, title)


def _plot_spatial(
    base_arm: Arm, baseline: ReflexSurface, q: np.ndarray, args: argparse.Namespace, settings: dict[str, Any]
) -> Path:
    """A spatial arm's 3D surface with its sections in the x-y, x-z and y-z planes."""
    count = args.directions or 360
    sections = {
        name: reflex_surface(
            base_arm, q, args.v0, **{**settings, "directions": plane_directions(name, count)}
        )
        for name in COORDINATE_PLANES
    }
    title = (
        f"{base_arm.name} at q = {np.round(np.degrees(q), 1).tolist()} deg, "
        f"r_m = {args.stator_diameter * 1e3:g} mm, v0 = {args.v0:g} m/s"
    )
    return plot_spatial_surface(args.plot, baseline, sections, title)


def _configuration(arm: Arm, positions: list[float] | None) -> np.ndarray:
    """The configuration of ``positions`` [rad, prismatic joints m], else the default pose (see ``--q``)."""
    if positions is None:
        if arm.task_dim == 2 and not np.any(arm.reference_configuration):
            angles = np.zeros(arm.nv)
            angles[1] = math.radians(45.0)
            return arm.configuration(angles)
        return arm.reference_configuration.copy()
    if len(positions) != arm.nv:
        raise InvalidParameter("--q", positions, f"{arm.nv} joint positions, one per joint of {arm.name}")
    return arm.configuration(np.asarray(positions, dtype=float))


def _print_summary(arm: Arm, surface: ReflexSurface) -> None:
    """Print the arm, the extreme impulses [N s] and their directions, and the range of v* [m/s]."""
    impulse = surface.impulse
    finite = np.isfinite(impulse)
    smallest, largest = surface.extremes()
    print(
        f"{arm!r}: {surface.directions.shape[0]} directions, v0 = {surface.v0:g} m/s, "
        f"gear ratios {np.round([a.gear_ratio for a in arm.actuators or ()], 2).tolist()}"
    )
    print(f"smallest impulse {impulse.min():.4g} N*s along {np.round(smallest, 3).tolist()}")
    if np.all(finite):
        print(f"largest impulse  {impulse.max():.4g} N*s along {np.round(largest, 3).tolist()}")
    else:
        print(
            f"largest finite impulse {impulse[finite].max():.4g} N*s; {int((~finite).sum())} singular "
            f"direction(s) with infinite impulse, e.g. {np.round(largest, 3).tolist()}"
        )
    v_star = surface.impulses.v_star[finite]
    print(
        f"optimal approach velocity v* from {v_star.min():.4g} to {v_star.max():.4g} m/s over the directions"
    )


def _write_table(path: str, surface: ReflexSurface) -> None:
    """Write ``surface`` as CSV, one row per direction: effective parameters and impulses in SI."""
    import csv

    p, i = surface.parameters, surface.impulses
    columns = {
        **{f"u{axis}": surface.directions[:, axis] for axis in range(surface.task_dim)},
        "m_f_kg": p.m_f,
        "m_r_kg": p.m_r,
        "k_N_per_m": p.k,
        "k_m_N_per_m": p.k_m,
        "F_a_N": p.F_a,
        "a_m_per_s2": p.a,
        "F_s_N": i.threshold,
        "impulse_initial_Ns": i.initial,
        "impulse_sensing_Ns": i.sensing,
        "impulse_reaction_Ns": i.reaction,
        "impulse_total_Ns": i.total,
        "v_star_m_per_s": i.v_star,
        "singular": p.singular.astype(int),
    }
    with atomic_open(path, newline="") as handle:
        writer = csv.writer(handle)
        writer.writerow(columns)
        for row in zip(*columns.values(), strict=True):
            writer.writerow([f"{float(value):.9g}" for value in row])
