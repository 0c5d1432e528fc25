"""Does `crx init` give a study that validates and runs for every robot `crx robots` lists as startable?

    PYTHONPATH=src python benchmarks/init_all_robots.py [ROBOT ...] [--full] [--keep DIR]

For each robot (default: every startable one) it writes the study with ``crx init``, validates it and runs it
(``--smoke`` unless ``--full``) in a fresh process, serially, and prints per robot the exit status, the wall
time with the load average before and after, the run's verdict line on its recommended design and, for a
failed run, its last error line. The test suite runs a representative few of these (tests/test_starter.py);
this covers them all.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("robots", nargs="*", help="robots to run (default: every startable one)")
    parser.add_argument("--full", action="store_true", help="full runs instead of smoke runs")
    parser.add_argument("--keep", type=Path, default=None, help="keep the studies and runs under this folder")
    args = parser.parse_args()
    sys.path.insert(0, str(ROOT / "src"))
    from collision_reflex.study.starter import robot_entries

    names = args.robots or [entry.name for entry in robot_entries() if entry.startable]
    work = args.keep or Path(tempfile.mkdtemp(prefix="init-all-"))
    work.mkdir(parents=True, exist_ok=True)
    env = {**os.environ, "PYTHONPATH": str(ROOT / "src")}
    failed = 0
    print(f"{len(names)} robots, {'full' if args.full else 'smoke'} runs, {os.cpu_count()} cores")
    for name in names:
        study, out = work / f"{name}.yaml", work / f"out-{name}"
        shutil.rmtree(out, ignore_errors=True)  # a fresh run each time
        load = os.getloadavg()[0]
        started = time.perf_counter()
        steps = [
            ["init", name, "--out", str(study), "--force"],
            ["validate", str(study)],
            [
                "run",
                str(study),
                "--quiet",
                "--executor",
                "serial",
                "--out",
                str(out),
                *([] if args.full else ["--smoke"]),
            ],
        ]
        status, error = 0, ""
        for step in steps:
            done = subprocess.run(
                [sys.executable, "-m", "collision_reflex", *step], capture_output=True, text=True, env=env
            )
            if done.returncode != 0:
                status, error = done.returncode, (done.stderr.strip().splitlines() or [""])[-1][:300]
                break
        wall = time.perf_counter() - started
        verdict = ""
        if status == 0:
            designs = json.loads((out / "designs.json").read_text())
            verdict = designs["verdict"][0][:160]
        failed += status != 0
        print(f"{name}: exit {status}, {wall:.1f} s (load {load:.2f} -> {os.getloadavg()[0]:.2f})")
        print(f"    {verdict or error}")
    print(f"{len(names) - failed} of {len(names)} ran")
    return 1 if failed else 0


if __name__ == "__main__":
    raise SystemExit(main())
