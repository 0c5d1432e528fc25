"""Arms through Pinocchio: loading URDFs and stock robots, contact samples, effective parameters along a
direction, transparency metrics and collision reflex surfaces.
"""

from .core import (
    Arm,
    ArmSamples,
    CollisionImpulses,
    EffectiveParameters,
    JointParameters,
    collision_impulses,
    effective_parameters,
)
from .directions import circle_directions, sphere_directions, unit_directions

__all__ = [
    "Arm",
    "ArmSamples",
    "CollisionImpulses",
    "EffectiveParameters",
    "JointParameters",
    "circle_directions",
    "collision_impulses",
    "effective_parameters",
    "sphere_directions",
    "unit_directions",
]
