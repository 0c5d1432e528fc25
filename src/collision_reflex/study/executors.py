"""Executors for a study's independent work (Pareto points, sample chunks).

In-process, a local process pool, or a Dask distributed cluster. All are :class:`concurrent.futures.Executor`;
nothing here schedules work itself.
"""

from __future__ import annotations

import contextlib
import multiprocessing
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
        with ProcessPoolExecutor(
            max_workers=workers, mp_context=multiprocessing.get_context("spawn")
        ) as pool:
            yield pool
    else:
        with _dask_executor(workers, scheduler) as executor:
            yield executor


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
