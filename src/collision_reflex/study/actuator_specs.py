"""The actuator sections of a study file: motors, gearboxes, each joint's actuator, and how contact is sensed.

Gearboxes are named from the packaged catalogue (``designs/gearboxes.yaml``), given by their figures, or scaled
from a catalogue unit; ``direct_drive`` is one of several gearbox options a run chooses among.
"""

from __future__ import annotations

import difflib
from typing import Annotated, Any

from pydantic import Field, field_validator, model_validator

from ..hardware.gearboxes import load_gearbox_catalogue
from ..vocabulary import GearboxKind, Placement, ScalingLawName, SensingScheme
from .quantities import (
    AngularSpeed,
    ContactStiffness,
    GearRatio,
    JointStiffness,
    JointTorque,
    MotorTorque,
    PartInertia,
    PartMass,
    PartSize,
    PositionError,
    ThresholdForce,
)
from .spec_base import PositiveInt, Spec

DEFAULT_REFERENCE_MOTOR = "OPN-060-013-A"


class MotorSpec(Spec):
    """A motor: a catalogue motor as it is, or scaled to another stator diameter (and stack length)."""

    reference: str = Field(DEFAULT_REFERENCE_MOTOR, description="catalogue name of the (reference) motor")
    scaling_law: ScalingLawName = "haddadin"
    stator_diameter: PartSize | None = Field(
        None, gt=0, description="scaled stator diameter [m]; null: reference's"
    )
    stack_length: PartSize | None = Field(
        None, gt=0, description="scaled stack length [m]; null: reference's"
    )

    @classmethod
    def __get_pydantic_json_schema__(cls, core_schema: Any, handler: Any) -> Any:
        # The shorthand: a catalogue name alone.
        return {"anyOf": [{"type": "string", "description": "catalogue name"}, handler(core_schema)]}

    @model_validator(mode="before")
    @classmethod
    def _catalogue_name(cls, value: Any) -> Any:
        # ``motor: "T-motor U8"`` is shorthand for an unscaled catalogue motor.
        return {"reference": value} if isinstance(value, str) else value


# A gearbox's input speed: from a slow hand crank (1e-3 rad/s) to beyond the fastest spindles (1e5 rad/s).


class GearboxSpec(Spec):
    """A gearbox with the figures of a real unit (its datasheet): mass and inertia enter the actuator.

    In an arm study the optional ``name``, ``peak_torque``, ``efficiency`` and ``max_input_speed`` complete it
    as a joint's gearbox (default: a name from its kind, the rated torque as peak, lossless, no speed limit);
    its ratios are the design's gear-ratio bounds.
    """

    kind: GearboxKind
    stages: PositiveInt = 1
    diameter: PartSize = Field(gt=0, description="outer diameter [m]")
    length: PartSize = Field(gt=0, description="length [m]")
    mass: PartMass = Field(gt=0, description="mass [kg]")
    inertia: PartInertia = Field(gt=0, description="inertia at the input shaft [kg m^2]")
    rated_torque: JointTorque = Field(gt=0, description="rated output torque [N m]")
    source: str = Field("", description="where the figures come from")
    name: str | None = Field(None, min_length=1, description="what reports call it (arm studies)")
    peak_torque: JointTorque | None = Field(
        None, gt=0, description="repeated peak output torque [N m]; null: the rated torque (arm studies)"
    )
    efficiency: float | None = Field(
        None, gt=0, le=1, description="efficiency (0, 1] [-]; null: 1 (arm studies)"
    )
    max_input_speed: AngularSpeed | None = Field(
        None, gt=0, description="maximum input speed [rad/s]; null: none (arm studies)"
    )


DIRECT_DRIVE = "direct_drive"
"""The gearbox option of no gearbox: the motor drives the joint at N = 1."""


def _catalogue_gearbox(value: Any) -> Any:
    """A gearbox name must be one of the packaged catalogue's (figures are checked by :class:`GearboxSpec`)."""
    if not isinstance(value, str):
        return value
    if value == DIRECT_DRIVE:
        raise ValueError(
            "a gearbox: direct_drive is one of several options (gearbox: [direct_drive, ...]); for direct drive "
            "alone write gearbox: null and gear_ratio: 1"
        )
    names = sorted(load_gearbox_catalogue())
    if value not in names:
        close = difflib.get_close_matches(value, names, n=1)
        raise ValueError(
            "a gearbox of the catalogue (designs/gearboxes.yaml): "
            + (f"{close[0]!r}? " if close else "")
            + "one of "
            + ", ".join(map(repr, names))
            + ", or the gearbox's figures"
        )
    return value


class ScaledGearboxSpec(Spec):
    """A gearbox of a catalogue unit's kind, sized by its kind's scaling law to carry the motor's peak torque.

    Its mass enters the actuator mass, its input inertia ``N^2 J_g`` the reflected inertia, its efficiency the
    driving torque (:class:`collision_reflex.hardware.gearboxes.ScaledGearbox`). The design relaxes ``ratios``
    to the range between the first and the last; its catalogue design picks a catalogue unit of the kind at a
    ratio it is sold with.
    """

    scaled_from: str = Field(description="the catalogue gearbox (designs/gearboxes.yaml) scaled from")
    ratios: list[GearRatio] | None = Field(
        None, min_length=1, description="ratios the kind is sold with [-]; null: the reference's own"
    )

    _known_gearbox = field_validator("scaled_from")(_catalogue_gearbox)


class JointActuatorSpec(Spec):
    """Per-joint overrides of the actuator defaults (every field optional)."""

    motor: MotorSpec | None = None
    gearbox: str | GearboxSpec | ScaledGearboxSpec | None = Field(
        None,
        description="catalogue name (designs/gearboxes.yaml), a gearbox's figures or {scaled_from: name}; null: "
        "the default",
    )
    gear_ratio: GearRatio | None = None
    mechanical_stiffness: JointStiffness | None = Field(None, gt=0)
    software_stiffness: JointStiffness | None = Field(None, gt=0)
    reflected_inertia_in: Placement | None = Field(
        None, description="this joint's rotor placement in the impact; null: the study's reflected_inertia_in"
    )

    _known_gearbox = field_validator("gearbox")(_catalogue_gearbox)


class ActuatorsSpec(Spec):
    """The actuator of every joint; ``joints`` overrides fields for named joints."""

    motor: MotorSpec = Field(default_factory=MotorSpec)  # type: ignore[arg-type]
    gearbox: (
        str
        | GearboxSpec
        | ScaledGearboxSpec
        | Annotated[list[str | GearboxSpec | ScaledGearboxSpec], Field(min_length=2, max_length=4)]
        | None
    ) = Field(
        None,
        description="every joint's gearbox: a catalogue name (designs/gearboxes.yaml), a gearbox's figures, or "
        "{scaled_from: name, ratios: [...]} (sized to its motor); a list of 2 to 4 of these, or direct_drive "
        "(no gearbox, N = 1): the run chooses one per module (or joint) by the study's objective; null: none "
        "(the gear ratio alone)",
    )
    gearbox_inertia: bool = Field(
        True,
        description="add the gearbox's input inertia to the reflected inertia; false: the paper's choice",
    )
    gear_ratio: GearRatio = 1.0
    mechanical_stiffness: JointStiffness = Field(gt=0, description="joint mechanical stiffness [N m/rad]")
    software_stiffness: JointStiffness = Field(gt=0, description="joint controller stiffness [N m/rad]")
    joints: dict[str, JointActuatorSpec] = Field(default_factory=dict)
    modules: list[list[str]] = Field(
        default_factory=list,
        description="groups of joints built from one actuator module (one motor, gearbox and gear ratio, sized "
        "for the most demanding of them), e.g. [[wrist_1_joint, wrist_2_joint, wrist_3_joint]]",
    )

    @field_validator("gearbox")
    @classmethod
    def _known_gearboxes(cls, value: Any) -> Any:
        if not isinstance(value, list):
            return _catalogue_gearbox(value)
        if len(set(map(repr, value))) < len(value):
            raise ValueError("gearbox options that differ: one of them is listed twice")
        for option in value:
            if option != DIRECT_DRIVE:
                _catalogue_gearbox(option)
        return value


class PlacementRuleSpec(Spec):
    """Each joint's rotor placement from its transmission's stiffness against the contact's, seen at the joint.

    ``finger`` where the joint's mechanical stiffness is at least 10 times the contact stiffness times the
    joint's squared moment arm along the contact direction (median over the samples), ``robot`` elsewhere.
    """

    contact_stiffness: ContactStiffness = Field(gt=0, description="stiffness of the object hit [N/m]")


# --- sensing -----------------------------------------------------------------------------------------------------


class SensingSpec(Spec):
    """How contact is detected (the model's sensing schemes).

    A contact-force threshold, a position-error threshold (``F_s = k e``) or a motor-current threshold
    (joint-side threshold torque ``N tau_s``).
    """

    scheme: SensingScheme
    threshold: ThresholdForce | None = Field(
        None, gt=0, description="contact-force threshold [N] (scheme: force)"
    )
    error: PositionError | None = Field(
        None, gt=0, description="position-error threshold [m] (scheme: position)"
    )
    motor_torque: MotorTorque | None = Field(
        None, gt=0, description="motor-side torque threshold [N m] (scheme: current)"
    )

    @model_validator(mode="after")
    def _matches_scheme(self) -> SensingSpec:
        needed = {"force": "threshold", "position": "error", "current": "motor_torque"}[self.scheme]
        given = [name for name in ("threshold", "error", "motor_torque") if getattr(self, name) is not None]
        if given != [needed]:
            raise ValueError(
                f"the {self.scheme} scheme takes exactly `{needed}` (found {', '.join(given) or 'none'})"
            )
        return self

    @property
    def value(self) -> float:
        """The threshold in SI: [N], [m] or [N m] by scheme."""
        value = {"force": self.threshold, "position": self.error, "current": self.motor_torque}[self.scheme]
        if value is None:  # pragma: no cover - excluded by _matches_scheme
            raise ValueError(f"no threshold for the {self.scheme} scheme")
        return float(value)
