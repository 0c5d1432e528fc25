"""The names of a run's result files, and atomic JSON and text writes (the run folder uses them too)."""

from __future__ import annotations

import json
import os

from .._io import atomic_open

DESIGNS = "designs.json"
PARETO = "pareto.csv"
REPORT = "report.html"
TIMINGS = "timings.json"


def write_json(path: str | os.PathLike[str], data: object) -> None:
    """Write ``data`` as JSON, atomically (NaN refused: it is never a valid result)."""
    with atomic_open(path, "w", encoding="utf-8") as handle:
        json.dump(data, handle, indent=1, allow_nan=False)
        handle.write("\n")


def write_text(path: str | os.PathLike[str], text: str) -> None:
    """Write ``text`` as UTF-8, atomically."""
    with atomic_open(path, "w", encoding="utf-8") as handle:
        handle.write(text)
