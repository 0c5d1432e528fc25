"""Ctrl-C that CasADi's symbolic code cannot lose.

CasADi's Python operators pick among overloads by calling Python helpers (``DM_from_array``, ``IM_from_array``,
...) to test each argument; a Ctrl-C whose ``KeyboardInterrupt`` is raised inside such a test is taken for "this
overload does not match" and cleared, so the interrupt is lost and the work goes on (a study run then
finishes normally, with exit status 0), or it surfaces as another error, such as a ``SystemError`` (an exception
left set while NumPy converted a CasADi matrix). Problem construction, solves, each catalogue combination's work
and every stage of a study run run inside :func:`interruptible`, which records every Ctrl-C and raises
``KeyboardInterrupt`` when its block ends if the interrupt was lost, or instead of an error the interrupt
caused (``benchmarks/ctrl_c_runs.py`` sends the interrupts and counts the outcomes).
"""

from __future__ import annotations

import contextlib
import signal
import threading
from collections.abc import Iterator
from types import FrameType


@contextlib.contextmanager
def interruptible() -> Iterator[None]:
    """A block in which a Ctrl-C (SIGINT) always ends in ``KeyboardInterrupt``, at the latest when it ends.

    The signal's handler is the one in place (usually Python's, which raises ``KeyboardInterrupt`` at once),
    with each ``KeyboardInterrupt`` it raises also recorded: if the block then ends normally, ``KeyboardInterrupt`` is raised; if it
    ends with another exception, that exception becomes the ``KeyboardInterrupt``'s cause. An ignored SIGINT
    (a pool's worker ignores it: its parent stops it) stays ignored. Outside the main thread, where signal
    handlers cannot be set, the block runs unchanged. Also a decorator.
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.getsignal(signal.SIGINT)
    if previous == signal.SIG_IGN:
        yield
        return
    interrupted = False

    def handler(signum: int, frame: FrameType | None) -> None:
        nonlocal interrupted
        if callable(previous):  # Python's own raises KeyboardInterrupt; a caller's may do something else
            try:
                previous(signum, frame)
            except KeyboardInterrupt:
                interrupted = True
                raise
            return
        interrupted = True  # SIG_DFL: stop, as Python's handler does
        raise KeyboardInterrupt

    signal.signal(signal.SIGINT, handler)
    try:
        yield
    except KeyboardInterrupt:
        raise
    except BaseException as error:
        if interrupted:
            raise KeyboardInterrupt from error
        raise
    finally:
        signal.signal(signal.SIGINT, previous)
    if interrupted:
        raise KeyboardInterrupt


def caused_by_interrupt(error: BaseException) -> bool:
    """Whether ``error`` is a ``KeyboardInterrupt`` or was raised while handling one (its cause or context).

    A Ctrl-C that arrives while a C extension runs (a module's initialisation, a conversion of CasADi's) can
    surface as another error, an ``ImportError`` or a ``SystemError``, with the ``KeyboardInterrupt`` as its
    context: it is the interrupt all the same.
    """
    seen: set[int] = set()
    current: BaseException | None = error
    while current is not None and id(current) not in seen:
        if isinstance(current, KeyboardInterrupt):
            return True
        seen.add(id(current))
        current = current.__cause__ or current.__context__
    return False
