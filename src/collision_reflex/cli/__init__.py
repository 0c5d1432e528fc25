"""The ``crx`` command line: one module per subcommand, each with ``register(subparsers)``.

Every option is declared once in :mod:`.options` (flag, unit, parser, range). Errors raised on purpose
(:class:`~collision_reflex.errors.CollisionReflexError`) and usage errors are printed as one line on stderr and
exit with status 2 (or the error's ``exit_status``: 1 for a failure after work started); Ctrl-C exits with 130.
"""

from __future__ import annotations

import argparse
import contextlib
import gc
import importlib
import os
import signal
import sys
from collections.abc import Iterator, Sequence

from .. import __version__, _units
from .._interrupt import caused_by_interrupt
from ..errors import CollisionReflexError
from . import options

# Subcommands, in the order `crx --help` lists them; each is the module of its name, with `register(subparsers)`.
SUBCOMMANDS = (
    "impulse",
    "motors",
    "sweep",
    "surface",
    "fit",
    "simulate",
    "robots",
    "init",
    "validate",
    "schema",
    "run",
    "report",
    "export",
    "safety",
)


def build_parser(command: str | None = None) -> argparse.ArgumentParser:
    """The ``crx`` parser with every subcommand, or with ``command``'s alone.

    A subcommand's module imports what its options need (the model's constants, the catalogues); parsing
    ``crx validate ...`` with the validate subcommand alone keeps the others' imports out of its start-up.
    """
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
    for name in SUBCOMMANDS if command is None else (command,):
        importlib.import_module(f".{name}", __name__).register(subparsers)
    return parser


@contextlib.contextmanager
def start_up() -> Iterator[None]:
    """No cyclic garbage collection inside, and the objects made inside left out of every later one.

    For the imports and first steps of a command: their objects (modules, classes, schemas, the unit registry)
    live to its end, and the collector would walk them again and again as they are created, and at each full
    collection. They are frozen (:func:`gc.freeze`) at the end of the block, with the little garbage among
    them.
    """
    collecting = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        gc.freeze()
        if collecting:
            gc.enable()


def main(argv: Sequence[str] | None = None) -> int:
    """Run ``crx`` with ``argv`` (default: the process's arguments) and return its exit status.

    The ``crx`` process keeps what :func:`start_up` froze until it exits (so that its exit does not walk it
    either), and ignores Ctrl-C once the command has returned (its status is decided; the exit only flushes);
    called with ``argv`` (from Python: tests, scripts) it unfreezes it on return, leaving the caller's garbage
    collector and signal handlers as it found them.
    """
    frozen = gc.get_freeze_count()
    try:
        return _command(sys.argv[1:] if argv is None else list(argv))
    finally:
        if argv is not None and not frozen:
            gc.unfreeze()
        if argv is None:
            # The command is done and its status decided: a Ctrl-C while the interpreter exits would only
            # turn a finished run's status into "killed by SIGINT".
            signal.signal(signal.SIGINT, signal.SIG_IGN)


def _command(arguments: list[str]) -> int:
    with start_up():
        # The command is the first argument (the options before it are --help and --version, which need them all).
        parser = build_parser(arguments[0] if arguments and arguments[0] in SUBCOMMANDS else None)
        try:
            args = parser.parse_args(arguments)
        except SystemExit as done:  # --help, --version, or a usage error already printed as one line
            return done.code if isinstance(done.code, int) else 0 if done.code is None else 2
    _units.hide_pint_extras()
    _units.cache_registry()
    try:
        try:
            status = int(args.run(args) or 0)
        except Exception as error:
            if caused_by_interrupt(error):  # Ctrl-C surfacing as another error (an import cut short, say)
                raise KeyboardInterrupt from error
            raise
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
