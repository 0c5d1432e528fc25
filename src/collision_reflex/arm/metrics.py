"""Metrics related to the collision reflex (the paper's section "Transparency").

- generalized inertia ellipsoid ``Lambda_0 = J^-T M J^-1`` (Asada), computed as ``(J M^-1 J^T)^-1`` so that it
  exists for redundant arms too, and its inverse, the ellipsoid of gyration ``J M^-1 J^T`` (Hogan), which
  exists even at singular configurations;
- dynamic manipulability ellipsoid ``Lambda_d = J (M^T M)^-1 J^T`` (Yoshikawa);
- effective mass along ``u``, ``(u^T Lambda_0^-1 u)^-1`` (Khatib, the paper's ``eq:effective_mass``);
- impact mitigation factor of a floating-base robot (Wensing et al. 2017): ``det(I - Lambda Lambda_l^-1)``,
  ``Lambda`` the operational-space inertia at a contact point of the robot with its reflected rotor inertias
  and ``Lambda_l`` that of the same robot with its joints locked (a single rigid body).

``M`` is the manipulator's full mass matrix: the structure, the motor masses and the reflected rotor inertia
on the diagonal (Pinocchio's armature). SI units: masses [kg], inertias [kg m^2], lengths [m].
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

from .. import _validate
from ..errors import FrameNotFound, InvalidParameter
from .directions import normalised_directions
from .joints import joint_array
from .robots import ROBOT_DEFAULTS, example_robot
from .samples import ArmSamples, task_inverse_inertia


@dataclass(frozen=True)
class Ellipsoid:
    """Stacked ellipsoids ``{x : x^T A^-1 x <= 1}`` of symmetric positive semi-definite matrices ``A``.

    ``A`` is (n, m, m); the semi-axes are the square roots of the eigenvalues of ``A``.
    """

    matrix: np.ndarray

    @property
    def semi_axes(self) -> np.ndarray:
        """(n, m) semi-axis lengths, ascending."""
        return np.sqrt(np.clip(np.linalg.eigvalsh(self.matrix), 0.0, None))

    @property
    def principal_directions(self) -> np.ndarray:
        """(n, m, m) unit principal directions, one per column, in the order of :attr:`semi_axes`."""
        return np.linalg.eigh(self.matrix)[1]

    def along(self, directions: npt.ArrayLike) -> np.ndarray:
        """The quadratic form ``u^T A u`` for unit directions (d, m), (n, d)."""
        units = normalised_directions(directions, self.matrix.shape[-1])
        return np.einsum("da,nab,db->nd", units, self.matrix, units)


def full_mass_matrix(
    samples: ArmSamples,
    reflected_inertia: npt.ArrayLike | None = None,
    motor_mass: npt.ArrayLike | None = None,
) -> np.ndarray:
    """``M = M_bb(q; m) + diag(N^2 J_m)`` (n, nv, nv).

    Structure, motor masses [kg] and reflected rotor inertia [kg m^2] (each default zero).
    """
    mass = samples.structure_mass_matrix(motor_mass)
    if reflected_inertia is None:
        return mass
    armature = joint_array("reflected_inertia", reflected_inertia, samples.nv, allow_zero=True)
    return mass + np.diag(armature)


def ellipsoid_of_gyration(
    samples: ArmSamples,
    reflected_inertia: npt.ArrayLike | None = None,
    motor_mass: npt.ArrayLike | None = None,
) -> Ellipsoid:
    """``Lambda_0^-1 = J M^-1 J^T`` [1/kg]: defined at every configuration, singular ones included."""
    return Ellipsoid(
        task_inverse_inertia(full_mass_matrix(samples, reflected_inertia, motor_mass), samples.jacobian)
    )


def generalized_inertia_ellipsoid(
    samples: ArmSamples,
    reflected_inertia: npt.ArrayLike | None = None,
    motor_mass: npt.ArrayLike | None = None,
) -> Ellipsoid:
    """``Lambda_0 = (J M^-1 J^T)^-1`` [kg] (equal to ``J^-T M J^-1`` for a square Jacobian).

    Raises :class:`InvalidParameter` at a singular configuration, where it does not exist; use
    :func:`ellipsoid_of_gyration` there.
    """
    gyration = ellipsoid_of_gyration(samples, reflected_inertia, motor_mass).matrix
    eigenvalues = np.linalg.eigvalsh(gyration)
    singular = eigenvalues[:, 0] <= 1e-12 * eigenvalues[:, -1]
    if np.any(singular):
        raise InvalidParameter(
            "samples",
            f"configuration {int(np.argmax(singular))} (q = {samples.q[int(np.argmax(singular))].round(4).tolist()})",
            "non-singular configurations",
            "the generalized inertia ellipsoid is unbounded there; use ellipsoid_of_gyration",
        )
    return Ellipsoid(np.linalg.inv(gyration))


def dynamic_manipulability_ellipsoid(
    samples: ArmSamples,
    reflected_inertia: npt.ArrayLike | None = None,
    motor_mass: npt.ArrayLike | None = None,
) -> Ellipsoid:
    """``Lambda_d = J (M^T M)^-1 J^T`` [(m/s^2)^2 per (N m)^2].

    The task accelerations reachable with joint torques of unit norm lie in this ellipsoid.
    """
    mass = full_mass_matrix(samples, reflected_inertia, motor_mass)
    with _validate.combining(reflected_inertia=reflected_inertia, motor_mass=motor_mass):
        return Ellipsoid(task_inverse_inertia(np.swapaxes(mass, 1, 2) @ mass, samples.jacobian))


def effective_mass(
    samples: ArmSamples,
    directions: npt.ArrayLike,
    reflected_inertia: npt.ArrayLike | None = None,
    motor_mass: npt.ArrayLike | None = None,
) -> np.ndarray:
    """Effective mass ``(u^T J M^-1 J^T u)^-1`` [kg] of the whole arm along each direction, (n, d).

    Rotor inertia included; ``inf`` along singular directions.
    """
    gyration = ellipsoid_of_gyration(samples, reflected_inertia, motor_mass)
    inverse = gyration.along(directions)
    scale = np.trace(gyration.matrix, axis1=1, axis2=2)[:, None]
    out = np.full(inverse.shape, np.inf)
    np.divide(1.0, inverse, out=out, where=inverse > 1e-12 * scale)
    return out


@dataclass(frozen=True)
class ImpactMitigation:
    """Impact mitigation of a floating-base robot at one contact (Wensing et al. 2017).

    factor: ``det(I - Lambda Lambda_l^-1)``, 0 for a robot that behaves as if its joints were locked, larger
        for a more backdrivable one.
    matrix: the impact mitigation matrix ``I - Lambda Lambda_l^-1`` (3, 3).
    free_inertia: ``Lambda``, operational-space inertia with the joints free [kg] (3, 3).
    locked_inertia: ``Lambda_l``, operational-space inertia with the joints locked [kg] (3, 3).
    robot, contact_frame: what was evaluated; q: the configuration (nq,).
    """

    factor: float
    matrix: np.ndarray
    free_inertia: np.ndarray
    locked_inertia: np.ndarray
    robot: str
    contact_frame: str
    q: np.ndarray


def impact_mitigation_factor(
    robot: str | Any,
    reflected_inertia: npt.ArrayLike,
    q: npt.ArrayLike | None = None,
    contact_frame: str | None = None,
) -> ImpactMitigation:
    """Impact mitigation factor of a floating-base robot at a contact frame.

    Parameters
    ----------
    robot: an example-robot-data name (``"solo12"``, ``"a1"``, ...) or a ``pinocchio.Model`` whose first joint
        is a free flyer.
    reflected_inertia: ``N^2 J_m`` per actuated joint [kg m^2] (scalar or one per joint), >= 0.
    q: configuration (nq,); default the model's ``"standing"`` reference configuration (else neutral).
    contact_frame: contact frame; default the front-left foot for the known robots.
    """
    import pinocchio as pin

    name, model = _floating_base_model(robot)
    if contact_frame is not None and not isinstance(contact_frame, str):
        raise InvalidParameter(
            "contact_frame", contact_frame, "a frame name, or None for the robot's default"
        )
    if contact_frame is None:
        contact_frame = ROBOT_DEFAULTS.get(name, {}).get("contact_frame")
        if contact_frame is None:
            raise InvalidParameter("contact_frame", None, f"a frame name for {name!r} (no default is known)")
    if not model.existFrame(contact_frame):
        raise FrameNotFound(contact_frame, [f.name for f in model.frames], "frame", name)
    if q is None:
        reference = model.referenceConfigurations
        q = np.array(reference["standing"]) if "standing" in reference else pin.neutral(model)
    q = _validate.real("q", q, f"a finite configuration of shape ({model.nq},)")
    if q.shape != (model.nq,) or not np.all(np.isfinite(q)):
        raise InvalidParameter("q", q.shape, f"a finite configuration of shape ({model.nq},)")
    free = model.copy()
    free.armature = np.concatenate(
        [np.zeros(6), joint_array("reflected_inertia", reflected_inertia, model.nv - 6, allow_zero=True)]
    )
    data = free.createData()
    mass = pin.crba(free, data, q)
    jacobian = pin.computeFrameJacobian(
        free, data, q, free.getFrameId(contact_frame), pin.LOCAL_WORLD_ALIGNED
    )[:3]
    free_inverse = task_inverse_inertia(mass[None], jacobian[None])[0]
    # Locked joints: the robot is one rigid body, the composite inertia of the floating-base block.
    locked_inverse = task_inverse_inertia(mass[None, :6, :6], jacobian[None, :, :6])[0]
    free_inertia = _inverse(free_inverse, "free")
    locked_inertia = _inverse(locked_inverse, "locked")
    matrix = np.eye(3) - free_inertia @ locked_inverse
    return ImpactMitigation(
        factor=float(np.linalg.det(matrix)),
        matrix=matrix,
        free_inertia=free_inertia,
        locked_inertia=locked_inertia,
        robot=name,
        contact_frame=contact_frame,
        q=q,
    )


def _floating_base_model(robot: str | Any) -> tuple[str, Any]:
    if isinstance(robot, str):
        model, name = example_robot(robot)[0], robot
    elif all(hasattr(robot, a) for a in ("name", "njoints", "joints", "existFrame")):  # a pinocchio.Model
        model, name = robot, str(robot.name)
    else:
        raise InvalidParameter("robot", robot, "an example-robot-data name or a pinocchio.Model")
    if model.njoints < 2 or model.joints[1].nv != 6:
        raise InvalidParameter("robot", name, "a floating-base model (a free-flyer root joint)")
    return name, model


def _inverse(matrix: np.ndarray, which: str) -> np.ndarray:
    eigenvalues = np.linalg.eigvalsh(matrix)
    if eigenvalues[0] <= 1e-12 * eigenvalues[-1]:
        raise InvalidParameter(
            "contact_frame",
            which,
            "a contact point that can move in every direction",
            "the contact Jacobian is singular at this configuration",
        )
    return np.linalg.inv(matrix)
