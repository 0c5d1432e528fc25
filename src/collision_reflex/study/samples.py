"""Configurations and contact directions of a study's samples, and the contact domain they are drawn in.

Directions are unit vectors in the arm's task coordinates (2 components for a planar arm, 3 otherwise). The
circle and sphere samplings are deterministic (evenly spread), and random configurations come from the study's
seed, so a study's numbers depend only on its file. Random configurations are drawn in the study's contact
domain (:class:`collision_reflex.arm.domain.ContactDomain`), each with the directions feasible there; listed
and trajectory configurations are taken as given, with every direction.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from .._table import TableProblem, header_index, read_table
from ..arm.directions import circle_directions, sphere_directions, unit_directions
from ..arm.domain import ContactDomain, DomainTooSmall
from ..arm.duty_cycle import joint_positions
from ..errors import InvalidParameter, StudyFileError, StudyProblem, TrajectoryError
from .duty import per_joint_values, position_limits, prismatic_joints
from .load import LoadedStudy
from .sample_specs import ConfigurationSamples, DirectionSamples
from .schema import ArmStudy
from .source import excerpt

if TYPE_CHECKING:
    from ..arm import Arm
    from ..arm.domain import DomainDraw


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


def contact_domain(loaded: LoadedStudy, arm: Arm) -> ContactDomain:
    """The study's contact domain (``samples.domain``), its speed limits checked against the arm's joints."""
    study = loaded.study
    assert isinstance(study, ArmStudy)
    spec = study.samples.domain
    limits = None
    if spec.joint_speed_limit is not None:
        problems: list[StudyProblem] = []
        limits = per_joint_values(
            loaded,
            ("samples", "domain", "joint_speed_limit"),
            spec.joint_speed_limit,
            list(arm.joint_names),
            problems,
        )
        if problems:
            raise StudyFileError(loaded.source.file, problems)
    return ContactDomain.of_arm(arm, spec.min_singular_value, limits)


def domain_draw(
    loaded: LoadedStudy, arm: Arm, domain: ContactDomain, directions: np.ndarray, velocity: float
) -> DomainDraw:
    """The study's random configurations drawn in ``domain``, with the ``directions`` feasible at ``velocity``.

    ``velocity`` [m/s] is the fastest approach the design space allows, so that every sample is in the domain
    of every design. A domain that keeps almost nothing is refused at ``samples.domain``.
    """
    study = loaded.study
    assert isinstance(study, ArmStudy) and study.samples.configurations.random is not None
    spec = study.samples.configurations.random
    try:
        return domain.draw(arm, spec.count, directions, velocity, np.random.default_rng(spec.seed))
    except DomainTooSmall as error:
        raise loaded.fail(("samples", "domain"), str(error.value), f"{error.allowed}; {error.hint}") from None


def configuration_samples(loaded: LoadedStudy, arm: Arm) -> np.ndarray:
    """The listed or trajectory configurations of an arm study [rad], shape (n, nq).

    A trajectory is a CSV file with one column per joint, named by the joint's name (other columns, e.g.
    time, are ignored), of which every ``every``-th row is used. Random configurations are drawn in the
    contact domain by :func:`domain_draw`.
    """
    study = loaded.study
    assert isinstance(study, ArmStudy)
    spec: ConfigurationSamples = study.samples.configurations
    assert spec.random is None, "random configurations are drawn in the domain (domain_draw)"
    if spec.list is not None:
        angles = np.asarray(spec.list, dtype=float)
        outside = _outside_limits(arm, angles)
        if outside is not None:
            row, what, expected = outside
            raise loaded.fail(("samples", "configurations", "list", row), what, expected)
        return np.asarray(arm.configuration(angles), dtype=float)
    assert spec.trajectory is not None  # exactly one source is guaranteed by the schema
    return _trajectory(loaded, arm, spec.trajectory.file, spec.trajectory.every)


def sample_counts(loaded: LoadedStudy, arm: Arm) -> tuple[int, int]:
    """The numbers of configurations and of directions of an arm study, without drawing the random samples.

    Listed samples and trajectory files are checked as :func:`configuration_samples` and
    :func:`direction_samples` check them (each problem at its line); counts come from the file.
    """
    study = loaded.study
    assert isinstance(study, ArmStudy)
    configurations = study.samples.configurations
    directions = study.samples.directions
    if configurations.random is not None:
        n_configurations = configurations.random.count
    else:
        n_configurations = configuration_samples(loaded, arm).shape[0]
    counted = directions.circle if directions.circle is not None else directions.sphere
    n_directions = counted if counted is not None else direction_samples(loaded, arm).shape[0]
    return int(n_configurations), int(n_directions)


def _outside_limits(arm: Arm, angles: np.ndarray) -> tuple[int, str, str] | None:
    """The first row of joint coordinates (n, nv) outside the robot model's position limits: (row, what, expected).

    None where every row is within them (a joint without limits, a continuous one, takes any position).
    """
    lower, upper = position_limits(arm)
    outside = (angles < lower) | (angles > upper)
    if not outside.any():
        return None
    row, joint = map(int, np.argwhere(outside)[0])
    name = arm.joint_names[joint]
    unit = " m" if name in prismatic_joints(arm) else " rad"
    return (
        row,
        f"{name} at {angles[row, joint]:.6g}{unit}, outside its limits",
        f"a configuration within the joint limits: {name} from {lower[joint]:.6g} to {upper[joint]:.6g}{unit} "
        "(the robot model's)",
    )


_MAX_TRAJECTORY_SIZE = 64 << 20
"""Largest trajectory file read [bytes]: a million rows of seven joints."""


def _trajectory(loaded: LoadedStudy, arm: Arm, file: str, every: int) -> np.ndarray:
    """Every ``every``-th row of a trajectory CSV; each problem located at the study line and the CSV line."""
    where = ("samples", "configurations", "trajectory", "file")
    expected = "a CSV file with a header row naming every joint with its unit (joint1 [deg]), one row per configuration"
    try:
        with loaded.path(file).open("rb") as stream:
            data = stream.read(_MAX_TRAJECTORY_SIZE + 1)
        if len(data) > _MAX_TRAJECTORY_SIZE:
            raise loaded.fail(
                where, f"{excerpt(file)}, a file over {_MAX_TRAJECTORY_SIZE >> 20} MiB", expected
            )
        lines = data.decode("utf-8").splitlines()
    except (OSError, ValueError) as error:  # unreadable, not UTF-8, a NUL in the path
        reason = getattr(error, "strerror", None) or str(error)
        raise loaded.fail(where, f"{excerpt(file)}, which cannot be read ({reason})", expected) from None
    header = header_index(lines)
    if header is None:
        raise loaded.fail(where, f"{file}: no header line and no rows", expected)
    try:
        table = read_table(lines, header)
    except TableProblem as problem:
        raise loaded.fail(where, f"{file}:{problem.line}: {problem.reason}", expected) from None
    try:
        values = joint_positions(table, arm.joint_names, prismatic_joints(arm), file, header + 1)
    except TrajectoryError as error:
        raise loaded.fail(where, f"{file}:{error.line}: {error.reason}", expected) from None
    finite = np.isfinite(values).all(axis=1)
    if not finite.all():
        line = header + 2 + int(np.argmin(finite))  # file lines are 1-based; the header is one line
        raise loaded.fail(
            where, f"{file}:{line}: a value that is not a finite number", "finite joint positions [rad]"
        )
    outside = _outside_limits(arm, values)
    if outside is not None:
        row, what, expected = outside
        raise loaded.fail(where, f"{file}:{header + 2 + row}: {what}", expected)
    values = values[::every]
    if values.size == 0:
        raise loaded.fail(where, f"{file}: no rows below the header", "finite joint positions [rad]")
    try:
        return np.asarray(arm.configuration(values), dtype=float)
    except InvalidParameter as error:
        raise loaded.fail(
            where, f"{file}: {error}", "joint positions within the joints' limits [rad]"
        ) from None
