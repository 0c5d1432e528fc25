"""A study held to a body region's permissible speed: the poses its samples missed, found and added.

The optimiser's rows hold the approach within the region's permissible speed at the study's samples only; between
them the arm's effective mass can be larger (near-singular poses, directions along a heavy link). After each round
of solves, a search draw of :data:`SEARCH_CONFIGURATIONS` configurations in the contact domain (an independent
stream of the study's seed, each with the study's directions feasible there) is evaluated for every design, the
robot mass with its rotors on the links as the rows take it, along the study's directions and along each pose's
heaviest direction (an eigenvector of the operational-space inertia); the poses where a design's approach exceeds the
permissible speed join the samples (the :data:`ADDED_PER_DESIGN` slowest per design, distinct configurations) and
the next round solves on them, as the worst case's violators do (:mod:`.worst_case`). What the last draw finds is
kept in the run's record; the fresh configurations (:mod:`.fresh`) check the recommended design independently.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ..model.contact import permissible_speed
from ..model.effective import task_inverse_inertia
from ..optimize.body_region import coupled_mass_matrix, region_speeds
from ..optimize.samples import ContactSamples
from .arm_setup import ArmSetup, ExtraSamples

if TYPE_CHECKING:
    from ..arm.domain import DomainDraw
    from ..arm.samples import ArmSamples
    from ..optimize import Design

SEARCH_STREAM = 0x5AFE
"""Spawn key of the search draw's generator under the study's seed, apart from the samples' and the fresh ones'."""

SEARCH_CONFIGURATIONS = 4096
"""Configurations the search draws: the slowest pose of 4,096 is within the slowest 0.07 % of the domain with
95 % confidence (``1 - 0.9993^4096``), whatever the arm."""

ADDED_PER_DESIGN = 8
"""Most poses a design adds to the samples per round: its slowest, at distinct configurations."""

REFINED = 4
"""Slowest configurations of the draw climbed locally per design and round (:func:`_refined_pose`)."""


@dataclass(frozen=True)
class RegionSearch:
    """What the search draw says of one design against the study's body region.

    samples: the (configuration, direction) pairs of the draw inside the design's domain; slowest: the least
    permissible speed among them [m/s]; below: how many are below the design's approach velocity; added: the
    poses that join the samples, as :data:`~.arm_setup.ExtraSamples`; robot_mass and link_mass [kg]: at the
    slowest pose, the design's coupled effective mass and the links' own (no actuator on them) along its
    direction; links_speed [m/s]: the permissible speed there with the links' mass alone, which no actuators
    could exceed.
    """

    samples: int
    slowest: float
    below: int
    added: ExtraSamples
    robot_mass: float
    link_mass: float
    links_speed: float


def search_draw(setup: ArmSetup) -> DomainDraw | None:
    """The search's configurations in the contact domain, or None without random configurations to seed it."""
    random = setup.study.samples.configurations.random
    if random is None or setup.constraints.body_region is None:
        return None
    rng = np.random.default_rng(np.random.SeedSequence(random.seed, spawn_key=(SEARCH_STREAM,)))
    slowest = float(setup.space.global_bounds("approach_velocity").lower)
    return setup.domain.draw(setup.arm, SEARCH_CONFIGURATIONS, setup.directions, slowest, rng)


def search_region(
    setup: ArmSetup, draw: DomainDraw, designs: Mapping[str, Design], tolerance: float, refine: bool = True
) -> dict[str, RegionSearch]:
    """Each design's permissible speeds over ``draw`` (inside its domain), and the poses it adds.

    At each configuration the study's directions feasible there are checked, and the direction of the design's
    largest coupled effective mass (:func:`heaviest_directions`) where it lies in the design's domain. With
    ``refine``, the :data:`REFINED` slowest configurations are then climbed locally toward a larger mass
    (:func:`_refined_pose`): random draws miss the narrow tail near the domain's edge. A pose is added where the
    design's approach exceeds its permissible speed by more than ``tolerance`` (relative).
    """
    region = setup.constraints.body_region
    assert region is not None
    config_index, direction_index = np.nonzero(draw.feasible)
    kinematics = setup.arm.kinematics(draw.q)
    found = {}
    for label, design in designs.items():
        coupled = _coupled_matrix(kinematics, design)
        heaviest = heaviest_directions(kinematics, coupled)
        caps = setup.domain.speed_caps(kinematics.jacobian, heaviest)
        samples = ContactSamples(
            kinematics,
            np.vstack([setup.directions[direction_index], heaviest]),
            np.concatenate([config_index, np.arange(draw.q.shape[0])]),
            speed_cap=np.concatenate([draw.speed_cap[config_index, direction_index], caps]),
        )
        inside = np.flatnonzero(samples.inside(design.approach_velocity))
        kept = ContactSamples(kinematics, samples.directions[inside], samples.config_index[inside])
        speeds = region_speeds(kept, design, region)
        # Per row: its configuration's id (the draw's index, refined poses after them) and direction.
        configs, directions, joints = kept.config_index, kept.directions, kinematics.q
        refined = _refined_poses(setup, design, joints, configs, speeds) if refine else None
        if refined is not None:
            q, u, refined_speeds = refined
            configs = np.concatenate([configs, joints.shape[0] + np.arange(q.shape[0])])
            directions = np.vstack([directions, u])
            # Unit rows to the last digit, as a ContactSamples holds its directions.
            directions /= np.linalg.norm(directions, axis=1)[:, None]
            speeds = np.concatenate([speeds, refined_speeds])
            joints = np.vstack([joints, q])
        below = np.flatnonzero(design.approach_velocity > speeds * (1 + tolerance))
        added: list[tuple[tuple[float, ...], tuple[float, ...]]] = []
        seen: set[int] = set()
        for row in below[np.argsort(speeds[below])]:
            config = int(configs[row])
            if config not in seen and len(added) < ADDED_PER_DESIGN:
                seen.add(config)
                added.append((tuple(map(float, joints[config])), tuple(map(float, directions[row]))))
        slowest = int(np.argmin(speeds))
        pose = setup.arm.kinematics(joints[configs[slowest]][None, :])
        direction = directions[slowest]
        masses = [
            effective_mass(pose, 0, direction, matrix[0])
            for matrix in (pose.mass_matrix, _coupled_matrix(pose, design))
        ]
        assert region.transient_force is not None
        found[label] = RegionSearch(
            int(inside.size),
            float(speeds[slowest]),
            int(below.size),
            tuple(added),
            robot_mass=masses[1],
            link_mass=masses[0],
            links_speed=float(
                permissible_speed(region.transient_force, masses[0], region.stiffness, region.mass)
            ),
        )
    return found


def effective_mass(kinematics: ArmSamples, config: int, direction: np.ndarray, matrix: np.ndarray) -> float:
    """``1 / (u^T J A^-1 J^T u)`` [kg] at configuration ``config`` along ``direction`` for the mass matrix ``A``."""
    arm = kinematics.jacobian[config].T @ direction
    return float(1 / (arm @ np.linalg.solve(matrix, arm)))


def _coupled_matrix(kinematics: ArmSamples, design: Design) -> np.ndarray:
    """:func:`~..optimize.body_region.coupled_mass_matrix` at every configuration of ``kinematics``."""
    assert kinematics.motor_mass_influence is not None  # full kinematics
    return coupled_mass_matrix(kinematics.mass_matrix, kinematics.motor_mass_influence, design)


def heaviest_directions(kinematics: ArmSamples, matrix: np.ndarray) -> np.ndarray:
    """Per configuration, the unit direction of the largest effective mass for the mass matrices ``matrix``.

    The effective mass along ``u`` is ``1 / (u^T J A^-1 J^T u)``: largest along the eigenvector of the smallest
    eigenvalue of ``J A^-1 J^T`` (either sign: the mass is the same). ``matrix``: (n, nv, nv) [kg m^2].
    """
    _, vectors = np.linalg.eigh(task_inverse_inertia(kinematics.jacobian, matrix))
    return np.asarray(vectors[..., :, 0])


def _refined_poses(
    setup: ArmSetup, design: Design, q: np.ndarray, configs: np.ndarray, speeds: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
    """The refined poses of the :data:`REFINED` slowest configurations: joints, directions and speeds [m/s].

    ``q``: the draw's configurations; ``configs`` and ``speeds``: each row's configuration and permissible speed.
    None where no climb found a heavier pose.
    """
    order = np.argsort(speeds)
    starts = list(dict.fromkeys(int(configs[row]) for row in order))[:REFINED]
    poses = [_refined_pose(setup, design, q[config]) for config in starts]
    found = [pose for pose in poses if pose is not None]
    if not found:
        return None
    joints = np.array([pose[0] for pose in found])
    u = np.array([pose[1] for pose in found])
    refined = ContactSamples(setup.arm.kinematics(joints), u, np.arange(joints.shape[0]))
    region = setup.constraints.body_region
    assert region is not None
    return joints, u, region_speeds(refined, design, region)


def _refined_pose(setup: ArmSetup, design: Design, q0: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
    """A pose near ``q0`` (rad) of larger coupled effective mass along its heaviest direction, inside the domain.

    Nelder-Mead on the joint coordinates (a derivative-free climb: the mass is Pinocchio's, numeric), a point
    outside the joint limits, below the singular-value floor or with its heaviest direction beyond the joint
    speed limits at the design's approach scoring nothing; 200 evaluations at most. None if it leaves the start
    no better.
    """
    from scipy.optimize import minimize  # lazy: scipy.optimize is slow to import

    domain, arm = setup.domain, setup.arm
    angles0 = arm.configuration_space.joint_coordinates(q0[None, :])[0]

    def negative_mass(angles: np.ndarray) -> float:
        if np.any(angles < domain.lower) or np.any(angles > domain.upper):
            return 0.0
        kinematics = arm.kinematics(arm.configuration(angles)[None, :])
        matrix = _coupled_matrix(kinematics, design)
        u = heaviest_directions(kinematics, matrix)
        jacobian = kinematics.jacobian
        if domain.configuration_margin(jacobian)[0] < 0 or np.any(
            domain.speed_margin(jacobian, u, design.approach_velocity) < 0
        ):
            return 0.0
        return -effective_mass(kinematics, 0, u[0], matrix[0])

    start = negative_mass(angles0)
    best = minimize(negative_mass, angles0, method="Nelder-Mead", options={"maxfev": 200, "xatol": 1e-4})
    if not best.fun < start:
        return None
    kinematics = arm.kinematics(arm.configuration(best.x)[None, :])
    u = heaviest_directions(kinematics, _coupled_matrix(kinematics, design))
    return kinematics.q[0], u[0]
