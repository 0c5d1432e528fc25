"""The arm as MuJoCo MJCF with a design's actuators: armature, motors with their gear, torque ranges.

MuJoCo's own URDF reader converts the exported URDF (:mod:`.urdf`, motor masses included), so that the body
tree, the inertials and the joints are read as MuJoCo reads URDF; the compiled model is then written out with
every number at full precision (MuJoCo's own XML writer rounds to six digits, too coarse to reproduce a mass
matrix), with per joint

- ``armature`` = ``N^2 (J_m + J_g)`` [kg m^2] (MuJoCo adds it to the diagonal of the joint-space inertia);
- ``actuatorfrcrange`` = the peak output torque ``N tau_p`` [N m];
- a ``<motor>`` actuator with ``gear`` = N whose control is the motor torque [N m]: ``ctrlrange`` and
  ``forcerange`` are the motor's peak torque ``tau_p`` (the force MuJoCo clamps is the actuator's, before the
  gear);

and each motor (and gearbox) mass is a body ``JOINT_actuator`` welded to the parent link at the joint origin.
Meshes are left out (MuJoCo needs them as files beside the model; the URDF keeps their references); primitive
collision shapes are kept. MuJoCo has no joint velocity limit: the URDF carries it.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from typing import Any

import numpy as np

from ..errors import CollisionReflexError, UrdfError
from .run_design import RunDesign
from .urdf import comment, number

CONTACT_SITE = "collision_reflex_contact"
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
    bodies: dict[int, ET.Element] = {0: world}
    for body in range(1, model.nbody):
        element = _body(mujoco, model, body, bodies[int(model.body_parentid[body])])
        bodies[body] = element
        for joint in range(model.body_jntadr[body], model.body_jntadr[body] + model.body_jntnum[body]):
            _joint(mujoco, model, joint, element, actuators)
        for geom in range(model.body_geomadr[body], model.body_geomadr[body] + model.body_geomnum[body]):
            _geom(model, geom, element)
    _contact_site(mujoco, model, design, bodies)
    motors = ET.SubElement(root, "actuator")
    for actuator in design.joints:
        torque = number(actuator.motor_peak_torque)
        ET.SubElement(
            motors,
            "motor",
            name=f"{actuator.joint}_motor",
            joint=actuator.joint,
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
        _placement_line(design.placement),
        "Meshes are left out (see the exported URDF for them); velocity limits are in the URDF only; the URDF's "
        "joint damping and friction are kept; integrator implicitfast.",
    ]
    return "\n  " + "\n  ".join(lines) + "\n"


def _placement_line(placement: str) -> str:
    """What the armature means against the placement the study was optimised with."""
    line = (
        "Reflected inertia: the armature sits rigidly on the joints, in the impact (the 'finger' placement); "
        f"the study was optimised with reflected_inertia_in = {placement}"
    )
    if placement == "finger":
        return line + ", the same."
    return line + (
        " (the rotors behind the joint springs): along a contact direction this model's finger mass is larger by "
        "the rotors' share, and its impulse a bound of the design's."
    )


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


def _joint(mujoco: Any, model: Any, joint: int, body: ET.Element, actuators: dict[str, Any]) -> None:
    """A hinge or slide joint, with the design's armature and output torque range."""
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
    actuator = actuators.get(name)
    if actuator is not None:
        torque = number(actuator.driving_peak_torque)
        attributes["armature"] = number(actuator.reflected_inertia)
        attributes["actuatorfrcrange"] = f"-{torque} {torque}"
    ET.SubElement(body, "joint", attributes)


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
