"""Actuator hardware: motors and their scaling laws, gearboxes, actuators, the catalogue, actuator sweeps."""

from .actuators import (
    Actuator,
    CollisionParameters,
    CurrentThreshold,
    ForceThreshold,
    PositionThreshold,
    gear_ratio_for,
)
from .gearboxes import CatalogueGearbox, Gearbox, ScaledGearbox, load_gearbox_catalogue
from .motors import (
    SCALING_LAWS,
    Motor,
    MotorQuantities,
    ScalingLaw,
    load_catalogue,
    reference_motor,
    scaled_motor_quantities,
    scaling_law,
)

__all__ = [
    "SCALING_LAWS",
    "Actuator",
    "CatalogueGearbox",
    "CollisionParameters",
    "CurrentThreshold",
    "ForceThreshold",
    "Gearbox",
    "Motor",
    "MotorQuantities",
    "PositionThreshold",
    "ScaledGearbox",
    "ScalingLaw",
    "gear_ratio_for",
    "load_catalogue",
    "load_gearbox_catalogue",
    "reference_motor",
    "scaled_motor_quantities",
    "scaling_law",
]
