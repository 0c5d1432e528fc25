"""Start-up time of ``import collision_reflex``, ``crx --help`` and ``crx validate``.

Each command runs in a fresh interpreter R times (default 7); the median wall time and the median CPU time
(user + system, which the load of a shared machine distorts less) are printed with the machine's load average
before and after, and with the heavy libraries the command imported and their import times (one extra run with
``python -X importtime``; a library imported by another counts in both). ``crx`` runs as
``python -m collision_reflex``, the same code as the installed script. Bytecode is cached, as for an installed
package (in a temporary folder: ``PYTHONPYCACHEPREFIX``), so that compiling the sources is not counted; so is
the unit registry's cache of ``crx`` (in a temporary user cache folder, ``XDG_CACHE_HOME``), which the first run
of each command, not timed, writes.

Then ``crx validate``'s phases, each timed in one fresh interpreter doing the command's steps in order (medians
of R runs), without garbage collection as in ``crx``: what the imports, the unit registry, reading the study and
loading the robot cost.

Run: ``PYTHONPATH=src python benchmarks/startup.py [--repeats R]``.
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

ROOT = Path(__file__).resolve().parents[1]
# Bytecode written and read as for an installed package, in a folder of our own (set in main()).
ENV = {name: value for name, value in os.environ.items() if name != "PYTHONDONTWRITEBYTECODE"}
# The libraries whose import time is worth knowing (NumPy for scale; pint imports Dask when it is installed).
LIBRARIES = "casadi scipy pinocchio pandas matplotlib pydantic pint jinja2 rich yaml dask numpy".split()


COMMANDS = {
    "python -c pass": None,  # the interpreter alone: the floor of every command
    "import collision_reflex": [],
    "crx --help": ["--help"],
    "crx validate studies/two_link_paper.yaml": ["validate", "studies/two_link_paper.yaml"],
}


def command_line(argv: list[str] | None) -> list[str]:
    if argv is None:
        return [sys.executable, "-c", "pass"]
    if not argv:
        return [sys.executable, "-c", "import collision_reflex"]
    return [sys.executable, "-m", "collision_reflex", *argv]


def timed(command: list[str]) -> tuple[float, float]:
    """Wall and CPU time (user + system) of one run of a command line."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    subprocess.run(command, cwd=ROOT, env=ENV, check=True, stdout=subprocess.DEVNULL)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return wall, after.ru_utime - before.ru_utime + after.ru_stime - before.ru_stime


STUDY = "studies/two_link_paper.yaml"
# The steps of `crx validate STUDY`, in the order the command takes them; each is timed after the previous ones.
PHASES = {
    "import numpy": "import numpy",
    "import collision_reflex.cli, parse": (
        "from collision_reflex.cli import build_parser\nbuild_parser().parse_args(['validate', STUDY])"
    ),
    "import pydantic": "import pydantic",
    "import study.schema (its models)": "import collision_reflex.study.schema",
    "import study, study.prepare": "import collision_reflex.study, collision_reflex.study.prepare",
    "import pint (as crx does)": (
        "from collision_reflex import _units\n_units.hide_pint_extras()\n_units.cache_registry()\n_units.import_pint()"
    ),
    "unit registry (cached)": "_units.unit_registry()",
    "load_study": "from collision_reflex.study import load_study\nloaded = load_study(STUDY)",
    "import pinocchio": "import pinocchio",
    "describe_study (robot, motors, samples)": (
        "from collision_reflex.study.prepare import describe_study\ndescribe_study(loaded)"
    ),
}


def phase_times() -> dict[str, tuple[float, float]]:
    """Wall and CPU time of each phase in one fresh interpreter."""
    # Without cyclic garbage collection, as crx's start-up (collision_reflex.cli.start_up).
    lines = ["import gc, json, time", "gc.disable()", f"STUDY = {STUDY!r}", "out = {}"]
    for name, code in PHASES.items():
        lines += ["w, c = time.perf_counter(), time.process_time()", code]
        lines += [f"out[{name!r}] = (time.perf_counter() - w, time.process_time() - c)"]
    lines.append("print(json.dumps(out))")
    done = subprocess.run(
        [sys.executable, "-c", "\n".join(lines)],
        cwd=ROOT,
        env=ENV,
        check=True,
        capture_output=True,
        text=True,
    )
    return {name: (wall, cpu) for name, (wall, cpu) in json.loads(done.stdout.splitlines()[-1]).items()}


def heavy_modules(argv: list[str] | None) -> str:
    """The heavy libraries the command imports, each with its import time (``-X importtime``, cumulative)."""
    done = subprocess.run(
        [sys.executable, "-X", "importtime", *command_line(argv)[1:]],
        cwd=ROOT,
        env=ENV,
        check=True,
        capture_output=True,
        text=True,
    )
    found = {}
    for line in done.stderr.splitlines():  # "import time: SELF | CUMULATIVE | <indent>NAME", in microseconds
        # An import refused on purpose (pint's extras, which crx hides) is listed with a few microseconds.
        if line.startswith("import time:") and (fields := line.split("|"))[2].strip() in LIBRARIES:
            if int(fields[1]) >= 1000:
                found[fields[2].strip()] = int(fields[1]) / 1e3
    shown = sorted(found.items(), key=lambda item: -item[1])
    return ", ".join(f"{name} {ms:.0f} ms" for name, ms in shown) or "none"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=7)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as cache:
        ENV["PYTHONPYCACHEPREFIX"] = cache
        ENV["XDG_CACHE_HOME"] = str(Path(cache) / "user-cache")
        report(args.repeats)


def report(repeats: int) -> None:
    """Print the commands' times and the phases of ``crx validate``."""
    print(f"load average before: {' '.join(f'{x:.2f}' for x in os.getloadavg())}")
    for name, argv in COMMANDS.items():
        timed(command_line(argv))  # warm the file cache
        walls, cpus = zip(*(timed(command_line(argv)) for _ in range(repeats)), strict=True)
        imports = "" if argv is None else f"; imports: {heavy_modules(argv)}"
        print(
            f"{name:42s} median {statistics.median(walls):.3f} s wall, {statistics.median(cpus):.3f} s CPU "
            f"(wall min {min(walls):.3f}, max {max(walls):.3f}, {repeats} runs){imports}"
        )
    print(f"load average: {' '.join(f'{x:.2f}' for x in os.getloadavg())}")
    print(f"phases of crx validate {STUDY} (medians of {repeats} runs, one interpreter each):")
    runs = [phase_times() for _ in range(repeats)]
    for name in PHASES:
        wall = statistics.median(run[name][0] for run in runs)
        cpu = statistics.median(run[name][1] for run in runs)
        print(f"  {name:42s} {wall:.3f} s wall, {cpu:.3f} s CPU")
    print(f"load average after:  {' '.join(f'{x:.2f}' for x in os.getloadavg())}")


if __name__ == "__main__":
    main()
