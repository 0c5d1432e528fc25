"""The optimisation problem an arm study poses: its design variables, objectives and constraints."""

from __future__ import annotations

from typing import Annotated, Any

from pydantic import Field, model_validator

from .quantities import (
    ApproachVelocity,
    GearRatio,
    JointStiffness,
    JointTorque,
    NoiseFloor,
    PartSize,
    Payload,
    PositionError,
    SafetyFactor,
    ThresholdForce,
)
from .spec_base import Spec

# Objective weights: a ratio of 1e6 between two terms already makes the smaller one vanish.
Weight = Annotated[float, Field(gt=0, le=1e6, allow_inf_nan=False)]


def _variable_model(name: str, quantity: Any, doc: str) -> type[Spec]:
    """A model for a design variable: ``{min, max}`` (free), ``{value}`` (fixed) or a bare value (fixed).

    Named ``<name>Bounds``, the module-level name it is bound to (so that a study pickles).
    """

    class Bound(Spec):
        min: quantity | None = Field(None, gt=0)
        max: quantity | None = Field(None, gt=0)
        value: quantity | None = Field(None, gt=0)

        @model_validator(mode="before")
        @classmethod
        def _bare_value(cls, value: Any) -> Any:
            return {"value": value} if not isinstance(value, dict) else value

        @model_validator(mode="after")
        def _bounds(self) -> Any:
            if self.value is not None:
                if self.min is not None or self.max is not None:
                    raise ValueError("either {min, max} (a free variable) or {value} (fixed), not both")
            elif self.min is None or self.max is None:
                raise ValueError("both min and max (a free variable), or value (fixed)")
            elif self.min > self.max:
                raise ValueError(
                    f"min <= max (min = {self.min:g}, max = {self.max:g} in SI units): swap them"
                )
            return self

        @property
        def bounds(self) -> tuple[float, float]:
            """``(lower, upper)`` in SI units (equal when fixed)."""
            if self.value is not None:
                return (self.value, self.value)
            assert self.min is not None and self.max is not None  # guaranteed by _bounds
            return (self.min, self.max)

        @property
        def free(self) -> bool:
            """Whether the optimiser may change it (its bounds differ)."""
            lower, upper = self.bounds
            return bool(lower < upper)

    Bound.__name__ = Bound.__qualname__ = f"{name}Bounds"
    Bound.__doc__ = doc
    return Bound


def _per_joint(name: str, bound: type[Spec], doc: str) -> type[Spec]:
    """A per-joint design variable: bounds for every joint, ``joints`` overriding them for named joints."""

    class PerJoint(bound):  # type: ignore[misc,valid-type]
        joints: dict[str, bound] = Field(default_factory=dict)  # type: ignore[valid-type]

        @model_validator(mode="before")
        @classmethod
        def _bare_value(cls, value: Any) -> Any:
            return {"value": value} if not isinstance(value, dict) else value

    PerJoint.__name__ = PerJoint.__qualname__ = name
    PerJoint.__doc__ = doc
    return PerJoint


StatorDiameterBounds = _variable_model("StatorDiameter", PartSize, "motor stator diameter [m]")
StackLengthBounds = _variable_model("StackLength", PartSize, "motor stack length [m]")
GearRatioBounds = _variable_model("GearRatio", GearRatio, "gear ratio [-], >= 1")
SoftwareStiffnessBounds = _variable_model("SoftwareStiffness", JointStiffness, "software stiffness [N m/rad]")
StatorDiameterVariable = _per_joint(
    "StatorDiameterVariable", StatorDiameterBounds, "motor stator diameter [m]"
)
StackLengthVariable = _per_joint("StackLengthVariable", StackLengthBounds, "motor stack length [m]")
GearRatioVariable = _per_joint("GearRatioVariable", GearRatioBounds, "gear ratio [-], >= 1")
SoftwareStiffnessVariable = _per_joint(
    "SoftwareStiffnessVariable", SoftwareStiffnessBounds, "software stiffness [N m/rad]"
)
ThresholdVariableBounds = _variable_model("ThresholdVariable", ThresholdForce, "contact-force threshold [N]")
PositionErrorVariableBounds = _variable_model(
    "PositionErrorVariable", PositionError, "position-error threshold [m]"
)
VelocityVariableBounds = _variable_model("VelocityVariable", ApproachVelocity, "approach velocity [m/s]")


class DesignSpec(Spec):
    """Design variables the optimiser may change.

    Any not listed keeps the value of its section (``actuators``, ``sensing``, ``approach_velocity``).
    Per-joint variables take ``joints: {name: {...}}``.
    """

    stator_diameter: StatorDiameterVariable | None = None  # type: ignore[valid-type]
    stack_length: StackLengthVariable | None = None  # type: ignore[valid-type]
    gear_ratio: GearRatioVariable | None = None  # type: ignore[valid-type]
    software_stiffness: SoftwareStiffnessVariable | None = None  # type: ignore[valid-type]
    threshold: ThresholdVariableBounds | None = None  # type: ignore[valid-type]
    position_error: PositionErrorVariableBounds | None = None  # type: ignore[valid-type]
    approach_velocity: VelocityVariableBounds | None = None  # type: ignore[valid-type]


class ConstraintsSpec(Spec):
    """Design constraints: payload [kg], torque safety factor, threshold noise floor [N], torques [N m], a body region."""

    payload: Payload = Field(
        0.0,
        ge=0,
        description="mass carried at the contact point [kg], a point mass (also over a duty cycle); or "
        "duty_cycle.payload with its inertia, not both",
    )
    safety_factor: SafetyFactor = Field(
        1.0, ge=1, description="peak torque >= safety_factor x required torque"
    )
    threshold_floor: NoiseFloor = Field(0.0, ge=0, description="sensing noise floor [N]")
    torque_required: list[JointTorque] | None = Field(
        None, description="required torque per joint [N m]; null: gravity (+ payload) over the samples"
    )
    body_region: str | None = Field(
        None,
        description="an ISO/TS 15066 body region (crx safety --list-regions) whose transient-force limit the "
        "approach keeps at every contact sample, the rotors counted on the links (arm studies)",
    )
