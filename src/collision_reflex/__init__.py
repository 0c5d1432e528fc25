"""collision-reflex: design optimisation of robot actuators for a gentle collision reflex.

The collision reflex is the total impulse a robot transfers to a rigid object when it runs into it, detects the
contact and backs away (Bhatia, Mason and Johnson, "Reacting to Contact: Transparency and Collision Reflex in
Actuation"). This package evaluates it from structure, actuation, stiffness and sensing, for single actuators and
URDF arms, and optimises actuator designs against it.
"""

from .actuators import (
    REFLECTED_INERTIA_PLACEMENTS,
    Actuator,
    CollisionParameters,
    CurrentThreshold,
    ForceThreshold,
    PositionThreshold,
    gear_ratio_for,
)
from .errors import CatalogueError, CollisionReflexError, InvalidParameter, UnknownMotor
from .gearboxes import GEARBOX_KINDS, Gearbox
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
from .motors import (
    SCALING_LAWS,
    Motor,
    MotorQuantities,
    ScalingLaw,
    load_catalogue,
    reference_motor,
    scaled_motor_quantities,
    scaling_law,
)

__version__ = "0.1.0"

__all__ = [
    "GEARBOX_KINDS",
    "REACTION_MODES",
    "REFLECTED_INERTIA_PLACEMENTS",
    "SCALING_LAWS",
    "Actuator",
    "CatalogueError",
    "CollisionParameters",
    "CollisionReflexError",
    "CurrentThreshold",
    "ForceThreshold",
    "Gearbox",
    "InvalidParameter",
    "Motor",
    "MotorQuantities",
    "PhaseImpulses",
    "PositionThreshold",
    "ScalingLaw",
    "UnknownMotor",
    "__version__",
    "collision_times",
    "force_profile",
    "gear_ratio_for",
    "load_catalogue",
    "minimum_impulse",
    "optimal_velocity",
    "phase_impulses",
    "reference_motor",
    "scaled_motor_quantities",
    "scaling_law",
    "series_stiffness",
    "total_impulse",
    "velocity_coefficients",
]
