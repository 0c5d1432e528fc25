"""An independent reference for the rebound closed form: the paper's 1D collision built in MuJoCo.

The finger is a sphere on a slide joint that hits a fixed box; MuJoCo's own soft contact (``solref``: a time
constant and a damping ratio) makes the impact, rebound included, and its contact force gives the impulse. The
spring behind the finger is applied as a force each step from a reference that moves at ``v0`` until the spring
force reaches the threshold, then (the software spring zeroed) from the robot mass on the mechanical spring alone,
moving on at ``v0 k / k_m`` and braking away at ``a`` (the closed form's ``moving`` reaction). The restitution is
measured in MuJoCo too: the finger alone, without the spring, against the same wall.
"""

from __future__ import annotations

import math

import numpy as np

RADIUS, GAP = 0.01, 1e-4  # the finger sphere [m] and its distance from the wall at the start [m]


def _model(m_f: float, time_constant: float, damping_ratio: float, timestep: float):
    import mujoco

    xml = f"""
    <mujoco>
      <option timestep="{timestep}" gravity="0 0 0" integrator="Euler"/>
      <worldbody>
        <geom name="wall" type="box" size="0.05 0.05 0.05" pos="{0.05 + RADIUS} 0 0"
              solref="{time_constant} {damping_ratio}" solimp="0.99 0.99 0.001"/>
        <body name="finger" pos="{-GAP} 0 0">
          <joint name="x" type="slide" axis="1 0 0" damping="0"/>
          <geom type="sphere" size="{RADIUS}" mass="{m_f}"
                solref="{time_constant} {damping_ratio}" solimp="0.99 0.99 0.001"/>
        </body>
      </worldbody>
    </mujoco>"""
    model = mujoco.MjModel.from_xml_string(xml)
    return model, mujoco.MjData(model)


def _contact_force(model, data) -> float:
    import mujoco

    force, wrench = 0.0, np.zeros(6)
    for i in range(data.ncon):
        mujoco.mj_contactForce(model, data, i, wrench)
        force += wrench[0]
    return force


def measured_restitution(
    m_f: float, v0: float, time_constant: float, damping_ratio: float, timestep: float
) -> float:
    """The finger alone hitting the wall at ``v0``: its speed after over its speed before."""
    import mujoco

    model, data = _model(m_f, time_constant, damping_ratio, timestep)
    data.qvel[0] = v0
    touched = False
    for _ in range(int(20 * time_constant / timestep) + int(2 * GAP / v0 / timestep)):
        mujoco.mj_step(model, data)
        touched |= data.ncon > 0
        if touched and data.ncon == 0:
            break
    return -float(data.qvel[0]) / v0


def collision_impulse(
    m_f: float,
    k: float,
    k_m: float,
    F_s: float,
    a: float,
    v0: float,
    time_constant: float,
    damping_ratio: float,
    timestep: float,
) -> float:
    """The impulse [N*s] MuJoCo's wall takes from the whole collision: impact(s), sensing and reaction."""
    import mujoco

    model, data = _model(m_f, time_constant, damping_ratio, timestep)
    data.qvel[0] = v0
    stiffness, detected = k, None  # detected: (time, robot position, robot velocity) at detection
    impulse, last_contact = 0.0, None
    t_end = math.inf
    while data.time < t_end:
        t, x = data.time, float(data.qpos[0])
        if detected is None:
            reference = v0 * t  # the spring's far end, unloaded at the start (the finger moves with it)
        else:
            t_d, r_d, v_r = detected
            s = t - t_d
            reference = r_d + v_r * s - a * s * s / 2
        spring = stiffness * (reference - x)
        if detected is None and spring >= F_s:
            # The software spring is zeroed: the robot mass sits on k_m alone, the force carried on.
            stiffness, detected = k_m, (t, x + spring / k_m, v0 * k / k_m)
            spring = F_s
            t_end = t + 4 * math.sqrt(2 * (F_s / k_m + (v0 * k / k_m) ** 2 / a) / a) + 0.05
        data.qfrc_applied[0] = spring
        mujoco.mj_step(model, data)
        force = _contact_force(model, data)
        impulse += force * timestep
        if force > 0:
            last_contact = data.time
        if data.time > 10.0:
            raise RuntimeError("the MuJoCo collision did not end within 10 s")
    assert last_contact is not None and last_contact < t_end - 0.01, "the contact lasted to the end"
    return impulse
