"""Single-threaded BLAS during solves: CasADi's OpenBLAS is limited even before IPOPT's first solver exists."""

from __future__ import annotations

import subprocess
import sys

# A fresh interpreter: in the test process another test may already have loaded IPOPT.
_PROBE = """
import threadpoolctl
from collision_reflex.optimize.blas import single_threaded_blas
with single_threaded_blas():
    threads = {i["internal_api"]: i["num_threads"] for i in threadpoolctl.threadpool_info()}
print(threads.get("casadi_openblas"))
"""


def test_casadi_openblas_is_single_threaded_before_the_first_solver() -> None:
    # Before the fix the library was not yet loaded at the limit, so a first solve ran it on every core.
    done = subprocess.run([sys.executable, "-c", _PROBE], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "1", done.stdout + done.stderr
    assert "already in use" not in done.stderr
