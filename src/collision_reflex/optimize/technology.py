"""The fixed actuation choices a design varies within.

They are the reference motor (one for every joint, or one per joint), the scaling law, the mechanical
stiffness, the sensing scheme and the reaction model. A catalogue motor is a joint's reference motor with its
stator diameter and stack length fixed at its own: its quantities are then its datasheet figures (scale factor
one), which is how a design is built from catalogue parts.

A joint may also have a gearbox (:attr:`ActuatorTechnology.gearboxes`, catalogue entries): its mass is carried
at the joint like the motor's, its input-side inertia adds to the rotor's, its efficiency scales the output
torque that drives the arm, and its torque and speed ratings bound the design
(:meth:`ActuatorTechnology.joint_quantities` is the one place these enter).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, NamedTuple

import numpy as np

from .. import _validate
from ..errors import InvalidParameter
from ..hardware.gearboxes import CatalogueGearbox, ScaledGearbox
from ..hardware.motors import Motor, MotorQuantities, scaled_motor_quantities
from ..model.effective import reflected_inertia
from ..model.sensing import sensing_scheme
from ..vocabulary import OPTIMIZED_SENSING_SCHEMES, REACTION_MODES, REFLECTED_INERTIA_PLACEMENTS


@dataclass(frozen=True)
class ActuatorTechnology:
    """The fixed choices of actuation the design varies within.

    reference_motor: motor every joint's motor is scaled from, or one motor per joint (a tuple).
    scaling_law: motor scaling law name (see :data:`collision_reflex.hardware.motors.SCALING_LAWS`).
    mechanical_stiffness: joint mechanical stiffness [N m/rad], one value or one per joint, finite > 0: it is
        the only spring left in the reaction phase.
    sensing: ``"force"`` (contact-force threshold) or ``"position"`` (contact position-error threshold), see
        :data:`collision_reflex.vocabulary.OPTIMIZED_SENSING_SCHEMES`.
    reaction: reaction-phase model, ``"at_rest"`` (the paper's) or ``"moving"``.
    reflected_inertia_in: where the reflected rotor inertia ``N^2 J_m`` acts. ``"robot"`` (default, the paper's
        arm model): behind the joint springs, in the robot mass ``m_r`` of the reaction phase only.
        ``"finger"``: also rigidly on the link side, in the finger mass ``m_f`` of the impact phase -- a stiff
        transmission with the compliance at the contact, as the paper measured for its geared A8 actuator
        (fitted finger mass 20 kg against 0.12 kg direct-drive).
    gearboxes: one gearbox per joint (None at a joint: direct drive, or no gearbox model there), or None for
        none at all: a catalogue unit (fixed figures) or a :class:`~collision_reflex.hardware.gearboxes.
        ScaledGearbox` (sized to carry the motor's peak output torque ``N tau_p``). See :func:`joint_quantities`
        for what a gearbox changes.
    gearbox_inertia: count the gearboxes' input-side inertia in the reflected inertia ``N^2 (J_m + J_g)``;
        False is the paper's choice (gearbox inertia ignored: ``N^2 J_m``).
    """

    reference_motor: Motor | tuple[Motor, ...]
    mechanical_stiffness: float | Sequence[float]
    scaling_law: str = "haddadin"
    sensing: str = "force"
    reaction: str = "at_rest"
    reflected_inertia_in: str | tuple[str, ...] = "robot"
    gearboxes: tuple[CatalogueGearbox | ScaledGearbox | None, ...] | None = None
    gearbox_inertia: bool = True

    def __post_init__(self) -> None:
        _validate.positive("mechanical_stiffness", np.asarray(self.mechanical_stiffness, dtype=float))
        if not isinstance(self.reference_motor, Motor):
            motors = tuple(self.reference_motor)
            if not motors or not all(isinstance(m, Motor) for m in motors):
                raise InvalidParameter(
                    "reference_motor", self.reference_motor, "a Motor or a tuple of Motors"
                )
            object.__setattr__(self, "reference_motor", motors)
        object.__setattr__(self, "sensing", sensing_scheme(self.sensing, OPTIMIZED_SENSING_SCHEMES))
        _validate.choice("reaction", self.reaction, REACTION_MODES)
        if isinstance(self.reflected_inertia_in, str):
            _validate.choice("reflected_inertia_in", self.reflected_inertia_in, REFLECTED_INERTIA_PLACEMENTS)
        else:
            placements = tuple(self.reflected_inertia_in)
            for j, placement in enumerate(placements):
                _validate.choice(f"reflected_inertia_in[{j}]", placement, REFLECTED_INERTIA_PLACEMENTS)
            object.__setattr__(self, "reflected_inertia_in", placements)
        if self.gearboxes is not None:
            gearboxes = tuple(self.gearboxes)
            if not all(g is None or isinstance(g, (CatalogueGearbox, ScaledGearbox)) for g in gearboxes):
                raise InvalidParameter(
                    "gearboxes",
                    self.gearboxes,
                    "one CatalogueGearbox, ScaledGearbox or None per joint, or None",
                )
            for gearbox in gearboxes:
                if gearbox is not None and gearbox.efficiency is not None:
                    if not 0 < gearbox.efficiency <= 1:
                        raise InvalidParameter(
                            f"gearbox {gearbox.name!r} efficiency", gearbox.efficiency, "a number in (0, 1]"
                        )
            object.__setattr__(self, "gearboxes", gearboxes)
        if not isinstance(self.gearbox_inertia, bool):
            raise InvalidParameter("gearbox_inertia", self.gearbox_inertia, "True or False")

    def finger_joints(self, n_joints: int) -> tuple[bool, ...]:
        """Per joint whether its reflected inertia takes part in the impact (``reflected_inertia_in: finger``).

        Raises
        ------
        InvalidParameter: per-joint placements not one per joint.
        """
        placements = self.reflected_inertia_in
        if isinstance(placements, str):
            return (placements == "finger",) * n_joints
        if len(placements) != n_joints:
            raise InvalidParameter(
                "reflected_inertia_in", placements, f"one placement or {n_joints}, one per joint"
            )
        return tuple(p == "finger" for p in placements)

    def joint_mechanical_stiffness(self, n_joints: int) -> np.ndarray:
        """The mechanical stiffness of each of ``n_joints`` joints [N m/rad], shape (n_joints,)."""
        return np.broadcast_to(np.asarray(self.mechanical_stiffness, dtype=float), (n_joints,)).copy()

    @property
    def motors(self) -> tuple[Motor, ...]:
        """The reference motors: the one of every joint, or each joint's."""
        return (self.reference_motor,) if isinstance(self.reference_motor, Motor) else self.reference_motor

    def joint_motors(self, n_joints: int) -> tuple[Motor, ...]:
        """The reference motor of each of ``n_joints`` joints."""
        if isinstance(self.reference_motor, Motor):
            return (self.reference_motor,) * n_joints
        if len(self.reference_motor) != n_joints:
            raise InvalidParameter(
                "reference_motor", len(self.reference_motor), f"one motor for all joints or {n_joints} motors"
            )
        return self.reference_motor

    def motor_quantities(self, stator_diameter: Any, stack_length: Any) -> MotorQuantities:
        """Each joint's motor quantities at its stator diameter and stack length [m] (one entry per joint).

        Works on NumPy arrays and CasADi columns alike (:func:`~collision_reflex.hardware.motors.
        scaled_motor_quantities`); ``max_speed`` is None when any joint's reference motor has none.
        """
        if isinstance(self.reference_motor, Motor):
            return scaled_motor_quantities(
                self.reference_motor, stator_diameter, stack_length, self.scaling_law
            )
        import casadi as ca  # lazily: the package imports without CasADi's start-up cost

        symbolic = isinstance(stator_diameter, (ca.MX, ca.SX, ca.DM))
        motors = self.joint_motors(stator_diameter.shape[0] if symbolic else np.size(stator_diameter))
        diameters = (
            stator_diameter if symbolic else np.broadcast_to(np.asarray(stator_diameter, float), len(motors))
        )
        lengths = stack_length if symbolic else np.broadcast_to(np.asarray(stack_length, float), len(motors))
        joints = [
            scaled_motor_quantities(motor, diameters[j], lengths[j], self.scaling_law)
            for j, motor in enumerate(motors)
        ]

        def stacked(field: str) -> Any:
            parts = [getattr(q, field) for q in joints]
            return ca.vertcat(*parts) if symbolic else np.array(parts, dtype=float)

        speeds = None if any(q.max_speed is None for q in joints) else stacked("max_speed")
        return MotorQuantities(
            stacked("rotor_inertia"),
            stacked("peak_torque"),
            stacked("continuous_torque"),
            stacked("mass"),
            speeds,
        )

    def joint_gearboxes(self, n_joints: int) -> tuple[CatalogueGearbox | ScaledGearbox | None, ...]:
        """The gearbox of each of ``n_joints`` joints (None: no gearbox at that joint)."""
        if self.gearboxes is None:
            return (None,) * n_joints
        if len(self.gearboxes) != n_joints:
            raise InvalidParameter(
                "gearboxes", len(self.gearboxes), f"one gearbox (or None) per joint: {n_joints}"
            )
        return self.gearboxes

    def gearbox_figures(self, n_joints: int, peak_torque: np.ndarray | None = None) -> GearboxFigures:
        """The figures of each joint's gearbox as arrays (n_joints,); see :class:`GearboxFigures`.

        A scaled gearbox's figures are those of its size at the joint's peak output torque ``N tau_p``
        ``peak_torque`` [N m]; without it, its constant part: its efficiency, none of its mass and inertia
        (:meth:`joint_quantities` adds them), and as its repeated peak rating the largest unit of its kind one can
        buy (infinite when not known): its own rating is ``N tau_p``, which the driving torque ``eta N tau_p`` a
        requirement must be within never exceeds, so the requirement is bounded by what can be bought.
        """
        gearboxes = self.joint_gearboxes(n_joints)
        scaled = {
            j: g.figures(float(peak_torque[j])) if peak_torque is not None else None
            for j, g in enumerate(gearboxes)
            if isinstance(g, ScaledGearbox)
        }

        def figure(name: str, absent: float) -> np.ndarray:
            values = []
            for j, g in enumerate(gearboxes):
                if j in scaled:
                    assert isinstance(g, ScaledGearbox)
                    at = scaled[j]
                    value = getattr(at, name, None) if at is not None else None
                    if name == "efficiency":
                        value = g.efficiency
                    elif name == "peak_torque" and at is None and g.largest is not None:
                        value = g.largest.peak_torque
                else:
                    value = getattr(g, name, None) if g is not None else None
                values.append(absent if value is None else float(value))
            return np.array(values, dtype=float)

        inertia = figure("inertia", 0.0)
        return GearboxFigures(
            names=tuple("" if g is None else g.name for g in gearboxes),
            mass=figure("mass", 0.0),
            inertia=inertia,
            counted_inertia=inertia if self.gearbox_inertia else np.zeros(n_joints),
            efficiency=figure("efficiency", 1.0),
            peak_torque=figure("peak_torque", np.inf),
            rated_torque=figure("rated_torque", np.inf),
            max_input_speed=figure("max_input_speed", np.inf),
        )

    def joint_quantities(self, stator_diameter: Any, stack_length: Any, gear_ratio: Any) -> JointQuantities:
        """Each joint's actuator (motor and gearbox) at its motor size [m] and gear ratio [-], joint side.

        The one place the gearbox enters (NumPy arrays and CasADi columns alike): the mass carried at the joint
        is the motor's plus the gearbox's [kg]; the reflected inertia ``N^2 (J_m + J_g)`` [kg m^2] (``J_g``
        zero unless :attr:`gearbox_inertia`); the peak torque ``N tau_p`` [N m] bounds the reaction; the
        driving torques ``eta N tau_p`` and ``eta N tau_c`` [N m] must cover the torque requirements.

        The efficiency ``eta`` applies to driving torque only, where the motor drives the arm through the
        gearbox (the static, given and duty-cycle requirements). The collision model's reaction (its
        backdriving) keeps ``N tau_p``: there the motor's torque brakes its own rotor (the reflected inertia
        ``m_r``, ``a = F_a / m_r``) while the contact pushes the link back through the gearbox, so power flows
        from the load into the gearbox, whose friction then opposes the motion and adds to the braking.
        Leaving it out keeps the paper's reaction model and can only overestimate the impulse.
        """
        motor = self.motor_quantities(stator_diameter, stack_length)
        gearbox = self.gearbox_figures(_rows(gear_ratio))
        peak = gear_ratio * motor.peak_torque
        continuous = gear_ratio * motor.continuous_torque
        if self.gearboxes is None:  # no gearbox anywhere: the motor's quantities, not a term added
            return JointQuantities(
                motor,
                gearbox,
                motor.mass,
                reflected_inertia(gear_ratio, motor.rotor_inertia),
                peak,
                peak,
                continuous,
            )
        mass, counted, efficiency = (
            _column(v, gear_ratio) for v in (gearbox.mass, gearbox.counted_inertia, gearbox.efficiency)
        )
        scaled_mass, scaled_inertia = self._scaled_terms(peak)
        return JointQuantities(
            motor=motor,
            gearbox=gearbox,
            actuator_mass=motor.mass + mass + scaled_mass,
            reflected_inertia=reflected_inertia(gear_ratio, motor.rotor_inertia + counted + scaled_inertia),
            peak_torque=peak,
            driving_peak_torque=efficiency * peak,
            driving_continuous_torque=efficiency * continuous,
        )

    def _scaled_terms(self, peak_torque: Any) -> tuple[Any, Any]:
        """The scaled gearboxes' masses [kg] and counted input inertias [kg m^2] at the joints' ``N tau_p``.

        Zero at the other joints; NumPy arrays or CasADi columns as ``peak_torque`` [N m] is.
        """
        import casadi as ca  # lazily: the package imports without CasADi's start-up cost

        symbolic = isinstance(peak_torque, (ca.MX, ca.SX, ca.DM))
        n = _rows(peak_torque)
        gearboxes = self.joint_gearboxes(n)
        masses: list[Any] = [0.0] * n
        inertias: list[Any] = [0.0] * n
        for j, gearbox in enumerate(gearboxes):
            if isinstance(gearbox, ScaledGearbox):
                figures = gearbox.figures(peak_torque[j])
                masses[j] = figures.mass
                inertias[j] = figures.inertia if self.gearbox_inertia else 0.0
        if symbolic:
            return ca.vertcat(*masses), ca.vertcat(*inertias)
        return np.array(masses, dtype=float), np.array(inertias, dtype=float)

    def default_stack_lengths(self, n_joints: int) -> list[float]:
        """Each joint's reference motor's stack length [m]: the stack length when the design leaves it out."""
        return [motor.stack_length for motor in self.joint_motors(n_joints)]


class GearboxFigures(NamedTuple):
    """Each joint's gearbox figures, (n_joints,) arrays; a joint without a gearbox has the neutral values.

    names: catalogue names ("" without a gearbox); mass [kg] (0); inertia: input-side inertia ``J_g`` [kg m^2]
    (0); counted_inertia: ``J_g`` as the reflected inertia counts it (0 unless ``gearbox_inertia``);
    efficiency [-] (1, also when the catalogue gives none); peak_torque: repeated peak output torque [N m],
    rated_torque: rated output torque [N m], max_input_speed [rad/s] (inf where not given).
    """

    names: tuple[str, ...]
    mass: np.ndarray
    inertia: np.ndarray
    counted_inertia: np.ndarray
    efficiency: np.ndarray
    peak_torque: np.ndarray
    rated_torque: np.ndarray
    max_input_speed: np.ndarray


class JointQuantities(NamedTuple):
    """Each joint's actuator quantities, joint side (see :meth:`ActuatorTechnology.joint_quantities`).

    motor: the motor's own quantities; gearbox: the gearbox figures (a scaled gearbox's constant part,
    :meth:`ActuatorTechnology.gearbox_figures`); actuator_mass: motor plus gearbox mass [kg]; reflected_inertia: ``N^2 (J_m + J_g)`` [kg m^2]; peak_torque: ``N tau_p`` [N m];
    driving_peak_torque: ``eta N tau_p`` [N m]; driving_continuous_torque: ``eta N tau_c`` [N m].
    """

    motor: MotorQuantities
    gearbox: GearboxFigures
    actuator_mass: Any
    reflected_inertia: Any
    peak_torque: Any
    driving_peak_torque: Any
    driving_continuous_torque: Any


PLACEMENT_STIFFNESS_RATIO = 10.0
"""How much stiffer than the contact (seen at the joint) a transmission must be for its rotor to take part in the
impact. The time-domain validity map (documentation: Time-domain simulation, "Where the arm closed form holds") sweeps the contact stiffness
at 0.1, 10 and 1000 times the joints' stiffness along the contact direction: compliant joints against a
contact ten or more times stiffer take no part of the rotor into the short impact (``robot``); a transmission
ten times stiffer than the contact carries the rotor along (``finger``, where the closed form is an estimate).
Between, the map validates neither."""


def placements_from_stiffness(
    moment_arms: np.ndarray, mechanical_stiffness: np.ndarray, contact_stiffness: float
) -> tuple[tuple[str, ...], np.ndarray]:
    """Each joint's reflected-inertia placement from its transmission's stiffness, and the stiffness ratios.

    The contact stiffness ``k_c`` [N/m] seen at joint ``j`` is ``k_c l_j^2``, with ``l_j^2`` the median over the
    samples of the squared moment arm ``(J^T u)_j^2`` [m^2/rad^2] (``moment_arms``: (n_samples, n_joints));
    against the joint's mechanical stiffness ``k_m,j`` [N m/rad] it gives the ratio ``k_c l_j^2 / k_m,j``.
    ``finger`` where the ratio is at most ``1 / PLACEMENT_STIFFNESS_RATIO`` (the transmission is the stiff
    side), ``robot`` elsewhere. Returns the placements and the ratios (n_joints,).
    """
    lever_squared = np.median(np.asarray(moment_arms, dtype=float) ** 2, axis=0)
    ratios = contact_stiffness * lever_squared / np.asarray(mechanical_stiffness, dtype=float)
    placements = tuple("finger" if r <= 1 / PLACEMENT_STIFFNESS_RATIO else "robot" for r in ratios)
    return placements, ratios


def _rows(values: Any) -> int:
    """Number of joints of a per-joint column (CasADi or NumPy)."""
    shape = getattr(values, "shape", None)
    return int(shape[0]) if shape else int(np.size(values))


def _column(values: np.ndarray, like: Any) -> Any:
    """Per-joint constants shaped as ``like``: a CasADi column (DM) for CasADi, an array for NumPy."""
    import casadi as ca  # lazily: the package imports without CasADi's start-up cost

    return ca.DM(values) if isinstance(like, (ca.MX, ca.SX, ca.DM)) else values
