"""``crx robots``: the robots a study's ``robot: {example_robot_data: NAME}`` can name."""

from __future__ import annotations

import argparse

from . import options

_HELP = "list the robots a study can name, with their joints and contact frames"
_DESCRIPTION = """
List the robots of example-robot-data that a study's robot: {example_robot_data: NAME} can name: base
(fixed or floating), joints, the contact frame a study would use (the robot's default, or the tip of its
longest chain of revolute joints) and how many revolute joints lead to it. 'init' marks those crx init
writes a study for (a fixed base and two or more joints to the contact frame).
"""


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add ``crx robots`` to ``subparsers``."""
    parser = options.add_subcommand(subparsers, "robots", _HELP, _DESCRIPTION, units=False)
    parser.add_argument("--all", action="store_true", help="also list the robots crx init cannot start from")
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    """Run ``crx robots`` with parsed ``args``; return the exit status."""
    from ..study.starter import robot_entries  # lazy: pydantic and yaml (the study schema)

    entries = [entry for entry in robot_entries() if args.all or entry.startable]
    width = max(len(entry.name) for entry in entries)
    frames = max(len(entry.contact_frame or "-") for entry in entries)
    print(f"{'robot':<{width}}  base      joints  {'contact frame':<{frames}}  chain  crx init")
    for entry in entries:
        verdict = "yes" if entry.startable else f"no: {entry.reason}"
        print(
            f"{entry.name:<{width}}  {entry.base:<8}  {entry.joints:>6}  {entry.contact_frame or '-':<{frames}}  "
            f"{len(entry.chain):>5}  {verdict}"
        )
    if not args.all:
        print(f"({len(entries)} robots; crx robots --all also lists floating-base robots and the others)")
    return 0
