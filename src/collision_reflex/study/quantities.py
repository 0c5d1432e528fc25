"""Physical quantities in study files: plain SI numbers or strings with units, each within a physical range.

``60 mm``, ``"1.3 N*m"``, ``0.2 m/s`` and ``0.06`` (metres, as a plain number is SI) all give a float in the
field's SI unit. Strings are read by :func:`collision_reflex._units.parse_quantity` (a bounded grammar: a number
and a unit expression). A string whose dimension differs from the field's (``"3 kg"`` for a stiffness) is
refused with a message naming both. A field type may carry a physical range (``1 mm .. 1 m`` for a stator
diameter): a value outside it is refused with the range in the message, so that a study that validates also
runs. The field types here are ``typing.Annotated`` floats for pydantic; their JSON Schema accepts a number
(within the range) or a string.
"""

from __future__ import annotations

import math
from typing import Annotated, Any

from pydantic import BeforeValidator, WithJsonSchema
from pydantic_core import PydanticCustomError

from .._units import QuantityError, parse_quantity


def to_si(value: Any, unit: str, what: str, example: str, bounds: tuple[float, float] | None = None) -> float:
    """``value`` (a number in ``unit``, or a string with units of the same dimension) as a float in ``unit``.

    Parameters
    ----------
    value : Any
        What the file holds: a number (in ``unit``) or a string such as ``"60 mm"``.
    unit : str
        The field's SI unit (pint syntax).
    what, example : str
        The field's kind (``"a length"``) and an example value (``"60 mm"``), for messages.
    bounds : tuple of float, optional
        The physical range ``(low, high)`` in ``unit``, both included.

    Raises ``PydanticCustomError`` (turned into a located :class:`~collision_reflex.errors.StudyProblem`).
    """
    in_unit = f" in {unit}" if unit else ""
    expected = f"{what}{in_unit}: a number (SI) or a string with units such as {example!r}"
    if isinstance(value, bool) or not isinstance(value, (int, float, str)):
        raise PydanticCustomError("quantity", "{expected}", {"expected": expected})
    if isinstance(value, str):
        try:
            # YAML 1.1 reads "2e7" (no dot) as a string: a number written as text is still a plain SI number.
            magnitude = parse_quantity(value, unit)
        except QuantityError as error:
            _refuse(error, value, expected)
    else:
        try:
            magnitude = float(value)
        except OverflowError:
            magnitude = math.inf
    if not math.isfinite(magnitude):
        raise PydanticCustomError("quantity", "{expected}", {"expected": "a finite " + expected})
    if bounds is not None and not bounds[0] <= magnitude <= bounds[1]:
        low, high = bounds
        expected = f"{what} from {low:g} to {high:g} {unit}".rstrip()
        if isinstance(value, str):  # the file's text is quoted as found: say what it is in SI
            expected += f" ({value.strip()} is {magnitude:.6g} {unit})".replace(" )", ")")
        raise PydanticCustomError("quantity_range", "{expected}", {"expected": expected})
    return magnitude


def _refuse(error: QuantityError, text: str, expected: str) -> Any:
    if error.kind == "dimension":
        raise PydanticCustomError(
            "quantity_dimension",
            "{expected} ({found} is {found_dimension}, not {dimension})",
            {
                "expected": expected,
                "found": _excerpt(text),  # pydantic fills {name} only, without format specs
                "found_dimension": error.found_dimension,
                "dimension": error.dimension,
            },
        )
    raise PydanticCustomError("quantity", "{expected}", {"expected": f"{expected} ({error.reason})"})


def _excerpt(text: str, limit: int = 40) -> str:
    shown = repr(text)
    return shown if len(shown) <= limit else shown[: limit - 3] + "..."


def quantity_type(
    unit: str, what: str, example: str, low: float | None = None, high: float | None = None
) -> Any:
    """An ``Annotated[float, ...]`` field type holding a quantity converted to ``unit``.

    ``low`` and ``high`` [``unit``] bound it (both or neither): the range a designer could mean.
    """
    bounds = (low, high) if low is not None and high is not None else None
    number: dict[str, Any] = {"type": "number"}
    description = f"{what} [{unit}]: a number in {unit} or a string with units, e.g. {example!r}"
    if bounds is not None:
        number.update(minimum=bounds[0], maximum=bounds[1])
        description += f"; from {bounds[0]:g} to {bounds[1]:g} {unit}"

    # A function of the value alone: pydantic reads a validator's signature for each field that uses it, which
    # is much slower for a functools.partial, and an arm study has many fields.
    def validate(value: Any) -> float:
        return to_si(value, unit, what, example, bounds)

    return Annotated[
        float,
        BeforeValidator(validate),
        WithJsonSchema({"anyOf": [number, {"type": "string"}], "description": description}),
    ]


# Field types of the study schema, by what they measure. Angles are dimensionless to pint (rad = 1), so a
# rotary stiffness may be written "N*m/rad" or "N*m".
Length = quantity_type("m", "a length", "60 mm")
Mass = quantity_type("kg", "a mass", "0.5 kg")
Force = quantity_type("N", "a force", "3 N")
Torque = quantity_type("N*m", "a torque", "1.3 N*m")
Velocity = quantity_type("m/s", "a velocity", "0.5 m/s")
Angle = quantity_type("rad", "an angle", "45 deg")
RotaryStiffness = quantity_type("N*m/rad", "a rotary stiffness", "1000 N*m/rad")
LinearStiffness = quantity_type("N/m", "a linear stiffness", "2e7 N/m")
Inertia = quantity_type("kg*m^2", "a moment of inertia", "2.21e-5 kg*m^2")
Ratio = quantity_type("", "a dimensionless number", "9")

# Physical ranges of the design quantities. Each is generous for a robot actuator, from a fingertip to a
# heavy industrial arm, and keeps every derived number (N^2 J_m, k/N^2, impulses) far from float limits.
# Motor and gearbox sizes: 1 mm (the smallest micromotors) to 1 m (torque motors of machine tools).
PartSize = quantity_type("m", "a length", "60 mm", 1e-3, 1.0)
# Gear ratios: 1 (direct drive) to 10,000 (multi-stage harmonic or worm drives).
GearRatio = quantity_type("", "a gear ratio", "9", 1.0, 1e4)
# Joint stiffness (mechanical or controller): 1e-3 N m/rad (a compliant finger joint) to 1e9 N m/rad (far
# stiffer than any steel joint; the stiffest industrial joints are ~1e7).
JointStiffness = quantity_type("N*m/rad", "a rotary stiffness", "1000 N*m/rad", 1e-3, 1e9)
# Contact stiffness of the object hit: 1 N/m (a soft foam) to 1e12 N/m (steel on steel).
ContactStiffness = quantity_type("N/m", "a linear stiffness", "2e7 N/m", 1.0, 1e12)
# Contact-force thresholds: 1 mN (a tactile skin) to 10 kN (beyond a heavy arm's rated force).
ThresholdForce = quantity_type("N", "a force", "3 N", 1e-3, 1e4)
# Position-error thresholds: 1 um (an encoder count of a precise joint) to 1 m.
PositionError = quantity_type("m", "a length", "1 mm", 1e-6, 1.0)
# Motor torque thresholds (current sensing): 1 uN m to 10 kN m.
MotorTorque = quantity_type("N*m", "a torque", "0.1 N*m", 1e-6, 1e4)
# Approach velocities: 1 um/s (a creeping approach) to 10 m/s (faster than any collaborative robot moves).
ApproachVelocity = quantity_type("m/s", "a velocity", "0.5 m/s", 1e-6, 10.0)
# Levers (joint axis to contact): 1 mm to 10 m.
Lever = quantity_type("m", "a length", "0.3 m", 1e-3, 10.0)
# Masses (finger, structure, payload, gearbox): 1 mg to 1 t.
PartMass = quantity_type("kg", "a mass", "0.5 kg", 1e-6, 1e3)
# Required or rated torques: up to 1e5 N m (the largest industrial robot joints are ~1e4 N m).
JointTorque = quantity_type("N*m", "a torque", "1.3 N*m", 0.0, 1e5)
# Inertias (payload, gearbox input): within 1e3 kg m^2 (a tonne at one metre); products of inertia may be < 0.
PartInertia = quantity_type("kg*m^2", "a moment of inertia", "2.21e-5 kg*m^2", -1e3, 1e3)
# Payloads: none to 1 t.
Payload = quantity_type("kg", "a mass", "0.5 kg", 0.0, 1e3)
# Contact offsets from the contact frame: within 10 m.
Offset = quantity_type("m", "a length", "50 mm", -10.0, 10.0)
# Joint positions: within 1000 rad (160 turns; or 1 km for a prismatic joint).
JOINT_POSITION_RANGE = (-1e3, 1e3)
JOINT_POSITION_EXPECTED = (
    "a joint position with its unit: an angle such as '30 deg' or '0.5 rad' (a prismatic joint's, a length such "
    "as '0.1 m')"
)


def joint_position_si(value: Any) -> tuple[float, str]:
    """A joint position of a study file as ``(magnitude, unit)``: ``rad`` for an angle, ``m`` for a length.

    A bare number is refused: radians and degrees both read naturally (a ``30`` meant as degrees would turn the
    joint 30 rad), so the unit must be written.
    """
    if isinstance(value, bool) or not isinstance(value, (int, float, str)):
        raise PydanticCustomError("quantity", "{expected}", {"expected": JOINT_POSITION_EXPECTED})
    try:
        float(value)
    except (TypeError, ValueError, OverflowError):
        pass
    else:
        raise PydanticCustomError(
            "quantity",
            "{expected}",
            {"expected": JOINT_POSITION_EXPECTED + "; a bare number could be either"},
        )
    assert isinstance(value, str)
    try:
        magnitude, unit = parse_quantity(value, "rad", angle_explicit=True), "rad"
    except QuantityError as error:
        if error.kind not in ("dimension", "angle"):
            _refuse(error, value, JOINT_POSITION_EXPECTED)
        try:
            magnitude, unit = parse_quantity(value, "m"), "m"
        except QuantityError as length_error:
            _refuse(
                length_error if length_error.kind != "dimension" else error, value, JOINT_POSITION_EXPECTED
            )
    low, high = JOINT_POSITION_RANGE
    if not low <= magnitude <= high:
        expected = (
            f"a joint position from {low:g} to {high:g} {unit} ({value.strip()} is {magnitude:.6g} {unit})"
        )
        raise PydanticCustomError("quantity_range", "{expected}", {"expected": expected})
    return magnitude, unit


JointPosition = Annotated[
    float,
    BeforeValidator(lambda value: joint_position_si(value)[0]),
    WithJsonSchema(
        {
            "type": "string",
            "pattern": r"^\s*[-+]?[0-9.]+([eE][-+]?[0-9]+)?\s*[^\s0-9.].*$",
            "description": f"{JOINT_POSITION_EXPECTED}; from {JOINT_POSITION_RANGE[0]:g} to "
            f"{JOINT_POSITION_RANGE[1]:g} rad (or m)",
        }
    ),
]
# Safety factors on torque: 1 to 100.
SafetyFactor = quantity_type("", "a dimensionless number", "1.5", 1.0, 100.0)
# Sensing noise floors: up to the largest threshold.
NoiseFloor = quantity_type("N", "a force", "0.5 N", 0.0, 1e4)
# Floors on a contact Jacobian's smallest singular value: 0 (none) up to a reach no arm has.
SingularValueFloor = quantity_type("m", "a length", "0.08 m", 0.0, 100.0)

# A gearbox's input speed: from a slow hand crank (1e-3 rad/s) to beyond the fastest spindles (1e5 rad/s).
AngularSpeed = quantity_type("rad/s", "an angular speed", "3000 rpm", 1e-3, 1e5)
# Sampling rates of a via-point motion: 1 Hz to 10 kHz (a servo loop's rate).
Rate = quantity_type("Hz", "a sampling rate", "500 Hz", 1.0, 1e4)


def per_item_quantity_type(
    unit: str, what: str, example: str, collection: type, minimum: str, maximum: float
) -> Any:
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
JointSpeed = per_item_quantity_type(
    "rad/s", "a joint speed (m/s for a prismatic joint)", "90 deg/s", dict, "> 0", 1e3
)
JointAcceleration = per_item_quantity_type(
    "rad/s^2", "a joint acceleration (m/s^2 for a prismatic joint)", "300 deg/s^2", dict, "> 0", 1e6
)
Dwell = per_item_quantity_type("s", "a time at rest", "0.5 s", list, ">= 0", 3600.0)
StoppingTime = per_item_quantity_type("s", "a stopping time", "0.25 s", dict, "> 0", 60.0)
