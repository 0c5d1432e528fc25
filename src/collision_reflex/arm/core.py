"""The arm's public names in one place, kept for the modules that import them from here.

The code lives in modules by concept: :mod:`.robot` (:class:`Arm`), :mod:`.samples` (:class:`ArmSamples`),
:mod:`.joints` (:class:`JointParameters`) and :mod:`.effective` (effective parameters and impulses).
"""

from .effective import (
    STIFFNESS_FORMS,
    CollisionImpulses,
    EffectiveParameters,
    collision_impulses,
    effective_parameters,
)
from .joints import JointParameters
from .robot import Arm
from .samples import ArmSamples, task_inverse_inertia

__all__ = [
    "STIFFNESS_FORMS",
    "Arm",
    "ArmSamples",
    "CollisionImpulses",
    "EffectiveParameters",
    "JointParameters",
    "collision_impulses",
    "effective_parameters",
    "task_inverse_inertia",
]
