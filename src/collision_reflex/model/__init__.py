"""The collision-reflex model: plain arithmetic that works on floats, NumPy arrays and CasADi symbols alike."""

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
    "PhaseImpulses",
    "collision_times",
    "current_threshold_torque",
    "force_profile",
    "minimum_impulse",
    "optimal_velocity",
    "phase_impulses",
    "series_stiffness",
    "threshold_force",
    "total_impulse",
    "velocity_coefficients",
]
