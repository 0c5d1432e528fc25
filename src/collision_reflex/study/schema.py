"""The study-file schema (pydantic v2): what a design study may say, with units, defaults and checks.

Two kinds of study share most sections:

- ``kind: arm`` (the default): actuators for every joint of a robot arm (example-robot-data or URDF), evaluated
  over sampled configurations and contact directions, optimised by :mod:`collision_reflex.optimize`;
- ``kind: actuator``: single-joint actuators (e.g. direct-drive against geared) compared in a 1D collision at a
  lever, over a range of approach velocities.

The sections are in their own modules (:mod:`.actuator_specs`, :mod:`.sample_specs`, :mod:`.motion_specs`,
:mod:`.design_specs`, :mod:`.run_specs`); here are the robot and the two kinds of study. Every model forbids
unknown keys. Quantities are floats in SI units once validated (see :mod:`.quantities`);
``model_dump(mode="json")`` gives the *resolved* study with every default explicit.
"""

from __future__ import annotations

from typing import Annotated, Any, Literal

from pydantic import BaseModel, Field, WithJsonSchema, field_validator, model_validator

from ..vocabulary import OBJECTIVE_NAMES, ObjectiveName, Placement, ReactionMode
from .actuator_specs import ActuatorsSpec, GearboxSpec, MotorSpec, PlacementRuleSpec, SensingSpec
from .design_specs import ConstraintsSpec, DesignSpec, Weight
from .motion_specs import DutyCycleSpec, RatingSpec
from .quantities import (
    ApproachVelocity,
    ContactStiffness,
    GearRatio,
    JointStiffness,
    Lever,
    Offset,
    PartMass,
)
from .run_specs import CatalogueSpec, ExecutionSpec, OptimizerSpec, OutputsSpec, ParetoSpec, SimulateSpec
from .sample_specs import SamplesSpec
from .spec_base import Name, Spec, exactly_one


class RobotSpec(Spec):
    """The arm: an example-robot-data model or a URDF, and where it touches the world."""

    example_robot_data: str | None = Field(
        None, description="name of an example-robot-data model, e.g. 'ur5'"
    )
    urdf: str | None = Field(None, description="URDF file, relative to the study file")
    package_dirs: list[str] = Field(
        default_factory=list, description="directories to resolve package:// URIs"
    )
    contact_frame: str | None = Field(
        None, description="frame of the contact point (default: the robot's tip)"
    )
    contact_offset: tuple[Offset, Offset, Offset] | None = Field(
        None,
        description="contact point in the contact frame [m]; null: the robot's default with its default frame "
        "(the double pendulum's tip, 0.2 m along its second link), else the frame's origin",
    )
    locked_joints: list[str] = Field(default_factory=list, description="joints held fixed (not actuated)")

    @field_validator("locked_joints")
    @classmethod
    def _distinct_joints(cls, value: list[str]) -> list[str]:
        twice = sorted({name for name in value if value.count(name) > 1})
        if twice:
            raise ValueError(f"each joint once (found {', '.join(map(repr, twice))} more than once)")
        return value

    @model_validator(mode="after")
    def _one_source(self) -> RobotSpec:
        exactly_one(self, ("example_robot_data", "urdf"), "the robot")
        return self


class ArmStudy(Spec):
    """A design study of the actuators of a robot arm."""

    kind: Literal["arm"] = "arm"
    name: Name = Field(description="the study's name; names the output folder")
    description: str = ""
    robot: RobotSpec
    actuators: ActuatorsSpec
    sensing: SensingSpec
    approach_velocity: ApproachVelocity = Field(gt=0, description="approach velocity [m/s]")
    reaction: ReactionMode = "at_rest"
    reflected_inertia_in: Placement | PlacementRuleSpec = Field(
        "robot",
        description="where N^2 J_m acts: 'robot' (behind the joint springs, the paper's arm model), 'finger' "
        "(also rigidly in the finger mass: a stiff transmission with the compliance at the contact), or "
        "{contact_stiffness: ...}: per joint from its transmission's stiffness against that contact's",
    )
    samples: SamplesSpec
    duty_cycle: DutyCycleSpec | None = Field(
        None,
        description="the motion the arm must make; null: the torque requirement is static (gravity only)",
    )
    rating: RatingSpec = Field(default_factory=RatingSpec)  # type: ignore[arg-type]
    design: DesignSpec = Field(default_factory=DesignSpec)
    objective: Annotated[
        dict[ObjectiveName, Weight],
        WithJsonSchema(
            {
                "anyOf": [
                    {"enum": list(OBJECTIVE_NAMES)},
                    {
                        "type": "object",
                        "propertyNames": {"enum": list(OBJECTIVE_NAMES)},
                        "additionalProperties": {"type": "number", "exclusiveMinimum": 0},
                        "minProperties": 1,
                    },
                ],
                "description": "an objective name, or a weighted sum {name: weight}",
            }
        ),
    ] = Field(default_factory=lambda: {"worst_case_impulse": 1.0}, min_length=1)  # type: ignore[arg-type]
    constraints: ConstraintsSpec = Field(default_factory=ConstraintsSpec)  # type: ignore[arg-type]
    pareto: ParetoSpec | None = None
    optimizer: OptimizerSpec = Field(default_factory=OptimizerSpec)  # type: ignore[arg-type]
    catalogue: CatalogueSpec = Field(default_factory=CatalogueSpec)  # type: ignore[arg-type]
    outputs: OutputsSpec = Field(default_factory=OutputsSpec)  # type: ignore[arg-type]
    execution: ExecutionSpec = Field(default_factory=ExecutionSpec)  # type: ignore[arg-type]
    simulate: SimulateSpec | None = Field(
        None, description="simulate the recommended design in the time domain; null: no simulation"
    )

    @field_validator("objective", mode="before")
    @classmethod
    def _single(cls, value: Any) -> Any:
        # ``objective: worst_case_impulse`` is a weighted sum with one term.
        return {value: 1.0} if isinstance(value, str) else value


class ActuatorCandidate(Spec):
    """One single-joint actuator of an actuator study."""

    motor: MotorSpec
    gearbox: GearboxSpec | None = None
    gearbox_inertia: bool = False
    gear_ratio: GearRatio = 1.0
    mechanical_stiffness: JointStiffness = Field(gt=0)
    software_stiffness: JointStiffness = Field(gt=0)
    reflected_inertia_in: Placement = Field(
        "robot",
        description="'finger': N^2 J_m also in the impact (a stiff transmission, like the paper's A8)",
    )
    sensing: SensingSpec | None = Field(None, description="overrides the study's sensing for this actuator")


class LoadSpec(Spec):
    """What the actuator drives: a link of given lever, whose structure mass is seen at the contact."""

    lever: Lever = Field(gt=0, description="distance from the joint axis to the contact [m]")
    finger_mass: PartMass = Field(gt=0, description="structure (sprung) mass seen at the contact [kg]")
    contact_stiffness: ContactStiffness | None = Field(
        None, gt=0, description="stiffness of the object hit [N/m], in series with the joint; null: rigid"
    )


class VelocityRange(Spec):
    """Approach velocities [m/s]: ``count`` values from ``min`` to ``max``, evenly spaced in log scale."""

    min: ApproachVelocity = Field(gt=0)
    max: ApproachVelocity = Field(gt=0)
    count: Annotated[int, Field(ge=2, le=10000, strict=True)] = 50

    @model_validator(mode="after")
    def _ordered(self) -> VelocityRange:
        if self.min >= self.max:
            raise ValueError(f"min < max (min = {self.min:g} m/s, max = {self.max:g} m/s)")
        return self


class ActuatorStudy(Spec):
    """Single-joint actuators compared in a 1D collision at a lever.

    For example the paper's direct-drive U8 against the geared A8.
    """

    kind: Literal["actuator"]
    name: Name
    description: str = ""
    load: LoadSpec
    actuators: dict[Name, ActuatorCandidate] = Field(min_length=1)
    sensing: SensingSpec
    approach_velocity: ApproachVelocity = Field(gt=0, description="approach velocity of the tables [m/s]")
    velocities: VelocityRange
    reaction: ReactionMode = "at_rest"
    outputs: OutputsSpec = Field(default_factory=OutputsSpec)  # type: ignore[arg-type]


Study = ArmStudy | ActuatorStudy
STUDY_KINDS: dict[str, type[BaseModel]] = {"arm": ArmStudy, "actuator": ActuatorStudy}
