"""The human body regions of ISO/TS 15066 (or a file of the same form), read like the catalogues."""

from __future__ import annotations

import os
from pathlib import Path

from ..hardware.catalogue import packaged_catalogue_path, read_entries
from ..model.contact import BodyRegion


def load_body_regions(path: str | os.PathLike[str] | None = None) -> dict[str, BodyRegion]:
    """The body regions of a YAML file, by name (default: the standard's, the packaged ``designs/body_regions.yaml``).

    The file has a top-level ``body_regions`` mapping from name to entry; each entry gives ``stiffness``,
    ``mass``, ``quasi_static_force``, optionally ``transient_force``, and a ``source`` (per-field ``sources`` and
    ``estimates`` as in the catalogues). Numbers are plain SI or strings with units (``"75 N/mm"``). Bad input
    raises :class:`~collision_reflex.errors.CatalogueError` naming the file, the line and the field.
    """
    target = Path(path) if path is not None else packaged_catalogue_path("body_regions.yaml")
    return {
        name: BodyRegion(
            name,
            entry.fields["stiffness"],
            entry.fields["mass"],
            entry.fields["transient_force"],
            entry.fields["quasi_static_force"],
        )
        for name, entry in read_entries(target, "body_regions").items()
    }


def transient_regions() -> dict[str, BodyRegion]:
    """The standard's regions that permit a transient contact (a transient force is given), by name."""
    return {
        name: region for name, region in load_body_regions().items() if region.transient_force is not None
    }
