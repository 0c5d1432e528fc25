"""``crx report``: re-render a run's figures and report.html (and PDF) from its saved results."""

from __future__ import annotations

import argparse

from ..report import render_report
from ..report.pdf import html_to_pdf
from . import options

_HELP = "re-render figures and report.html from a run's saved results"
_DESCRIPTION = "Redraw the figures and rewrite report.html of an output folder from its designs.json."


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add ``crx report`` and its options to ``subparsers``."""
    parser = options.add_subcommand(subparsers, "report", _HELP, _DESCRIPTION, units=False)
    parser.add_argument("folder", metavar="DIR", help="output folder of `crx run`")
    parser.add_argument("--pdf", action="store_true", help="also print report.pdf with headless Chromium")
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    """Run ``crx report`` with parsed ``args``; return the exit status."""
    from pathlib import Path

    path = render_report(args.folder)
    print(path)
    if args.pdf:
        print(html_to_pdf(path, Path(args.folder) / "report.pdf"))
    return 0
