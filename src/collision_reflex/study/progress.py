"""Progress bars of a study run, on stderr."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any


class RunProgress:
    """Rich progress bars on stderr (none when quiet).

    Drawn from the first bar on: the bars' refresh thread starts then, after the run's executor has started
    its workers (a local pool forks them: :data:`~collision_reflex.study.executors.START_METHOD`).
    """

    def __init__(self, quiet: bool) -> None:
        self._bar: Any = None
        if not quiet:
            from rich.console import Console
            from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn

            self._bar = Progress(
                TextColumn("{task.description}"),
                BarColumn(),
                MofNCompleteColumn(),
                TimeElapsedColumn(),
                console=Console(stderr=True),
            )

    def _add(self, description: str, **counts: int) -> Any:
        if not self._bar.live.is_started:
            self._bar.start()
        return self._bar.add_task(description, **counts)

    def stage(self, description: str, total: int, done: int = 0) -> Callable[[], None]:
        """An ``advance()`` callback drawing one bar of ``total`` steps, ``done`` of them done."""
        if self._bar is None:
            return lambda: None
        task = self._add(description, total=total, completed=done)
        return lambda: self._bar.advance(task)

    def counter(self, description: str) -> Callable[[int, int], None]:
        """A ``progress(done, total)`` callback drawing one bar."""
        state: dict[str, Any] = {}

        def update(done: int, total: int) -> None:
            if self._bar is None:
                return
            if "task" not in state:
                state["task"] = self._add(description, total=total)
            self._bar.update(state["task"], completed=done, total=total)

        return update

    def stop(self) -> None:
        """Stop drawing (the bars stay as drawn)."""
        if self._bar is not None:
            self._bar.stop()
            self._bar = None
