"""collision-reflex: design optimisation of robot actuators for a gentle collision reflex.

The collision reflex is the total impulse a robot transfers to a rigid object when it runs into it, detects the
contact and backs away (Bhatia, Mason and Johnson, "Reacting to Contact: Transparency and Collision Reflex in
Actuation"). This package evaluates it from structure, actuation, stiffness and sensing, for single actuators and
URDF arms, and optimises actuator designs against it.
"""

from . import experiments
from .errors import CollisionReflexError, FitFailed, InvalidParameter, TraceError
from .impulse import (
    REACTION_MODES,
    PhaseImpulses,
    collision_times,
    force_profile,
    minimum_impulse,
    optimal_velocity,
    phase_impulses,
    series_stiffness,
    total_impulse,
    velocity_coefficients,
)

__version__ = "0.1.0"

__all__ = [
    "REACTION_MODES",
    "CollisionReflexError",
    "FitFailed",
    "InvalidParameter",
    "PhaseImpulses",
    "TraceError",
    "__version__",
    "collision_times",
    "experiments",
    "force_profile",
    "minimum_impulse",
    "optimal_velocity",
    "phase_impulses",
    "series_stiffness",
    "total_impulse",
    "velocity_coefficients",
]
