"""Start-up time of ``import collision_reflex``, ``crx --help`` and ``crx validate``.

Each command runs in a fresh interpreter R times (default 7); the median wall time is printed with the machine's
load average before and after, and with the heavy libraries the command imported and their import times (one
extra run with ``python -X importtime``; a library imported by another counts in both). ``crx`` runs as ``python -m collision_reflex``, the same code as the
installed script.

Run: ``PYTHONPATH=src python benchmarks/startup.py [--repeats R]``.
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
# The libraries whose import time is worth knowing (NumPy for scale; pint imports Dask when it is installed).
LIBRARIES = "casadi scipy pinocchio pandas matplotlib pydantic pint jinja2 rich yaml dask numpy".split()


COMMANDS = {
    "import collision_reflex": [],
    "crx --help": ["--help"],
    "crx validate studies/two_link_paper.yaml": ["validate", "studies/two_link_paper.yaml"],
}


def command_line(argv: list[str]) -> list[str]:
    if not argv:
        return [sys.executable, "-c", "import collision_reflex"]
    return [sys.executable, "-m", "collision_reflex", *argv]


def wall_time(argv: list[str]) -> float:
    start = time.perf_counter()
    subprocess.run(command_line(argv), cwd=ROOT, check=True, stdout=subprocess.DEVNULL)
    return time.perf_counter() - start


def heavy_modules(argv: list[str]) -> str:
    """The heavy libraries the command imports, each with its import time (``-X importtime``, cumulative)."""
    done = subprocess.run(
        [sys.executable, "-X", "importtime", *command_line(argv)[1:]],
        cwd=ROOT,
        check=True,
        capture_output=True,
        text=True,
    )
    found = {}
    for line in done.stderr.splitlines():  # "import time: SELF | CUMULATIVE | <indent>NAME", in microseconds
        if line.startswith("import time:") and (fields := line.split("|"))[2].strip() in LIBRARIES:
            found[fields[2].strip()] = int(fields[1]) / 1e3
    shown = sorted(found.items(), key=lambda item: -item[1])
    return ", ".join(f"{name} {ms:.0f} ms" for name, ms in shown) or "none"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=7)
    args = parser.parse_args()
    print(f"load average before: {' '.join(f'{x:.2f}' for x in os.getloadavg())}")
    for name, argv in COMMANDS.items():
        wall_time(argv)  # warm the file cache
        times = [wall_time(argv) for _ in range(args.repeats)]
        print(
            f"{name:42s} median {statistics.median(times):.3f} s "
            f"(min {min(times):.3f}, max {max(times):.3f}, {args.repeats} runs); "
            f"imports: {heavy_modules(argv)}"
        )
    print(f"load average after:  {' '.join(f'{x:.2f}' for x in os.getloadavg())}")


if __name__ == "__main__":
    main()
