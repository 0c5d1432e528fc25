"""The contact samples a design is evaluated on, and the numeric and symbolic per-sample data of the NLP.

Sample ``s`` is a configuration with its Pinocchio data hit along a unit direction ``u``. Per sample the NLP
needs ``w = J^T u``, the structure mass matrix ``M_bb0`` and the motor-mass influence matrices (numeric,
packed into one data column), and one SX function that maps the symbolic design column and the sample's
auxiliaries to the effective parameters of the paper's "Collision Reflex in Higher Dimensions" and the 1D
impulse of :mod:`collision_reflex.model.impulse`.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import casadi as ca
import numpy as np

from ..errors import InvalidParameter
from ..model import effective as formulas
from ..model.impulse import phase_impulses
from ..model.sensing import threshold_force

if TYPE_CHECKING:
    from ..arm.samples import ArmSamples


SPEED_CAP_TOLERANCE = 1e-6
"""Relative amount by which a design's approach velocity may exceed a sample's speed cap with the sample still in
its domain: an interior-point solve holds a velocity bound to about 1e-8 relative."""


@dataclass(frozen=True)
class ContactSamples:
    """Contact cases the design is evaluated on.

    Sample ``s`` is configuration ``config_index[s]`` of ``kinematics`` hit along unit direction
    ``directions[s]`` (world-aligned, ``task_dim`` components).

    kinematics: :class:`collision_reflex.arm.ArmSamples` of the configurations.
    directions: (n_samples, task_dim) unit vectors.
    config_index: (n_samples,) index into the configurations.
    speed_cap: (n_samples,) the fastest approach velocity [m/s] whose guarded move along the sample's direction
        stays within the joint speed limits (the contact domain, :mod:`collision_reflex.arm.domain`): the sample
        counts for designs approaching no faster; default ``inf`` (every design), as for samples drawn at the
        fastest approach of the design space.
    drawn: (n_samples,) True for samples drawn at random or given, False for points a worst-case search added;
        means are taken over the drawn samples, worst cases over all (within their speed caps). Default all.
    """

    kinematics: ArmSamples
    directions: np.ndarray
    config_index: np.ndarray
    labels: tuple[str, ...] = field(default=())
    speed_cap: np.ndarray | None = None
    drawn: np.ndarray | None = None

    def __post_init__(self) -> None:
        directions = np.atleast_2d(np.asarray(self.directions, dtype=float))
        index = np.asarray(self.config_index, dtype=int).ravel()
        task_dim = self.kinematics.jacobian.shape[1]
        if directions.shape != (index.size, task_dim):
            raise InvalidParameter("directions", directions.shape, f"shape ({index.size}, {task_dim})")
        norms = np.linalg.norm(directions, axis=1)
        if not np.all(np.isfinite(norms) & (norms > 0)):
            raise InvalidParameter("directions", self.directions, "non-zero finite vectors")
        if index.size == 0 or index.min() < 0 or index.max() >= self.kinematics.q.shape[0]:
            raise InvalidParameter("config_index", index, f"indices in [0, {self.kinematics.q.shape[0]})")
        object.__setattr__(self, "directions", directions / norms[:, None])
        object.__setattr__(self, "config_index", index)
        cap = (
            np.full(index.size, np.inf)
            if self.speed_cap is None
            else np.asarray(self.speed_cap, float).ravel()
        )
        if cap.shape != (index.size,) or not np.all(cap > 0):
            raise InvalidParameter(
                "speed_cap", self.speed_cap, f"{index.size} velocities > 0 [m/s] (inf: none)"
            )
        drawn = (
            np.ones(index.size, bool) if self.drawn is None else np.asarray(self.drawn, dtype=bool).ravel()
        )
        if drawn.shape != (index.size,) or not np.any(drawn):
            raise InvalidParameter("drawn", self.drawn, f"{index.size} flags, at least one sample drawn")
        object.__setattr__(self, "speed_cap", cap)
        object.__setattr__(self, "drawn", drawn)

    @classmethod
    def grid(cls, kinematics: ArmSamples, directions: np.ndarray) -> ContactSamples:
        """Every configuration of ``kinematics`` with every direction."""
        directions = np.atleast_2d(np.asarray(directions, dtype=float))
        n_config = kinematics.q.shape[0]
        index = np.repeat(np.arange(n_config), directions.shape[0])
        return cls(kinematics, np.tile(directions, (n_config, 1)), index)

    @property
    def size(self) -> int:
        """Number of samples."""
        return int(self.config_index.size)

    def inside(self, velocity: float) -> np.ndarray:
        """Which samples lie in the contact domain of a design approaching at ``velocity`` [m/s], (n,) bool."""
        assert self.speed_cap is not None  # set in __post_init__
        return np.asarray(self.speed_cap >= velocity * (1 - SPEED_CAP_TOLERANCE))

    @property
    def joint_moment_arms(self) -> np.ndarray:
        """``w = J^T u`` per sample, (n_samples, nv): joint torque per unit contact force [m or N m/N]."""
        jacobian = self.kinematics.jacobian[self.config_index]
        return np.einsum("sdj,sd->sj", jacobian, self.directions)


def kinematic_term(samples: ContactSamples, name: str) -> np.ndarray:
    """The samples' kinematic term ``name`` (a field of :class:`collision_reflex.arm.ArmSamples`).

    The gravity and motor-mass terms are None in kinematics computed with ``full=False``; the design problem
    needs them, so a missing one is a clear error.
    """
    value: np.ndarray | None = getattr(samples.kinematics, name)
    if value is None:
        raise InvalidParameter(
            f"samples.kinematics.{name}",
            None,
            "the full kinematics of the configurations",
            "compute them with Arm.kinematics(q) (full=True)",
        )
    return value


def loaded_joints(samples: ContactSamples) -> np.ndarray:
    """Mark the joints a contact force along each sample's direction loads, (n_samples, n_joints) bool.

    A loaded joint's torque limit bounds the reaction force; ``|w_i|`` below 1e-12 of the largest counts as
    unloaded.
    """
    w = np.abs(samples.joint_moment_arms)
    return w > 1e-12 * np.maximum(w.max(axis=1, keepdims=True), 1e-300)


def reaction_compliance(samples: ContactSamples, peak_torque: np.ndarray) -> np.ndarray:
    """Give ``1 / F_a = max_i |w_i| / tau_i`` per sample [1/N] for peak joint torques ``tau`` [N m].

    It is the inverse of the largest contact force the joints can push back with before the first saturates
    (the paper's "Collision Reflex in Higher Dimensions").
    """
    return np.asarray(
        formulas.reaction_compliance(
            formulas.torque_fractions(samples.joint_moment_arms, np.asarray(peak_torque, dtype=float))
        )
    )


def finger_mass_directions(
    samples: ContactSamples, motor_mass: np.ndarray, finger_joint_inertia: np.ndarray | None = None
) -> np.ndarray:
    """Give the minimiser ``x_s = M_f^-1 w_s / (w_s^T M_f^-1 w_s)`` of ``x^T M_f x`` with ``w_s^T x = 1``.

    One row per sample, (n_samples, n_joints): ``M_f`` the structure mass matrix with motor masses ``m`` [kg]
    and, when the reflected inertia acts on the finger, ``diag(N^2 J_m)`` [kg m^2].
    """
    kin = samples.kinematics
    index = samples.config_index
    structure = formulas.finger_mass_matrix(
        kin.mass_matrix[index],
        kinematic_term(samples, "motor_mass_influence")[index],
        motor_mass,
        finger_joint_inertia,
    )
    return np.asarray(formulas.finger_mass_direction(samples.joint_moment_arms, structure))


@functools.lru_cache(maxsize=8)
def sample_function(
    n_joints: int, sensing: str, reaction: str, finger_joints: tuple[bool, ...]
) -> ca.Function:
    """SX function of one contact sample, built once per process for each set of arguments.

    Every problem of one arm (a study's objective, its anchors, its active-set rounds, each catalogue
    combination) shares it: it holds no design or technology figure, only the model.

    Inputs: the design column (motor masses, reflected inertias, joint stiffnesses (n each), threshold,
    approach velocity), the finger-mass direction ``x`` (n, with ``w^T x = 1``), the reaction compliance ``c``
    (``1/F_a`` [1/N]), the sample's data (``w = J^T u`` (n), ``M_bb0`` (n*n), motor-mass influence matrices
    (n*n*n), effective mechanical stiffness) and the coupled-mass direction ``y`` (n, with ``w^T y = 1``).
    Outputs: the impulse [N*s], the contact-force threshold [N], ``w^T x``, the effective parameters
    ``(m_f, m_r, k, k_m, a)`` of :mod:`collision_reflex.model.effective`, the coupled mass
    ``y^T (M_f + diag(N^2 J)) y`` [kg] (every rotor on the links: the robot mass a body region meets,
    :func:`collision_reflex.model.contact_robot_mass`'s bound; exact at the optimal ``y``) and ``w^T y``.
    """
    n = n_joints
    design = ca.SX.sym("design", 3 * n + 2)
    direction = ca.SX.sym("x", n)
    coupled_direction = ca.SX.sym("y", n)
    compliance = ca.SX.sym("c")
    data = ca.SX.sym("data", n + n * n + n**3 + 1)
    mass, inertia, stiffness = (design[i * n : (i + 1) * n] for i in range(3))
    threshold_variable, velocity = design[3 * n], design[3 * n + 1]
    w = data[:n]
    offset = n + n * n
    influence = [ca.reshape(data[offset + i * n * n : offset + (i + 1) * n * n], n, n) for i in range(n)]
    finger_matrix = formulas.finger_mass_matrix(
        ca.reshape(data[n:offset], n, n),
        influence,
        mass,
        formulas.finger_inertia(inertia, ca.DM(finger_joints)) if any(finger_joints) else None,
    )
    # x^T M_f x: the finger mass at the optimal x (the NLP's constraint w^T x = 1 and its minimisation).
    finger_mass = formulas.finger_mass(direction, finger_matrix)
    k_mech = data[-1]

    # Effective parameters along u (the paper's "Collision Reflex in Higher Dimensions"), compliance forms;
    # w^T is the Jacobian along u.
    robot_compliance = formulas.task_compliance(ca.transpose(w), inertia)
    k = 1 / formulas.task_compliance(ca.transpose(w), stiffness)
    force_threshold = threshold_force(sensing, threshold_variable, k)
    acceleration = formulas.reaction_acceleration(robot_compliance, compliance)
    impulse = phase_impulses(finger_mass, k, k_mech, force_threshold, acceleration, velocity, reaction).total
    parameters = ca.vertcat(finger_mass, 1 / robot_compliance, k, k_mech, acceleration)
    behind = ca.DM([0.0 if placed else 1.0 for placed in finger_joints])  # the rotors not yet in M_f
    coupled_mass = formulas.finger_mass(coupled_direction, finger_matrix) + ca.dot(
        behind * inertia, coupled_direction * coupled_direction
    )
    return ca.Function(
        "sample_impulse",
        [design, direction, compliance, data, coupled_direction],
        [
            impulse,
            force_threshold,
            ca.dot(w, direction),
            parameters,
            coupled_mass,
            ca.dot(w, coupled_direction),
        ],
    )


def sample_data(samples: ContactSamples, k_mech: np.ndarray) -> np.ndarray:
    """Numeric data column per sample (see :func:`sample_function`), shape (rows, n_samples).

    ``k_mech`` is the joint mechanical stiffness [N m/rad] per joint; the column holds its effective value
    along ``u`` [N/m].
    """
    kin = samples.kinematics
    w = samples.joint_moment_arms
    n_samples, n = w.shape
    unreachable = ~np.any(loaded_joints(samples), axis=1)
    if np.any(unreachable):
        bad = int(np.flatnonzero(unreachable)[0])
        raise InvalidParameter(
            f"sample {bad}",
            samples.directions[bad],
            "a direction the arm can move along (J^T u != 0)",
            "drop samples at singular configurations along their singular direction",
        )
    structure = kin.mass_matrix[samples.config_index].reshape(n_samples, n * n, order="F")
    influence = (
        kinematic_term(samples, "motor_mass_influence")[samples.config_index]
        .transpose(0, 1, 3, 2)
        .reshape(n_samples, n * n * n)
    )
    k_mech_effective = 1 / formulas.task_compliance(w[:, None, :], k_mech)[:, 0, 0]
    return np.column_stack([w, structure, influence, k_mech_effective]).T


def check_finite(values: np.ndarray, what: str, samples: ContactSamples) -> None:
    """Raise :class:`InvalidParameter` at the first sample where ``values`` (one per sample) is not finite."""
    if not np.all(np.isfinite(values)):
        bad = int(np.flatnonzero(~np.isfinite(values))[0])
        raise InvalidParameter(
            what,
            f"non-finite at sample {bad} (direction {samples.directions[bad]})",
            "finite values at every sample",
            "check the arm's mass matrix and the bounds, or drop singular samples",
        )
