"""The configuration space of an arm: joint limits, joint coordinates and Pinocchio configurations.

A configuration ``q`` (nq,) is Pinocchio's: an unbounded revolute joint is stored as cosine and sine, so
``nq`` may exceed the number of joints ``nv``. Joint coordinates (nv,) are angles [rad] or displacements [m].
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from .. import _validate
from ..errors import InvalidParameter
from .kinematic_tree import JointKinematics

# Joints whose limits are missing or meaningless (URDF "continuous", or lower >= upper) are sampled on a full
# turn; limits beyond this magnitude are treated as missing.
_UNBOUNDED_LIMIT = 1e3


MAX_CONFIGURATIONS = 10_000_000
"""Most configurations drawn at once: ten million (n, nq) rows are already gigabytes of kinematics."""


@dataclass(frozen=True)
class ConfigurationSpace:
    """The joints of an arm as coordinates: their limits, and the map to and from configurations.

    Attributes
    ----------
    joints: the joint tree (:func:`collision_reflex.arm.kinematic_tree.joint_kinematics`).
    joint_names: one name per joint, for messages.
    lower_position_limit, upper_position_limit: the model's limits per configuration entry (nq,) [rad or m].
    """

    joints: Sequence[JointKinematics]
    joint_names: tuple[str, ...]
    lower_position_limit: np.ndarray
    upper_position_limit: np.ndarray

    @property
    def nq(self) -> int:
        """Size of a configuration vector (an unbounded revolute joint counts twice: cosine and sine)."""
        return int(self.lower_position_limit.size)

    @property
    def nv(self) -> int:
        """Number of joints (degrees of freedom)."""
        return len(self.joints)

    def joint_limits(self) -> tuple[np.ndarray, np.ndarray]:
        """Lower and upper limit per joint [rad or m], (nv,) each; a full turn where the URDF gives none."""
        lower = np.empty(self.nv)
        upper = np.empty(self.nv)
        for v, joint in enumerate(self.joints):
            if joint.nq == 1:
                lo, hi = self.lower_position_limit[joint.idx_q], self.upper_position_limit[joint.idx_q]
            else:
                lo, hi = np.nan, np.nan
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

    def configuration(self, angles: npt.ArrayLike) -> np.ndarray:
        """Configurations (..., nq) from joint coordinates (..., nv) [rad or m]."""
        angles = _validate.real("angles", angles, "real joint coordinates [rad, m]")
        if angles.shape[-1:] != (self.nv,):
            raise InvalidParameter("angles", angles.shape, f"a last axis of {self.nv} joint coordinates")
        if not np.all(np.isfinite(angles)):
            raise InvalidParameter("angles", angles, "finite joint coordinates [rad, m]")
        q = np.empty((*angles.shape[:-1], self.nq))
        for v, joint in enumerate(self.joints):
            if joint.nq == 1:
                q[..., joint.idx_q] = angles[..., v]
            else:
                q[..., joint.idx_q] = np.cos(angles[..., v])
                q[..., joint.idx_q + 1] = np.sin(angles[..., v])
        return q

    def joint_coordinates(self, q: npt.ArrayLike) -> np.ndarray:
        """Joint angles or displacements (n, nv) [rad or m] of configurations (n, nq) or (nq,)."""
        q = self.checked(q)
        out = np.empty((q.shape[0], self.nv))
        for v, joint in enumerate(self.joints):
            if joint.nq == 1:
                out[:, v] = q[:, joint.idx_q]
            else:
                out[:, v] = np.arctan2(q[:, joint.idx_q + 1], q[:, joint.idx_q])
        return out

    def sample(self, count: int, rng: np.random.Generator) -> np.ndarray:
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
        count = _validate.integer("count", count, 1, MAX_CONFIGURATIONS)
        lower, upper = self.joint_limits()
        return self.configuration(rng.uniform(lower, upper, size=(int(count), self.nv)))

    def checked(self, q: npt.ArrayLike) -> np.ndarray:
        """Configurations ``q`` as a finite (n, nq) array [rad, m]; a single (nq,) one becomes (1, nq)."""
        q = np.atleast_2d(_validate.real("q", q, "real joint coordinates [rad, m]"))
        if q.ndim != 2 or q.shape[1] != self.nq:
            raise InvalidParameter("q", q.shape, f"configurations of shape (n, {self.nq})")
        if not np.all(np.isfinite(q)):
            raise InvalidParameter("q", q, "finite joint coordinates")
        return q
