"""The one-dimensional collision-reflex model.

From Bhatia, Mason and Johnson, "Reacting to Contact: Transparency and Collision Reflex in Actuation"
(equations ``eq:initial`` to ``eq:v_star``). A finger (sprung) mass ``m_f`` and a robot (unsprung) mass ``m_r``,
joined by a spring, move at ``v0`` into a rigid constraint. The impulse transferred has three phases:

1. plastic impact of the finger, ``I1 = m_f v0``;
2. sensing: the velocity-controlled robot compresses the lumped spring ``k`` until the force reaches the
   threshold ``F_s`` at ``t1 = F_s / (k v0)``, ``I2 = F_s**2 / (2 k v0)``;
3. reaction: the software spring is zeroed and the robot accelerates away at ``a`` against the mechanical
   spring ``k_m`` until the force returns to zero at ``t2``.

Every function here accepts floats, NumPy arrays (broadcast against each other) and CasADi ``SX``/``MX``
symbols alike, from one implementation. Units are SI throughout: masses [kg], stiffnesses [N/m], forces [N],
accelerations [m/s^2], velocities [m/s], times [s], impulses [N*s].

Supported range of numeric inputs: any finite positive number (integers and integer arrays are converted to
float64 first; strings, booleans and complex numbers are refused with :class:`InvalidParameter`). A result is
computed without intermediate overflow or underflow wherever it is representable: where the direct formula
overflows, it is evaluated from logarithms instead. A result beyond the float64 range (about ``1.8e308``)
raises :class:`InvalidParameter`, and so does a total, a time or a minimum impulse that underflows below the
smallest float64 (about ``5e-324``): never a silent 0 for a quantity that is positive. None is ever NaN.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from .. import _validate
from .._backend import is_symbolic, sin, sqrt, where
from ..errors import InvalidParameter
from ..vocabulary import REACTION_MODES


@dataclass(frozen=True)
class PhaseImpulses:
    """Impulse of each phase of a collision [N*s] (floats, arrays or CasADi expressions)."""

    initial: Any
    """Plastic impact of the finger mass, ``m_f v0`` (``eq:initial``)."""
    sensing: Any
    """Spring compression until detection, ``F_s**2 / (2 k v0)`` (``eq:sensing``)."""
    reaction: Any
    """Acceleration away against the mechanical spring (``eq:reaction`` or its moving-robot extension)."""

    @property
    def total(self) -> Any:
        """Collision-reflex metric, the sum of the three phases (``eq:total_impulse``)."""
        return self.initial + self.sensing + self.reaction


def series_stiffness(k_m: Any, k_s: Any) -> Any:
    """Lumped stiffness of the mechanical and software springs in series [N/m].

    Parameters
    ----------
    k_m: mechanical stiffness [N/m], > 0 (``inf`` for a rigid structure).
    k_s: software (controller) stiffness [N/m], > 0 (``inf`` for an ideal position controller).
    """
    _validate.positive("k_m", k_m, allow_inf=True)
    _validate.positive("k_s", k_s, allow_inf=True)
    _broadcastable(k_m=k_m, k_s=k_s)
    # Compliances add; written this way an infinite stiffness simply drops out (and two give inf).
    if is_symbolic(k_m, k_s):
        return 1 / (1 / k_m + 1 / k_s)
    with np.errstate(divide="ignore"):
        lumped = 1 / (1 / np.asarray(k_m, dtype=float) + 1 / np.asarray(k_s, dtype=float))
    return lumped if lumped.ndim else float(lumped)


def phase_impulses(
    m_f: Any, k: Any, k_m: Any, F_s: Any, a: Any, v0: Any, reaction: str = "at_rest", v_r: Any = None
) -> PhaseImpulses:
    """Impulse of the three phases of a collision.

    Parameters
    ----------
    m_f: finger (sprung) mass [kg].
    k: lumped stiffness during sensing [N/m], see :func:`series_stiffness`.
    k_m: mechanical stiffness, the only spring left during the reaction [N/m].
    F_s: sensing threshold, contact force at detection [N].
    a: acceleration of the robot mass away from the constraint during the reaction [m/s^2].
    v0: pre-impact (approach) velocity [m/s].
    reaction: ``"at_rest"`` (the paper's model) or ``"moving"`` (robot still moving at ``v_r`` at detection).
    v_r: robot-mass velocity toward the constraint at detection [m/s], ``"moving"`` only; default ``v0``
        (an ideally velocity-controlled robot mass).
    """
    m_f, k, k_m, F_s, a, v0, v_r = _checked(m_f, k, k_m, F_s, a, v0, reaction, v_r)
    initial = _representable(
        "the impact impulse m_f v0", (m_f, v0), lambda: m_f * v0, lambda: np.log(m_f) + np.log(v0)
    )
    sensing = _representable(
        "the sensing impulse F_s^2 / (2 k v0)",
        (F_s, k, v0),
        lambda: F_s**2 / (2 * k * v0),
        lambda: 2 * np.log(F_s) - np.log(2.0) - np.log(k) - np.log(v0),
    )
    _, reaction_impulse = _reaction_phase(F_s, k_m, a, v_r)
    return PhaseImpulses(initial, sensing, reaction_impulse)


def total_impulse(
    m_f: Any, k: Any, k_m: Any, F_s: Any, a: Any, v0: Any, reaction: str = "at_rest", v_r: Any = None
) -> Any:
    """Collision-reflex metric ``I = I1 + I2 + I3`` [N*s]; arguments as :func:`phase_impulses`."""
    return _finite("the total impulse", phase_impulses(m_f, k, k_m, F_s, a, v0, reaction, v_r).total)


def collision_times(
    m_f: Any, k: Any, k_m: Any, F_s: Any, a: Any, v0: Any, reaction: str = "at_rest", v_r: Any = None
) -> tuple[Any, Any]:
    """Detection time ``t1`` and end of contact ``t2`` [s], impact at ``t = 0``.

    Arguments as :func:`phase_impulses`.
    """
    m_f, k, k_m, F_s, a, v0, v_r = _checked(m_f, k, k_m, F_s, a, v0, reaction, v_r)
    t1 = _detection_time(F_s, k, v0)
    duration, _ = _reaction_phase(F_s, k_m, a, v_r)
    return t1, _finite("the end of contact t2", t1 + duration)


def velocity_coefficients(m_f: Any, k: Any, k_m: Any, F_s: Any, a: Any) -> tuple[Any, Any, Any]:
    """Coefficients of ``I(v0) = A v0 + B / v0 + C`` for the paper's (at-rest) reaction.

    Returns ``(A, B, C) = (m_f, F_s**2 / (2 k), I3)``: ``A`` [kg] = [N*s per m/s], ``B`` [N*m] = [N*s times
    m/s], ``C`` [N*s]; they are the three phase impulses at ``v0 = 1 m/s`` (paper, "Effect of Actuator
    Selection").
    """
    phases = phase_impulses(m_f, k, k_m, F_s, a, 1.0)
    return phases.initial, phases.sensing, phases.reaction


def optimal_velocity(
    m_f: Any, k: Any, F_s: Any, reaction: str = "at_rest", k_m: Any = None, a: Any = None
) -> Any:
    """Approach velocity that minimises the impulse [m/s].

    For the paper's reaction it is ``v* = F_s / sqrt(2 k m_f)`` (``eq:v_star``); ``d2I/dv0^2 = F_s^2/(k v0^3)
    > 0`` so it is the unique minimum. With ``reaction="moving"`` and the robot moving at ``v_r = v0``, the
    reaction impulse grows with ``v0`` and the optimum lies below the paper's ``v*``; it is found numerically
    (bounded scalar minimisation per element, numeric inputs only) and needs ``k_m`` and ``a``.
    """
    _validate.choice("reaction", reaction, REACTION_MODES)
    m_f, k, F_s = (_validate.positive(name, value) for name, value in (("m_f", m_f), ("k", k), ("F_s", F_s)))
    _broadcastable(m_f=m_f, k=k, F_s=F_s)
    v_star = _representable(
        "the optimal velocity F_s / sqrt(2 k m_f)",
        (F_s, k, m_f),
        lambda: F_s / sqrt(2 * k * m_f),
        lambda: np.log(F_s) - (np.log(2.0) + np.log(k) + np.log(m_f)) / 2,
    )
    if reaction == "at_rest":
        return v_star
    if k_m is None or a is None:
        raise InvalidParameter(
            "k_m, a", (k_m, a), "both given", "the moving-robot optimum depends on the reaction phase"
        )
    if is_symbolic(m_f, k, F_s, k_m, a):
        raise InvalidParameter(
            "reaction",
            reaction,
            "'at_rest' for symbolic arguments",
            "the moving-robot optimum has no closed form; use numeric values",
        )
    k_m, a = _validate.positive("k_m", k_m), _validate.positive("a", a)
    _broadcastable(m_f=m_f, k=k, F_s=F_s, k_m=k_m, a=a)
    if np.any(np.asarray(v_star) < np.finfo(np.float64).tiny):
        raise InvalidParameter(
            "the optimal velocity F_s / sqrt(2 k m_f)",
            v_star,
            "a result within the float64 range (above 2.2e-308)",
        )
    return _moving_optimum(m_f, k, k_m, F_s, a, v_star)


def minimum_impulse(m_f: Any, k: Any, k_m: Any, F_s: Any, a: Any, reaction: str = "at_rest") -> Any:
    """Impulse at the optimal approach velocity [N*s].

    For the paper's reaction, ``I* = sqrt(2) F_s / w_s + I3`` with ``w_s = sqrt(k / m_f)`` the open-loop
    sensing bandwidth and ``I3`` the reaction impulse (the paper writes the latter with ``w_a = sqrt(k/m_r)``;
    its own derivation uses ``k_m`` in the reaction, which is what is used here). For ``"moving"``, the total
    impulse at the numerically found optimum with ``v_r = v0``.
    """
    _validate.choice("reaction", reaction, REACTION_MODES)
    if reaction == "moving":
        v_opt = optimal_velocity(m_f, k, F_s, "moving", k_m, a)
        return total_impulse(m_f, k, k_m, F_s, a, v_opt, "moving")
    m_f, k, k_m, F_s, a, _, _ = _checked(m_f, k, k_m, F_s, a, 1.0, reaction, None)
    sensing = _representable(
        "the sensing-and-impact impulse sqrt(2) F_s / w_s",
        (F_s, k, m_f),
        lambda: np.sqrt(2.0) * F_s / sqrt(k / m_f),  # w_s = sqrt(k / m_f)
        lambda: np.log(2.0) / 2 + np.log(F_s) - (np.log(k) - np.log(m_f)) / 2,
    )
    _, reaction_impulse = _reaction_phase(F_s, k_m, a, 0.0)
    return _finite("the minimum impulse", sensing + reaction_impulse)


def force_profile(
    t: Any, m_f: Any, k: Any, k_m: Any, F_s: Any, a: Any, v0: Any, reaction: str = "at_rest", v_r: Any = None
) -> Any:
    """Contact force ``F(t)`` [N] of the model, impact at ``t = 0`` [s].

    The sum of three pieces whose integrals are the three phase impulses:

    - the impact pulse, the compression quarter-period of ``m_f`` on ``k_m``:
      ``m_f v0 w sin(w t)`` for ``0 <= t <= pi/(2 w)``, ``w = sqrt(k_m/m_f)`` (area ``m_f v0``);
    - the sensing ramp ``k v0 t`` for ``0 <= t < t1``;
    - the reaction from ``t1`` until the force returns to zero at ``t2``: ``F_s - k_m a tau^2/2`` at rest, or
      ``k_m (x1 + v_r tau - a tau^2/2)`` with ``x1 = F_s/k_m`` when moving (``tau = t - t1``).
    """
    t = _validate.finite("t", t)
    m_f, k, k_m, F_s, a, v0, v_r = _checked(m_f, k, k_m, F_s, a, v0, reaction, v_r)
    _broadcastable(t=t, m_f=m_f, k=k, k_m=k_m, F_s=F_s, a=a, v0=v0, v_r=v_r)
    omega = sqrt(k_m / m_f)
    t1 = _detection_time(F_s, k, v0)
    duration, _ = _reaction_phase(F_s, k_m, a, v_r)
    tau = t - t1

    def in_reaction(value: Any) -> Any:  # the value inside the reaction's window, 0 outside
        return where(tau >= 0, where(tau <= duration, value, 0.0), 0.0)

    pulse_end = impact_pulse_duration(m_f, k_m)
    pulse = where(t >= 0, where(t <= pulse_end, m_f * v0 * omega * sin(omega * t), 0.0), 0.0)
    ramp = where(t >= 0, where(t < t1, sensing_force(t, k, v0), 0.0), 0.0)
    window_tau = in_reaction(tau)  # tau**2 of a far-off t would overflow
    reaction_part = in_reaction(k_m * (F_s / k_m + v_r * window_tau - a * window_tau**2 / 2))
    return pulse + ramp + reaction_part


def impact_pulse_duration(m_f: Any, k_m: Any) -> Any:
    """Duration of the impact pulse [s]: the compression quarter-period ``pi / (2 w)``.

    That of the finger mass ``m_f`` [kg] on the mechanical spring ``k_m`` [N/m], ``w = sqrt(k_m / m_f)``.
    """
    m_f, k_m = _validate.positive("m_f", m_f), _validate.positive("k_m", k_m)
    with _validate.combining(m_f=m_f, k_m=k_m):
        return _finite("the impact pulse duration", np.pi / (2 * sqrt(k_m / m_f)))


def sensing_force(t: Any, k: Any, v0: Any) -> Any:
    """Contact force of the sensing ramp at time ``t`` [s] after impact [N].

    The velocity-controlled robot compresses the lumped spring ``k`` [N/m] at ``v0`` [m/s], ``F = k v0 t``
    (valid until detection, ``t1``).
    """
    t, k, v0 = _validate.finite("t", t), _validate.positive("k", k), _validate.positive("v0", v0)
    with _validate.combining(t=t, k=k, v0=v0):
        force = k * v0 * t
    if not is_symbolic(force) and not np.all(np.isfinite(force)):
        raise InvalidParameter(
            "t, k, v0", (t, k, v0), "values whose force k v0 t is within the float64 range"
        )
    return force


def reaction_duration(F_s: Any, k_m: Any, a: Any, v_r: Any = 0.0) -> Any:
    """Duration ``t2 - t1`` of the reaction phase [s].

    From detection at ``F_s`` [N] until the mechanical spring ``k_m`` [N/m] is unloaded, the robot mass
    accelerating away at ``a`` [m/s^2] from a velocity ``v_r`` [m/s] toward the constraint (0: the paper's
    robot at rest, ``sqrt(2 F_s / (a k_m))``).
    """
    F_s, k_m, a = (_validate.positive(name, value) for name, value in (("F_s", F_s), ("k_m", k_m), ("a", a)))
    v_r = _validate.non_negative("v_r", v_r)
    _broadcastable(F_s=F_s, k_m=k_m, a=a, v_r=v_r)
    duration, _ = _reaction_phase(F_s, k_m, a, v_r)
    return duration


def _reaction_phase(F_s: Any, k_m: Any, a: Any, v_r: Any) -> tuple[Any, Any]:
    """Duration ``t2 - t1`` [s] and impulse [N*s] of the reaction phase.

    The spring starts compressed by ``x1 = F_s/k_m`` and the robot mass moves toward the constraint at ``v_r``
    while accelerating away at ``a``: compression ``x1 + v_r tau - a tau^2/2``, zero at
    ``tau_e = (v_r + sqrt(v_r^2 + 2 a x1)) / a``, impulse ``k_m (x1 tau_e + v_r tau_e^2/2 - a tau_e^3/6)``.
    With ``v_r = 0`` this is the paper's ``eq:reaction``: ``tau_e = tau_0 = sqrt(2 F_s/(a k_m))`` and
    ``I3 = sqrt(8 F_s^3 / (9 a k_m))``.

    Written in the scale-free velocity ``r = v_r / (a tau_0)``, with ``g = r + sqrt(1 + r^2)`` (so that
    ``g^2 = 2 r g + 1``): ``tau_e = tau_0 g`` and ``I3 = F_s tau_0 (2 g (1 + r^2) + r) / 3``, a sum of positive
    terms that cannot cancel, whatever the velocity.
    """

    def direct() -> tuple[Any, Any]:
        tau_0 = sqrt(2 * F_s / (a * k_m))
        r = v_r / (a * tau_0)
        g = r + sqrt(1 + r**2)
        return tau_0 * g, F_s * tau_0 * (2 * g * (1 + r**2) + r) / 3

    if is_symbolic(F_s, k_m, a, v_r):
        return direct()
    inputs = (F_s, k_m, a, v_r)
    logs = functools.cache(lambda: _reaction_logarithms(F_s, k_m, a, v_r))
    duration = _representable("the reaction time", inputs, lambda: direct()[0], lambda: logs()[0])
    impulse = _representable("the reaction impulse", inputs, lambda: direct()[1], lambda: logs()[1])
    return duration, impulse


def sprung_reaction(F_s: Any, k_m: Any, F_a: Any, m_r: Any, v_r: Any = 0.0) -> tuple[Any, Any]:
    """Duration [s] and impulse [N*s] of the reaction when the spring also pushes the robot mass away.

    An option beside :func:`phase_impulses`' reaction, which moves the robot mass at the constant ``a = F_a /
    m_r`` whatever the spring does. A torque-limited motor is pushed back by the compressed spring as well:
    ``m_r x'' = -F_a - k_m x`` for the compression ``x`` (finger at the constraint), ``x(0) = x1 = F_s / k_m``,
    ``x'(0) = v_r``. With ``w = sqrt(k_m / m_r)`` and ``A = F_a / k_m``, ``x = -A + (x1 + A) cos wt + (v_r / w)
    sin wt``; it is zero first at ``w tau_e = phi + arccos(A / R)``, ``R = hypot(x1 + A, v_r / w)``, ``phi =
    atan2(v_r / w, x1 + A)``, and the impulse is ``k_m (-A tau_e + (x1 + A) sin(w tau_e) / w + v_r (1 - cos(w
    tau_e)) / w^2)``. It tends to the constant-acceleration reaction as ``F_s / F_a -> 0`` (the spring's push
    ``k_m x1 = F_s`` against the motor's ``F_a``); at ``F_s = F_a`` and ``v_r = 0`` it is 27 % smaller.

    Parameters
    ----------
    F_s: contact force at detection [N], > 0.
    k_m: mechanical stiffness [N/m], > 0.
    F_a: the motors' largest force along the escape direction [N], > 0.
    m_r: robot (motor-side) mass [kg], > 0.
    v_r: robot-mass velocity toward the constraint at detection [m/s], >= 0.
    """
    F_s, k_m, F_a, m_r = (
        np.asarray(_validate.positive(name, value), dtype=float)
        for name, value in (("F_s", F_s), ("k_m", k_m), ("F_a", F_a), ("m_r", m_r))
    )
    v_r = np.asarray(_validate.non_negative("v_r", v_r), dtype=float)
    _broadcastable(F_s=F_s, k_m=k_m, F_a=F_a, m_r=m_r, v_r=v_r)
    with _validate.combining(F_s=F_s, k_m=k_m, F_a=F_a, m_r=m_r, v_r=v_r), np.errstate(invalid="ignore"):
        w = np.sqrt(k_m / m_r)
        x1, push = F_s / k_m, F_a / k_m
        phase = np.arctan2(v_r / w, x1 + push)
        tau_e = (phase + np.arccos(push / np.hypot(x1 + push, v_r / w))) / w
        impulse = k_m * (
            -push * tau_e + (x1 + push) * np.sin(w * tau_e) / w + v_r * (1 - np.cos(w * tau_e)) / w**2
        )
    tau_e, impulse = _finite("the reaction time", tau_e), _finite("the reaction impulse", impulse)
    return (tau_e if tau_e.ndim else float(tau_e)), (impulse if impulse.ndim else float(impulse))


def _reaction_logarithms(F_s: Any, k_m: Any, a: Any, v_r: Any) -> tuple[Any, Any]:
    """Logarithms of the reaction's duration and impulse, from the inputs' logarithms (no overflow)."""
    log_tau_0 = (np.log(2.0) + np.log(F_s) - np.log(a) - np.log(k_m)) / 2
    log_r = np.log(v_r) - np.log(a) - log_tau_0  # -inf for v_r = 0
    log_1r2 = np.logaddexp(0.0, 2 * log_r)  # ln(1 + r^2)
    log_g = np.logaddexp(log_r, log_1r2 / 2)  # ln(r + sqrt(1 + r^2))
    log_bracket = np.logaddexp(np.log(2.0) + log_g + log_1r2, log_r) - np.log(3.0)
    return log_tau_0 + log_g, np.log(F_s) + log_tau_0 + log_bracket


def _detection_time(F_s: Any, k: Any, v0: Any) -> Any:
    """Detection time ``t1 = F_s / (k v0)`` (``eq:t1def``) [s]."""
    return _representable(
        "the detection time F_s / (k v0)",
        (F_s, k, v0),
        lambda: F_s / (k * v0),
        lambda: np.log(F_s) - np.log(k) - np.log(v0),
    )


_LOG_MAX = float(np.log(np.finfo(np.float64).max))
_EVERYDAY = (1e-25, 1e25)
"""Inputs within this range (or 0) keep every intermediate of the direct formulas (products of at most a few
such factors and their square roots) far from overflow to inf and from underflow into subnormals, where
digits are lost silently; the direct form is then exact to a few ulps."""


def _representable(
    what: str, inputs: tuple[Any, ...], direct: Callable[[], Any], logarithm: Callable[[], Any]
) -> Any:
    """``direct()`` where ``inputs`` are everyday values and it is finite, else ``exp(logarithm())``.

    A symbolic ``direct()`` is returned as it is; a result beyond the float64 range raises
    :class:`InvalidParameter` naming ``what``. The logarithmic form is accurate to about ``|ln x|`` ulps.
    """
    if is_symbolic(*inputs):
        return direct()
    with np.errstate(over="ignore", under="ignore", invalid="ignore", divide="ignore"):
        try:
            value = direct()
        except (ZeroDivisionError, OverflowError):  # Python floats raise where NumPy's give inf
            value = np.full(np.shape(logarithm()), np.nan)
        value = np.asarray(value, dtype=float)
        bad = ~np.isfinite(value)
        for x in inputs:
            x = np.asarray(x, dtype=float)
            bad = bad | ~((x == 0) | ((x >= _EVERYDAY[0]) & (x <= _EVERYDAY[1])))
        if np.any(bad):
            logs = np.broadcast_to(np.asarray(logarithm(), dtype=float), value.shape)
            if np.any(logs[bad] > _LOG_MAX) or np.any(np.isnan(logs[bad])):
                exponent = float(np.max(logs[bad])) / np.log(10.0)
                raise InvalidParameter(
                    what,
                    math.inf,
                    "a result within the float64 range (below 1.8e308)",
                    f"it would be about 1e{exponent:.0f}; see collision_reflex.model.impulse for the inputs' range",
                )
            value = np.where(bad, np.exp(logs), value)
    return value if value.ndim else float(value)


def _finite(what: str, value: Any) -> Any:
    """``value`` (positive by construction) if it is symbolic or a positive finite number.

    Else :class:`InvalidParameter`: a sum beyond the float64 range, or one that underflowed to 0 (never
    returned as a silent 0 for a quantity that cannot be 0).
    """
    if is_symbolic(value):
        return value
    if not np.all(np.isfinite(value)):
        raise InvalidParameter(what, value, "a result within the float64 range (below 1.8e308)")
    if np.any(np.asarray(value) == 0):
        raise InvalidParameter(
            what,
            value,
            "a result within the float64 range (above 5e-324)",
            "it underflows to 0 though it is positive: the inputs are at the edge of the float64 range; rescale "
            "them (other units)",
        )
    return value


def _broadcastable(**arguments: Any) -> None:
    """Raise :class:`InvalidParameter` unless the NumPy arrays among ``arguments`` broadcast together."""
    shapes = {name: np.shape(value) for name, value in arguments.items() if not is_symbolic(value)}
    try:
        np.broadcast_shapes(*shapes.values())
    except ValueError:
        arrays = {name: shape for name, shape in shapes.items() if shape}
        raise InvalidParameter(
            ", ".join(arrays), arrays, "shapes that broadcast together (NumPy rules)"
        ) from None


def _checked(
    m_f: Any, k: Any, k_m: Any, F_s: Any, a: Any, v0: Any, reaction: str, v_r: Any
) -> tuple[Any, Any, Any, Any, Any, Any, Any]:
    """Validate the model's inputs and resolve ``v_r`` from the reaction mode."""
    _validate.choice("reaction", reaction, REACTION_MODES)
    inputs = (("m_f", m_f), ("k", k), ("k_m", k_m), ("F_s", F_s), ("a", a), ("v0", v0))
    m_f, k, k_m, F_s, a, v0 = (_validate.positive(name, value) for name, value in inputs)
    if reaction == "at_rest":
        if v_r is not None:
            raise InvalidParameter(
                "v_r", v_r, "None with reaction='at_rest'", "pass reaction='moving' to give a robot velocity"
            )
        v_r = 0.0
    elif v_r is None:
        v_r = v0
    else:
        v_r = _validate.non_negative("v_r", v_r)
    _broadcastable(m_f=m_f, k=k, k_m=k_m, F_s=F_s, a=a, v0=v0, v_r=v_r)
    return m_f, k, k_m, F_s, a, v0, v_r


def _moving_optimum(m_f: Any, k: Any, k_m: Any, F_s: Any, a: Any, v_star: Any) -> Any:
    """Minimise ``I(v0)`` with the moving-robot reaction (``v_r = v0``) per element on ``(0, v*]``.

    The search runs on ``ln v0`` and ``ln I``: scale-free, so that it neither overflows nor loses digits
    whatever the magnitudes (the minimiser is the same).
    """
    from scipy.optimize import minimize_scalar

    args = np.broadcast_arrays(*(np.asarray(x, dtype=float) for x in (m_f, k, k_m, F_s, a, v_star)))
    out = np.empty(args[0].shape)
    for index in np.ndindex(out.shape):
        mf_i, k_i, km_i, fs_i, a_i, vs_i = (float(x[index]) for x in args)
        log_impulse = functools.partial(_moving_log_impulse, mf_i, k_i, km_i, fs_i, a_i)
        # The reaction impulse grows with v_r = v0, so the optimum is below the at-rest v*; I -> inf as v0 -> 0.
        top = math.log(vs_i)
        found = minimize_scalar(
            log_impulse, bounds=(top + math.log(1e-6), top), method="bounded", options={"xatol": 1e-12}
        )
        out[index] = math.exp(found.x)
    return out if out.ndim else float(out)


def _moving_log_impulse(m_f: float, k: float, k_m: float, F_s: float, a: float, log_v0: float) -> float:
    impulse = float(total_impulse(m_f, k, k_m, F_s, a, math.exp(log_v0), "moving"))
    if impulse < np.finfo(np.float64).tiny:  # below the normal floats: no digits left to minimise
        raise InvalidParameter(
            "the moving-robot impulse", impulse, "a result within the float64 range (above 2.2e-308)"
        )
    return math.log(impulse)
