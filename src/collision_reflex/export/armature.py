"""The armature companion of an exported URDF: the reflected inertia per joint, ready for Pinocchio.

URDF has no armature field; ``FILE.armature.json`` beside ``FILE`` holds, per joint, the armature
``N^2 (J_m + J_g)`` [kg m^2] with the gear ratio and the inertias it comes from. Pinocchio's joint-space
inertia is ``crba(model) + diag(model.armature)``; set it with :func:`set_armature`, or by hand::

    import json, pinocchio as pin
    model = pin.buildModelFromUrdf("arm.urdf")
    for name, joint in json.load(open("arm.urdf.armature.json"))["joints"].items():
        model.armature[model.joints[model.getJointId(name)].idx_v] = joint["armature"]
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

from .._io import read_json
from ..errors import InvalidParameter
from .run_design import RunDesign

SUFFIX = ".armature.json"
"""Appended to the exported file's name for its armature companion."""


def companion_path(out: str | os.PathLike[str]) -> Path:
    """The armature companion of the exported file ``out``."""
    path = Path(out)
    return path.with_name(path.name + SUFFIX)


def armature_record(design: RunDesign, urdf_name: str) -> dict[str, Any]:
    """The companion's content: per joint the armature [kg m^2], gear ratio, rotor and gearbox inertia."""
    return {
        "urdf": urdf_name,
        "study": design.study,
        "design": design.label,
        "units": {"armature": "kg*m^2", "rotor_inertia": "kg*m^2", "gearbox_inertia": "kg*m^2"},
        "how": "model.armature[model.joints[model.getJointId(name)].idx_v] = joints[name]['armature']",
        "joints": {
            j.joint: {
                "armature": j.reflected_inertia,
                "gear_ratio": j.gear_ratio,
                "rotor_inertia": j.rotor_inertia,
                "gearbox_inertia": j.gearbox_inertia,
            }
            for j in design.joints
        },
    }


def set_armature(model: Any, companion: str | os.PathLike[str]) -> Any:
    """Set ``model.armature`` (a ``pinocchio.Model`` of the exported URDF) from its companion file; returns it.

    Joints the companion does not name keep their armature.
    """
    joints = read_json(companion)["joints"]
    armature = model.armature.copy()
    for name, joint in joints.items():
        if not model.existJointName(name):
            raise InvalidParameter("companion", f"joint {name!r}", "joints of the model", str(companion))
        armature[model.joints[model.getJointId(name)].idx_v] = float(joint["armature"])
    model.armature = armature
    return model
