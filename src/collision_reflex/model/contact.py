"""Transient contacts with a compliant object: a human body region as a spring with an effective mass.

A collaborative robot does not only touch rigid objects. ISO/TS 15066 (Annex A, carried into ISO 10218-2:2025)
models a body region as a linear spring ``k_c`` with an effective body mass ``m_H``, and the robot as one mass
``m_R`` moving at ``v`` along the contact direction. Two free masses joined at contact by a linear spring exchange
their relative kinetic energy with the spring: the reduced mass ``mu = m_R m_H / (m_R + m_H)`` compresses it by
``v sqrt(mu / k_c)``, so the transient (peak) contact force is ``F = v sqrt(mu k_c)``, reached a quarter period
after first touch, and the contact lasts half a period, ``pi sqrt(mu / k_c)``. The speed at which a region's
permissible transient force ``F_T`` is just reached is ``v = F_T / sqrt(mu k_c)``.

Which robot mass takes part depends on how fast the contact is against the joint's own spring. The robot is a
finger mass ``m_f`` (structure ahead of the joint springs) and the mass behind the springs ``m_r`` (the reflected
rotor inertia when the transmission is compliant), joined by ``k_m``. A contact much stiffer than the joint
(``k_c >= 100 k_m``) is over before the joint spring loads: the finger alone hits, ``m_R = m_f``. A contact much
softer (``k_c <= 0.01 k_m``) lasts long enough for the stiff joint to carry the rotor along: ``m_R = m_f + m_r``.
In between, the first peak lies between the two (checked against the time-domain simulator,
``tests/test_contact.py``), and the coupled mass is the conservative bound.

Integrators without a dynamic model take the robot's mass as ISO/TS 15066 (Annex A) estimates it:
``m_R = M / 2 + m_L``, half the moving mass plus the payload; :func:`iso_robot_mass` gives it for comparison.

A rigid object that returns part of the finger's momentum (coefficient of restitution ``e``) adds to the plastic
closed form an impulse that has one closed form where the finger has settled on the object before the contact is
detected. With the reference moving on at ``v0`` and the finger on the lumped spring ``k``, time in units of
``1 / w_s`` (``w_s = sqrt(k / m_f)``) and positions in ``v0 / w_s`` leave ``e`` as the only parameter: each
flight after an impact is a sine arc of the free oscillator, the finger lands again at the root of one equation,
and the flights shorten geometrically until it rests at ``w_s T(e)``. The spring then carries what it would have
carried had the finger stuck, plus the integral of its extra stretch, ``G(e) m_f v0`` (:func:`rebound`); ``G(e)
= 1.5 e^2`` for small ``e``. Detection waits for it if the plastic detection time ``F_s / (k v0)`` is at least
``T(e) / w_s``, i.e. up to ``v0 = F_s / (T(e) sqrt(k m_f)) = sqrt(2) v* / T(e)`` (:func:`settled_rebound_speed`);
beyond, the sensing and reaction overlap the rebound and only the simulator
(:mod:`collision_reflex.simulate`, ``contact_damping_for_restitution``) gives the impulse.

Every function accepts floats, NumPy arrays (broadcast) and CasADi symbols, except the rebound's (numeric
only). SI units: kg, N/m, m/s, N, s.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from .. import _validate
from .._backend import is_symbolic, sqrt
from ..errors import InvalidParameter

DECOUPLED_STIFFNESS_RATIO = 100.0
"""``k_c / k_m`` at and above which the finger alone meets the contact: its first peak is within 0.1 % of the
finger-only closed form in the simulator (``tests/test_contact.py`` checks 1 % over 100 to 10,000)."""
COUPLED_STIFFNESS_RATIO = 0.01
"""``k_c / k_m`` at and below which finger and rotor meet the contact as one mass (within 0.3 % in the
simulator; ``tests/test_contact.py`` checks 1 % over 0.0001 to 0.01)."""


@dataclass(frozen=True)
class BodyRegion:
    """A human body region as ISO/TS 15066 models it: a spring with an effective mass, and its force limits.

    name: what it is called; stiffness: its effective spring constant ``k_c`` [N/m]; mass: its effective mass
    ``m_H`` [kg] (``inf`` for a region held against something); transient_force: the largest permissible
    transient contact force ``F_T`` [N] (None where the standard permits no transient contact);
    quasi_static_force: the largest permissible quasi-static (clamping) force [N], None when not given.
    The standard's regions are :func:`collision_reflex.study.body_regions.load_body_regions`.
    """

    name: str
    stiffness: float
    mass: float
    transient_force: float | None
    quasi_static_force: float | None = None

    def __post_init__(self) -> None:
        _validate.positive("stiffness", self.stiffness)
        _validate.positive("mass", self.mass, allow_inf=True)
        for name in ("transient_force", "quasi_static_force"):
            if getattr(self, name) is not None:
                _validate.positive(name, getattr(self, name))


@dataclass(frozen=True)
class TransientContact:
    """A transient contact of a robot mass with a body region (floats, arrays or CasADi expressions).

    reduced_mass [kg]: ``mu = m_R m_H / (m_R + m_H)``; peak_force [N]: ``v sqrt(mu k_c)``; duration [s]: ``pi
    sqrt(mu / k_c)``, first touch to separation; compression [m]: the spring's largest compression,
    ``v sqrt(mu / k_c)``.
    """

    reduced_mass: Any
    peak_force: Any
    duration: Any
    compression: Any


def reduced_mass(robot_mass: Any, body_mass: Any = math.inf) -> Any:
    """``mu = m_R m_H / (m_R + m_H)`` [kg]; an infinite ``body_mass`` (a fixed object) gives ``m_R``.

    Parameters
    ----------
    robot_mass: the robot's effective mass along the contact direction [kg], > 0, finite.
    body_mass: the body region's effective mass [kg], > 0 (``inf`` for a fixed, rigidly supported object).
    """
    m_R = _validate.positive("robot_mass", robot_mass)
    m_H = _validate.positive("body_mass", body_mass, allow_inf=True)
    return _plain(1 / (1 / m_R + 1 / m_H))  # an infinite body mass drops out exactly


def transient_contact(
    velocity: Any, robot_mass: Any, contact_stiffness: Any, body_mass: Any = math.inf
) -> TransientContact:
    """Peak force, duration and compression of a robot mass meeting a body region at ``velocity``.

    Parameters
    ----------
    velocity: relative speed along the contact direction at first touch [m/s], > 0.
    robot_mass: the robot's effective mass [kg] (:func:`contact_robot_mass` says which one).
    contact_stiffness: the body region's spring constant ``k_c`` [N/m], > 0, finite.
    body_mass: the region's effective mass ``m_H`` [kg] (default ``inf``: a fixed object).
    """
    v = _validate.positive("velocity", velocity)
    k_c = _validate.positive("contact_stiffness", contact_stiffness)
    mu = reduced_mass(robot_mass, body_mass)
    with _validate.combining(velocity=v, robot_mass=robot_mass, contact_stiffness=k_c, body_mass=body_mass):
        return TransientContact(
            reduced_mass=mu,
            peak_force=_plain(v * sqrt(mu * k_c)),
            duration=_plain(math.pi * sqrt(mu / k_c)),
            compression=_plain(v * sqrt(mu / k_c)),
        )


def permissible_speed(
    force_limit: Any, robot_mass: Any, contact_stiffness: Any, body_mass: Any = math.inf
) -> Any:
    """The approach speed [m/s] at which the transient contact force just reaches ``force_limit`` [N].

    ``v = F_T / sqrt(mu k_c)``, the relation of ISO/TS 15066:2016 Annex A between a region's permissible force and
    speed; the other arguments as :func:`transient_contact`.
    """
    F_T = _validate.positive("force_limit", force_limit)
    k_c = _validate.positive("contact_stiffness", contact_stiffness)
    mu = reduced_mass(robot_mass, body_mass)
    with _validate.combining(
        force_limit=F_T, robot_mass=robot_mass, contact_stiffness=k_c, body_mass=body_mass
    ):
        return _plain(F_T / sqrt(mu * k_c))


def contact_robot_mass(
    finger_mass: Any, rotor_mass: Any, contact_stiffness: Any, mechanical_stiffness: Any
) -> tuple[Any, Any]:
    """The robot mass a contact meets [kg], and whether that mass is exact (``True``) or a bound.

    ``finger_mass`` ``m_f`` is ahead of the joint springs ``k_m``, ``rotor_mass`` ``m_r`` (the reflected rotor
    inertia, an effective mass) behind them. With ``k_c >= 100 k_m`` the finger alone (exact); with
    ``k_c <= 0.01 k_m`` finger and rotor together (exact); in between ``m_f + m_r``, which bounds the first peak
    from above (not exact). Numeric inputs only for the choice: CasADi symbols get the coupled mass and
    ``False``.
    """
    m_f = _validate.positive("finger_mass", finger_mass)
    m_r = _validate.non_negative("rotor_mass", rotor_mass)
    k_c = _validate.positive("contact_stiffness", contact_stiffness)
    k_m = _validate.positive("mechanical_stiffness", mechanical_stiffness, allow_inf=True)
    with _validate.combining(
        finger_mass=m_f, rotor_mass=m_r, contact_stiffness=k_c, mechanical_stiffness=k_m
    ):
        coupled = m_f + m_r
        np.broadcast_shapes(*(np.shape(x) for x in (m_f, m_r, k_c, k_m) if not is_symbolic(x)))
    if is_symbolic(m_f, m_r, k_c, k_m):
        return coupled, False
    ratio = np.asarray(k_c, dtype=float) / np.asarray(k_m, dtype=float)
    decoupled = ratio >= DECOUPLED_STIFFNESS_RATIO
    mass = np.where(decoupled, m_f, coupled)
    exact = decoupled | (ratio <= COUPLED_STIFFNESS_RATIO)
    if mass.ndim == 0:
        return float(mass), bool(exact)
    return mass, exact


def iso_robot_mass(moving_mass: Any, payload: Any = 0.0) -> Any:
    """The robot's effective mass as ISO/TS 15066 estimates it without a dynamic model [kg].

    ``m_R = M / 2 + m_L`` (ISO/TS 15066:2016, Annex A): ``moving_mass`` ``M`` [kg] is the total
    mass of the robot's moving parts, ``payload`` ``m_L`` [kg] the effective payload and tool.
    """
    M = _validate.positive("moving_mass", moving_mass)
    m_L = _validate.non_negative("payload", payload)
    return _plain(M / 2 + m_L)


@dataclass(frozen=True)
class Rebound:
    """How a finger that rebounds from a rigid object settles on it, pushed by the spring behind it.

    restitution: the contact's coefficient of restitution ``e`` for the finger alone; excess: ``G(e)``, the
    impulse the rebound adds to the plastic closed form, over ``m_f v0``; settling: ``T(e)``, the time from first
    touch until the finger rests on the object, over ``1 / w_s`` with ``w_s = sqrt(k / m_f)``; impacts: how many
    flights were followed exactly before the geometric tail (dimensionless all).
    """

    restitution: float
    excess: float
    settling: float
    impacts: int


MAX_REBOUNDS = 100_000
"""Flights followed before a rebound is refused as not settling (``e = 0.999`` needs about 6,800)."""


def rebound(restitution: float) -> Rebound:
    """The rebound of a finger pushed against a rigid object by a spring whose far end moves on at ``v0``.

    Scaled (time ``w_s t``, position ``x w_s / v0``, toward the object positive) the finger flies
    ``x(s) = t (1 - cos s) + s - (1 + e u) sin s`` after an impact at time ``t`` with speed ``u``, lands at the
    first root ``s > 0`` (within one period), and the spring's extra stretch ``-x`` integrates in closed form.
    Flights shorter than 1e-4 are parabolic to 1e-8: their geometric tail (ratio ``e``) is summed at once.

    Parameters
    ----------
    restitution: ``e`` in [0, 1), dimensionless (0 is the plastic impact: nothing added).
    """
    e = _validate.real("restitution", restitution, "a number in [0, 1)")
    if e.ndim or not 0 <= e < 1:
        raise InvalidParameter(
            "restitution", restitution, "one number in [0, 1)", "a contact with e >= 1 never settles"
        )
    return _settle(float(e))


@functools.lru_cache(maxsize=256)
def _settle(e: float) -> Rebound:
    """:func:`rebound` of a checked ``e``."""
    if 0 < e and 1 + e == 1:  # below float resolution the flight cannot be solved for; its limit e -> 0:
        # one flight s = sqrt(6 e) (from -e s + s^3/6 = 0), excess e s^2/2 - s^4/24 = 3 e^2 / 2
        return Rebound(e, 1.5 * e * e, math.sqrt(6 * e), 1)
    t, u, excess, impacts = 0.0, 1.0, 0.0, 0
    while e > 0:
        kick = 1 + e * u  # the finger's speed away from the spring's far end just after the impact

        def position(s: float, t: float = t, kick: float = kick) -> float:
            return t * _one_minus_cos(s) + s - kick * math.sin(s)

        # The flight's length to third order in s: -e u s + t s^2 / 2 + kick s^3 / 6 = 0.
        guess = min(2 * e * u / (t / 2 + math.sqrt(t * t / 4 + 2 * kick * e * u / 3)), math.pi)
        if t > 0 and guess < 1e-4:
            break
        if impacts == MAX_REBOUNDS:
            raise InvalidParameter(
                "restitution", e, "a contact that settles within 100,000 impacts", "simulate it instead"
            )
        step, end = guess / 16, guess / 16
        while position(end) < 0:  # negative just after the impact, positive after one period at most
            end += step
        from scipy.optimize import brentq  # lazy: scipy.optimize is slow to import

        s = brentq(position, end - step, end, xtol=1e-14 * guess, rtol=1e-15)
        excess += kick * _one_minus_cos(s) - t * (s - math.sin(s)) - s * s / 2
        u = 1 + t * math.sin(s) - kick * math.cos(s)
        t += s
        impacts += 1
    if e > 0:  # the parabolic tail: flights 2 e u / t long, each impact e times the last
        lift = e * u
        excess += 2 * lift**3 / (3 * t * t * (1 - e**3))
        t += 2 * lift / (t * (1 - e))
    return Rebound(e, excess, t, impacts)


def settled_rebound_speed(finger_mass: Any, stiffness: Any, threshold: Any, restitution: float) -> Any:
    """The fastest approach [m/s] at which a rebounding finger rests on the object before it is detected.

    ``F_s / (T(e) sqrt(k m_f))`` (:func:`rebound`; ``inf`` for a plastic contact). Parameters: ``finger_mass``
    ``m_f`` [kg], ``stiffness`` the lumped ``k`` [N/m], ``threshold`` the force at detection ``F_s`` [N], and the
    coefficient of restitution.
    """
    m_f = _validate.positive("finger_mass", finger_mass)
    k = _validate.positive("stiffness", stiffness)
    F_s = _validate.positive("threshold", threshold)
    settling = rebound(restitution).settling
    with _validate.combining(finger_mass=m_f, stiffness=k, threshold=F_s), np.errstate(divide="ignore"):
        return _plain(np.divide(F_s, settling * np.sqrt(k * m_f)))


def rebound_impulse(
    finger_mass: Any, stiffness: Any, threshold: Any, velocity: Any, restitution: float
) -> Any:
    """The impulse [N*s] a rebounding contact adds to the plastic closed form, ``G(e) m_f v0``.

    Exact for the paper's model (the far end of the spring moving on at ``v0`` until detection) where the
    finger settles before it is detected, i.e. ``velocity <= settled_rebound_speed(...)``; beyond it the rebound
    overlaps the sensing and :class:`~collision_reflex.errors.InvalidParameter` says to simulate it. Arguments
    as :func:`settled_rebound_speed`, ``velocity`` ``v0`` [m/s] > 0.
    """
    v0 = _validate.positive("velocity", velocity)
    fastest = settled_rebound_speed(finger_mass, stiffness, threshold, restitution)
    with _validate.combining(velocity=v0, finger_mass=finger_mass, stiffness=stiffness, threshold=threshold):
        beyond = np.asarray(v0 > fastest * (1 + 1e-12))
    if beyond.any():
        raise InvalidParameter(
            "velocity",
            velocity,
            f"at most the settled-rebound speed {np.min(fastest):.4g} m/s (restitution {restitution:g})",
            "faster, the finger is still rebounding when the contact is detected: simulate it "
            "(crx simulate --restitution)",
        )
    return _plain(rebound(restitution).excess * np.asarray(finger_mass, dtype=float) * v0)


def _one_minus_cos(s: float) -> float:
    """``1 - cos s`` without the cancellation of small ``s``."""
    return 2 * math.sin(s / 2) ** 2


def _plain(value: Any) -> Any:
    """A numeric scalar as a Python float; arrays and CasADi expressions as they are."""
    if is_symbolic(value) or np.ndim(value):
        return value
    return float(value)
