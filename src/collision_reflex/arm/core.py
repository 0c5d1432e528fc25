"""URDF arms through Pinocchio: loading, contact points, batched kinematics and effective collision parameters.

An :class:`Arm` is a fixed-base URDF robot with a contact point (a frame, optionally with an offset) and per-joint
actuation (reflected inertia, stiffness, torque limit, motor mass). :meth:`Arm.kinematics` evaluates the
configuration-dependent quantities once per configuration with Pinocchio and returns them stacked
(:class:`ArmSamples`); :func:`effective_parameters` then maps them, for many directions at once, to the 1D
collision parameters of the paper's section "Collision Reflex in Higher Dimensions" (``eq:eff_mf`` to
``eq:eff_a``), and :func:`collision_impulses` to impulses through :mod:`collision_reflex.model.impulse`.

Conventions (SI throughout): the contact Jacobian is the translational Jacobian of the contact point in
world-aligned axes; a planar arm (all joint axes parallel) is described in the plane perpendicular to its axes
(``task_dim == 2``), any other arm in 3D. ``model.armature`` carries the reflected rotor inertia ``N^2 J_m``; the
structure mass matrix of :class:`ArmSamples` excludes it, and excludes the motor masses, whose effect is given
separately and linearly (``M_bb(q; m) = M_bb0(q) + sum_i m_i A_i(q)``).
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from .. import _validate
from ..errors import FrameNotFound, InvalidParameter, UrdfError
from .robots import (
    ROBOT_DEFAULTS,
    captured_stderr,
    configuration_by_name,
    example_robot,
    load_urdf,
    parser_reason,
    with_locked_joints,
)

# Joints whose limits are missing or meaningless (URDF "continuous", or lower >= upper) are sampled on a full
# turn; limits beyond this magnitude are treated as missing.
_UNBOUNDED_LIMIT = 1e3


@dataclass(frozen=True)
class JointParameters:
    """Per-joint actuation of an arm, arrays of shape (nv,).

    reflected_inertia: rotor (and gearbox) inertia seen at the joint, ``N^2 J_m`` [kg m^2], >= 0.
    torque_limit: largest output torque of the joint [N m], > 0 (``nan`` when unknown).
    stiffness: lumped joint stiffness while sensing, mechanical and software springs in series [N m/rad].
    mechanical_stiffness: joint mechanical stiffness, the spring left during the reaction [N m/rad].
    motor_mass: mass of the joint's motor (and gearbox), carried by the parent link at the joint [kg].
    """

    reflected_inertia: np.ndarray
    torque_limit: np.ndarray
    stiffness: np.ndarray
    mechanical_stiffness: np.ndarray
    motor_mass: np.ndarray

    def __post_init__(self) -> None:
        arrays = [np.atleast_1d(np.asarray(getattr(self, n), dtype=float)) for n in _JOINT_FIELDS]
        size = max(a.size for a in arrays)
        for name, array in zip(_JOINT_FIELDS, arrays, strict=True):
            if array.ndim != 1 or array.size not in (1, size):
                raise InvalidParameter(name, array, f"one value or {size} values, one per joint")
            array = np.broadcast_to(array, (size,)).copy()
            array.flags.writeable = False
            object.__setattr__(self, name, array)
        _validate.non_negative("reflected_inertia", self.reflected_inertia)
        _validate.non_negative("motor_mass", self.motor_mass)
        _validate.positive("stiffness", self.stiffness, allow_inf=True)
        _validate.positive("mechanical_stiffness", self.mechanical_stiffness, allow_inf=True)
        known = self.torque_limit[~np.isnan(self.torque_limit)]
        _validate.positive("torque_limit", known, allow_inf=True)

    @property
    def size(self) -> int:
        return int(self.reflected_inertia.size)

    @classmethod
    def from_actuators(cls, actuators: Any, nv: int) -> JointParameters:
        """From one actuator per joint, or one actuator used at every joint.

        An actuator is anything with ``reflected_inertia`` [kg m^2], ``peak_torque`` [N m], ``stiffness`` and
        ``mechanical_stiffness`` [N m/rad] and ``mass`` [kg] (:class:`collision_reflex.hardware.actuators.Actuator`).
        """
        items = list(actuators) if isinstance(actuators, list | tuple) else [actuators] * nv
        if len(items) != nv:
            raise InvalidParameter(
                "actuators", f"{len(items)} actuators", f"one actuator, or {nv} (one per joint)"
            )
        try:
            return cls(
                reflected_inertia=np.array([float(a.reflected_inertia) for a in items]),
                torque_limit=np.array([float(a.peak_torque) for a in items]),
                stiffness=np.array([float(a.stiffness) for a in items]),
                mechanical_stiffness=np.array([float(a.mechanical_stiffness) for a in items]),
                motor_mass=np.array([float(a.mass) for a in items]),
            )
        except AttributeError as error:
            raise InvalidParameter(
                "actuators",
                actuators,
                "Actuator objects (with reflected_inertia, peak_torque, stiffness, mechanical_stiffness, mass)",
                str(error),
            ) from None


_JOINT_FIELDS = ("reflected_inertia", "torque_limit", "stiffness", "mechanical_stiffness", "motor_mass")


@dataclass(frozen=True)
class ArmSamples:
    """Configuration-dependent quantities of an arm, stacked over ``n`` configurations (SI units).

    q: (n, nq) configurations.
    mass_matrix: (n, nv, nv) joint-space mass matrix of the structure (links only: no armature, no motor
        masses) [kg m^2, kg m, kg].
    jacobian: (n, task_dim, nv) translational Jacobian of the contact point, world-aligned axes (in the arm's
        plane for a planar arm) [m/rad].
    gravity: (n, nv) generalized gravity torques of the structure [N m].
    motor_mass_influence: (n, nv, nv, nv); ``[s, i]`` is the matrix ``A_i`` with
        ``M_bb(q; m) = M_bb0(q) + sum_i m_i A_i(q)`` for a point motor mass of joint ``i`` at that joint's
        origin, carried by its parent link [m^2 per rad^2].
    motor_gravity: (n, nv, nv); ``[s, i]`` is the gravity torque vector per kilogram of motor ``i`` [N m/kg].
    contact_gravity: (n, nv) gravity torque per kilogram of payload at the contact point [N m/kg].
    contact_position: (n, 3) world position of the contact point [m].
    joint_positions: (n, nv, 3) world positions of the joint origins [m].

    The gravity and motor-mass terms are None when :meth:`Arm.kinematics` was asked to skip them.
    """

    q: np.ndarray
    mass_matrix: np.ndarray
    jacobian: np.ndarray
    gravity: np.ndarray | None = None
    motor_mass_influence: np.ndarray | None = None
    motor_gravity: np.ndarray | None = None
    contact_gravity: np.ndarray | None = None
    contact_position: np.ndarray | None = None
    joint_positions: np.ndarray | None = None

    def __post_init__(self) -> None:
        mass = np.asarray(self.mass_matrix)
        if mass.ndim != 3 or mass.shape[1] != mass.shape[2]:
            raise InvalidParameter("mass_matrix", mass.shape, "an array of shape (n, nv, nv)")
        n, nv = mass.shape[0], mass.shape[-1]
        expected = {
            "q": (n, None),
            "mass_matrix": (n, nv, nv),
            "jacobian": (n, None, nv),
            "gravity": (n, nv),
            "motor_mass_influence": (n, nv, nv, nv),
            "motor_gravity": (n, nv, nv),
            "contact_gravity": (n, nv),
            "contact_position": (n, 3),
            "joint_positions": (n, nv, 3),
        }
        for name, shape in expected.items():
            value = getattr(self, name)
            if value is None:
                continue
            array = np.asarray(value, dtype=float)
            if array.ndim != len(shape) or any(
                s is not None and s != a for s, a in zip(shape, array.shape, strict=False)
            ):
                raise InvalidParameter(name, array.shape, f"an array of shape {shape} (None: any)")
            if not np.all(np.isfinite(array)):
                raise InvalidParameter(name, array, "finite values", "check the configurations and the model")
            object.__setattr__(self, name, array)
        if self.jacobian.shape[1] not in (2, 3):
            raise InvalidParameter("jacobian", self.jacobian.shape, "task dimension 2 or 3")

    @property
    def count(self) -> int:
        """Number of configurations."""
        return int(self.q.shape[0])

    @property
    def nv(self) -> int:
        return int(self.mass_matrix.shape[-1])

    @property
    def task_dim(self) -> int:
        return int(self.jacobian.shape[1])

    def take(self, index: Any) -> ArmSamples:
        """The samples at ``index`` (an integer array, slice or boolean mask over configurations)."""
        single = np.ndim(np.arange(self.count)[index]) == 0  # an integer: keep the leading axis
        picked: dict[str, Any] = {}
        for name in self.__dataclass_fields__:
            value = getattr(self, name)
            if value is not None:
                value = np.asarray(value)[index]
                picked[name] = value[None] if single else value
            else:
                picked[name] = None
        return ArmSamples(**picked)

    def structure_mass_matrix(self, motor_mass: Any = None) -> np.ndarray:
        """``M_bb(q; m) = M_bb0(q) + sum_i m_i A_i(q)`` [kg m^2], (n, nv, nv); ``motor_mass`` [kg], (nv,)."""
        if motor_mass is None:
            return self.mass_matrix
        masses = _joint_array("motor_mass", motor_mass, self.nv, allow_zero=True)
        if not np.any(masses):
            return self.mass_matrix
        if self.motor_mass_influence is None:
            raise InvalidParameter(
                "motor_mass",
                motor_mass,
                "None for samples without motor terms",
                "compute the samples with Arm.kinematics(q, motor_terms=True)",
            )
        return self.mass_matrix + np.einsum("i,sijk->sjk", masses, self.motor_mass_influence)


@dataclass(frozen=True)
class _JointKinematics:
    """What the batched forward kinematics needs about one 1-DoF joint (SI, parent-joint frame)."""

    parent: int  # index of the parent joint in the model (0: the world)
    idx_q: int
    nq: int  # 1, or 2 for an unbounded revolute joint stored as (cos, sin)
    revolute: bool
    axis: np.ndarray  # unit axis in the joint frame
    rotation: np.ndarray  # placement of the joint frame in the parent joint frame
    translation: np.ndarray

    @property
    def rotation_skew(self) -> np.ndarray:
        return self.rotation @ _skew(self.axis)

    @property
    def rotation_skew2(self) -> np.ndarray:
        skew = _skew(self.axis)
        return self.rotation @ skew @ skew


class Arm:
    """A fixed-base robot arm from a URDF, with a contact point and per-joint actuation.

    Parameters
    ----------
    model: a fixed-base ``pinocchio.Model`` whose joints all have one degree of freedom (revolute or
        prismatic). It is copied; the copy's ``armature`` is set to the reflected inertia.
    contact_frame: name of the frame that makes contact.
    contact_offset: contact point in that frame's coordinates [m], default its origin.
    actuators: one actuator per joint, or one for all joints (anything with ``reflected_inertia``,
        ``peak_torque``, ``stiffness``, ``mechanical_stiffness`` and ``mass``); or a :class:`JointParameters`.
        Default: the model's armature and URDF effort limits, rigid joints and no motor masses.
    name: a name for messages and figures.
    urdf_path: the URDF the model came from (for :meth:`visual_model`).
    package_dirs: directories that resolve the URDF's ``package://`` mesh references.
    """

    def __init__(
        self,
        model: Any,
        contact_frame: str,
        contact_offset: Any = None,
        actuators: Any = None,
        name: str = "",
        urdf_path: str | os.PathLike[str] | None = None,
        package_dirs: Sequence[str | os.PathLike[str]] | None = None,
    ) -> None:
        import pinocchio as pin

        self.name = name or str(model.name)
        self.urdf_path = None if urdf_path is None else Path(urdf_path)
        self.package_dirs = tuple(str(p) for p in package_dirs or ())
        self._joints = _joint_kinematics(model, self.name)
        self.joint_names: tuple[str, ...] = tuple(model.names[i] for i in range(1, model.njoints))
        if not model.existFrame(contact_frame):
            raise FrameNotFound(contact_frame, [f.name for f in model.frames], "frame", self.name)
        self.contact_frame = contact_frame
        offset = np.zeros(3) if contact_offset is None else np.asarray(contact_offset, dtype=float)
        if offset.shape != (3,) or not np.all(np.isfinite(offset)):
            raise InvalidParameter("contact_offset", contact_offset, "three finite coordinates [m]")
        self.contact_offset = offset
        frame = model.frames[model.getFrameId(contact_frame)]
        self._contact_joint = int(frame.parentJoint)
        if self._contact_joint == 0:
            raise InvalidParameter(
                "contact_frame",
                contact_frame,
                "a frame moved by at least one joint",
                "it is fixed to the base",
            )
        # The contact point in its parent joint's frame.
        self._contact_local = np.asarray(frame.placement.act(offset), dtype=float)

        effort = np.asarray(model.effortLimit, dtype=float)
        # URDFs often leave effort at 0 (unknown); Pinocchio reports "no limit" as the largest double.
        unknown = (effort <= 0) | (effort > 1e300) | ~np.isfinite(effort)
        self.urdf_torque_limit: np.ndarray = np.where(unknown, np.nan, effort)
        """The URDF's effort limit per joint [N m], ``nan`` where it gives none."""
        if isinstance(actuators, JointParameters):
            params = actuators
        elif actuators is not None:
            params = JointParameters.from_actuators(actuators, model.nv)
        else:
            params = JointParameters(
                reflected_inertia=np.asarray(model.armature, dtype=float),
                torque_limit=self.urdf_torque_limit,
                stiffness=np.full(model.nv, np.inf),
                mechanical_stiffness=np.full(model.nv, np.inf),
                motor_mass=np.zeros(model.nv),
            )
        if params.size != model.nv:
            raise InvalidParameter("actuators", params.size, f"{model.nv} joints' parameters")
        self.joint_parameters = params
        if actuators is None or isinstance(actuators, JointParameters):
            self.actuators: tuple[Any, ...] | None = None
        else:
            self.actuators = (
                tuple(actuators) if isinstance(actuators, list | tuple) else (actuators,) * model.nv
            )

        self._source_model = model
        self.model = model.copy()
        self.model.armature = params.reflected_inertia.copy()
        # Kinematics use a structure-only model (no armature), so ArmSamples.mass_matrix is M_bb0.
        self._structure = model.copy()
        self._structure.armature = np.zeros(model.nv)
        # A frame at the contact point itself, so that Pinocchio's frame Jacobian is the contact Jacobian.
        self._contact_frame_id = self._structure.addFrame(
            pin.Frame(
                "collision_reflex_contact_point",
                self._contact_joint,
                pin.SE3(np.eye(3), self._contact_local),
                pin.FrameType.OP_FRAME,
            )
        )
        self._data = self._structure.createData()
        self._gravity = np.asarray(self._structure.gravity.linear, dtype=float).copy()
        # Masks of the joints (velocity indices) that move the contact point and each motor's parent link.
        supports = [set(self._structure.supports[j]) for j in range(self._structure.njoints)]
        self._motor_masks = np.array(
            [_support_mask(self._structure, supports[jk.parent]) for jk in self._joints]
        )
        self.plane = _plane_basis(self._structure, self._joints)
        self.reference_configuration: np.ndarray = np.array(pin.neutral(model))
        """A configuration to start from [rad, m]: the robot's reference pose when known, else neutral."""
        self._pin = pin

    # ------------------------------------------------------------------ construction
    @classmethod
    def from_urdf(
        cls,
        path: str | os.PathLike[str],
        contact_frame: str,
        package_dirs: Sequence[str | os.PathLike[str]] | None = None,
        contact_offset: Any = None,
        actuators: Any = None,
        locked_joints: Sequence[str] = (),
        name: str = "",
    ) -> Arm:
        """Load an arm from a URDF file.

        Parameters
        ----------
        path: the URDF file.
        contact_frame: name of the contact frame (a link or a fixed joint of the URDF).
        package_dirs: directories that resolve ``package://`` mesh references; only needed for
            :meth:`visual_model`.
        contact_offset: contact point in the contact frame [m].
        actuators: see :class:`Arm`.
        locked_joints: names of joints to lock at zero (``pinocchio.buildReducedModel``), e.g. gripper fingers.
        """
        model = load_urdf(path)
        model = with_locked_joints(model, locked_joints, str(path))
        return cls(
            model, contact_frame, contact_offset, actuators, name or Path(path).stem, path, package_dirs
        )

    @classmethod
    def from_example_robot_data(
        cls,
        name: str,
        contact_frame: str | None = None,
        contact_offset: Any = None,
        actuators: Any = None,
        locked_joints: Sequence[str] | None = None,
    ) -> Arm:
        """Load a robot of the ``example-robot-data`` package by name (``"ur5"``, ``"panda"``,
        ``"double_pendulum"``, ...).

        Defaults per robot: Panda contacts at ``panda_hand_tcp`` with its two finger joints locked; UR robots at
        ``tool0``; the double pendulum at its second link's tip (0.2 m along the link); legged robots (``solo12``,
        ``a1``) at the front-left foot with the base fixed to the world. Other robots need ``contact_frame``.
        ``locked_joints`` replaces the default list of locked joints (``()`` locks none).
        """
        full_model, urdf, q0 = example_robot(name)
        model = full_model
        defaults = ROBOT_DEFAULTS.get(name, {})
        if contact_frame is None:
            if "contact_frame" not in defaults:
                raise InvalidParameter(
                    "contact_frame",
                    None,
                    f"a frame name for {name!r} (no default is known)",
                    "frames: " + ", ".join(f.name for f in model.frames),
                )
            contact_frame = defaults["contact_frame"]
            if contact_offset is None:
                contact_offset = defaults.get("contact_offset")
        if model.njoints > 1 and model.joints[1].nq == 7:  # free-flyer root: fix the base to the world
            model = load_urdf(urdf)
        to_lock = defaults.get("locked_joints", ()) if locked_joints is None else tuple(locked_joints)
        model = with_locked_joints(model, to_lock, name)
        # The robots' URDFs name their meshes package://example-robot-data/robots/...: the package directory
        # is two levels above the "robots" directory.
        share = Path(urdf).resolve()
        while share.name != "robots" and share != share.parent:
            share = share.parent
        arm = cls(model, contact_frame, contact_offset, actuators, name, urdf, [share.parent.parent])
        arm.reference_configuration = configuration_by_name(full_model, q0, model)
        return arm

    def with_actuators(self, actuators: Any) -> Arm:
        """The same arm and contact point with other actuators (see :class:`Arm`)."""
        arm = Arm(
            self._source_model,
            self.contact_frame,
            self.contact_offset,
            actuators,
            self.name,
            self.urdf_path,
            self.package_dirs,
        )
        arm.reference_configuration = self.reference_configuration.copy()
        return arm

    def with_scaled_motors(
        self,
        stator_diameter: float,
        torque_required: Any = None,
        *,
        reference: Any = None,
        law: str = "haddadin",
        mechanical_stiffness: Any = np.inf,
        software_stiffness: Any = np.inf,
        sensing: Any = None,
    ) -> Arm:
        """The same arm with a scaled motor at every joint, geared to meet a torque requirement (the paper's
        sweep of ``tab:motor_params``): ``N_i = max(1, tau_req,i / tau_p(r))``.

        Parameters
        ----------
        stator_diameter: stator outer diameter of every motor [m] (the paper's ``r_m``).
        torque_required: output torque per joint [N m] (scalar or (nv,)); default the URDF effort limits
            (:attr:`urdf_torque_limit`).
        reference: the motor scaled from; default the Omni+ OPN-060-013-A (``motors.reference_motor``).
        law: scaling law name (``motors.SCALING_LAWS``).
        mechanical_stiffness, software_stiffness: joint springs [N m/rad] (scalar or (nv,)).
        sensing: a sensing scheme of :mod:`collision_reflex.hardware.actuators` for every joint; default a 3 N force
            threshold.
        """
        from ..hardware.actuators import Actuator, ForceThreshold, gear_ratio_for
        from ..hardware.motors import reference_motor

        required = self.urdf_torque_limit if torque_required is None else torque_required
        required = _joint_array("torque_required", required, self.nv)
        motor = (reference if reference is not None else reference_motor()).scaled(
            stator_diameter=stator_diameter, law=law
        )
        ratios = np.atleast_1d(gear_ratio_for(required, motor.peak_torque))
        k_mech = _joint_array("mechanical_stiffness", mechanical_stiffness, self.nv, allow_inf=True)
        k_soft = _joint_array("software_stiffness", software_stiffness, self.nv, allow_inf=True)
        scheme = ForceThreshold() if sensing is None else sensing
        actuators = [
            Actuator(motor, float(ratios[i]), float(k_mech[i]), float(k_soft[i]), scheme)
            for i in range(self.nv)
        ]
        return self.with_actuators(actuators)

    def sensing_options(self) -> dict[str, Any]:
        """The sensing of this arm's actuators as keyword arguments: ``{"sensing": "force", "threshold": F_s}``
        for force thresholds at the contact, or ``{"sensing": "joint_torque", "joint_threshold": tau_s}`` [N m]
        for the joint-side schemes (position error, motor current), where the first joint to reach its
        threshold detects the contact.
        """
        from ..hardware.actuators import ForceThreshold

        if not self.actuators:
            raise InvalidParameter(
                "actuators", None, "Actuator objects with sensing schemes", "give the threshold explicitly"
            )
        schemes = [actuator.sensing for actuator in self.actuators]
        if all(isinstance(scheme, ForceThreshold) for scheme in schemes):
            forces = {float(scheme.force) for scheme in schemes}
            if len(forces) > 1:
                raise InvalidParameter(
                    "actuators", sorted(forces), "one contact-force threshold for the whole arm"
                )
            return {"sensing": "force", "threshold": forces.pop()}
        if any(isinstance(scheme, ForceThreshold) for scheme in schemes):
            raise InvalidParameter(
                "actuators", [type(s).__name__ for s in schemes], "force thresholds at every joint or at none"
            )
        torques = [
            scheme.joint_threshold_torque(actuator)
            for scheme, actuator in zip(schemes, self.actuators, strict=True)
        ]
        return {"sensing": "joint_torque", "joint_threshold": np.array(torques)}

    def visual_model(self) -> Any:
        """Pinocchio visual ``GeometryModel`` of the URDF, meshes resolved through ``package_dirs``."""
        if self.urdf_path is None:
            raise InvalidParameter("urdf_path", None, "an arm loaded from a URDF file")
        pin = self._pin
        failure: Exception | None = None
        with captured_stderr() as captured:
            try:
                geometry = pin.buildGeomFromUrdf(
                    self._structure,
                    str(self.urdf_path),
                    pin.GeometryType.VISUAL,
                    package_dirs=list(self.package_dirs) or None,
                )
            except (ValueError, RuntimeError) as error:
                failure = error
        if failure is not None:
            raise UrdfError(self.urdf_path, parser_reason(failure, captured.text))
        return geometry

    # ------------------------------------------------------------------ properties
    @property
    def nq(self) -> int:
        return int(self._structure.nq)

    @property
    def nv(self) -> int:
        return int(self._structure.nv)

    @property
    def task_dim(self) -> int:
        """2 for a planar arm (all joint axes parallel), 3 otherwise."""
        return 3 if self.plane is None else 2

    @property
    def reflected_inertia(self) -> np.ndarray:
        """``N^2 J_m`` per joint [kg m^2] (``model.armature``)."""
        return self.joint_parameters.reflected_inertia

    @property
    def torque_limit(self) -> np.ndarray:
        """Largest output torque per joint [N m] (``nan`` where unknown)."""
        return self.joint_parameters.torque_limit

    def __repr__(self) -> str:
        return (
            f"Arm({self.name!r}, {self.nv} joints, contact {self.contact_frame!r}"
            f"{' + ' + str(self.contact_offset.tolist()) if np.any(self.contact_offset) else ''}, "
            f"{'planar' if self.plane is not None else 'spatial'})"
        )

    # ------------------------------------------------------------------ configurations
    def joint_limits(self) -> tuple[np.ndarray, np.ndarray]:
        """Lower and upper limit per joint [rad or m], (nv,) each; a full turn where the URDF gives none."""
        lower = np.empty(self.nv)
        upper = np.empty(self.nv)
        low_q = np.asarray(self._structure.lowerPositionLimit, dtype=float)
        high_q = np.asarray(self._structure.upperPositionLimit, dtype=float)
        for v, joint in enumerate(self._joints):
            lo, hi = (low_q[joint.idx_q], high_q[joint.idx_q]) if joint.nq == 1 else (np.nan, np.nan)
            bounded = (
                np.isfinite(lo) and np.isfinite(hi) and lo < hi and max(abs(lo), abs(hi)) < _UNBOUNDED_LIMIT
            )
            if bounded:
                lower[v], upper[v] = lo, hi
            elif joint.revolute:
                lower[v], upper[v] = -np.pi, np.pi
            else:
                raise InvalidParameter(
                    "joint limits",
                    (lo, hi),
                    f"finite limits for prismatic joint {self.joint_names[v]!r}",
                    "add <limit lower=... upper=...> to the URDF",
                )
        return lower, upper

    def configuration(self, angles: Any) -> np.ndarray:
        """Configurations (..., nq) from joint coordinates (..., nv) [rad or m] (unbounded revolute joints are
        stored by Pinocchio as cosine and sine).
        """
        angles = np.asarray(angles, dtype=float)
        if angles.shape[-1:] != (self.nv,):
            raise InvalidParameter("angles", angles.shape, f"a last axis of {self.nv} joint coordinates")
        q = np.empty((*angles.shape[:-1], self.nq))
        for v, joint in enumerate(self._joints):
            if joint.nq == 1:
                q[..., joint.idx_q] = angles[..., v]
            else:
                q[..., joint.idx_q] = np.cos(angles[..., v])
                q[..., joint.idx_q + 1] = np.sin(angles[..., v])
        return q

    def joint_coordinates(self, q: Any) -> np.ndarray:
        """Joint angles or displacements (..., nv) of configurations (..., nq) [rad or m]."""
        q = self._checked_q(q)
        out = np.empty((q.shape[0], self.nv))
        for v, joint in enumerate(self._joints):
            if joint.nq == 1:
                out[:, v] = q[:, joint.idx_q]
            else:
                out[:, v] = np.arctan2(q[:, joint.idx_q + 1], q[:, joint.idx_q])
        return out

    def sample_configurations(self, count: int, rng: np.random.Generator) -> np.ndarray:
        """``count`` configurations drawn uniformly within the joint limits, shape (count, nq).

        Parameters
        ----------
        count: number of configurations, >= 1.
        rng: the random generator (``numpy.random.default_rng(seed)``), for reproducible samples.
        """
        if not isinstance(rng, np.random.Generator):
            raise InvalidParameter(
                "rng", rng, "a numpy.random.Generator", "use numpy.random.default_rng(seed)"
            )
        if int(count) != count or count < 1:
            raise InvalidParameter("count", count, "an integer >= 1")
        lower, upper = self.joint_limits()
        return self.configuration(rng.uniform(lower, upper, size=(int(count), self.nv)))

    # ------------------------------------------------------------------ kinematics
    def kinematics(self, q: Any, *, full: bool = True) -> ArmSamples:
        """Mass matrix, contact Jacobian, gravity and motor-mass terms at configurations ``q`` (n, nq).

        Pinocchio evaluates the mass matrix (CRBA) and the contact Jacobian once per configuration, and with
        ``full`` also the joint Jacobians and the gravity torques, from which the motor-point Jacobians, the
        motor-mass terms and the positions are assembled for all configurations at once. ``full=False`` returns
        only what the effective collision parameters need (``q``, ``mass_matrix``, ``jacobian``; the other
        fields are None).
        """
        q = self._checked_q(q)
        pin, model, data = self._pin, self._structure, self._data
        n, nv = q.shape[0], self.nv
        mass = np.empty((n, nv, nv))
        contact_jacobian = np.empty((n, 6, nv))
        crba, frame_jacobian = pin.crba, pin.computeFrameJacobian
        frame, aligned = self._contact_frame_id, pin.LOCAL_WORLD_ALIGNED
        for s, qs in enumerate(q):
            mass[s] = crba(model, data, qs)
            contact_jacobian[s] = frame_jacobian(model, data, qs, frame, aligned)
        jacobian3 = np.ascontiguousarray(contact_jacobian[:, :3])
        jacobian = jacobian3 if self.plane is None else np.einsum("tp,stj->spj", self.plane, jacobian3)
        if not full:
            return ArmSamples(q=q, mass_matrix=mass, jacobian=jacobian)

        spatial = np.empty((n, 6, nv))
        gravity = np.empty((n, nv))
        joint_jacobians, generalized_gravity = pin.computeJointJacobians, pin.computeGeneralizedGravity
        for s, qs in enumerate(q):
            spatial[s] = joint_jacobians(model, data, qs)  # world frame, every joint
            gravity[s] = generalized_gravity(model, data, qs)
        rotations, origins, motor_points = self._forward_kinematics(q)
        linear, angular = spatial[:, :3], spatial[:, 3:]
        contact_joint = self._contact_joint - 1
        contact = origins[contact_joint] + rotations[contact_joint] @ self._contact_local
        # Motor i sits at joint i's origin on the parent link: it moves with the parent link's point there.
        points = np.stack(motor_points, axis=1)  # (n, motor i, 3)
        motor_jac = self._motor_masks[None, :, None, :] * (
            linear[:, None] - _skew(points) @ angular[:, None]
        )  # (n, motor i, 3, nv)
        return ArmSamples(
            q=q,
            mass_matrix=mass,
            jacobian=jacobian,
            gravity=gravity,
            motor_mass_influence=np.swapaxes(motor_jac, -1, -2) @ motor_jac,
            motor_gravity=-np.einsum("sitj,t->sij", motor_jac, self._gravity),
            contact_gravity=-np.einsum("stj,t->sj", jacobian3, self._gravity),
            contact_position=contact,
            joint_positions=np.stack(origins, axis=1),
        )

    def effective_parameters(
        self, samples: ArmSamples, directions: Any, **options: Any
    ) -> EffectiveParameters:
        """:func:`effective_parameters` with this arm's joint parameters (motor masses included); keyword
        ``options`` are passed on and may override any of them.
        """
        params = self.joint_parameters
        kwargs: dict[str, Any] = {
            "reflected_inertia": params.reflected_inertia,
            "stiffness": params.stiffness,
            "mechanical_stiffness": params.mechanical_stiffness,
            "torque_limit": params.torque_limit,
            "motor_mass": params.motor_mass if np.any(params.motor_mass > 0) else None,
        }
        kwargs.update(options)
        return effective_parameters(samples, directions, **kwargs)

    def _checked_q(self, q: Any) -> np.ndarray:
        q = np.atleast_2d(np.asarray(q, dtype=float))
        if q.ndim != 2 or q.shape[1] != self.nq:
            raise InvalidParameter("q", q.shape, f"configurations of shape (n, {self.nq})")
        if not np.all(np.isfinite(q)):
            raise InvalidParameter("q", q, "finite joint coordinates")
        return q

    def _forward_kinematics(
        self, q: np.ndarray
    ) -> tuple[list[np.ndarray], list[np.ndarray], list[np.ndarray]]:
        """Joint frames for all configurations at once, one array per joint: rotations (n, 3, 3) and origins
        (n, 3) of the joint frames, and the parent-side points of the joint origins (n, 3), where the motors
        sit [m].
        """
        n = q.shape[0]
        rotations: list[np.ndarray] = []
        origins: list[np.ndarray] = []
        motor_points: list[np.ndarray] = []
        for joint in self._joints:
            if joint.parent == 0:
                parent_rotation = np.broadcast_to(np.eye(3), (n, 3, 3))
                parent_origin = np.zeros((n, 3))
            else:
                parent_rotation = rotations[joint.parent - 1]
                parent_origin = origins[joint.parent - 1]
            point = parent_origin + parent_rotation @ joint.translation
            motor_points.append(point)
            if joint.nq == 1:
                coordinate = q[:, joint.idx_q]
            else:
                coordinate = np.arctan2(q[:, joint.idx_q + 1], q[:, joint.idx_q])
            if joint.revolute:
                # placement rotation times Rodrigues' rotation about the axis, as R_p + sin R_p K + (1-cos) R_p K^2
                local = (
                    joint.rotation
                    + np.sin(coordinate)[:, None, None] * joint.rotation_skew
                    + (1 - np.cos(coordinate))[:, None, None] * joint.rotation_skew2
                )
                rotations.append(parent_rotation @ local)
                origins.append(point)
            else:
                placed = parent_rotation @ joint.rotation
                rotations.append(placed)
                origins.append(point + coordinate[:, None] * (placed @ joint.axis))
        return rotations, origins, motor_points


# ---------------------------------------------------------------------- effective parameters
STIFFNESS_FORMS: tuple[str, ...] = ("compliance", "paper")
"""``"compliance"``: ``k = 1 / (u^T J K^-1 J^T u)`` (default, any Jacobian); ``"paper"``: the paper's
``k = u^T J^-T K J^-1 u`` (``eq:eff_k``), square Jacobians only."""


@dataclass(frozen=True)
class EffectiveParameters:
    """The 1D collision parameters along each direction, arrays of one shape: (n_configurations,
    n_directions) for a grid, (n_samples,) for paired samples.

    m_f: effective finger (structure) mass ``1 / (u^T J M_bb^-1 J^T u)`` (``eq:eff_mf``) [kg].
    m_r: effective robot (actuator) mass ``1 / (u^T J M_jj^-1 J^T u)`` [kg].
    k: effective lumped stiffness while sensing [N/m].
    k_m: effective mechanical stiffness [N/m].
    F_a: largest reaction force along ``-u`` before a joint saturates, ``min_i tau_i / |(J^T u)_i|`` [N].
    a: reaction acceleration ``F_a / m_r`` (``eq:eff_a``) [m/s^2].
    singular: True where the arm cannot move along ``u`` (``J^T u`` numerically zero): there ``m_f``, ``m_r``,
        ``k``, ``k_m`` and ``F_a`` are ``inf`` and ``a`` is 0, their limits.
    joint_threshold_force: contact force at which the first joint reaches its torque threshold,
        ``min_i tau_s,i / |(J^T u)_i|`` [N], when joint thresholds were given (else None).
    """

    m_f: np.ndarray
    m_r: np.ndarray
    k: np.ndarray
    k_m: np.ndarray
    F_a: np.ndarray
    a: np.ndarray
    singular: np.ndarray
    joint_threshold_force: np.ndarray | None = field(default=None)

    @property
    def shape(self) -> tuple[int, ...]:
        return tuple(self.m_f.shape)


def effective_parameters(
    samples: ArmSamples,
    directions: Any,
    reflected_inertia: Any,
    stiffness: Any,
    mechanical_stiffness: Any,
    torque_limit: Any,
    *,
    config_index: Any = None,
    motor_mass: Any = None,
    finger_joint_inertia: Any = None,
    stiffness_form: str = "compliance",
    joint_threshold: Any = None,
    task_stiffness: Any = None,
    singular_tolerance: float = 1e-12,
) -> EffectiveParameters:
    """Effective 1D collision parameters for many configurations and directions at once (MODEL.md §3).

    Parameters
    ----------
    samples: the arm's :class:`ArmSamples` (``Arm.kinematics``).
    directions: unit collision directions, world-aligned (in the arm's plane for a planar arm): (d, task_dim),
        every one applied to every configuration; or, with ``config_index``, (n_samples, task_dim), sample ``s``
        pairing ``directions[s]`` with configuration ``config_index[s]``. Normalised here.
    reflected_inertia: ``N^2 J_m`` per joint [kg m^2], > 0 (scalar or (nv,)).
    stiffness: lumped joint stiffness (mechanical and software in series) [N m/rad], > 0, ``inf`` allowed.
    mechanical_stiffness: joint mechanical stiffness [N m/rad], > 0, ``inf`` allowed.
    torque_limit: largest output torque per joint [N m], > 0, ``inf`` allowed.
    config_index: (n_samples,) configuration of each paired sample; None for the grid.
    motor_mass: motor mass per joint [kg], added to the structure as ``sum_i m_i A_i``; None for none.
    finger_joint_inertia: joint-space inertia per joint [kg m^2] that acts rigidly on the link side during the
        impact, added to the finger's mass matrix as ``diag(...)``: the reflected rotor inertia of a stiff
        transmission whose compliance sits at the contact (the paper's geared A8). None for none (the paper's
        arm model, reflected inertia in the robot mass only).
    stiffness_form: ``"compliance"`` (default) or ``"paper"`` (square Jacobians only), see
        :data:`STIFFNESS_FORMS`.
    joint_threshold: joint torque at which a joint detects the contact [N m] (a motor-current threshold
        reflected through the transmission); fills ``joint_threshold_force``.
    task_stiffness: stiffness of a Cartesian (task-space) controller [N/m], the same in every direction, in
        series with the joint springs while sensing (``1/k = u^T J K^-1 J^T u + 1/k_task``); None for none.
        With stiff joints it makes the sensing phase isotropic, as the paper's two-link example assumes.
    singular_tolerance: a direction is singular where ``u^T J M_bb^-1 J^T u`` is below this fraction of
        ``trace(J M_bb^-1 J^T)`` (an effective-mass ratio above ``1 / singular_tolerance``).

    Returns
    -------
    :class:`EffectiveParameters`; never NaN: singular directions are ``inf`` (``a = 0``) and flagged.
    """
    _validate.choice("stiffness_form", stiffness_form, STIFFNESS_FORMS)
    nv, task_dim = samples.nv, samples.task_dim
    inertia = _joint_array("reflected_inertia", reflected_inertia, nv)
    joint_k = _joint_array("stiffness", stiffness, nv, allow_inf=True)
    joint_km = _joint_array("mechanical_stiffness", mechanical_stiffness, nv, allow_inf=True)
    tau_max = _joint_array("torque_limit", torque_limit, nv, allow_inf=True)
    tau_s = None if joint_threshold is None else _joint_array("joint_threshold", joint_threshold, nv)
    if not (np.isfinite(singular_tolerance) and 0 < singular_tolerance < 1):
        raise InvalidParameter("singular_tolerance", singular_tolerance, "a number in (0, 1)")
    units = _unit_directions(directions, task_dim)
    paired = config_index is not None
    if paired:
        index = np.asarray(config_index, dtype=int).ravel()
        if index.shape != (units.shape[0],):
            raise InvalidParameter(
                "config_index", index.shape, f"one index per direction, ({units.shape[0]},)"
            )
        if index.size and (index.min() < 0 or index.max() >= samples.count):
            raise InvalidParameter("config_index", index, f"indices in [0, {samples.count})")
    if stiffness_form == "paper" and task_dim != nv:
        raise InvalidParameter(
            "stiffness_form",
            stiffness_form,
            f"'compliance' for a {task_dim} x {nv} Jacobian",
            "the paper's J^-T K J^-1 needs a square Jacobian",
        )

    jac = samples.jacobian
    structure = samples.structure_mass_matrix(motor_mass)
    if finger_joint_inertia is not None:
        structure = structure + np.diag(_joint_array("finger_joint_inertia", finger_joint_inertia, nv))
    jac_t = np.swapaxes(jac, 1, 2)
    # Task-space inverse inertias and compliances, once per configuration: G = J X^-1 J^T, stacked as
    # (structure, actuators, stiffness, mechanical stiffness).
    task = np.stack(
        [
            task_inverse_inertia(structure, jac),
            (jac / inertia) @ jac_t,
            (jac / joint_k) @ jac_t,
            (jac / joint_km) @ jac_t,
        ]
    )  # (4, n, task_dim, task_dim)
    scale = np.trace(task[0], axis1=1, axis2=2)
    pair_index = index if paired else None
    if paired:
        forms = np.einsum("sa,qsab,sb->qs", units, task[:, index], units)
        scale_s = scale[index]
    else:
        # u^T G u for every G and u in one product: (4 n, task_dim^2) x (task_dim^2, d).
        outer = np.einsum("da,db->dab", units, units).reshape(units.shape[0], -1)
        forms = (task.reshape(-1, task_dim * task_dim) @ outer.T).reshape(4, samples.count, -1)
        scale_s = scale[:, None]

    # Reciprocals in place: a zero compliance (an infinite joint stiffness or torque) gives inf; the 0/0 and
    # negative rounding of singular directions are overwritten with their limits below.
    with np.errstate(divide="ignore", invalid="ignore"):
        w_f, w_r, k, k_m = forms
        singular = w_f <= singular_tolerance * scale_s
        m_f = np.reciprocal(w_f, out=w_f)
        load = _largest_moment(jac, 1 / tau_max, units, pair_index)  # 1 / F_a
        a = w_r / load  # F_a / m_r
        m_r = np.reciprocal(w_r, out=w_r)
        F_a = np.reciprocal(load, out=load)
        if stiffness_form == "paper":
            k = _paper_stiffness(jac, joint_k, units, pair_index)
        else:
            np.reciprocal(k, out=k)
        np.reciprocal(k_m, out=k_m)
        joint_force = None
        if tau_s is not None:
            joint_force = _largest_moment(jac, 1 / tau_s, units, pair_index)
            np.reciprocal(joint_force, out=joint_force)
    if np.any(singular):
        for value in (m_f, m_r, k, k_m, F_a, joint_force):
            if value is not None:
                value[singular] = np.inf
        a[singular] = 0.0
    if task_stiffness is not None:
        from ..model.impulse import series_stiffness

        _validate.positive("task_stiffness", task_stiffness)
        k = np.where(singular, np.inf, series_stiffness(k, task_stiffness))
    return EffectiveParameters(m_f, m_r, k, k_m, F_a, a, singular, joint_force)


# ---------------------------------------------------------------------- impulses
SENSING_SCHEMES: tuple[str, ...] = ("force", "position", "joint_torque")
"""How contact is detected: ``"force"``, a force threshold at the contact [N]; ``"position"``, a tracking-error
threshold [m] so that ``F_s = k e_th``; ``"joint_torque"``, per-joint torque thresholds (motor current seen
through the transmission) given to :func:`effective_parameters` as ``joint_threshold``."""


@dataclass(frozen=True)
class CollisionImpulses:
    """Impulses of collisions along many directions, arrays of the shape of the effective parameters.

    threshold: the contact force at detection ``F_s`` [N].
    initial, sensing, reaction: the phase impulses [N s].
    total: the collision-reflex metric [N s]; ``inf`` along singular directions.
    v_star: the optimal approach velocity ``F_s / sqrt(2 k m_f)`` [m/s] (0 along singular directions).
    singular: as :attr:`EffectiveParameters.singular`.
    """

    threshold: np.ndarray
    initial: np.ndarray
    sensing: np.ndarray
    reaction: np.ndarray
    total: np.ndarray
    v_star: np.ndarray
    singular: np.ndarray


def collision_impulses(
    params: EffectiveParameters,
    v0: Any,
    threshold: Any = None,
    sensing: str = "force",
    reaction: str = "at_rest",
) -> CollisionImpulses:
    """Collision impulses from effective parameters, through :mod:`collision_reflex.model.impulse`.

    Parameters
    ----------
    params: from :func:`effective_parameters`.
    v0: approach velocity [m/s], a scalar or broadcastable to ``params.shape``.
    threshold: ``F_s`` [N] for ``sensing="force"``, the tracking-error threshold [m] for ``"position"``;
        unused for ``"joint_torque"`` (the thresholds were given to :func:`effective_parameters`).
    sensing: one of :data:`SENSING_SCHEMES`.
    reaction: ``"at_rest"`` (the paper's) or ``"moving"``, see :func:`collision_reflex.phase_impulses`.
    """
    from ..model.impulse import optimal_velocity, phase_impulses

    _validate.choice("sensing", sensing, SENSING_SCHEMES)
    shape = params.shape
    if sensing == "joint_torque":
        if params.joint_threshold_force is None:
            raise InvalidParameter(
                "sensing",
                sensing,
                "'force' or 'position' here",
                "pass joint_threshold=... to effective_parameters for joint-torque sensing",
            )
        force = params.joint_threshold_force
    else:
        if threshold is None:
            raise InvalidParameter("threshold", None, "a force [N] or a position error [m]")
        _validate.positive("threshold", threshold)
        force = np.asarray(threshold, dtype=float)
        if sensing == "position":
            force = params.k * force
    _validate.positive("v0", v0)
    singular = params.singular
    any_singular = bool(np.any(singular))

    def stand_in(value: Any) -> Any:
        """Finite stand-ins along singular directions (their results are replaced below), so that the 1D
        model sees only valid numbers; scalars pass as they are.
        """
        value = np.asarray(value, dtype=float)
        return np.where(singular, 1.0, value) if any_singular and value.ndim else value

    m_f, k, k_m, a = (stand_in(x) for x in (params.m_f, params.k, params.k_m, params.a))
    f_s, velocity = stand_in(force), stand_in(v0)
    phases = phase_impulses(m_f, k, k_m, f_s, a, velocity, reaction)
    v_star = optimal_velocity(m_f, k, f_s, reaction, k_m, a)
    parts = [np.broadcast_to(x, shape) for x in (phases.initial, phases.sensing, phases.reaction)]
    if any_singular:
        parts = [np.where(singular, np.inf, x) for x in parts]
        v_star = np.where(singular, 0.0, v_star)
    initial, sensing_part, reaction_part = parts
    return CollisionImpulses(
        threshold=np.broadcast_to(force, shape),
        initial=initial,
        sensing=sensing_part,
        reaction=reaction_part,
        total=initial + sensing_part + reaction_part,
        v_star=np.broadcast_to(v_star, shape),
        singular=singular,
    )


# ---------------------------------------------------------------------- helpers
def _joint_array(
    name: str, value: Any, nv: int, *, allow_inf: bool = False, allow_zero: bool = False
) -> np.ndarray:
    hint = "the URDF gives none for some joint; pass actuators= to the Arm or give the values explicitly"
    array = np.asarray(value, dtype=float)
    if array.ndim > 1 or array.size not in (1, nv):
        raise InvalidParameter(name, array, f"one value or {nv} values, one per joint")
    if np.any(np.isnan(array)):
        raise InvalidParameter(name, value, "known values for every joint", hint)
    try:
        if allow_zero:
            _validate.non_negative(name, array)
        else:
            _validate.positive(name, array, allow_inf=allow_inf)
    except InvalidParameter as error:
        raise InvalidParameter(name, value, error.allowed, hint) from None
    return np.broadcast_to(array, (nv,)).astype(float)


def _unit_directions(directions: Any, task_dim: int) -> np.ndarray:
    units = np.atleast_2d(np.asarray(directions, dtype=float))
    if units.ndim != 2 or units.shape[1] != task_dim:
        raise InvalidParameter("directions", units.shape, f"unit vectors of shape (d, {task_dim})")
    norms = np.linalg.norm(units, axis=1)
    if not np.all(np.isfinite(norms) & (norms > 0)):
        raise InvalidParameter("directions", directions, "non-zero finite vectors")
    return units / norms[:, None]


def task_inverse_inertia(mass_matrix: np.ndarray, jacobian: np.ndarray) -> np.ndarray:
    """``J M^-1 J^T`` for stacked mass matrices (n, nv, nv) [kg m^2] and Jacobians (n, m, nv) [m/rad],
    (n, m, m) [1/kg]: the inverse of the task-space (operational-space) inertia, the ellipsoid of gyration.
    """
    return jacobian @ _solve_spd(mass_matrix, np.swapaxes(jacobian, -1, -2))


def _solve_spd(matrix: np.ndarray, rhs: np.ndarray) -> np.ndarray:
    """Solve stacked symmetric positive-definite systems."""
    try:
        return np.linalg.solve(matrix, rhs)
    except np.linalg.LinAlgError:
        raise InvalidParameter(
            "mass_matrix",
            "singular",
            "positive-definite structure mass matrices",
            "every joint must move some link with mass or inertia",
        ) from None


def _largest_moment(
    jac: np.ndarray, weight: np.ndarray, units: np.ndarray, index: np.ndarray | None
) -> np.ndarray:
    """``max_i weight_i |(J^T u)_i|`` for the grid (n, d) or for paired samples (n_samples,)."""
    scaled = jac * weight
    if index is not None:
        return np.max(np.abs(np.einsum("sta,st->sa", scaled[index], units)), axis=-1)
    n, nv, d = jac.shape[0], jac.shape[2], units.shape[0]
    out = np.empty((n, d))
    # Blocks of configurations small enough to stay in cache (about 1 MB of moments each).
    step = max(1, 2**17 // (nv * d))
    directions_t = np.ascontiguousarray(units.T)
    for start in range(0, n, step):
        block = np.swapaxes(scaled[start : start + step], 1, 2) @ directions_t  # (block, nv, d)
        np.abs(block, out=block)
        np.max(block, axis=1, out=out[start : start + step])
    return out


def _paper_stiffness(
    jac: np.ndarray, joint_k: np.ndarray, units: np.ndarray, index: np.ndarray | None
) -> np.ndarray:
    """``u^T J^-T K J^-1 u`` (``eq:eff_k``) for square Jacobians, through the SVD so that a singular Jacobian
    gives ``inf`` along its singular direction and the finite limit perpendicular to it.
    """
    if not np.all(np.isfinite(joint_k)):
        raise InvalidParameter("stiffness", joint_k, "finite joint stiffnesses for stiffness_form='paper'")
    left, sigma, right_t = np.linalg.svd(jac)
    tiny = sigma <= 1e-12 * sigma[:, :1]
    inverse_sigma = np.where(tiny, 0.0, 1.0 / np.where(tiny, 1.0, sigma))
    # K_t = U S^-1 V^T K V S^-1 U^T: its quadratic form in u, with y = U^T u.
    inner = np.einsum("sia,a,sja->sij", right_t, joint_k, right_t)
    middle = inverse_sigma[:, :, None] * inner * inverse_sigma[:, None, :]
    if index is None:
        y = np.einsum("sti,dt->sdi", left, units)
        k = np.einsum("sdi,sij,sdj->sd", y, middle, y)
        along_null = np.any(tiny[:, None, :] & (np.abs(y) > 1e-9), axis=-1)
    else:
        y = np.einsum("sti,st->si", left[index], units)
        k = np.einsum("si,sij,sj->s", y, middle[index], y)
        along_null = np.any(tiny[index] & (np.abs(y) > 1e-9), axis=-1)
    return np.where(along_null, np.inf, k)


def _skew(vector: np.ndarray) -> np.ndarray:
    """Cross-product matrices ``[v]x`` of vectors (..., 3) -> (..., 3, 3), so that ``[v]x w = v x w``."""
    x, y, z = vector[..., 0], vector[..., 1], vector[..., 2]
    zero = np.zeros_like(x)
    return np.stack([zero, -z, y, z, zero, -x, -y, x, zero], axis=-1).reshape(*vector.shape[:-1], 3, 3)


def _support_mask(model: Any, joints: set[int]) -> np.ndarray:
    mask = np.zeros(model.nv)
    for j in joints:
        if j > 0:
            joint = model.joints[j]
            mask[joint.idx_v : joint.idx_v + joint.nv] = 1.0
    return mask


def _joint_kinematics(model: Any, robot: str) -> list[_JointKinematics]:
    """Describe every joint of a fixed-base model with 1-DoF joints; refuse anything else clearly."""
    import pinocchio as pin

    if model.njoints < 2:
        raise InvalidParameter("model", robot, "a robot with at least one joint")
    data = model.createData()
    q0 = pin.neutral(model)
    pin.computeJointJacobians(model, data, q0)
    joints = []
    for j in range(1, model.njoints):
        joint = model.joints[j]
        if joint.nv != 1 or joint.nq not in (1, 2):
            raise InvalidParameter(
                "model",
                f"joint {model.names[j]!r} ({joint.shortname()}, nq={joint.nq}, nv={joint.nv})",
                "a fixed-base robot whose joints are revolute or prismatic",
                "floating-base robots: use collision_reflex.arm.metrics for the impact mitigation factor, or load "
                "the URDF without a root joint",
            )
        local = np.asarray(pin.getJointJacobian(model, data, j, pin.LOCAL))[:, joint.idx_v]
        linear, angular = local[:3], local[3:]
        revolute = bool(np.linalg.norm(angular) > 1e-9)
        if revolute and np.linalg.norm(linear) > 1e-9:
            raise InvalidParameter("model", model.names[j], "revolute or prismatic joints (not helical)")
        axis = angular if revolute else linear
        placement = model.jointPlacements[j]
        joints.append(
            _JointKinematics(
                parent=int(model.parents[j]),
                idx_q=int(joint.idx_q),
                nq=int(joint.nq),
                revolute=revolute,
                axis=axis / np.linalg.norm(axis),
                rotation=np.array(placement.rotation),
                translation=np.array(placement.translation),
            )
        )
        if joint.idx_v != j - 1:
            raise InvalidParameter("model", robot, "joints numbered in velocity order")
    return joints


def _plane_basis(model: Any, joints: list[_JointKinematics]) -> np.ndarray | None:
    """(3, 2) world basis of the plane of motion when every revolute axis is parallel (and every prismatic
    axis perpendicular to them) in all configurations; None for a spatial arm.
    """
    import pinocchio as pin

    data = model.createData()
    rng = np.random.default_rng(0)  # a few fixed test configurations; the answer is geometric
    normal = None
    for trial in range(3):
        q = pin.neutral(model) if trial == 0 else _random_q(model, joints, rng)
        pin.computeJointJacobians(model, data, q)
        spatial = np.asarray(data.J)
        for v, joint in enumerate(joints):
            if not joint.revolute:
                continue
            axis = spatial[3:, v] / np.linalg.norm(spatial[3:, v])
            if normal is None:
                normal = axis
            elif np.linalg.norm(np.cross(normal, axis)) > 1e-9:
                return None
        if normal is None:
            return None  # prismatic only: treat as spatial
        for v, joint in enumerate(joints):
            if not joint.revolute and abs(np.dot(spatial[:3, v], normal)) > 1e-9:
                return None
    assert normal is not None
    normal = normal * np.sign(normal[np.argmax(np.abs(normal))])
    first = np.eye(3)[int(np.argmin(np.abs(normal)))]
    first = first - np.dot(first, normal) * normal
    first /= np.linalg.norm(first)
    second = np.cross(normal, first)
    return np.stack([first, second], axis=1)


def _random_q(model: Any, joints: list[_JointKinematics], rng: np.random.Generator) -> np.ndarray:
    import pinocchio as pin

    q = pin.neutral(model)
    for joint in joints:
        angle = rng.uniform(-np.pi, np.pi)
        if joint.nq == 1:
            q[joint.idx_q] = angle if joint.revolute else rng.uniform(-0.1, 0.1)
        else:
            q[joint.idx_q : joint.idx_q + 2] = np.cos(angle), np.sin(angle)
    return q
