"""A run's output folder: atomic files, a manifest that ties it to one study, finished work kept for resuming.

Layout::

    OUT/study.resolved.yaml   the study as run (defaults explicit, SI units)
    OUT/run.json              manifest: study fingerprint, status, timings
    OUT/points/*.json         one file per finished piece of work (a Pareto point, an anchor, ...)
    OUT/pareto.csv, OUT/designs.json, OUT/figures/*, OUT/report.html   the results

Every file is written to a temporary name and renamed, so it is complete or absent.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ..errors import CollisionReflexError
from ..report.files import DESIGNS, PARETO, REPORT, ResultsMissing, read_json, write_json, write_text

MANIFEST = "run.json"
RESOLVED = "study.resolved.yaml"
__all__ = [
    "DESIGNS",
    "MANIFEST",
    "PARETO",
    "REPORT",
    "RESOLVED",
    "OutputFolderInUse",
    "ResultsMissing",
    "RunFolder",
    "read_json",
    "write_json",
    "write_text",
]


class OutputFolderInUse(CollisionReflexError):
    """The output folder holds results of a different study (or of the same study with other settings)."""


@dataclass(frozen=True)
class RunFolder:
    """The output folder of one study run."""

    path: Path

    @property
    def points(self) -> Path:
        """The folder of finished pieces of work."""
        return self.path / "points"

    @property
    def figures(self) -> Path:
        """The folder of the report's figures."""
        return self.path / "figures"

    def claim(self, fingerprint: str, resolved_yaml: str, details: dict[str, Any]) -> bool:
        """Make the folder this study's; returns True if it already was (a resumed run).

        Raises :class:`OutputFolderInUse` if it holds another study's results.
        """
        manifest = self.path / MANIFEST
        resumed = False
        if manifest.exists():
            try:
                previous = read_json(manifest)
            except (OSError, ValueError):
                previous = {}
            if previous.get("fingerprint") != fingerprint:
                raise OutputFolderInUse(
                    f"{self.path} holds results of {previous.get('study', 'another study')!r} run with other "
                    "settings; give another folder with --out, or delete this one to start afresh"
                )
            resumed = True
        elif self.path.exists() and any(self.path.iterdir()):
            raise OutputFolderInUse(
                f"{self.path} exists and is not a study's output folder; give another folder with --out"
            )
        self.path.mkdir(parents=True, exist_ok=True)
        write_text(self.path / RESOLVED, resolved_yaml)
        write_json(manifest, {"fingerprint": fingerprint, "status": "running", **details})
        return resumed

    def finished(self, name: str) -> dict[str, Any] | None:
        """A finished piece of work saved under ``name``, or None."""
        path = self.points / f"{name}.json"
        if not path.exists():
            return None
        try:
            record: dict[str, Any] = read_json(path)
            return record
        except (OSError, ValueError):
            return None  # unreadable: do the work again

    def save(self, name: str, record: dict[str, Any]) -> None:
        """Keep a finished piece of work under ``name`` (atomically)."""
        write_json(self.points / f"{name}.json", record)

    def update_manifest(self, **fields: Any) -> None:
        """Set ``fields`` in the run manifest, keeping the others."""
        manifest = self.path / MANIFEST
        data = read_json(manifest) if manifest.exists() else {}
        data.update(fields)
        write_json(manifest, data)
