"""A starting study for a robot: what ``crx robots`` lists and ``crx init`` writes.

A robot's study needs its contact frame, the joints that carry it, bounds that fit its size, what it is rated
for and a motion within its joint limits. Here they come from the robot's own model: the revolute joints of the
limb that carries the contact frame (every other joint is locked), the URDF's effort and velocity limits, and
its joint limits. Every figure the model does not give is an estimate, and the written study says how it
was made, so that the designer knows what to replace by a datasheet figure.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np

from ..arm import Arm
from ..arm.robots import ROBOT_DEFAULTS, example_robot, load_urdf
from ..arm.static_hold import hold_torques
from ..errors import InvalidParameter
from ..hardware.gearboxes import load_gearbox_catalogue

SAFETY_FACTOR = 1.5
"""The torque safety factor the written study asks for (as the shipped UR5 and Panda studies)."""
PAYLOAD_SHARE = 0.5
"""Share of the payload the URDF's effort limits could hold that the written study rates: the rest is left for
the designed actuators' own weight, which the robot's links already carry once (its stock drives)."""
REFERENCE_TORQUE = 1.3
"""Peak torque of the reference motor (Omni+ OPN-060-013-A, 60 mm) [N m], the paper's ``tab:motor_params``."""
MAX_RATIO = 160.0
"""Largest ratio of the strain-wave gearing the study uses (the CSF series' ratios 30 to 160)."""
SANE_EFFORT = (1e-3, 999.0)
SANE_SPEED = (1e-3, 100.0)
"""Effort [N m] and velocity [rad/s] limits taken from a URDF (exclusive); outside, a URDF's placeholder (0,
1000, 50000, inf): the collaborative arms this is for have joints well below 1000 N m."""
MAX_RATED_SPEED = math.radians(180.0)
"""Largest rated joint speed written [rad/s]: a collaborative arm's (the UR5's 180 deg/s, Universal Robots' UR5
technical specifications); URDF velocity limits of a spine or a finger may be a motor's no-load speed."""
POSES = 256
"""Poses drawn within the joint limits for the payload, hold-torque and reach estimates."""
APPROACH_VELOCITY = 0.25
"""Approach velocity of the written study [m/s], as the shipped UR5 study; lower for a slow or small arm."""
_TIP_WORDS = re.compile(r"tcp|tool|eef|end_effector|ee_|hand|gripper|wrist", re.IGNORECASE)
_DIGIT_WORDS = re.compile(
    r"finger|thumb|thmb|index|indx|middle|ring|rng|pinky|pnky|little|mrl|knuckle|flex|phalan|palm|nail",
    re.IGNORECASE,
)


@dataclass(frozen=True)
class RobotEntry:
    """What ``crx robots`` says of a robot model.

    Attributes
    ----------
    name: the example-robot-data name (or the URDF's stem).
    base: ``"fixed"`` or ``"floating"``.
    joints: its joints that move (one degree of freedom each; a free-flyer root not counted).
    contact_frame: the frame a study makes contact at (the package's default for the robot, else the tip of its
        longest chain of revolute joints), or None.
    chain: the revolute joints of the limb from its root (the base, or the tree's last branching) to
        ``contact_frame``: the study's actuated joints.
    startable: ``crx init`` writes a study for it: a fixed base and at least two joints on the chain.
    reason: why not, when not.
    """

    name: str
    base: str
    joints: int
    contact_frame: str | None
    chain: tuple[str, ...]
    startable: bool
    reason: str = ""


def robot_entries() -> list[RobotEntry]:
    """Every robot of example-robot-data, in name order."""
    from example_robot_data.robots_loader import ROBOTS

    entries = []
    for name in sorted(ROBOTS):
        try:
            model, _, _ = example_robot(name)
        except (
            Exception
        ) as error:  # a model its own loader cannot build here (e.g. an SDF one): listed as such
            entries.append(RobotEntry(name, "?", 0, None, (), False, f"does not load: {str(error)[:80]}"))
            continue
        entries.append(robot_entry(name, model))
    return entries


def robot_entry(name: str, model: Any, frame: str | None = None) -> RobotEntry:
    """The entry of ``model`` (a Pinocchio model), its contact frame ``frame`` or the one chosen for it."""
    floating = model.njoints > 1 and model.joints[1].nq == 7
    joints = sum(1 for j in range(1, model.njoints) if model.joints[j].nv == 1)
    if frame is None:
        frame = ROBOT_DEFAULTS.get(name, {}).get("contact_frame") or _tip_frame(model)
    names = [f.name for f in model.frames]
    if frame is None or frame not in names:
        return RobotEntry(
            name, "floating" if floating else "fixed", joints, None, (), False, "no contact frame"
        )
    chain = _chain(model, names.index(frame))
    reason = ""
    if floating:
        reason = "a floating base (crx init writes studies of fixed-base arms)"
    elif len(chain) < 2:
        reason = f"{len(chain)} revolute joint(s) from the base to {frame}"
    base = "floating" if floating else "fixed"
    return RobotEntry(name, base, joints, frame, chain, not reason, reason)


def _revolute(joint: Any) -> bool:
    kind = joint.shortname().removeprefix("JointModel")
    return joint.nv == 1 and (kind.startswith("R") or kind.startswith("Revolute"))


def _chain(model: Any, frame: int) -> tuple[str, ...]:
    """The revolute joints of the limb that carries ``frame``, from its root out.

    The limb starts where the tree last branches on the way to the base: an arm's own joints, not the trunk it
    shares with another arm or a head (a humanoid's spine, a mobile manipulator's torso), which a study of that
    arm locks.
    """
    children = np.bincount(np.asarray(model.parents[1:], dtype=int), minlength=model.njoints)
    joint = int(model.frames[frame].parentJoint)
    chain = []
    while joint > 0:
        if _revolute(model.joints[joint]):
            chain.append(model.names[joint])
        parent = int(model.parents[joint])
        if children[parent] > 1 and chain:
            break
        joint = parent
    return tuple(reversed(chain))


def _tip_frame(model: Any) -> str | None:
    """The frame at the end of the longest chain of revolute joints, a tool-like name first among equals.

    Frames of a hand's digits (finger, thumb, knuckle, ...) are passed over while another frame ends a chain of
    two or more joints: an arm's tool is the contact a study is about, not one fingertip.
    """
    keyed = [
        (
            (
                len(_chain(model, index)),
                1 if np.linalg.norm(frame.placement.translation) > 1e-3 else 0,  # off its joint: it moves
                1 if _TIP_WORDS.search(frame.name) else 0,
                index,
            ),
            frame.name,
        )
        for index, frame in enumerate(model.frames)
        if frame.parentJoint != 0
    ]
    arm = [item for item in keyed if not _DIGIT_WORDS.search(item[1]) and item[0][0] >= 2]
    chosen = max(arm or keyed, default=None)
    return chosen[1] if chosen is not None else None


# --- the study ----------------------------------------------------------------------------------------------


def starter_study(robot: str, out: Path, frame: str | None = None, payload: float | None = None) -> str:
    """The text of a commented, valid study for ``robot`` (an example-robot-data name or a URDF file).

    ``out`` is where the study will be written (a URDF's path is written relative to its folder); ``frame`` the
    contact frame (default: the robot's, or its tip); ``payload`` the rated payload [kg] (default: an estimate
    from the URDF's effort limits).

    Raises
    ------
    InvalidParameter: an unknown robot, a frame it does not have, a robot with a floating base or with fewer than
        two revolute joints to its contact frame.
    """
    urdf = Path(robot) if robot.endswith(".urdf") or Path(robot).is_file() else None
    if urdf is not None:
        model, name = load_urdf(urdf), urdf.stem
    else:
        from example_robot_data.robots_loader import ROBOTS

        if robot not in ROBOTS:
            raise InvalidParameter("robot", robot, "a robot `crx robots` lists, or a URDF file")
        model, name = example_robot(robot)[0], robot
    frames = [f.name for f in model.frames]
    if frame is not None and frame not in frames:
        import difflib

        close = difflib.get_close_matches(frame, frames, n=3)
        raise InvalidParameter(
            "frame",
            frame,
            f"a frame of {name}",
            ("e.g. " + ", ".join(close)) if close else "crx robots lists tips",
        )
    entry = robot_entry(name, model, frame)
    if not entry.startable:
        raise InvalidParameter(
            "robot", robot, "a fixed-base arm with at least two revolute joints", entry.reason
        )
    assert entry.contact_frame is not None  # a startable entry has one
    locked = [model.names[j] for j in range(1, model.njoints) if model.names[j] not in entry.chain]
    offset, offset_note = _contact_offset(name, model, entry.contact_frame)
    if urdf is not None:
        arm = Arm.from_urdf(urdf, entry.contact_frame, contact_offset=offset, locked_joints=locked)
        source = f"urdf: {_relative(urdf, out)}"
    else:
        arm = Arm.from_example_robot_data(
            robot, contact_frame=entry.contact_frame, contact_offset=offset, locked_joints=locked
        )
        source = f"example_robot_data: {robot}"
    offset_line = (
        f"  contact_offset: [{', '.join(f'{x:.4g} m' for x in offset)}]   # {offset_note}\n"
        if offset is not None
        else ""
    )
    return _study_text(name, source, entry, locked, arm, payload, offset_line)


def _contact_offset(name: str, model: Any, frame: str) -> tuple[np.ndarray | None, str]:
    """The contact point in ``frame`` [m] where the frame itself sits on its joint's axis (None: its origin).

    A frame at its joint's origin does not move with that joint, so no contact there can be reflexed by it:
    the robot's known tip, else twice the link's centre of mass (the end of a uniform link), is used.
    """
    defaults = ROBOT_DEFAULTS.get(name, {})
    if defaults.get("contact_frame") == frame and defaults.get("contact_offset") is not None:
        return np.asarray(defaults["contact_offset"], dtype=float), "the robot's tip (its package default)"
    placement = model.frames[model.getFrameId(frame)].placement
    if np.linalg.norm(placement.translation) > 1e-3:
        return None, ""
    lever = np.asarray(
        model.inertias[int(model.frames[model.getFrameId(frame)].parentJoint)].lever, dtype=float
    )
    if np.linalg.norm(lever) < 1e-3:
        return None, ""
    offset = placement.rotation.T @ (2 * lever - placement.translation)
    return (
        offset,
        "ESTIMATE: the end of the link, twice its centre of mass from the joint; SET the tool point",
    )


def _relative(path: Path, out: Path) -> str:
    """``path`` relative to the study's folder (studies name files so) when it is below it, else absolute."""
    import os

    relative = Path(os.path.relpath(path.resolve(), out.resolve().parent))
    return (
        relative.as_posix() if not relative.parts or relative.parts[0] != ".." else path.resolve().as_posix()
    )


@dataclass(frozen=True)
class _Figures:
    """The robot's figures a study is written from, each with how it was found."""

    limits: np.ndarray  # (2, n) joint limits [rad]
    speeds: np.ndarray  # (n,) rated joint speeds [rad/s]
    speeds_from_urdf: bool
    efforts: np.ndarray  # (n,) [N m], NaN where the URDF has none
    payload: float  # [kg]
    payload_note: str
    home: np.ndarray  # (n,) [rad]
    approach_velocity: float  # [m/s]
    poses: Any  # ArmSamples at poses drawn within the limits: gravity, payload gravity, contact positions


def _figures(arm: Any) -> _Figures:
    model = arm.model
    n = int(arm.nv)
    low, high = (np.asarray(bound, dtype=float).copy() for bound in arm.joint_limits())
    continuous = ~np.isfinite(low) | ~np.isfinite(high) | (high - low > 4 * math.pi)
    low[continuous], high[continuous] = -math.pi, math.pi  # a continuous joint: a turn each way of zero
    speeds = np.asarray(model.velocityLimit, dtype=float)[:n]
    sane = (speeds > SANE_SPEED[0]) & (speeds < SANE_SPEED[1])
    speeds_from_urdf = bool(sane.all())
    speeds = np.minimum(np.where(sane, speeds, math.radians(90.0)), MAX_RATED_SPEED)
    efforts = np.asarray(model.effortLimit, dtype=float)[:n]
    efforts = np.where((efforts > SANE_EFFORT[0]) & (efforts < SANE_EFFORT[1]), efforts, np.nan)
    inside = 0.01 * (high - low)  # off the limits by more than the written digits move a value
    home = np.clip(np.ravel(arm.joint_coordinates(arm.reference_configuration)), low + inside, high - inside)
    angles = np.random.default_rng(0).uniform(low, high, (POSES, low.size))
    poses = arm.kinematics(arm.configuration(angles))  # the gravity terms the static hold uses, batched
    payload, note = _payload(poses, efforts)
    # A tenth of the slowest joint's speed at the arm's reach: an approach its joints can follow everywhere.
    reach = float(np.max(np.linalg.norm(poses.contact_position, axis=1)))
    approach = min(APPROACH_VELOCITY, float(f"{0.1 * float(np.min(speeds)) * reach:.2g}"))
    return _Figures(
        np.array([low, high]), speeds, speeds_from_urdf, efforts, payload, note, home, approach, poses
    )


def _hold_torques(figures: _Figures) -> np.ndarray:
    """Each joint's largest gravity torque [N m] holding the links and the rated payload over the poses.

    The designed actuators' own masses are left out (:func:`collision_reflex.arm.static_hold.hold_torques`
    with none).
    """
    nv = figures.limits.shape[1]
    return np.max(np.abs(hold_torques(figures.poses, figures.payload, np.zeros(nv))), axis=0)


def _payload(poses: Any, efforts: np.ndarray) -> tuple[float, str]:
    """A payload to rate the arm for, from the URDF's effort limits at ``poses`` (ArmSamples), and how."""
    if np.isnan(efforts).all():
        return 0.5, "SET: the rated payload from the datasheet (the URDF gives no usable effort limit)"
    spare = efforts / SAFETY_FACTOR - np.abs(poses.gravity)  # (poses, joints) left for the payload [N m]
    per_kg = np.abs(poses.contact_gravity)  # joint torque per kg at the contact point [N m/kg]
    with np.errstate(divide="ignore", invalid="ignore"):
        held = np.where(per_kg > 1e-9, spare / per_kg, np.inf)
    payload = PAYLOAD_SHARE * float(np.nanmin(held))
    if not math.isfinite(payload) or payload < 0.05:
        return 0.5, "SET: the rated payload from the datasheet (the URDF's effort limits barely hold the arm)"
    payload = float(f"{payload:.2g}")
    return payload, (
        f"ESTIMATE: {PAYLOAD_SHARE:g} x the mass the URDF's effort limits hold at the contact point over {POSES}\n"
        f"  # poses within the joint limits, with the {SAFETY_FACTOR:g} safety factor; SET the datasheet figure"
    )


def _stator_bounds(efforts: np.ndarray, ratio: float) -> tuple[float, float]:
    """Stator diameters [mm] from which every joint can reach its torque at the largest ``ratio`` of its gearing.

    The reference motor's peak torque grows as the diameter to the power 2.5 (the Haddadin law): the largest
    diameter lets the strongest joint meet ten times its effort limit (its continuous torque is a fraction of
    the peak), the smallest lets the weakest meet a quarter of its own at the strain-wave gearing's largest
    ratio; without effort limits, 20 to 160 mm.
    """
    if np.isnan(efforts).all():
        return 20.0, 160.0

    def diameter(torque: float, ratio: float) -> float:
        return 60.0 * (torque / (ratio * REFERENCE_TORQUE)) ** (1 / 2.5)

    high = float(np.clip(diameter(10 * np.nanmax(efforts), ratio), 60.0, 400.0))
    low = float(np.clip(diameter(0.25 * np.nanmin(efforts), MAX_RATIO), 10.0, high / 2))
    return round(low), round(high)


MOTION_SPAN = math.radians(60.0)
"""Largest swing of a joint in the written duty cycle [rad] (a sixth of its range where that is less)."""


def _via_points(figures: _Figures) -> np.ndarray:
    """Home, two poses a sixth of each joint's range away (at most 60 deg, within its limits), home again [rad]."""
    low, high = figures.limits
    margin = 0.05 * (high - low)
    span = np.minimum((high - low) / 6, MOTION_SPAN)
    signs = np.where(np.arange(low.size) % 2 == 0, 1.0, -1.0)
    first = np.clip(figures.home + signs * span, low + margin, high - margin)
    second = np.clip(figures.home - signs * span, low + margin, high - margin)
    return np.array([figures.home, first, second, figures.home])


def _deg(values: Any) -> str:
    return "[" + ", ".join(f"{math.degrees(v):.4g} deg" for v in np.atleast_1d(values)) + "]"


def _by_joint(names: tuple[str, ...], values: np.ndarray, unit: str, scale: float = 1.0) -> str:
    return (
        "{"
        + ", ".join(f"{name}: {v * scale:.4g} {unit}" for name, v in zip(names, values, strict=True))
        + "}"
    )


def _groups(names: tuple[str, ...]) -> list[list[str]]:
    """Two actuator sizes for four or more joints, as arms are built (proximal and distal); else one a joint."""
    if len(names) < 4:
        return [[name] for name in names]
    split = (len(names) + 1) // 2
    return [list(names[:split]), list(names[split:])]


def _modules(groups: list[list[str]]) -> str:
    if all(len(group) == 1 for group in groups):
        return "  modules: []   # e.g. [[joint_a, joint_b]]: joints built from one actuator (one size, one part)\n"
    return (
        "  # Two actuator sizes, as arms are built: the proximal joints and the distal ones (each module is sized "
        "for\n  # the most demanding of its joints). Edit the groups to your robot's.\n  modules:\n"
        + "".join(f"    - [{', '.join(group)}]\n" for group in groups)
    )


ACTUATOR_WEIGHT_MARGIN = 2.0
"""ESTIMATE: how much the designed actuators' own weight and the motion may raise a joint's static hold torque
(the shipped UR5 and Panda studies need 1.2 to 2 times the links' and payload's gravity torque)."""


HEAVY_GEARBOX = "AF042-2"
"""The catalogue unit a joint too strong for strain-wave gearing gets scaled from: a two-stage planetary unit
(ratios 20 and 50), whose scaled figures stop at the catalogue's strongest planetary unit (the SP140's)."""
HEAVY_RATIO = 50.0
"""Largest ratio of :data:`HEAVY_GEARBOX`."""


def _heavy_joints(
    groups: list[list[str]], names: tuple[str, ...], hold: np.ndarray
) -> tuple[list[str], float]:
    """The joints (whole groups) whose static hold no strain-wave unit carries, and that unit's peak torque [N m].

    ``hold``: each joint's largest gravity torque over the poses, links and payload [N m], raised by the safety
    factor and :data:`ACTUATOR_WEIGHT_MARGIN`. The scaled strain-wave gearing stops at the catalogue's strongest
    CSF unit.
    """
    strongest = max(unit.peak_torque for unit in load_gearbox_catalogue().values() if unit.kind == "harmonic")
    torque = dict(zip(names, hold * SAFETY_FACTOR * ACTUATOR_WEIGHT_MARGIN, strict=True))
    heavy = [name for group in groups if max(torque[name] for name in group) > strongest for name in group]
    return heavy, strongest


def _heavy_gearboxes(heavy: list[str], strongest: float) -> str:
    """The study's per-joint planetary gearboxes of the ``heavy`` joints (none: nothing)."""
    if not heavy:
        return ""
    return (
        f"  # ESTIMATE: joints whose gravity torque (links and payload) x {SAFETY_FACTOR:g} x "
        f"{ACTUATOR_WEIGHT_MARGIN:g} for the actuators'\n  # own weight exceeds the strongest strain-wave unit "
        f"({strongest:g} N*m) get a two-stage planetary unit scaled\n  # from the Apex Dynamics {HEAVY_GEARBOX} "
        "(ratios 20 and 50).\n  joints:\n"
        + "".join(f"    {name}: {{gearbox: {{scaled_from: {HEAVY_GEARBOX}}}}}\n" for name in heavy)
    )


def _study_text(
    name: str,
    source: str,
    entry: RobotEntry,
    locked: list[str],
    arm: Any,
    payload: float | None,
    offset_line: str,
) -> str:
    figures = _figures(arm)
    if payload is not None:
        figures = replace(
            figures, payload=payload, payload_note="the rated payload given (crx init --payload)"
        )
    joints = tuple(arm.joint_names)
    groups = _groups(joints)
    heavy, strongest = _heavy_joints(groups, joints, _hold_torques(figures))
    low_d, high_d = _stator_bounds(figures.efforts, HEAVY_RATIO if heavy else MAX_RATIO)
    planar = int(arm.task_dim) == 2
    directions = "{circle: 16}" if planar else "{sphere: 14}"
    via = _via_points(figures)
    approach_note = (
        ""
        if figures.approach_velocity == APPROACH_VELOCITY
        else "   # ESTIMATE: a tenth of the slowest rated joint speed at the arm's reach"
    )
    speed_note = (
        "the URDF's velocity limits"
        if figures.speeds_from_urdf
        else "ESTIMATE 90 deg/s where the URDF has none"
    )
    locked_text = f"[{', '.join(locked)}]" if locked else "[]"
    via_text = "".join(f"    - {_deg(point)}\n" for point in via)
    return f"""\
# A design study of {name}'s actuators, written by `crx init` as a starting point. Figures marked ESTIMATE
# are derived here (the comment says how) and figures marked SET need your robot's datasheet; the rest are
# the toolkit's usual choices. Check it with `crx validate`, run it with `crx run` (`--smoke` for a quick
# look first).
name: {name}-actuators
description: >
  Actuators of {name} ({len(joints)} joints from the base to {entry.contact_frame}): which motor sizes, gear
  ratios and controller stiffnesses give the gentlest collision reflex, and what does the actuator mass cost?
robot:
  {source}
  contact_frame: {entry.contact_frame}   # the tip of its chain of {len(joints)} revolute joints
{offset_line}\
  # Joints off that chain (other limbs, fingers, prismatic joints) held at their neutral position.
  locked_joints: {locked_text}
actuators:
  # Scaled Omni+ frameless motors (the paper's reference, 1.3 N*m at 60 mm) behind strain-wave gearing: a
  # Harmonic Drive CSF unit scaled from the CSF-17-100-2UH to carry its motor's peak torque (ratios 30 to 160,
  # the CSF series'); list other options (e.g. {{scaled_from: AF042-2}}, a two-stage planetary) to let the run
  # choose.
  motor: {{reference: "OPN-060-013-A", scaling_law: haddadin, stator_diameter: 60 mm}}
  gearbox: {{scaled_from: CSF-17-100-2UH, ratios: [30, 50, 80, 100, 120, 160]}}
  gear_ratio: 100
{_modules(groups)}\
{_heavy_gearboxes(heavy, strongest)}\
  mechanical_stiffness: 5000 N*m/rad   # ESTIMATE: a strain-wave joint's torsional stiffness, as studies/ur5.yaml
  software_stiffness: 500 N*m/rad
sensing: {{scheme: force, threshold: 5 N}}
approach_velocity: {figures.approach_velocity:g} m/s{approach_note}
rating:
  # {figures.payload_note}
  payload: {figures.payload:g} kg
  # Rated joint speeds: {speed_note}.
  joint_speeds: {_by_joint(joints, figures.speeds, "rad/s")}
samples:
  configurations: {{random: {{count: 16, seed: 1}}}}
  directions: {directions}
design:
  # ESTIMATE: motor sizes from which every joint reaches its URDF effort limit at a ratio of the gearing.
  stator_diameter: {{min: {low_d:g} mm, max: {high_d:g} mm}}
  gear_ratio: {{min: 1, max: 160}}   # each gearbox's ratios narrow it
  software_stiffness: {{min: 50 N*m/rad, max: 5000 N*m/rad}}
  threshold: {{min: 2 N, max: 20 N}}
objective: {{worst_case_impulse: 1.0, actuator_mass: 0.1}}
constraints: {{safety_factor: {SAFETY_FACTOR:g}}}
# A motion within the joint limits: from the robot's reference pose to two poses a sixth of each joint's range
# away (at most 60 deg) and back, at half the rated speeds, with the rated payload. ESTIMATE: each joint
# reaches its speed in 1 s. Replace it by your robot's task (via points or a recorded trajectory file).
duty_cycle:
  via:
{via_text}\
  max_speed: {_by_joint(joints, figures.speeds, "rad/s", 0.5)}
  max_acceleration: {_by_joint(joints, figures.speeds, "rad/s^2", 0.5)}
  dwell: 0.2 s
  rate: 50 Hz
  payload: {{mass: {figures.payload:g} kg}}
pareto: {{objectives: [worst_case_impulse, actuator_mass], points: 8}}
catalogue: {{gearbox_kinds: [harmonic, planetary]}}
"""
