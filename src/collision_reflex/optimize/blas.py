"""Every BLAS on one thread while a solve runs, so that every executor gives the same numbers."""

from __future__ import annotations

import contextlib
from typing import Any

_CONTROLLER: list[Any] = []  # threadpoolctl's controller of every BLAS, made once they are all loaded


def single_threaded_blas() -> contextlib.AbstractContextManager[object]:
    """A context with every BLAS on one thread.

    That is NumPy's, SciPy's own (its optimisers' quasi-Newton steps call it), and the OpenBLAS that CasADi
    bundles for IPOPT and MUMPS. A threaded BLAS sums in an order that depends on its thread count, and Dask
    workers pin it to one thread where a plain process does not; the difference moves IPOPT's iterates and so
    the results, within the solver tolerance. With one thread everywhere, every executor gives the same
    numbers, bitwise in practice (parallelism comes from the executor's processes).

    The libraries are found once per process (a search of the loaded libraries costs milliseconds, and a
    study enters this context hundreds of times), after the three above are loaded.
    """
    if not _CONTROLLER:
        import scipy.linalg  # noqa: F401  # loads SciPy's OpenBLAS now: threadpoolctl limits only loaded ones
        import threadpoolctl  # lazy: needed only once a solve runs

        threadpoolctl.register(_casadi_openblas_controller())
        _load_casadi_openblas()
        _CONTROLLER.append(threadpoolctl.ThreadpoolController())
    return _CONTROLLER[0].limit(limits=1)


def _load_casadi_openblas() -> None:
    """Load IPOPT with its OpenBLAS now: threadpoolctl limits only the libraries already loaded.

    CasADi loads them with the first solver; without this, a first solve spins two BLAS threads, whose
    contention costs kernel time on the small matrices here.
    """
    import casadi  # lazy: casadi
    import threadpoolctl

    if all(info["internal_api"] != "casadi_openblas" for info in threadpoolctl.threadpool_info()):
        casadi.load_nlpsol("ipopt")  # not loaded yet (it links that OpenBLAS), so no "already in use" warning


def _casadi_openblas_controller() -> type:
    from threadpoolctl import OpenBLASController  # lazy: needed only once a solve runs

    class CasadiOpenBLAS(OpenBLASController):
        """CasADi's bundled OpenBLAS, which threadpoolctl does not know by its file name."""

        internal_api = "casadi_openblas"
        filename_prefixes = ("libcasadi-tp-openblas",)

    return CasadiOpenBLAS
