"""Collision directions: unit vectors on the circle (planar arms) or the sphere (spatial arms).

Directions are world-aligned. For a planar arm they are given in the arm's plane coordinates (its
``Arm.plane`` basis); world-named directions (``"x"``, ``"-z"``, ...) are projected into that plane.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np

from .. import _validate
from ..errors import InvalidParameter

NAMED_DIRECTIONS: dict[str, tuple[float, float, float]] = {
    "x": (1.0, 0.0, 0.0),
    "y": (0.0, 1.0, 0.0),
    "z": (0.0, 0.0, 1.0),
    "up": (0.0, 0.0, 1.0),
    "down": (0.0, 0.0, -1.0),
}
"""World axes by name; a leading ``-`` (or ``+``) flips (keeps) the sense, e.g. ``"-x"``."""


def circle_directions(count: int, start: float = 0.0) -> np.ndarray:
    """``count`` unit vectors evenly spaced on the circle, (count, 2), the first at angle ``start`` [rad]."""
    count = _count(count)
    if np.ndim(_validate.finite("start", start)) != 0:
        raise InvalidParameter("start", start, "one finite angle [rad]")
    angles = start + 2 * np.pi * np.arange(count) / count
    return np.stack([np.cos(angles), np.sin(angles)], axis=1)


def sphere_directions(count: int) -> np.ndarray:
    """``count`` nearly uniform unit vectors on the sphere, (count, 3).

    The Fibonacci (golden-angle) lattice: deterministic, with equal-area bands in ``z``.
    """
    count = _count(count)
    index = np.arange(count) + 0.5
    z = 1 - 2 * index / count
    radius = np.sqrt(1 - z**2)
    azimuth = np.pi * (3 - np.sqrt(5)) * index
    return np.stack([radius * np.cos(azimuth), radius * np.sin(azimuth), z], axis=1)


COORDINATE_PLANES: tuple[str, ...] = ("x-y", "x-z", "y-z")


def coordinate_plane(name: str) -> np.ndarray:
    """(3, 2) world basis of a coordinate plane named ``"x-y"``, ``"x-z"`` or ``"y-z"``."""
    if name not in COORDINATE_PLANES:
        raise InvalidParameter("plane", name, "one of " + ", ".join(COORDINATE_PLANES))
    index = {"x": 0, "y": 1, "z": 2}
    first, second = (index[axis] for axis in name.split("-"))
    return np.eye(3)[:, [first, second]]


def plane_directions(name: str, count: int) -> np.ndarray:
    """``count`` world unit vectors (count, 3) evenly spread on the great circle of a coordinate plane."""
    return circle_directions(count) @ coordinate_plane(name).T


def unit_directions(spec: Any, task_dim: int, plane: np.ndarray | None = None) -> np.ndarray:
    """Directions from a specification, as unit vectors (d, task_dim).

    Parameters
    ----------
    spec: a count (evenly spread on the circle or sphere); a name (``"x"``, ``"-z"``, ``"down"``) or a
        comma-separated list of names; or a sequence of names and vectors. Vectors have ``task_dim`` components
        (plane coordinates for a planar arm) or 3 world components (projected into the plane).
    task_dim: 2 (planar arm) or 3.
    plane: (3, 2) basis of a planar arm's plane (``Arm.plane``), needed to project world vectors.
    """
    if (
        isinstance(task_dim, bool | np.bool_)
        or not isinstance(task_dim, int | np.integer)
        or task_dim not in (2, 3)
    ):
        raise InvalidParameter("task_dim", task_dim, "2 or 3")
    if isinstance(spec, int | np.integer):
        return circle_directions(int(spec)) if task_dim == 2 else sphere_directions(int(spec))
    if isinstance(spec, str):
        spec = [part.strip() for part in spec.split(",") if part.strip()]
    if isinstance(spec, np.ndarray) and spec.ndim == 1:
        spec = [spec]
    if not isinstance(spec, Sequence | np.ndarray) or len(spec) == 0:
        raise InvalidParameter("directions", spec, "a count, names such as 'x,-z', or a list of vectors")
    vectors = [_vector(item, task_dim, plane) for item in spec]
    return np.array(vectors)


def normalised_directions(directions: Any, task_dim: int) -> np.ndarray:
    """Direction vectors (d, task_dim) checked (non-zero, finite) and scaled to unit length."""
    units = np.atleast_2d(_validate.real("directions", directions, "real direction vectors"))
    if units.ndim != 2 or units.shape[1] != task_dim:
        raise InvalidParameter("directions", units.shape, f"unit vectors of shape (d, {task_dim})")
    norms = np.linalg.norm(units, axis=1)
    if not np.all(np.isfinite(norms) & (norms > 0)):
        raise InvalidParameter("directions", directions, "non-zero finite vectors")
    return units / norms[:, None]


def _vector(item: Any, task_dim: int, plane: np.ndarray | None) -> np.ndarray:
    if isinstance(item, str):
        text = item.strip().lower()
        sign = -1.0 if text.startswith("-") else 1.0
        name = text.lstrip("+-")
        if name not in NAMED_DIRECTIONS:
            raise InvalidParameter(
                "direction",
                item,
                "one of " + ", ".join(sorted(NAMED_DIRECTIONS)) + " (with an optional sign)",
            )
        vector = sign * np.array(NAMED_DIRECTIONS[name])
    else:
        vector = np.asarray(item, dtype=float).ravel()
    if vector.size == 3 and task_dim == 2:
        if plane is None:
            raise InvalidParameter("direction", item, "2 plane coordinates (no plane basis to project onto)")
        world = vector
        vector = plane.T @ world
        if float(np.linalg.norm(vector)) < 1e-9 * float(np.linalg.norm(world)):
            raise InvalidParameter("direction", item, "a direction with a component in the arm's plane")
    if vector.size != task_dim or not np.all(np.isfinite(vector)) or np.linalg.norm(vector) == 0:
        raise InvalidParameter("direction", item, f"a non-zero finite vector of {task_dim} components")
    return vector / np.linalg.norm(vector)


MAX_DIRECTIONS = 1_000_000
"""Most directions a set may hold: far beyond any study's, and a bound on the memory a count can ask for."""


def _count(count: Any) -> int:
    """``count`` as an int, if it is a whole number from 1 to :data:`MAX_DIRECTIONS` (not a bool)."""
    allowed = f"a whole number from 1 to {MAX_DIRECTIONS:,}"
    if isinstance(count, bool | np.bool_) or not isinstance(count, int | np.integer | float | np.floating):
        raise InvalidParameter("count", count, allowed)
    if not (math.isfinite(count) and int(count) == count and 1 <= count <= MAX_DIRECTIONS):
        raise InvalidParameter("count", count, allowed)
    return int(count)
