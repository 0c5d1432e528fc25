"""The arm closed form of a design at one configuration and direction, against a contact of given stiffness.

A design's joint parameters (:class:`JointDesign`), put on an arm, give the effective 1D parameters along the
collision direction and the closed form's impulse for either placement of the reflected inertia and each
reaction model; :mod:`collision_reflex.simulate.validity` compares them with the arm simulator.
"""

from __future__ import annotations

import copy
import dataclasses
import math
from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

from .. import _validate
from ..arm.effective import effective_parameters
from ..errors import InvalidParameter
from ..model.impulse import phase_impulses, series_stiffness, sprung_reaction
from ..model.joint_space import DETECTIONS as JOINT_SPACE_DETECTIONS
from ..model.joint_space import JointSpaceArm
from ..vocabulary import REACTION_MODES, REFLECTED_INERTIA_PLACEMENTS
from .dynamics import admittance_share

REACTION_MODELS: tuple[str, ...] = ("constant", "sprung", "joint_space")
"""The closed form's reaction: ``"constant"``, the paper's constant acceleration ``a = F_a / m_r``;
``"sprung"``, :func:`collision_reflex.model.impulse.sprung_reaction` (the compressed spring also pushes the
robot mass away, the term the constant acceleration leaves out); ``"joint_space"``,
:func:`collision_reflex.model.joint_space.joint_space_collision` (all three phases with the links' motion along
the wall, linearised at ``q``; it places each inertia where the arm has it, so it is the same under both
placements, and it takes the contact as rigid: against a compliant object it leaves the object out)."""


@dataclass(frozen=True)
class JointDesign:
    """A design's joint parameters, one value per joint or one for all, and its detection threshold.

    Attributes
    ----------
    mechanical_stiffness: joint spring between link and motor [N m/rad], finite.
    reflected_inertia: ``N^2 J_m`` per joint [kg m^2].
    torque_limit: output torque limit per joint [N m].
    threshold: contact-force threshold of the detector ``F_s`` [N].
    software_stiffness: joint software stiffness [N m/rad]; ``inf`` for ideally velocity-controlled motors.
    motor_mass: motor (and gearbox) mass per joint [kg], carried by the parent link; None: the arm's.
    software_damping: the impedance drive's joint damping [N m s/rad] (``drive="impedance"`` only).
    """

    mechanical_stiffness: Any
    reflected_inertia: Any
    torque_limit: Any
    threshold: float
    software_stiffness: Any = math.inf
    motor_mass: Any = None
    software_damping: Any = 0.0

    def on(self, arm: Any) -> Any:
        """``arm`` with this design's motor masses (the arm itself when they are the arm's)."""
        if self.motor_mass is None:
            return arm
        params = arm.joint_parameters
        mass = np.broadcast_to(np.asarray(self.motor_mass, dtype=float), params.motor_mass.shape)
        _validate.non_negative("motor_mass", mass)
        out = copy.copy(arm)
        out.joint_parameters = dataclasses.replace(params, motor_mass=mass.copy())
        return out

    def simulator_keywords(self) -> dict[str, Any]:
        """The keywords of :func:`simulate_arm_collision` that carry the joint parameters."""
        return {
            "mechanical_stiffness": self.mechanical_stiffness,
            "reflected_inertia": self.reflected_inertia,
            "torque_limit": self.torque_limit,
            "software_stiffness": self.software_stiffness,
            "software_damping": self.software_damping,
        }


@dataclass(frozen=True)
class ArmClosedForm:
    """The arm closed form at one configuration and direction, against a contact of given stiffness.

    Attributes
    ----------
    m_f, m_r: effective finger and robot masses along ``u`` [kg]; k, k_m: lumped and mechanical stiffness along
    ``u``, each in series with the contact [N/m]; F_a: the motors' force along ``-u`` [N]; a: reaction
    acceleration ``F_a / m_r`` [m/s^2]; v_r: robot velocity at detection along ``u`` per unit approach velocity
    [-]; threshold: ``F_s`` [N]; reaction: ``"moving"`` or ``"at_rest"``.
    """

    m_f: float
    m_r: float
    k: float
    k_m: float
    F_a: float
    a: float
    v_r: float
    threshold: float
    reaction: str
    joint_space: JointSpaceArm | None = None

    def impulse(self, approach_velocity: float, model: str = "constant", detection: str = "force") -> float:
        """The closed form's impulse [N*s] at the approach velocity [m/s] with a reaction of :data:`REACTION_MODELS`.

        ``detection`` (a scheme of the simulator) matters to ``"joint_space"`` only, which models the contact
        force, spring-torque and position signals (:data:`collision_reflex.model.joint_space.DETECTIONS`) and
        takes the contact force for the others (the observer estimates it, lagged).
        """
        _validate.choice("model", model, REACTION_MODELS)
        v0 = float(approach_velocity)
        if model == "joint_space":
            if self.joint_space is None:
                raise InvalidParameter("model", model, "a closed form made by arm_closed_form")
            scheme = detection if detection in JOINT_SPACE_DETECTIONS else "force"
            return self.joint_space.collision(self.threshold, v0, detection=scheme).total
        robot_velocity = self.v_r * v0 if self.reaction == "moving" else None
        phases = phase_impulses(
            self.m_f, self.k, self.k_m, self.threshold, self.a, v0, self.reaction, robot_velocity
        )
        if model == "constant":
            return float(phases.total)
        _, reaction = sprung_reaction(self.threshold, self.k_m, self.F_a, self.m_r, robot_velocity or 0.0)
        return float(phases.initial + phases.sensing + reaction)


def arm_closed_form(
    arm: Any,
    q: npt.ArrayLike,
    direction: npt.ArrayLike,
    joints: JointDesign,
    placement: str = "robot",
    contact_stiffness: float = math.inf,
    reaction: str = "moving",
    stiffness_form: str = "compliance",
) -> ArmClosedForm:
    """The arm closed form of a design at configuration ``q`` [rad] along ``direction``.

    Parameters
    ----------
    arm: a :class:`collision_reflex.Arm`.
    q: configuration (nq,) [rad]; direction: collision direction in task coordinates, normalised here.
    joints: the design's joint parameters.
    placement: ``"robot"`` or ``"finger"`` (reflected inertia also in ``m_f``).
    contact_stiffness: stiffness of the object hit [N/m], in series with ``k`` and ``k_m``; ``inf``: rigid.
    reaction: ``"moving"`` (robot still moving at detection, as the simulation) or ``"at_rest"``.
    stiffness_form: the form of ``k``, ``"compliance"`` (the links free along the wall) or ``"paper"`` (blocked;
        square Jacobians only), see :func:`collision_reflex.arm.effective.effective_parameters`.
    """
    arm = joints.on(arm)
    _validate.choice("placement", placement, REFLECTED_INERTIA_PLACEMENTS)
    _validate.choice("reaction", reaction, REACTION_MODES)
    _validate.positive("contact_stiffness", contact_stiffness, allow_inf=True)
    nv = int(arm.nv)
    inertia = np.broadcast_to(np.asarray(joints.reflected_inertia, dtype=float), (nv,))
    k_m = np.broadcast_to(np.asarray(joints.mechanical_stiffness, dtype=float), (nv,))
    k_s = np.broadcast_to(np.asarray(joints.software_stiffness, dtype=float), (nv,))
    u = np.asarray(direction, dtype=float).reshape(-1)
    u = u / np.linalg.norm(u)
    samples = arm.kinematics(np.asarray(q, dtype=float)[None])
    motor_mass = np.asarray(arm.joint_parameters.motor_mass, dtype=float)
    effective = effective_parameters(
        samples,
        u[None],
        inertia,
        series_stiffness(k_m, k_s),
        k_m,
        joints.torque_limit,
        motor_mass=motor_mass if np.any(motor_mass > 0) else None,
        finger_joint_inertia=inertia if placement == "finger" else None,
        stiffness_form=stiffness_form,
    )
    if bool(effective.singular[0, 0]):
        raise InvalidParameter(
            "direction", direction, "a direction the arm can move along at q", "q is singular"
        )
    jac = samples.jacobian[0]
    v_r = float(u @ jac @ (admittance_share(k_m, k_s) * (np.linalg.pinv(jac) @ u)))
    value = {name: float(getattr(effective, name)[0, 0]) for name in ("m_f", "m_r", "k", "k_m", "F_a", "a")}
    return ArmClosedForm(
        m_f=value["m_f"],
        m_r=value["m_r"],
        k=float(series_stiffness(value["k"], contact_stiffness)),
        k_m=float(series_stiffness(value["k_m"], contact_stiffness)),
        F_a=value["F_a"],
        a=value["a"],
        v_r=v_r,
        threshold=float(joints.threshold),
        reaction=reaction,
        joint_space=JointSpaceArm(
            samples.structure_mass_matrix(motor_mass if np.any(motor_mass > 0) else None)[0],
            jac,
            u,
            k_m,
            inertia,
            joints.torque_limit,
            k_s,
        ),
    )
