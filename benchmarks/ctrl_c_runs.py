"""Ctrl-C at evenly spaced times over a whole ``crx run``: does every interrupt stop the run?

    PYTHONPATH=src python benchmarks/ctrl_c_runs.py [STUDY] [--interrupts 60] [--executor serial] [--full]

Times one run of the study (``--smoke`` sizes unless ``--full``), then starts it again ``--interrupts`` times,
each in a fresh process, and sends SIGINT at evenly spaced fractions of that time (from 5 % to 105 %: the last
ones arrive as the run ends). Prints the count of each outcome: ``interrupted`` (exit status 130 with the
one-line message), ``finished`` (status 0: the interrupt came after the run's work, or was lost), anything
else (a traceback, another status) in full; and, for every run that went on for more than a second after the
signal, the time and outcome: an interrupt that is lost lets the run finish long after it.
"""

from __future__ import annotations

import argparse
import collections
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
INTERRUPTED = "crx run: interrupted; rerun the same command to resume"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("study", nargs="?", default=str(ROOT / "studies" / "panda.yaml"))
    parser.add_argument("--interrupts", type=int, default=60)
    parser.add_argument("--executor", default="serial")
    parser.add_argument("--full", action="store_true", help="the study's own sample counts, not --smoke")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as scratch:
        out = Path(scratch) / "run"
        command = [sys.executable, "-m", "collision_reflex", "run", args.study, "--quiet", "--out", str(out)]
        command += ["--executor", args.executor] + ([] if args.full else ["--smoke"])
        environment = {**os.environ, "PYTHONPATH": str(ROOT / "src")}
        started = time.monotonic()
        subprocess.run(command, env=environment, check=True, capture_output=True)
        whole = time.monotonic() - started
        print(f"{Path(args.study).name}: one run {whole:.1f} s; load average {os.getloadavg()[0]:.2f}")
        outcomes: collections.Counter[str] = collections.Counter()
        for k in range(args.interrupts):
            delay = whole * (0.05 + k / max(args.interrupts - 1, 1))
            shutil.rmtree(out, ignore_errors=True)
            process = subprocess.Popen(
                command, env=environment, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True
            )
            time.sleep(delay)
            process.send_signal(signal.SIGINT)
            sent = time.monotonic()
            _, stderr = process.communicate(timeout=600)
            after = time.monotonic() - sent
            last = stderr.strip().splitlines()[-1] if stderr.strip() else ""
            if process.returncode == 130 and last == INTERRUPTED:
                outcome = "interrupted"
            elif process.returncode == 0:
                outcome = "finished"
            else:
                outcome = f"status {process.returncode}"
                print(f"  at {delay:.2f} s: {outcome}\n{stderr}")
            outcomes[outcome] += 1
            if after > 1.0:
                print(f"  at {delay:.2f} s: {outcome} {after:.2f} s after the signal")
        print("outcomes: " + ", ".join(f"{name} {count}" for name, count in sorted(outcomes.items())))
        print(f"load average after: {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
