"""The :class:`Arm`: a fixed-base URDF robot with a contact point and per-joint actuation.

Loaded through Pinocchio, with its configurations and its batched kinematics (:class:`ArmSamples`).

Conventions (SI throughout): the contact Jacobian is the translational Jacobian of the contact point in
world-aligned axes; a planar arm (all joint axes parallel) is described in the plane perpendicular to its axes
(``task_dim == 2``), any other arm in 3D. ``model.armature`` carries the reflected rotor inertia ``N^2 J_m``; the
structure mass matrix of :class:`ArmSamples` excludes it, and excludes the motor masses, whose effect is given
separately and linearly (``M_bb(q; m) = M_bb0(q) + sum_i m_i A_i(q)``).
"""

from __future__ import annotations

import hashlib
import os
import pickle
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt

from .. import _validate
from ..errors import FrameNotFound, InvalidParameter, UrdfError
from .actuation import joint_parameters, scaled_actuators, sensing_options
from .configurations import ConfigurationSpace
from .effective import EffectiveParameters, effective_parameters
from .joints import JointParameters
from .kinematic_tree import joint_kinematics
from .robots import captured_stderr, load_urdf, loaded_example_robot, parser_reason, with_locked_joints
from .samples import ArmSamples, ContactKinematics, GravityTerms

if TYPE_CHECKING:
    from ..hardware.actuators import CurrentThreshold, ForceThreshold, PositionThreshold
    from ..hardware.motors import Motor


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
        contact_offset: npt.ArrayLike | None = None,
        actuators: Any = None,
        name: str = "",
        urdf_path: str | os.PathLike[str] | None = None,
        package_dirs: Sequence[str | os.PathLike[str]] | None = None,
    ) -> None:
        import pinocchio as pin

        self.name = name or str(model.name)
        self.urdf_path = None if urdf_path is None else Path(urdf_path)
        self.package_dirs = tuple(str(p) for p in package_dirs or ())
        self._joints = joint_kinematics(model, self.name)
        self.joint_names: tuple[str, ...] = tuple(model.names[i] for i in range(1, model.njoints))
        if not isinstance(contact_frame, str):
            raise InvalidParameter("contact_frame", contact_frame, "the name of a frame of the model")
        if not model.existFrame(contact_frame):
            raise FrameNotFound(contact_frame, [f.name for f in model.frames], "frame", self.name)
        self.contact_frame = contact_frame
        offset = (
            np.zeros(3)
            if contact_offset is None
            else _validate.real("contact_offset", contact_offset, "three finite coordinates [m]")
        )
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
        speed = np.asarray(model.velocityLimit, dtype=float)
        self.joint_speed_limit: np.ndarray = np.where(
            (speed <= 0) | (speed > 1e300) | ~np.isfinite(speed), np.inf, speed
        )
        """The URDF's velocity limit per joint [rad/s or m/s], ``inf`` where it gives none."""
        params = joint_parameters(actuators, model.nv, model.armature, self.urdf_torque_limit)
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
        self._contact_kinematics = ContactKinematics.of_model(
            model, self._joints, self._contact_joint, self._contact_local
        )
        # Kinematics use a structure-only model (no armature), so ArmSamples.mass_matrix is M_bb0.
        self._structure = self._contact_kinematics.model
        self.plane = self._contact_kinematics.plane
        self.configuration_space = ConfigurationSpace(
            tuple(self._joints),
            self.joint_names,
            np.asarray(self._structure.lowerPositionLimit, dtype=float),
            np.asarray(self._structure.upperPositionLimit, dtype=float),
        )
        """The joints as coordinates: limits, and the map to and from configurations."""
        self.reference_configuration: np.ndarray = np.array(pin.neutral(model))
        """A configuration to start from [rad, m]: the robot's reference pose when known, else neutral."""
        self._pin = pin

    @property
    def fingerprint(self) -> bytes:
        """A digest of the model (links, joints, limits, armature) and the contact point.

        Arms with equal fingerprints have the same kinematics: what is computed from those alone (the reach,
        the worst hold poses) is shared between them.
        """
        return hashlib.sha256(pickle.dumps((self.model, self.contact_frame, self.contact_offset))).digest()

    # ------------------------------------------------------------------ construction
    @classmethod
    def from_urdf(
        cls,
        path: str | os.PathLike[str],
        contact_frame: str,
        package_dirs: Sequence[str | os.PathLike[str]] | None = None,
        contact_offset: npt.ArrayLike | None = None,
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
        contact_offset: npt.ArrayLike | None = None,
        actuators: Any = None,
        locked_joints: Sequence[str] | None = None,
    ) -> Arm:
        """Load a robot of the ``example-robot-data`` package by name.

        Names such as ``"ur5"``, ``"panda"``, ``"double_pendulum"``, ...

        Defaults per robot: Panda contacts at ``panda_hand_tcp`` with its two finger joints locked; UR robots at
        ``tool0``; the double pendulum at its second link's tip (0.2 m along the link); legged robots (``solo12``,
        ``a1``) at the front-left foot with the base fixed to the world. Other robots need ``contact_frame``.
        ``locked_joints`` replaces the default list of locked joints (``()`` locks none).
        """
        robot = loaded_example_robot(name, contact_frame, contact_offset, locked_joints)
        arm = cls(
            robot.model,
            robot.contact_frame,
            robot.contact_offset,
            actuators,
            name,
            robot.urdf,
            [robot.package_dir],
        )
        arm.reference_configuration = robot.reference_configuration
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
        torque_required: npt.ArrayLike | None = None,
        *,
        reference: Motor | None = None,
        law: str = "haddadin",
        mechanical_stiffness: npt.ArrayLike = np.inf,
        software_stiffness: npt.ArrayLike = np.inf,
        sensing: ForceThreshold | PositionThreshold | CurrentThreshold | None = None,
    ) -> Arm:
        """The same arm with a scaled motor at every joint, geared to meet a torque requirement.

        The paper's sweep of ``tab:motor_params``: ``N_i = max(1, tau_req,i / tau_p(r))``.

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
        required = self.urdf_torque_limit if torque_required is None else torque_required
        actuators = scaled_actuators(
            stator_diameter,
            required,
            self.nv,
            reference=reference,
            law=law,
            mechanical_stiffness=mechanical_stiffness,
            software_stiffness=software_stiffness,
            sensing=sensing,
        )
        return self.with_actuators(actuators)

    def sensing_options(self) -> dict[str, Any]:
        """The sensing of this arm's actuators as keyword arguments.

        ``{"sensing": "force", "threshold": F_s}`` [N] for force thresholds at the contact, or
        ``{"sensing": "current", "joint_threshold": tau_s}`` [N m] for the joint-side schemes (motor current,
        and joint position errors, whose threshold is the joint torque ``k e_th`` as well), where the first
        joint to reach its threshold detects the contact.
        """
        return sensing_options(self.actuators)

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
        """Size of a configuration vector (a continuous joint counts twice: cosine and sine)."""
        return int(self._structure.nq)

    @property
    def nv(self) -> int:
        """Number of joints (degrees of freedom)."""
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
        return self.configuration_space.joint_limits()

    def configuration(self, angles: npt.ArrayLike) -> np.ndarray:
        """Configurations (..., nq) from joint coordinates (..., nv) [rad or m].

        Unbounded revolute joints are stored by Pinocchio as cosine and sine.
        """
        return self.configuration_space.configuration(angles)

    def joint_coordinates(self, q: npt.ArrayLike) -> np.ndarray:
        """Joint angles or displacements (..., nv) of configurations (..., nq) [rad or m]."""
        return self.configuration_space.joint_coordinates(q)

    def sample_configurations(self, count: int, rng: np.random.Generator) -> np.ndarray:
        """``count`` configurations drawn uniformly within the joint limits, shape (count, nq).

        Parameters
        ----------
        count: number of configurations, >= 1.
        rng: the random generator (``numpy.random.default_rng(seed)``), for reproducible samples.
        """
        return self.configuration_space.sample(count, rng)

    # ------------------------------------------------------------------ kinematics
    def kinematics(self, q: npt.ArrayLike, *, full: bool = True) -> ArmSamples:
        """Mass matrix, contact Jacobian, gravity and motor-mass terms at configurations ``q`` (n, nq).

        Pinocchio evaluates the mass matrix (CRBA) and the contact Jacobian once per configuration, and with
        ``full`` also the joint Jacobians and the gravity torques, from which the motor-point Jacobians, the
        motor-mass terms and the positions are assembled for all configurations at once. ``full=False`` returns
        only what the effective collision parameters need (``q``, ``mass_matrix``, ``jacobian``; the other
        fields are None).
        """
        return self._contact_kinematics.samples(self.configuration_space.checked(q), full)

    def gravity_terms(self, q: npt.ArrayLike) -> GravityTerms:
        """The gravity fields of :meth:`kinematics` alone at configurations ``q`` (n, nq).

        What holding the arm still needs, the same numbers without the mass matrix.
        """
        return self._contact_kinematics.gravity_terms(self.configuration_space.checked(q))

    def effective_parameters(
        self, samples: ArmSamples, directions: npt.ArrayLike, **options: Any
    ) -> EffectiveParameters:
        """:func:`effective_parameters` with this arm's joint parameters (motor masses included).

        Keyword ``options`` are passed on and may override any of them.
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
