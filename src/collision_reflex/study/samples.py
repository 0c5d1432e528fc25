"""Configurations and contact directions of a study's samples.

Directions are unit vectors in the arm's task coordinates (2 components for a planar arm, 3 otherwise). The
circle and sphere samplings are deterministic (evenly spread), so a study's numbers depend only on its file.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from .load import LoadedStudy
from .schema import ArmStudy, ConfigurationSamples, DirectionSamples

_AXES = {"x": 0, "y": 1, "z": 2}


def circle_directions(count: int, task_dim: int = 2) -> np.ndarray:
    """``count`` unit vectors evenly spread over the circle, starting at +x; in the x-y plane for ``task_dim`` 3.

    Returns an array of shape (count, task_dim).
    """
    angles = 2 * np.pi * np.arange(count) / count
    out = np.zeros((count, task_dim))
    out[:, 0], out[:, 1] = np.cos(angles), np.sin(angles)
    return out


def sphere_directions(count: int) -> np.ndarray:
    """``count`` unit vectors spread evenly over the sphere (a Fibonacci lattice), shape (count, 3).

    Each vector stands for an equal area of the sphere (the lattice places point ``i`` at height
    ``1 - (2 i + 1) / count``, equally spaced in ``z``, which by Archimedes' hat-box theorem is equal area).
    """
    index = np.arange(count)
    z = 1 - (2 * index + 1) / count
    radius = np.sqrt(np.clip(1 - z**2, 0.0, None))
    golden_angle = math.pi * (3 - math.sqrt(5))
    azimuth = golden_angle * index
    return np.column_stack([radius * np.cos(azimuth), radius * np.sin(azimuth), z])


def named_directions(names: list[str], task_dim: int) -> np.ndarray:
    """Unit vectors for names such as ``"+x"`` or ``"-z"``, shape (len(names), task_dim)."""
    out = np.zeros((len(names), task_dim))
    for row, name in enumerate(names):
        out[row, _AXES[name[1]]] = 1.0 if name[0] == "+" else -1.0
    return out


def direction_samples(spec: DirectionSamples, task_dim: int) -> np.ndarray:
    """The contact directions of a study, unit vectors of shape (n, task_dim)."""
    if spec.circle is not None:
        return circle_directions(spec.circle, task_dim)
    if spec.sphere is not None:
        return sphere_directions(spec.sphere)
    if spec.named is not None:
        return named_directions(list(spec.named), task_dim)
    vectors = np.asarray(spec.list, dtype=float)
    return vectors / np.linalg.norm(vectors, axis=1, keepdims=True)


def configuration_samples(loaded: LoadedStudy, arm: Any) -> np.ndarray:
    """The configurations of an arm study [rad], shape (n, nq).

    Random configurations come from ``arm.sample_configurations`` with ``numpy.random.default_rng(seed)``; a
    trajectory is a CSV file with one column per joint, named by the joint's name (other columns, e.g. time,
    are ignored), of which every ``every``-th row is used.
    """
    study = loaded.study
    assert isinstance(study, ArmStudy)
    spec: ConfigurationSamples = study.samples.configurations
    if spec.random is not None:
        rng = np.random.default_rng(spec.random.seed)
        return np.asarray(arm.sample_configurations(spec.random.count, rng), dtype=float)
    if spec.list is not None:
        return np.asarray(spec.list, dtype=float)
    assert spec.trajectory is not None  # exactly one source is guaranteed by the schema
    return _trajectory(loaded, arm, spec.trajectory.file, spec.trajectory.every)


def _trajectory(loaded: LoadedStudy, arm: Any, file: str, every: int) -> np.ndarray:
    import pandas as pd

    where = ("samples", "configurations", "trajectory", "file")
    try:
        table = pd.read_csv(loaded.path(file))
    except (OSError, ValueError) as error:
        raise loaded.fail(where, f"{file!r}, which cannot be read as CSV ({error})", "a CSV file") from None
    joints = list(arm.joint_names)
    missing = [name for name in joints if name not in table.columns]
    if missing:
        raise loaded.fail(where, f"{file!r} without columns {', '.join(missing)}",
                          "a header row naming every joint: " + ", ".join(joints))
    if arm.model.nq != len(joints):
        raise loaded.fail(where, "a trajectory for a robot whose nq differs from its joint count",
                          "random or listed configurations for this robot")
    values = table[joints].to_numpy(dtype=float)[::every]
    if values.size == 0 or not np.all(np.isfinite(values)):
        raise loaded.fail(where, f"{file!r} with no rows or with non-numeric values", "finite joint positions [rad]")
    return values
