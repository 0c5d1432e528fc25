"""The closed sets of names the toolkit speaks in, each written once.

The study schema, the optimiser, the simulator and the command line import them from here: a name added or
renamed here is added or renamed everywhere. Each is a ``Literal`` type (for the schema and type checkers) and
the tuple of its values, in the order the outputs list them.
"""

from __future__ import annotations

from typing import Literal, get_args

SensingScheme = Literal["force", "position", "current"]
"""``"force"``: a contact-force threshold [N]; ``"position"``: a position-error threshold [m] at the contact
point; ``"current"``: a motor-current (joint-torque) threshold [N·m] per joint."""
SENSING_SCHEMES: tuple[SensingScheme, ...] = get_args(SensingScheme)

OptimizedSensingScheme = Literal["force", "position"]
"""The sensing schemes the optimiser handles: a current threshold makes the contact threshold a minimum over
joints, which is evaluated but not optimised."""
OPTIMIZED_SENSING_SCHEMES: tuple[OptimizedSensingScheme, ...] = get_args(OptimizedSensingScheme)

ObjectiveName = Literal[
    "worst_case_impulse", "mean_impulse", "cvar_impulse", "actuator_mass", "approach_velocity"
]
"""The design objectives (their sense, unit and meaning: :data:`collision_reflex.optimize.objectives.OBJECTIVES`)."""
OBJECTIVE_NAMES: tuple[ObjectiveName, ...] = get_args(ObjectiveName)

ImpulseObjective = Literal["worst_case_impulse", "mean_impulse", "cvar_impulse"]
"""The objectives that are statistics of the per-sample collision impulses."""
IMPULSE_OBJECTIVES: tuple[ImpulseObjective, ...] = get_args(ImpulseObjective)

ScalingLawName = Literal["haddadin", "isometric", "empirical", "quadruped"]
"""The motor scaling laws (:data:`collision_reflex.hardware.motors.SCALING_LAWS`)."""
SCALING_LAW_NAMES: tuple[ScalingLawName, ...] = get_args(ScalingLawName)

GearboxKind = Literal["planetary", "parallel_shaft", "harmonic", "cycloidal", "ball_screw"]
"""The gearbox kinds with a scaling law (:data:`collision_reflex.hardware.gearbox_scaling.GEARBOX_SCALING`)."""
GEARBOX_KINDS: tuple[GearboxKind, ...] = get_args(GearboxKind)

PerRatioFigure = Literal["rated_torque", "peak_torque", "momentary_torque", "inertia"]
"""The catalogue gearbox's figures a datasheet may give per ratio (a mapping gear ratio -> figure)."""
PER_RATIO_FIELDS: tuple[PerRatioFigure, ...] = get_args(PerRatioFigure)

ExecutorName = Literal["serial", "processes", "dask"]
"""Where a study's solves run: in the calling process, a local process pool, or a Dask cluster."""
EXECUTORS: tuple[ExecutorName, ...] = get_args(ExecutorName)

ReactionMode = Literal["at_rest", "moving"]
"""The closed form's reaction: the robot mass at rest at detection (the paper's), or still moving."""
REACTION_MODES: tuple[ReactionMode, ...] = get_args(ReactionMode)

Placement = Literal["robot", "finger"]
"""Where the reflected rotor inertia ``N² J_m`` counts: with the finger (a stiff transmission) or with the robot
behind the mechanical spring."""
REFLECTED_INERTIA_PLACEMENTS: tuple[Placement, ...] = get_args(Placement)

Retreat = Literal["along_u", "saturated"]
"""The motors' push in an arm's reaction: ``"along_u"``, ``tau = -F_a J^T u`` with ``F_a = min_i tau_max,i /
|(J^T u)_i|`` (each joint at most at its limit and the first at it: the closed form's reaction); ``"saturated"``,
``tau_i = -tau_max,i sign((J^T u)_i)`` (every joint at its limit: a real controller's retreat, more force along
``-u`` and a push off it)."""
RETREATS: tuple[Retreat, ...] = get_args(Retreat)

Drive = Literal["ideal", "impedance", "free"]
"""The 1D simulator's robot-side drive during the approach (:mod:`collision_reflex.simulate`)."""
DRIVES: tuple[Drive, ...] = get_args(Drive)

ControlledDrive = Literal["ideal", "impedance"]
"""The drives with a controller: the arm simulator's, and what ``crx simulate`` offers (``"free"`` applies no
actuator force, for energy bookkeeping only)."""
CONTROLLED_DRIVES: tuple[ControlledDrive, ...] = get_args(ControlledDrive)

ActiveSetMode = Literal["auto", "always", "never"]
"""Whether the optimiser solves on an active set of samples: by sample count, always, or never."""
ACTIVE_SET_CHOICES: tuple[ActiveSetMode, ...] = get_args(ActiveSetMode)

PerJointVariable = Literal["stator_diameter", "stack_length", "gear_ratio", "software_stiffness"]
"""The design variables each joint has (the threshold and approach velocity are one for the arm)."""
PER_JOINT_VARIABLES: tuple[PerJointVariable, ...] = get_args(PerJointVariable)

ModuleVariable = Literal["stator_diameter", "stack_length", "gear_ratio"]
"""The per-joint variables that make an actuator: the joints of one module share them."""
MODULE_VARIABLES: tuple[ModuleVariable, ...] = get_args(ModuleVariable)

GlobalVariable = Literal["threshold", "approach_velocity"]
"""The design variables the whole arm shares."""
GLOBAL_VARIABLES: tuple[GlobalVariable, ...] = get_args(GlobalVariable)

ExportFormat = Literal["urdf", "mjcf"]
"""The robot formats a design is exported to."""
EXPORT_FORMATS: tuple[ExportFormat, ...] = get_args(ExportFormat)

DesignChoice = Literal["catalogue", "recommended", "chosen"]
"""A run's designs named by word: the design built from catalogue parts (the recommended design snapped to the
catalogues), the recommended design and the single-objective optimum as solved."""
DESIGN_CHOICES: tuple[DesignChoice, ...] = get_args(DesignChoice)

TIME_COLUMN_NAMES: tuple[str, ...] = ("time", "t")
"""The names a CSV file's time column may have (force traces, duty cycles), compared without case."""
