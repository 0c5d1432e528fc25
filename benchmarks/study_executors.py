"""Wall time of a design study run through each executor, and whether they agree.

    PYTHONPATH=src python benchmarks/study_executors.py [STUDY] [--smoke] [--workers N]

Runs the study (default: the paper's two-link study) serially, on a local process pool and on a local Dask
cluster, each into a fresh temporary folder, and prints the wall time of each run and the largest relative
difference of its Pareto objectives from the serial run (0 expected: every Pareto point is a pure function of
the resolved study).
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

import numpy as np
import pandas as pd

from collision_reflex.study.runner import run_study

ROOT = Path(__file__).resolve().parents[1]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("study", nargs="?", default=str(ROOT / "studies" / "two_link_paper.yaml"))
    parser.add_argument("--smoke", action="store_true", help="small sample counts")
    parser.add_argument("--workers", type=int, default=2)
    args = parser.parse_args()
    reference = None
    print(f"{'executor':<10}{'wall time [s]':>15}{'points':>8}{'max rel. diff':>15}")
    with tempfile.TemporaryDirectory() as tmp:
        for executor in ("serial", "processes", "dask"):
            started = time.perf_counter()
            result = run_study(
                args.study,
                Path(tmp) / executor,
                quiet=True,
                smoke=args.smoke,
                executor=executor,
                workers=args.workers,
                figures=False,
            )
            elapsed = time.perf_counter() - started
            table = pd.read_csv(result.folder / "pareto.csv")
            values = table[[c for c in table.columns if c.endswith(("[N*s]", "[kg]"))]].to_numpy(dtype=float)
            reference = values if reference is None else reference
            diff = float(np.max(np.abs(values - reference) / np.maximum(np.abs(reference), 1e-300)))
            print(f"{executor:<10}{elapsed:>15.2f}{len(table):>8}{diff:>15.2e}")


if __name__ == "__main__":
    main()
