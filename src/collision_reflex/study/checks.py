"""What a study may not say beyond what its schema checks: every check across its fields, each written once.

:func:`cross_checks` runs when a study is loaded (no robot needed). The others run when an arm study is set up
(:func:`~.arm_setup.arm_setup`): features the arm optimiser does not model, actuator modules, gearboxes whose
ratios miss their joint's gear-ratio bounds, torque requirements given twice or out of reach; and
:func:`located_refusal` places a refusal of the design problem at the study field it comes from. Each problem
is located in the study file.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

from .._io import not_a_file
from ..errors import CatalogueError, InvalidParameter, StudyFileError, StudyProblem
from ..hardware.catalogue import read_entries
from ..hardware.motors import scaled_motor_quantities
from ..vocabulary import GLOBAL_VARIABLES, PER_JOINT_VARIABLES
from .body_regions import load_body_regions, transient_regions
from .schema import ActuatorStudy, ArmStudy
from .source import PathKey, excerpt

if TYPE_CHECKING:
    from ..arm.rating import Rating
    from ..hardware.gearboxes import CatalogueGearbox, ScaledGearbox
    from ..optimize import Bounds
    from .arm_setup import ArmSetup
    from .load import LoadedStudy


def raise_problems(loaded: LoadedStudy, problems: list[StudyProblem]) -> None:
    """Raise :class:`StudyFileError` with ``problems``, if there are any."""
    if problems:
        raise StudyFileError(loaded.source.file, problems)


def cross_checks(loaded: LoadedStudy) -> list[StudyProblem]:
    """The problems across a study's fields that need no robot model (paths, sensing against design, sizes)."""
    study = loaded.study
    if isinstance(study, ArmStudy):
        return _arm_checks(loaded, study)
    if isinstance(study, ActuatorStudy):
        return _actuator_checks(loaded, study)
    return []  # pragma: no cover - the kinds are exhaustive


def _arm_checks(loaded: LoadedStudy, study: ArmStudy) -> list[StudyProblem]:
    problems: list[StudyProblem] = []
    scheme = study.sensing.scheme
    if scheme == "current":
        problems.append(
            loaded.problem(
                ("sensing", "scheme"),
                "'current'",
                "'force' or 'position' for an arm study: a motor-current threshold makes the contact threshold "
                "a minimum over joints, which the optimiser does not handle; compare current sensing in an "
                "actuator study (kind: actuator)",
            )
        )
    design = study.design
    if design.threshold is not None and scheme != "force":
        problems.append(
            loaded.problem(
                ("design", "threshold"),
                f"a contact-force threshold with sensing scheme {scheme!r}",
                "design.position_error for position sensing (or sensing.scheme: force)",
            )
        )
    if design.position_error is not None and scheme != "position":
        problems.append(
            loaded.problem(
                ("design", "position_error"),
                f"a position-error threshold with sensing scheme {scheme!r}",
                "design.threshold for force sensing (or sensing.scheme: position)",
            )
        )
    if study.pareto is not None:
        for index, name in enumerate(study.pareto.objectives):
            if name == "approach_velocity" and (
                design.approach_velocity is None or not design.approach_velocity.free
            ):
                problems.append(
                    loaded.problem(
                        ("pareto", "objectives", index),
                        "'approach_velocity' while the velocity is fixed",
                        "free bounds design.approach_velocity: {min, max} to trade it off",
                    )
                )
    problems += _body_region_checks(loaded, study)
    problems += _catalogue_checks(loaded, study)
    robot = study.robot
    if robot.urdf is not None and not _is_file(loaded.path(robot.urdf)):
        problems.append(
            loaded.problem(("robot", "urdf"), f"{excerpt(robot.urdf)} (no such file)", _relative_hint(loaded))
        )
    for index, directory in enumerate(robot.package_dirs):
        if not _is_dir(loaded.path(directory)):
            problems.append(
                loaded.problem(
                    ("robot", "package_dirs", index),
                    f"{excerpt(directory)} (no such directory)",
                    _relative_hint(loaded),
                )
            )
    trajectory = study.samples.configurations.trajectory
    if trajectory is not None and not _is_file(loaded.path(trajectory.file)):
        problems.append(
            loaded.problem(
                ("samples", "configurations", "trajectory", "file"),
                f"{excerpt(trajectory.file)} (no such file)",
                _relative_hint(loaded),
            )
        )
    problems += _duty_cycle_checks(loaded, study)
    lengths = {len(q) for q in study.samples.configurations.list or []}
    if len(lengths) > 1:
        problems.append(
            loaded.problem(
                ("samples", "configurations", "list"),
                f"configurations of sizes {sorted(lengths)}",
                "every configuration with the same number of joint positions",
            )
        )
    directions = study.samples.directions.list or []
    if len({len(u) for u in directions}) > 1:
        problems.append(
            loaded.problem(
                ("samples", "directions", "list"),
                "vectors of different sizes",
                "every direction with the same number of components (2 for a planar arm, else 3)",
            )
        )
    return problems


def _duty_cycle_checks(loaded: LoadedStudy, study: ArmStudy) -> list[StudyProblem]:
    """The trajectory file exists; the payload is given once (``duty_cycle.payload`` or ``constraints.payload``)."""
    cycle = study.duty_cycle
    if cycle is None:
        return []
    problems = []
    why = None if cycle.file is None else not_a_file(loaded.path(cycle.file))
    if why is not None:  # a folder, a pipe or a device is not 'no such file'
        problems.append(
            loaded.problem(("duty_cycle", "file"), f"{excerpt(cycle.file)} ({why})", _relative_hint(loaded))
        )
    if cycle.payload is not None and study.constraints.payload != 0:
        problems.append(
            loaded.problem(
                ("constraints", "payload"),
                f"a payload of {study.constraints.payload:g} kg here and another in duty_cycle.payload",
                "the payload once: remove constraints.payload (duty_cycle.payload loads the static "
                "requirement too)",
            )
        )
    return problems


def _is_file(path: Path) -> bool:
    """Whether ``path`` is a regular file; False for a path the system refuses (too long, a NUL)."""
    try:
        return path.is_file()
    except (OSError, ValueError):
        return False


def _is_dir(path: Path) -> bool:
    """Whether ``path`` is a directory; False for a path the system refuses."""
    try:
        return path.is_dir()
    except (OSError, ValueError):
        return False


def _relative_hint(loaded: LoadedStudy) -> str:
    return "a path relative to the study file's folder"


def _actuator_checks(loaded: LoadedStudy, study: ActuatorStudy) -> list[StudyProblem]:
    problems: list[StudyProblem] = []
    if not study.velocities.min <= study.approach_velocity <= study.velocities.max:
        problems.append(
            loaded.problem(
                ("approach_velocity",),
                f"{study.approach_velocity:g} m/s",
                f"a velocity within velocities [{study.velocities.min:g}, {study.velocities.max:g}] m/s",
            )
        )
    return problems


# --- checks of an arm study's setup (the robot loaded) -----------------------------------------------------------


def unsupported_features(loaded: LoadedStudy, study: ArmStudy) -> list[StudyProblem]:
    """The study features the arm optimiser does not model: a joint's own reference motor or scaling law."""
    problems: list[StudyProblem] = []
    base = study.actuators.motor
    for joint, override in study.actuators.joints.items():
        motor = override.motor
        if motor is not None and (motor.reference != base.reference or motor.scaling_law != base.scaling_law):
            problems.append(
                loaded.problem(
                    ("actuators", "joints", joint, "motor"),
                    "a different reference motor or law",
                    "the same reference motor and scaling law for every joint (the optimiser scales one "
                    "reference); override stator_diameter or stack_length only",
                )
            )
    return problems


def module_problems(
    loaded: LoadedStudy, study: ArmStudy, joints: list[str], actuators: list[Any]
) -> list[StudyProblem]:
    """The study's actuator modules that are not one part each, at ``actuators.modules``.

    A module's joints must name joints of the arm, each once, and share the motor and gearbox the study gives
    them (one reference motor, one gearbox).
    """
    problems = []
    seen: set[str] = set()
    for k, group in enumerate(study.actuators.modules):
        path = ("actuators", "modules", k)
        unknown = [name for name in group if name not in joints]
        twice = [name for name in group if name in seen or group.count(name) > 1]
        seen |= set(group)
        if unknown:
            problems.append(
                loaded.problem(path, f"joint {unknown[0]!r}, not a joint of the arm", ", ".join(joints))
            )
        elif len(group) < 2 or twice:
            problems.append(
                loaded.problem(
                    path,
                    f"{group}" + (f": {twice[0]} in two modules or twice" if twice else ""),
                    "two or more joints, each in one module only",
                )
            )
        elif len({_parts(actuators[joints.index(name)]) for name in group}) > 1:
            problems.append(
                loaded.problem(
                    path,
                    f"joints {', '.join(group)} with different motors or gearboxes",
                    "one motor and one gearbox for every joint of a module (actuators.joints overrides "
                    "them per joint)",
                )
            )
    return problems


def _parts(actuator: Any) -> tuple[str, str]:
    """A joint's motor and gearbox, as a module compares them."""
    return str(actuator.motor), str(actuator.gearbox)


def gearbox_ratio_problems(
    loaded: LoadedStudy,
    joints: list[str],
    gearboxes: list[CatalogueGearbox | ScaledGearbox | None],
    paths: list[PathKey],
    ratio_bounds: list[Bounds],
) -> list[StudyProblem]:
    """The gearboxes whose ratios miss their joint's gear-ratio bounds, each at the gearbox's line (``paths``)."""
    problems = []
    for joint, gearbox, path, bounds in zip(joints, gearboxes, paths, ratio_bounds, strict=True):
        if gearbox is not None:
            low, high = gearbox.ratio_range
            lower, upper = gearbox.clip(bounds)
            if lower > upper:
                problems.append(
                    loaded.problem(
                        path,
                        f"{gearbox.name} (ratios {low:g} to {high:g}) at {joint}",
                        f"a gearbox whose ratios overlap the gear-ratio bounds of {joint}, "
                        f"{bounds.lower:g} to {bounds.upper:g} (design.gear_ratio, or actuators.gear_ratio "
                        "when it is fixed); widen them or choose another gearbox",
                    )
                )
    return problems


def requirement_problems(
    loaded: LoadedStudy, study: ArmStudy, cycle: bool, rating: Rating | None
) -> list[StudyProblem]:
    """Torques given (``constraints.torque_required``) beside a duty ``cycle`` or a rated motion that moves."""
    if study.constraints.torque_required is None:
        return []
    where = ("constraints", "torque_required")
    if cycle:
        return [
            loaded.problem(
                where,
                "given torques with a duty cycle",
                "one requirement: remove torque_required (the duty cycle's torques and the static hold "
                "replace it) or the duty_cycle section",
            )
        ]
    if rating is not None and rating.moves:
        return [
            loaded.problem(
                where,
                "given torques with a rated motion",
                "one requirement: remove torque_required (the rated motion and the static hold replace it) "
                "or the rating's speeds and accelerations",
            )
        ]
    return []


def torque_out_of_reach(loaded: LoadedStudy, setup: ArmSetup) -> list[StudyProblem]:
    """The torque requirements no design within the bounds can meet.

    A requirement is unmet when the largest motor at the largest gear ratio (torque grows with motor size
    under every scaling law) is short of the safety factor times the need.
    """
    required = setup.study.constraints.torque_required
    if required is None:
        return []
    joints = list(setup.arm.joint_names)
    n = len(joints)
    references = setup.technology.joint_motors(n)
    diameters = setup.space.per_joint("stator_diameter", n)
    stacks = setup.space.per_joint("stack_length", n, setup.technology.default_stack_lengths(n))
    gears = setup.space.per_joint("gear_ratio", n)
    factor = setup.study.constraints.safety_factor
    problems = []
    for i, joint in enumerate(joints):
        motor = scaled_motor_quantities(
            references[i], diameters[i].upper, stacks[i].upper, setup.technology.scaling_law
        )
        reachable = gears[i].upper * float(motor.peak_torque)
        if factor * required[i] > reachable * (1 + 1e-9):
            problems.append(
                loaded.problem(
                    ("constraints", "torque_required", i),
                    f"{required[i]:g} N*m for {joint} (x {factor:g} safety)",
                    f"at most {reachable:.4g} N*m, the peak torque of the largest motor at the largest gear "
                    "ratio; widen design.stator_diameter or design.gear_ratio, or lower the requirement",
                )
            )
    return problems


def _body_region_checks(loaded: LoadedStudy, study: ArmStudy) -> list[StudyProblem]:
    """The body region a study holds its approach to: one of the standard's that permits transient contact."""
    name = study.constraints.body_region
    if name is None:
        return []
    regions = transient_regions()
    if name in regions:
        return []
    forbidden = name in load_body_regions()
    return [
        loaded.problem(
            ("constraints", "body_region"),
            f"{excerpt(name)}"
            + (" (ISO/TS 15066 permits no transient contact with it)" if forbidden else ""),
            "one of " + ", ".join(regions),
        )
    ]


def _catalogue_checks(loaded: LoadedStudy, study: ArmStudy) -> list[StudyProblem]:
    """Each catalogue the study names (``catalogue.motors``, ``catalogue.gearboxes``), read as the packaged ones.

    Read by the same loader (:func:`~collision_reflex.hardware.catalogue.read_entries`): a problem is told at
    the study's line, quoting the catalogue's own file and line.
    """
    problems = []
    for kind in ("motors", "gearboxes"):
        named = getattr(study.catalogue, kind)
        if named is None:
            continue
        try:
            read_entries(loaded.path(named), kind)
        except CatalogueError as error:
            shown = named if named.strip() else excerpt(named)
            where = shown if error.line is None else f"{shown}:{error.line}"
            field = f"{error.field}: " if error.field else ""
            problems.append(
                loaded.problem(
                    ("catalogue", kind),
                    f"{where}: {field}{error.reason}",
                    f"a {kind} catalogue file like designs/{kind}.yaml, relative to the study file's folder: "
                    f"fix it where quoted, or leave catalogue.{kind} out for the packaged one",
                )
            )
    return problems


def located_refusal(loaded: LoadedStudy, error: InvalidParameter) -> StudyFileError:
    """A refusal of the design problem (``error``) at the study field it comes from, to raise."""
    if " requirement of " in error.name:  # a motion's requirement: said in full, at what asks for it
        what, _, joint = error.name.rpartition(" requirement of ")
        constraint, _, margin = str(error.value).rpartition(": ")
        hint = f"; {error.hint}" if error.hint else ""
        return loaded.fail(
            _motion_field(loaded.study, constraint), f"{joint}: {margin}", f"{error.allowed} ({what}){hint}"
        )
    return loaded.fail(_field_of(error.name), f"{error}", "inputs the design problem accepts")


def _motion_field(study: Any, constraint: str) -> tuple[str, ...]:
    """Where a motion requirement's refusal belongs: the gearbox, else the rating or the duty cycle."""
    if constraint.startswith("gearbox"):
        return ("actuators", "gearbox")
    rating = study.rating
    moves = rating.joint_speeds is not None or rating.joint_accelerations is not None
    return ("rating",) if moves else ("duty_cycle",)


def _field_of(name: str) -> tuple[str, ...]:
    """The study field an optimiser parameter comes from (for locating its errors)."""
    root = name.split("[")[0].split(" ")[0]
    if root in PER_JOINT_VARIABLES or root in GLOBAL_VARIABLES:
        return ("design", root)
    if root in ("payload", "safety_factor", "torque_required", "threshold_floor"):
        return ("constraints", root)
    if root in ("sample", "directions", "config_index"):
        return ("samples",)
    return ()
