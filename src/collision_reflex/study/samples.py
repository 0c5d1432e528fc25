"""Configurations and contact directions of a study's samples.

Directions are unit vectors in the arm's task coordinates (2 components for a planar arm, 3 otherwise). The
circle and sphere samplings are deterministic (evenly spread), and random configurations come from the study's
seed, so a study's numbers depend only on its file.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ..arm.directions import circle_directions, sphere_directions, unit_directions
from ..errors import InvalidParameter
from .load import LoadedStudy
from .schema import ArmStudy, ConfigurationSamples, DirectionSamples

if TYPE_CHECKING:
    from ..arm import Arm


def direction_samples(loaded: LoadedStudy, arm: Arm) -> np.ndarray:
    """The contact directions of an arm study, unit vectors (n, task_dim) in the arm's task coordinates.

    ``circle: n`` spreads n directions evenly over the arm's plane (planar arms) or the world x-y plane;
    ``sphere: n`` over the sphere (:func:`collision_reflex.arm.directions.sphere_directions`); named directions and
    listed vectors go through :func:`collision_reflex.arm.directions.unit_directions` (world vectors are projected
    into a planar arm's plane). A direction the arm cannot use is reported at its line.
    """
    study = loaded.study
    assert isinstance(study, ArmStudy)
    spec: DirectionSamples = study.samples.directions
    task_dim = int(arm.task_dim)
    if spec.circle is not None:
        planar = circle_directions(spec.circle)
        return planar if task_dim == 2 else np.column_stack([planar, np.zeros(spec.circle)])
    if spec.sphere is not None:
        return sphere_directions(spec.sphere)
    field, items = ("named", list(spec.named)) if spec.named is not None else ("list", list(spec.list or []))
    out = []
    for index, item in enumerate(items):
        try:
            out.append(unit_directions([item], task_dim, arm.plane)[0])
        except InvalidParameter as error:
            raise loaded.fail(("samples", "directions", field, index), repr(item), error.allowed) from None
    return np.array(out)


def configuration_samples(loaded: LoadedStudy, arm: Arm) -> np.ndarray:
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
        return np.asarray(arm.configuration(np.asarray(spec.list, dtype=float)), dtype=float)
    assert spec.trajectory is not None  # exactly one source is guaranteed by the schema
    return _trajectory(loaded, arm, spec.trajectory.file, spec.trajectory.every)


def _trajectory(loaded: LoadedStudy, arm: Arm, file: str, every: int) -> np.ndarray:
    import pandas as pd

    where = ("samples", "configurations", "trajectory", "file")
    try:
        table = pd.read_csv(loaded.path(file))
    except (OSError, ValueError) as error:
        raise loaded.fail(where, f"{file!r}, which cannot be read as CSV ({error})", "a CSV file") from None
    joints = list(arm.joint_names)
    missing = [name for name in joints if name not in table.columns]
    if missing:
        raise loaded.fail(
            where,
            f"{file!r} without columns {', '.join(missing)}",
            "a header row naming every joint: " + ", ".join(joints),
        )
    values = table[joints].to_numpy(dtype=float)[::every]
    if values.size == 0 or not np.all(np.isfinite(values)):
        raise loaded.fail(
            where, f"{file!r} with no rows or with non-numeric values", "finite joint positions [rad]"
        )
    return np.asarray(arm.configuration(values), dtype=float)
