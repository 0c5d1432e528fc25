"""A certified worst case: an adversarial search of the contact domain for the largest impulse of a design.

A sampled maximum is a lower bound on the worst case over the domain
(:class:`collision_reflex.arm.domain.ContactDomain`). The search maximises the impulse of one design over the
configuration and the contact direction, continuously, from several starts (the worst samples and random
points of the domain), subject to the domain's constraints: joint limits as bounds, the singular-value floor
and the joint speed limits of the guarded move as inequality rows. The configuration dependence is Pinocchio's
(numeric), so the gradient is a forward difference, every start's stencil evaluated as one batch through the
NumPy path (:func:`collision_reflex.optimize.evaluate.sample_impulses`). The largest impulse at any point of
the domain the search visited is the result, with where it occurs.

The exchange method for semi-infinite programs then adds the violators to the sample set and solves again
(:func:`collision_reflex.study.arm_results` drives it for studies), until no search finds an impulse above the
reported worst case by more than its tolerance.
"""

from __future__ import annotations

import threading
import time
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ..arm.directions import sphere_directions
from ..errors import InvalidParameter
from .blas import single_threaded_blas
from .evaluate import sample_impulses
from .samples import ContactSamples, loaded_joints

if TYPE_CHECKING:
    from ..arm import Arm, ArmSamples
    from ..arm.domain import ContactDomain
    from .design import Design
    from .technology import ActuatorTechnology

SEARCH_TOLERANCE = 0.005
"""Relative amount by which a searched impulse may exceed the reported worst case before it counts as a
violator (the exchange method's stopping rule)."""

FD_STEP = 1e-6
"""Forward-difference step of the search's gradient [rad, and rad on the direction's angles]."""

_INSIDE = -1e-9
"""Smallest domain margin (relative) of a point the search counts as inside the domain."""


@dataclass(frozen=True)
class WorstCase:
    """The largest impulse the search found for a design, where, and at what cost.

    impulse: the largest impulse at a point of the domain [N*s]; q (nq,) and direction (task_dim,): where.
    maxima_q (k, nq), maxima_directions (k, task_dim), maxima_impulse (k,): each start's best point in the
        domain, largest first (the candidates to add to a sample set).
    starts: local searches run; evaluations: impulses evaluated; elapsed: wall time [s].
    domain_kept: the fraction of the joint-limit box's (configuration, direction) pairs in the design's domain,
        as the random starts' draw measured it (None without random starts).
    """

    impulse: float
    q: np.ndarray
    direction: np.ndarray
    maxima_q: np.ndarray
    maxima_directions: np.ndarray
    maxima_impulse: np.ndarray
    starts: int
    evaluations: int
    elapsed: float
    domain_kept: float | None = None

    def violators(self, level: float, tolerance: float = SEARCH_TOLERANCE) -> np.ndarray:
        """Indices of the maxima above ``level`` [N*s] by more than the relative ``tolerance``."""
        return np.flatnonzero(self.maxima_impulse > level * (1 + tolerance))

    def to_json(self) -> dict[str, object]:
        """The search's result as JSON types."""
        return {
            "impulse": self.impulse,
            "q": self.q.tolist(),
            "direction": self.direction.tolist(),
            "starts": self.starts,
            "evaluations": self.evaluations,
            "search_time": self.elapsed,
            "domain_kept": self.domain_kept,
        }


class _Objective:
    """Impulse and domain margins of points ``z = (joint coordinates, direction angles)`` of several starts.

    Start ``k``'s angles are taken about its own direction (``bases[k]``, far from the angles' poles); the best
    point inside the domain each start reaches is kept.
    """

    def __init__(
        self,
        arm: Arm,
        domain: ContactDomain,
        technology: ActuatorTechnology,
        design: Design,
        bases: list[np.ndarray],
    ) -> None:
        self.arm, self.domain, self.technology, self.design = arm, domain, technology, design
        self.bases = bases
        self.nv = domain.nv
        self.speed_rows = np.flatnonzero(np.isfinite(domain.joint_speed_limit))
        self.evaluations = 0
        self.best: list[tuple[float, np.ndarray, np.ndarray]] = [(-np.inf, np.empty(0), np.empty(0))] * len(
            bases
        )

    def directions(self, angles: np.ndarray, owner: np.ndarray) -> np.ndarray:
        """Unit directions (m, task_dim) from angles (m, task_dim - 1) about each point's start direction."""
        if angles.shape[1] == 1:
            local = np.column_stack([np.cos(angles[:, 0]), np.sin(angles[:, 0])])
        else:
            a, b = angles[:, 0], angles[:, 1]
            local = np.column_stack([np.cos(b) * np.cos(a), np.cos(b) * np.sin(a), np.sin(b)])
        bases = np.stack(self.bases)[owner]  # (m, task_dim, task_dim)
        return np.asarray(np.einsum("sd,sde->se", local, bases))

    def __call__(self, z: np.ndarray, owner: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Impulses (m,) [N*s] and margins (m, rows) (>= 0 inside the domain) at points of several starts.

        ``z`` (m, nz) are the points, ``owner`` (m,) the start each belongs to.
        """
        q = self.arm.configuration(z[:, : self.nv])
        u = self.directions(z[:, self.nv :], owner)
        kinematics = self.arm.kinematics(q)
        impulses = self._impulses(kinematics, u)
        jacobian = kinematics.jacobian
        margins = [self.domain.speed_margin(jacobian, u, self.design.approach_velocity)[:, self.speed_rows]]
        if self.domain.min_singular_value > 0:
            margins.insert(0, self.domain.configuration_margin(jacobian)[:, None])
        margin = np.concatenate(margins, axis=1)
        self.evaluations += q.shape[0]
        inside = np.all(margin >= _INSIDE, axis=1) & np.isfinite(impulses)
        for k in np.unique(owner[inside]):
            mine = np.flatnonzero(inside & (owner == k))
            s = int(mine[np.argmax(impulses[mine])])
            if impulses[s] > self.best[k][0]:
                self.best[k] = (float(impulses[s]), q[s].copy(), u[s].copy())
        return impulses, margin

    def _impulses(self, kinematics: ArmSamples, u: np.ndarray) -> np.ndarray:
        """Impulses [N*s] along ``u`` at each configuration; ``inf`` where the model is undefined there.

        That is where the arm cannot move along ``u``: a point the search's stencil or line search tried
        beyond the domain.
        """
        out = np.full(u.shape[0], np.inf)
        index = np.arange(u.shape[0])
        movable = np.any(loaded_joints(ContactSamples(kinematics, u, index)), axis=1)
        for part in (index[movable],) if np.any(movable) else ():
            try:
                with np.errstate(all="ignore"):
                    out[part] = sample_impulses(
                        ContactSamples(kinematics, u[part], part), self.technology, self.design
                    )
            except InvalidParameter:  # a point where a parameter leaves the model's range: one by one
                for s in part:
                    try:
                        out[s] = sample_impulses(
                            ContactSamples(kinematics, u[s : s + 1], index[s : s + 1]),
                            self.technology,
                            self.design,
                        )[0]
                    except InvalidParameter:
                        out[s] = np.inf
        return np.where(np.isfinite(out), out, np.inf)


class _Stopped(Exception):
    """Raised in a local search's thread when the search is abandoned (an error or Ctrl-C elsewhere)."""


class _Lockstep:
    """Several local searches, each in a thread, whose stencils are evaluated together as one batch.

    A local search is sequential (SLSQP asks for one point at a time), but an evaluation costs mostly per call,
    not per point: so each search runs in its own thread and waits at :meth:`stencil`, and the calling thread
    (:meth:`serve`) evaluates the stencils of all waiting searches in one call once every running search waits.
    """

    def __init__(self, objective: _Objective, count: int) -> None:
        self.objective = objective
        self.condition = threading.Condition()
        self.waiting: dict[int, np.ndarray] = {}
        self.answers: dict[int, tuple[np.ndarray, np.ndarray]] = {}
        self.running = count
        self.stopped = False

    def stencil(self, owner: int, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The impulses and margins at ``points`` of search ``owner`` (called in its thread)."""
        with self.condition:
            self.waiting[owner] = points
            self.condition.notify_all()
            while owner not in self.answers:
                if self.stopped:
                    raise _Stopped
                self.condition.wait()
            return self.answers.pop(owner)

    def finished(self) -> None:
        """A search's thread is done (it asks for no more points)."""
        with self.condition:
            self.running -= 1
            self.condition.notify_all()

    def serve(self) -> None:
        """Evaluate the waiting searches' stencils in batches until every search has finished."""
        try:
            while True:
                with self.condition:
                    while self.running and len(self.waiting) < self.running:
                        self.condition.wait(0.05)  # a timeout, so that a Ctrl-C here is seen
                    if not self.running:
                        return
                    batch, self.waiting = self.waiting, {}
                owners = sorted(batch)
                points = np.vstack([batch[k] for k in owners])
                owner = np.repeat(owners, [batch[k].shape[0] for k in owners])
                impulses, margins = self.objective(points, owner)
                with self.condition:
                    for k in owners:
                        self.answers[k] = (impulses[owner == k], margins[owner == k])
                    self.condition.notify_all()
        except BaseException:
            with self.condition:
                self.stopped = True
                self.condition.notify_all()
            raise


def _basis(direction: np.ndarray) -> np.ndarray:
    """An orthonormal basis whose first row is ``direction`` (unit)."""
    if direction.size == 2:
        return np.array([direction, [-direction[1], direction[0]]])
    helper = np.eye(3)[int(np.argmin(np.abs(direction)))]
    second = np.cross(direction, helper)
    second /= np.linalg.norm(second)
    return np.array([direction, second, np.cross(direction, second)])


def _local_search(
    lockstep: _Lockstep,
    owner: int,
    theta: np.ndarray,
    bounds: list[tuple[float, float]],
    scale: float,
    max_iter: int,
    constrained: bool,
) -> None:
    """Maximise the impulse from ``theta`` (joint coordinates, the direction at angle zero) with SLSQP.

    Runs in its own thread; every stencil (the point and its forward differences) goes through ``lockstep``.
    """
    from scipy.optimize import minimize  # lazy: scipy

    nz = len(bounds)
    cache: dict[bytes, tuple[float, np.ndarray, np.ndarray, np.ndarray]] = {}

    def evaluated(z: np.ndarray) -> tuple[float, np.ndarray, np.ndarray, np.ndarray]:
        key = z.tobytes()
        if key not in cache:
            impulses, margins = lockstep.stencil(owner, np.vstack([z, z + FD_STEP * np.eye(nz)]))
            value = -impulses[0] / scale
            with np.errstate(invalid="ignore"):  # inf - inf where the model is undefined: caught below
                gradient = -(impulses[1:] - impulses[0]) / scale / FD_STEP
            rows = margins[0]
            jacobian = ((margins[1:] - margins[0]) / FD_STEP).T
            if not (np.isfinite(value) and np.all(np.isfinite(gradient))):
                value, gradient = 0.0, np.zeros(nz)  # outside where the model is defined: stop here
            cache.clear()
            cache[key] = (value, gradient, rows, jacobian)
        return cache[key]

    constraints = (
        [{"type": "ineq", "fun": lambda z: evaluated(z)[2], "jac": lambda z: evaluated(z)[3]}]
        if constrained
        else []
    )
    try:
        minimize(
            lambda z: evaluated(z)[0],
            np.concatenate([theta, np.zeros(nz - theta.size)]),
            jac=lambda z: evaluated(z)[1],
            bounds=bounds,
            constraints=constraints,
            method="SLSQP",
            options={"maxiter": max_iter, "ftol": 1e-6},
        )
    except _Stopped:
        pass
    finally:
        lockstep.finished()


def search_worst_case(
    arm: Arm,
    domain: ContactDomain,
    technology: ActuatorTechnology,
    design: Design,
    start_q: np.ndarray,
    start_directions: np.ndarray,
    random_starts: int = 6,
    rng: np.random.Generator | None = None,
    max_iter: int = 30,
) -> WorstCase:
    """The largest collision impulse of ``design`` over ``domain``, by local searches from several starts.

    Parameters
    ----------
    arm, technology, design: the arm, its actuator technology and the design (as solved).
    domain: where contacts are considered; the guarded move is checked at the design's approach velocity.
    start_q (k, nq), start_directions (k, task_dim): starts, e.g. the worst samples of a solve.
    random_starts: further starts drawn in the domain by ``rng`` (default ``numpy.random.default_rng(0)``).
    max_iter: SLSQP iterations per start.

    Raises
    ------
    InvalidParameter: no start, or starts of the wrong shape.
    """
    import scipy.optimize  # noqa: F401  # loaded (with its BLAS) before the BLAS is limited to one thread

    # Every BLAS on one thread, SciPy's too: a threaded BLAS sums in another order, and SLSQP's path (so the
    # maximum found) would depend on whether SciPy's BLAS was loaded before a caller limited the threads.
    with single_threaded_blas():
        started = time.perf_counter()
        start_q, start_directions, kept = _starts(
            arm, domain, design.approach_velocity, start_q, start_directions, random_starts, rng
        )
        task_dim = int(arm.task_dim)
        theta_starts = np.clip(arm.joint_coordinates(start_q), domain.lower, domain.upper)
        joint_bounds = list(zip(domain.lower, domain.upper, strict=True))
        angle_bounds = [(-np.pi, np.pi)] if task_dim == 2 else [(-np.pi, np.pi), (-1.55, 1.55)]
        bases = [_basis(d / np.linalg.norm(d)) for d in start_directions]
        objective = _Objective(arm, domain, technology, design, bases)
        owners = np.arange(len(bases))
        first, _ = objective(np.hstack([theta_starts, np.zeros((len(bases), task_dim - 1))]), owners)
        scales = np.where(np.isfinite(first) & (first > 0), first, 1.0)
        lockstep = _Lockstep(objective, len(bases))
        constrained = bool(objective.speed_rows.size) or domain.min_singular_value > 0
        threads = [
            threading.Thread(
                target=_local_search,
                args=(
                    lockstep,
                    k,
                    theta_starts[k],
                    joint_bounds + angle_bounds,
                    scales[k],
                    max_iter,
                    constrained,
                ),
                daemon=True,
            )
            for k in owners
        ]
        for thread in threads:
            thread.start()
        try:
            lockstep.serve()
        finally:
            for thread in threads:
                thread.join()
        maxima = [best for best in objective.best if np.isfinite(best[0])]
        maxima.sort(key=lambda m: -m[0])
        if not maxima:
            raise InvalidParameter(
                "starts", start_q.shape[0], "starts from which the search reaches the domain"
            )
        return WorstCase(
            impulse=maxima[0][0],
            q=maxima[0][1],
            direction=maxima[0][2],
            maxima_q=np.array([m[1] for m in maxima]),
            maxima_directions=np.array([m[2] for m in maxima]),
            maxima_impulse=np.array([m[0] for m in maxima]),
            starts=len(theta_starts),
            evaluations=objective.evaluations,
            elapsed=time.perf_counter() - started,
            domain_kept=kept,
        )


def _starts(
    arm: Arm,
    domain: ContactDomain,
    velocity: float,
    start_q: np.ndarray,
    start_directions: np.ndarray,
    random_starts: int,
    rng: np.random.Generator | None,
) -> tuple[np.ndarray, np.ndarray, float | None]:
    """The search's starts, ``random_starts`` of them drawn in ``domain`` at ``velocity``, and the share kept."""
    generator = rng if rng is not None else np.random.default_rng(0)
    start_q = np.atleast_2d(np.asarray(start_q, dtype=float))
    start_directions = np.atleast_2d(np.asarray(start_directions, dtype=float))
    task_dim = int(arm.task_dim)
    kept = None
    if random_starts:
        pool = (
            sphere_directions(32)
            if task_dim == 3
            else np.column_stack([np.cos(a := np.linspace(0, 2 * np.pi, 16, endpoint=False)), np.sin(a)])
        )
        draw = domain.draw(arm, random_starts, pool, velocity, generator)
        picks = [pool[generator.choice(np.flatnonzero(row))] for row in draw.feasible]
        kept = draw.samples_kept
        start_q = np.vstack([start_q, draw.q]) if start_q.size else draw.q
        start_directions = np.vstack([start_directions, picks]) if start_directions.size else np.array(picks)
    if start_q.shape[0] == 0 or start_directions.shape != (start_q.shape[0], task_dim):
        raise InvalidParameter(
            "starts",
            (start_q.shape, start_directions.shape),
            f"k configurations and k directions of {task_dim}",
        )
    return start_q, start_directions, kept
