"""Wall time of whole ``crx run`` runs of the shipped studies, serially, and where it goes.

    PYTHONPATH=src python benchmarks/study_runs.py [STUDY ...] [--repeats 3] [--smoke] [--keep DIR]

By default the Panda and UR5 studies (targets on a quiet machine: ``studies/panda.yaml`` <= 10 s,
``studies/ur5.yaml`` <= 20 s). Each run is ``crx run STUDY --out <new folder> --quiet --executor serial`` in a
fresh Python process (the package imported, the robot loaded and every problem built as a user's run does),
the studies interleaved. It prints, per study, the median wall time with the load average before and after
each run, and per stage the median wall and CPU time read back from the run's ``timings.json``
(``stages/<stage>/wall|cpu``: load, prepare, optimum, pareto, catalogue snap, results, result files, figures,
report). CPU time is the run's process's, steadier than wall time on a loaded machine. Bytecode is compiled
before the runs and read as an installed package's is (``PYTHONDONTWRITEBYTECODE`` is dropped from the runs'
environment), so that no run counts compiling the package's sources. It also prints the
largest single solve and any solve that stopped at the iteration cap (a run reports such a point as failed).

``--keep DIR``: keep each run's output folder under DIR (default: a temporary folder, removed after).

``--snap-only``: after each study's first run, redo its catalogue snap alone ``--repeats`` times (the run resumed
with its saved snap removed: every other piece is reused) and print the snap stage's median wall and CPU time,
its re-solves and their IPOPT iterations, with the load; ``--from DIR`` takes the first runs from DIR (folders
``<study>-0`` of an earlier ``--keep``) instead of running them.
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
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DEFAULT_STUDIES = (ROOT / "studies" / "panda.yaml", ROOT / "studies" / "ur5.yaml")
STAGE_PREFIX = "stages/"
# Bytecode written and read as for an installed package: a shell with PYTHONDONTWRITEBYTECODE set would make every
# run compile the package's sources again (measured: 0.06-0.09 s for 40 modules, at load 3).
ENV = {name: value for name, value in os.environ.items() if name != "PYTHONDONTWRITEBYTECODE"}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("studies", nargs="*", default=[str(p) for p in DEFAULT_STUDIES])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--smoke", action="store_true", help="small sample counts (a quick check)")
    parser.add_argument("--keep", metavar="DIR", help="keep the runs' output folders under DIR")
    parser.add_argument("--snap-only", action="store_true", help="time the catalogue snap stage alone")
    parser.add_argument(
        "--from", dest="source", metavar="DIR", help="with --snap-only: earlier runs' folders"
    )
    args = parser.parse_args()
    package = ROOT / "src" / "collision_reflex"
    subprocess.run([sys.executable, "-m", "compileall", "-q", str(package)], env=ENV, check=True)
    with tempfile.TemporaryDirectory() as scratch:
        base = Path(args.keep) if args.keep else Path(scratch)
        if args.snap_only:
            for study in args.studies:
                snap_only(study, base, Path(args.source) if args.source else None, args.repeats, args.smoke)
            return
        runs: dict[str, list[dict]] = {study: [] for study in args.studies}
        for repeat in range(args.repeats):
            for study in args.studies:
                out = base / f"{Path(study).stem}-{repeat}"
                runs[study].append(run_once(study, out, args.smoke))
                last = runs[study][-1]
                print(
                    f"  {Path(study).name} run {repeat + 1}: {last['wall']:.1f} s "
                    f"(load {last['load_before']:.2f} -> {last['load_after']:.2f})",
                    flush=True,
                )
        for study, records in runs.items():
            report(study, records)


def run_once(study: str, out: Path, smoke: bool) -> dict:
    """One ``crx run`` in a fresh process: its wall time, the load before and after, and its timings."""
    command = [sys.executable, "-m", "collision_reflex", "run", study, "--out", str(out), "--quiet"]
    command += ["--executor", "serial"] + (["--smoke"] if smoke else [])
    load_before = os.getloadavg()[0]
    started = time.perf_counter()
    subprocess.run(command, env=ENV, check=True, stdout=subprocess.DEVNULL)
    wall = time.perf_counter() - started
    load_after = os.getloadavg()[0]
    timings = json.loads((out / "timings.json").read_text(encoding="utf-8"))
    designs = json.loads((out / "designs.json").read_text(encoding="utf-8"))
    return {
        "wall": wall,
        "load_before": load_before,
        "load_after": load_after,
        "timings": timings,
        "capped": capped_solves(designs),
    }


def snap_only(study: str, base: Path, source: Path | None, repeats: int, smoke: bool) -> None:
    """The catalogue snap stage of ``study`` alone, ``repeats`` times, on one finished run (see the docstring)."""
    name = Path(study).stem
    first = base / f"{name}-0"
    if source is not None:
        shutil.copytree(source / f"{name}-0", first, dirs_exist_ok=True)
    else:
        run_once(study, first, smoke)
    walls, cpus, loads = [], [], []
    for _ in range(repeats):
        (first / "points" / "catalogue.json").unlink(missing_ok=True)
        record = run_once(study, first, smoke)
        walls.append(record["timings"]["stages/catalogue snap/wall"])
        cpus.append(record["timings"]["stages/catalogue snap/cpu"])
        loads.append(f"{record['load_before']:.2f}->{record['load_after']:.2f}")
    catalogue = json.loads((first / "designs.json").read_text(encoding="utf-8"))["catalogue"]
    solved = [t for t in catalogue["tried"] if t["objective"] is not None]
    print(
        f"{Path(study).name} catalogue snap alone: median wall {statistics.median(walls):.2f} s, CPU "
        f"{statistics.median(cpus):.2f} s over {repeats} (each wall {', '.join(f'{w:.2f}' for w in walls)}; CPU "
        f"{', '.join(f'{c:.2f}' for c in cpus)}; load {', '.join(loads)}); {len(catalogue['tried'])} "
        f"combinations re-solved ({len(solved)} feasible, {sum(t.get('iterations') or 0 for t in solved)} IPOPT "
        f"iterations), {catalogue['method']}; chosen: {' + '.join(j['part'] or '-' for j in catalogue['joints'])}"
        f"; its objectives: {', '.join(f'{k} {v:.10g}' for k, v in (catalogue['objectives'] or {}).items())}",
        flush=True,
    )


def capped_solves(designs: dict) -> list[str]:
    """The pieces of a run whose solve stopped at IPOPT's iteration cap (by where they are in the results)."""
    found: list[str] = []

    def visit(node: object, at: str) -> None:
        if isinstance(node, dict):
            if node.get("status") == "Maximum_Iterations_Exceeded":
                found.append(at or "(top)")
            for key, value in node.items():
                visit(value, f"{at}/{key}" if at else str(key))
        elif isinstance(node, list):
            for index, value in enumerate(node):
                visit(value, f"{at}/{index}")

    visit(designs, "")
    return found


def report(study: str, records: list[dict]) -> None:
    """Median wall time with the load, the stages' median wall and CPU times, the largest solve, capped solves."""
    walls = [r["wall"] for r in records]
    loads = ", ".join(f"{r['load_before']:.2f}->{r['load_after']:.2f}" for r in records)
    print(f"\n{Path(study).name}: median wall {statistics.median(walls):.1f} s over {len(walls)} runs")
    print(f"  each: {', '.join(f'{w:.1f}' for w in walls)} s; load average (1 min) before->after: {loads}")
    stages: dict[str, dict[str, list[float]]] = {}
    for r in records:
        for key, value in r["timings"].items():
            if key.startswith(STAGE_PREFIX):
                stage, kind = key[len(STAGE_PREFIX) :].rsplit("/", 1)
                stages.setdefault(stage, {}).setdefault(kind, []).append(value)
    print(f"  {'stage':<16} {'wall [s]':>9} {'cpu [s]':>9}")
    for stage, kinds in stages.items():
        wall = statistics.median(kinds.get("wall", [float("nan")]))
        cpu = statistics.median(kinds.get("cpu", [float("nan")]))
        print(f"  {stage:<16} {wall:9.2f} {cpu:9.2f}")
    solves = [
        max(v for k, v in r["timings"].items() if k.endswith("solver/solve_time") and v is not None)
        for r in records
    ]
    print(
        f"  largest single solve: median {statistics.median(solves):.1f} s (each: "
        + ", ".join(f"{s:.1f}" for s in solves)
        + ")"
    )
    capped = sorted({c for r in records for c in r["capped"]})
    print("  solves stopped at the iteration cap: " + (", ".join(capped) if capped else "none"))


if __name__ == "__main__":
    main()
