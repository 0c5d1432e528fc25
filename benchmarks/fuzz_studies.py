"""A long fuzz run over the shipped studies and catalogues: the CI test's mutants, in larger numbers.

The mutants are those of ``tests/test_fuzz_studies.py`` (seeded, each rebuilt from its index), from ``--first``
on; the test checks the first ``N_MUTANTS`` (1,500), this script by default the 100,000 after them. Prints the
count of each outcome (valid or a located error, by kind of mutation), the slowest mutant's time and index, the
process's peak memory and its growth over the run. A mutant that is neither valid nor a one-line located error
stops the run with its index; a run that fails the test's check (every kind of outcome reached, no mutant
slower than ``MAX_SECONDS``, peak memory within ``MAX_PEAK_GROWTH_MB``) ends with exit status 1.

Run: ``PYTHONPATH=src python benchmarks/fuzz_studies.py [--mutants N] [--first I]``.
"""

from __future__ import annotations

import argparse
import resource
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))

from test_fuzz_studies import N_MUTANTS, SOURCES, check_fuzz_report, fuzz  # noqa: E402  (the test holds the mutators)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--mutants", type=int, default=100_000, help="number of mutants (default 100,000)")
    parser.add_argument(
        "--first", type=int, default=N_MUTANTS, help="index of the first (default: after the test's)"
    )
    args = parser.parse_args()
    print(
        f"{args.mutants} mutants from index {args.first} of {len(SOURCES)} files: "
        + ", ".join(path.name for path in SOURCES)
    )
    with tempfile.TemporaryDirectory() as folder:
        report = fuzz(
            args.mutants, Path(folder), args.first, progress=lambda done: print(f"  {done} done", flush=True)
        )
    for outcome, count in sorted(report.counts.items()):
        print(f"{outcome:>18}: {count}")
    elapsed, index = report.slowest
    peak_mb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024  # kB on Linux
    print(
        f"all valid or located: {sum(report.counts.values())} mutants in {report.seconds:.1f} s "
        f"({sum(report.counts.values()) / report.seconds:.0f} per s)"
    )
    print(f"slowest mutant: {elapsed * 1e3:.0f} ms (index {index})")
    print(f"peak memory: {peak_mb:.0f} MB, {report.peak_growth_mb:.0f} MB more than before the first mutant")
    try:
        check_fuzz_report(report, args.mutants)
    except AssertionError as error:
        sys.exit(f"FAILED: {error}")


if __name__ == "__main__":
    main()
