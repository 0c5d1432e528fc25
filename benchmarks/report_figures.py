"""Time of the "figures" stage of ``crx run``, redone from finished runs' folders.

    PYTHONPATH=src python benchmarks/report_figures.py RUN_FOLDER [RUN_FOLDER ...] [--repeats 5]

A run folder is the ``--out`` of a ``crx run`` (``benchmarks/study_runs.py --keep DIR`` keeps them). Each repeat
copies the folder into a temporary one and, in a fresh Python process (Matplotlib not yet imported, as in a
run), redraws the figures as the run's figures stage does; the folders are interleaved. It prints, per folder,
the median wall and CPU time of the stage (CPU: the process's, steadier on a loaded machine) with the load
average before and after.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

# The figures stage as render_report times it, from the folder's saved results.
STAGE = """
import json, sys
from collision_reflex.report.outputs import StageTimes, _figures, _read_results
folder = sys.argv[1]
results = _read_results(__import__("pathlib").Path(folder))
stages = StageTimes()
with stages.stage("figures"):
    _figures(__import__("pathlib").Path(folder), results, True)
print(json.dumps(stages.times))
"""


def time_once(folder: Path, scratch: Path) -> tuple[float, float]:
    """Wall and CPU time [s] of the figures stage redone in a copy of ``folder``."""
    copy = scratch / folder.name
    shutil.rmtree(copy, ignore_errors=True)
    shutil.copytree(folder, copy)
    done = subprocess.run(
        [sys.executable, "-c", STAGE, str(copy)], cwd=ROOT, check=True, capture_output=True, text=True
    )
    times = json.loads(done.stdout.splitlines()[-1])
    return times["stages/figures/wall"], times["stages/figures/cpu"]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("folders", nargs="+", type=Path)
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()
    load_before = os.getloadavg()[0]
    times: dict[Path, list[tuple[float, float]]] = {folder: [] for folder in args.folders}
    with tempfile.TemporaryDirectory() as scratch:
        for _ in range(args.repeats):
            for folder in args.folders:
                times[folder].append(time_once(folder, Path(scratch)))
    load_after = os.getloadavg()[0]
    print(f"load average (1 min) before -> after: {load_before:.2f} -> {load_after:.2f}")
    for folder, runs in times.items():
        walls, cpus = zip(*runs, strict=True)
        print(
            f"{folder.name}: figures stage median {statistics.median(walls):.3f} s wall, "
            f"{statistics.median(cpus):.3f} s CPU (CPU min {min(cpus):.3f}, max {max(cpus):.3f}, {len(runs)} runs)"
        )


if __name__ == "__main__":
    main()
