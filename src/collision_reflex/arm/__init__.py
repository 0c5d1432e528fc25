"""Arms through Pinocchio: loading URDFs and stock robots, contact samples, effective parameters along a
direction, transparency metrics and collision reflex surfaces.
"""

from .directions import circle_directions, sphere_directions, unit_directions
from .effective import CollisionImpulses, EffectiveParameters, collision_impulses, effective_parameters
from .joints import JointParameters
from .robot import Arm
from .samples import ArmSamples

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
