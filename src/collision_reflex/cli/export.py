"""``crx export``: write a run's design as a robot model for simulators (URDF with motors, MJCF with armature)."""

from __future__ import annotations

import argparse
from pathlib import Path

from ..vocabulary import EXPORT_FORMATS
from . import options

_HELP = "write a run's design as URDF (motor masses, transmissions, limits) or MJCF (armature, motors)"
_DESCRIPTION = """
Write the arm of a `crx run` output folder with the actuators of one of its designs. URDF: each motor (and
gearbox) as a point mass on its parent link at the joint origin (a link JOINT_actuator on a fixed joint),
a transmission per joint with the gear ratio and rotor inertia, effort limits N tau_p [N*m] and velocity
limits omega_max / N [rad/s], and beside it FILE.armature.json with the armature N^2 (J_m + J_g) [kg*m^2]
per joint for Pinocchio's model.armature, and the meshes it references, copied into STEM_meshes/ (MuJoCo,
Pinocchio and Drake load the URDF as written). MJCF (needs the 'mujoco' extra): the same arm with the armature,
a geared motor actuator per joint and its torque ranges. Exit status 2 if the folder, the design or the
output is unusable.
"""


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add ``crx export`` and its options to ``subparsers``."""
    parser = options.add_subcommand(subparsers, "export", _HELP, _DESCRIPTION, units=False)
    parser.add_argument("run_dir", metavar="RUN_DIR", help="output folder of `crx run` (an arm study)")
    options.add_design(parser)
    parser.add_argument("--format", choices=EXPORT_FORMATS, required=True, help="the robot format to write")
    options.add_out_file(parser, what="the robot model (.urdf or MJCF .xml)")
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    """Run ``crx export`` with parsed ``args``; return the exit status."""
    from ..export import export_design  # lazy: pydantic and yaml (the run's study)

    written = export_design(args.run_dir, args.design, args.format, args.out)
    models = [p for p in written if p.suffix in (".urdf", ".xml", ".json")]
    for path in models:
        print(path)
    meshes = [p for p in written if p not in models]
    if meshes:
        print(f"{len(meshes)} meshes copied to {Path(args.out).with_name(Path(args.out).stem + '_meshes')}")
    return 0
