"""Arms through Pinocchio: loading, contact samples, effective parameters, metrics and reflex surfaces.

Loading covers URDFs and stock robots; effective parameters are along a direction; the metrics are
transparency metrics, and the surfaces collision reflex surfaces.
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
