"""Time-domain collision models that show where the closed form holds.

They are the 1D collision (contact, controller, detection, reaction) and the elastic-joint arm against a
compliant wall.

The 1D collision, from the wall outwards (positions positive toward the wall)::

    wall | contact (rigid plastic, or stiffness k_c + damping c_c) | finger m_f | spring k_m (+ backlash)
         | robot mass m_r (+ Coulomb and viscous friction) | controller: software spring k_s, damping d_s,
           reference moving at v0; after detection, the actuator's force limit F_a away from the wall

The robot approaches at ``v0`` and the finger touches the wall at ``t = 0``. Detection (force on the spring, a
tracking error, or the actuator force seen as motor current) triggers, after an optional delay and at the next
control sample, the reaction: the software spring is zeroed and the actuator pushes the robot mass away with
its force limit ``F_a``. The simulation ends when the finger has left the wall for good; the impulse is the
integral of the contact force (plus the impulses of rigid plastic impacts).

The ideal limit and the closed form (:mod:`collision_reflex.model.impulse`)
----------------------------------------------------------------------------
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

Modules: :mod:`.setup` (the parameters and their checks), :mod:`.budget` (the work estimate that refuses
hopeless settings), :mod:`.contact` (wall restitution),
:mod:`.dynamics` (the hybrid model), :mod:`.integrator` (the event-driven integration), :mod:`.result`,
:mod:`.sweeps` (against the closed form), :mod:`.arm` (the arm-level collision). Everything is SI: kg, m, s,
N, N/m, N*s/m, N*s.
"""

from .arm import ArmCollision, simulate_arm_collision
from .contact import contact_damping_for_restitution, contact_restitution
from .integrator import simulate
from .result import SimulationResult
from .setup import CollisionSetup, Detection
from .sweeps import SWEEP_PARAMETERS, Sweep, sweep

__all__ = [
    "SWEEP_PARAMETERS",
    "ArmCollision",
    "CollisionSetup",
    "Detection",
    "SimulationResult",
    "Sweep",
    "contact_damping_for_restitution",
    "contact_restitution",
    "simulate",
    "simulate_arm_collision",
    "sweep",
]
