"""The study-file schema (pydantic v2): what a design study may say, with units, defaults and checks.

Two kinds of study share most sections:

- ``kind: arm`` (the default): actuators for every joint of a robot arm (example-robot-data or URDF), evaluated
  over sampled configurations and contact directions, optimised by :mod:`collision_reflex.optimize`;
- ``kind: actuator``: single-joint actuators (e.g. direct-drive against geared) compared in a 1D collision at a
  lever, over a range of approach velocities.

Every model forbids unknown keys. Quantities are floats in SI units once validated (see :mod:`.quantities`);
``model_dump(mode="json")`` gives the *resolved* study with every default explicit.
"""

from __future__ import annotations

import builtins
import difflib
import itertools
import re
from typing import Annotated, Any, Literal

from pydantic import (
    BaseModel,
    BeforeValidator,
    ConfigDict,
    Field,
    WithJsonSchema,
    field_validator,
    model_validator,
)
from pydantic_core import PydanticCustomError

from .quantities import (
    ApproachVelocity,
    ContactStiffness,
    GearRatio,
    JointPosition,
    JointStiffness,
    JointTorque,
    Lever,
    MotorTorque,
    NoiseFloor,
    Offset,
    PartInertia,
    PartMass,
    PartSize,
    Payload,
    PositionError,
    SafetyFactor,
    SingularValueFloor,
    ThresholdForce,
    quantity_type,
    to_si,
)

OBJECTIVE_NAMES = ("worst_case_impulse", "mean_impulse", "cvar_impulse", "actuator_mass", "approach_velocity")
ObjectiveName = Literal[
    "worst_case_impulse", "mean_impulse", "cvar_impulse", "actuator_mass", "approach_velocity"
]
SCALING_LAW_NAMES = ("haddadin", "isometric", "empirical", "quadruped")
GEARBOX_KINDS = ("planetary", "parallel_shaft", "harmonic", "cycloidal", "ball_screw")
GearboxKind = Literal["planetary", "parallel_shaft", "harmonic", "cycloidal", "ball_screw"]
NAMED_DIRECTIONS = ("+x", "-x", "+y", "-y", "+z", "-z")
DEFAULT_REFERENCE_MOTOR = "OPN-060-013-A"

PositiveInt = Annotated[int, Field(ge=1, strict=True)]
# Sample counts: a run evaluates every configuration in every direction, so more than these would take days;
# the bounds also keep a validation from allocating what the file merely names.
ConfigurationCount = Annotated[int, Field(ge=1, le=10_000, strict=True)]
DirectionCount = Annotated[int, Field(ge=1, le=10_000, strict=True)]
# A direction's components before normalisation: a bound keeps their squares finite.
Component = Annotated[float, Field(ge=-1e6, le=1e6, allow_inf_nan=False)]
Name = Annotated[str, Field(pattern=r"^[A-Za-z0-9][A-Za-z0-9._-]*$", max_length=80)]


class _Model(BaseModel):
    # defer_build: a model's validator is built on its first use, not at import (a cost every start would pay).
    model_config = ConfigDict(extra="forbid", frozen=True, validate_default=True, defer_build=True)


def _exactly_one(model: BaseModel, names: tuple[str, ...], what: str) -> None:
    given = [name for name in names if getattr(model, name) is not None]
    if len(given) != 1:
        found = "none of them" if not given else " and ".join(given)
        raise ValueError(f"exactly one of {', '.join(names)} for {what} (found {found})")


# --- robot -------------------------------------------------------------------------------------------------------


class RobotSpec(_Model):
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
        _exactly_one(self, ("example_robot_data", "urdf"), "the robot")
        return self


# --- actuators ---------------------------------------------------------------------------------------------------


class MotorSpec(_Model):
    """A motor: a catalogue motor as it is, or scaled to another stator diameter (and stack length)."""

    reference: str = Field(DEFAULT_REFERENCE_MOTOR, description="catalogue name of the (reference) motor")
    scaling_law: Literal["haddadin", "isometric", "empirical", "quadruped"] = "haddadin"
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
AngularSpeed = quantity_type("rad/s", "an angular speed", "3000 rpm", 1e-3, 1e5)


class GearboxSpec(_Model):
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
    max_input_speed: AngularSpeed | None = Field(  # type: ignore[valid-type]
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
    from ..hardware.gearboxes import load_gearbox_catalogue

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


class ScaledGearboxSpec(_Model):
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


class JointActuatorSpec(_Model):
    """Per-joint overrides of the actuator defaults (every field optional)."""

    motor: MotorSpec | None = None
    gearbox: str | GearboxSpec | ScaledGearboxSpec | None = Field(
        None,
        description="catalogue name (designs/gearboxes.yaml), a gearbox's figures or {scaled_from: name}; null: "
        "the default",
    )
    gear_ratio: GearRatio | None = Field(None, ge=1)
    mechanical_stiffness: JointStiffness | None = Field(None, gt=0)
    software_stiffness: JointStiffness | None = Field(None, gt=0)
    reflected_inertia_in: Literal["robot", "finger"] | None = Field(
        None, description="this joint's rotor placement in the impact; null: the study's reflected_inertia_in"
    )

    _known_gearbox = field_validator("gearbox")(_catalogue_gearbox)


class ActuatorsSpec(_Model):
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
    gear_ratio: GearRatio = Field(1.0, ge=1)
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


class PlacementRuleSpec(_Model):
    """Each joint's rotor placement from its transmission's stiffness against the contact's, seen at the joint.

    ``finger`` where the joint's mechanical stiffness is at least 10 times the contact stiffness times the
    joint's squared moment arm along the contact direction (median over the samples), ``robot`` elsewhere.
    """

    contact_stiffness: ContactStiffness = Field(gt=0, description="stiffness of the object hit [N/m]")


# --- sensing -----------------------------------------------------------------------------------------------------


class SensingSpec(_Model):
    """How contact is detected (the model's sensing schemes).

    A contact-force threshold, a position-error threshold (``F_s = k e``) or a motor-current threshold
    (joint-side threshold torque ``N tau_s``).
    """

    scheme: Literal["force", "position", "current"]
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


# --- samples -----------------------------------------------------------------------------------------------------


class RandomConfigurations(_Model):
    """Configurations drawn at random within the joint limits."""

    count: ConfigurationCount = Field(
        description="number of configurations drawn uniformly within joint limits"
    )
    seed: int = Field(0, ge=0, lt=2**64, strict=True, description="seed of the numpy Generator (>= 0)")


class TrajectorySpec(_Model):
    """Configurations read from a trajectory file (joint positions [rad])."""

    file: str = Field(description="CSV of joint positions [rad], one row per time step, one column per joint")
    every: Annotated[int, Field(ge=1, le=1_000_000, strict=True)] = Field(1, description="use every n-th row")


class ConfigurationSamples(_Model):
    """Exactly one of ``random``, ``list`` or ``trajectory``."""

    random: RandomConfigurations | None = None
    list: builtins.list[builtins.list[JointPosition]] | None = Field(
        None, min_length=1, description="configurations [rad]"
    )
    trajectory: TrajectorySpec | None = None

    @model_validator(mode="after")
    def _one(self) -> ConfigurationSamples:
        _exactly_one(self, ("random", "list", "trajectory"), "configurations")
        return self


class DirectionSamples(_Model):
    """The contact directions: exactly one of ``circle``, ``sphere``, ``named`` or ``list``.

    ``circle``: n directions in the plane (the arm's plane, or the world x-y plane); ``sphere``: n directions
    spread evenly over the sphere; ``named`` or ``list``: vectors, normalised.
    """

    circle: DirectionCount | None = None
    sphere: DirectionCount | None = None
    named: builtins.list[Literal["+x", "-x", "+y", "-y", "+z", "-z"]] | None = Field(None, min_length=1)
    list: builtins.list[builtins.list[Component]] | None = Field(None, min_length=1)

    @model_validator(mode="after")
    def _one(self) -> DirectionSamples:
        _exactly_one(self, ("circle", "sphere", "named", "list"), "directions")
        for index, vector in enumerate(self.list or []):
            if not 2 <= len(vector) <= 3 or not any(vector) or not all(abs(x) < 1e300 for x in vector):
                raise ValueError(f"directions.list[{index}]: a non-zero finite vector of 2 or 3 components")
        return self


class DomainSpec(_Model):
    """Where contacts are considered: the domain a worst case is taken over.

    Configurations within the joint limits whose contact Jacobian has ``sigma_min(J_v)`` at least
    ``min_singular_value``, and directions along which the guarded move at the approach velocity stays within
    the joint speed limits (``J_v^+ u v0``). Random configurations are drawn in it.
    """

    min_singular_value: SingularValueFloor | None = Field(
        None,
        description="floor on the smallest singular value of the contact Jacobian [m]; null: a tenth of the "
        "arm's reach (the largest base-to-contact distance); 0: no floor (near singular poses the finger mass, "
        "and so the worst case, is unbounded)",
    )
    joint_speed_limit: JointSpeed | None = Field(  # type: ignore[valid-type]
        None,
        description="joint speed limits of the guarded move [rad/s], one for all or by joint name; null: the "
        "URDF's velocity limits (a joint without one is not limited)",
    )


class SamplesSpec(_Model):
    """The contact samples: arm configurations crossed with contact directions, within the contact domain."""

    configurations: ConfigurationSamples
    directions: DirectionSamples
    domain: DomainSpec = Field(default_factory=DomainSpec)  # type: ignore[arg-type]
    error_tolerance: Annotated[float, Field(gt=0, le=1, allow_inf_nan=False)] = Field(
        0.02,
        description="largest relative sampling error (99 % bootstrap interval) of a mean impulse objective "
        "before the report warns and names the configurations that would meet it",
    )
    fresh: Annotated[int, Field(ge=0, le=65_536, strict=True)] = Field(
        4096,
        description="configurations drawn afresh in the contact domain (an independent stream of the random "
        "configurations' seed, with the study's directions) on which every reported design is checked after "
        "the solves: its largest impulse against its worst case, its mean and high quantile with their "
        "sampling errors; 0: no check (random configurations only)",
    )


# --- duty cycle --------------------------------------------------------------------------------------------------

# Sampling rates of a via-point motion: 1 Hz to 10 kHz (a servo loop's rate).
Rate = quantity_type("Hz", "a sampling rate", "500 Hz", 1.0, 1e4)


def _quantities(unit: str, what: str, example: str, collection: type, minimum: str, maximum: float) -> Any:
    """A quantity for every item (a number or a string with units), or a ``collection`` of them, in ``unit``.

    ``collection`` is ``dict`` (by joint name) or ``list`` (one per item); ``minimum`` is ``"> 0"`` or
    ``">= 0"``; ``maximum`` [``unit``] the largest physical value. One validator for both forms, so that a bad
    value gives one located problem.
    """

    def one(value: Any) -> float:
        number = to_si(value, unit, what, example, (-maximum, maximum))
        if not (number > 0 or (minimum == ">= 0" and number == 0)):
            raise PydanticCustomError(
                "quantity", "{expected}", {"expected": f"{what} {minimum} (found {number:g})"}
            )
        return number

    def validate(value: Any) -> Any:
        if isinstance(value, dict) and collection is dict:
            return {str(key): one(item) for key, item in value.items()}
        if isinstance(value, list) and collection is list:
            return [one(item) for item in value]
        return one(value)

    bound = "exclusiveMinimum" if minimum == "> 0" else "minimum"
    quantity = {"anyOf": [{"type": "number", bound: 0, "maximum": maximum}, {"type": "string"}]}
    many = (
        {"type": "object", "additionalProperties": quantity}
        if collection is dict
        else {"type": "array", "items": quantity}
    )
    form = "a mapping by joint name naming every joint" if collection is dict else "a list, one per via point"
    return Annotated[
        (float | dict[str, float]) if collection is dict else (float | list[float]),
        BeforeValidator(validate),
        WithJsonSchema(
            {
                "anyOf": [quantity, many],
                "description": f"{what} [{unit}] {minimum}, e.g. {example!r}: one for all, or {form}",
            }
        ),
    ]


# Limits a joint could physically reach (1000 rad/s is ~10,000 rpm at the output; 1e6 rad/s^2 ~ 100 g at 0.01
# m), and an hour at rest: beyond these a duty cycle is a typing error.
JointSpeed = _quantities("rad/s", "a joint speed (m/s for a prismatic joint)", "90 deg/s", dict, "> 0", 1e3)
JointAcceleration = _quantities(
    "rad/s^2", "a joint acceleration (m/s^2 for a prismatic joint)", "300 deg/s^2", dict, "> 0", 1e6
)
Dwell = _quantities("s", "a time at rest", "0.5 s", list, ">= 0", 3600.0)
DEFAULT_DWELL = 0.0
DEFAULT_RATE = 1000.0
_VIA_ONLY = ("max_speed", "max_acceleration", "dwell", "rate")


class PayloadSpec(_Model):
    """The payload the arm carries over its duty cycle, its centre of mass at the contact point."""

    mass: PartMass = Field(gt=0, description="payload mass [kg]")
    inertia: tuple[
        tuple[PartInertia, PartInertia, PartInertia],
        tuple[PartInertia, PartInertia, PartInertia],
        tuple[PartInertia, PartInertia, PartInertia],
    ] = Field(
        ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0), (0.0, 0.0, 0.0)),
        description="3x3 inertia about the centre of mass, contact-frame axes [kg m^2]; default a point mass",
    )

    @model_validator(mode="after")
    def _physical(self) -> PayloadSpec:
        from ..arm.duty_cycle import Payload
        from ..errors import InvalidParameter

        try:
            Payload(self.mass, self.inertia)  # type: ignore[arg-type]
        except InvalidParameter as error:
            raise ValueError(f"payload {error.name}: {error.allowed}") from None
        return self


class DutyCycleSpec(_Model):
    """The motion the arm must make: a trajectory file, or a motion through via configurations.

    ``file``: a CSV with a time column and one position column per joint (named by the joint, units in the
    header, e.g. ``time [s]``, ``shoulder [deg]``), relative to the study file; columns of other names are
    ignored. ``via``: configurations [rad] passed through at rest, joined by synchronised trapezoidal profiles
    within ``max_speed`` and ``max_acceleration`` (one value for every joint, or a mapping by joint name), with
    ``dwell`` at each via point and sampled at ``rate``.
    """

    file: str | None = Field(None, description="trajectory CSV, relative to the study file")
    via: builtins.list[builtins.list[JointPosition]] | None = Field(
        None, min_length=2, description="via configurations [rad], one position per joint, at least 2"
    )
    max_speed: JointSpeed | None = Field(  # type: ignore[valid-type]
        None, description="joint speed limit [rad/s] (via only): one for all joints or by joint name"
    )
    max_acceleration: JointAcceleration | None = Field(  # type: ignore[valid-type]
        None, description="joint acceleration limit [rad/s^2] (via only): one for all joints or by joint name"
    )
    dwell: Dwell | None = Field(  # type: ignore[valid-type]
        None, description=f"rest at each via point [s] (via only; default {DEFAULT_DWELL:g} s)"
    )
    rate: Rate | None = Field(  # type: ignore[valid-type]
        None, gt=0, description=f"sampling rate [Hz] (via only; default {DEFAULT_RATE:g} Hz)"
    )
    payload: PayloadSpec | None = Field(
        None, description="payload carried (default: constraints.payload as a point mass, if any)"
    )

    @model_validator(mode="after")
    def _one_source(self) -> DutyCycleSpec:
        _exactly_one(self, ("file", "via"), "the duty cycle")
        if self.file is not None:
            given = [name for name in _VIA_ONLY if getattr(self, name) is not None]
            if given:
                raise ValueError(
                    f"{', '.join(given)} only with via points (a trajectory file gives the motion)"
                )
            return self
        missing = [name for name in ("max_speed", "max_acceleration") if getattr(self, name) is None]
        if missing:
            raise ValueError(f"{' and '.join(missing)} for a motion through via points")
        dwell = self.dwell if self.dwell is not None else DEFAULT_DWELL
        if isinstance(dwell, builtins.list) and len(dwell) != len(self.via or []):
            raise ValueError(
                f"dwell: one time for all via points or one per via point ({len(self.via or [])})"
            )
        rate = self.rate if self.rate is not None else DEFAULT_RATE
        samples = _motion_duration_bound(self.via or [], self.max_speed, self.max_acceleration, dwell) * rate
        if samples > MAX_CYCLE_SAMPLES:
            raise ValueError(
                f"a motion of at most {MAX_CYCLE_SAMPLES:.0e} samples (these via points, limits and rate may "
                f"need up to {samples:.2g}): raise max_speed or max_acceleration, or lower the rate"
            )
        # The defaults become explicit (the resolved study shows them).
        object.__setattr__(self, "dwell", dwell)
        object.__setattr__(self, "rate", rate)
        return self


MAX_CYCLE_SAMPLES = 500_000
"""Most samples of a via-point motion: 500 s at 1 kHz; each sample costs the dynamics of every joint."""


def _motion_duration_bound(via: Any, speed: Any, acceleration: Any, dwell: Any) -> float:
    """An upper bound of a via-point motion's duration [s], before the joints are known.

    A rest-to-rest move of distance d within speed v and acceleration a takes at most d/v + v/a (less when it
    never reaches v). Bounded with the largest step between via points, the lowest speed limit and the highest
    speed over the lowest acceleration limit.
    """
    speeds = list(speed.values()) if isinstance(speed, dict) else [speed]
    accelerations = list(acceleration.values()) if isinstance(acceleration, dict) else [acceleration]
    if not speeds or not accelerations:
        return 0.0
    v_min, v_max, a_min = min(speeds), max(speeds), min(accelerations)
    steps = [
        max((abs(b - a) for a, b in zip(start, end, strict=False)), default=0.0)
        for start, end in itertools.pairwise(via)
    ]
    rests = sum(dwell) if isinstance(dwell, builtins.list) else dwell * len(via)
    return sum(step / v_min + v_max / a_min for step in steps) + rests


# --- design variables --------------------------------------------------------------------------------------------


def _variable_model(name: str, quantity: Any, floor: float | None, doc: str) -> type[_Model]:
    """A model for a design variable: ``{min, max}`` (free), ``{value}`` (fixed) or a bare value (fixed)."""

    class Bound(_Model):
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
            if floor is not None:
                low = self.value if self.value is not None else self.min
                if low is not None and low < floor:
                    raise ValueError(f"values >= {floor:g} (found {low:g})")
            return self

        @property
        def bounds(self) -> tuple[float, float]:
            """``(lower, upper)`` in SI units (equal when fixed)."""
            if self.value is not None:
                return (self.value, self.value)
            assert self.min is not None and self.max is not None  # guaranteed by _bounds
            return (self.min, self.max)

    Bound.__name__ = Bound.__qualname__ = f"{name}Bounds"
    Bound.__doc__ = doc
    return Bound


def _per_joint(name: str, bound: type[_Model], doc: str) -> type[_Model]:
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


_StatorBounds = _variable_model("StatorDiameter", PartSize, None, "motor stator diameter [m]")
_StackBounds = _variable_model("StackLength", PartSize, None, "motor stack length [m]")
_GearBounds = _variable_model("GearRatio", GearRatio, 1.0, "gear ratio [-], >= 1")
_SoftBounds = _variable_model("SoftwareStiffness", JointStiffness, None, "software stiffness [N m/rad]")
StatorDiameterVariable = _per_joint("StatorDiameterVariable", _StatorBounds, "motor stator diameter [m]")
StackLengthVariable = _per_joint("StackLengthVariable", _StackBounds, "motor stack length [m]")
GearRatioVariable = _per_joint("GearRatioVariable", _GearBounds, "gear ratio [-], >= 1")
SoftwareStiffnessVariable = _per_joint(
    "SoftwareStiffnessVariable", _SoftBounds, "software stiffness [N m/rad]"
)
ThresholdVariable = _variable_model("ThresholdVariable", ThresholdForce, None, "contact-force threshold [N]")
PositionErrorVariable = _variable_model(
    "PositionErrorVariable", PositionError, None, "position-error threshold [m]"
)
VelocityVariable = _variable_model("VelocityVariable", ApproachVelocity, None, "approach velocity [m/s]")

PER_JOINT_DESIGN_VARIABLES = ("stator_diameter", "stack_length", "gear_ratio", "software_stiffness")
MODULE_DESIGN_VARIABLES = ("stator_diameter", "stack_length", "gear_ratio")
"""The optimiser's ``MODULE_VARIABLES`` (what a module's joints share), named here for the study layer, which
loads no optimiser (tests/test_modules.py checks they agree)."""


class DesignSpec(_Model):
    """Design variables the optimiser may change.

    Any not listed keeps the value of its section (``actuators``, ``sensing``, ``approach_velocity``).
    Per-joint variables take ``joints: {name: {...}}``.
    """

    stator_diameter: StatorDiameterVariable | None = None  # type: ignore[valid-type]
    stack_length: StackLengthVariable | None = None  # type: ignore[valid-type]
    gear_ratio: GearRatioVariable | None = None  # type: ignore[valid-type]
    software_stiffness: SoftwareStiffnessVariable | None = None  # type: ignore[valid-type]
    threshold: ThresholdVariable | None = None  # type: ignore[valid-type]
    position_error: PositionErrorVariable | None = None  # type: ignore[valid-type]
    approach_velocity: VelocityVariable | None = None  # type: ignore[valid-type]


# --- objectives, constraints, Pareto, outputs, execution ---------------------------------------------------------


class ConstraintsSpec(_Model):
    """Design constraints: payload [kg], torque safety factor, threshold noise floor [N], torques [N m]."""

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


class ParetoSpec(_Model):
    """The Pareto front to trace: two or three objectives, the number of points, the anchors' start points."""

    objectives: list[ObjectiveName] = Field(min_length=2, max_length=3)
    points: Annotated[int, Field(ge=2, le=400, strict=True)] = 20
    anchor_starts: Annotated[
        int,
        Field(
            ge=1,
            le=50,
            strict=True,
            description="start points of each anchor's first solve (multi-start against local optima)",
        ),
    ] = 1

    @field_validator("objectives")
    @classmethod
    def _distinct(cls, value: list[str]) -> list[str]:
        if len(set(value)) != len(value):
            raise ValueError("different objectives")
        return value


class CatalogueSpec(_Model):
    """The catalogue the recommended design (and every Pareto design) is snapped to after the front.

    See :mod:`collision_reflex.optimize.snap`: per joint the ``candidates`` nearest catalogue motors within
    bounds; every combination re-solved when there are at most ``max_combinations``, else coordinate descent.
    """

    snap: bool = Field(True, description="snap the recommended and the Pareto designs to catalogue parts")
    motors: str | None = Field(
        None, description="motor catalogue file, relative to the study file; null: the packaged catalogue"
    )
    gearboxes: str | None = Field(
        None, description="gearbox catalogue file, relative to the study file; null: the packaged catalogue"
    )
    candidates: Annotated[int, Field(ge=1, le=20, strict=True)] = Field(
        3, description="catalogue motors considered per joint, the nearest to the continuous optimum first"
    )
    max_combinations: Annotated[int, Field(ge=1, le=10000, strict=True)] = Field(
        64, description="the most combinations re-solved exactly; beyond, a coordinate-descent heuristic"
    )
    gearbox_kinds: list[GearboxKind] | None = Field(
        None,
        description="the gearbox kinds a joint may take in the catalogue design, e.g. [harmonic, planetary]; "
        "null: the kind of its study gearbox",
    )


class OutputsSpec(_Model):
    """Which files a run writes besides the results: figure formats and the PDF report."""

    figures: list[Literal["png", "svg"]] = Field(default_factory=lambda: ["png", "svg"])  # type: ignore[arg-type]
    pdf: bool = Field(False, description="also write report.pdf (needs Chromium)")


class SimulateSpec(_Model):
    """Simulate the recommended (and optionally each Pareto) design on its worst contact samples.

    The time-domain arm simulation beside the closed form, samples outside its validity region flagged.
    """

    recommended: bool = Field(True, description="simulate the recommended design")
    pareto: bool = Field(False, description="also simulate each Pareto design")
    samples: Annotated[int, Field(ge=1, le=50, strict=True)] = Field(
        3, description="contact samples per design: those with the largest closed-form impulse"
    )
    detection: str | None = Field(
        None,
        description="the simulator's detection scheme; null: its default (spring_torque, the joint spring torques' force estimate)",
    )
    contact_stiffness_ratio: float = Field(
        100.0, ge=1, le=1e4, description="the wall's stiffness over the joints' stiffness along u [-]"
    )
    tolerance: float = Field(
        0.05, gt=0, le=1, description="relative difference beyond which a sample is flagged [-]"
    )

    @field_validator("detection")
    @classmethod
    def _known_detection(cls, value: str | None) -> str | None:
        from ..simulate.validity import available_detections

        if value is not None and value not in available_detections():
            raise ValueError(f"one of {', '.join(available_detections())} (found {value!r})")
        return value


class SearchSpec(_Model):
    """The adversarial search of the contact domain that certifies each design's worst case.

    After the solves, the impulse of each design is maximised over the domain from its worst samples and from
    random points; the maxima above the design's worst case by more than ``tolerance`` join the samples, and
    the solves are repeated (the exchange method), at most ``rounds`` times.
    """

    enabled: bool = Field(True, description="search the domain after the solves; false: samples only")
    starts: Annotated[int, Field(ge=1, le=64, strict=True)] = Field(
        6, description="local searches from the worst samples of each design"
    )
    random_starts: Annotated[int, Field(ge=0, le=64, strict=True)] = Field(
        4, description="local searches from random points of the domain, per design"
    )
    tolerance: Annotated[float, Field(gt=0, le=0.5, allow_inf_nan=False)] = Field(
        0.005,
        description="relative excess over the reported worst case that makes a searched point a violator",
    )
    rounds: Annotated[int, Field(ge=1, le=10, strict=True)] = Field(
        4, description="most solve-and-search rounds; a worst case still exceeded after them is reported so"
    )
    seed: int = Field(0, ge=0, lt=2**64, strict=True, description="seed of the random starts")


class OptimizerSpec(_Model):
    """How the optimiser solves the study's problems (the numbers agree within the solver's tolerance)."""

    worst_case_search: SearchSpec = Field(default_factory=SearchSpec)  # type: ignore[arg-type]

    active_set: Literal["auto", "always", "never"] = Field(
        "auto",
        description="solve the optimum and every Pareto point on active sets of the contact samples (a subset, "
        "grown by the samples found above its worst case until none is: exact for worst-case objectives): "
        "'auto' from 128 samples (ACTIVE_SET_THRESHOLD), 'always', or 'never' (all samples in one NLP)",
    )


class ExecutionSpec(_Model):
    """Where the independent work runs: in-process, a local process pool, or a Dask cluster."""

    executor: Literal["serial", "processes", "dask"] = "serial"
    # Local worker processes: more than 256 is more than the cores of any one machine (a Dask cluster scales
    # with a scheduler address instead).
    workers: Annotated[int, Field(ge=1, le=256, strict=True)] = 2
    scheduler: str | None = Field(None, description="Dask scheduler address, e.g. tcp://host:8786")

    @model_validator(mode="after")
    def _scheduler(self) -> ExecutionSpec:
        if self.scheduler is not None and not re.match(r"^(tcp|tls|inproc|ucx)://\S+$", self.scheduler):
            raise ValueError(f"a scheduler address such as tcp://host:8786 (found {self.scheduler!r})")
        return self


# Objective weights: a ratio of 1e6 between two terms already makes the smaller one vanish.
Weight = Annotated[float, Field(gt=0, le=1e6, allow_inf_nan=False)]


StoppingTime = _quantities("s", "a stopping time", "0.25 s", dict, "> 0", 60.0)


class RatingSpec(_Model):
    """What the robot is rated for, as its datasheet gives it (each figure optional).

    At every sampled configuration the joints must hold the payload still (the static hold), move at their rated
    speeds while accelerating at their rated accelerations (the rated motion) and stop from their rated speeds
    within their stopping times (braking), all with the rated payload; the motors and gearboxes must turn at the
    rated speeds. Speeds, accelerations and stopping times: one value for every joint or a mapping by joint name.
    """

    payload: Payload | None = Field(
        None,
        ge=0,
        description="rated payload [kg], held still at every sampled configuration (the static hold) and carried "
        "in the rated motion; null: the payload the study carries (duty_cycle.payload or constraints.payload)",
    )
    joint_speeds: JointSpeed | None = Field(  # type: ignore[valid-type]
        None, description="rated joint speeds [rad/s]: one for all joints or by joint name"
    )
    joint_accelerations: JointAcceleration | None = Field(  # type: ignore[valid-type]
        None, description="rated joint accelerations [rad/s^2]: one for all joints or by joint name"
    )
    stopping_time: StoppingTime | None = Field(  # type: ignore[valid-type]
        None, description="time to stop from the rated speed [s] (needs joint_speeds): one or by joint name"
    )

    @model_validator(mode="after")
    def _stops_from_a_speed(self) -> RatingSpec:
        if self.stopping_time is not None and self.joint_speeds is None:
            raise ValueError("stopping_time needs the joint_speeds it stops from")
        return self


class ArmStudy(_Model):
    """A design study of the actuators of a robot arm."""

    kind: Literal["arm"] = "arm"
    name: Name = Field(description="the study's name; names the output folder")
    description: str = ""
    robot: RobotSpec
    actuators: ActuatorsSpec
    sensing: SensingSpec
    approach_velocity: ApproachVelocity = Field(gt=0, description="approach velocity [m/s]")
    reaction: Literal["at_rest", "moving"] = "at_rest"
    reflected_inertia_in: Literal["robot", "finger"] | PlacementRuleSpec = Field(
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


class ActuatorCandidate(_Model):
    """One single-joint actuator of an actuator study."""

    motor: MotorSpec
    gearbox: GearboxSpec | None = None
    gearbox_inertia: bool = False
    gear_ratio: GearRatio = Field(1.0, ge=1)
    mechanical_stiffness: JointStiffness = Field(gt=0)
    software_stiffness: JointStiffness = Field(gt=0)
    reflected_inertia_in: Literal["robot", "finger"] = Field(
        "robot",
        description="'finger': N^2 J_m also in the impact (a stiff transmission, like the paper's A8)",
    )
    sensing: SensingSpec | None = Field(None, description="overrides the study's sensing for this actuator")


class LoadSpec(_Model):
    """What the actuator drives: a link of given lever, whose structure mass is seen at the contact."""

    lever: Lever = Field(gt=0, description="distance from the joint axis to the contact [m]")
    finger_mass: PartMass = Field(gt=0, description="structure (sprung) mass seen at the contact [kg]")
    contact_stiffness: ContactStiffness | None = Field(
        None, gt=0, description="stiffness of the object hit [N/m], in series with the joint; null: rigid"
    )


class VelocityRange(_Model):
    """Approach velocities [m/s]: ``count`` values from ``min`` to ``max``, evenly spaced in log scale."""

    min: ApproachVelocity = Field(gt=0)
    max: ApproachVelocity = Field(gt=0)
    count: Annotated[int, Field(ge=2, le=10000, strict=True)] = 50

    @model_validator(mode="after")
    def _ordered(self) -> VelocityRange:
        if self.min >= self.max:
            raise ValueError(f"min < max (min = {self.min:g} m/s, max = {self.max:g} m/s)")
        return self


class ActuatorStudy(_Model):
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
    reaction: Literal["at_rest", "moving"] = "at_rest"
    outputs: OutputsSpec = Field(default_factory=OutputsSpec)  # type: ignore[arg-type]


Study = ArmStudy | ActuatorStudy
STUDY_KINDS: dict[str, type[BaseModel]] = {"arm": ArmStudy, "actuator": ActuatorStudy}
