"""Arms through Pinocchio, with their contact samples, duty cycles and joint torques.

Loading URDFs and stock robots, contact samples, effective parameters along a direction, transparency
metrics, collision reflex surfaces, duty cycles and the joint torques over them.
"""

from .directions import circle_directions, sphere_directions, unit_directions
from .duty_cycle import DutyCycle, Payload
from .dynamics import CycleTorques, cycle_torques, joint_side_torque
from .effective import CollisionImpulses, EffectiveParameters, collision_impulses, effective_parameters
from .joints import JointParameters
from .robot import Arm
from .samples import ArmSamples

__all__ = [
    "Arm",
    "ArmSamples",
    "CollisionImpulses",
    "CycleTorques",
    "DutyCycle",
    "EffectiveParameters",
    "JointParameters",
    "Payload",
    "circle_directions",
    "collision_impulses",
    "cycle_torques",
    "effective_parameters",
    "joint_side_torque",
    "sphere_directions",
    "unit_directions",
]
