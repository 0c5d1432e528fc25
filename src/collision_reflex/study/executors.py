"""Executors for a study's independent work (Pareto points, sample chunks).

In-process, a local process pool, or a Dask distributed cluster. All are :class:`concurrent.futures.Executor`;
nothing here schedules work itself.
"""

from __future__ import annotations

import contextlib
import ctypes
import multiprocessing
import os
import signal
import sys
import threading
import time
from collections.abc import Iterator
from concurrent.futures import Executor, ProcessPoolExecutor

from ..errors import CollisionReflexError, InvalidParameter
from ..optimize.serial import SerialExecutor

EXECUTORS = ("serial", "processes", "dask")
__all__ = ["EXECUTORS", "DaskUnavailable", "SerialExecutor", "open_executor"]


class DaskUnavailable(CollisionReflexError):
    """Dask's distributed scheduler is needed but not installed (or the cluster cannot be reached)."""


@contextlib.contextmanager
def open_executor(kind: str = "serial", workers: int = 2, scheduler: str | None = None) -> Iterator[Executor]:
    """An executor of ``kind``, shut down on exit.

    Parameters
    ----------
    kind: ``"serial"``, ``"processes"`` (a local pool of ``workers`` processes) or ``"dask"``.
    workers: number of local worker processes (``processes``; ``dask`` without a scheduler address).
    scheduler: address of a Dask scheduler (``tcp://host:8786``); giving one implies ``dask``. Without it,
        ``dask`` starts a local cluster of ``workers`` processes.
    """
    if scheduler is not None:
        kind = "dask"
    if kind not in EXECUTORS:
        raise InvalidParameter("executor", kind, "one of " + ", ".join(EXECUTORS))
    if not isinstance(workers, int) or workers < 1:
        raise InvalidParameter("workers", workers, "an integer >= 1")
    if kind == "serial":
        yield SerialExecutor()
    elif kind == "processes":
        # "spawn": workers start clean (no copied locks or solver state from this process), the same on every OS.
        pool = ProcessPoolExecutor(
            max_workers=workers,
            mp_context=multiprocessing.get_context("spawn"),
            initializer=_die_with_parent,
            initargs=(os.getpid(),),
        )
        try:
            yield pool
        except BaseException:
            _stop(pool)  # an interrupt or a failure: do not wait for the solves in flight
            raise
        pool.shutdown(wait=True)
    else:
        with _dask_executor(workers, scheduler) as executor:
            yield executor


def _stop(pool: ProcessPoolExecutor) -> None:
    """Cancel the queued work and end the workers now."""
    processes = list(getattr(pool, "_processes", {}).values())  # the pool offers no public way before 3.14
    pool.shutdown(wait=False, cancel_futures=True)
    for process in processes:
        process.terminate()
    for process in processes:
        process.join(timeout=5)


def _die_with_parent(parent: int) -> None:
    """Worker initializer: end this worker when the run's process ends, even by ``kill -9``.

    On Linux the kernel does it (``PR_SET_PDEATHSIG``); elsewhere a daemon thread watches the parent. Ctrl-C is
    left to the parent, which stops the workers (a worker interrupted while idle would print a traceback).
    """
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    if sys.platform.startswith("linux"):
        with contextlib.suppress(OSError, AttributeError):
            libc = ctypes.CDLL(None, use_errno=True)
            if libc.prctl(_PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0) == 0:
                if os.getppid() != parent:  # the parent died before the call
                    os._exit(1)
                return
    threading.Thread(target=_watch_parent, args=(parent,), daemon=True).start()


_PR_SET_PDEATHSIG = 1
"""``prctl`` option: the signal the kernel sends this process when its parent ends (linux/prctl.h)."""


def _watch_parent(parent: int) -> None:
    while os.getppid() == parent:
        time.sleep(1.0)
    os._exit(1)


@contextlib.contextmanager
def _dask_executor(workers: int, scheduler: str | None) -> Iterator[Executor]:
    try:
        from distributed import Client, LocalCluster
    except ImportError:
        raise DaskUnavailable(
            "the dask executor needs Dask's distributed scheduler: pip install 'collision-reflex[dask]'"
        ) from None
    if scheduler is None:
        with (
            LocalCluster(
                n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None
            ) as cluster,
            Client(cluster) as client,
        ):
            yield client.get_executor()
        return
    try:
        client = Client(scheduler, timeout="10s")
    except (OSError, TimeoutError) as error:
        raise DaskUnavailable(
            f"cannot reach the Dask scheduler at {scheduler} ({error}); is it running?"
        ) from None
    with client:
        yield client.get_executor()
