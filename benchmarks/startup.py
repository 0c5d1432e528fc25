"""Start-up time of ``import collision_reflex``, ``crx --help`` and ``crx validate``.

Each command runs in a fresh interpreter R times (default 7); the median wall time is printed with the machine's
load average before and after, and with the heavy libraries the command imported (read from ``sys.modules``
when it has finished, in one extra run). ``crx`` runs as ``python -m collision_reflex``, the same code as the
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
HEAVY = ("casadi", "scipy", "pinocchio", "pandas", "matplotlib", "pydantic", "pint", "jinja2", "rich", "yaml")

# Runs a command's code in-process, then prints the heavy libraries it left in sys.modules on stderr.
PROBE = """
import sys
HEAVY = {heavy!r}
argv = sys.argv[1:]
if argv:
    from collision_reflex.cli import main
    status = main(argv)
else:
    import collision_reflex
    status = 0
heavy = sorted(set(name.split('.')[0] for name in sys.modules) & set(HEAVY))
print("HEAVY", " ".join(heavy) or "-", file=sys.stderr)
sys.exit(status)
"""

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
    probe = PROBE.format(heavy=HEAVY)
    done = subprocess.run(
        [sys.executable, "-c", probe, *argv], cwd=ROOT, check=True, capture_output=True, text=True
    )
    line = next(line for line in done.stderr.splitlines() if line.startswith("HEAVY "))
    return line.removeprefix("HEAVY ")


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
