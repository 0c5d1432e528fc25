"""The shipped studies' results are the recorded ones, byte for byte: a change of structure changes no number.

``tests/golden/<study>/`` holds, gzip-compressed, the ``designs.json``, ``pareto.csv`` and ``study.resolved.yaml``
of each shipped study's smoke run (``crx run STUDY --smoke --executor serial``), with the checkout's folder
written ``<checkout>`` (a study that names a URDF file records its absolute path). A change that is meant to
change results records them anew: ``CRX_RECORD_RESULTS=1 python -m pytest tests/test_study_results_unchanged.py``
and says so in its commit.
"""

from __future__ import annotations

import gzip
import os
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
GOLDEN = ROOT / "tests" / "golden"
STUDIES = sorted(path.stem for path in (ROOT / "studies").glob("*.yaml"))
FILES = ("designs.json", "pareto.csv", "study.resolved.yaml")


def _first_difference(made: bytes, recorded: bytes) -> str:
    """The first line where ``made`` and ``recorded`` differ, both ways, for the failure message."""
    for number, (a, b) in enumerate(zip(made.splitlines(), recorded.splitlines(), strict=False), start=1):
        if a != b:
            return f"line {number}: made {a[:200]!r}, recorded {b[:200]!r}"
    return f"lengths differ: made {len(made)} bytes, recorded {len(recorded)}"


def test_every_shipped_study_has_recorded_results():
    assert STUDIES and sorted(path.name for path in GOLDEN.iterdir()) == STUDIES


@pytest.mark.parametrize("study", STUDIES)
def test_a_shipped_studys_results_are_the_recorded_ones(study, smoke_runs):
    for name in FILES:
        made = (smoke_runs[study] / name).read_bytes().replace(str(ROOT).encode(), b"<checkout>")
        recorded_file = GOLDEN / study / f"{name}.gz"
        if os.environ.get("CRX_RECORD_RESULTS") == "1":
            recorded_file.parent.mkdir(parents=True, exist_ok=True)
            recorded_file.write_bytes(gzip.compress(made, mtime=0))
        recorded = gzip.decompress(recorded_file.read_bytes())
        assert made == recorded, f"{study}/{name} differs from the recorded result: " + _first_difference(
            made, recorded
        )
