"""``crx init``: write a commented, valid design study for a robot, to start one's own from."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from .._io import atomic_open
from ..errors import InvalidParameter, StudyFileError
from . import options

_HELP = "write a starting design study for a robot (a name crx robots lists, or a URDF file)"
_DESCRIPTION = """
Write a commented design study for ROBOT: an example-robot-data name (crx robots lists them) or a URDF
file. Its actuated joints are the revolute joints from the base to the contact frame (the others are
locked); its motor-size bounds follow the URDF's effort limits, its rated joint speeds the URDF's velocity
limits, its rated payload what those effort limits hold, and its duty cycle stays within the joint limits.
Every figure not read from the robot is marked ESTIMATE (with how it was made) or SET (yours to give). The
study is checked before it is written.
"""


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add ``crx init`` and its options to ``subparsers``."""
    parser = options.add_subcommand(subparsers, "init", _HELP, _DESCRIPTION, units=False)
    parser.add_argument("robot", metavar="ROBOT", help="an example-robot-data name, or a URDF file")
    parser.add_argument("--frame", default=None, help="the contact frame (default: the robot's tool or tip)")
    parser.add_argument(
        "--out", metavar="FILE", default=None, help="the study file to write (default: ROBOT.yaml here)"
    )
    options.RATED_PAYLOAD.add(parser, note="default: an estimate from the URDF's effort limits")
    parser.add_argument("--force", action="store_true", help="replace FILE if it exists")
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    """Run ``crx init`` with parsed ``args``; return the exit status."""
    from ..study import parse_study  # lazy: pydantic and yaml (the study schema)
    from ..study.prepare import describe_study
    from ..study.starter import starter_study  # lazy: pydantic and yaml (the study schema)

    out = Path(args.out) if args.out is not None else Path(f"{Path(args.robot).stem}.yaml")
    if out.exists() and not args.force:
        raise InvalidParameter("--out", str(out), "a file that does not exist yet", "--force replaces it")
    if out.is_dir():
        raise InvalidParameter("--out", str(out), "a file name, not a folder")
    text = starter_study(args.robot, out, args.frame, args.payload)
    try:  # the study as it will be read from its folder
        describe_study(parse_study(text, str(out), out.resolve().parent))
    except StudyFileError as error:  # a study this command wrote must be valid: say so, write nothing
        print(f"crx init: the study written for {args.robot} does not validate:\n{error}", file=sys.stderr)
        return 1
    out.parent.mkdir(parents=True, exist_ok=True)
    with atomic_open(out, "w", encoding="utf-8") as handle:
        handle.write(text)
    print(f"wrote {out}: check it with `crx validate {out}`, run it with `crx run {out} --smoke`")
    return 0
