"""collision-reflex: design optimisation of robot actuators for a gentle collision reflex.

The collision reflex is the total impulse a robot transfers to a rigid object when it runs into it, detects the
contact and backs away (Bhatia, Mason and Johnson, "Reacting to Contact: Transparency and Collision Reflex in
Actuation"). This package evaluates it from structure, actuation, stiffness and sensing, for single actuators and
URDF arms, and optimises actuator designs against it.

Every public name is imported on first use (PEP 562), so that ``import collision_reflex`` and the ``crx`` command
start without loading CasADi, SciPy, Pinocchio or Matplotlib.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from ._lazy import lazy_attributes

if TYPE_CHECKING:  # the names as type checkers and IDEs see them; at run time `__getattr__` imports them
    from . import experiments
    from .arm import (
        Arm,
        ArmSamples,
        CollisionImpulses,
        CycleTorques,
        DutyCycle,
        EffectiveParameters,
        JointParameters,
        Payload,
        collision_impulses,
        cycle_torques,
        effective_parameters,
        joint_side_torque,
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
        TrajectoryError,
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
    from .hardware.gearbox_scaling import GEARBOX_KINDS
    from .hardware.gearboxes import Gearbox
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
    from .model.sensing import SENSING_SCHEMES, current_threshold_torque, threshold_force
    from .optimize import (
        OBJECTIVES,
        ActuatorTechnology,
        Bounds,
        CatalogueDesign,
        Constraints,
        ContactSamples,
        Design,
        DesignProblem,
        DesignResult,
        DesignSpace,
        ParetoSet,
        build_problem,
        hypervolume,
        pareto_front,
        snap_to_catalogue,
    )
    from .optimize.results import result_from_json, result_to_json
    from .optimize.solve import solve  # from its module: mypy confuses it with `optimize.solve`
    from .report import render_report
    from .simulate import (
        DETECTION_KINDS,
        DRIVES,
        SWEEP_PARAMETERS,
        ArmCollision,
        CollisionSetup,
        Detection,
        SimulationResult,
        contact_damping_for_restitution,
        contact_restitution,
        simulate_arm_collision,
    )
    from .simulate import Sweep as SimulationSweep
    from .simulate import simulate as simulate_collision
    from .simulate import sweep as simulation_sweep
    from .study import load_study, study_json_schema
    from .study.runner import run_study

__version__ = "0.1.0"

# Where each public name lives: the module it is defined in (relative to this package), by module ...
_EXPORTS: dict[str, tuple[str, ...]] = {
    ".arm": (
        "Arm",
        "ArmSamples",
        "CollisionImpulses",
        "CycleTorques",
        "DutyCycle",
        "EffectiveParameters",
        "JointParameters",
        "Payload",
        "collision_impulses",
        "cycle_torques",
        "effective_parameters",
        "joint_side_torque",
    ),
    ".arm.directions": (
        "circle_directions",
        "sphere_directions",
        "unit_directions",
    ),
    ".arm.metrics": (
        "Ellipsoid",
        "ImpactMitigation",
        "dynamic_manipulability_ellipsoid",
        "effective_mass",
        "ellipsoid_of_gyration",
        "generalized_inertia_ellipsoid",
        "impact_mitigation_factor",
    ),
    ".arm.surfaces": (
        "ReflexSurface",
        "reflex_surface",
    ),
    ".errors": (
        "CatalogueError",
        "CollisionReflexError",
        "FitFailed",
        "FrameNotFound",
        "InvalidParameter",
        "SimulationError",
        "SolverFailed",
        "StudyFileError",
        "StudyProblem",
        "StudyRunFailed",
        "TraceError",
        "TrajectoryError",
        "UnknownMotor",
        "UrdfError",
    ),
    ".hardware.actuators": (
        "REFLECTED_INERTIA_PLACEMENTS",
        "Actuator",
        "CollisionParameters",
        "CurrentThreshold",
        "ForceThreshold",
        "PositionThreshold",
        "gear_ratio_for",
    ),
    ".hardware.gearbox_scaling": ("GEARBOX_KINDS",),
    ".hardware.gearboxes": ("Gearbox",),
    ".hardware.motors": (
        "SCALING_LAWS",
        "Motor",
        "MotorQuantities",
        "ScalingLaw",
        "load_catalogue",
        "reference_motor",
        "scaled_motor_quantities",
        "scaling_law",
    ),
    ".model.impulse": (
        "REACTION_MODES",
        "PhaseImpulses",
        "collision_times",
        "force_profile",
        "minimum_impulse",
        "optimal_velocity",
        "phase_impulses",
        "series_stiffness",
        "total_impulse",
        "velocity_coefficients",
    ),
    ".model.sensing": (
        "SENSING_SCHEMES",
        "current_threshold_torque",
        "threshold_force",
    ),
    ".optimize": (
        "OBJECTIVES",
        "ActuatorTechnology",
        "Bounds",
        "CatalogueDesign",
        "Constraints",
        "ContactSamples",
        "Design",
        "DesignProblem",
        "DesignResult",
        "DesignSpace",
        "ParetoSet",
        "build_problem",
        "hypervolume",
        "pareto_front",
        "snap_to_catalogue",
        "solve",
    ),
    ".optimize.results": (
        "result_from_json",
        "result_to_json",
    ),
    ".report": ("render_report",),
    ".simulate": (
        "DETECTION_KINDS",
        "DRIVES",
        "SWEEP_PARAMETERS",
        "ArmCollision",
        "CollisionSetup",
        "Detection",
        "SimulationResult",
        "contact_damping_for_restitution",
        "contact_restitution",
        "simulate_arm_collision",
    ),
    ".study": (
        "load_study",
        "study_json_schema",
    ),
    ".study.runner": ("run_study",),
}
# ... and the names exported under another name than their module's (new name: module, attribute).
_RENAMED: dict[str, tuple[str, str]] = {
    "SimulationSweep": (".simulate", "Sweep"),
    "simulate_collision": (".simulate", "simulate"),
    "simulation_sweep": (".simulate", "sweep"),
}
_WHERE: dict[str, tuple[str, str]] = {
    **{name: (module, name) for module, names in _EXPORTS.items() for name in names},
    **_RENAMED,
}

__all__ = [
    "DETECTION_KINDS",
    "DRIVES",
    "GEARBOX_KINDS",
    "OBJECTIVES",
    "REACTION_MODES",
    "REFLECTED_INERTIA_PLACEMENTS",
    "SCALING_LAWS",
    "SENSING_SCHEMES",
    "SWEEP_PARAMETERS",
    "Actuator",
    "ActuatorTechnology",
    "Arm",
    "ArmCollision",
    "ArmSamples",
    "Bounds",
    "CatalogueDesign",
    "CatalogueError",
    "CollisionImpulses",
    "CollisionParameters",
    "CollisionReflexError",
    "CollisionSetup",
    "Constraints",
    "ContactSamples",
    "CurrentThreshold",
    "CycleTorques",
    "Design",
    "DesignProblem",
    "DesignResult",
    "DesignSpace",
    "Detection",
    "DutyCycle",
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
    "Payload",
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
    "TrajectoryError",
    "UnknownMotor",
    "UrdfError",
    "__version__",
    "build_problem",
    "circle_directions",
    "collision_impulses",
    "collision_times",
    "contact_damping_for_restitution",
    "contact_restitution",
    "current_threshold_torque",
    "cycle_torques",
    "dynamic_manipulability_ellipsoid",
    "effective_mass",
    "effective_parameters",
    "ellipsoid_of_gyration",
    "experiments",
    "force_profile",
    "gear_ratio_for",
    "generalized_inertia_ellipsoid",
    "hypervolume",
    "impact_mitigation_factor",
    "joint_side_torque",
    "load_catalogue",
    "load_study",
    "minimum_impulse",
    "optimal_velocity",
    "pareto_front",
    "phase_impulses",
    "reference_motor",
    "reflex_surface",
    "render_report",
    "result_from_json",
    "result_to_json",
    "run_study",
    "scaled_motor_quantities",
    "scaling_law",
    "series_stiffness",
    "simulate_arm_collision",
    "simulate_collision",
    "simulation_sweep",
    "snap_to_catalogue",
    "solve",
    "sphere_directions",
    "study_json_schema",
    "threshold_force",
    "total_impulse",
    "unit_directions",
    "velocity_coefficients",
]

if not TYPE_CHECKING:  # hidden from type checkers, so that a misspelt name is still an error for them
    __getattr__, __dir__ = lazy_attributes(globals(), _WHERE, __all__)
