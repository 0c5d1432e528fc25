"""Cost of a certified worst case on many samples: the Panda study's optimum with the search of its domain.

    PYTHONPATH=src python benchmarks/worst_case_search.py [--configurations 2731] [--repeats 3]

``studies/panda.yaml`` with ``--configurations`` random configurations (x 6 directions, those feasible in the
contact domain: 2,731 give about 16,384 samples), no Pareto front, no catalogue snap, no figures: the
optimum of the worst-case impulse, solved on active sets, then the worst-case search and the exchange rounds
until the search certifies it. Each repeat is a ``crx run`` in a fresh process; it prints per run the wall
time, the peak resident memory, the samples (drawn and searched), the rounds and the stages' wall times
(``timings.json``), and the medians, with the load average before and after.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import yaml

ROOT = Path(__file__).resolve().parents[1]


def study_text(configurations: int) -> str:
    data = yaml.safe_load((ROOT / "studies" / "panda.yaml").read_text())
    data["samples"]["configurations"]["random"]["count"] = configurations
    data["pareto"] = None
    data["catalogue"] = {"snap": False}
    data["execution"] = {"executor": "serial"}
    return yaml.safe_dump(data, sort_keys=False)


def one_run(study: Path, out: Path) -> dict[str, float]:
    before = os.getloadavg()[0]
    started = time.perf_counter()
    command = [sys.executable, "-m", "collision_reflex", "run", str(study), "--out", str(out), "--quiet"]
    subprocess.run(command, check=True, env={**os.environ, "PYTHONPATH": str(ROOT / "src")})
    wall = time.perf_counter() - started
    peak = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024  # [MB]: the largest child so far
    results = json.loads((out / "designs.json").read_text())
    timings = json.loads((out / "timings.json").read_text())
    worst = results["recommended"]["worst_case"]
    return {
        "wall": wall,
        "peak_mb": peak,
        "samples": len(results["samples"]["config_index"]),
        "searched": results["domain"]["searched_samples"],
        "certified": worst["certified"],
        "worst": worst["domain"],
        "sampled": worst["sampled"],
        "machine_load": (before, os.getloadavg()[0]),
        **{k.split("/")[1]: v for k, v in timings.items() if k.startswith("stages/") and k.endswith("/wall")},
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--configurations", type=int, default=2731)
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as scratch:
        study = Path(scratch) / "panda_many.yaml"
        study.write_text(study_text(args.configurations))
        runs = []
        for k in range(args.repeats):
            run = one_run(study, Path(scratch) / f"run-{k}")
            runs.append(run)
            stages = ", ".join(
                f"{name} {run[name]:.2f} s"
                for name in ("prepare", "optimum", "worst-case search", "results")
                if name in run
            )
            print(
                f"run {k}: {run['wall']:.1f} s, peak {run['peak_mb']:.0f} MB, {run['samples']} samples "
                f"({run['searched']} searched), worst case {run['worst']:.5g} N*s (sampled {run['sampled']:.5g}, "
                f"certified {run['certified']}), load {run['machine_load'][0]:.2f}-{run['machine_load'][1]:.2f}; {stages}"
            )
        solving = [r.get("optimum", 0.0) + r.get("worst-case search", 0.0) for r in runs]
        print(
            f"median wall {statistics.median(r['wall'] for r in runs):.1f} s (the whole run: files, figures, "
            f"report), of which the optimum and the search {statistics.median(solving):.1f} s; "
            f"peak memory {max(r['peak_mb'] for r in runs):.0f} MB over {len(runs)} runs"
        )


if __name__ == "__main__":
    main()
