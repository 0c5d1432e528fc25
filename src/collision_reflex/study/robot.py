"""The robot of an arm study: load it, and check every name and size in the study against it.

Problems (an unknown robot, frame or joint, a configuration of the wrong size, ...) are reported at the line of
the study file that names them.
"""

from __future__ import annotations

import difflib

from ..arm import Arm
from ..errors import FrameNotFound, InvalidParameter, StudyFileError, StudyProblem, UrdfError
from ..vocabulary import PER_JOINT_VARIABLES
from .duty import prismatic_joints
from .load import LoadedStudy
from .quantities import joint_position_si
from .resolve import JOINT_POSITION_PATHS, at_path
from .schema import ArmStudy
from .source import PathKey, excerpt


def example_robot_names() -> list[str]:
    """Names of the models example-robot-data can load."""
    from example_robot_data.robots_loader import ROBOTS

    return sorted(ROBOTS)


def load_arm(loaded: LoadedStudy) -> Arm:
    """The :class:`collision_reflex.arm.Arm` of an arm study, checked against the study.

    Raises
    ------
    StudyFileError: the robot, its contact frame or a joint named in the study does not exist, or a size in the
        study does not match the robot.
    """
    study = loaded.study
    if not isinstance(study, ArmStudy):
        raise TypeError("load_arm needs an arm study")
    spec = study.robot
    offset = None if spec.contact_offset is None else list(spec.contact_offset)
    locked = list(spec.locked_joints)
    try:
        if spec.example_robot_data is not None:
            names = example_robot_names()
            if spec.example_robot_data not in names:
                close = difflib.get_close_matches(spec.example_robot_data, names, n=3)
                raise loaded.fail(
                    ("robot", "example_robot_data"),
                    f"{excerpt(spec.example_robot_data)}, not an example-robot-data model",
                    ("one of " + ", ".join(map(repr, close)) + " or another of " if close else "one of ")
                    + f"the {len(names)} models of example-robot-data (e.g. ur5, panda, double_pendulum)",
                )
            arm = Arm.from_example_robot_data(
                spec.example_robot_data,
                contact_frame=spec.contact_frame,
                contact_offset=offset,
                locked_joints=locked,
            )
        else:
            assert spec.urdf is not None  # one source is guaranteed by the schema
            if spec.contact_frame is None:
                raise loaded.fail(
                    ("robot",),
                    "a URDF without contact_frame",
                    "robot.contact_frame: the frame (link or fixed joint) that makes contact",
                )
            arm = Arm.from_urdf(
                str(loaded.path(spec.urdf)),
                spec.contact_frame,
                package_dirs=[str(loaded.path(p)) for p in spec.package_dirs] or None,
                contact_offset=offset,
                locked_joints=locked,
            )
    except FrameNotFound as error:
        if error.kind == "joint" and error.name in locked:
            where: PathKey = ("robot", "locked_joints", locked.index(error.name))
        else:
            where = ("robot", "contact_frame")
        close = difflib.get_close_matches(error.name, error.available, n=1)
        raise loaded.fail(
            where,
            f"{error.kind} {excerpt(error.name)}, not in the robot",
            (f"{close[0]!r}? " if close else "") + f"one of the {len(error.available)} "
            f"{error.kind}s: " + ", ".join(error.available),
        ) from None
    except UrdfError as error:
        raise loaded.fail(
            ("robot", "urdf"),
            f"a URDF that cannot be loaded ({error.reason})",
            "a URDF file Pinocchio can parse",
        ) from None
    except OSError as error:  # a file that exists but cannot be read (a device, /proc, permissions)
        raise loaded.fail(
            ("robot", "urdf"),
            f"{excerpt(spec.urdf)}, which cannot be read ({error.strerror or error})",
            "a readable URDF file",
        ) from None
    except InvalidParameter as error:
        field = error.name if error.name in type(spec).model_fields else None
        raise loaded.fail(
            ("robot", field) if field else ("robot",),
            str(error),
            "a robot and contact point the arm model accepts",
        ) from None
    problems = check_against_arm(loaded, arm)
    if problems:
        raise StudyFileError(loaded.source.file, problems)
    return arm


def check_against_arm(loaded: LoadedStudy, arm: Arm) -> list[StudyProblem]:
    """Every joint name and size in the study, checked against ``arm``."""
    study = loaded.study
    assert isinstance(study, ArmStudy)
    joints = list(arm.joint_names)
    problems: list[StudyProblem] = []

    def check_joint(path: PathKey, name: str) -> None:
        if name not in joints:
            close = difflib.get_close_matches(name, joints, n=1)
            problems.append(
                loaded.problem(
                    path,
                    f"joint {excerpt(name)}, not a joint of the robot",
                    (f"{close[0]!r}? " if close else "") + "one of " + ", ".join(map(repr, joints)),
                )
            )

    def check_sizes(samples: str, size: int, found: str, expected: str) -> None:
        """The rows of ``samples.<samples>.list`` have ``size`` entries each."""
        for index, row in enumerate(getattr(study.samples, samples).list or []):
            if len(row) != size:
                problems.append(
                    loaded.problem(("samples", samples, "list", index), found.format(len(row)), expected)
                )

    for name in study.actuators.joints:
        check_joint(("actuators", "joints", name), name)
    for variable in PER_JOINT_VARIABLES:
        spec = getattr(study.design, variable)
        for name in getattr(spec, "joints", {}) or {}:
            check_joint(("design", variable, "joints", name), name)

    nv = int(arm.nv)
    per_joint = f"{nv}, one per joint ({', '.join(joints)}), each with its unit"
    check_sizes("configurations", nv, "{} joint angles", per_joint)
    problems += _position_units(loaded, arm)
    task_dim = int(arm.task_dim)
    directions = study.samples.directions
    plane = "a planar arm" if task_dim == 2 else "a spatial arm"
    check_sizes("directions", task_dim, "a vector of {} components", f"{task_dim} components ({plane})")
    if task_dim == 2 and directions.sphere is not None:
        problems.append(
            loaded.problem(
                ("samples", "directions", "sphere"),
                "sphere directions for a planar arm",
                "circle: N (directions in the arm's plane)",
            )
        )
    required = study.constraints.torque_required
    if required is not None and len(required) != len(joints):
        problems.append(
            loaded.problem(
                ("constraints", "torque_required"),
                f"{len(required)} torques",
                f"one per actuated joint ({len(joints)}: {', '.join(joints)}) in N*m",
            )
        )
    return problems


def _position_units(loaded: LoadedStudy, arm: Arm) -> list[StudyProblem]:
    """An angle for each revolute joint, a length for each prismatic one, in the study's joint positions."""
    prismatic = prismatic_joints(arm)
    units = ["m" if name in prismatic else "rad" for name in arm.joint_names]
    problems = []
    for path in JOINT_POSITION_PATHS:
        rows = at_path(loaded.source.data, path)
        for index, row in enumerate(rows if isinstance(rows, list) else []):
            if not isinstance(row, list) or len(row) != len(units):
                continue  # its length is refused where it is checked
            for joint, (text, unit) in enumerate(zip(row, units, strict=True)):
                if joint_position_si(text)[1] != unit:
                    name = arm.joint_names[joint]
                    kind = "a length (prismatic joint)" if unit == "m" else "an angle (revolute joint)"
                    problems.append(
                        loaded.problem((*path, index, joint), f"{excerpt(str(text))} for joint {name}", kind)
                    )
    return problems
