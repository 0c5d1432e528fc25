"""The test's scan of random feasible design problems, in full: no solve may fail.

Each problem of ``tests/test_optimize_feasibility.py``'s scan (seed 14) has a feasible design by construction,
so a failed solve, "infeasible" among them, is a wrong answer; without IPOPT's retries 7 of the first 2 x 120
failed. The test solves the first ``SCAN`` (40) per robot; this script the first ``--problems`` (default 120)
per robot, for the double pendulum and the planar two-link arm. Prints per robot the problems solved, those
solved after a retry, the failures and the time; ends with exit status 1 if any solve failed.

Run: ``PYTHONPATH=src python benchmarks/feasibility_scan.py [--problems N]``.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import collision_reflex as cr

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))

from test_optimize_feasibility import TWO_LINK, scan  # noqa: E402  (the test holds the problems)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--problems", type=int, default=120, help="problems per robot (default 120)")
    args = parser.parse_args()
    arms = {
        "double_pendulum": cr.Arm.from_example_robot_data("double_pendulum"),
        "two_link": cr.Arm.from_urdf(TWO_LINK, "tip"),
    }
    failed = []
    for robot, arm in arms.items():
        started = time.perf_counter()
        try:
            solved, retried, failures = scan(arm, args.problems)
        except AssertionError:  # a solve that ended without converging and without raising
            sys.exit(f"FAILED: {robot}: a solve ended without converging")
        print(
            f"{robot}: {solved} solved, {retried} after a retry, {len(failures)} failed "
            f"{sorted(set(failures))}, {time.perf_counter() - started:.1f} s"
        )
        failed += [f"{robot}: {status}" for status in failures]
    if failed:
        sys.exit(f"FAILED: {len(failed)} of {len(arms) * args.problems} feasible problems: {failed}")
    print(f"all {len(arms) * args.problems} feasible problems solved")


if __name__ == "__main__":
    main()
