"""Electric motors, their scaling laws, and the motor catalogue.

A motor is described by its stator outer diameter ``r`` (the paper's ``r_m``), stack length ``l``, rotor
inertia, peak and continuous torque and mass. Scaling a reference motor ``(r0, l0)`` to ``(r, l)`` multiplies
every quantity by ``(l/l0) (r/r0)**e`` with the exponent ``e`` of a scaling law (Bhatia, Mason and Johnson,
"Reacting to Contact: Transparency and Collision Reflex in Actuation", ``tab:scaling_laws``).

The scaling arithmetic (:func:`scaled_motor_quantities`) works on floats, NumPy arrays and CasADi symbols, since
the optimiser uses it with motor sizes as decision variables. The catalogue is YAML (plain SI numbers or
quantities with units such as ``"60 mm"``); the packaged one holds the paper's reference motor.
"""

from __future__ import annotations

import numbers
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any, NamedTuple

from .. import _validate
from ..errors import InvalidParameter

__all__ = [
    "DEFAULT_SCALING_LAW",
    "REFERENCE_MOTOR_NAME",
    "SCALING_LAWS",
    "Motor",
    "MotorQuantities",
    "ScalingLaw",
    "load_catalogue",
    "reference_motor",
    "scaled_motor_quantities",
    "scaling_law",
]


@dataclass(frozen=True)
class ScalingLaw:
    """Exponents ``e`` of the stator diameter in ``q = q0 (l/l0) (r/r0)**e`` for mass, rotor inertia, torque.

    Every law in ``tab:scaling_laws`` is linear in the stack length ``l``; only the diameter exponents differ.
    """

    name: str
    mass_exponent: float
    inertia_exponent: float
    torque_exponent: float
    source: str = ""

    def __post_init__(self) -> None:
        for field in ("mass_exponent", "inertia_exponent", "torque_exponent"):
            _validate.non_negative(f"ScalingLaw.{field}", getattr(self, field))

    @property
    def inertia_torque_exponent(self) -> float:
        """``p`` in ``J_m ∝ tau**p`` at fixed length (the paper's comparison of laws: 1, 1.43, 1.5, 1.6)."""
        return self.inertia_exponent / self.torque_exponent


SCALING_LAWS: dict[str, ScalingLaw] = {
    law.name: law
    for law in (
        ScalingLaw(
            "isometric", 2.0, 4.0, 4.0, "Spletzer and Marron 1999 (isometric scaling), tab:scaling_laws"
        ),
        ScalingLaw(
            "empirical",
            2.0,
            4.0,
            2.8,
            "Dermitzakis et al. 2011 (empirical torque fit; mass and inertia isometric), tab:scaling_laws",
        ),
        ScalingLaw(
            "quadruped",
            1.0,
            3.0,
            2.0,
            "Seok et al. 2012, Kenneally et al. 2016 (fixed radial thickness), tab:scaling_laws",
        ),
        ScalingLaw(
            "haddadin",
            2.0,
            4.0,
            2.5,
            "Haddadin et al. 2012 (electrical and thermal); the paper's choice, tab:scaling_laws",
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
    """

    name: str
    stator_diameter: float
    stack_length: float
    rotor_inertia: float
    peak_torque: float
    continuous_torque: float
    mass: float
    source: str = ""

    def __post_init__(self) -> None:
        for field in _MOTOR_NUMBERS:
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
    """Rotor inertia, peak and continuous torque and mass of ``reference`` scaled to a new size.

    ``q = q0 (l/l0) (r/r0)**e`` with ``e`` from ``law`` (``tab:scaling_laws``). Works on floats, NumPy arrays
    (broadcast) and CasADi ``SX``/``MX`` symbols alike.

    Parameters
    ----------
    reference: the motor scaled from (``r0``, ``l0`` and its quantities ``q0``).
    stator_diameter: new stator outer diameter ``r`` [m], > 0.
    stack_length: new stack length ``l`` [m], > 0; default the reference's.
    law: a scaling-law name (see :data:`SCALING_LAWS`) or a :class:`ScalingLaw`.
    """
    law = scaling_law(law)
    _validate.positive("stator_diameter", stator_diameter)
    if stack_length is None:
        stack_length = reference.stack_length
    _validate.positive("stack_length", stack_length)
    length_ratio = stack_length / reference.stack_length
    diameter_ratio = stator_diameter / reference.stator_diameter

    def scale(value: float, exponent: float) -> Any:
        return value * length_ratio * diameter_ratio**exponent

    return MotorQuantities(
        rotor_inertia=scale(reference.rotor_inertia, law.inertia_exponent),
        peak_torque=scale(reference.peak_torque, law.torque_exponent),
        continuous_torque=scale(reference.continuous_torque, law.torque_exponent),
        mass=scale(reference.mass, law.mass_exponent),
    )


def load_catalogue(path: str | os.PathLike[str] | None = None) -> dict[str, Motor]:
    """Motors of a YAML catalogue file, by name (default: the packaged catalogue).

    The file has a top-level ``motors`` mapping from name to entry; each entry gives ``stator_diameter``,
    ``stack_length``, ``rotor_inertia``, ``peak_torque``, ``continuous_torque``, ``mass`` (plain SI numbers or
    strings with units, e.g. ``"60 mm"``, ``"1.3 N*m"``) and a ``source``. A missing or mistyped field raises
    :class:`~collision_reflex.errors.CatalogueError` naming the field, the file and the line.
    """
    from .catalogue import read_catalogue

    target = Path(path) if path is not None else default_catalogue_path()
    entries = read_catalogue(target)
    return {name: Motor(name=name, **fields) for name, fields in entries.items()}


def default_catalogue_path() -> Path:
    """The packaged motor catalogue, ``designs/motors.yaml``."""
    from .catalogue import packaged_catalogue_path

    return packaged_catalogue_path()


def reference_motor() -> Motor:
    """The paper's reference motor, Celera Motion Omni+ OPN-060-013-A (``tab:motor_params``, M2)."""
    return get_motor(REFERENCE_MOTOR_NAME)


def get_motor(name: str, path: str | os.PathLike[str] | None = None) -> Motor:
    """The motor called ``name`` in a catalogue (default: the packaged one)."""
    from ..errors import UnknownMotor

    catalogue = load_catalogue(path)
    try:
        return catalogue[name]
    except KeyError:
        raise UnknownMotor(name, sorted(catalogue), str(path or default_catalogue_path())) from None
