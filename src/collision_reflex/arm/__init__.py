"""Arms through Pinocchio, with their contact samples, duty cycles and joint torques.

Loading URDFs and stock robots, contact samples, effective parameters along a direction, transparency
metrics, collision reflex surfaces, duty cycles and the joint torques over them.
"""

from .directions import circle_directions, sphere_directions, unit_directions
from .duty_cycle import DutyCycle, Payload
from .dynamics import CycleTorques, cycle_torques, joint_side_torque
from .effective import CollisionImpulses, EffectiveParameters, collision_impulses, effective_parameters
from .joints import JointParameters
from .metrics import (
    Ellipsoid,
    ImpactMitigation,
    dynamic_manipulability_ellipsoid,
    effective_mass,
    ellipsoid_of_gyration,
    generalized_inertia_ellipsoid,
    impact_mitigation_factor,
)
from .robot import Arm
from .samples import ArmSamples
from .surfaces import ReflexSurface, reflex_surface

__all__ = [
    "Arm",
    "ArmSamples",
    "CollisionImpulses",
    "CycleTorques",
    "DutyCycle",
    "EffectiveParameters",
    "Ellipsoid",
    "ImpactMitigation",
    "JointParameters",
    "Payload",
    "ReflexSurface",
    "circle_directions",
    "collision_impulses",
    "cycle_torques",
    "dynamic_manipulability_ellipsoid",
    "effective_mass",
    "effective_parameters",
    "ellipsoid_of_gyration",
    "generalized_inertia_ellipsoid",
    "impact_mitigation_factor",
    "joint_side_torque",
    "reflex_surface",
    "sphere_directions",
    "unit_directions",
]
