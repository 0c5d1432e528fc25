"""The wall contact: restitution of a Kelvin-Voigt contact that cannot pull, and the damping that gives one."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from .. import _validate
from ..errors import InvalidParameter


def contact_restitution(damping_ratio: float) -> float:
    """Coefficient of restitution of a mass on a Kelvin-Voigt contact that cannot pull.

    ``damping_ratio = c / (2 sqrt(k m))`` (dimensionless). The contact ends when ``k x + c xdot`` returns to
    zero, which for an undamped contact is at ``x = 0`` (restitution 1) and for a damped one while the surface
    is still indented; the restitution falls to ``exp(-2) = 0.135`` at critical damping and to 0 as
    ``1/(4 zeta^2)``, which it is taken as above ``zeta = 1e4`` (within 1e-7; it underflows to 0 above 1e154).
    """
    zeta = _scalar("damping_ratio", _validate.non_negative("damping_ratio", damping_ratio))
    if zeta == 0:
        return 1.0
    if zeta > 1e4:
        return 1 / (4 * zeta * zeta)
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

    from scipy.optimize import brentq  # imported when needed: scipy.optimize is slow to import

    upper = 0.5
    while force(upper) > 0:
        upper *= 2
    t_end = brentq(force, 1e-12, upper, xtol=1e-15, rtol=1e-14)
    return -position_velocity(t_end)[1]


def contact_damping_for_restitution(restitution: float, m_f: float, contact_stiffness: float) -> float:
    """Contact damping [N*s/m] giving ``restitution`` (in (0, 1]) to the finger alone on the contact.

    Parameters
    ----------
    restitution: coefficient of restitution, ``0 < e <= 1`` (dimensionless).
    m_f: finger mass [kg].
    contact_stiffness: contact stiffness [N/m], finite.
    """
    m_f = _scalar("m_f", _validate.positive("m_f", m_f))
    contact_stiffness = _scalar(
        "contact_stiffness", _validate.positive("contact_stiffness", contact_stiffness)
    )
    return damping_from_ratio(damping_ratio_for_restitution(restitution), m_f, contact_stiffness)


def damping_ratio_for_restitution(restitution: float) -> float:
    """The Kelvin-Voigt contact's damping ratio (dimensionless) that gives ``restitution``, ``0 < e <= 1``.

    The inverse of :func:`contact_restitution`, found by bracketing.
    """
    restitution = _scalar("restitution", _validate.real("restitution", restitution, "a number in (0, 1]"))
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
    return float(brentq(lambda z: contact_restitution(z) - restitution, 0.0, zeta_max, xtol=1e-14))


def damping_from_ratio(damping_ratio: float, mass: float, stiffness: float) -> float:
    """Damping [N*s/m] that is ``damping_ratio`` (dimensionless) times critical, ``2 sqrt(k m)``.

    Here ``mass`` [kg] is on a spring of ``stiffness`` [N/m].
    """
    return 2 * damping_ratio * math.sqrt(stiffness * mass)


def _scalar(name: str, value: Any) -> float:
    """``value`` (already checked to be real) as one float, or :class:`InvalidParameter` for an array."""
    if np.ndim(value) != 0:
        raise InvalidParameter(name, value, "one number, not an array")
    return float(value)
