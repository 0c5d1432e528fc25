"""The collision-reflex model: plain arithmetic that works on floats, NumPy arrays and CasADi symbols alike."""

from .contact import (
    BodyRegion,
    Rebound,
    TransientContact,
    contact_robot_mass,
    iso_robot_mass,
    permissible_speed,
    rebound,
    rebound_impulse,
    reduced_mass,
    settled_rebound_speed,
    transient_contact,
)
from .impulse import (
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
from .sensing import current_threshold_torque, threshold_force

__all__ = [
    "BodyRegion",
    "PhaseImpulses",
    "Rebound",
    "TransientContact",
    "collision_times",
    "contact_robot_mass",
    "current_threshold_torque",
    "force_profile",
    "iso_robot_mass",
    "minimum_impulse",
    "optimal_velocity",
    "permissible_speed",
    "phase_impulses",
    "rebound",
    "rebound_impulse",
    "reduced_mass",
    "series_stiffness",
    "settled_rebound_speed",
    "threshold_force",
    "total_impulse",
    "transient_contact",
    "velocity_coefficients",
]
