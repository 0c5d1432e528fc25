"""``crx run``: run a design study end to end and write its results and sizing report."""

from __future__ import annotations

import argparse
import sys

from ..vocabulary import EXECUTORS
from . import options

_HELP = "run a design study (YAML) end to end: designs, Pareto front, figures, report.html"
_DESCRIPTION = """
Run a design study: check it (nothing is written if the study has a problem), solve the designs through
the study's executor, and write the resolved study, pareto.csv, designs.json, figures (PNG and SVG) and
report.html to the output folder. Run the same command again after an interruption to resume from the
finished Pareto points.
"""


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add ``crx run`` and its options to ``subparsers``."""
    parser = options.add_subcommand(subparsers, "run", _HELP, _DESCRIPTION, units=False)
    parser.add_argument("study", metavar="STUDY", help="study file (YAML)")
    options.add_out_dir(parser, what="the results and the report", shown="results/NAME")
    parser.add_argument("--quiet", action="store_true", help="no progress bars; print only the report's path")
    parser.add_argument(
        "--scheduler",
        metavar="ADDR",
        default=None,
        help="run on the Dask cluster at ADDR (e.g. tcp://host:8786); needs the 'dask' extra",
    )
    parser.add_argument(
        "--executor",
        choices=EXECUTORS,
        default=None,
        help="override the study's executor",
    )
    parser.add_argument(
        "--workers", type=int, default=None, metavar="N", help="override the number of workers"
    )
    parser.add_argument(
        "--smoke",
        action="store_true",
        help="shrink sample counts and Pareto points for a quick check (also: CRX_SMOKE=1)",
    )
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    """Run ``crx run`` with parsed ``args``; return the exit status."""
    from ..study.runner import run_study  # lazy: casadi (the optimiser)

    if args.workers is not None and args.workers < 1:
        print("crx run: error: --workers must be at least 1", file=sys.stderr)
        return 2
    result = run_study(
        args.study,
        args.out,
        quiet=args.quiet,
        scheduler=args.scheduler,
        executor=args.executor,
        workers=args.workers,
        smoke=True if args.smoke else None,
    )
    if not args.quiet:
        for line in result.verdict:
            print(line)
        how = f"{result.computed} computed" + (
            f", {result.reused} reused from the interrupted run" if result.reused else ""
        )
        print(f"finished in {result.elapsed:.1f} s ({how})")
    print(result.report)
    return 0
