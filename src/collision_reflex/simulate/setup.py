"""One simulated 1D collision: how the contact is detected, the setup's parameters and their checks.

It also gives the quantities derived from them (the closed form's inputs and the time scales of the
simulation).

Contact-level quantities carry the paper's symbols (``m_f``, ``m_r``, ``k_m``, ``k_s``, ``F_a``, ``v0``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from .. import _validate
from ..errors import InvalidParameter
from ..model.impulse import PhaseImpulses, impact_pulse_duration, phase_impulses, series_stiffness
from ..model.sensing import threshold_force
from ..vocabulary import DRIVES, SENSING_SCHEMES


def oscillation_period(mass: float, stiffness: float) -> float:
    """Period of ``mass`` [kg] on a spring ``stiffness`` [N/m] [s]: four impact-pulse quarter-periods."""
    return 4 * float(impact_pulse_duration(mass, stiffness))


@dataclass(frozen=True)
class Detection:
    """How the controller detects the contact.

    Parameters
    ----------
    kind: one of :data:`~collision_reflex.vocabulary.SENSING_SCHEMES`: ``"force"`` watches the mechanical
        spring's force (a force sensor measures its own deflection) [N]; ``"position"`` the output (finger)
        position lag behind the reference, beyond its pre-contact value [m]; ``"current"`` the actuator force,
        i.e. motor current times torque constant, seen at the output [N] (with the ideal drive: spring force
        plus friction plus ``m_r`` times the robot's acceleration; the ideal controller's impulsive force at
        the instant the finger stops is not counted, as a real current loop would filter it).
    threshold: detection threshold: a force [N] for ``"force"`` and ``"current"``, a position error ``e_th``
        [m] for ``"position"``.
    """

    kind: str
    threshold: float

    def __post_init__(self) -> None:
        _validate.choice("detection kind", self.kind, SENSING_SCHEMES)
        _scalar(
            self,
            "threshold",
            _validate.positive("detection threshold", self.threshold),
            "detection threshold",
        )


@dataclass(frozen=True)
class CollisionSetup:
    """Parameters of one simulated collision (SI units).

    Parameters
    ----------
    m_f: finger (sprung) mass [kg].
    m_r: robot (unsprung + reflected rotor) mass [kg].
    k_m: mechanical spring between finger and robot mass [N/m].
    k_s: controller stiffness [N/m]; ``inf`` (``drive="ideal"`` only) for an ideally velocity-controlled robot
        mass.
    F_a: actuator force limit [N]; the reaction pushes with it, so ``a = F_a / m_r``.
    v0: approach velocity [m/s].
    detection: a :class:`Detection`.
    drive: ``"ideal"``, ``"impedance"`` or ``"free"`` (see :mod:`collision_reflex.simulate`).
    software_damping: controller damping ``d_s`` [N*s/m], ``drive="impedance"`` only.
    delay: sensing delay from detection to the reaction [s].
    control_rate: rate of the sampled controller [Hz]; ``None`` for continuous control. Detection is checked,
        and the impedance force updated (zero-order hold), only at the samples ``(k + sample_phase) / rate``.
    sample_phase: offset of the sampling grid from the impact, a fraction of a period in [0, 1).
    contact_stiffness: wall contact stiffness ``k_c`` [N/m]; ``inf`` for a rigid, perfectly plastic wall.
    contact_damping: wall contact damping ``c_c`` [N*s/m] (Kelvin-Voigt, no adhesion: the surface recovers
        at the rate ``k_c / c_c`` once unloaded); see
        :func:`collision_reflex.simulate.contact_damping_for_restitution`.
    coulomb_friction: Coulomb friction on the robot mass [N], below ``F_a``.
    viscous_friction: viscous friction on the robot mass [N*s/m].
    backlash: total play of the spring's attachment [m].
    initial_play: part of the play still open at impact [m], in [0, backlash]; default half of it (the
        approach does not tell which flank is engaged).
    duration: simulated time limit [s]; default 20 times the closed form's contact time, plus the delay.
    max_step: largest integrator step [s]; default a fraction of the shortest period in play. Events
        (contacts, detection) are found by sign changes between steps, so a step longer than a contact can
        miss it: steps above a quarter of the contact time are refused.
    rtol: relative tolerance of the integrator.
    max_steps: budget of integrator steps. A setup whose up-front estimate (its phases' spans over their
        fastest time scales, :mod:`collision_reflex.simulate.budget`) exceeds ten times it is refused at once
        with what to change; a run that uses it up (12 right-hand-side evaluations a step, 3 steps a control sample or
        mode change) stops with a :class:`~collision_reflex.errors.SimulationError`. The default is about ten
        seconds of work at most; ordinary collisions take a few hundred steps.
    """

    m_f: float
    m_r: float
    k_m: float
    k_s: float
    F_a: float
    v0: float
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
    max_steps: int = 50_000

    def __post_init__(self) -> None:
        _validate.choice("drive", self.drive, DRIVES)
        if not isinstance(self.detection, Detection):
            raise InvalidParameter("detection", self.detection, "a Detection(kind, threshold)")
        _check_signs(self)
        _check_drive(self)
        _check_play_and_friction(self)
        _check_timing(self)
        if self.detection.kind == "current" and self.detection.threshold <= self.approach_force:
            raise InvalidParameter(
                "detection threshold",
                self.detection.threshold,
                f"above the actuator force of the free approach, {self.approach_force:g} N (friction)",
                "raise the current threshold above the friction force or the robot detects before touching",
            )

    # ----- derived quantities -------------------------------------------------------------------------------
    @property
    def lumped_stiffness(self) -> float:
        """Series stiffness ``k`` of the mechanical and software springs [N/m]."""
        return float(series_stiffness(self.k_m, self.k_s))

    @property
    def acceleration(self) -> float:
        """Reaction acceleration ``a = F_a / m_r`` [m/s^2]."""
        return self.F_a / self.m_r

    @property
    def play(self) -> float:
        """Part of the backlash still open at impact [m]."""
        return self.backlash / 2 if self.initial_play is None else self.initial_play

    @property
    def contact_time(self) -> float:
        """Duration ``pi sqrt(m_f / k_c)`` of an undamped contact of the finger alone [s] (0 when rigid).

        It spans compression and restitution.
        """
        return 2 * float(impact_pulse_duration(self.m_f, self.contact_stiffness))

    @property
    def approach_force(self) -> float:
        """Actuator force of the free approach at ``v0``: the friction it overcomes [N]."""
        return self.coulomb_friction + self.viscous_friction * self.v0

    @property
    def detection_robot_velocity(self) -> float:
        """Robot-mass velocity toward the wall while the finger is held there, ``v0 k / k_m`` [m/s].

        This is for ``drive="ideal"``; the closed form's reaction starts from it.
        """
        return self.v0 * self.lumped_stiffness / self.k_m

    @property
    def equivalent_threshold(self) -> float:
        """Spring force at detection in the ideal limit, the closed form's ``F_s`` [N].

        Force detection: the threshold; position: ``k (e_th - play)`` (the play is taken up first); current:
        the threshold less the friction the actuator also overcomes at ``v0 k / k_m``.
        """
        threshold = self.detection.threshold
        if self.detection.kind == "position":
            # The play is taken up before the spring builds force; a play beyond the threshold leaves none.
            return float(threshold_force("position", max(threshold - self.play, 0.0), self.lumped_stiffness))
        if self.detection.kind == "current":
            v_r = self.detection_robot_velocity
            return threshold - self.coulomb_friction - self.viscous_friction * v_r
        return threshold

    def closed_form(self, reaction: str = "at_rest", v_r: float | None = None) -> PhaseImpulses:
        """Phase impulses of the closed form for this setup (:func:`collision_reflex.model.phase_impulses`) [N*s].

        Uses ``m_f``, ``k`` (series), ``k_m``, ``F_s`` (:attr:`equivalent_threshold`), ``a = F_a / m_r`` and
        ``v0``; ``reaction`` and ``v_r`` [m/s] as there (pass ``v_r=setup.detection_robot_velocity`` with
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
        k, a = self.lumped_stiffness, self.acceleration
        return phase_impulses(self.m_f, k, self.k_m, F_s, a, self.v0, reaction, v_r)


def _scalar(owner: object, name: str, value: object, label: str | None = None) -> None:
    """Store a checked value on a frozen dataclass as a float; an array is refused."""
    if not isinstance(value, float):
        raise InvalidParameter(label or name, getattr(owner, name), "a single number")
    object.__setattr__(owner, name, value)


def _check_signs(setup: CollisionSetup) -> None:
    """Masses, stiffnesses, the force limit and the velocity > 0; damping, delay, friction and play >= 0.

    Each is stored as a float: integers and NumPy scalars are converted, strings and arrays refused.
    """
    for name in ("m_f", "m_r", "k_m", "F_a", "v0"):
        _scalar(setup, name, _validate.positive(name, getattr(setup, name)))
    for name in ("k_s", "contact_stiffness"):
        _scalar(setup, name, _validate.positive(name, getattr(setup, name), allow_inf=True))
    for name in (
        "software_damping",
        "delay",
        "contact_damping",
        "coulomb_friction",
        "viscous_friction",
        "backlash",
    ):
        _scalar(setup, name, _validate.non_negative(name, getattr(setup, name)))
    _scalar(setup, "rtol", _validate.positive("rtol", setup.rtol))
    if not 1e-14 <= setup.rtol <= 1e-3:
        raise InvalidParameter("rtol", setup.rtol, "between 1e-14 and 1e-3")
    if isinstance(setup.max_steps, bool) or not isinstance(setup.max_steps, int) or setup.max_steps < 1:
        raise InvalidParameter("max_steps", setup.max_steps, "a whole number >= 1")


def _check_drive(setup: CollisionSetup) -> None:
    """The controller's parameters fit its drive."""
    if math.isinf(setup.k_s) and setup.drive == "impedance":
        raise InvalidParameter(
            "k_s",
            setup.k_s,
            "finite with drive='impedance'",
            "an infinite controller stiffness is the ideal velocity-controlled robot: use drive='ideal'",
        )
    if setup.software_damping > 0 and setup.drive != "impedance":
        raise InvalidParameter(
            "software_damping",
            setup.software_damping,
            "0 unless drive='impedance'",
            "the ideal drive tracks its reference exactly; damping acts on the robot mass only with "
            "drive='impedance'",
        )


def _check_play_and_friction(setup: CollisionSetup) -> None:
    """Friction the actuator can overcome, and an initial play within the backlash."""
    if setup.coulomb_friction >= setup.F_a:
        raise InvalidParameter(
            "coulomb_friction",
            setup.coulomb_friction,
            f"below F_a = {setup.F_a:g} N",
            "the actuator could not move the robot mass at all",
        )
    if setup.initial_play is not None:
        _scalar(setup, "initial_play", _validate.non_negative("initial_play", setup.initial_play))
        if setup.initial_play > setup.backlash:
            raise InvalidParameter(
                "initial_play", setup.initial_play, f"at most backlash = {setup.backlash:g} m"
            )


def _check_timing(setup: CollisionSetup) -> None:
    """Control rate, sample phase, duration and step that the integration can honour."""
    if setup.control_rate is not None:
        _scalar(setup, "control_rate", _validate.positive("control_rate", setup.control_rate))
    _scalar(setup, "sample_phase", _validate.non_negative("sample_phase", setup.sample_phase))
    if not 0.0 <= setup.sample_phase < 1.0:
        raise InvalidParameter("sample_phase", setup.sample_phase, "a fraction in [0, 1)")
    if setup.duration is not None:
        _scalar(setup, "duration", _validate.positive("duration", setup.duration))
        if setup.delay >= setup.duration:
            raise InvalidParameter(
                "delay",
                setup.delay,
                f"shorter than the simulated duration = {setup.duration:g} s",
                "lengthen duration (or leave it unset) or shorten the delay",
            )
    if setup.max_step is not None:
        _scalar(setup, "max_step", _validate.positive("max_step", setup.max_step))
        contact_time = setup.contact_time
        if contact_time > 0 and setup.max_step > contact_time / 4:
            raise InvalidParameter(
                "max_step",
                setup.max_step,
                f"at most a quarter of the contact time pi*sqrt(m_f/k_c) = {contact_time:.3g} s "
                f"(contact_stiffness = {setup.contact_stiffness:g} N/m)",
                f"a coarser step can step over a whole contact; use max_step <= {contact_time / 4:.3g} s "
                "or leave it unset",
            )
