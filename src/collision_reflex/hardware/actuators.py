"""Actuators: a motor, a transmission, joint stiffness and a collision-sensing scheme.

An :class:`Actuator` turns a motor (:mod:`collision_reflex.hardware.motors`), a gear ratio ``N`` and an optional gearbox
into joint quantities: reflected inertia ``N**2 J_m``, peak output torque ``N tau_p``, the series joint
stiffness of its mechanical and software springs, and its mass. For a rotary joint acting on a contact point at
lever ``L`` it gives the 1D collision parameters of the model in :mod:`collision_reflex.model.impulse` (mass
``J/L**2``, stiffness ``k_rot/L**2``, force ``tau/L``), with the sensing threshold from its sensing scheme:

- :class:`ForceThreshold`: a fixed contact force ``F_s`` (a force sensor or an external-force observer);
- :class:`PositionThreshold`: a position-error threshold ``e_th``, so ``F_s = k e_th`` grows with stiffness;
- :class:`CurrentThreshold`: a motor-current (torque) threshold on the motor side of the transmission, so the
  joint threshold torque is ``N tau_s`` (plus any joint friction).

Joint units: stiffness [N m/rad], torque [N m], inertia [kg m^2], angles [rad].
"""

from __future__ import annotations

import math
import numbers
from dataclasses import dataclass, field
from typing import Any, Protocol

import numpy as np
from numpy.typing import ArrayLike

from .. import _validate
from ..errors import InvalidParameter
from ..model import effective
from ..model.impulse import series_stiffness
from ..model.sensing import current_threshold_torque, threshold_force
from ..vocabulary import REFLECTED_INERTIA_PLACEMENTS
from .gearboxes import Gearbox
from .motors import Motor

__all__ = [
    "Actuator",
    "CollisionParameters",
    "CurrentThreshold",
    "ForceThreshold",
    "PositionThreshold",
    "SensingScheme",
    "gear_ratio_for",
]


def gear_ratio_for(torque_required: ArrayLike, peak_torque: ArrayLike) -> float | np.ndarray:
    """The smallest gear ratio that meets a torque requirement: ``N = max(1, tau_req / tau_p)``.

    Floats and NumPy arrays (broadcast); the paper's sweep rule (``tab:motor_params``).

    Parameters
    ----------
    torque_required: output torque the joint must deliver [N m], > 0.
    peak_torque: the motor's peak torque ``tau_p`` [N m], > 0.
    """
    required = np.asarray(_validate.positive("torque_required", torque_required))
    peak = np.asarray(_validate.positive("peak_torque", peak_torque))
    with _validate.combining(torque_required=required, peak_torque=peak):
        ratio = np.maximum(1.0, required / peak)
    return ratio if ratio.ndim else float(ratio)


class SensingScheme(Protocol):
    """How a collision is detected: gives the joint threshold torque of an actuator."""

    def joint_threshold_torque(self, actuator: Actuator, lever: float | None = None) -> float:
        """Joint torque at detection [N m]."""
        ...

    def contact_threshold(self, actuator: Actuator, lever: float) -> float:
        """Contact force at detection [N] for a contact at ``lever`` [m]."""
        ...

    def describe(self) -> str:
        """One line naming the scheme and its threshold, with units."""
        ...


@dataclass(frozen=True)
class ForceThreshold:
    """Detection when the contact force reaches ``force`` [N] (force sensor or external-force observer).

    The threshold is fixed at the contact, so it does not change with stiffness or gear ratio. As a joint
    torque it needs the lever: see :meth:`Actuator.contact_parameters`.
    """

    force: float = 3.0

    def __post_init__(self) -> None:
        _validate.positive("ForceThreshold.force", self.force)

    def contact_threshold(self, actuator: Actuator, lever: float) -> float:
        """Contact force at detection [N]."""
        return float(self.force)

    def joint_threshold_torque(self, actuator: Actuator, lever: float | None = None) -> float:
        """Joint torque at detection [N m] for a contact at ``lever`` [m]: ``F_s L``."""
        if lever is None:
            raise InvalidParameter(
                "lever", lever, "a lever length [m]", "a contact-force threshold maps to a joint torque via L"
            )
        _validate.positive("lever", lever)
        return float(self.force) * lever

    def describe(self) -> str:
        """One line naming the scheme and its threshold [N]."""
        return f"force threshold F_s = {self.force:g} N"


@dataclass(frozen=True)
class PositionThreshold:
    """Detection when the position error reaches ``error`` [rad] at the joint.

    The error is the deflection of the whole joint (mechanical and software springs in series) from its
    commanded position, so the joint threshold torque is ``k e_th`` with ``k`` the actuator's series joint
    stiffness: a stiffer joint detects at a higher force (the paper's ``fig:stiff-sensing-impulse``).
    """

    error: float

    def __post_init__(self) -> None:
        _validate.positive("PositionThreshold.error", self.error)

    def joint_threshold_torque(self, actuator: Actuator, lever: float | None = None) -> float:
        """Joint torque at detection [N m]: ``k e_th`` with the series joint stiffness ``k`` (``lever`` unused)."""
        stiffness = actuator.stiffness
        if math.isinf(stiffness):
            raise InvalidParameter(
                "stiffness",
                stiffness,
                "a finite joint stiffness for a position-error threshold",
                "a rigid joint never builds a position error; give mechanical or software stiffness",
            )
        return float(threshold_force("position", self.error, stiffness))

    def contact_threshold(self, actuator: Actuator, lever: float) -> float:
        """Contact force at detection [N]: ``k e_th / L``."""
        _validate.positive("lever", lever)
        return self.joint_threshold_torque(actuator) / lever

    def describe(self) -> str:
        """One line naming the scheme and its threshold [rad]."""
        return f"position-error threshold e_th = {self.error:g} rad"


@dataclass(frozen=True)
class CurrentThreshold:
    """Detection when the motor torque (current times torque constant) reaches ``motor_torque`` [N m].

    The threshold sits on the motor side of the transmission, so at the joint it is ``N tau_s`` plus the
    joint friction the motor must overcome (the paper's geared A8 detects at about 40 N against 3 N for the
    direct-drive U8).

    Parameters
    ----------
    motor_torque: motor-side threshold torque ``tau_s`` [N m].
    friction_torque: joint-side friction torque added to the threshold [N m], default 0.
    """

    motor_torque: float
    friction_torque: float = 0.0

    def __post_init__(self) -> None:
        _validate.positive("CurrentThreshold.motor_torque", self.motor_torque)
        _validate.non_negative("CurrentThreshold.friction_torque", self.friction_torque)

    def joint_threshold_torque(self, actuator: Actuator, lever: float | None = None) -> float:
        """Joint torque at detection [N m]: ``N tau_s`` plus the friction torque (``lever`` unused)."""
        return float(current_threshold_torque(actuator.gear_ratio, self.motor_torque, self.friction_torque))

    def contact_threshold(self, actuator: Actuator, lever: float) -> float:
        """Contact force at detection [N]: ``(N tau_s + tau_friction) / L``."""
        _validate.positive("lever", lever)
        return self.joint_threshold_torque(actuator) / lever

    def describe(self) -> str:
        """One line naming the scheme and its thresholds [N m]."""
        text = f"motor-current threshold tau_s = {self.motor_torque:g} N m (motor side)"
        return text + (f" + friction {self.friction_torque:g} N m" if self.friction_torque else "")


@dataclass(frozen=True)
class CollisionParameters:
    """The 1D collision parameters at a contact point (arguments of :func:`collision_reflex.total_impulse`).

    ``m_f`` finger mass [kg], ``m_r`` robot mass [kg], ``k`` series stiffness [N/m], ``k_m`` mechanical
    stiffness [N/m], ``F_s`` threshold [N], ``a`` reaction acceleration [m/s^2], ``F_a`` reaction force [N].
    """

    m_f: float
    m_r: float
    k: float
    k_m: float
    F_s: float
    a: float
    F_a: float

    def __post_init__(self) -> None:
        for name in ("m_f", "m_r", "k", "k_m", "F_s", "a", "F_a"):
            _validate.positive(f"CollisionParameters.{name}", getattr(self, name))

    def impulse_arguments(self) -> dict[str, Any]:
        """Keyword arguments for :func:`collision_reflex.model.phase_impulses` (all but ``v0``)."""
        return {"m_f": self.m_f, "k": self.k, "k_m": self.k_m, "F_s": self.F_s, "a": self.a}


@dataclass(frozen=True)
class Actuator:
    """A joint actuator: motor, gear ratio, optional gearbox, joint stiffness and sensing scheme.

    Parameters
    ----------
    motor: the motor.
    gear_ratio: transmission ratio ``N`` >= 1 (1: direct drive).
    mechanical_stiffness: joint mechanical stiffness [N m/rad] (``inf``: rigid).
    software_stiffness: joint controller stiffness [N m/rad] (``inf``: ideal position control).
    sensing: collision detection scheme.
    gearbox: optional gearbox (mass, and inertia if ``gearbox_inertia``).
    gearbox_inertia: add the gearbox's reflected inertia; off by default, as in the paper.
    """

    motor: Motor
    gear_ratio: float = 1.0
    mechanical_stiffness: float = math.inf
    software_stiffness: float = math.inf
    sensing: ForceThreshold | PositionThreshold | CurrentThreshold = field(default_factory=ForceThreshold)
    gearbox: Gearbox | None = None
    gearbox_inertia: bool = False

    def __post_init__(self) -> None:
        if not isinstance(self.motor, Motor):
            raise InvalidParameter("Actuator.motor", self.motor, "a Motor")
        ratio = self.gear_ratio
        if isinstance(ratio, bool) or not isinstance(ratio, numbers.Real) or not (1 <= ratio < math.inf):
            raise InvalidParameter(
                "Actuator.gear_ratio",
                ratio,
                "a finite number >= 1",
                "N = 1 is direct drive; see gear_ratio_for",
            )
        object.__setattr__(self, "gear_ratio", float(ratio))
        _validate.positive("Actuator.mechanical_stiffness", self.mechanical_stiffness, allow_inf=True)
        _validate.positive("Actuator.software_stiffness", self.software_stiffness, allow_inf=True)
        if not isinstance(self.sensing, ForceThreshold | PositionThreshold | CurrentThreshold):
            raise InvalidParameter(
                "Actuator.sensing", self.sensing, "a ForceThreshold, PositionThreshold or CurrentThreshold"
            )
        if self.gearbox is not None and not isinstance(self.gearbox, Gearbox):
            raise InvalidParameter("Actuator.gearbox", self.gearbox, "a Gearbox or None")
        if not isinstance(self.gearbox_inertia, bool | np.bool_):
            raise InvalidParameter("Actuator.gearbox_inertia", self.gearbox_inertia, "True or False")
        if self.gearbox_inertia and self.gearbox is None:
            raise InvalidParameter(
                "Actuator.gearbox_inertia", True, "False without a gearbox", "pass gearbox=Gearbox(...)"
            )

    @property
    def rotor_reflected_inertia(self) -> float:
        """Rotor inertia seen at the joint, ``N**2 J_m`` [kg m^2]."""
        return float(effective.reflected_inertia(self.gear_ratio, self.motor.rotor_inertia))

    @property
    def reflected_inertia(self) -> float:
        """Inertia seen at the joint [kg m^2]: ``N**2 J_m``, plus the gearbox's if ``gearbox_inertia``."""
        inertia = self.rotor_reflected_inertia
        if self.gearbox_inertia and self.gearbox is not None:
            inertia += float(self.gearbox.reflected_inertia(self.gear_ratio))
        return inertia

    @property
    def peak_torque(self) -> float:
        """Peak output torque ``N tau_p`` [N m] of the motor (see :attr:`torque_limit` for the gearbox's cap)."""
        return self.gear_ratio * self.motor.peak_torque

    @property
    def torque_limit(self) -> float:
        """Largest output torque [N m]: ``N tau_p``, capped by the gearbox's rated torque if there is one."""
        if self.gearbox is None:
            return self.peak_torque
        return min(self.peak_torque, self.gearbox.rated_torque)

    @property
    def continuous_torque(self) -> float:
        """Continuous output torque ``N tau_c`` [N m]."""
        return self.gear_ratio * self.motor.continuous_torque

    @property
    def stiffness(self) -> float:
        """Joint stiffness, mechanical and software springs in series [N m/rad] (``inf`` if both rigid)."""
        if math.isinf(self.mechanical_stiffness) and math.isinf(self.software_stiffness):
            return math.inf  # no compliance at all (series_stiffness would divide by zero)
        return float(series_stiffness(self.mechanical_stiffness, self.software_stiffness))

    @property
    def mass(self) -> float:
        """Motor mass plus gearbox mass [kg]."""
        return self.motor.mass + (self.gearbox.mass if self.gearbox is not None else 0.0)

    def contact_parameters(
        self,
        lever: float,
        m_f: float = 0.0,
        m_r: float = 0.0,
        reflected_inertia_in: str = "robot",
    ) -> CollisionParameters:
        """The 1D collision parameters of a rotary joint acting on a contact point at ``lever``.

        A joint inertia ``J`` appears at the contact as ``J/L**2``, a joint stiffness as ``k/L**2`` and a
        torque as ``tau/L``. The reflected inertia always counts in the robot mass that the reaction
        accelerates away; ``reflected_inertia_in`` says whether it also reaches the contact in the impact:

        - ``"robot"`` (the arm model's placement): the compliance sits between the rotor and the finger, so the
          finger mass is only ``m_f``;
        - ``"finger"``: a rigid transmission with the compliance at the contact (like the paper's geared A8,
          whose fitted finger mass was 20 kg), so ``N**2 J_m / L**2`` is added to the finger mass too.

        Parameters
        ----------
        lever: distance from the joint axis to the contact point, perpendicular to the motion [m].
        m_f: sprung (link) mass at the contact [kg].
        m_r: unsprung mass at the contact besides the reflected inertia [kg].
        reflected_inertia_in: ``"robot"`` or ``"finger"``.
        """
        _validate.positive("lever", lever)
        _validate.non_negative("m_f", m_f)
        _validate.non_negative("m_r", m_r)
        _validate.choice("reflected_inertia_in", reflected_inertia_in, REFLECTED_INERTIA_PLACEMENTS)
        reflected_mass = self.reflected_inertia / lever**2
        finger = m_f + effective.finger_inertia(reflected_mass, float(reflected_inertia_in == "finger"))
        if finger <= 0:
            raise InvalidParameter(
                "m_f",
                m_f,
                "a number > 0 when the reflected inertia is not in the finger",
                "give the link's sprung mass at the contact",
            )
        robot = m_r + reflected_mass
        k_m = self.mechanical_stiffness / lever**2
        if math.isinf(k_m):
            raise InvalidParameter(
                "Actuator.mechanical_stiffness",
                self.mechanical_stiffness,
                "a finite stiffness for a collision",
                "a rigid joint meets a rigid constraint with an infinite force; give the structure's stiffness",
            )
        k = self.stiffness / lever**2
        F_a = self.peak_torque / lever
        return CollisionParameters(
            m_f=finger,
            m_r=robot,
            k=k,
            k_m=k_m,
            F_s=float(self.sensing.contact_threshold(self, lever)),
            a=F_a / robot,
            F_a=F_a,
        )
