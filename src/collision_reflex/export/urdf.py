"""The arm's URDF with a design's actuators: motor masses, transmissions, torque and speed limits.

What the optimiser models, written into the robot's own URDF:

- each joint's motor (and gearbox) is a point mass carried by the parent link at the joint origin (the
  motor-mass terms of :class:`collision_reflex.arm.ArmSamples`). It is written as its own link,
  ``<joint>_actuator``, fixed to the parent link at the joint's origin, with the mass and no rotational inertia
  of its own: the URDF's link inertials stay as their authors gave them, the motors can be edited or removed
  on their own, and every URDF reader (Pinocchio, MuJoCo, Drake) lumps a fixed child into its parent exactly;
- URDF has no field for the rotor inertia: each joint gets a ``<transmission>`` with
  ``mechanicalReduction`` = N, Drake's ``drake:gear_ratio`` and ``drake:rotor_inertia`` (``J_m + J_g``,
  motor side), and a comment with the armature ``N^2 (J_m + J_g)``; the armature companion file
  (:mod:`.armature`) carries it for Pinocchio;
- the joint's effort limit is the design's peak output torque ``N tau_p``, its velocity limit the motor's
  maximum speed over N (the URDF's own velocity limit is kept where the catalogue gives no motor speed);
- joints the study locks (gripper fingers) become fixed joints at their locked position, zero;
- meshes: every mesh the URDF references (``package://`` ones resolved through the robot's package
  directories) is copied beside the output, into ``<name>_meshes/``, and referenced there by a relative path,
  so the file loads unmodified wherever it is taken and names no absolute local path; a mesh that cannot be
  found keeps its reference (``package://``, or a path relative to the output) and the header names it;
- a ``<mujoco>`` block tells MuJoCo's URDF reader to keep those relative paths and to skip the visual meshes
  (MuJoCo reads no COLLADA); other readers ignore it.
"""

from __future__ import annotations

import os
import re
import xml.etree.ElementTree as ET
from pathlib import Path
from typing import Any

from ..errors import InvalidParameter, UrdfError
from .run_design import JointActuator, RunDesign

DRAKE_NAMESPACE = "http://drake.mit.edu"
"""Drake's URDF extensions: ``drake:rotor_inertia`` and ``drake:gear_ratio`` of a transmission's actuator."""
ET.register_namespace("drake", DRAKE_NAMESPACE)

ACTUATOR_LINK = "{joint}_actuator"
"""Name of the link that carries a joint's motor (and gearbox) mass."""


def number(value: float) -> str:
    """A float as text that reads back to the same double."""
    return repr(float(value))


def comment(text: str) -> ET.Element[Any]:
    """An XML comment of ``text`` that cannot end early or break the file, whatever the text holds.

    A run folder is input like any other file: a name in it may hold ``-->`` (which would close the comment and
    let the rest in as elements), characters XML forbids, or lone surrogates (which no encoding writes).
    """
    safe = text.encode("utf-8", "replace").decode("utf-8")
    safe = re.sub(r"[\x00-\x08\x0b\x0c\x0e-\x1f\ufffe\uffff]", "?", safe)
    while "--" in safe:
        safe = safe.replace("--", "- -")
    return ET.Comment(safe + " " if safe.endswith("-") else safe)


def design_urdf(design: RunDesign, out: str | os.PathLike[str]) -> tuple[str, dict[Path, Path]]:
    """The URDF text of ``design``'s arm with its actuators, to be written at ``out``, and the meshes to copy.

    The meshes map each mesh file the text references to where it goes (``<out stem>_meshes/...``, beside
    ``out``).

    Raises
    ------
    UrdfError: the arm's URDF cannot be read, or lacks a joint or link the arm has.
    """
    source = design.arm.urdf_path
    if source is None:
        raise InvalidParameter("design", design.label, "an arm loaded from a URDF file")
    try:
        root = ET.parse(source).getroot()
    except (OSError, ET.ParseError) as error:
        raise UrdfError(source, str(error)) from None
    joints = {str(j.get("name")): j for j in root.findall("joint")}
    names = {j.joint for j in design.joints}
    missing = sorted(names - joints.keys())
    if missing:
        raise UrdfError(source, "no joint " + ", ".join(map(repr, missing)))
    locked = [n for n, j in joints.items() if j.get("type") != "fixed" and n not in names]
    for name in locked:
        _lock(joints[name])
    for transmission in root.findall("transmission"):
        driven = {j.get("name") for j in transmission.findall("joint")}
        if driven & (names | set(locked)):
            root.remove(transmission)
    copies, missing_meshes = _relocate_meshes(
        root, design, Path(source).resolve().parent, Path(out).resolve()
    )
    header = _header(design, locked, missing_meshes)
    root.insert(0, comment(header))
    for actuator in design.joints:
        _set_limits(joints[actuator.joint], actuator)
        if actuator.actuator_mass > 0:
            _add_actuator_link(root, joints[actuator.joint], actuator)
        _add_transmission(root, actuator)
    extension = ET.SubElement(root, "mujoco")
    ET.SubElement(extension, "compiler", strippath="false", discardvisual="true")
    ET.indent(root, space="  ")
    return '<?xml version="1.0"?>\n' + ET.tostring(root, encoding="unicode") + "\n", copies


def _header(design: RunDesign, locked: list[str], missing_meshes: list[str]) -> str:
    """The header comment: study, design, catalogue parts and sources, and how the model is written."""
    lines = [
        f"Exported by collision-reflex from study {design.study!r}, {design.label}.",
        f"Robot: {design.arm.name}; contact frame {design.arm.contact_frame!r}"
        + (
            f" at [{', '.join(number(v) for v in design.arm.contact_offset)}] m"
            if any(design.arm.contact_offset)
            else ""
        )
        + ".",
        *design.parts,
        "Each motor (and gearbox) is a point mass on its parent link at the joint origin: link JOINT_actuator, "
        "fixed to the parent link, as the optimiser models it.",
        "Rotor inertia: transmissions (mechanicalReduction = N, drake:rotor_inertia = J_m + J_g); the armature "
        "N^2 (J_m + J_g) per joint is in the companion FILE.armature.json (set it as model.armature).",
        "Joint effort = the design's driving peak output torque eta N tau_p [N m] (eta the gearbox efficiency; at "
        "most the catalogue gearbox's repeated peak torque); "
        "velocity = the motor's maximum speed (or the gearbox's maximum input speed, if lower) / N [rad/s].",
    ]
    if locked:
        lines.append("Joints locked by the study (fixed here at 0): " + ", ".join(locked) + ".")
    if missing_meshes:
        lines.append("Meshes not found, references kept: " + ", ".join(missing_meshes) + ".")
    for actuator in design.joints:
        lines.append(_joint_summary(actuator))
    parts = design.catalogue["parts"] if design.catalogue else []
    if any(parts):
        lines.append(
            "Nearest catalogue parts of the design (quick snap): "
            + "; ".join(p or "none" for p in parts)
            + "."
        )
    return "\n  " + "\n  ".join(lines) + "\n"


def _joint_summary(actuator: JointActuator) -> str:
    """One line describing a joint's actuator, every figure as ``designs.json`` holds it (SI, full precision)."""
    gearbox = f", gearbox {actuator.gearbox} ({number(actuator.gearbox_mass)} kg)" if actuator.gearbox else ""
    if actuator.motor:
        motor = f"catalogue motor {actuator.motor}"
    else:
        nearest = f" (nearest catalogue motor {actuator.nearest_motor})" if actuator.nearest_motor else ""
        motor = f"motor {number(actuator.stator_diameter)} m x {number(actuator.stack_length)} m{nearest}"
    return (
        f"{actuator.joint}: {motor}, {number(actuator.motor_mass)} kg, N = {number(actuator.gear_ratio)}{gearbox}, "
        f"effort {number(actuator.driving_peak_torque)} N m"
    )


def _lock(joint: ET.Element) -> None:
    """Make a joint fixed at its zero position (its origin), as the study locks it."""
    joint.set("type", "fixed")
    for tag in ("axis", "limit", "dynamics", "safety_controller", "mimic", "calibration"):
        for child in joint.findall(tag):
            joint.remove(child)


def _set_limits(joint: ET.Element, actuator: JointActuator) -> None:
    """Effort limit ``eta N tau_p`` [N m]; velocity limit ``omega_max / N`` [rad/s] where the motor's is known."""
    limit = joint.find("limit")
    if limit is None:
        limit = ET.SubElement(joint, "limit")
    limit.set("effort", number(actuator.driving_peak_torque))
    if actuator.max_speed is not None:
        limit.set("velocity", number(actuator.max_speed))
    elif limit.get("velocity") is None:
        raise InvalidParameter(
            "design",
            actuator.joint,
            "a motor with a maximum speed, or a URDF velocity limit",
            "add max_speed to the reference motor's catalogue entry",
        )
    else:
        joint.append(comment(" velocity limit of the source URDF: the catalogue gives no motor speed "))


def _add_actuator_link(root: ET.Element, joint: ET.Element, actuator: JointActuator) -> None:
    """A link with the actuator's point mass, fixed to the joint's parent link at the joint origin."""
    parent = joint.find("parent")
    if parent is None or parent.get("link") is None:
        raise UrdfError("URDF", f"joint {actuator.joint!r} has no parent link")
    name = ACTUATOR_LINK.format(joint=actuator.joint)
    gearbox = f" + gearbox {actuator.gearbox} {number(actuator.gearbox_mass)} kg" if actuator.gearbox else ""
    root.append(comment(f" {actuator.joint}: motor {number(actuator.motor_mass)} kg{gearbox}, a point mass "))
    link = ET.SubElement(root, "link", name=name)
    inertial = ET.SubElement(link, "inertial")
    ET.SubElement(inertial, "origin", xyz="0 0 0", rpy="0 0 0")
    ET.SubElement(inertial, "mass", value=number(actuator.actuator_mass))
    ET.SubElement(inertial, "inertia", ixx="0", ixy="0", ixz="0", iyy="0", iyz="0", izz="0")
    mount = ET.SubElement(root, "joint", name=f"{name}_mount", type="fixed")
    ET.SubElement(mount, "parent", link=str(parent.get("link")))
    ET.SubElement(mount, "child", link=name)
    origin = joint.find("origin")
    ET.SubElement(
        mount,
        "origin",
        xyz=origin.get("xyz", "0 0 0") if origin is not None else "0 0 0",
        rpy=origin.get("rpy", "0 0 0") if origin is not None else "0 0 0",
    )


def _add_transmission(root: ET.Element, actuator: JointActuator) -> None:
    """A simple transmission: reduction N, rotor (+ gearbox input) inertia, and the armature as a comment."""
    armature = actuator.reflected_inertia
    root.append(
        comment(
            f" {actuator.joint}: armature N^2 (J_m + J_g) = {number(actuator.gear_ratio)}^2 x "
            f"({number(actuator.rotor_inertia)} + {number(actuator.gearbox_inertia)}) = {number(armature)} kg m^2 "
        )
    )
    transmission = ET.SubElement(root, "transmission", name=f"{actuator.joint}_transmission")
    ET.SubElement(transmission, "type").text = "transmission_interface/SimpleTransmission"
    joint = ET.SubElement(transmission, "joint", name=actuator.joint)
    ET.SubElement(joint, "hardwareInterface").text = "hardware_interface/EffortJointInterface"
    motor = ET.SubElement(transmission, "actuator", name=f"{actuator.joint}_motor")
    ET.SubElement(motor, "mechanicalReduction").text = number(actuator.gear_ratio)
    ET.SubElement(motor, f"{{{DRAKE_NAMESPACE}}}gear_ratio", value=number(actuator.gear_ratio))
    ET.SubElement(
        motor,
        f"{{{DRAKE_NAMESPACE}}}rotor_inertia",
        value=number(actuator.rotor_inertia + actuator.gearbox_inertia),
    )


def _relocate_meshes(
    root: ET.Element, design: RunDesign, source_dir: Path, out: Path
) -> tuple[dict[Path, Path], list[str]]:
    """Point every mesh at its copy in ``<out stem>_meshes/``; the copies to make and the meshes not found.

    A ``package://PKG/rest`` reference is looked for as ``PKG/rest`` in each of the arm's package directories
    and copied to ``PKG/rest`` there; a path (absolute, ``file://`` or relative to the source URDF) is copied
    under its file name (numbered where two share one). A mesh not found keeps a ``package://`` reference, or
    a path relative to the output's folder.
    """
    folder = Path(f"{out.stem}_meshes")
    copies: dict[Path, Path] = {}
    taken: dict[Path, Path] = {}  # destination -> source
    missing: list[str] = []
    for mesh in root.iter("mesh"):
        filename = mesh.get("filename", "")
        if not filename:
            continue
        source, relative = _mesh_source(filename, design.arm.package_dirs, source_dir)
        if source is None:
            missing.append(filename)
            if not filename.startswith("package://"):
                path = Path(filename.removeprefix("file://"))
                absolute = path if path.is_absolute() else source_dir / path
                mesh.set("filename", Path(os.path.relpath(absolute.resolve(), out.parent)).as_posix())
            continue
        destination = folder / relative
        number_ = 1
        while taken.get(destination, source) != source:  # another file of that name: number this one
            destination = folder / f"{relative.stem}_{number_}{relative.suffix}"
            number_ += 1
        taken[destination] = source
        copies[source] = out.parent / destination
        mesh.set("filename", destination.as_posix())
    return copies, sorted(set(missing))


def _mesh_source(filename: str, package_dirs: tuple[str, ...], source_dir: Path) -> tuple[Path | None, Path]:
    """The mesh file a reference names (None if it is not there), and where its copy goes in the meshes folder."""
    if filename.startswith("package://"):
        relative = Path(filename.removeprefix("package://"))
        for directory in package_dirs:
            candidate = Path(directory) / relative
            if candidate.is_file():
                return candidate.resolve(), relative
        return None, relative
    path = Path(filename.removeprefix("file://"))
    absolute = path if path.is_absolute() else source_dir / path
    return (absolute.resolve() if absolute.is_file() else None), Path(path.name)
