"""The record of one simulated 1D collision: force trace, phase times and impulses, energy bookkeeping."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import SimulationError
from .setup import CollisionSetup


@dataclass(frozen=True)
class SimulationResult:
    """A simulated collision.

    Attributes
    ----------
    setup: the :class:`CollisionSetup` simulated.
    t: sample times of the trace [s], impact at 0 (the integrator's steps, increasing).
    contact_force: wall force on the finger at ``t`` [N] (rigid impacts are impulses, not in the trace).
    spring_force: force in the mechanical spring at ``t`` [N].
    finger_velocity, robot_velocity: velocities toward the wall at ``t`` [m/s].
    impacts: ``(time [s], impulse [N*s])`` of each rigid plastic impact.
    impulse: total impulse on the wall [N*s]: integral of ``contact_force`` plus the impacts.
    detection_time: when the contact was detected [s] (``nan`` with ``drive="free"``).
    reaction_time: when the reaction started, detection plus delay on the control grid [s].
    contact_end: when the finger last left the wall [s].
    impulse_to_detection, impulse_delay, impulse_reaction: the impulse before detection, between detection
        and reaction, and after the reaction started [N*s]; they add up to ``impulse``.
    robot_velocity_at_reaction: robot-mass velocity toward the wall when the reaction started [m/s].
    actuator_work: work done by the actuator on the robot mass [J].
    dissipated: energy lost in contact damping, plastic impacts and friction [J].
    initial_energy, final_energy: kinetic plus elastic energy at the start and the end [J].
    events: ``(time [s], what)`` of every mode change (impacts, contact loss, detection, reaction, play,
        stiction), in order.
    """

    setup: CollisionSetup
    t: np.ndarray
    contact_force: np.ndarray
    spring_force: np.ndarray
    finger_velocity: np.ndarray
    robot_velocity: np.ndarray
    impacts: tuple[tuple[float, float], ...]
    impulse: float
    detection_time: float
    reaction_time: float
    contact_end: float
    impulse_to_detection: float
    impulse_delay: float
    impulse_reaction: float
    robot_velocity_at_reaction: float
    actuator_work: float
    dissipated: float
    initial_energy: float
    final_energy: float
    events: tuple[tuple[float, str], ...] = field(default=())

    def __post_init__(self) -> None:
        if not np.isfinite(self.impulse) or self.impulse < 0:
            raise SimulationError(f"the simulated impulse is {self.impulse!r}; expected a finite value >= 0")

    @property
    def peak_force(self) -> float:
        """Largest contact force of the trace [N]."""
        return float(np.max(self.contact_force)) if self.contact_force.size else 0.0

    @property
    def energy_residual(self) -> float:
        """``final - initial - work + dissipated`` [J]: zero up to integration error."""
        return self.final_energy - self.initial_energy - self.actuator_work + self.dissipated
