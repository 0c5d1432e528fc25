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
from .errors import CatalogueError, CollisionReflexError, InvalidParameter, SolverFailed, UnknownMotor
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
from .optimize import (
    OBJECTIVES,
    ActuatorTechnology,
    Bounds,
    Constraints,
    ContactSamples,
    Design,
    DesignProblem,
    DesignResult,
    DesignSpace,
    ParetoSet,
    build_problem,
    pareto_front,
    solve,
)

__version__ = "0.1.0"

__all__ = [
    "GEARBOX_KINDS",
    "OBJECTIVES",
    "REACTION_MODES",
    "REFLECTED_INERTIA_PLACEMENTS",
    "SCALING_LAWS",
    "Actuator",
    "ActuatorTechnology",
    "Bounds",
    "CatalogueError",
    "CollisionParameters",
    "CollisionReflexError",
    "Constraints",
    "ContactSamples",
    "CurrentThreshold",
    "Design",
    "DesignProblem",
    "DesignResult",
    "DesignSpace",
    "ForceThreshold",
    "Gearbox",
    "InvalidParameter",
    "Motor",
    "MotorQuantities",
    "ParetoSet",
    "PhaseImpulses",
    "PositionThreshold",
    "ScalingLaw",
    "SolverFailed",
    "UnknownMotor",
    "__version__",
    "build_problem",
    "collision_times",
    "force_profile",
    "gear_ratio_for",
    "load_catalogue",
    "minimum_impulse",
    "optimal_velocity",
    "pareto_front",
    "phase_impulses",
    "reference_motor",
    "scaled_motor_quantities",
    "scaling_law",
    "series_stiffness",
    "solve",
    "total_impulse",
    "velocity_coefficients",
]
