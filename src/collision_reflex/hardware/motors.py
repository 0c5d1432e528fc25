"""Electric motors, their scaling laws, and the motor catalogue.

A motor is described by its stator outer diameter ``r`` (the paper's ``r_m``), stack length ``l``, rotor
inertia, peak and continuous torque, mass and (when known) maximum speed. Scaling a reference motor ``(r0, l0)``
to ``(r, l)`` multiplies mass, inertia and torques by ``(l/l0) (r/r0)**e`` with the exponent ``e`` of a scaling
law (Bhatia, Mason and Johnson, "Reacting to Contact: Transparency and Collision Reflex in Actuation",
``tab:scaling_laws``), and the maximum speed by ``(l/l0)**a (r/r0)**b`` of the law's :class:`SpeedScaling`
(default: constant rotor surface speed, ``omega_max ∝ 1/r``).

The scaling arithmetic (:func:`scaled_motor_quantities`) works on floats, NumPy arrays and CasADi symbols, since
the optimiser uses it with motor sizes as decision variables. The catalogue is YAML (plain SI numbers or
quantities with units such as ``"60 mm"``); the packaged one holds the paper's reference motor.
"""

from __future__ import annotations

import math
import numbers
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any, NamedTuple

from .. import _validate
from ..errors import InvalidParameter, UnknownMotor

__all__ = [
    "CONSTANT_SURFACE_SPEED",
    "DEFAULT_SCALING_LAW",
    "REFERENCE_MOTOR_NAME",
    "SCALING_LAWS",
    "Motor",
    "MotorQuantities",
    "ScalingLaw",
    "SpeedScaling",
    "load_catalogue",
    "reference_motor",
    "scaled_motor_quantities",
    "scaling_law",
]


@dataclass(frozen=True)
class SpeedScaling:
    """How a scaled motor's maximum speed changes with size: ``omega_max = omega0 (l/l0)**a (r/r0)**b``.

    Parameters
    ----------
    length_exponent : float
        ``a``, the exponent of the stack-length ratio ``l/l0``.
    diameter_exponent : float
        ``b``, the exponent of the stator-diameter ratio ``r/r0``.
    source : str
        The physics assumed and where it comes from, for reports.
    """

    length_exponent: float
    diameter_exponent: float
    source: str

    def __post_init__(self) -> None:
        for field in ("length_exponent", "diameter_exponent"):
            value = getattr(self, field)
            if isinstance(value, bool) or not isinstance(value, numbers.Real) or not math.isfinite(value):
                raise InvalidParameter(f"SpeedScaling.{field}", value, "a finite number")


CONSTANT_SURFACE_SPEED = SpeedScaling(
    length_exponent=0.0,
    diameter_exponent=-1.0,
    source=(
        "ASSUMPTION: constant rotor surface speed, omega_max = v_tip / r_rotor with the rotor diameter in "
        "proportion to the stator diameter, so omega_max ∝ 1/r and independent of the stack length. The "
        "centrifugal hoop stress of a rotating ring is rho v**2 (v = omega r; Timoshenko and Goodier, Theory "
        "of Elasticity, rotating disks), so the magnet retention and laminations limit the peripheral "
        "speed, not omega (Pyrhonen, Jokinen, Hrabovcova, Design of Rotating Electrical Machines, Wiley "
        "2014, on peripheral-speed limits). Not chosen: a fixed drive voltage and current, omega_max ∝ "
        "1/tau_p (the back-EMF constant grows with the torque constant), since a scaled motor's winding "
        "is redesigned for its drive. The paper's table of scaling laws says nothing of speed."
    ),
)
"""The default :class:`SpeedScaling`: constant rotor surface (tip) speed, ``omega_max ∝ 1/r``."""


@dataclass(frozen=True)
class ScalingLaw:
    """Exponents ``e`` of the stator diameter in ``q = q0 (l/l0) (r/r0)**e`` for mass, rotor inertia, torque.

    Every law in ``tab:scaling_laws`` is linear in the stack length ``l``; only the diameter exponents differ.
    The maximum speed scales by ``speed`` (a :class:`SpeedScaling`, default :data:`CONSTANT_SURFACE_SPEED`),
    a stated assumption since ``tab:scaling_laws`` gives no speed.
    """

    name: str
    mass_exponent: float
    inertia_exponent: float
    torque_exponent: float
    source: str = ""
    speed: SpeedScaling = CONSTANT_SURFACE_SPEED

    def __post_init__(self) -> None:
        for field in ("mass_exponent", "inertia_exponent", "torque_exponent"):
            # > 0: a size that did not change a motor's mass, inertia or torque would not be a motor law.
            _validate.positive(f"ScalingLaw.{field}", getattr(self, field))
        if not isinstance(self.speed, SpeedScaling):
            raise InvalidParameter("ScalingLaw.speed", self.speed, "a SpeedScaling")

    @property
    def inertia_torque_exponent(self) -> float:
        """``p`` in ``J_m ∝ tau**p`` at fixed length (the paper's comparison of laws: 1, 1.43, 1.5, 1.6)."""
        return self.inertia_exponent / self.torque_exponent


SCALING_LAWS: dict[str, ScalingLaw] = {
    law.name: law
    for law in (
        ScalingLaw(
            "isometric",
            2.0,
            4.0,
            4.0,
            "Spletzer and Marron 1999 (isometric scaling), the paper's table of scaling laws",
        ),
        ScalingLaw(
            "empirical",
            2.0,
            4.0,
            2.8,
            "Dermitzakis et al. 2011 (empirical torque fit; mass and inertia isometric), the paper's table of scaling laws",
        ),
        ScalingLaw(
            "quadruped",
            1.0,
            3.0,
            2.0,
            "Seok et al. 2012, Kenneally et al. 2016 (fixed radial thickness), the paper's table of scaling laws",
        ),
        ScalingLaw(
            "haddadin",
            2.0,
            4.0,
            2.5,
            "Haddadin et al. 2012 (electrical and thermal); the paper's choice, in its table of scaling laws",
        ),
    )
}
"""The four motor scaling laws of ``tab:scaling_laws``, by name."""

DEFAULT_SCALING_LAW = "haddadin"
REFERENCE_MOTOR_NAME = "OPN-060-013-A"


def scaling_law(name: str | ScalingLaw) -> ScalingLaw:
    """The scaling law called ``name`` (one of :data:`SCALING_LAWS`); a :class:`ScalingLaw` passes through."""
    if isinstance(name, ScalingLaw):
        return name
    try:
        return SCALING_LAWS[name]
    except (KeyError, TypeError):
        raise InvalidParameter(
            "law", name, "one of " + ", ".join(repr(n) for n in SCALING_LAWS), "or a ScalingLaw"
        ) from None


class MotorQuantities(NamedTuple):
    """Scaled motor quantities (floats, arrays or CasADi expressions, as the inputs)."""

    rotor_inertia: Any
    """Rotor inertia [kg m^2]."""
    peak_torque: Any
    """Peak torque [N m]."""
    continuous_torque: Any
    """Continuous torque [N m]."""
    mass: Any
    """Motor mass [kg]."""
    max_speed: Any = None
    """Maximum speed [rad/s]; None when the reference motor's is not known."""


@dataclass(frozen=True)
class Motor:
    """An electric motor.

    Parameters
    ----------
    name: a label (catalogue key or a description of how it was made).
    stator_diameter: stator outer diameter ``r`` [m] (the paper's ``r_m``).
    stack_length: stack length (height) ``l`` [m].
    rotor_inertia: rotor inertia ``J_m`` [kg m^2].
    peak_torque: peak torque ``tau_p`` [N m].
    continuous_torque: continuous torque ``tau_c`` [N m], at most the peak torque.
    mass: motor mass [kg].
    source: where the figures come from (datasheet, paper, scaling).
    max_speed: maximum speed ``omega_max`` [rad/s], or None when not known (none is made up:
        :meth:`speed_limit` then says so).
    torque_constant: torque per ampere of phase current ``K_t`` [N m/A] as its datasheet states it, or None
        when not given (informative: no model here uses it).
    """

    name: str
    stator_diameter: float
    stack_length: float
    rotor_inertia: float
    peak_torque: float
    continuous_torque: float
    mass: float
    source: str = ""
    max_speed: float | None = None
    torque_constant: float | None = None

    def __post_init__(self) -> None:
        optional_given = tuple(f for f in ("max_speed", "torque_constant") if getattr(self, f) is not None)
        numbers_given = (*_MOTOR_NUMBERS, *optional_given)
        for field in numbers_given:
            value = getattr(self, field)
            if isinstance(value, bool) or not isinstance(value, numbers.Real):
                raise InvalidParameter(f"Motor.{field}", value, "a number (SI units)")
            _validate.positive(f"Motor.{field}", value)
            object.__setattr__(self, field, float(value))
        if self.continuous_torque > self.peak_torque:
            raise InvalidParameter(
                "Motor.continuous_torque",
                self.continuous_torque,
                f"at most the peak torque {self.peak_torque!r} N m",
            )

    def speed_limit(self) -> float:
        """Return the maximum speed [rad/s]; raise :class:`InvalidParameter` when it is not known."""
        if self.max_speed is None:
            raise InvalidParameter(
                "Motor.max_speed",
                None,
                "a maximum speed in rad/s",
                f"no speed limit known for motor {self.name!r}: give max_speed in its catalogue entry "
                "(e.g. '3000 rpm')",
            )
        return self.max_speed

    def scaled(
        self,
        stator_diameter: float | None = None,
        stack_length: float | None = None,
        law: str | ScalingLaw = DEFAULT_SCALING_LAW,
    ) -> Motor:
        """Return this motor scaled to a new stator diameter [m] and/or stack length [m] under ``law``.

        An omitted dimension keeps this motor's value.
        """
        law = scaling_law(law)
        diameter = self.stator_diameter if stator_diameter is None else stator_diameter
        length = self.stack_length if stack_length is None else stack_length
        quantities = scaled_motor_quantities(self, diameter, length, law)
        return Motor(
            name=f"{self.name} scaled to {diameter * 1e3:g} mm x {length * 1e3:g} mm ({law.name})",
            stator_diameter=float(diameter),
            stack_length=float(length),
            rotor_inertia=float(quantities.rotor_inertia),
            peak_torque=float(quantities.peak_torque),
            continuous_torque=float(quantities.continuous_torque),
            mass=float(quantities.mass),
            source=f"scaled from {self.name} by the {law.name} law ({law.source})",
            max_speed=None if quantities.max_speed is None else float(quantities.max_speed),
        )


_MOTOR_NUMBERS = (
    "stator_diameter",
    "stack_length",
    "rotor_inertia",
    "peak_torque",
    "continuous_torque",
    "mass",
)


def scaled_motor_quantities(
    reference: Motor,
    stator_diameter: Any,
    stack_length: Any = None,
    law: str | ScalingLaw = DEFAULT_SCALING_LAW,
) -> MotorQuantities:
    """Rotor inertia, peak and continuous torque, mass and maximum speed of ``reference`` scaled to a new size.

    ``q = q0 (l/l0) (r/r0)**e`` with ``e`` from ``law`` (``tab:scaling_laws``), and ``omega_max = omega0
    (l/l0)**a (r/r0)**b`` with ``a``, ``b`` from ``law.speed`` (:class:`SpeedScaling`); ``max_speed`` is None
    when the reference's is. Works on floats, NumPy arrays (broadcast) and CasADi ``SX``/``MX`` symbols alike.

    Parameters
    ----------
    reference: the motor scaled from (``r0``, ``l0`` and its quantities ``q0``).
    stator_diameter: new stator outer diameter ``r`` [m], > 0.
    stack_length: new stack length ``l`` [m], > 0; default the reference's.
    law: a scaling-law name (see :data:`SCALING_LAWS`) or a :class:`ScalingLaw`.
    """
    if not isinstance(reference, Motor):
        raise InvalidParameter("reference", reference, "a Motor (e.g. reference_motor() or get_motor(name))")
    law = scaling_law(law)
    _validate.positive("stator_diameter", stator_diameter)
    if stack_length is None:
        stack_length = reference.stack_length
    _validate.positive("stack_length", stack_length)
    length_ratio = stack_length / reference.stack_length
    diameter_ratio = stator_diameter / reference.stator_diameter
    with _validate.combining(stator_diameter=stator_diameter, stack_length=stack_length):
        return _scaled(reference, law, length_ratio, diameter_ratio)


def _scaled(reference: Motor, law: ScalingLaw, length_ratio: Any, diameter_ratio: Any) -> MotorQuantities:
    def scale(value: float, exponent: float) -> Any:
        return value * length_ratio * diameter_ratio**exponent

    return MotorQuantities(
        rotor_inertia=scale(reference.rotor_inertia, law.inertia_exponent),
        peak_torque=scale(reference.peak_torque, law.torque_exponent),
        continuous_torque=scale(reference.continuous_torque, law.torque_exponent),
        mass=scale(reference.mass, law.mass_exponent),
        max_speed=None
        if reference.max_speed is None
        else reference.max_speed
        * length_ratio**law.speed.length_exponent
        * diameter_ratio**law.speed.diameter_exponent,
    )


def load_catalogue(path: str | os.PathLike[str] | None = None) -> dict[str, Motor]:
    """Motors of a YAML catalogue file, by name (default: the packaged catalogue).

    The file has a top-level ``motors`` mapping from name to entry; each entry gives ``stator_diameter``,
    ``stack_length``, ``rotor_inertia``, ``peak_torque``, ``continuous_torque``, ``mass`` (plain SI numbers or
    strings with units, e.g. ``"60 mm"``, ``"1.3 N*m"``), optionally ``max_speed`` (rad/s, or e.g. ``"3000
    rpm"``; omitted means not known) and a ``source``. A missing or mistyped field raises
    :class:`~collision_reflex.errors.CatalogueError` naming the field, the file and the line.
    """
    from .catalogue import read_catalogue  # lazy: pydantic, yaml

    target = Path(path) if path is not None else default_catalogue_path()
    entries = read_catalogue(target)
    return {name: Motor(name=name, **fields) for name, fields in entries.items()}


def default_catalogue_path() -> Path:
    """The packaged motor catalogue, ``designs/motors.yaml``."""
    from .catalogue import packaged_catalogue_path  # lazy: pydantic, yaml

    return packaged_catalogue_path()


def reference_motor() -> Motor:
    """The paper's reference motor, Celera Motion Omni+ OPN-060-013-A (``tab:motor_params``, M2)."""
    return get_motor(REFERENCE_MOTOR_NAME)


def get_motor(name: str, path: str | os.PathLike[str] | None = None) -> Motor:
    """The motor called ``name`` in a catalogue (default: the packaged one)."""
    if not isinstance(name, str):
        raise InvalidParameter("name", name, "a motor's name (text)")
    catalogue = load_catalogue(path)
    try:
        return catalogue[name]
    except KeyError:
        raise UnknownMotor(name, sorted(catalogue), str(path or default_catalogue_path())) from None
