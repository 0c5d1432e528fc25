"""The collision reflex run in MuJoCo on a design's exported MJCF, against a rigid plastic wall.

The arm starts at one of the run's contact samples (a configuration ``q0`` and a direction ``u`` of
``designs.json``) with its contact point touching a wall normal to ``u``. The controller is the arm simulator's
impedance drive (:mod:`collision_reflex.simulate.arm`, ``drive="impedance"``), read from the MJCF's controller
block:

- approach: each rotor is driven by its motor with ``tau = k_s (theta_ref - theta)`` [N m, output side] (within
  the joint's torque range), the reference ``theta_ref = q0 + J(q0)^+ u v0 t`` moving the contact point along
  ``u`` at the approach velocity ``v0``; links and rotors start at ``q0`` with the reference's rates (the joint
  springs unloaded);
- detection: the wall's contact force reaches the threshold ``F_s`` once the impact pulse is over (a force
  sensor, blanked as the arm simulator blanks it), or, for position sensing, the contact point's error along
  ``u`` against the commanded path reaches the threshold error;
- reflex: the software spring is switched off and the motors push along ``-u`` with ``tau = -F_a J^T u``,
  ``F_a = min_i tau_max,i / |(J^T u)_i|`` at the configuration of detection (the closed form's reaction force);
- the impulse is the integral of the wall's contact force until the finger has left the wall (the reflex's
  contact); the motors then stop pushing, and any touch of the wall in the two finger periods after is reported
  on its own (``impulse_after``), not counted.

The wall is MuJoCo's own soft contact (``solref``: a time constant and a damping ratio) on a small frictionless
sphere at the contact site, stiffer than the joints along ``u`` by :data:`CONTACT_STIFFNESS_RATIO`, damped at
:data:`CONTACT_DAMPING_RATIO` of critical for the finger mass (a plastic impact). Gravity is switched off, as
the closed form leaves it out. MuJoCo is imported when a run starts (the ``mujoco`` extra). Run it as
``python -m collision_reflex.export.mujoco_reflex RUN_DIR --sample N [--model FILE]``.
"""

from __future__ import annotations

import argparse
import copy
import dataclasses
import math
import os
import sys
import xml.etree.ElementTree as ET
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, NoReturn

import numpy as np

from ..errors import CollisionReflexError, InvalidParameter, SimulationError
from ..simulate.arm_dynamics import impact_pulse_duration
from ..simulate.contact import damping_from_ratio
from ..simulate.design_closed_form import ArmClosedForm, JointDesign, arm_closed_form
from ..simulate.setup import oscillation_period
from ..vocabulary import OPTIMIZED_SENSING_SCHEMES
from .mjcf import CONTACT_SITE, CONTROLLER, ROTOR, design_mjcf, load_mujoco
from .reflex_sample import ContactSample, contact_sample, joint_design, sample_closed_form
from .run_design import RunDesign, read_run_design
from .urdf import design_urdf

CONTACT_STIFFNESS_RATIO = 1e6
"""The wall's contact stiffness over the joints' mechanical stiffness along ``u``: the closed form's ``k`` and
``k_m`` move by about 1e-6 in series with it, and the wall's damper, which a contact sensor also reads, carries a
share of the force in the sensing ramp that falls as one over its square root
(:func:`collision_reflex.simulate.validity.damper_share`). Against the validity map's rigid object (1000 times
the joints') with this damping, the UR5 catalogue design's contact force stays above its threshold from the
impact on, and the force sensor detects only at the end of its blanking window."""

CONTACT_DAMPING_RATIO = 30.0
"""The wall's damping, a ratio of critical for the finger mass: a plastic impact. The finger alone leaves such a
wall at 0.028 % of its speed (4.8 % at the arm simulator's default of 2, which is too elastic here: at an
approach many times ``v*`` the finger's flight after that rebound outlasts the sensing phase, and its second
impact sets the detection). The more damped, the shorter the impact pulse's tail, which a force sensor must see
fall below its threshold before the sensing ramp crosses it; the tail is longest where the impact is largest
against the threshold, near a singularity (``benchmarks/results/export_mujoco.md`` has the figures)."""

STEPS_PER_PERIOD = 20
"""MuJoCo steps per shortest period in play: the wall's time constant and period, each rotor on its springs (20
steps per ``2 pi`` time constants: 0.31 of the time constant, within MuJoCo's least of two steps per time
constant)."""

FINGER_RADIUS = 1e-3
"""The sphere at the contact site that touches the wall [m]; the force's line passes through its centre."""

_WATCH_PERIODS = 2.0  # finger periods on the joint springs watched after the finger has left the wall


@dataclass(frozen=True)
class MujocoReflex:
    """A collision reflex run in MuJoCo, beside the design's predicted impulse.

    Attributes
    ----------
    sample: the contact sample's index in ``designs.json``.
    impulse: the impulse MuJoCo's wall took [N s].
    predicted: the design's impulse at the sample as ``designs.json`` records it [N s].
    closed_form: the closed form at the sample against the wall's stiffness (rigid in the prediction) [N s].
    detection_time, contact_end: from the impact [s].
    detected_impulse: the impulse until detection [N s] (the closed form's impact and sensing phases).
    impulse_after: the impulse of any touch of the wall in the watch after the finger has left it [N s] (0: none);
        the watch steps by the arm's own periods until the finger nears the wall, so that figure, whose timing is
        sensitive to the step, is approximate (a few per cent).
    timestep: MuJoCo's step [s]; contact_stiffness: the wall's stiffness along ``u`` [N/m].
    """

    sample: int
    impulse: float
    predicted: float
    closed_form: float
    detection_time: float
    detected_impulse: float
    contact_end: float
    impulse_after: float
    timestep: float
    contact_stiffness: float

    @property
    def relative_difference(self) -> float:
        """``impulse / predicted - 1``."""
        return self.impulse / self.predicted - 1


def mujoco_reflex(
    run_dir: str | os.PathLike[str],
    sample: int,
    model: str | os.PathLike[str] | None = None,
    *,
    contact_stiffness_ratio: float = CONTACT_STIFFNESS_RATIO,
    steps_per_period: float = STEPS_PER_PERIOD,
    contact_damping_ratio: float = CONTACT_DAMPING_RATIO,
) -> MujocoReflex:
    """Run the catalogue design's collision reflex in MuJoCo at contact sample ``sample`` of ``run_dir``.

    Parameters
    ----------
    run_dir: the output folder of ``crx run`` of an arm study with a catalogue design.
    sample: the contact sample's index (``designs.json``'s ``samples``).
    model: the design's MJCF as ``crx export RUN_DIR --design catalogue --format mjcf`` wrote it; None: made
        here the same way.
    contact_stiffness_ratio: the wall's stiffness over the joints' along ``u`` [-].
    steps_per_period: MuJoCo steps per shortest period in play [-].
    contact_damping_ratio: the wall's damping, a ratio of critical for the finger mass [-].

    The controller (threshold, sensing, approach velocity, software stiffnesses) is the model's controller
    block; the prediction is ``designs.json``'s at the design's own.

    Raises
    ------
    MujocoMissing: MuJoCo is not installed.
    InvalidParameter: not an arm study, no catalogue design, a sample out of range, a design sensed otherwise
        than by force or position, a model without the design's rotors or controller block.
    """
    mujoco = load_mujoco()
    design = read_run_design(run_dir, "catalogue")
    if design.sensing not in OPTIMIZED_SENSING_SCHEMES:
        raise InvalidParameter(
            "run_dir", str(run_dir), "a design with force or position sensing", f"not {design.sensing!r}"
        )
    if not all(math.isfinite(j.mechanical_stiffness) for j in design.joints) or design.placement != "robot":
        raise InvalidParameter(
            "run_dir",
            str(run_dir),
            "a study with the rotors behind finite joint springs (reflected_inertia_in: robot)",
            "the reflex needs the rotors as degrees of freedom of their own",
        )
    point = contact_sample(run_dir, sample)
    root = _parsed(_model_text(design, model))
    design = _as_modelled(design, root)
    joints = joint_design(design)
    arm = joints.on(design.arm)
    closed = sample_closed_form(design, point)
    k_c = contact_stiffness_ratio * closed.k_m
    wall = sample_closed_form(design, point, contact_stiffness=k_c)
    run = _Run(mujoco, root, design, arm, joints, point, closed, k_c, steps_per_period, contact_damping_ratio)
    impulse, detection, detected, end, after = run.collide()
    return MujocoReflex(
        sample=sample,
        impulse=impulse,
        predicted=point.predicted,
        closed_form=wall.impulse(design.approach_velocity),
        detection_time=detection,
        detected_impulse=detected,
        contact_end=end,
        impulse_after=after,
        timestep=run.timestep,
        contact_stiffness=k_c,
    )


def _model_text(design: RunDesign, model: str | os.PathLike[str] | None) -> str:
    """The MJCF text: the file ``model``, or the design's exported in memory."""
    if model is not None:
        try:
            return Path(model).read_text(encoding="utf-8")
        except OSError as error:
            raise InvalidParameter(
                "model", str(model), "a readable MJCF file", error.strerror or ""
            ) from None
    urdf, _ = design_urdf(design, "design.urdf")
    return design_mjcf(design, urdf)


class _Run:
    """The arm, the wall and the controller in MuJoCo; :meth:`collide` runs the collision."""

    def __init__(
        self,
        mujoco: Any,
        root: ET.Element,
        design: RunDesign,
        arm: Any,
        joints: JointDesign,
        point: ContactSample,
        closed: ArmClosedForm,
        contact_stiffness: float,
        steps_per_period: float,
        damping_ratio: float,
    ) -> None:
        self.mujoco, self.arm, self.closed, self.joints = mujoco, arm, closed, joints
        self.names = [j.joint for j in design.joints]
        self.u = point.u / np.linalg.norm(point.u)
        plane = arm.plane
        self.normal = plane @ self.u if plane is not None else self.u  # world-aligned wall normal
        self.v0 = float(design.approach_velocity)
        jac0 = arm.kinematics(point.q[None]).jacobian[0]
        self.q0, self.v_ref = point.q, np.linalg.pinv(jac0) @ self.u * self.v0  # theta_ref' [rad/s]
        self.k_s = np.array([j.software_stiffness for j in design.joints])
        self.tau_max = np.asarray(joints.torque_limit, dtype=float)
        self.gear = np.array([j.gear_ratio for j in design.joints])
        self.position_sensing = design.sensing == "position"
        m_f = closed.m_f
        omega = math.sqrt(contact_stiffness / m_f)
        # MuJoCo's solref (time constant, damping ratio): stiffness omega^2, damping 2 zeta omega, per unit mass.
        time_constant = 1 / (omega * damping_ratio)
        self.finger_period = oscillation_period(m_f, closed.k_m)
        arm_periods = [self.finger_period] + [
            oscillation_period(j.reflected_inertia, j.software_stiffness + j.mechanical_stiffness)
            for j in design.joints
        ]
        wall_periods = [oscillation_period(m_f, contact_stiffness), 2 * math.pi * time_constant]
        self.timestep = min(wall_periods + arm_periods) / steps_per_period
        # Off the wall its stiffness is out of play: the watch after the reflex steps by the arm's own periods.
        self.watch_timestep = min(arm_periods) / steps_per_period
        damping = damping_from_ratio(damping_ratio, m_f, contact_stiffness)
        self.model = self._compile(root, time_constant, damping_ratio)
        self.blanking = (
            0.0
            if self.position_sensing
            else impact_pulse_duration(m_f, contact_stiffness, damping, closed.k_m, self.v0, design.threshold)
        )
        self.threshold = design.threshold
        self.link = np.array([self.model.joint(n).qposadr[0] for n in self.names])
        self.rotor = np.array([self.model.joint(n + ROTOR).qposadr[0] for n in self.names])
        self.motor = np.array([self.model.actuator(n + "_motor").id for n in self.names])

    def _compile(self, root: ET.Element, time_constant: float, damping_ratio: float) -> Any:
        """The MJCF with the wall, the finger sphere (the only pair that collides), no gravity, the step."""
        mujoco = self.mujoco
        root = copy.deepcopy(root)
        site = next(s for s in root.iter("site") if s.get("name") == CONTACT_SITE)  # checked by _as_modelled
        default = ET.Element("default")
        ET.SubElement(default, "geom", contype="0", conaffinity="0")
        root.insert(1, default)
        option = root.find("option")
        assert option is not None  # the exported MJCF has one
        option.set("gravity", "0 0 0")
        option.set("timestep", repr(self.timestep))
        contact: dict[str, str] = {
            "contype": "1",
            "conaffinity": "1",
            "condim": "1",
            "solref": f"{time_constant!r} {damping_ratio!r}",
            "solimp": "0.99 0.99 0.001",
        }
        body = next(b for b in root.iter("body") if site in list(b))
        finger = {
            "name": "collision_reflex_finger",
            "type": "sphere",
            "size": repr(FINGER_RADIUS),
            "mass": "0",
        }
        ET.SubElement(body, "geom", {**finger, "pos": str(site.get("pos", "0 0 0")), **contact})
        model = mujoco.MjModel.from_xml_string(ET.tostring(root, encoding="unicode"))
        data = mujoco.MjData(model)
        _set_state(model, data, self.names, self.q0, self.v_ref)
        mujoco.mj_kinematics(model, data)
        self.site0 = np.array(data.site(CONTACT_SITE).xpos)  # where the finger touches the wall
        position = self.site0 + FINGER_RADIUS * self.normal
        quat = np.zeros(4)
        mujoco.mju_quatZ2Vec(quat, -self.normal)  # the plane's normal (its z) points back at the arm
        world = root.find("worldbody")
        assert world is not None
        wall = {"name": "collision_reflex_wall", "type": "plane", "size": "0 0 1", **contact}
        place = {"pos": _numbers(position), "quat": _numbers(quat)}
        ET.SubElement(world, "geom", {**wall, **place})
        return mujoco.MjModel.from_xml_string(ET.tostring(root, encoding="unicode"))

    def collide(self) -> tuple[float, float, float, float, float]:
        """Run the collision; its impulse, detection time, impulse until then, contact end, impulse after.

        Impulses in [N s], times in [s] from the first touch of the wall.
        """
        mujoco, model = self.mujoco, self.model
        data = mujoco.MjData(model)
        dt = self.timestep
        start = -5 * dt  # the finger five steps of travel from the wall
        _set_state(model, data, self.names, self.q0 + self.v_ref * start, self.v_ref)
        data.time = start
        mujoco.mj_forward(model, data)
        reference = mujoco.MjData(model)  # the commanded path's kinematics (position sensing)
        touch = detection = detected = end = math.nan
        push: np.ndarray | None = None
        idle = np.zeros(len(self.motor))  # the motors' torque once the reflex is over
        wrench = np.zeros(6)  # mj_contactForce's output, reused at every step
        state, impulse, after = "waiting", 0.0, 0.0  # the detector: waiting, blanked, armed
        limit = start + 1e4 * self.finger_period
        while data.time < limit:
            t = float(data.time)
            if push is None:
                theta = data.qpos[self.rotor]
                torque = np.clip(self.k_s * (self.q0 + self.v_ref * t - theta), -self.tau_max, self.tau_max)
            else:
                torque = push if math.isnan(end) else idle
            data.ctrl[self.motor] = torque / self.gear
            mujoco.mj_step(model, data)
            force = _wall_force(mujoco, model, data, wrench)
            if math.isnan(end):
                impulse += force * dt
            else:
                after += force * dt
            if force > 0 and math.isnan(touch):
                touch = t
            if push is None and not math.isnan(touch):
                signal = self._position_error(reference, data, t) if self.position_sensing else force
                state, fire = _detector(state, signal >= self.threshold, t - touch >= self.blanking)
                if fire:
                    detection, detected, push = t - touch, impulse, self._push(data)
            elif (
                push is not None and math.isnan(end) and force == 0
            ):  # the finger has left: the reflex is over
                end = t - touch
                limit = data.time + _WATCH_PERIODS * self.finger_period
            if not math.isnan(end) and force == 0:  # watching: the motors idle, the finger off the wall
                self._step_off_the_wall(data, limit)
        if math.isnan(end):
            raise SimulationError(
                f"the finger had not left the wall {limit - start:.3g} s after the start"
                + ("" if push is not None else "; the contact was never detected")
            )
        return impulse, detection, detected, end, after

    def _step_off_the_wall(self, data: Any, limit: float) -> None:
        """One step of :attr:`watch_timestep` (the arm's own periods' step) if the finger surely stays off the wall.

        Else none: the wall's step follows. Sure: its gap to the wall is three steps of travel at its closing speed, or at the approach velocity if
        that is larger (the scale of the arm's motion; a step is a twentieth of the shortest period, in which no
        speed turns by much more).
        """
        if data.time + self.watch_timestep > limit:
            return
        gap = float(self.normal @ (self.site0 - data.site(CONTACT_SITE).xpos))
        velocity = np.zeros(6)  # [rotation; translation] of the contact site, world axes
        self.mujoco.mj_objectVelocity(
            self.model, data, self.mujoco.mjtObj.mjOBJ_SITE, self.model.site(CONTACT_SITE).id, velocity, 0
        )
        closing = max(float(self.normal @ velocity[3:]), self.v0)  # [m/s], toward the wall
        if gap > 3 * closing * self.watch_timestep:
            self.model.opt.timestep = self.watch_timestep
            self.mujoco.mj_step(self.model, data)
            self.model.opt.timestep = self.timestep

    def _position_error(self, reference: Any, data: Any, t: float) -> float:
        """The contact point's error along ``u`` against the commanded path [m]."""
        reference.qpos[:] = data.qpos
        reference.qpos[self.link] = self.q0 + self.v_ref * t
        self.mujoco.mj_kinematics(self.model, reference)
        commanded = reference.site(CONTACT_SITE).xpos
        return float(self.normal @ (commanded - data.site(CONTACT_SITE).xpos))

    def _push(self, data: Any) -> np.ndarray:
        """The reflex's output torques [N m]: ``-F_a J^T u`` at the links' configuration now."""
        q = np.array(data.qpos[self.link])
        lever = self.arm.kinematics(q[None]).jacobian[0].T @ self.u
        return -arm_closed_form(self.arm, q, self.u, self.joints).F_a * lever


def _numbers(values: np.ndarray) -> str:
    return " ".join(repr(float(x)) for x in values)


def _set_state(model: Any, data: Any, names: list[str], q: np.ndarray, rate: np.ndarray) -> None:
    """Links and rotors at ``q`` [rad] moving at ``rate`` [rad/s] (the joint springs unloaded)."""
    for i, name in enumerate(names):
        for joint in (model.joint(name), model.joint(name + ROTOR)):
            data.qpos[joint.qposadr[0]] = q[i]
            data.qvel[joint.dofadr[0]] = rate[i]


def _detector(state: str, above: bool, window_over: bool) -> tuple[str, bool]:
    """The detector's next state and whether it fires, as the arm simulator blanks the impact pulse.

    ``waiting``: in the window after the impact, nothing above the threshold yet (armed when the window is over);
    ``blanked``: the signal rose above the threshold in the window, the impact pulse: armed once it falls below,
    fired if it is still above when the window is over; ``armed``: fires when the signal is at the threshold.
    """
    if state == "waiting":
        state = "armed" if window_over else "blanked" if above else "waiting"
    elif state == "blanked":
        if not above:
            return "armed", False
        if window_over:
            return "blanked", True
        return "blanked", False
    return state, state == "armed" and above


def _wall_force(mujoco: Any, model: Any, data: Any, wrench: np.ndarray) -> float:
    """The normal force of the wall's contacts [N] (only the finger touches it); ``wrench``: a (6,) buffer."""
    force = 0.0
    for i in range(data.ncon):
        mujoco.mj_contactForce(model, data, i, wrench)
        force += wrench[0]
    return force


def _as_modelled(design: RunDesign, root: ET.Element) -> RunDesign:
    """``design`` with the controller of the MJCF ``root`` (threshold, sensing, approach velocity, ``k_s``).

    Raises :class:`InvalidParameter` for a model without the design's rotors, the contact site or a number of the
    controller block.
    """
    names = {j.get("name") for j in root.iter("joint")}
    if any(j.joint + ROTOR not in names for j in design.joints):
        raise InvalidParameter("model", design.label, "an MJCF with the design's rotors (JOINT_rotor)")
    if not any(s.get("name") == CONTACT_SITE for s in root.iter("site")):
        raise InvalidParameter("model", design.label, f"an MJCF with the site {CONTACT_SITE}")

    def numeric(name: str) -> float:
        element = root.find(f"custom/numeric[@name='{CONTROLLER}{name}']")
        try:
            return float(str(element.get("data")) if element is not None else "nan")
        except ValueError:
            return math.nan

    stiffnesses = [f"{j.joint}_software_stiffness" for j in design.joints]
    values = {
        name: numeric(name) for name in ("threshold", "position_sensing", "approach_velocity", *stiffnesses)
    }
    bad = [name for name, value in values.items() if not value > 0 and name != "position_sensing"]
    if bad or values["position_sensing"] not in (0.0, 1.0):
        name = (bad or ["position_sensing"])[0]
        raise InvalidParameter(
            "model",
            design.label,
            f"an MJCF whose controller block has {CONTROLLER}{name} (crx export writes it)",
        )
    joints = tuple(
        dataclasses.replace(j, software_stiffness=values[f"{j.joint}_software_stiffness"])
        for j in design.joints
    )
    return dataclasses.replace(
        design,
        joints=joints,
        threshold=values["threshold"],
        sensing="position" if values["position_sensing"] else "force",
        approach_velocity=values["approach_velocity"],
    )


def _parsed(text: str) -> ET.Element:
    try:
        return ET.fromstring(text)
    except ET.ParseError as error:
        raise InvalidParameter("model", "the MJCF", "an MJCF file", str(error)) from None


class _Parser(argparse.ArgumentParser):
    """Usage errors as one line on stderr (exit status 2)."""

    def error(self, message: str) -> NoReturn:
        self.exit(2, f"{self.prog}: error: {message} (see {self.prog} --help)\n")


def main(argv: Sequence[str] | None = None) -> int:
    """Run the catalogue design's reflex in MuJoCo at a sample and print its impulse beside the prediction.

    Returns the exit status: 0, or 2 after a one-line error (no MuJoCo, no catalogue design, a bad sample...).
    """
    parser = _Parser(
        prog="python -m collision_reflex.export.mujoco_reflex",
        description="Run the collision reflex of a run's catalogue design in MuJoCo against a rigid plastic wall "
        "at one of its contact samples, and print the impulse beside the one designs.json predicts.",
    )
    parser.add_argument("run_dir", metavar="RUN_DIR", help="output folder of `crx run` (an arm study)")
    parser.add_argument(
        "--sample", type=int, required=True, help="the contact sample's index in designs.json"
    )
    parser.add_argument(
        "--model", metavar="FILE", help="the MJCF of `crx export RUN_DIR --design catalogue --format mjcf`"
    )
    try:
        args = parser.parse_args(argv)
    except SystemExit as done:  # --help, or a usage error already printed as one line
        return done.code if isinstance(done.code, int) else 0
    try:
        result = mujoco_reflex(args.run_dir, args.sample, args.model)
    except CollisionReflexError as error:
        print(f"{parser.prog}: error: {error}", file=sys.stderr)
        return 2
    later = f"; a later touch, not counted: {result.impulse_after:.3g} N*s" if result.impulse_after else ""
    print(
        f"sample {result.sample}: MuJoCo impulse {result.impulse:.6g} N*s, predicted {result.predicted:.6g} N*s "
        f"({result.relative_difference:+.2%}); detected at {result.detection_time * 1e3:.3g} ms, contact over at "
        f"{result.contact_end * 1e3:.3g} ms{later}"
    )
    return 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
