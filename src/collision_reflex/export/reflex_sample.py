"""What a run's report predicts at one of its contact samples.

The catalogue design's impulse there, the closed form it comes from, and how much the closed form's assumptions
move it: the rule that picks a sample where the report's model holds, for
:mod:`collision_reflex.export.mujoco_reflex`.
"""

from __future__ import annotations

import dataclasses
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import InvalidParameter
from ..model.sensing import threshold_force
from ..record.read import checked_run_record, read_saved_record
from ..report.files import DESIGNS
from ..simulate.design_closed_form import ArmClosedForm, JointDesign, arm_closed_form
from .run_design import RunDesign, read_run_design


@dataclass(frozen=True)
class ContactSample:
    """A contact sample of a run and the catalogue design's predicted impulse there.

    q: configuration (nv,) [rad]; u: direction (task_dim,); predicted: ``designs.json``'s impulse [N s].
    """

    q: np.ndarray
    u: np.ndarray
    predicted: float


def contact_sample(run_dir: str | os.PathLike[str], sample: int) -> ContactSample:
    """Sample ``sample`` of the run ``run_dir`` and its catalogue design's predicted impulse there.

    Raises :class:`InvalidParameter` for a sample out of range (the run's catalogue design is read first, by
    :func:`~collision_reflex.export.read_run_design`, which refuses a run without one).
    """
    path = Path(run_dir) / DESIGNS
    results = checked_run_record(read_saved_record(path), path)
    if results["kind"] != "arm":
        raise InvalidParameter("run_dir", str(run_dir), "the folder of an arm study")
    samples = results["samples"]
    count = len(samples["config_index"])
    if isinstance(sample, bool) or not isinstance(sample, int) or not 0 <= sample < count:
        raise InvalidParameter("sample", sample, f"a sample index 0 to {count - 1}")
    catalogue = results.get("catalogue")
    record = catalogue.get("design") if catalogue else None
    if record is None:
        raise InvalidParameter("run_dir", str(run_dir), "a run with a catalogue design")
    q = np.asarray(samples["configurations"][samples["config_index"][sample]], dtype=float)
    u = np.asarray(samples["sample_directions"][sample], dtype=float)
    return ContactSample(q, u, float(record["impulses"][sample]))


MODEL_SPREAD = 0.01
"""How far the closed form's variants may move the prediction at a sample where its assumptions hold [-]."""


def model_spread(run_dir: str | os.PathLike[str], sample: int) -> float:
    """How much the closed form's assumptions move the catalogue design's impulse at ``sample`` [-].

    The largest ``|I / I_report - 1|`` against the report's impulse (``designs.json``) over the closed form with
    the robot mass still moving at detection (``reaction="moving"``), the joint-space model, which keeps the
    links' motion along the wall (:data:`collision_reflex.simulate.design_closed_form.REACTION_MODELS`), and,
    for a square Jacobian, the sensing stiffness ``k`` with the links blocked along the wall (the paper's form):
    on a sensing phase shorter than the links' own period along the wall their inertia holds them, and the force
    rises with that stiffness, not the compliance form's. Where the spread is small, the report's model (robot at
    rest at detection, the links free along the wall) is not what sets the impulse there.
    """
    design = read_run_design(run_dir, "catalogue")
    point = contact_sample(run_dir, sample)
    closed = sample_closed_form(design, point, reaction="moving")
    v0 = design.approach_velocity
    variants = [closed.impulse(v0), closed.impulse(v0, "joint_space")]
    if design.arm.task_dim == design.arm.nv:
        blocked = sample_closed_form(design, point, reaction="at_rest", stiffness_form="paper")
        variants.append(blocked.impulse(v0))
    return max(abs(value / point.predicted - 1) for value in variants)


def sample_closed_form(design: RunDesign, point: ContactSample, **options: Any) -> ArmClosedForm:
    """The design's closed form at the sample, its threshold as the force at detection.

    For position sensing that is ``k e_th`` with the sample's (rigid-contact) ``k``, as the optimiser takes it
    (:func:`collision_reflex.model.sensing.threshold_force`). ``options``: those of :func:`arm_closed_form`.
    """
    joints = joint_design(design)
    arm = joints.on(design.arm)
    stiffness = arm_closed_form(arm, point.q, point.u, joints).k
    force = float(threshold_force(design.sensing, design.threshold, stiffness))
    return arm_closed_form(arm, point.q, point.u, dataclasses.replace(joints, threshold=force), **options)


def joint_design(design: RunDesign) -> JointDesign:
    """The design's joint parameters as the arm simulator and the closed form take them."""
    joints = design.joints
    return JointDesign(
        mechanical_stiffness=[j.mechanical_stiffness for j in joints],
        reflected_inertia=[j.reflected_inertia for j in joints],
        torque_limit=[j.driving_peak_torque for j in joints],
        threshold=design.threshold,
        software_stiffness=[j.software_stiffness for j in joints],
        motor_mass=[j.actuator_mass for j in joints],
    )
