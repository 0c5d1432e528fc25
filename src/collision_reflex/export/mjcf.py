"""The arm as MuJoCo MJCF with a design's actuators: armature, motors with their gear, torque ranges.

MuJoCo's own URDF reader converts the exported URDF (:mod:`.urdf`, motor masses included), so that the body
tree, the inertials and the joints are read as MuJoCo reads URDF; the compiled model is then written out with
every number at full precision (MuJoCo's own XML writer rounds to six digits, too coarse to reproduce a mass
matrix), with per joint

- ``armature`` = ``N^2 (J_m + J_g)`` [kg m^2] (MuJoCo adds it to the diagonal of the joint-space inertia): where
  the study placed the rotors behind the joint springs (``robot``), on a rotor of its own (body and joint
  ``JOINT_rotor`` on the parent link, joined to the link by a fixed tendon ``JOINT_spring`` of the joint's
  stiffness ``k_m``), else on the joint;
- ``actuatorfrcrange`` = the driving peak output torque ``eta N tau_p`` [N m], on the rotor or the joint;
- a ``<motor>`` actuator with ``gear`` = N on the rotor (or the joint) whose control is the motor torque [N m]: ``ctrlrange`` and
  ``forcerange`` are the motor's peak torque ``tau_p`` (the force MuJoCo clamps is the actuator's, before the
  gear);

and each motor (and gearbox) mass is a body ``JOINT_actuator`` welded to the parent link at the joint origin.
Meshes are left out (MuJoCo needs them as files beside the model; the URDF keeps their references); primitive
collision shapes are kept. MuJoCo has no joint velocity limit: the URDF carries it.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from typing import Any

import numpy as np

from ..errors import CollisionReflexError, UrdfError
from .run_design import RunDesign
from .urdf import comment, number

CONTACT_SITE = "collision_reflex_contact"

ROTOR = "_rotor"
"""Suffix of a joint's rotor body and joint, where the design places the rotor behind the joint spring."""
TOKEN_MASS, TOKEN_INERTIA = 1e-12, 1e-12
"""A rotor body's own inertial [kg, kg m^2]: MuJoCo moves no massless body; its inertia is the armature."""
"""The site at the design's contact point."""

_GEOM_SIZES = {2: ("sphere", 1), 3: ("capsule", 2), 4: ("ellipsoid", 3), 5: ("cylinder", 2), 6: ("box", 3)}
"""MuJoCo's primitive geom types: type id to (name, number of size entries)."""


class MujocoMissing(CollisionReflexError):
    """MuJoCo is not installed: the MJCF export needs it (``pip install collision-reflex[mujoco]``)."""


def load_mujoco() -> Any:
    """The ``mujoco`` module, or :class:`MujocoMissing` with how to install it."""
    try:
        import mujoco
    except ImportError:
        raise MujocoMissing(
            "the MJCF export needs MuJoCo: pip install 'collision-reflex[mujoco]' (or pip install mujoco)"
        ) from None
    return mujoco


def design_mjcf(design: RunDesign, urdf_text: str) -> str:
    """The MJCF text of ``design``'s arm, from its exported URDF text (:func:`.urdf.design_urdf`)."""
    mujoco = load_mujoco()
    try:
        model = mujoco.MjModel.from_xml_string(_mujoco_urdf(urdf_text))
    except ValueError as error:
        raise UrdfError(
            design.label, f"MuJoCo cannot read the exported URDF: {' '.join(str(error).split())}"
        ) from None
    root = ET.Element("mujoco", model=design.arm.name)
    root.append(comment(_header(design)))
    ET.SubElement(root, "compiler", angle="radian", autolimits="true", inertiafromgeom="false")
    # implicitfast: the joints' damping and the armature integrated implicitly, stable at MuJoCo's default step
    # where the explicit Euler integrator lets a stiff arm diverge.
    ET.SubElement(
        root, "option", gravity=" ".join(number(g) for g in model.opt.gravity), integrator="implicitfast"
    )
    world = ET.SubElement(root, "worldbody")
    actuators = {j.joint: j for j in design.joints}
    rotors = _has_rotors(design)
    bodies: dict[int, ET.Element] = {0: world}
    for body in range(1, model.nbody):
        parent = bodies[int(model.body_parentid[body])]
        element = _body(mujoco, model, body, parent)
        bodies[body] = element
        for joint in range(model.body_jntadr[body], model.body_jntadr[body] + model.body_jntnum[body]):
            actuator = actuators.get(str(mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_JOINT, joint)))
            _joint(mujoco, model, joint, element, None if rotors else actuator)
            if rotors and actuator is not None:
                _rotor(mujoco, model, body, joint, parent, actuator)
        for geom in range(model.body_geomadr[body], model.body_geomadr[body] + model.body_geomnum[body]):
            _geom(model, geom, element)
    _contact_site(mujoco, model, design, bodies)
    if rotors:
        tendons = ET.SubElement(root, "tendon")
        for actuator in design.joints:  # the joint spring, between the link and the rotor
            spring = ET.SubElement(
                tendons,
                "fixed",
                name=f"{actuator.joint}_spring",
                stiffness=number(actuator.mechanical_stiffness),
                springlength="0",
            )
            ET.SubElement(spring, "joint", joint=actuator.joint, coef="1")
            ET.SubElement(spring, "joint", joint=f"{actuator.joint}{ROTOR}", coef="-1")
    _controller(root, design)
    motors = ET.SubElement(root, "actuator")
    for actuator in design.joints:
        torque = number(actuator.motor_peak_torque)
        ET.SubElement(
            motors,
            "motor",
            name=f"{actuator.joint}_motor",
            joint=actuator.joint + (ROTOR if rotors else ""),
            gear=number(actuator.gear_ratio),
            ctrlrange=f"-{torque} {torque}",
            forcerange=f"-{torque} {torque}",
        )
    ET.indent(root, space="  ")
    return ET.tostring(root, encoding="unicode") + "\n"


def _mujoco_urdf(urdf_text: str) -> str:
    """The URDF as MuJoCo reads it here: no meshes, no transmissions, static links kept as bodies."""
    root = ET.fromstring(urdf_text)
    for link in root.findall("link"):
        for visual in link.findall("visual"):
            link.remove(visual)
        for collision in link.findall("collision"):
            if collision.find("geometry/mesh") is not None:
                link.remove(collision)
    for transmission in root.findall("transmission"):
        root.remove(transmission)
    for extension in root.findall("mujoco"):  # the exported URDF's own, for its meshes: replaced
        root.remove(extension)
    extension = ET.SubElement(root, "mujoco")
    ET.SubElement(extension, "compiler", fusestatic="false", discardvisual="true", balanceinertia="false")
    return ET.tostring(root, encoding="unicode")


def _header(design: RunDesign) -> str:
    lines = [
        f"Exported by collision-reflex from study {design.study!r}, {design.label}.",
        *design.parts,
        "Per joint: armature = N^2 (J_m + J_g) [kg m^2]; motor actuator with gear = N, control = motor torque "
        "[N m] within the motor's peak torque; actuatorfrcrange = driving peak output torque eta N tau_p [N m].",
        "Motor (and gearbox) masses: bodies JOINT_actuator welded to the parent link at the joint origin.",
        _placement_line(design.placement, _has_rotors(design)),
        "Controller (MuJoCo runs none; a script reads it): custom numerics collision_reflex_threshold (a contact "
        "force [N], or a position error [m] where collision_reflex_position_sensing is 1), "
        "collision_reflex_approach_velocity [m/s] and collision_reflex_JOINT_software_stiffness [N m/rad] per joint "
        "(the impedance controller's k_s on the motor).",
        "Meshes are left out (see the exported URDF for them); velocity limits are in the URDF only; the URDF's "
        "joint damping and friction are kept; integrator implicitfast.",
    ]
    return "\n  " + "\n  ".join(lines) + "\n"


def _placement_line(placement: str, rotors: bool) -> str:
    """Where the reflected inertia sits, against the placement the study was optimised with."""
    if rotors:
        return (
            "Reflected inertia: each rotor is a degree of freedom of its own behind the joint spring (body and joint "
            "JOINT_rotor with the armature, a fixed tendon JOINT_spring of the joint's stiffness k_m, the motor on "
            "the rotor), as the study was optimised (reflected_inertia_in = robot)."
        )
    line = (
        "Reflected inertia: the armature sits rigidly on the joints, in the impact (the 'finger' placement); "
        f"the study was optimised with reflected_inertia_in = {placement}"
    )
    return line + (
        ", the same." if placement == "finger" else ": this model's impact is a bound of the design's."
    )


CONTROLLER = "collision_reflex_"
"""Prefix of the controller block's numerics (``<custom>``): what the design's controller and detector use."""


def _controller(root: ET.Element, design: RunDesign) -> None:
    """The design's controller as numbers a script reads (MuJoCo runs no controller of its own).

    ``collision_reflex_threshold`` (the detection threshold: a contact force [N] for force sensing, a position
    error [m] for position sensing), ``collision_reflex_position_sensing`` (1 or 0),
    ``collision_reflex_approach_velocity`` [m/s] and per joint ``collision_reflex_JOINT_software_stiffness``
    [N m/rad], the impedance controller's joint stiffness ``k_s`` on the motor.
    """
    custom = ET.SubElement(root, "custom")
    values = {
        "threshold": design.threshold,
        "position_sensing": 1.0 if design.sensing == "position" else 0.0,
        "approach_velocity": design.approach_velocity,
        **{f"{j.joint}_software_stiffness": j.software_stiffness for j in design.joints},
    }
    for name, value in values.items():
        ET.SubElement(custom, "numeric", name=f"{CONTROLLER}{name}", data=number(value))


def _has_rotors(design: RunDesign) -> bool:
    """Whether the rotors are degrees of freedom of their own: the study placed them behind finite springs."""
    return design.placement == "robot" and all(math.isfinite(j.mechanical_stiffness) for j in design.joints)


def _vector(values: Any) -> str:
    return " ".join(number(v) for v in np.asarray(values, dtype=float).ravel())


def _body(mujoco: Any, model: Any, body: int, parent: ET.Element) -> ET.Element:
    """A body with its placement and its inertial (bodies without mass have none)."""
    name = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_BODY, body) or f"body{body}"
    element = ET.SubElement(
        parent, "body", name=name, pos=_vector(model.body_pos[body]), quat=_vector(model.body_quat[body])
    )
    if model.body_mass[body] > 0:
        ET.SubElement(
            element,
            "inertial",
            pos=_vector(model.body_ipos[body]),
            quat=_vector(model.body_iquat[body]),
            mass=number(model.body_mass[body]),
            diaginertia=_vector(model.body_inertia[body]),
        )
    return element


def _joint(mujoco: Any, model: Any, joint: int, body: ET.Element, actuator: Any) -> None:
    """A hinge or slide joint, with the armature and output torque range of its ``actuator``.

    ``actuator`` is None where the rotor is a degree of freedom of its own (:func:`_rotor`).
    """
    name = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_JOINT, joint)
    kind = {int(mujoco.mjtJoint.mjJNT_HINGE): "hinge", int(mujoco.mjtJoint.mjJNT_SLIDE): "slide"}.get(
        int(model.jnt_type[joint])
    )
    if kind is None:
        raise UrdfError(name, "a joint that is neither revolute nor prismatic")
    attributes = {
        "name": name,
        "type": kind,
        "pos": _vector(model.jnt_pos[joint]),
        "axis": _vector(model.jnt_axis[joint]),
    }
    if model.jnt_limited[joint]:
        attributes["range"] = _vector(model.jnt_range[joint])
    dof = int(model.jnt_dofadr[joint])
    for field, values in (("damping", model.dof_damping), ("frictionloss", model.dof_frictionloss)):
        if values[dof] > 0:  # the URDF's <dynamics damping friction>, kept
            attributes[field] = number(values[dof])
    if actuator is not None:
        torque = number(actuator.driving_peak_torque)
        attributes["armature"] = number(actuator.reflected_inertia)
        attributes["actuatorfrcrange"] = f"-{torque} {torque}"
    ET.SubElement(body, "joint", attributes)


def _rotor(mujoco: Any, model: Any, body: int, joint: int, parent: ET.Element, actuator: Any) -> None:
    """The joint's rotor as a degree of freedom of its own, behind the joint spring.

    A body on the parent link at the joint, turning about the joint's axis with the armature ``N^2 (J_m + J_g)``
    and the output torque range; the joint spring ``k_m`` joins it to the link (a fixed tendon). Its inertial is
    a token (MuJoCo moves no massless body).
    """
    quat = model.body_quat[body]
    position, axis = np.zeros(3), np.zeros(3)
    mujoco.mju_rotVecQuat(position, model.jnt_pos[joint], quat)
    mujoco.mju_rotVecQuat(axis, model.jnt_axis[joint], quat)
    name = f"{actuator.joint}{ROTOR}"
    rotor = ET.SubElement(parent, "body", name=name, pos=_vector(model.body_pos[body] + position))
    ET.SubElement(
        rotor, "inertial", pos="0 0 0", mass=number(TOKEN_MASS), diaginertia=_vector([TOKEN_INERTIA] * 3)
    )
    kind = "slide" if int(model.jnt_type[joint]) == int(mujoco.mjtJoint.mjJNT_SLIDE) else "hinge"
    torque = number(actuator.driving_peak_torque)
    ET.SubElement(
        rotor,
        "joint",
        name=name,
        type=kind,
        axis=_vector(axis),
        armature=number(actuator.reflected_inertia),
        actuatorfrcrange=f"-{torque} {torque}",
    )


def _geom(model: Any, geom: int, body: ET.Element) -> None:
    """A primitive collision geom as MuJoCo placed it."""
    kind = _GEOM_SIZES.get(int(model.geom_type[geom]))
    if kind is None:
        return
    shape, sizes = kind
    ET.SubElement(
        body,
        "geom",
        type=shape,
        size=_vector(model.geom_size[geom][:sizes]),
        pos=_vector(model.geom_pos[geom]),
        quat=_vector(model.geom_quat[geom]),
    )


def _contact_site(mujoco: Any, model: Any, design: RunDesign, bodies: dict[int, ET.Element]) -> None:
    """A site at the contact point, where the contact frame is a body (a URDF link)."""
    body = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, design.arm.contact_frame)
    if body > 0:
        ET.SubElement(bodies[body], "site", name=CONTACT_SITE, pos=_vector(design.arm.contact_offset))
