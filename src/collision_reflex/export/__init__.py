"""Export a design of a run to the robot formats simulators read: URDF with motors, MJCF with armature.

:func:`export_design` writes the arm of a run folder with one of its designs: URDF (:mod:`.urdf`, with its
armature companion :mod:`.armature`) or MJCF (:mod:`.mjcf`, needs the ``mujoco`` extra).
"""

from __future__ import annotations

import json
import os
import shutil
from pathlib import Path

from .._io import atomic_open
from ..errors import CollisionReflexError, InvalidParameter
from ..vocabulary import DESIGN_CHOICES, EXPORT_FORMATS
from .armature import armature_record, companion_path, set_armature
from .mjcf import design_mjcf
from .run_design import RunDesign, read_run_design
from .urdf import design_urdf

__all__ = [
    "DESIGN_CHOICES",
    "ExportUnwritable",
    "RunDesign",
    "companion_path",
    "export_design",
    "read_run_design",
    "set_armature",
]


class ExportUnwritable(CollisionReflexError):
    """The exported file cannot be written (a missing or read-only folder, a folder in the way)."""


def export_design(
    run_dir: str | os.PathLike[str],
    design: str | int = "recommended",
    format: str = "urdf",
    out: str | os.PathLike[str] = "design.urdf",
) -> list[Path]:
    """Write the arm of the run folder ``run_dir`` with the actuators of one of its designs.

    Parameters
    ----------
    run_dir: the output folder of ``crx run`` of an arm study.
    design: ``"recommended"``, ``"chosen"`` (the single-objective optimum) or a Pareto design's index.
    format: ``"urdf"`` (with the armature companion ``OUT.armature.json``) or ``"mjcf"``.
    out: the file to write.

    Returns
    -------
    The files written.
    """
    if format not in EXPORT_FORMATS:
        raise InvalidParameter("format", format, " or ".join(EXPORT_FORMATS))
    out = Path(out)
    try:
        if out.is_dir():
            raise ExportUnwritable(f"cannot write {out}: it is a folder; give a file name")
        if out.parent.exists() and not out.parent.is_dir():
            raise ExportUnwritable(f"cannot write {out}: {out.parent} is a file, not a folder")
    except OSError as error:  # a name too long for the file system, say
        raise ExportUnwritable(f"cannot write {out}: {error.strerror or error}") from None
    chosen = read_run_design(run_dir, design)
    urdf, meshes = design_urdf(chosen, out)
    if format == "mjcf":
        return [_write(out, design_mjcf(chosen, urdf))]
    companion = json.dumps(armature_record(chosen, out.name), indent=1) + "\n"
    return [_write(out, urdf), _write(companion_path(out), companion), *_copy_meshes(meshes)]


def _copy_meshes(meshes: dict[Path, Path]) -> list[Path]:
    """Copy each mesh file to its place beside the URDF; an unwritable place is :class:`ExportUnwritable`."""
    written = []
    for source, destination in meshes.items():
        try:
            destination.parent.mkdir(parents=True, exist_ok=True)
            shutil.copyfile(source, destination)
        except OSError as error:
            raise ExportUnwritable(f"cannot write {destination}: {error.strerror or error}") from None
        written.append(destination)
    return written


def _write(path: Path, text: str) -> Path:
    """Write ``text`` to ``path`` atomically; an unwritable place is :class:`ExportUnwritable`."""
    try:
        with atomic_open(path, "w", encoding="utf-8") as handle:
            handle.write(text)
    except OSError as error:
        raise ExportUnwritable(f"cannot write {path}: {error.strerror or error}") from None
    return path
