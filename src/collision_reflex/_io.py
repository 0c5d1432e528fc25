"""Atomic output: a file appears complete under its final name or not at all."""

from __future__ import annotations

import contextlib
import os
import tempfile
import time
from collections.abc import Iterator
from pathlib import Path
from typing import IO, Any

TEMPORARY_PREFIX = ".tmp-"
"""Names of temporary files start so: a writer killed before its rename leaves one, removable by name."""


@contextlib.contextmanager
def atomic_path(path: str | os.PathLike[str]) -> Iterator[Path]:
    """Yield a temporary path beside ``path``; on success rename it to ``path``, on error remove it.

    The temporary file keeps the target's suffix so that writers which infer the format from it (matplotlib)
    behave as for the real name, and gets the mode of a newly created file (the umask's, not ``mkstemp``'s
    0600), so that the result is as readable as any other file the user writes.
    """
    target = Path(path)
    target.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp_name = tempfile.mkstemp(
        prefix=f"{TEMPORARY_PREFIX}{target.stem}.", suffix=target.suffix, dir=target.parent
    )
    tmp = Path(tmp_name)
    try:
        if hasattr(os, "fchmod"):  # POSIX; Windows has no such modes
            os.fchmod(fd, 0o666 & ~_umask())
    finally:
        os.close(fd)
    try:
        yield tmp
        os.replace(tmp, target)
    finally:
        if tmp.exists():
            tmp.unlink()


@contextlib.contextmanager
def atomic_open(path: str | os.PathLike[str], mode: str = "w", **kwargs: Any) -> Iterator[IO[Any]]:
    """``open`` for writing, atomically (see :func:`atomic_path`)."""
    with atomic_path(path) as tmp, open(tmp, mode, **kwargs) as handle:
        yield handle


def remove_temporary_files(folder: str | os.PathLike[str], older_than: float = 60.0) -> list[Path]:
    """Remove the temporary files a killed writer left in ``folder`` (not below it); returns them.

    Only files untouched for ``older_than`` [s] go: a younger one may be another process's write in progress.
    """
    removed = []
    now = time.time()
    for stale in Path(folder).glob(f"{TEMPORARY_PREFIX}*"):
        with contextlib.suppress(FileNotFoundError):
            if stale.is_file() and now - stale.stat().st_mtime >= older_than:
                stale.unlink()
                removed.append(stale)
    return removed


def _umask() -> int:
    """The process's umask (reading it means setting it: set it straight back)."""
    mask = os.umask(0o022)
    os.umask(mask)
    return mask
