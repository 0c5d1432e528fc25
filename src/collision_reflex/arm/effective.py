"""Effective 1D collision parameters of an arm along many directions at once, and their collision impulses.

The paper's section "Collision Reflex in Higher Dimensions", ``eq:eff_mf`` to ``eq:eff_a``; the documentation's
model page ("The model") for the decisions taken where the paper is ambiguous.

:func:`effective_parameters` maps :class:`ArmSamples` and unit directions ``u`` to ``m_f``, ``m_r``, ``k``,
``k_m``, ``F_a`` and ``a``; :func:`collision_impulses` applies the 1D model of
:mod:`collision_reflex.model.impulse` to them.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np
import numpy.typing as npt

from .. import _validate
from ..errors import InvalidParameter
from ..model import effective as formulas
from ..model.impulse import optimal_velocity, phase_impulses, series_stiffness
from ..model.sensing import sensing_scheme, threshold_force
from .directions import normalised_directions
from .joints import joint_array
from .samples import ArmSamples, task_inverse_inertia

# ---------------------------------------------------------------------- effective parameters
STIFFNESS_FORMS: tuple[str, ...] = ("compliance", "paper")
"""``"compliance"``: ``k = 1 / (u^T J K^-1 J^T u)`` (default, any Jacobian); ``"paper"``: the paper's
``k = u^T J^-T K J^-1 u`` (``eq:eff_k``), square Jacobians only."""


@dataclass(frozen=True)
class EffectiveParameters:
    """The 1D collision parameters along each direction, arrays of one shape.

    The shape is (n_configurations, n_directions) for a grid, (n_samples,) for paired samples.

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
        """The arrays' shape: (n_configurations, n_directions) or (n_samples,)."""
        return tuple(self.m_f.shape)


def effective_parameters(
    samples: ArmSamples,
    directions: npt.ArrayLike,
    reflected_inertia: npt.ArrayLike,
    stiffness: npt.ArrayLike,
    mechanical_stiffness: npt.ArrayLike,
    torque_limit: npt.ArrayLike,
    *,
    config_index: npt.ArrayLike | None = None,
    motor_mass: npt.ArrayLike | None = None,
    finger_joint_inertia: npt.ArrayLike | None = None,
    stiffness_form: str = "compliance",
    joint_threshold: npt.ArrayLike | None = None,
    task_stiffness: npt.ArrayLike | None = None,
    singular_tolerance: float = 1e-12,
) -> EffectiveParameters:
    """Effective 1D collision parameters for many configurations and directions at once.

    The formulas of the paper's "Collision Reflex in Higher Dimensions".

    Parameters
    ----------
    samples: the arm's :class:`ArmSamples` (``Arm.kinematics``).
    directions: unit collision directions, world-aligned (in the arm's plane for a planar arm): (d, task_dim),
        every one applied to every configuration; or, with ``config_index``, (n_samples, task_dim), sample ``s``
        pairing ``directions[s]`` with configuration ``config_index[s]``. Normalised here.
    reflected_inertia: ``N^2 J_m`` per joint [kg m^2], > 0 (scalar or (nv,)).
    stiffness: lumped joint stiffness (mechanical and software in series) [N m/rad], > 0, ``inf`` allowed.
    mechanical_stiffness: joint mechanical stiffness [N m/rad], finite and > 0 (a rigid joint is a very stiff
        one: the two-mass model needs a spring between finger and robot mass).
    torque_limit: largest output torque per joint [N m], > 0, ``inf`` allowed.
    config_index: (n_samples,) configuration of each paired sample; None for the grid.
    motor_mass: motor mass per joint [kg], added to the structure as ``sum_i m_i A_i``; None for none.
    finger_joint_inertia: joint-space inertia per joint [kg m^2], >= 0, that acts rigidly on the link side during the
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
    inertia, joint_k, joint_km, tau_max, tau_s = _joint_arrays(
        nv, reflected_inertia, stiffness, mechanical_stiffness, torque_limit, joint_threshold
    )
    tolerance = _validate.real("singular_tolerance", singular_tolerance, "a number in (0, 1)")
    if tolerance.ndim != 0 or not (np.isfinite(tolerance) and 0 < tolerance < 1):
        raise InvalidParameter("singular_tolerance", singular_tolerance, "a number in (0, 1)")
    units = normalised_directions(directions, task_dim)
    pair_index = None if config_index is None else _checked_index(config_index, units, samples.count)
    if stiffness_form == "paper" and task_dim != nv:
        raise InvalidParameter(
            "stiffness_form",
            stiffness_form,
            f"'compliance' for a {task_dim} x {nv} Jacobian",
            "the paper's J^-T K J^-1 needs a square Jacobian",
        )

    jac = samples.jacobian
    task = _task_matrices(samples, inertia, joint_k, joint_km, motor_mass, finger_joint_inertia)
    forms = _quadratic_forms(task, units, pair_index)
    scale = np.trace(task[0], axis1=1, axis2=2)
    scale_s = scale[:, None] if pair_index is None else scale[pair_index]

    # Reciprocals in place: a zero compliance (an infinite joint stiffness or torque) gives inf; the 0/0 and
    # negative rounding of singular directions are overwritten with their limits below.
    with np.errstate(divide="ignore", invalid="ignore"):
        w_f, w_r, k, k_m = forms
        singular = w_f <= singular_tolerance * scale_s
        m_f = np.reciprocal(w_f, out=w_f)
        load = _reaction_compliance(jac, tau_max, units, pair_index)  # 1 / F_a
        # Singular directions get a = 0 below; with every torque unlimited (1 / F_a = 0) a is unlimited too.
        a = np.where(load > 0, 0.0, np.inf)
        live = ~singular & (load > 0)
        a[live] = formulas.reaction_acceleration(w_r[live], load[live])
        m_r = np.reciprocal(w_r, out=w_r)
        F_a = np.reciprocal(load, out=load)
        if stiffness_form == "paper":
            k = _paper_stiffness(jac, joint_k, units, pair_index)
        else:
            np.reciprocal(k, out=k)
        np.reciprocal(k_m, out=k_m)
        joint_force = None
        if tau_s is not None:
            joint_force = _reaction_compliance(jac, tau_s, units, pair_index)
            np.reciprocal(joint_force, out=joint_force)
    return _with_limits(EffectiveParameters(m_f, m_r, k, k_m, F_a, a, singular, joint_force), task_stiffness)


def _joint_arrays(
    nv: int,
    reflected_inertia: Any,
    stiffness: Any,
    mechanical_stiffness: Any,
    torque_limit: Any,
    joint_threshold: Any,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray | None]:
    """Validated (nv,) arrays of per-joint arguments of :func:`effective_parameters`; threshold or None."""
    return (
        joint_array("reflected_inertia", reflected_inertia, nv),
        joint_array("stiffness", stiffness, nv, allow_inf=True),
        # Finite: a rigid joint would join the finger and the robot mass into one body, which the two-mass
        # collision does not describe (its impact would miss the robot mass).
        joint_array("mechanical_stiffness", mechanical_stiffness, nv),
        joint_array("torque_limit", torque_limit, nv, allow_inf=True),
        None if joint_threshold is None else joint_array("joint_threshold", joint_threshold, nv),
    )


def _task_matrices(
    samples: ArmSamples,
    inertia: np.ndarray,
    joint_k: np.ndarray,
    joint_km: np.ndarray,
    motor_mass: Any,
    finger_joint_inertia: Any,
) -> np.ndarray:
    """Task-space inverse inertias and compliances ``G = J X^-1 J^T``, once per configuration.

    Stacked as (structure, actuators, stiffness, mechanical stiffness), shape (4, n, task_dim, task_dim); the
    quantities along ``u`` are ``1 / (u^T G u)``. ``inertia`` [kg m^2] and the stiffnesses [N m/rad] are per
    joint; ``motor_mass`` [kg] and ``finger_joint_inertia`` [kg m^2] as in :func:`effective_parameters`.
    """
    jac = samples.jacobian
    structure = samples.structure_mass_matrix(motor_mass)
    if finger_joint_inertia is not None:
        finger = joint_array("finger_joint_inertia", finger_joint_inertia, samples.nv, allow_zero=True)
        structure = np.asarray(formulas.finger_mass_matrix(structure, joint_finger_inertia=finger))
    return np.stack(
        [
            task_inverse_inertia(structure, jac),
            formulas.task_compliance(jac, inertia),
            formulas.task_compliance(jac, joint_k),
            formulas.task_compliance(jac, joint_km),
        ]
    )


def _with_limits(params: EffectiveParameters, task_stiffness: Any) -> EffectiveParameters:
    """``params`` with their singular limits, and a task-space spring [N/m] in series with ``k``.

    Singular directions get ``inf`` masses, stiffnesses and forces and ``a = 0`` (in place: the arrays are
    fresh); ``task_stiffness`` (None for none) adds its compliance to ``k`` off the singular directions.
    """
    singular = params.singular
    if np.any(singular):
        for value in (params.m_f, params.m_r, params.k, params.k_m, params.F_a, params.joint_threshold_force):
            if value is not None:
                value[singular] = np.inf
        params.a[singular] = 0.0
    if task_stiffness is None:
        return params
    _validate.positive("task_stiffness", task_stiffness)
    k = np.where(singular, np.inf, series_stiffness(params.k, task_stiffness))
    return replace(params, k=k)


# ---------------------------------------------------------------------- impulses
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
    v0: npt.ArrayLike,
    threshold: npt.ArrayLike | None = None,
    sensing: str = "force",
    reaction: str = "at_rest",
) -> CollisionImpulses:
    """Collision impulses from effective parameters, through :mod:`collision_reflex.model.impulse`.

    Parameters
    ----------
    params: from :func:`effective_parameters`.
    v0: approach velocity [m/s], a scalar or broadcastable to ``params.shape``.
    threshold: ``F_s`` [N] for ``sensing="force"``, the tracking-error threshold [m] for ``"position"``;
        unused for ``"current"`` (the joint-side threshold torques were given to :func:`effective_parameters`
        as ``joint_threshold``, and the first joint to reach its threshold detects).
    sensing: one of :data:`collision_reflex.vocabulary.SENSING_SCHEMES`.
    reaction: ``"at_rest"`` (the paper's) or ``"moving"``, see :func:`collision_reflex.model.phase_impulses`.
    """
    sensing = sensing_scheme(sensing)
    shape = params.shape
    if sensing == "current":
        if params.joint_threshold_force is None:
            raise InvalidParameter(
                "sensing",
                sensing,
                "'force' or 'position' here",
                "pass joint_threshold=... to effective_parameters for motor-current sensing",
            )
        force = params.joint_threshold_force
    else:
        if threshold is None:
            raise InvalidParameter("threshold", None, "a force [N] or a position error [m]")
        _validate.positive("threshold", threshold)
        force = threshold_force(sensing, np.asarray(threshold, dtype=float), params.k)
    _validate.positive("v0", v0)
    singular = params.singular
    any_singular = bool(np.any(singular))

    def stand_in(value: Any) -> Any:
        """Finite stand-ins along singular directions (their results are replaced below).

        So the 1D model sees only valid numbers; scalars pass as they are.
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


def _checked_index(config_index: Any, units: np.ndarray, count: int) -> np.ndarray:
    """The configuration index of paired samples, one per direction, each in ``[0, count)``."""
    allowed = f"whole-number indices in [0, {count}), one per direction"
    if isinstance(config_index, np.ndarray) and config_index.dtype.kind in "iu":
        index = config_index.ravel()
    else:
        raw = _validate.real("config_index", config_index, allowed).ravel()
        if not np.all(np.isfinite(raw) & (raw == np.round(raw)) & (np.abs(raw) <= count)):
            raise InvalidParameter("config_index", config_index, allowed)  # (a fraction was truncated before)
        index = raw.astype(int)
    if index.shape != (units.shape[0],):
        raise InvalidParameter("config_index", index.shape, f"one index per direction, ({units.shape[0]},)")
    if index.size and (index.min() < 0 or index.max() >= count):
        raise InvalidParameter("config_index", index, f"indices in [0, {count})")
    return index


def _quadratic_forms(task: np.ndarray, units: np.ndarray, index: np.ndarray | None) -> np.ndarray:
    """``u^T G u`` of stacked task matrices ``task`` (q, n, m, m).

    For the grid of every configuration with every direction (q, n, d), or for paired samples (q, n_samples).
    """
    if index is not None:
        return np.einsum("sa,qsab,sb->qs", units, task[:, index], units)
    # Every G with every u in one product: (q n, m^2) x (m^2, d).
    q, n, m = task.shape[0], task.shape[1], task.shape[-1]
    outer = np.einsum("da,db->dab", units, units).reshape(units.shape[0], -1)
    return (task.reshape(-1, m * m) @ outer.T).reshape(q, n, -1)


def _reaction_compliance(
    jac: np.ndarray, torque: np.ndarray, units: np.ndarray, index: np.ndarray | None
) -> np.ndarray:
    """``max_i |(J^T u)_i| / torque_i`` [1/N], for the grid (n, d) or for paired samples (n_samples,).

    As :func:`collision_reflex.model.effective.reaction_compliance`.
    """
    # The torque fractions are linear in J^T u: scale the Jacobian's joint columns once, not every moment.
    scaled = formulas.torque_fractions(jac, torque)
    if index is not None:
        return formulas.reaction_compliance(np.einsum("sta,st->sa", scaled[index], units))
    n, nv, d = jac.shape[0], jac.shape[2], units.shape[0]
    out = np.empty((n, d))
    # Blocks of configurations small enough to stay in cache (about 256 kB of fractions each).
    step = max(1, 2**15 // (nv * d))
    directions_t = np.ascontiguousarray(units.T)
    for start in range(0, n, step):
        fractions = np.swapaxes(scaled[start : start + step], 1, 2) @ directions_t  # (block, nv, d)
        out[start : start + step] = formulas.reaction_compliance(fractions, joint_axis=-2)
    return out


def _paper_stiffness(
    jac: np.ndarray, joint_k: np.ndarray, units: np.ndarray, index: np.ndarray | None
) -> np.ndarray:
    """``u^T J^-T K J^-1 u`` (``eq:eff_k``) for square Jacobians [N/m].

    Through the SVD, so that a singular Jacobian gives ``inf`` along its singular direction and the finite
    limit perpendicular to it.
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
