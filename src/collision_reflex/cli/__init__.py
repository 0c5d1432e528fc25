"""The ``crx`` command line: one module per subcommand, each with ``register(subparsers)``.

Every option is declared once in :mod:`.options` (flag, unit, parser, range). Errors raised on purpose
(:class:`~collision_reflex.errors.CollisionReflexError`) and usage errors are printed as one line on stderr and
exit with status 2 (or the error's ``exit_status``: 1 for a failure after work started); Ctrl-C exits with 130.
"""

from __future__ import annotations

import argparse
import os
import sys
from collections.abc import Sequence

from .. import __version__, _units
from ..errors import CollisionReflexError
from . import export as _export
from . import fit as _fit
from . import impulse as _impulse
from . import motors as _motors
from . import options
from . import report as _report
from . import run as _run
from . import schema as _schema
from . import simulate as _simulate
from . import surface as _surface
from . import sweep as _sweep
from . import validate as _validate

# Subcommand modules, in the order `crx --help` lists them.
_SUBCOMMANDS = [
    _impulse,
    _motors,
    _sweep,
    _surface,
    _fit,
    _simulate,
    _validate,
    _schema,
    _run,
    _report,
    _export,
]


def build_parser() -> argparse.ArgumentParser:
    """The ``crx`` parser with every subcommand."""
    parser = options.Parser(
        prog="crx",
        description=(
            "collision-reflex: evaluate and optimise the impulse a robot transfers in a surprise contact "
            "(detect, stop, back away)."
        ),
        epilog=options.UNITS_EPILOG,
    )
    parser.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for module in _SUBCOMMANDS:
        module.register(subparsers)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run ``crx`` with ``argv`` (default: the process's arguments) and return its exit status."""
    parser = build_parser()
    try:
        args = parser.parse_args(argv)
    except SystemExit as done:  # --help, --version, or a usage error already printed as one line
        return done.code if isinstance(done.code, int) else 0 if done.code is None else 2
    _units.hide_pint_extras()
    try:
        status = int(args.run(args) or 0)
        sys.stdout.flush()  # a closed pipe shows here, not in the interpreter's exit flush
        return status
    except CollisionReflexError as error:
        print(f"crx {args.command}: error: {error}", file=sys.stderr)
        return int(getattr(error, "exit_status", 2))
    except KeyboardInterrupt:
        hint = "; rerun the same command to resume" if args.command == "run" else ""
        print(f"crx {args.command}: interrupted{hint}", file=sys.stderr)
        return 130
    except BrokenPipeError:
        # The reader left (`crx ... | head`): stop quietly; point stdout at nothing so the exit flush is silent.
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        os.close(devnull)
        return 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
