"""Time-domain simulation of a one-dimensional collision: checks the closed form and shows where it breaks.

Topology, from the wall outwards (positions positive toward the wall)::

    wall | contact (rigid plastic, or stiffness k_c + damping c_c) | finger m_f | spring k_m (+ backlash)
         | robot mass m_r (+ Coulomb and viscous friction) | controller: software spring k_s, damping d_s,
           reference moving at v0; after detection, the actuator's force limit F_a away from the wall

The robot approaches at ``v0`` and the finger touches the wall at ``t = 0``. Detection (force on the spring, a
tracking error, or the actuator force seen as motor current) triggers, after an optional delay and at the next
control sample, the reaction: the software spring is zeroed and the actuator pushes the robot mass away with
its force limit ``F_a``. The simulation ends when the finger has left the wall for good; the impulse is the
integral of the contact force (plus the impulses of rigid plastic impacts).

The ideal limit and the closed form (:mod:`collision_reflex.model.impulse`)
----------------------------------------------------------------------
The closed form assumes a plastic impact, a robot that tracks its reference ideally while sensing, instant
detection and a constant reaction acceleration ``a``. In this model that is ``drive="ideal"``: the robot mass
is ideally velocity-controlled, and the software stiffness acts as an admittance (the robot yields by
``F / k_s`` under the spring force ``F``), so the two springs are exactly in series and the force ramps as
``k v0 t`` with ``k = k_m k_s / (k_m + k_s)``; with a rigid plastic contact the finger's impulse is exactly
``m_f v0``. At detection the admittance is switched off (the software spring is zeroed) and the actuator
applies ``-F_a``. Two consequences follow from the physics and are what the closed form's two reaction
variants idealise:

- while the finger is held at the wall, the spring ``k_m`` compresses at ``k v0 / k_m``, so the robot mass is
  still moving at ``v_r = v0 k / k_m`` at detection. The paper's reaction (robot at rest) is the limit
  ``k_s << k_m`` (more precisely ``v_r << sqrt(2 a F_s / k_m)``); the moving-robot variant with its default
  ``v_r = v0`` is the limit ``k_s -> inf`` (an ideally velocity-controlled robot mass, ``k = k_m``); in between
  the moving variant with ``v_r = v0 k / k_m`` is exact.
- the spring also pushes the robot away, so its acceleration is ``(F_a + F) / m_r``, not ``a = F_a / m_r``:
  the closed form needs ``F << F_a`` throughout the reaction.

``drive="impedance"`` is the physical controller: the software spring and damper act as forces on the robot
mass (saturated at ``F_a``), whose momentum then loads the spring as well. ``drive="free"`` applies no actuator
force at all (an uncontrolled collision; detection is ignored), for energy bookkeeping.

Everything is SI: kg, m, s, N, N/m, N*s/m, N*s.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np
from scipy.integrate import solve_ivp

from .. import _validate
from ..errors import InvalidParameter, SimulationError
from ..model.impulse import PhaseImpulses, phase_impulses, series_stiffness

DRIVES: tuple[str, ...] = ("ideal", "impedance", "free")
"""Robot-side drive during the approach: see the module docstring."""

DETECTION_KINDS: tuple[str, ...] = ("force", "position", "current")
"""``"force"``: the mechanical spring's force (a force sensor measures its own deflection) [N];
``"position"``: the output (finger) position lag behind the reference, beyond its pre-contact value [m];
``"current"``: the actuator force, i.e. motor current times torque constant, seen at the output [N] (with the
ideal drive: spring force plus friction plus ``m_r`` times the robot's acceleration; the ideal controller's
impulsive force at the instant the finger stops is not counted, as a real current loop would filter it)."""

# State layout. Deflections are states of their own (not differences of absolute positions) so that the
# tolerances resolve a spring compression of nanometres while the reference travels centimetres.
_XF, _VF, _DEFL, _VR, _ERR, _SURF, _IMP, _WORK, _LOSS = range(9)
_NSTATE = 9
_TRACE_POINTS = 40  # interpolated trace points per integration segment


@dataclass(frozen=True)
class Detection:
    """How the controller detects the contact.

    Parameters
    ----------
    kind: one of :data:`DETECTION_KINDS`.
    threshold: detection threshold: a force [N] for ``"force"`` and ``"current"``, a position error [m] for
        ``"position"``.
    """

    kind: str
    threshold: float

    def __post_init__(self) -> None:
        _validate.choice("detection kind", self.kind, DETECTION_KINDS)
        _validate.positive("detection threshold", self.threshold)


@dataclass(frozen=True)
class CollisionSetup:
    """Parameters of one simulated collision (SI units).

    Parameters
    ----------
    finger_mass: finger (sprung) mass ``m_f`` [kg].
    robot_mass: robot (unsprung + reflected rotor) mass ``m_r`` [kg].
    mechanical_stiffness: spring ``k_m`` between finger and robot mass [N/m].
    software_stiffness: controller stiffness ``k_s`` [N/m]; ``inf`` (``drive="ideal"`` only) for an ideally
        velocity-controlled robot mass.
    force_limit: actuator force limit ``F_a`` [N]; the reaction pushes with it, so ``a = F_a / m_r``.
    velocity: approach velocity ``v0`` [m/s].
    detection: a :class:`Detection`.
    drive: ``"ideal"``, ``"impedance"`` or ``"free"`` (see the module docstring).
    software_damping: controller damping ``d_s`` [N*s/m], ``drive="impedance"`` only.
    delay: sensing delay from detection to the reaction [s].
    control_rate: rate of the sampled controller [Hz]; ``None`` for continuous control. Detection is checked,
        and the impedance force updated (zero-order hold), only at the samples ``(k + sample_phase) / rate``.
    sample_phase: offset of the sampling grid from the impact, a fraction of a period in [0, 1).
    contact_stiffness: wall contact stiffness ``k_c`` [N/m]; ``inf`` for a rigid, perfectly plastic wall.
    contact_damping: wall contact damping ``c_c`` [N*s/m] (Kelvin-Voigt, no adhesion: the surface recovers
        at the rate ``k_c / c_c`` once unloaded); see :func:`contact_damping_for_restitution`.
    coulomb_friction: Coulomb friction on the robot mass [N], below ``force_limit``.
    viscous_friction: viscous friction on the robot mass [N*s/m].
    backlash: total play of the spring's attachment [m].
    initial_play: part of the play still open at impact [m], in [0, backlash]; default half of it (the
        approach does not tell which flank is engaged).
    duration: simulated time limit [s]; default 20 times the closed form's contact time, plus the delay.
    max_step: largest integrator step [s]; default a fraction of the shortest period in play. Events
        (contacts, detection) are found by sign changes between steps, so a step longer than a contact can
        miss it: steps above a quarter of the contact time are refused.
    rtol: relative tolerance of the integrator.
    """

    finger_mass: float
    robot_mass: float
    mechanical_stiffness: float
    software_stiffness: float
    force_limit: float
    velocity: float
    detection: Detection
    drive: str = "ideal"
    software_damping: float = 0.0
    delay: float = 0.0
    control_rate: float | None = None
    sample_phase: float = 0.0
    contact_stiffness: float = math.inf
    contact_damping: float = 0.0
    coulomb_friction: float = 0.0
    viscous_friction: float = 0.0
    backlash: float = 0.0
    initial_play: float | None = None
    duration: float | None = None
    max_step: float | None = None
    rtol: float = 1e-10

    def __post_init__(self) -> None:
        _validate.choice("drive", self.drive, DRIVES)
        if not isinstance(self.detection, Detection):
            raise InvalidParameter("detection", self.detection, "a Detection(kind, threshold)")
        for name in ("finger_mass", "robot_mass", "mechanical_stiffness", "force_limit", "velocity"):
            _validate.positive(name, getattr(self, name))
        _validate.positive("software_stiffness", self.software_stiffness, allow_inf=True)
        _validate.positive("contact_stiffness", self.contact_stiffness, allow_inf=True)
        for name in (
            "software_damping",
            "delay",
            "contact_damping",
            "coulomb_friction",
            "viscous_friction",
            "backlash",
        ):
            _validate.non_negative(name, getattr(self, name))
        _validate.positive("rtol", self.rtol)
        if not 1e-14 <= self.rtol <= 1e-3:
            raise InvalidParameter("rtol", self.rtol, "between 1e-14 and 1e-3")
        if math.isinf(self.software_stiffness) and self.drive == "impedance":
            raise InvalidParameter(
                "software_stiffness",
                self.software_stiffness,
                "finite with drive='impedance'",
                "an infinite controller stiffness is the ideal velocity-controlled robot: use drive='ideal'",
            )
        if self.software_damping > 0 and self.drive != "impedance":
            raise InvalidParameter(
                "software_damping",
                self.software_damping,
                "0 unless drive='impedance'",
                "the ideal drive tracks its reference exactly; damping acts on the robot mass only with "
                "drive='impedance'",
            )
        if self.coulomb_friction >= self.force_limit:
            raise InvalidParameter(
                "coulomb_friction",
                self.coulomb_friction,
                f"below force_limit = {self.force_limit:g} N",
                "the actuator could not move the robot mass at all",
            )
        if self.initial_play is not None:
            _validate.non_negative("initial_play", self.initial_play)
            if self.initial_play > self.backlash:
                raise InvalidParameter(
                    "initial_play", self.initial_play, f"at most backlash = {self.backlash:g} m"
                )
        if self.control_rate is not None:
            _validate.positive("control_rate", self.control_rate)
        if not 0.0 <= self.sample_phase < 1.0:
            raise InvalidParameter("sample_phase", self.sample_phase, "a fraction in [0, 1)")
        if self.duration is not None:
            _validate.positive("duration", self.duration)
            if self.delay >= self.duration:
                raise InvalidParameter(
                    "delay",
                    self.delay,
                    f"shorter than the simulated duration = {self.duration:g} s",
                    "lengthen duration (or leave it unset) or shorten the delay",
                )
        if self.max_step is not None:
            _validate.positive("max_step", self.max_step)
            contact_time = self.contact_time
            if contact_time > 0 and self.max_step > contact_time / 4:
                raise InvalidParameter(
                    "max_step",
                    self.max_step,
                    f"at most a quarter of the contact time pi*sqrt(m_f/k_c) = {contact_time:.3g} s "
                    f"(contact_stiffness = {self.contact_stiffness:g} N/m)",
                    f"a coarser step can step over a whole contact; use max_step <= {contact_time / 4:.3g} s "
                    "or leave it unset",
                )
        if self.detection.kind == "current" and self.detection.threshold <= self._approach_force:
            raise InvalidParameter(
                "detection threshold",
                self.detection.threshold,
                f"above the actuator force of the free approach, {self._approach_force:g} N (friction)",
                "raise the current threshold above the friction force or the robot detects before touching",
            )

    # ----- derived quantities -------------------------------------------------------------------------------
    @property
    def lumped_stiffness(self) -> float:
        """Series stiffness ``k`` of the mechanical and software springs [N/m]."""
        return float(series_stiffness(self.mechanical_stiffness, self.software_stiffness))

    @property
    def acceleration(self) -> float:
        """Reaction acceleration ``a = F_a / m_r`` [m/s^2]."""
        return self.force_limit / self.robot_mass

    @property
    def play(self) -> float:
        """Part of the backlash still open at impact [m]."""
        return self.backlash / 2 if self.initial_play is None else self.initial_play

    @property
    def contact_time(self) -> float:
        """Duration ``pi sqrt(m_f / k_c)`` of an undamped contact of the finger alone [s] (0 when rigid)."""
        return math.pi * math.sqrt(self.finger_mass / self.contact_stiffness)

    @property
    def detection_robot_velocity(self) -> float:
        """Robot-mass velocity toward the wall while the finger is held there, ``v0 k / k_m`` [m/s]
        (``drive="ideal"``); the closed form's reaction starts from it."""
        return self.velocity * self.lumped_stiffness / self.mechanical_stiffness

    @property
    def equivalent_threshold(self) -> float:
        """Spring force at detection in the ideal limit, the closed form's ``F_s`` [N].

        Force detection: the threshold; position: ``k (e_th - play)`` (the play is taken up first); current:
        the threshold less the friction the actuator also overcomes at ``v0 k / k_m``.
        """
        threshold = self.detection.threshold
        if self.detection.kind == "position":
            return self.lumped_stiffness * (threshold - self.play)
        if self.detection.kind == "current":
            v_r = self.detection_robot_velocity
            return threshold - self.coulomb_friction - self.viscous_friction * v_r
        return threshold

    @property
    def _approach_force(self) -> float:
        return self.coulomb_friction + self.viscous_friction * self.velocity

    def closed_form(self, reaction: str = "at_rest", v_r: float | None = None) -> PhaseImpulses:
        """Phase impulses of the closed form for this setup (:func:`collision_reflex.phase_impulses`) [N*s].

        Uses ``m_f``, ``k`` (series), ``k_m``, ``F_s`` (:attr:`equivalent_threshold`), ``a = F_a / m_r`` and
        ``v0``; ``reaction`` and ``v_r`` as there (pass ``v_r=setup.detection_robot_velocity`` with
        ``reaction="moving"`` for the variant that is exact in the ideal limit).
        """
        F_s = self.equivalent_threshold
        if F_s <= 0:
            raise InvalidParameter(
                "detection threshold",
                self.detection.threshold,
                "one that the spring force must exceed (equivalent F_s > 0)",
                "the play or the friction alone already reaches it",
            )
        return phase_impulses(
            self.finger_mass,
            self.lumped_stiffness,
            self.mechanical_stiffness,
            F_s,
            self.acceleration,
            self.velocity,
            reaction,
            v_r,
        )


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


def contact_restitution(damping_ratio: float) -> float:
    """Coefficient of restitution of a mass on a Kelvin-Voigt contact that cannot pull.

    ``damping_ratio = c / (2 sqrt(k m))``. The contact ends when ``k x + c xdot`` returns to zero, which for an
    undamped contact is at ``x = 0`` (restitution 1) and for a damped one while the surface is still
    indented; the restitution falls to ``exp(-2) = 0.135`` at critical damping and to 0 as ``1/(4 zeta^2)``.
    """
    _validate.non_negative("damping_ratio", damping_ratio)
    zeta = float(damping_ratio)
    if zeta == 0:
        return 1.0
    # Unit mass, unit stiffness, unit impact velocity: x(t) = (e^{s1 t} - e^{s2 t}) / (s1 - s2).
    root = np.sqrt(complex(zeta**2 - 1))
    s1, s2 = -zeta + root, -zeta - root

    def position_velocity(t: float) -> tuple[float, float]:
        if abs(zeta - 1) < 1e-9:
            return t * math.exp(-t), (1 - t) * math.exp(-t)
        x = (np.exp(s1 * t) - np.exp(s2 * t)) / (s1 - s2)
        v = (s1 * np.exp(s1 * t) - s2 * np.exp(s2 * t)) / (s1 - s2)
        return float(x.real), float(v.real)

    def force(t: float) -> float:
        x, v = position_velocity(t)
        return x + 2 * zeta * v

    from scipy.optimize import brentq

    upper = 0.5
    while force(upper) > 0:
        upper *= 2
    t_end = brentq(force, 1e-12, upper, xtol=1e-15, rtol=1e-14)
    return -position_velocity(t_end)[1]


def contact_damping_for_restitution(
    restitution: float, finger_mass: float, contact_stiffness: float
) -> float:
    """Contact damping [N*s/m] giving ``restitution`` (in (0, 1]) to the finger alone on the contact.

    Parameters
    ----------
    restitution: coefficient of restitution, ``0 < e <= 1``.
    finger_mass: finger mass [kg].
    contact_stiffness: contact stiffness [N/m], finite.
    """
    _validate.positive("finger_mass", finger_mass)
    _validate.positive("contact_stiffness", contact_stiffness)
    if not 0 < restitution <= 1:
        raise InvalidParameter(
            "restitution", restitution, "a number in (0, 1]", "a perfectly plastic contact is a rigid wall"
        )
    if restitution == 1:
        return 0.0
    from scipy.optimize import brentq

    zeta_max = 1.0
    while contact_restitution(zeta_max) > restitution:
        zeta_max *= 2
        if zeta_max > 1e6:
            raise InvalidParameter(
                "restitution", restitution, "at least 1e-12", "use a rigid wall for a plastic contact"
            )
    zeta = brentq(lambda z: contact_restitution(z) - restitution, 0.0, zeta_max, xtol=1e-14)
    return 2 * zeta * math.sqrt(contact_stiffness * finger_mass)


# ----- the hybrid integration -------------------------------------------------------------------------------


class _Collision:
    """Mode-switching model of one collision; modes change only at events or at sample instants.

    Contact modes: ``"held"`` (rigid wall: the finger rests on it, the wall carries the spring force),
    ``"pressed"`` (compliant wall loaded), ``"free"``. Drive modes: ``"kinematic"`` (ideal approach),
    ``"impedance"``, ``"none"`` (free collision) and ``"reaction"``.
    """

    def __init__(self, setup: CollisionSetup) -> None:
        self.s = setup
        self.m_f, self.m_r = setup.finger_mass, setup.robot_mass
        self.k_m, self.k_s = setup.mechanical_stiffness, setup.software_stiffness
        self.k_c, self.c_c = setup.contact_stiffness, setup.contact_damping
        self.v0 = setup.velocity
        self.half_gap = setup.backlash / 2
        self.rigid = math.isinf(self.k_c)
        self.contact = "free"
        self.drive = {"ideal": "kinematic", "impedance": "impedance", "free": "none"}[setup.drive]
        self.robot_stuck = False  # Coulomb stiction of the robot mass
        self.held_force = 0.0  # sampled impedance force (zero-order hold)
        self.sampled = setup.control_rate is not None
        self.impacts: list[tuple[float, float]] = []
        self.events: list[tuple[float, str]] = []

    # -- forces ----------------------------------------------------------------------------------------------
    def spring(self, deflection: float) -> float:
        """Spring force for a deflection (compression positive), with the backlash dead band [N]."""
        if deflection > self.half_gap:
            return self.k_m * (deflection - self.half_gap)
        if deflection < -self.half_gap:
            return self.k_m * (deflection + self.half_gap)
        return 0.0

    def friction(self, velocity: float) -> float:
        """Sliding friction on the robot mass, opposing its velocity [N]."""
        return self.s.coulomb_friction * float(np.sign(velocity)) + self.s.viscous_friction * velocity

    def kinematic(self, total: float, v_f: float) -> tuple[float, float, float, float]:
        """Ideal drive: split the chain deflection ``total`` (spring deflection + admittance yield) between the
        spring and the admittance. Returns ``(deflection, yield, robot velocity, d v_r / d a_f)``."""
        if math.isinf(self.k_s):
            return total, 0.0, self.v0, 0.0
        closing = self.v0 - v_f  # rate of change of `total`
        if total > self.half_gap or (total == self.half_gap and closing > 0):
            edge = self.half_gap
        elif total < -self.half_gap or (total == -self.half_gap and closing < 0):
            edge = -self.half_gap
        else:  # inside the play: the spring carries nothing and the robot tracks the reference exactly
            return total, 0.0, self.v0, 0.0
        share = self.k_s / (self.k_s + self.k_m)
        deflection = edge + share * (total - edge)
        return deflection, total - deflection, share * self.v0 + (1 - share) * v_f, 1 - share

    def impedance_law(self, y: np.ndarray) -> float:
        force = self.k_s * y[_ERR] + self.s.software_damping * (self.v0 - y[_VR])
        return float(np.clip(force, -self.s.force_limit, self.s.force_limit))

    def resolved(self, y: np.ndarray) -> np.ndarray:
        """The state with the algebraic parts of the current mode filled in."""
        y = np.array(y, dtype=float)
        if self.contact == "held":
            y[_VF] = 0.0
        if self.drive == "kinematic":
            y[_DEFL], y[_ERR], y[_VR], _ = self.kinematic(y[_DEFL] + y[_ERR], y[_VF])
        elif self.robot_stuck:
            y[_VR] = 0.0
        return y

    def forces(self, t: float, y: np.ndarray) -> dict[str, float]:
        """Spring, contact and actuator forces and both accelerations, for a resolved state."""
        v_f, v_r, deflection = y[_VF], y[_VR], y[_DEFL]
        spring = self.spring(deflection)
        if self.contact == "held":
            contact = spring
        elif self.contact == "pressed":
            contact = self.k_c * y[_XF] + self.c_c * v_f
        else:
            contact = 0.0
        a_f = 0.0 if self.contact == "held" else (spring - contact) / self.m_f
        if self.drive == "kinematic":
            a_r = self.kinematic(deflection + y[_ERR], v_f)[3] * a_f
            actuator = spring + self.friction(v_r) + self.m_r * a_r  # what the ideal controller must supply
        else:
            if self.drive == "reaction":
                actuator = -self.s.force_limit
            elif self.drive == "impedance":
                actuator = self.held_force if self.sampled else self.impedance_law(y)
            else:
                actuator = 0.0
            a_r = 0.0 if self.robot_stuck else (actuator - spring - self.friction(v_r)) / self.m_r
        return {"spring": spring, "contact": contact, "actuator": actuator, "a_f": a_f, "a_r": a_r}

    def rhs(self, t: float, y_raw: np.ndarray) -> np.ndarray:
        y = self.resolved(y_raw)
        f = self.forces(t, y)
        v_f, v_r = y[_VF], y[_VR]
        dy = np.zeros(_NSTATE)
        loss = self.friction(v_r) * v_r
        if self.contact == "pressed":
            dy[_SURF] = v_f
            loss += self.c_c * v_f**2
        elif not self.rigid and self.c_c > 0 and y[_SURF] > 0:
            rate = self.k_c / self.c_c  # an unloaded Kelvin-Voigt surface recovers exponentially
            dy[_SURF] = -rate * y[_SURF]
            loss += self.c_c * (rate * y[_SURF]) ** 2
        dy[_XF] = v_f
        dy[_VF] = f["a_f"]
        dy[_DEFL] = v_r - v_f
        dy[_VR] = f["a_r"]
        dy[_ERR] = self.v0 - v_r if self.drive in ("kinematic", "impedance") else 0.0
        dy[_IMP] = f["contact"]
        dy[_WORK] = f["actuator"] * v_r
        dy[_LOSS] = loss
        return dy

    def measurement(self, t: float, y: np.ndarray, start: np.ndarray) -> float:
        """What the detector sees (see :data:`DETECTION_KINDS`)."""
        y = self.resolved(y)
        kind = self.s.detection.kind
        if kind == "force":
            return self.spring(y[_DEFL])
        if kind == "position":
            return (y[_ERR] + y[_DEFL]) - (start[_ERR] + start[_DEFL])
        return self.forces(t, y)["actuator"]

    def energy(self, y: np.ndarray) -> float:
        """Kinetic energy of both masses plus the energy stored in the spring and the wall [J]."""
        y = self.resolved(y)
        elastic = self.spring(y[_DEFL]) ** 2 / (2 * self.k_m)
        wall = 0.0 if self.rigid else 0.5 * self.k_c * y[_SURF] ** 2
        return 0.5 * self.m_f * y[_VF] ** 2 + 0.5 * self.m_r * y[_VR] ** 2 + elastic + wall

    # -- events ----------------------------------------------------------------------------------------------
    def mode_events(self, detecting: bool, start: np.ndarray, y0: np.ndarray) -> list[tuple[Any, str]]:
        """Terminal events leaving the current mode. Each is written so that it is not at zero, or is moving
        away from zero, at the start of the segment (solve_ivp counts a zero as a crossing)."""
        events: list[tuple[Any, str]] = []

        def add(function: Callable[[float, np.ndarray], float], direction: int, name: str) -> None:
            def event(t: float, y: np.ndarray) -> float:
                return float(function(t, self.resolved(y)))

            event.terminal = True  # type: ignore[attr-defined]
            event.direction = direction  # type: ignore[attr-defined]
            events.append((event, name))

        if self.contact == "held":
            # The finger stays until the spring pulls on it (beyond the play, if any).
            add(lambda t, y: y[_DEFL] + self.half_gap, -1, "finger leaves the wall")
        elif self.contact == "pressed":
            add(lambda t, y: self.k_c * y[_XF] + self.c_c * y[_VF], -1, "finger leaves the wall")
        else:
            add(lambda t, y: y[_XF] - (0.0 if self.rigid else y[_SURF]), 1, "finger hits the wall")
        if self.drive == "kinematic" and self.half_gap > 0 and math.isfinite(self.k_s):
            # Taking up or opening the play changes the ideal robot's velocity at once: stop there so that the
            # controller's impulsive work is booked.
            total = y0[_DEFL] + y0[_ERR]
            if total > self.half_gap or (total == self.half_gap and self.v0 > y0[_VF]):
                add(lambda t, y: y[_DEFL] + y[_ERR] - self.half_gap, -1, "play opens")
            elif total < -self.half_gap or (total == -self.half_gap and self.v0 < y0[_VF]):
                add(lambda t, y: y[_DEFL] + y[_ERR] + self.half_gap, 1, "play opens")
            else:
                add(lambda t, y: y[_DEFL] + y[_ERR] - self.half_gap, 1, "play taken up")
                add(lambda t, y: y[_DEFL] + y[_ERR] + self.half_gap, -1, "play taken up")
        if self.drive != "kinematic" and self.s.coulomb_friction > 0:
            if self.robot_stuck:

                def net(t: float, y: np.ndarray) -> float:
                    f = self.forces(t, y)
                    return f["actuator"] - f["spring"]

                add(lambda t, y: net(t, y) - self.s.coulomb_friction, 1, "robot breaks away")
                add(lambda t, y: net(t, y) + self.s.coulomb_friction, -1, "robot breaks away")
            else:
                y0 = self.resolved(y0)
                moving = y0[_VR] if y0[_VR] != 0 else self.forces(0.0, y0)["a_r"]
                add(lambda t, y: y[_VR], -int(np.sign(moving)) or -1, "robot stops")
        if detecting and not self.sampled:
            threshold = self.s.detection.threshold
            add(lambda t, y: self.measurement(t, y, start) - threshold, 1, "detection")
        return events

    def max_step(self) -> float:
        if self.s.max_step is not None:
            return self.s.max_step
        periods = [math.inf]
        if self.contact != "held":
            periods.append(2 * math.pi * math.sqrt(self.m_f / self.k_m))
            if not self.rigid:
                periods.append(2 * math.pi * math.sqrt(self.m_f / (self.k_c + self.k_m)))
        if self.drive != "kinematic":
            stiffness = self.k_m + (self.k_s if self.drive == "impedance" else 0.0)
            periods.append(2 * math.pi * math.sqrt(self.m_r / stiffness))
        return min(periods) / 16

    # -- transitions -----------------------------------------------------------------------------------------
    def touch(self, t: float, y: np.ndarray) -> np.ndarray:
        """The finger reaches the wall: a perfectly plastic impact on a rigid wall, or the start of a
        compliant contact."""
        y = self.resolved(y)
        if not self.rigid:
            self.contact = "pressed"
            y[_SURF] = y[_XF]
            return y
        before = self.energy(y)
        v_r_before = y[_VR]
        impulse = self.m_f * max(y[_VF], 0.0)
        y[_XF] = y[_VF] = 0.0
        y[_IMP] += impulse
        self.contact = "held"
        y = self.resolved(y)
        if self.spring(y[_DEFL]) < 0:
            self.contact = "free"  # stopped, but the spring pulls it straight off again
        # An ideal controller changes the robot's velocity at once; its work is the kinetic-energy change.
        work = 0.5 * self.m_r * (y[_VR] ** 2 - v_r_before**2) if self.drive == "kinematic" else 0.0
        y[_WORK] += work
        y[_LOSS] += before + work - self.energy(y)
        if impulse > 0:
            self.impacts.append((t, impulse))
        return y

    def leave(self, y: np.ndarray) -> np.ndarray:
        y = self.resolved(y)
        if self.contact == "pressed":
            y[_SURF] = y[_XF]
        self.contact = "free"
        return y


def simulate(setup: CollisionSetup) -> SimulationResult:
    """Simulate one collision from the impact (``t = 0``) until the finger has left the wall for good.

    After the finger leaves the wall during the reaction (or at all, with ``drive="free"``), the simulation
    watches five periods of the finger on its spring for a new contact before it stops.

    Returns a :class:`SimulationResult` with the force trace, the phase times and impulses and the energy
    bookkeeping. Raises :class:`~collision_reflex.errors.SimulationError` if nothing is detected, or the
    contact does not end, within ``setup.duration``.
    """
    sim = _Collision(setup)
    k = setup.lumped_stiffness
    kind, threshold = setup.detection.kind, setup.detection.threshold
    F_ref = k * threshold if kind == "position" else threshold
    watch = 5 * 2 * math.pi * math.sqrt(setup.finger_mass / setup.mechanical_stiffness)
    if setup.duration is not None:
        duration = setup.duration
    else:
        duration = 20 * _contact_time_estimate(setup, F_ref) + 2 * setup.delay + watch
        if setup.control_rate is not None:
            duration += 10 / setup.control_rate

    # Absolute tolerances from the scale of each state.
    deflection_scale = F_ref / setup.mechanical_stiffness
    yield_scale = F_ref / setup.software_stiffness if math.isfinite(setup.software_stiffness) else 0.0
    finger_scale = deflection_scale
    if not sim.rigid:
        finger_scale = max(
            finger_scale, setup.velocity * math.sqrt(setup.finger_mass / setup.contact_stiffness)
        )
    impulse_scale = setup.finger_mass * setup.velocity + F_ref**2 / (k * setup.velocity)
    energy_scale = 0.5 * (setup.finger_mass + setup.robot_mass) * setup.velocity**2 + F_ref * deflection_scale
    scales = [finger_scale, setup.velocity, deflection_scale, setup.velocity]
    scales += [max(yield_scale, deflection_scale), finger_scale, impulse_scale, energy_scale, energy_scale]
    atol = 1e-3 * setup.rtol * np.array(scales)

    # The finger touches the wall at v0; the spring carries no force, with `play` still to take up.
    y = np.zeros(_NSTATE)
    y[_VF] = y[_VR] = setup.velocity
    y[_DEFL] = sim.half_gap - setup.play
    if setup.drive == "impedance":
        y[_ERR] = setup._approach_force / setup.software_stiffness  # the steady lag that overcomes friction
    start = y.copy()
    initial_energy = sim.energy(y)
    y = sim.touch(0.0, y)
    sim.events.append((0.0, "impact"))

    detecting = setup.drive != "free"
    detection_time = reaction_time = math.inf
    impulse_at_detection = impulse_at_reaction = v_r_at_reaction = math.nan
    watch_end = math.inf
    contact_end = math.nan
    rate = setup.control_rate
    if sim.sampled and setup.drive == "impedance":
        sim.held_force = sim.impedance_law(y)

    def next_sample(after: float, strictly: bool = False) -> float:
        """First control sample at (or strictly after) ``after`` [s]."""
        assert rate is not None
        position = after * rate - setup.sample_phase
        index = math.floor(position + 1e-9) + 1 if strictly else math.ceil(position - 1e-9)
        return (max(index, 0) + setup.sample_phase) / rate

    def detect(t: float, y: np.ndarray) -> None:
        nonlocal detection_time, reaction_time, impulse_at_detection
        detection_time = t
        impulse_at_detection = float(y[_IMP])
        reaction_time = t + setup.delay if rate is None else next_sample(t + setup.delay)

    times: list[np.ndarray] = [np.array([0.0])]
    states: list[np.ndarray] = [y[:, None]]
    modes: list[str] = [sim.contact]
    t = 0.0
    tiny = 1e-12 * duration
    last_event: tuple[float, str] = (math.nan, "")
    repeats = 0
    for _ in range(100_000):
        # Transitions due now.
        if detecting and sim.drive != "reaction" and t >= reaction_time - tiny:
            sim.drive = "reaction"
            sim.robot_stuck = False
            impulse_at_reaction = float(y[_IMP])
            v_r_at_reaction = float(y[_VR])
            sim.events.append((t, "reaction"))
            if sim.contact == "free":
                watch_end = t + watch
        if t >= watch_end - tiny:
            break
        if t >= duration - tiny:
            if math.isfinite(watch_end):
                break  # the contact has ended; the watch for a new one is cut short by the duration
            if detecting and math.isinf(detection_time):
                limited = ""
                if setup.drive == "impedance" and kind != "position" and threshold >= setup.force_limit:
                    limited = f" (the impedance controller pushes with at most force_limit = {setup.force_limit:g} N)"
                raise SimulationError(
                    f"nothing was detected within {duration:.3g} s: the {kind} threshold {threshold:g} is "
                    f"never reached{limited}; lower the threshold or lengthen duration"
                )
            raise SimulationError(
                f"the contact had not ended after {duration:.3g} s (reaction at {reaction_time:.3g} s); "
                "lengthen duration, or check that the force limit can pull the robot away"
            )
        if sim.robot_stuck:
            # A force that changed at a sample (or at the reaction) may now exceed stiction.
            f = sim.forces(t, y)
            if abs(f["actuator"] - f["spring"]) > setup.coulomb_friction:
                sim.robot_stuck = False
        sample_time = math.inf
        if (
            sim.sampled
            and sim.drive != "reaction"
            and (sim.drive == "impedance" or math.isinf(detection_time))
        ):
            sample_time = next_sample(t, strictly=True)
        pending_reaction = reaction_time if detecting and sim.drive != "reaction" else math.inf
        t_stop = min(duration, watch_end, sample_time, pending_reaction)
        events = sim.mode_events(detecting and math.isinf(detection_time), start, y)
        solution = solve_ivp(
            sim.rhs,
            (t, t_stop),
            y,
            method="DOP853",
            events=[event for event, _ in events],
            rtol=setup.rtol,
            atol=atol,
            max_step=min(sim.max_step(), t_stop - t),
            dense_output=True,
        )
        if solution.status < 0:
            raise SimulationError(f"the integrator failed at t = {t:.6g} s: {solution.message}")
        # The trace: the integrator's steps plus evenly spaced points from its interpolant, so that a segment
        # covered in a few long steps (a linear ramp) is still drawn smoothly where it bends later.
        trace_times = solution.t[1:]
        if solution.t.size > 1:
            extra = np.linspace(solution.t[0], solution.t[-1], _TRACE_POINTS)[1:-1]
            trace_times = np.union1d(trace_times, extra)
            trace_states = solution.sol(trace_times)
            trace_states[:, -1] = solution.y[:, -1]
        else:
            trace_states = np.zeros((_NSTATE, 0))
        times.append(trace_times)
        states.append(
            np.stack([sim.resolved(column) for column in trace_states.T], axis=1)
            if trace_times.size
            else np.zeros((_NSTATE, 0))
        )
        modes.extend([sim.contact] * trace_times.size)
        t = float(solution.t[-1])
        y = sim.resolved(solution.y[:, -1])
        if sim.drive == "kinematic":
            # The integrated robot velocity follows the ideal one between jumps; book the controller's
            # impulsive work at a jump (play taken up or opened).
            y[_WORK] += 0.5 * setup.robot_mass * (y[_VR] ** 2 - solution.y[_VR, -1] ** 2)
        if solution.status == 1:
            name = next(name for (_, name), hits in zip(events, solution.t_events, strict=True) if hits.size)
            sim.events.append((t, name))
            if name == "finger hits the wall":
                y = sim.touch(t, y)
                watch_end = math.inf
            elif name == "finger leaves the wall":
                y = sim.leave(y)
                contact_end = t
                if sim.drive in ("reaction", "none"):
                    watch_end = t + watch
            elif name == "detection":
                detect(t, y)
            elif name == "robot stops":
                y[_VR] = 0.0  # exactly, so that the next segment starts from rest
                f = sim.forces(t, y)
                if abs(f["actuator"] - f["spring"]) <= setup.coulomb_friction:
                    sim.robot_stuck = True
            elif name == "robot breaks away":
                sim.robot_stuck = False
            elif name in ("play taken up", "play opens"):
                # Snap the chain exactly onto the edge of the play: a rounding error on the gap side would
                # re-fire the same event at once.
                edge = sim.half_gap if y[_DEFL] + y[_ERR] > 0 else -sim.half_gap
                v_r_before = y[_VR]
                y[_DEFL], y[_ERR] = edge, 0.0
                y = sim.resolved(y)
                y[_WORK] += 0.5 * setup.robot_mass * (y[_VR] ** 2 - v_r_before**2)  # the ideal controller's
            repeats = repeats + 1 if (t, name) == last_event else 0
            last_event = (t, name)
            if repeats > 20:
                raise SimulationError(
                    f"the event {name!r} keeps firing at t = {t:.9g} s without the simulation advancing; "
                    "change rtol or the parameters slightly"
                )
            if states[-1].shape[1]:
                states[-1][:, -1] = y
            continue
        if t >= sample_time - tiny:
            if sim.drive == "impedance":
                sim.held_force = sim.impedance_law(y)
            if detecting and math.isinf(detection_time) and sim.measurement(t, y, start) >= threshold:
                detect(t, y)
                sim.events.append((t, "detection"))
    else:
        raise SimulationError(
            "the simulation changed mode 100000 times without ending (a chattering contact)"
        )

    trace_t = np.concatenate(times)
    trace_y = np.concatenate(states, axis=1)
    spring = np.array([sim.spring(d) for d in trace_y[_DEFL]])
    contact = np.where(
        np.array(modes) == "held",
        spring,
        np.where(
            np.array(modes) == "pressed",
            (0.0 if sim.rigid else setup.contact_stiffness) * trace_y[_XF]
            + setup.contact_damping * trace_y[_VF],
            0.0,
        ),
    )
    total = float(y[_IMP])
    if not detecting:
        detection_time = reaction_time = math.nan
        impulse_at_detection = impulse_at_reaction = total
    return SimulationResult(
        setup=setup,
        t=trace_t,
        contact_force=np.maximum(contact, 0.0),
        spring_force=spring,
        finger_velocity=trace_y[_VF],
        robot_velocity=trace_y[_VR],
        impacts=tuple(sim.impacts),
        impulse=total,
        detection_time=detection_time,
        reaction_time=reaction_time,
        contact_end=contact_end,
        impulse_to_detection=impulse_at_detection,
        impulse_delay=impulse_at_reaction - impulse_at_detection,
        impulse_reaction=total - impulse_at_reaction,
        robot_velocity_at_reaction=v_r_at_reaction,
        actuator_work=float(y[_WORK]),
        dissipated=float(y[_LOSS]),
        initial_energy=initial_energy,
        final_energy=sim.energy(y),
        events=tuple(sim.events),
    )


def _contact_time_estimate(setup: CollisionSetup, F_ref: float) -> float:
    """A generous contact time: the closed form's with the robot still moving at ``v0``, plus a period of
    both masses on the spring and the time to take up the play [s]."""
    t1 = F_ref / (setup.lumped_stiffness * setup.velocity)
    a, v = setup.acceleration, setup.velocity
    reaction = (v + math.sqrt(v * v + 2 * a * F_ref / setup.mechanical_stiffness)) / a
    free = 2 * math.pi * math.sqrt((setup.finger_mass + setup.robot_mass) / setup.mechanical_stiffness)
    return t1 + reaction + free + setup.backlash / v


SWEEP_PARAMETERS: tuple[str, ...] = ("delay", "backlash")
"""Setup fields that :func:`sweep` can vary besides the velocity."""


@dataclass(frozen=True)
class Sweep:
    """Simulated impulses against the closed form over approach velocities (and optionally a second parameter).

    Arrays have shape ``(len(values), len(velocities))``; ``values`` is ``[None]`` without a second parameter.

    Attributes
    ----------
    velocities: approach velocities [m/s].
    parameter: the second parameter's name (``"delay"`` [s] or ``"backlash"`` [m]) or None.
    values: its values.
    simulated: simulated impulse [N*s].
    closed_form: the closed form's impulse for the same setup [N*s] (it knows no delay or backlash).
    reaction: the closed form's reaction variant compared against.
    tolerance: relative difference beyond which the two are said to part.
    """

    velocities: np.ndarray
    parameter: str | None
    values: tuple[Any, ...]
    simulated: np.ndarray
    closed_form: np.ndarray
    reaction: str
    tolerance: float

    @property
    def relative_difference(self) -> np.ndarray:
        """``simulated / closed_form - 1``."""
        return self.simulated / self.closed_form - 1

    @property
    def parted(self) -> np.ndarray:
        """True where ``|relative_difference| > tolerance``."""
        return np.abs(self.relative_difference) > self.tolerance


def sweep(
    setup: CollisionSetup,
    velocities: Any,
    parameter: str | None = None,
    values: Any = None,
    reaction: str = "at_rest",
    v_r: float | str | None = None,
    tolerance: float = 0.05,
) -> Sweep:
    """Simulate ``setup`` at each approach velocity (and each value of ``parameter``) and evaluate the
    closed form (:meth:`CollisionSetup.closed_form`) alongside.

    Parameters
    ----------
    setup: the collision; its ``velocity`` (and the swept parameter) are replaced.
    velocities: approach velocities [m/s], > 0.
    parameter: ``"delay"`` [s] or ``"backlash"`` [m] to sweep as well, or None.
    values: the parameter's values (>= 0); with ``"backlash"``, half of each is open at impact unless
        ``setup.initial_play`` says otherwise (it is then capped at the backlash).
    reaction, v_r: the closed form's reaction variant, as :func:`collision_reflex.phase_impulses`; ``v_r`` may
        also be ``"detected"``: the robot's velocity at detection in the ideal limit, ``v0 k / k_m``, per
        velocity (with ``reaction="moving"``).
    tolerance: relative difference that counts as parting, > 0.
    """
    speeds = np.atleast_1d(np.asarray(velocities, dtype=float))
    _validate.positive("velocities", speeds)
    _validate.positive("tolerance", tolerance)
    if parameter is None:
        levels: tuple[Any, ...] = (None,)
    else:
        _validate.choice("parameter", parameter, SWEEP_PARAMETERS)
        if values is None:
            raise InvalidParameter("values", values, f"the values of {parameter} to sweep")
        array = np.atleast_1d(np.asarray(values, dtype=float))
        _validate.non_negative(parameter, array)
        levels = tuple(float(v) for v in array)
    simulated = np.empty((len(levels), speeds.size))
    closed = np.empty_like(simulated)
    for i, level in enumerate(levels):
        changes: dict[str, Any] = {}
        if parameter == "delay":
            changes["delay"] = level
        elif parameter == "backlash":
            changes["backlash"] = level
            if setup.initial_play is not None:
                changes["initial_play"] = min(setup.initial_play, level)
        for j, v0 in enumerate(speeds):
            case = replace(setup, velocity=float(v0), **changes)
            simulated[i, j] = simulate(case).impulse
            robot_velocity = case.detection_robot_velocity if v_r == "detected" else v_r
            closed[i, j] = float(case.closed_form(reaction, robot_velocity).total)  # type: ignore[arg-type]
    label = "moving at v0 k/k_m" if v_r == "detected" else reaction
    return Sweep(speeds, parameter, levels, simulated, closed, label, float(tolerance))
