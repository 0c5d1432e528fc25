"""``crx safety``: permissible approach speeds of a run's design against a human body region."""

from __future__ import annotations

import argparse
import csv
import dataclasses

from .._io import atomic_open
from ..errors import InvalidParameter
from ..model.contact import BodyRegion
from . import options

_HELP = "permissible approach speeds of a run's design against a human body region (ISO/TS 15066)"
_DESCRIPTION = """
For each contact sample of a finished `crx run` (configuration and direction), the approach speed at which the
design's transient contact force on a body region just reaches the region's limit: v = F_T / sqrt(mu k_c), with
mu the reduced mass of the region and the design's effective mass along the direction (the finger alone against
a region much stiffer than the joints, the links with the rotors on them against a much softer one, the latter
as a bound in between). Beside it, the ISO/TS 15066 estimate without a dynamic model: half the moving mass plus
the payload. Exit status 2 if the folder, the design or a value cannot be used.
"""


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add ``crx safety`` and its options to ``subparsers``."""
    parser = options.add_subcommand(subparsers, "safety", _HELP, _DESCRIPTION)
    parser.add_argument(
        "run_dir", metavar="RUN_DIR", nargs="?", help="output folder of `crx run` (an arm study)"
    )
    parser.add_argument(
        "--region",
        default=None,
        metavar="NAME",
        help="a body region of the standard (hand_finger, chest, ...: `crx safety --list-regions`) or of --regions",
    )
    parser.add_argument(
        "--regions", default=None, metavar="FILE", help="a body-region YAML file (default: the standard's)"
    )
    parser.add_argument("--list-regions", action="store_true", help="list the body regions and exit")
    options.REGION_STIFFNESS.add(parser, note="overrides the named region's")
    options.REGION_MASS.add(parser, note="overrides the named region's")
    options.TRANSIENT_FORCE.add(parser, note="overrides the named region's")
    options.add_design(parser)
    options.add_csv(parser, what="one row per contact sample")
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    """Run ``crx safety`` with parsed ``args``; return the exit status."""
    from ..study.body_regions import load_body_regions  # lazy: the catalogue reader
    from ..study.safety import speed_map  # lazy: casadi and pinocchio (the run's study)

    regions = load_body_regions(args.regions)
    if args.list_regions:
        for name, r in regions.items():
            transient = (
                "no transient contact" if r.transient_force is None else f"F_T {r.transient_force:g} N"
            )
            print(f"{name}: k_c {r.stiffness / 1e3:g} N/mm, m_H {r.mass:g} kg, {transient}")
        return 0
    figures = {
        "stiffness": args.region_stiffness,
        "mass": args.region_mass,
        "transient_force": args.transient_force,
    }
    if args.region is not None:
        if args.region not in regions:
            raise InvalidParameter("--region", args.region, "one of " + ", ".join(regions))
        region = dataclasses.replace(
            regions[args.region], **{k: v for k, v in figures.items() if v is not None}
        )
    elif None in figures.values():
        raise InvalidParameter(
            "--region",
            "missing",
            "a body region's name",
            "or all of --region-stiffness, --region-mass and --transient-force",
        )
    else:
        region = BodyRegion("body region", **figures)
    if args.run_dir is None:
        raise InvalidParameter("RUN_DIR", "missing", "the output folder of `crx run` of an arm study")
    result = speed_map(args.run_dir, region, args.design)
    for line in result.summary():
        print(line)
    if args.csv is not None:
        rows = result.rows()
        with atomic_open(args.csv, newline="") as handle:
            writer = csv.DictWriter(handle, fieldnames=list(rows[0]))
            writer.writeheader()
            writer.writerows(rows)
        print(f"wrote {args.csv}")
    return 0
