"""A run's output folder: atomic files, a manifest that ties it to one study, finished work kept for resuming.

Layout::

    OUT/study.resolved.yaml   the study as run (defaults explicit, SI units)
    OUT/run.json              manifest: study fingerprint, status, timings
    OUT/points/*.json         one file per finished piece of work (a Pareto point, an anchor, ...)
    OUT/pareto.csv, OUT/designs.json, OUT/figures/*, OUT/report.html   the results

Every file is written to a temporary name and renamed, so it is complete or absent.
"""

from __future__ import annotations

import json
import os
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from .._io import read_json, remove_temporary_files
from ..errors import CollisionReflexError
from ..report.files import DESIGNS, PARETO, REPORT, write_json, write_text

MANIFEST = "run.json"
RESOLVED = "study.resolved.yaml"
__all__ = [
    "DESIGNS",
    "MANIFEST",
    "PARETO",
    "REPORT",
    "RESOLVED",
    "OutputFolderInUse",
    "OutputFolderUnusable",
    "RunFolder",
    "read_json",
    "write_json",
    "write_text",
]


class OutputFolderInUse(CollisionReflexError):
    """The output folder holds results of a different study (or of the same study with other settings)."""


class OutputFolderUnusable(CollisionReflexError):
    """The output folder cannot be made or written (a read-only parent, a regular file, a full disk).

    ``exit_status``: 2 when nothing was computed yet, 1 when the failure came after work had started (the
    finished pieces are kept).
    """

    def __init__(self, path: str | os.PathLike[str], reason: str, exit_status: int = 2) -> None:
        self.path = Path(path)
        self.exit_status = exit_status
        super().__init__(f"cannot write {self.path}: {reason}")

    @classmethod
    def from_os_error(
        cls, error: OSError, fallback: str | os.PathLike[str], exit_status: int = 2
    ) -> OutputFolderUnusable:
        """The error for ``error`` (its file, else ``fallback``; its reason)."""
        reason = error.strerror or str(error)
        return cls(error.filename or fallback, reason, exit_status)


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
        try:
            return self._claim(fingerprint, resolved_yaml, details)
        except OSError as error:
            raise OutputFolderUnusable.from_os_error(error, self.path) from None

    def _claim(self, fingerprint: str, resolved_yaml: str, details: dict[str, Any]) -> bool:
        manifest = self.path / MANIFEST
        resumed = False
        if self.path.exists() and not self.path.is_dir():
            raise OutputFolderUnusable(self.path, "it is a file, not a folder; give a folder with --out")
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
        for folder in (self.path, self.points, self.figures):
            remove_temporary_files(folder)  # left by a writer killed before its rename
        write_text(self.path / RESOLVED, resolved_yaml)
        write_json(manifest, {"fingerprint": fingerprint, "status": "running", **details})
        return resumed

    def finished(self, name: str) -> dict[str, Any] | None:
        """A finished piece of work saved under ``name``, or None."""
        path = self.points / f"{name}.json"
        if not path.exists():
            return None
        try:
            record = read_json(path)
        except (OSError, ValueError) as error:
            return self._damaged(path, f"unreadable ({error})")
        if not isinstance(record, dict) or not record:
            return self._damaged(
                path, f"holds {type(record).__name__} {_excerpt(record)} instead of a record"
            )
        return record

    @staticmethod
    def _damaged(path: Path, reason: str) -> None:
        """Report a damaged piece, which is then done again."""
        print(f"warning: {path} is {reason}; computing it again", file=sys.stderr)
        return None

    def peek(self, name: str) -> dict[str, Any] | None:
        """:meth:`finished` before the folder is claimed: None where the folder or the piece cannot be read."""
        try:
            return self.finished(name)
        except OSError:
            return None

    def save(self, name: str, record: dict[str, Any]) -> None:
        """Keep a finished piece of work under ``name`` (atomically)."""
        write_json(self.points / f"{name}.json", record)

    def update_manifest(self, **fields: Any) -> None:
        """Set ``fields`` in the run manifest, keeping the others."""
        manifest = self.path / MANIFEST
        data = read_json(manifest) if manifest.exists() else {}
        data.update(fields)
        write_json(manifest, data)


def _excerpt(value: Any, limit: int = 40) -> str:
    """``value`` as short JSON text, for a message."""
    text = json.dumps(value)
    return text if len(text) <= limit else text[: limit - 3] + "..."
