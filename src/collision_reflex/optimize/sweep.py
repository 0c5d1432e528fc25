"""Where the pieces of a sweep run, and how finished ones are kept.

A :class:`Runner` says which executor, how many pieces at a time, how finished pieces are kept and found
again, and whom to tell of the progress. A piece is named (``anchor-<objective>``, ``point-007``, ``optimum``)
and gives a :class:`~collision_reflex.optimize.results.SweepPoint`; one found finished is not run again, so
that a sweep resumed after an interruption redoes only the rest.
"""

from __future__ import annotations

import contextlib
from collections.abc import Callable, Iterable, Mapping
from concurrent.futures import FIRST_COMPLETED, Executor, Future, wait
from dataclasses import dataclass
from typing import Any

from ..errors import InvalidParameter
from .results import SweepPoint
from .serial import SerialExecutor

FinishedHook = Callable[[str], Mapping[str, Any] | None]
"""``finished(name)``: the saved JSON of a finished piece of a sweep (``anchor-<objective>``, ``point-007``),
or None to compute it."""
SaveHook = Callable[[str, dict[str, Any]], None]
"""``save(name, data)``: keep a piece of a sweep as it finishes (JSON types)."""


def check_count(name: str, value: object, least: int) -> None:
    """Refuse a count (of points, starts, pieces) that is not an integer of at least ``least``."""
    if not isinstance(value, int) or isinstance(value, bool) or value < least:
        raise InvalidParameter(name, value, f"an integer >= {least}")


@dataclass(frozen=True)
class Runner:
    """Where the pieces of a sweep run, how finished ones are kept, and whom to tell of the progress.

    The default runs every piece in this process, one at a time, and keeps nothing.

    executor: where the pieces run (default: in this process, :class:`~.serial.SerialExecutor`); a process
        pool or a Dask client's executor give the same numbers.
    in_flight: pieces submitted at a time (default 1 in-process, all otherwise); finished pieces are saved
        while the others run.
    finished, save: keep each finished piece (``save(name, json)``) and find it again (``finished(name)``), so
        that a sweep resumed after an interruption redoes only the rest.
    progress: called as ``progress(done, total)`` after each piece.
    """

    executor: Executor | None = None
    in_flight: int | None = None
    finished: FinishedHook | None = None
    save: SaveHook | None = None
    progress: Callable[[int, int], None] | None = None

    def schedule(self, total: int) -> Schedule:
        """A new schedule of (about) ``total`` pieces, nothing done yet.

        Raises
        ------
        InvalidParameter: ``in_flight`` is not an integer >= 1.
        """
        check_count("in_flight", 1 if self.in_flight is None else self.in_flight, 1)
        return Schedule(self, total)


class Schedule:
    """Runs named pieces as a :class:`Runner` says, a few at a time, reusing and saving finished ones.

    total: the pieces to report progress against (a sweep sets it once it knows its grid); done, computed,
    reused: the pieces finished so far, of them run now and found finished.
    """

    def __init__(self, runner: Runner, total: int) -> None:
        self.executor = runner.executor or SerialExecutor()
        self.in_flight = runner.in_flight or (1 if runner.executor is None else 10**6)
        self.finished, self.save, self.progress = runner.finished, runner.save, runner.progress
        self.total, self.done, self.computed, self.reused = total, 0, 0, 0

    def _tick(self) -> None:
        self.done += 1
        if self.progress is not None:
            self.progress(self.done, self.total)

    def run(
        self, tasks: Mapping[str, tuple[Callable[..., SweepPoint], tuple[object, ...]]]
    ) -> dict[str, SweepPoint]:
        """Every task's :class:`SweepPoint`, in the order of ``tasks``."""
        out: dict[str, SweepPoint] = {}
        queue = []
        for name, task in tasks.items():
            saved = _reusable(self.finished(name)) if self.finished is not None else None
            if saved is not None:
                out[name] = saved
                self.reused += 1
                self._tick()
            else:
                queue.append((name, task))
        pending: dict[Future, str] = {}
        try:
            while queue or pending:
                while queue and len(pending) < self.in_flight:
                    name, (function, args) = queue.pop(0)
                    pending[self.executor.submit(function, *args)] = name
                done, _ = wait(pending, return_when=FIRST_COMPLETED)
                self._collect(done, pending, out)
        except BaseException:
            for future in pending:
                future.cancel()
            # Interrupted (or failed): keep what finished meanwhile, so that the resumed run need not redo it.
            finished = [f for f in pending if f.done() and not f.cancelled() and f.exception() is None]
            with contextlib.suppress(Exception):
                self._collect(finished, pending, out)
            raise
        return {name: out[name] for name in tasks}

    def _collect(
        self, done: Iterable[Future], pending: dict[Future, str], out: dict[str, SweepPoint]
    ) -> None:
        """Take the results of ``done`` futures out of ``pending`` into ``out``, saving each."""
        for future in sorted(done, key=lambda f: pending[f]):
            name = pending.pop(future)
            out[name] = future.result()
            if self.save is not None:
                self.save(name, out[name].to_json())
            self.computed += 1
            self._tick()


def _reusable(saved: Mapping[str, Any] | None) -> SweepPoint | None:
    """A saved piece, or None if there is none or it is not one (another version's file): then it is redone."""
    if saved is None:
        return None
    try:
        return SweepPoint.from_json(saved)
    except (AttributeError, KeyError, TypeError, ValueError):
        return None
