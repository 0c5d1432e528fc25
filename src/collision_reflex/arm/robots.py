"""Loading robot models: URDF files through Pinocchio and the robots of ``example-robot-data``.

URDF failures carry the parser's own reasons; the stock robots get sensible contact points and locked
joints.
"""

from __future__ import annotations

import contextlib
import functools
import os
import sys
import tempfile
import xml.etree.ElementTree as ElementTree
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import FrameNotFound, InvalidParameter, UrdfError

# Sensible contact points and locked joints of the example-robot-data robots most used as arms. The double
# pendulum's URDF has no tip frame: its second link is about 0.2 m long (its centre of mass sits at 0.10 m
# along z), so the tip is taken 0.2 m along that link's z axis.
ROBOT_DEFAULTS: dict[str, dict[str, Any]] = {
    "panda": {
        "contact_frame": "panda_hand_tcp",
        "locked_joints": ("panda_finger_joint1", "panda_finger_joint2"),
    },
    "ur5": {"contact_frame": "tool0"},
    "ur3": {"contact_frame": "tool0"},
    "ur10": {"contact_frame": "tool0"},
    "double_pendulum": {"contact_frame": "link2", "contact_offset": (0.0, 0.0, 0.2)},
    "solo12": {"contact_frame": "FL_FOOT"},
    "a1": {"contact_frame": "FL_foot"},
}


@functools.lru_cache(maxsize=16)
def _cachedexample_robot(name: str) -> tuple[Any, str, np.ndarray]:
    try:
        import example_robot_data
    except ImportError as error:  # pragma: no cover - a declared dependency
        raise InvalidParameter(
            "name", name, "an installed example-robot-data", "pip install example-robot-data"
        ) from error
    fast = _kinematic_model(name)
    if fast is not None:
        return fast
    try:
        robot = example_robot_data.load(name)
    except Exception as error:  # the loader raises plain ValueErrors for unknown names
        raise InvalidParameter(
            "name",
            name,
            "a robot of example-robot-data, e.g. 'ur5', 'panda', 'double_pendulum', 'solo12'",
            str(error),
        ) from None
    return robot.model, str(robot.urdf), np.array(robot.q0, dtype=float)


def _kinematic_model(name: str) -> tuple[Any, str, np.ndarray] | None:
    """The robot's model, URDF path and reference posture read as its loader does, without its meshes.

    ``example_robot_data.load`` also builds the visual and collision geometry, which is slow; the kinematic and
    inertial model alone is fast. The loader's own class attributes say where its files are. None (and the
    caller loads the whole robot) for anything this does not cover.
    """
    import pinocchio as pin
    from example_robot_data import robots_loader

    loader = robots_loader.ROBOTS.get(name)
    if loader is None or not loader.urdf_filename:
        return None
    try:
        relative = os.path.join(loader.path, loader.urdf_subpath, loader.urdf_filename)
        root = loader.model_path or robots_loader.getModelPath(relative)
        urdf = os.path.join(root, relative)
        if loader.free_flyer:
            model = pin.buildModelFromUrdf(urdf, pin.JointModelFreeFlyer())
        else:
            model = pin.buildModelFromUrdf(urdf)
        if loader.srdf_filename:
            srdf = os.path.join(root, loader.path, loader.srdf_subpath, loader.srdf_filename)
            q0 = robots_loader.readParamsFromSrdf(
                model, srdf, False, loader.has_rotor_parameters, loader.ref_posture
            )
        else:
            q0 = pin.neutral(model)
    except Exception:  # another layout of the package: its own loader knows it
        return None
    return model, urdf, np.array(q0, dtype=float)


@dataclass(frozen=True)
class ExampleRobot:
    """An example-robot-data robot made ready for :class:`~collision_reflex.arm.Arm`.

    Attributes
    ----------
    model: its fixed-base Pinocchio model, the locked joints removed.
    contact_frame: the frame that makes contact.
    contact_offset: the contact point in that frame [m], or None for its origin.
    urdf: the robot's URDF file.
    package_dir: the directory that resolves its ``package://`` mesh references.
    reference_configuration: the robot's reference pose in ``model``'s coordinates [rad, m], (nq,).
    """

    model: Any
    contact_frame: str
    contact_offset: Any
    urdf: str
    package_dir: Path
    reference_configuration: np.ndarray


def loaded_example_robot(
    name: str, contact_frame: str | None, contact_offset: Any, locked_joints: Sequence[str] | None
) -> ExampleRobot:
    """Load ``name`` with the defaults of :data:`ROBOT_DEFAULTS` for what the caller leaves None.

    The contact offset [m] defaults with the frame only; ``locked_joints`` replaces the default list (``()``
    locks none); a floating base is fixed to the world.
    """
    full_model, urdf, q0 = example_robot(name)
    model = full_model
    defaults = ROBOT_DEFAULTS.get(name, {})
    if contact_frame is None:
        if "contact_frame" not in defaults:
            raise InvalidParameter(
                "contact_frame",
                None,
                f"a frame name for {name!r} (no default is known)",
                "frames: " + ", ".join(f.name for f in model.frames),
            )
        contact_frame = defaults["contact_frame"]
        if contact_offset is None:
            contact_offset = defaults.get("contact_offset")
    if model.njoints > 1 and model.joints[1].nq == 7:  # free-flyer root: fix the base to the world
        model = load_urdf(urdf)
    to_lock = defaults.get("locked_joints", ()) if locked_joints is None else tuple(locked_joints)
    model = with_locked_joints(model, to_lock, name)
    # The robots' URDFs name their meshes package://example-robot-data/robots/...: the package directory
    # is two levels above the "robots" directory.
    share = Path(urdf).resolve()
    while share.name != "robots" and share != share.parent:
        share = share.parent
    return ExampleRobot(
        model,
        contact_frame,
        contact_offset,
        urdf,
        share.parent.parent,
        configuration_by_name(full_model, q0, model),
    )


def example_robot(name: str) -> tuple[Any, str, np.ndarray]:
    """The Pinocchio model (a copy), URDF path and reference configuration of an example-robot-data robot.

    Loading parses meshes and is slow, so it happens once per name.
    """
    model, urdf, q0 = _cachedexample_robot(name)
    return model.copy(), urdf, q0.copy()


def configuration_by_name(source: Any, q_source: np.ndarray, target: Any) -> np.ndarray:
    """A configuration of ``target`` taking each joint's coordinates from ``q_source`` of ``source``.

    Joints are matched by name; joints ``source`` does not have are neutral.
    """
    import pinocchio as pin

    q = np.array(pin.neutral(target))
    names = list(source.names)
    for j in range(1, target.njoints):
        if target.names[j] in names:
            joint, origin = target.joints[j], source.joints[names.index(target.names[j])]
            q[joint.idx_q : joint.idx_q + joint.nq] = q_source[origin.idx_q : origin.idx_q + origin.nq]
    return q


def with_locked_joints(model: Any, locked_joints: Sequence[str], robot: str) -> Any:
    """The model with ``locked_joints`` fixed at their neutral position."""
    import pinocchio as pin

    if not locked_joints:
        return model
    names = list(model.names)
    ids = []
    for name in locked_joints:
        if name not in names:
            raise FrameNotFound(name, names[1:], "joint", robot)
        ids.append(names.index(name))
    return pin.buildReducedModel(model, ids, pin.neutral(model))


def load_urdf(path: str | os.PathLike[str]) -> Any:
    """Parse a URDF with Pinocchio; a missing or malformed file raises :class:`UrdfError` with the reason."""
    import pinocchio as pin

    target = Path(path)
    if not target.is_file():
        raise UrdfError(target, "no such file")
    try:
        ElementTree.parse(target)
    except ElementTree.ParseError as error:  # XML syntax: the parser's message carries line and column
        raise UrdfError(target, f"not well-formed XML: {error}") from None
    failure: Exception | None = None
    with captured_stderr() as captured:
        try:
            model = pin.buildModelFromUrdf(str(target))
        except (ValueError, RuntimeError) as error:
            failure = error
    if failure is not None:
        raise UrdfError(target, parser_reason(failure, captured.text))
    return model


def parser_reason(error: Exception, messages: str) -> str:
    """The URDF parser's own explanation (it prints it to stderr), else the exception's text."""
    lines = [line.strip() for line in messages.splitlines() if line.strip().startswith("Error:")]
    reasons = [line.removeprefix("Error:").strip() for line in lines]
    return "; ".join(reasons) if reasons else str(error).strip()


class _Captured:
    text = ""


@contextlib.contextmanager
def captured_stderr() -> Iterator[_Captured]:
    """Capture what C++ code writes to the process's stderr (file descriptor 2) while the block runs.

    The text is in the yielded object's ``text`` once the block has ended.
    """
    captured = _Captured()
    sys.stderr.flush()
    with tempfile.TemporaryFile(mode="w+b") as sink:
        saved = os.dup(2)
        try:
            os.dup2(sink.fileno(), 2)
            yield captured
        finally:
            os.dup2(saved, 2)
            os.close(saved)
            sink.seek(0)
            captured.text = sink.read().decode(errors="replace")
