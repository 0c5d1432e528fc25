"""Executors for a study's independent work (Pareto points, sample chunks).

In-process, a local process pool, or a Dask distributed cluster. All are :class:`concurrent.futures.Executor`;
nothing here schedules work itself. A local pool or cluster starts all its workers at once, forked from this
process where that is safe (:data:`START_METHOD`), and has each import what a piece of work needs
(:func:`warm_worker`: nothing left to do in a forked worker) while this process goes on, so that no piece waits
for a worker's start-up behind another.
"""

from __future__ import annotations

import contextlib
import ctypes
import importlib
import multiprocessing
import os
import signal
import sys
import threading
import time
from collections.abc import Iterator
from concurrent.futures import Executor, ProcessPoolExecutor

from ..errors import CollisionReflexError, InvalidParameter
from ..optimize.blas import single_threaded_blas
from ..optimize.serial import SerialExecutor
from ..vocabulary import EXECUTORS

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
        pool = ProcessPoolExecutor(
            max_workers=workers,
            mp_context=multiprocessing.get_context(START_METHOD),
            initializer=_start_worker,
            initargs=(os.getpid(),),
        )
        try:
            for _ in range(workers):  # on demand, the pool would start a worker per piece submitted
                pool.submit(int)
            yield pool
        except BaseException:
            _stop(pool)  # an interrupt or a failure: do not wait for the solves in flight
            raise
        pool.shutdown(wait=True)
    else:
        with _dask_executor(workers, scheduler) as executor:
            yield executor


START_METHOD = "fork" if sys.platform.startswith("linux") else "spawn"
"""How a local pool's or cluster's workers start: forked from this process on Linux, spawned elsewhere.

A forked worker starts with what this process has loaded (the package, CasADi, Pinocchio, the robot and the
samples) instead of importing and loading it again, so its start-up costs next to nothing and a parallel
front gains more over a serial one than with spawned workers, with the same numbers to the last bit
(``benchmarks/study_executors.py`` measures the executors). Forking is safe here: the pool's workers start
before this process starts any thread of its own (the pool launches all of them at its first submission, and
the run's progress bars start after), a Dask nanny forks from its event-loop thread as Dask's
``multiprocessing-method`` setting provides, OpenBLAS stops its threads around a fork, and nothing here runs
an OpenMP region (Pinocchio's parallel algorithms are not used). macOS and Windows spawn: fork is unsafe with
their system libraries, or absent."""


def _stop(pool: ProcessPoolExecutor) -> None:
    """Cancel the queued work and end the workers now."""
    processes = list(getattr(pool, "_processes", {}).values())  # the pool offers no public way before 3.14
    pool.shutdown(wait=False, cancel_futures=True)
    for process in processes:
        process.terminate()
    for process in processes:
        process.join(timeout=5)


WARM_MODULES = ("collision_reflex.optimize.pareto", "collision_reflex.study.problems", "pinocchio")
"""What a worker imports when it starts: the pieces of a sweep, a study's problems, and the robot models'
library (with CasADi, NumPy and SciPy behind them), which the first piece would otherwise import."""


def warm_worker() -> None:
    """Import :data:`WARM_MODULES` and load IPOPT with its BLAS, in a worker before its first piece.

    An optional module that is not installed is left to the piece that needs it (which then says so).
    """
    for module in WARM_MODULES:
        with contextlib.suppress(ImportError):
            importlib.import_module(module)
    with single_threaded_blas():  # loads CasADi's IPOPT and registers its OpenBLAS
        pass


def _start_worker(parent: int) -> None:
    """Process-pool initializer: end with the parent (:func:`_die_with_parent`), then :func:`warm_worker`."""
    _die_with_parent(parent)
    warm_worker()


def _die_with_parent(parent: int) -> None:
    """End this worker when the run's process ends, even by ``kill -9``.

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


_LOCAL_DASK_CONFIG = {
    "distributed.nanny.pre-spawn-environ": {
        "OMP_NUM_THREADS": 1,
        "MKL_NUM_THREADS": 1,
        "OPENBLAS_NUM_THREADS": 1,
    },
    "distributed.worker.multiprocessing-method": START_METHOD,
    "distributed.worker.profile.enabled": False,
    "distributed.scheduler.worker-saturation": 1.0,
    "distributed.scheduler.work-stealing": False,
    "distributed.admin.tick.interval": "1s",
    "distributed.admin.system-monitor.interval": "5s",
    "distributed.worker.memory.monitor-interval": "1s",
}
"""Dask settings of a local cluster, for CPU-bound pieces of seconds that hold little data.

A worker's environment without Dask's ``MALLOC_TRIM_THRESHOLD_=65536`` (set to hand freed memory back to the
system sooner): it also turns off glibc's adaptive mmap threshold, so that CasADi's and IPOPT's large work
arrays are mapped and unmapped afresh, with many more page faults and more CPU. No statistical profiler (it
samples every thread's stack every 10 ms). Each worker gets its next piece when it finishes one (saturation 1:
the others wait at the scheduler), so no piece waits behind a long one and no stealing is needed. Slower ticks
and monitors: an idle cluster then takes little CPU."""


@contextlib.contextmanager
def _dask_executor(workers: int, scheduler: str | None) -> Iterator[Executor]:
    try:
        from distributed import Client, LocalCluster
    except ImportError:
        raise DaskUnavailable(
            "the dask executor needs Dask's distributed scheduler: pip install 'collision-reflex[dask]'"
        ) from None
    if scheduler is None:
        import dask

        with (
            dask.config.set(_LOCAL_DASK_CONFIG),
            LocalCluster(
                n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None
            ) as cluster,
            Client(cluster) as client,
        ):
            # Not awaited: the workers warm up while this process goes on (kept: a dropped future is cancelled).
            warming = [
                client.submit(warm_worker, workers=[w], pure=False)
                for w in client.scheduler_info()["workers"]
            ]
            yield client.get_executor()
            del warming
        return
    try:
        client = Client(scheduler, timeout="10s")
    except (OSError, TimeoutError) as error:
        raise DaskUnavailable(
            f"cannot reach the Dask scheduler at {scheduler} ({error}); is it running?"
        ) from None
    with client:
        yield client.get_executor()
