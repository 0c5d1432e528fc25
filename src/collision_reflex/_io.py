"""Files in and out: bounded input (a regular file of a limited size), atomic output (complete or absent)."""

from __future__ import annotations

import contextlib
import errno
import json
import os
import re
import stat
import tempfile
import time
from collections.abc import Iterator
from pathlib import Path
from typing import IO, Any

INPUT_LIMIT = 64 * 2**20
"""Largest input file read [bytes]: more than any study, catalogue, trace or run record needs, and small enough
that a wrong file (a disk image, ``/dev/zero``) is refused at once instead of filling the memory."""


def not_a_file(path: str | os.PathLike[str]) -> str | None:
    """Why ``path`` is not a regular file to read, in a short phrase, or None when it is one.

    Symbolic links are followed: ``"no such file"`` (also for a dangling link), ``"a folder, not a file"``,
    ``"a named pipe (FIFO), not a regular file"``, ``"a device, not a regular file"``, ``"a socket, not a
    regular file"``, or the system's reason for a path it refuses (too long, a NUL byte).
    """
    try:
        mode = os.stat(path).st_mode
    except FileNotFoundError:
        return "no such file"
    except (OSError, ValueError) as error:  # ValueError: a NUL byte in the path
        return str(getattr(error, "strerror", None) or error)
    if stat.S_ISREG(mode):
        return None
    if stat.S_ISDIR(mode):
        return "a folder, not a file"
    if stat.S_ISFIFO(mode):
        return "a named pipe (FIFO), not a regular file"
    if stat.S_ISCHR(mode) or stat.S_ISBLK(mode):
        return "a device, not a regular file"
    return "a socket, not a regular file" if stat.S_ISSOCK(mode) else "not a regular file"


def read_limited(path: str | os.PathLike[str], limit: int = INPUT_LIMIT) -> bytes:
    """The bytes of the regular file ``path``, of at most ``limit`` bytes.

    Raises :class:`OSError` (its ``strerror`` says why) for a file that is not there, not a regular file (a
    device, a pipe, a folder: reading it could block or never end) or larger than ``limit``, checked before
    reading and again while reading (a file that grows).
    """
    target = Path(path)
    if not stat.S_ISREG(target.stat().st_mode):
        raise OSError(errno.EINVAL, "not a regular file (a device, a pipe or a folder)", str(target))
    with target.open("rb") as handle:
        if os.fstat(handle.fileno()).st_size > limit:
            raise OSError(errno.EFBIG, f"larger than {limit / 2**20:g} MiB", str(target))
        data = handle.read(limit + 1)
    if len(data) > limit:
        raise OSError(errno.EFBIG, f"larger than {limit / 2**20:g} MiB", str(target))
    return data


def read_json(path: str | os.PathLike[str]) -> Any:
    """A JSON file (UTF-8), bounded as :func:`read_limited`.

    NaN and infinities are read as floats: the package writes none (``allow_nan=False``), and the record
    checks (:mod:`collision_reflex.record.checked`) refuse one where it is found, naming its field.
    """
    return json.loads(read_limited(path).decode("utf-8"))


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
    # Renaming onto a device or a pipe would replace it (as root, /dev/zero itself): refuse it.
    with contextlib.suppress(FileNotFoundError):
        if not stat.S_ISREG(mode := target.lstat().st_mode) and not stat.S_ISLNK(mode):
            raise OSError(errno.EINVAL, "not a regular file (a device, a pipe or a folder)", str(target))
    target.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp_name = tempfile.mkstemp(  # the writer's process id in the name: a dead writer's is removable
        prefix=f"{TEMPORARY_PREFIX}{target.stem}.{os.getpid()}.", suffix=target.suffix, dir=target.parent
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

    A file whose writer (the process id in its name) is gone goes at once; any other only once untouched for
    ``older_than`` [s]: a younger one may be another process's write in progress.
    """
    removed = []
    now = time.time()
    for stale in Path(folder).glob(f"{TEMPORARY_PREFIX}*"):
        with contextlib.suppress(FileNotFoundError):
            if stale.is_file() and (_writer_gone(stale) or now - stale.stat().st_mtime >= older_than):
                stale.unlink()
                removed.append(stale)
    return removed


_WRITER = re.compile(r"\.(\d+)\.[A-Za-z0-9_]+(?:\.[^.]*)?$")
"""The writer's process id in a temporary file's name (:func:`atomic_path`), before mkstemp's random part."""


def _writer_gone(path: Path) -> bool:
    """Whether the process that wrote the temporary file ``path`` no longer runs (False when unknown)."""
    match = _WRITER.search(path.name)
    if match is None:
        return False
    try:
        os.kill(int(match.group(1)), 0)  # signal 0: only asks whether the process exists
    except ProcessLookupError:
        return True
    except (PermissionError, OverflowError, ValueError):  # another user's process, or not a process id
        return False
    return False


def _umask() -> int:
    """The process's umask (reading it means setting it: set it straight back)."""
    mask = os.umask(0o022)
    os.umask(mask)
    return mask
