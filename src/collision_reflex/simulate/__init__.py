"""Time-domain collision models that show where the closed form holds: the 1D collision (contact, controller,
detection, reaction) and the elastic-joint arm against a compliant wall."""

from .arm import ArmCollision, simulate_arm_collision
from .collision import (
    CollisionSetup,
    Detection,
    SimulationResult,
    Sweep,
    contact_damping_for_restitution,
    contact_restitution,
    simulate,
    sweep,
)

__all__ = [
    "ArmCollision",
    "CollisionSetup",
    "Detection",
    "SimulationResult",
    "Sweep",
    "contact_damping_for_restitution",
    "contact_restitution",
    "simulate",
    "simulate_arm_collision",
    "sweep",
]
