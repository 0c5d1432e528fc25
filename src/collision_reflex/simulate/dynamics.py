"""The collision as a hybrid system: its state, its forces and equations of motion in each mode.

It also holds the events that leave a mode and the jumps at them (impacts, contact loss, play, stiction).

Topology, from the wall outwards (positions positive toward the wall)::

    wall | contact (rigid plastic, or stiffness k_c + damping c_c) | finger m_f | spring k_m (+ backlash)
         | robot mass m_r (+ Coulomb and viscous friction) | controller: software spring k_s, damping d_s,
           reference moving at v0; after detection, the actuator's force limit F_a away from the wall
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np

from .setup import CollisionSetup, oscillation_period

# State layout. Deflections are states of their own (not differences of absolute positions) so that the
# tolerances resolve a spring compression of nanometres while the reference travels centimetres.
XF, VF, DEFL, VR, ERR, SURF, IMP, WORK, LOSS = range(9)
NSTATE = 9


def admittance_share(k_m: Any, k_s: Any) -> Any:
    """Share ``k_s / (k_s + k_m)`` of the reference velocity that an admittance-controlled drive follows.

    This holds while its springs ``k_m``, ``k_s`` [N/m] are loaded (the rest follows the finger); 1 where
    ``k_s`` is infinite.
    """
    k_s = np.asarray(k_s, dtype=float)
    finite = np.where(np.isinf(k_s), 1.0, k_s)
    share = np.where(np.isinf(k_s), 1.0, finite / (finite + k_m))
    return share if share.ndim else float(share)


class HybridCollision:
    """Mode-switching model of one collision; modes change only at events or at sample instants.

    Contact modes: ``"held"`` (rigid wall: the finger rests on it, the wall carries the spring force),
    ``"pressed"`` (compliant wall loaded), ``"free"``. Drive modes: ``"kinematic"`` (ideal approach),
    ``"impedance"``, ``"none"`` (free collision) and ``"reaction"``.
    """

    def __init__(self, setup: CollisionSetup) -> None:
        self.s = setup
        self.m_f, self.m_r = setup.m_f, setup.m_r
        self.k_m, self.k_s = setup.k_m, setup.k_s
        self.k_c, self.c_c = setup.contact_stiffness, setup.contact_damping
        self.v0 = setup.v0
        self.share = admittance_share(self.k_m, self.k_s)  # of the ideal drive, while the spring is loaded
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
        """Ideal drive: split the chain deflection ``total`` between the spring and the admittance.

        ``total`` is the spring deflection + admittance yield. Returns
        ``(deflection, yield, robot velocity, d v_r / d a_f)``.
        """
        if math.isinf(self.k_s):
            return total, 0.0, self.v0, 0.0
        closing = self.v0 - v_f  # rate of change of `total`
        if total > self.half_gap or (total == self.half_gap and closing > 0):
            edge = self.half_gap
        elif total < -self.half_gap or (total == -self.half_gap and closing < 0):
            edge = -self.half_gap
        else:  # inside the play: the spring carries nothing and the robot tracks the reference exactly
            return total, 0.0, self.v0, 0.0
        share = self.share
        deflection = edge + share * (total - edge)
        return deflection, total - deflection, share * self.v0 + (1 - share) * v_f, 1 - share

    def impedance_law(self, y: np.ndarray) -> float:
        """Impedance force ``k_s e + d_s (v0 - v_r)`` on the robot mass, saturated at ``F_a`` [N]."""
        force = self.k_s * y[ERR] + self.s.software_damping * (self.v0 - y[VR])
        return float(np.clip(force, -self.s.F_a, self.s.F_a))

    def resolved(self, y: np.ndarray) -> np.ndarray:
        """The state with the algebraic parts of the current mode filled in."""
        y = np.array(y, dtype=float)
        if self.contact == "held":
            y[VF] = 0.0
        if self.drive == "kinematic":
            y[DEFL], y[ERR], y[VR], _ = self.kinematic(y[DEFL] + y[ERR], y[VF])
        elif self.robot_stuck:
            y[VR] = 0.0
        return y

    def forces(self, t: float, y: np.ndarray) -> dict[str, float]:
        """Spring, contact and actuator forces and both accelerations, for a resolved state."""
        v_f, v_r, deflection = y[VF], y[VR], y[DEFL]
        spring = self.spring(deflection)
        if self.contact == "held":
            contact = spring
        elif self.contact == "pressed":
            contact = self.k_c * y[XF] + self.c_c * v_f
        else:
            contact = 0.0
        a_f = 0.0 if self.contact == "held" else (spring - contact) / self.m_f
        if self.drive == "kinematic":
            a_r = self.kinematic(deflection + y[ERR], v_f)[3] * a_f
            actuator = spring + self.friction(v_r) + self.m_r * a_r  # what the ideal controller must supply
        else:
            if self.drive == "reaction":
                actuator = -self.s.F_a
            elif self.drive == "impedance":
                actuator = self.held_force if self.sampled else self.impedance_law(y)
            else:
                actuator = 0.0
            a_r = 0.0 if self.robot_stuck else (actuator - spring - self.friction(v_r)) / self.m_r
        return {"spring": spring, "contact": contact, "actuator": actuator, "a_f": a_f, "a_r": a_r}

    def rhs(self, t: float, y_raw: np.ndarray) -> np.ndarray:
        """Time derivative of the state in the current mode, for ``solve_ivp``."""
        y = self.resolved(y_raw)
        f = self.forces(t, y)
        v_f, v_r = y[VF], y[VR]
        dy = np.zeros(NSTATE)
        loss = self.friction(v_r) * v_r
        if self.contact == "pressed":
            dy[SURF] = v_f
            loss += self.c_c * v_f**2
        elif not self.rigid and self.c_c > 0 and y[SURF] > 0:
            rate = self.k_c / self.c_c  # an unloaded Kelvin-Voigt surface recovers exponentially
            dy[SURF] = -rate * y[SURF]
            loss += self.c_c * (rate * y[SURF]) ** 2
        dy[XF] = v_f
        dy[VF] = f["a_f"]
        dy[DEFL] = v_r - v_f
        dy[VR] = f["a_r"]
        dy[ERR] = self.v0 - v_r if self.drive in ("kinematic", "impedance") else 0.0
        dy[IMP] = f["contact"]
        dy[WORK] = f["actuator"] * v_r
        dy[LOSS] = loss
        return dy

    def measurement(self, t: float, y: np.ndarray, start: np.ndarray) -> float:
        """What the detector sees (see :data:`~collision_reflex.vocabulary.SENSING_SCHEMES`)."""
        y = self.resolved(y)
        kind = self.s.detection.kind
        if kind == "force":
            return self.spring(y[DEFL])
        if kind == "position":
            return (y[ERR] + y[DEFL]) - (start[ERR] + start[DEFL])
        return self.forces(t, y)["actuator"]

    def energy(self, y: np.ndarray) -> float:
        """Kinetic energy of both masses plus the energy stored in the spring and the wall [J]."""
        y = self.resolved(y)
        elastic = self.spring(y[DEFL]) ** 2 / (2 * self.k_m)
        wall = 0.0 if self.rigid else 0.5 * self.k_c * y[SURF] ** 2
        return 0.5 * self.m_f * y[VF] ** 2 + 0.5 * self.m_r * y[VR] ** 2 + elastic + wall

    # -- events ----------------------------------------------------------------------------------------------
    def mode_events(self, detecting: bool, start: np.ndarray, y0: np.ndarray) -> list[tuple[Any, str]]:
        """Terminal events leaving the current mode.

        Each is written so that it is not at zero, or is moving away from zero, at the start of the segment
        (solve_ivp counts a zero as a crossing).
        """
        events: list[tuple[Any, str]] = []

        def add(function: Callable[[float, np.ndarray], float], direction: int, name: str) -> None:
            def event(t: float, y: np.ndarray) -> float:
                return float(function(t, self.resolved(y)))

            event.terminal = True  # type: ignore[attr-defined]
            event.direction = direction  # type: ignore[attr-defined]
            events.append((event, name))

        if self.contact == "held":
            # The finger stays until the spring pulls on it (beyond the play, if any).
            add(lambda t, y: y[DEFL] + self.half_gap, -1, "finger leaves the wall")
        elif self.contact == "pressed":
            add(lambda t, y: self.k_c * y[XF] + self.c_c * y[VF], -1, "finger leaves the wall")
        else:
            add(lambda t, y: y[XF] - (0.0 if self.rigid else y[SURF]), 1, "finger hits the wall")
        if self.drive == "kinematic" and self.half_gap > 0 and math.isfinite(self.k_s):
            # Taking up or opening the play changes the ideal robot's velocity at once: stop there so that the
            # controller's impulsive work is booked.
            total = y0[DEFL] + y0[ERR]
            if total > self.half_gap or (total == self.half_gap and self.v0 > y0[VF]):
                add(lambda t, y: y[DEFL] + y[ERR] - self.half_gap, -1, "play opens")
            elif total < -self.half_gap or (total == -self.half_gap and self.v0 < y0[VF]):
                add(lambda t, y: y[DEFL] + y[ERR] + self.half_gap, 1, "play opens")
            else:
                add(lambda t, y: y[DEFL] + y[ERR] - self.half_gap, 1, "play taken up")
                add(lambda t, y: y[DEFL] + y[ERR] + self.half_gap, -1, "play taken up")
        if self.drive != "kinematic" and self.s.coulomb_friction > 0:
            if self.robot_stuck:

                def net(t: float, y: np.ndarray) -> float:
                    f = self.forces(t, y)
                    return f["actuator"] - f["spring"]

                add(lambda t, y: net(t, y) - self.s.coulomb_friction, 1, "robot breaks away")
                add(lambda t, y: net(t, y) + self.s.coulomb_friction, -1, "robot breaks away")
            else:
                y0 = self.resolved(y0)
                moving = y0[VR] if y0[VR] != 0 else self.forces(0.0, y0)["a_r"]
                add(lambda t, y: y[VR], -int(np.sign(moving)) or -1, "robot stops")
        if detecting and not self.sampled:
            threshold = self.s.detection.threshold
            add(lambda t, y: self.measurement(t, y, start) - threshold, 1, "detection")
        return events

    def max_step(self) -> float:
        """Largest integrator step [s]: ``setup.max_step``, or 1/16 of the shortest period of the mode."""
        if self.s.max_step is not None:
            return self.s.max_step
        periods = [math.inf]
        if self.contact != "held":
            periods.append(oscillation_period(self.m_f, self.k_m))
            if not self.rigid:
                periods.append(oscillation_period(self.m_f, self.k_c + self.k_m))
        if self.drive != "kinematic":
            stiffness = self.k_m + (self.k_s if self.drive == "impedance" else 0.0)
            periods.append(oscillation_period(self.m_r, stiffness))
        return min(periods) / 16

    # -- transitions -----------------------------------------------------------------------------------------
    def touch(self, t: float, y: np.ndarray) -> np.ndarray:
        """The finger reaches the wall.

        On a rigid wall this is a perfectly plastic impact; on a compliant one, the start of the contact.
        """
        y = self.resolved(y)
        if not self.rigid:
            self.contact = "pressed"
            y[SURF] = y[XF]
            return y
        before = self.energy(y)
        v_r_before = y[VR]
        impulse = self.m_f * max(y[VF], 0.0)
        y[XF] = y[VF] = 0.0
        y[IMP] += impulse
        self.contact = "held"
        y = self.resolved(y)
        if self.spring(y[DEFL]) < 0:
            self.contact = "free"  # stopped, but the spring pulls it straight off again
        # An ideal controller changes the robot's velocity at once; its work is the kinetic-energy change.
        work = 0.5 * self.m_r * (y[VR] ** 2 - v_r_before**2) if self.drive == "kinematic" else 0.0
        y[WORK] += work
        y[LOSS] += before + work - self.energy(y)
        if impulse > 0:
            self.impacts.append((t, impulse))
        return y

    def leave(self, y: np.ndarray) -> np.ndarray:
        """The finger leaves the wall: the contact becomes ``"free"``; returns the resolved state."""
        y = self.resolved(y)
        if self.contact == "pressed":
            y[SURF] = y[XF]
        self.contact = "free"
        return y
