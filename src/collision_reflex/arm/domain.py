"""Where contacts are considered: the contact domain over which a worst case is a number.

Near a singular pose the contact Jacobian ``J_v`` loses rank along a direction, and the finger mass along it,
``1 / (u^T J M^-1 J^T u)``, grows like ``1 / sigma_min(J_v)^2``: over every configuration and every direction
the worst collision impulse is unbounded, and a sampled maximum is only a quantile of a heavy-tailed
distribution. A worst case is therefore taken over a stated domain (the studies guide, "The contact domain"):

- configurations within the joint limits whose contact Jacobian has ``sigma_min(J_v) >= min_singular_value``
  (default a tenth of the arm's reach, the largest base-to-contact distance): arms are not operated at their
  singularities;
- directions ``u`` along which a guarded move at the approach velocity ``v0`` is feasible: the minimum-norm
  joint velocity ``J_v^+ u v0`` stays within every joint's speed limit.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ..errors import InvalidParameter

if TYPE_CHECKING:
    from .robot import Arm

REACH_FRACTION = 0.1
"""Default singular-value floor as a fraction of the arm's reach [-] (the studies guide, "The contact domain")."""

REACH_SAMPLES = 4096
"""Configurations drawn (seeded) to estimate an arm's reach: the largest base-to-contact distance found."""

MIN_KEPT_FRACTION = 0.01
"""Smallest fraction of the joint-limit box a domain may keep before it is refused as (nearly) empty."""

_DRAW_BATCH = 512
"""Configurations drawn at a time when sampling within the domain."""


_REACHES: dict[bytes, float] = {}
"""Reaches from the default seed by :attr:`Arm.fingerprint`: a run sets its study up several times (as written,
as solved, per gearbox option), and each reach is thousands of kinematics evaluations."""


def arm_reach(arm: Arm, rng: np.random.Generator | None = None) -> float:
    """The arm's reach [m]: the largest base-to-contact distance over seeded random configurations.

    The base is the world origin the model is attached to. A sampled maximum is below the true reach by a
    little, so a floor derived from it is on the side of the larger domain. Without ``rng`` (the seed 0), found
    once per arm.
    """
    key = arm.fingerprint if rng is None else None
    if key is not None and key in _REACHES:
        return _REACHES[key]
    q = arm.sample_configurations(REACH_SAMPLES, rng if rng is not None else np.random.default_rng(0))
    positions = arm.kinematics(q).contact_position
    assert positions is not None  # full kinematics
    reach = float(np.linalg.norm(positions, axis=1).max())
    if key is not None:
        if len(_REACHES) >= 32:
            _REACHES.pop(next(iter(_REACHES)))
        _REACHES[key] = reach
    return reach


def smallest_singular_values(jacobian: np.ndarray) -> np.ndarray:
    """``sigma_min(J_v)`` [m] of stacked contact Jacobians (n, task_dim, nv), shape (n,)."""
    return np.asarray(np.linalg.svd(jacobian, compute_uv=False)[..., -1])


def unit_speed_joint_rates(jacobian: np.ndarray, directions: np.ndarray) -> np.ndarray:
    """``J_v^+ u`` [rad/m]: the minimum-norm joint velocity per unit contact speed along ``u``, (n, nv).

    ``jacobian`` (n, task_dim, nv) [m/rad], ``directions`` (n, task_dim) unit vectors.
    """
    return np.asarray(np.einsum("sjd,sd->sj", np.linalg.pinv(jacobian), directions))


@dataclass(frozen=True)
class ContactDomain:
    """Configurations and directions where contacts are considered (the module's description).

    lower, upper: joint limits (nv,) [rad or m], the box configurations are drawn in.
    min_singular_value: floor on ``sigma_min(J_v)`` [m] (0: no floor).
    joint_speed_limit: (nv,) [rad/s or m/s]; ``inf`` where a joint has none.
    reach: the arm's reach [m] the default floor was taken from (for reports).
    """

    lower: np.ndarray
    upper: np.ndarray
    min_singular_value: float
    joint_speed_limit: np.ndarray
    reach: float

    def __post_init__(self) -> None:
        lower, upper = (np.asarray(v, dtype=float) for v in (self.lower, self.upper))
        limits = np.asarray(self.joint_speed_limit, dtype=float)
        if lower.shape != upper.shape or lower.ndim != 1 or not np.all(lower < upper):
            raise InvalidParameter("joint limits", (lower, upper), "lower < upper for every joint")
        if limits.shape != lower.shape or not np.all(limits > 0) or np.any(np.isnan(limits)):
            raise InvalidParameter(
                "joint_speed_limit", limits, f"{lower.size} positive speed limits (inf: none) [rad/s]"
            )
        if not (np.isfinite(self.min_singular_value) and self.min_singular_value >= 0):
            raise InvalidParameter("min_singular_value", self.min_singular_value, "a length >= 0 [m]")
        object.__setattr__(self, "lower", lower)
        object.__setattr__(self, "upper", upper)
        object.__setattr__(self, "joint_speed_limit", limits)

    @classmethod
    def of_arm(
        cls,
        arm: Arm,
        min_singular_value: float | None = None,
        joint_speed_limit: np.ndarray | None = None,
    ) -> ContactDomain:
        """The default domain of ``arm``: floor ``REACH_FRACTION`` x reach, the URDF's joint speed limits.

        ``min_singular_value`` [m] and ``joint_speed_limit`` (nv,) [rad/s] replace the defaults.
        """
        reach = arm_reach(arm)
        floor = REACH_FRACTION * reach if min_singular_value is None else float(min_singular_value)
        limits = arm.joint_speed_limit if joint_speed_limit is None else np.asarray(joint_speed_limit, float)
        lower, upper = arm.joint_limits()
        return cls(lower, upper, floor, limits, reach)

    @property
    def nv(self) -> int:
        """Number of joints."""
        return int(self.lower.size)

    def configuration_margin(self, jacobian: np.ndarray) -> np.ndarray:
        """``sigma_min(J_v) / floor - 1`` per configuration (>= 0 inside; ``inf`` without a floor), (n,)."""
        sigma = smallest_singular_values(jacobian)
        if self.min_singular_value == 0:
            return np.full(sigma.shape, np.inf)
        return np.asarray(sigma / self.min_singular_value - 1)

    def speed_margin(self, jacobian: np.ndarray, directions: np.ndarray, velocity: float) -> np.ndarray:
        """``1 - v0 |J_v^+ u|_i / qdot_max,i`` per sample and joint (>= 0 inside), (n, nv).

        ``velocity``: the approach velocity ``v0`` [m/s].
        """
        rates = np.abs(unit_speed_joint_rates(jacobian, directions)) * velocity
        return np.asarray(1 - rates / self.joint_speed_limit)

    def speed_caps(self, jacobian: np.ndarray, directions: np.ndarray) -> np.ndarray:
        """The fastest approach [m/s] along each direction within the joint speed limits, (n,) (inf: none)."""
        rates = np.abs(unit_speed_joint_rates(jacobian, directions)) / self.joint_speed_limit
        with np.errstate(divide="ignore"):
            return np.asarray(1 / rates.max(axis=1))

    def direction_speed_caps(self, jacobian: np.ndarray, directions: np.ndarray) -> np.ndarray:
        """:meth:`speed_caps` of every direction (m, task_dim) at every configuration (n, task_dim, nv), (n, m).

        One pseudo-inverse per configuration, however many directions.
        """
        rates = (
            np.abs(np.einsum("cjd,md->cmj", np.linalg.pinv(jacobian), directions)) / self.joint_speed_limit
        )
        with np.errstate(divide="ignore"):
            return np.asarray(1 / rates.max(axis=2))

    def contains(self, jacobian: np.ndarray, directions: np.ndarray, velocity: float) -> np.ndarray:
        """Whether each sample (a configuration's Jacobian with a direction) lies in the domain, (n,) bool."""
        inside_configuration = self.configuration_margin(jacobian) >= 0
        inside_speed = np.all(self.speed_margin(jacobian, directions, velocity) >= 0, axis=1)
        return np.asarray(inside_configuration & inside_speed)

    def draw(
        self, arm: Arm, count: int, directions: np.ndarray, velocity: float, rng: np.random.Generator
    ) -> DomainDraw:
        """``count`` configurations drawn uniformly in the domain, each with the ``directions`` feasible there.

        Configurations are drawn uniformly in the joint-limit box and kept when ``sigma_min(J_v)`` meets the
        floor and at least one of ``directions`` (m, task_dim) is feasible at ``velocity`` [m/s] (rejection
        sampling). The draw also measures how much of the box the domain keeps.

        Raises
        ------
        DomainTooSmall: the domain keeps under :data:`MIN_KEPT_FRACTION` of the box (drawn samples).
        """
        directions = np.atleast_2d(np.asarray(directions, dtype=float))
        m = directions.shape[0]
        kept_q: list[np.ndarray] = []
        kept_caps: list[np.ndarray] = []
        drawn = drawn_pairs = inside_configurations = inside_pairs = 0
        most = int(np.ceil(count / MIN_KEPT_FRACTION)) + _DRAW_BATCH
        while len(kept_q) < count:
            if drawn >= most:
                raise DomainTooSmall(self, drawn, inside_configurations, drawn_pairs, inside_pairs, velocity)
            q = arm.sample_configurations(_DRAW_BATCH, rng)
            jacobian = arm.kinematics(q, full=False).jacobian
            drawn += q.shape[0]
            good = self.configuration_margin(jacobian) >= 0
            inside_configurations += int(good.sum())
            caps = np.zeros((q.shape[0], m))
            if np.any(good):
                caps[good] = self.direction_speed_caps(jacobian[good], directions)
            pairs = caps >= velocity
            drawn_pairs += q.shape[0] * m
            inside_pairs += int(pairs.sum())
            for s in np.flatnonzero(pairs.any(axis=1)):
                if len(kept_q) < count:
                    kept_q.append(q[s])
                    kept_caps.append(caps[s])
        if inside_pairs < MIN_KEPT_FRACTION * drawn_pairs:
            raise DomainTooSmall(self, drawn, inside_configurations, drawn_pairs, inside_pairs, velocity)
        return DomainDraw(
            np.array(kept_q),
            np.array(kept_caps),
            velocity,
            inside_configurations / drawn,
            inside_pairs / drawn_pairs,
        )

    def to_json(self) -> dict[str, object]:
        """The domain as JSON types (``designs.json``: ``domain``)."""
        return {
            "min_singular_value": self.min_singular_value,
            "reach": self.reach,
            "joint_speed_limit": [None if not np.isfinite(v) else float(v) for v in self.joint_speed_limit],
            "joint_lower": self.lower.tolist(),
            "joint_upper": self.upper.tolist(),
        }


@dataclass(frozen=True)
class DomainDraw:
    """Configurations drawn in a domain and which directions are feasible at each.

    q: (count, nq) configurations [rad]; speed_cap: (count, m) the fastest approach [m/s] along each direction
    within the joint speed limits (:meth:`ContactDomain.speed_caps`); velocity: the approach [m/s] they were
    drawn for; configurations_kept: fraction of the drawn configurations that meet the singular-value floor;
    samples_kept: fraction of the drawn (configuration, direction) pairs inside the domain.
    """

    q: np.ndarray
    speed_cap: np.ndarray
    velocity: float
    configurations_kept: float
    samples_kept: float

    @property
    def feasible(self) -> np.ndarray:
        """(count, m) bool: direction ``j`` feasible at configuration ``i`` at the drawn velocity."""
        return np.asarray(self.speed_cap >= self.velocity)


class DomainTooSmall(InvalidParameter):
    """A contact domain that keeps (almost) nothing of the joint-limit box."""

    def __init__(
        self,
        domain: ContactDomain,
        drawn: int,
        inside_configurations: int,
        drawn_pairs: int,
        inside_pairs: int,
        velocity: float,
    ) -> None:
        self.samples_kept = inside_pairs / max(drawn_pairs, 1)
        self.configurations_kept = inside_configurations / max(drawn, 1)
        if self.configurations_kept < MIN_KEPT_FRACTION:
            cause = (
                f"{self.configurations_kept:.2%} of {drawn} configurations drawn within the joint limits have "
                f"sigma_min(J) >= {domain.min_singular_value:.4g} m"
            )
            hint = "lower samples.domain.min_singular_value"
        else:
            cause = (
                f"{self.samples_kept:.2%} of the {drawn_pairs} (configuration, direction) pairs drawn can be "
                f"approached at {velocity:.4g} m/s within the joint speed limits"
            )
            hint = "lower the approach velocity (its upper bound) or raise samples.domain.joint_speed_limit"
        self.hint = hint
        super().__init__(
            "samples.domain",
            cause,
            f"a contact domain keeping at least {MIN_KEPT_FRACTION:.0%} of the joint-limit box",
            hint,
        )
