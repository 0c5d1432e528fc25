"""An actuator design: the motor, gear ratio and stiffness of every joint, and the quantities they give.

:func:`layout_design` reads a design from the NLP's variables (log values, as :mod:`.layout` lays them out),
:func:`design_at` from a :class:`DesignProblem`'s point.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from .layout import DesignLayout
    from .problem import DesignProblem
    from .technology import ActuatorTechnology


@dataclass(frozen=True)
class Design:
    """An actuator design for every joint of an arm, with the quantities derived from it (SI units).

    Per joint (arrays of length n_joints): ``stator_diameter`` [m], ``stack_length`` [m], ``gear_ratio`` [-],
    ``software_stiffness`` and ``mechanical_stiffness`` [N m/rad], ``rotor_inertia`` [kg m^2],
    ``reflected_inertia`` = N^2 (J_m + J_g) [kg m^2] (``J_g`` the gearbox's input inertia where counted),
    ``motor_peak_torque`` [N m], ``peak_torque`` = N tau_p [N m], ``motor_mass`` [kg] (the motor's own).
    Global: ``threshold`` ([N] for force sensing, [m] for position sensing) and ``approach_velocity`` [m/s].
    Per joint, its gearbox: ``gearbox`` its catalogue name ("" for none), ``gearbox_mass`` [kg],
    ``gearbox_inertia`` its input-side inertia [kg m^2] (as the catalogue gives it, also when the reflected
    inertia leaves it out), ``gearbox_efficiency`` [-] (1 without a gearbox). Left out, there are none.
    """

    joint_names: tuple[str, ...]
    stator_diameter: np.ndarray
    stack_length: np.ndarray
    gear_ratio: np.ndarray
    software_stiffness: np.ndarray
    mechanical_stiffness: np.ndarray
    rotor_inertia: np.ndarray
    reflected_inertia: np.ndarray
    motor_peak_torque: np.ndarray
    peak_torque: np.ndarray
    motor_mass: np.ndarray
    threshold: float
    approach_velocity: float
    sensing: str
    gearbox: tuple[str, ...] = ()
    gearbox_mass: np.ndarray = field(default_factory=lambda: np.empty(0))
    gearbox_inertia: np.ndarray = field(default_factory=lambda: np.empty(0))
    gearbox_efficiency: np.ndarray = field(default_factory=lambda: np.empty(0))

    def __post_init__(self) -> None:
        n = len(self.joint_names)
        if not self.gearbox:
            object.__setattr__(self, "gearbox", ("",) * n)
        for name, absent in (("gearbox_mass", 0.0), ("gearbox_inertia", 0.0), ("gearbox_efficiency", 1.0)):
            value = np.asarray(getattr(self, name), dtype=float)
            object.__setattr__(self, name, np.full(n, absent) if value.size == 0 else value)

    @property
    def actuator_mass(self) -> np.ndarray:
        """Per joint the mass carried at the joint [kg]: the motor's and the gearbox's."""
        return self.motor_mass + self.gearbox_mass

    @property
    def driving_peak_torque(self) -> np.ndarray:
        """Per joint the peak output torque that drives the arm ``eta N tau_p`` [N m]."""
        return self.gearbox_efficiency * self.peak_torque

    def as_dict(self) -> dict[str, Any]:
        """Plain lists and floats, for JSON."""
        out: dict[str, Any] = {}
        for name, value in self.__dict__.items():
            out[name] = (
                value.tolist()
                if isinstance(value, np.ndarray)
                else (list(value) if isinstance(value, tuple) else value)
            )
        return out


def design_at(problem: DesignProblem, x: np.ndarray) -> Design:
    """The design (and its derived actuator quantities) at NLP point ``x``."""
    return layout_design(problem.layout, problem.technology, problem.joint_names, x)


def layout_design(
    layout: DesignLayout, technology: ActuatorTechnology, joint_names: tuple[str, ...], x: np.ndarray
) -> Design:
    """The design at ``x`` (its design part, log values as ``layout`` lays them out) of ``technology``."""
    values = layout.values(np.asarray(x, dtype=float))
    gear = values["gear_ratio"]
    joint = technology.joint_quantities(values["stator_diameter"], values["stack_length"], gear)
    motor = joint.motor
    gearbox = technology.gearbox_figures(len(joint_names), np.asarray(joint.peak_torque, dtype=float))
    return Design(
        joint_names=joint_names,
        stator_diameter=values["stator_diameter"],
        stack_length=values["stack_length"],
        gear_ratio=gear,
        software_stiffness=values["software_stiffness"],
        mechanical_stiffness=technology.joint_mechanical_stiffness(len(joint_names)),
        rotor_inertia=np.asarray(motor.rotor_inertia, dtype=float),
        reflected_inertia=np.asarray(joint.reflected_inertia, dtype=float),
        motor_peak_torque=np.asarray(motor.peak_torque, dtype=float),
        peak_torque=np.asarray(joint.peak_torque, dtype=float),
        motor_mass=np.asarray(motor.mass, dtype=float),
        threshold=float(values["threshold"][0]),
        approach_velocity=float(values["approach_velocity"][0]),
        sensing=technology.sensing,
        gearbox=gearbox.names,
        gearbox_mass=gearbox.mass,
        gearbox_inertia=gearbox.inertia,
        gearbox_efficiency=gearbox.efficiency,
    )
