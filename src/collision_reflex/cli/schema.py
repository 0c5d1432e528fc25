"""``crx schema``: the JSON Schema of study files (for editors that complete and check YAML)."""

from __future__ import annotations

import argparse
import json

from .._io import atomic_open
from . import options

_HELP = "print the JSON Schema of study files"
_DESCRIPTION = """
Print the JSON Schema of design-study files. Save it and point your editor at it, e.g. with the first line
'# yaml-language-server: $schema=study.schema.json'.
"""


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add ``crx schema`` and its options to ``subparsers``."""
    parser = options.add_subcommand(subparsers, "schema", _HELP, _DESCRIPTION, units=False)
    parser.add_argument(
        "--json",
        metavar="FILE",
        default=None,
        help="write to FILE (atomically) instead of stdout",
    )
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    """Run ``crx schema`` with parsed ``args``; return the exit status."""
    from ..study import study_json_schema  # lazy: pydantic and yaml (the study schema)

    text = json.dumps(study_json_schema(), indent=2) + "\n"
    if args.json is None:
        print(text, end="")
    else:
        with atomic_open(args.json, "w", encoding="utf-8") as handle:
            handle.write(text)
        print(f"wrote {args.json}")
    return 0
