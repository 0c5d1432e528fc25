"""The ``crx`` command line: one module per subcommand, each with ``register(subparsers)``.

Errors raised on purpose (:class:`~collision_reflex.errors.CollisionReflexError`) are printed as one line and
exit with status 2; argparse's usage errors exit with status 2 as well.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence

from .. import __version__
from ..errors import CollisionReflexError
from . import fit as _fit
from . import impulse as _impulse
from . import motors as _motors
from . import report as _report
from . import run as _run
from . import schema as _schema
from . import simulate as _simulate
from . import surface as _surface
from . import sweep as _sweep
from . import validate as _validate

# Subcommand modules, in the order `crx --help` lists them.
_SUBCOMMANDS = [_impulse, _motors, _sweep, _surface, _fit, _simulate, _validate, _schema, _run, _report]


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="crx",
        description=(
            "collision-reflex: evaluate and optimise the impulse a robot transfers in a surprise contact "
            "(detect, stop, back away). All plain numbers are SI: kg, m, s, N, N/m, N*s."
        ),
    )
    parser.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for module in _SUBCOMMANDS:
        module.register(subparsers)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return int(args.run(args) or 0)
    except CollisionReflexError as error:
        print(f"crx {args.command}: error: {error}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f"crx {args.command}: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
