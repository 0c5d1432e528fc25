"""``crx validate``: check study files, reporting every problem with its file and line."""

from __future__ import annotations

import argparse
import contextlib
import sys

from ..errors import StudyFileError
from . import options, start_up

_HELP = "check study files (schema, units, robot, frames, joints, duty cycle); every problem with its line"
_DESCRIPTION = """
Check design-study files without running them: the schema (unknown keys, units of the right dimension,
bounds), and for arm studies the robot, its contact frame, joint names and sizes, and the duty cycle (a
trajectory file's problems quote its own line: found cycle.csv:17: ...). A valid arm study's summary ends
with its duty cycle (duration, samples, peak joint speed) or says that its torque requirement is the
static one. Every problem is printed as FILE:LINE:COLUMN: FIELD: found ...; expected ... . Exit status 2
if any file has a problem.
"""


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add ``crx validate`` and its options to ``subparsers``."""
    parser = options.add_subcommand(subparsers, "validate", _HELP, _DESCRIPTION, units=False)
    parser.add_argument("studies", nargs="+", metavar="STUDY", help="study file(s) (YAML)")
    parser.add_argument(
        "--schema-only",
        action="store_true",
        help="skip the checks that load the robot model (faster; names of frames and joints are not checked)",
    )
    parser.add_argument("--resolved", action="store_true", help="print the resolved study (YAML, SI units)")
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    """Run ``crx validate`` with parsed ``args``; return the exit status."""
    status = 0
    for index, path in enumerate(args.studies):
        # The first study is still start-up: its checks import what they need (pydantic, pint, Pinocchio).
        with start_up() if index == 0 else contextlib.nullcontext():
            status = max(status, _validate(path, args))
    return status


def _validate(path: str, args: argparse.Namespace) -> int:
    """Check one study file, printing its summary or its problems; return its exit status."""
    from ..study import load_study, resolved_yaml  # lazy: pydantic and yaml (the study schema)
    from ..study.prepare import describe_study

    try:
        loaded = load_study(path)
        summary = describe_study(loaded, load_robot=not args.schema_only)
    except StudyFileError as error:
        for problem in error.problems:
            print(problem, file=sys.stderr)
        return 2
    print(f"{path}: valid — {summary}")
    if args.resolved:
        print(resolved_yaml(loaded))
    return 0
