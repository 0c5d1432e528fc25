"""collision-reflex: design optimisation of robot actuators for a gentle collision reflex.

The collision reflex is the total impulse a robot transfers to a rigid object when it runs into it, detects the
contact and backs away (Bhatia, Mason and Johnson, "Reacting to Contact: Transparency and Collision Reflex in
Actuation"). This package evaluates it from structure, actuation, stiffness and sensing, for single actuators and
URDF arms, and optimises actuator designs against it.
"""

from . import experiments
from .arm.core import (
    Arm,
    ArmSamples,
    CollisionImpulses,
    EffectiveParameters,
    JointParameters,
    collision_impulses,
    effective_parameters,
)
from .arm.directions import circle_directions, sphere_directions, unit_directions
from .arm.metrics import (
    Ellipsoid,
    ImpactMitigation,
    dynamic_manipulability_ellipsoid,
    effective_mass,
    ellipsoid_of_gyration,
    generalized_inertia_ellipsoid,
    impact_mitigation_factor,
)
from .arm.surfaces import ReflexSurface, reflex_surface
from .errors import (
    CatalogueError,
    CollisionReflexError,
    FitFailed,
    FrameNotFound,
    InvalidParameter,
    SimulationError,
    SolverFailed,
    StudyFileError,
    StudyProblem,
    StudyRunFailed,
    TraceError,
    UnknownMotor,
    UrdfError,
)
from .hardware.actuators import (
    REFLECTED_INERTIA_PLACEMENTS,
    Actuator,
    CollisionParameters,
    CurrentThreshold,
    ForceThreshold,
    PositionThreshold,
    gear_ratio_for,
)
from .hardware.gearboxes import GEARBOX_KINDS, Gearbox
from .hardware.motors import (
    SCALING_LAWS,
    Motor,
    MotorQuantities,
    ScalingLaw,
    load_catalogue,
    reference_motor,
    scaled_motor_quantities,
    scaling_law,
)
from .model.impulse import (
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
from .simulate.arm import ArmCollision, simulate_arm_collision
from .simulate.collision import (
    CollisionSetup,
    Detection,
    SimulationResult,
    contact_damping_for_restitution,
    contact_restitution,
)
from .simulate.collision import Sweep as SimulationSweep
from .simulate.collision import simulate as simulate_collision
from .simulate.collision import sweep as simulation_sweep
from .study import load_study, study_json_schema
from .study.runner import run_study

__version__ = "0.1.0"

__all__ = [
    "GEARBOX_KINDS",
    "OBJECTIVES",
    "REACTION_MODES",
    "REFLECTED_INERTIA_PLACEMENTS",
    "SCALING_LAWS",
    "Actuator",
    "ActuatorTechnology",
    "Arm",
    "ArmCollision",
    "ArmSamples",
    "Bounds",
    "CatalogueError",
    "CollisionImpulses",
    "CollisionParameters",
    "CollisionReflexError",
    "CollisionSetup",
    "Constraints",
    "ContactSamples",
    "CurrentThreshold",
    "Design",
    "DesignProblem",
    "DesignResult",
    "DesignSpace",
    "Detection",
    "EffectiveParameters",
    "Ellipsoid",
    "FitFailed",
    "ForceThreshold",
    "FrameNotFound",
    "Gearbox",
    "ImpactMitigation",
    "InvalidParameter",
    "JointParameters",
    "Motor",
    "MotorQuantities",
    "ParetoSet",
    "PhaseImpulses",
    "PositionThreshold",
    "ReflexSurface",
    "ScalingLaw",
    "SimulationError",
    "SimulationResult",
    "SimulationSweep",
    "SolverFailed",
    "StudyFileError",
    "StudyProblem",
    "StudyRunFailed",
    "TraceError",
    "UnknownMotor",
    "UrdfError",
    "__version__",
    "build_problem",
    "circle_directions",
    "collision_impulses",
    "collision_times",
    "contact_damping_for_restitution",
    "contact_restitution",
    "dynamic_manipulability_ellipsoid",
    "effective_mass",
    "effective_parameters",
    "ellipsoid_of_gyration",
    "experiments",
    "force_profile",
    "gear_ratio_for",
    "generalized_inertia_ellipsoid",
    "impact_mitigation_factor",
    "load_catalogue",
    "load_study",
    "minimum_impulse",
    "optimal_velocity",
    "pareto_front",
    "phase_impulses",
    "reference_motor",
    "reflex_surface",
    "run_study",
    "scaled_motor_quantities",
    "scaling_law",
    "series_stiffness",
    "simulate_arm_collision",
    "simulate_collision",
    "simulation_sweep",
    "solve",
    "sphere_directions",
    "study_json_schema",
    "total_impulse",
    "unit_directions",
    "velocity_coefficients",
]
