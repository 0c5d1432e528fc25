"""Evaluate a design on the problem's samples through the NumPy path, independently of the CasADi model.

The CasADi model takes the maximum over joints of per-joint reaction impulses (its epigraph form); this path
computes the reaction capacity as the minimum over joints, ``F_a = min_i tau_i / |w_i|`` (the paper's "Collision Reflex in Higher Dimensions"),
and then the 1D impulse once. Agreement of the two checks the reformulation as well as the code.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ..arm.effective import effective_parameters
from ..model import effective as formulas
from ..model.impulse import series_stiffness, total_impulse

if TYPE_CHECKING:
    from ..arm.effective import EffectiveParameters
    from .design import Design
    from .problem import DesignProblem
    from .samples import ContactSamples
    from .technology import ActuatorTechnology


def design_collision_parameters(
    problem: DesignProblem, design: Design
) -> tuple[EffectiveParameters, np.ndarray]:
    """Effective 1D parameters of ``design`` at each of the problem's samples, and their force thresholds.

    The parameters are a :class:`collision_reflex.arm.EffectiveParameters`; the contact-force threshold [N] is
    one per sample, shape (n_samples,).
    """
    return collision_parameters(problem.samples, problem.technology, design)


def collision_parameters(
    samples: ContactSamples, technology: ActuatorTechnology, design: Design
) -> tuple[EffectiveParameters, np.ndarray]:
    """:func:`design_collision_parameters` at any ``samples`` of the arm, with the design's ``technology``."""
    in_finger = technology.finger_joints(design.reflected_inertia.size)
    params = effective_parameters(
        samples.kinematics,
        samples.directions,
        config_index=samples.config_index,
        reflected_inertia=design.reflected_inertia,
        stiffness=series_stiffness(design.mechanical_stiffness, design.software_stiffness),
        mechanical_stiffness=design.mechanical_stiffness,
        torque_limit=design.peak_torque,
        motor_mass=design.actuator_mass,
        finger_joint_inertia=(
            formulas.finger_inertia(design.reflected_inertia, np.array(in_finger)) if any(in_finger) else None
        ),
    )
    threshold = design.threshold if design.sensing == "force" else params.k * design.threshold
    return params, np.broadcast_to(np.asarray(threshold, dtype=float), params.m_f.shape)


def evaluate_design(problem: DesignProblem, design: Design) -> np.ndarray:
    """Collision impulse [N*s] of ``design`` at each of the problem's samples, shape (n_samples,)."""
    return sample_impulses(problem.samples, problem.technology, design)


def sample_impulses(samples: ContactSamples, technology: ActuatorTechnology, design: Design) -> np.ndarray:
    """Collision impulse [N*s] of ``design`` at any ``samples`` of the arm, shape (n_samples,)."""
    params, threshold = collision_parameters(samples, technology, design)
    return np.asarray(
        total_impulse(
            params.m_f,
            params.k,
            params.k_m,
            threshold,
            params.a,
            design.approach_velocity,
            technology.reaction,
        )
    )
