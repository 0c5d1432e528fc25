"""Permissible approach speeds of a run's design against a human body region, over the run's contact domain.

For each contact sample of a finished run (configuration and direction), the robot mass a body region meets is
the design's effective mass along the direction (:mod:`collision_reflex.model.contact`): the finger alone when the
region is much stiffer than the joints along that direction, the links with the rotors on them when it is much
softer, the latter as a bound in between. The permissible speed is then ``v = F_T / sqrt(mu k_c)``. Beside it, the
ISO/TS 15066 estimate integrators use without a dynamic model: half the moving mass plus the payload, the same
for every pose and direction.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from ..arm.effective import effective_parameters
from ..errors import InvalidParameter
from ..model import effective as formulas
from ..model.contact import (
    COUPLED_STIFFNESS_RATIO,
    DECOUPLED_STIFFNESS_RATIO,
    BodyRegion,
    iso_robot_mass,
    permissible_speed,
)
from ..model.impulse import series_stiffness
from ..optimize.results import record_design
from ..optimize.samples import SPEED_CAP_TOLERANCE
from ..record.read import checked_run_record, pick_design, read_saved_record
from ..report.files import DESIGNS
from .body_regions import load_body_regions
from .fresh import fresh_draw
from .problems import StudyProblems
from .region_search import search_region

if TYPE_CHECKING:
    from ..record.design import DesignRecord
    from ..record.run import HumanContactRecord, RegionSpeeds
    from .arm_setup import ArmSetup


@dataclass(frozen=True)
class SpeedMap:
    """A design's permissible approach speeds against a body region, one per contact sample of its run.

    masses: the design's effective masses over the samples (:class:`ContactMasses`); region: the body region;
    robot_mass: the mass the region meets per sample [kg], and exact (False where it is the coupled bound);
    speed: the permissible speed per sample [m/s] (0 where the arm cannot move along the direction: an infinite
    mass); iso_mass [kg] and iso_speed [m/s]: the ISO/TS 15066 estimate without a dynamic model.
    """

    masses: ContactMasses
    region: BodyRegion
    robot_mass: np.ndarray
    exact: np.ndarray
    speed: np.ndarray
    iso_mass: float
    iso_speed: float

    def rows(self) -> list[dict[str, Any]]:
        """One row per sample, SI units in the column names (for a CSV file)."""
        rows = []
        for s in range(self.speed.size):
            row: dict[str, Any] = {"sample": s}
            row.update({f"q{j + 1} [rad]": float(v) for j, v in enumerate(self.masses.q[s])})
            row.update({f"u{j + 1}": float(v) for j, v in enumerate(self.masses.directions[s])})
            row.update(
                {
                    "finger_mass [kg]": float(self.masses.finger_mass[s]),
                    "coupled_mass [kg]": float(self.masses.coupled_mass[s]),
                    "mechanical_stiffness [N/m]": float(self.masses.mechanical_stiffness[s]),
                    "robot_mass [kg]": float(self.robot_mass[s]),
                    "exact": bool(self.exact[s]),
                    "permissible_speed [m/s]": float(self.speed[s]),
                    "iso_speed [m/s]": self.iso_speed,
                }
            )
            rows.append(row)
        return rows

    @property
    def above_approach(self) -> np.ndarray:
        """Per sample, whether the design's approach exceeds the permissible speed, (n,) bool.

        Beyond a relative 1e-6 (:data:`~collision_reflex.optimize.samples.SPEED_CAP_TOLERANCE`): a design a study
        held to the region's limit sits on it, to the solver's tolerance.
        """
        return np.asarray(self.masses.approach_velocity > self.speed * (1 + SPEED_CAP_TOLERANCE))

    def summary(self) -> list[str]:
        """The lines a designer reads first.

        The slowest pose and the spread, the design's own speed against them, the ISO estimate beside them,
        and how many samples take the bound.
        """
        r = self.region
        slowest = int(np.argmin(self.speed))
        lines = [
            f"{self.masses.design} against {r.name} (k_c = {r.stiffness / 1e3:g} N/mm, m_H = {r.mass:g} kg, "
            f"F_T = {r.transient_force:g} N), over {self.speed.size} contact samples of the run:",
            f"permissible speed {np.min(self.speed):.3g} to {np.max(self.speed):.3g} m/s "
            f"(median {np.median(self.speed):.3g} m/s); slowest at sample {slowest} "
            f"(q = {', '.join(f'{v:.3g}' for v in self.masses.q[slowest])}; robot mass {self.robot_mass[slowest]:.3g} kg)",
        ]
        above = int(np.sum(self.above_approach))
        lines.append(
            f"the design approaches at {self.masses.approach_velocity:.3g} m/s: "
            + (
                f"above the permissible speed at {above} of {self.speed.size} samples"
                if above
                else "within the permissible speed at every sample"
            )
        )
        slowest_speed = float(np.min(self.speed))
        compared = (
            f"{self.iso_speed / slowest_speed:.3g}x the slowest pose's"
            if slowest_speed > 0
            else "a sampled direction is singular: no speed is permissible along it"
        )
        lines.append(
            "ISO/TS 15066 estimate without a dynamic model: robot mass M/2 + payload = "
            f"{self.masses.moving_mass:.3g}/2 + {self.masses.payload:.3g} = {self.iso_mass:.3g} kg, permissible "
            f"speed {self.iso_speed:.3g} m/s ({compared})"
        )
        bound = int(np.sum(~self.exact))
        if bound:
            lines.append(
                f"at {bound} of {self.speed.size} samples the region is neither much stiffer nor much softer than "
                f"the joints ({COUPLED_STIFFNESS_RATIO:g} < k_c/k_m < {DECOUPLED_STIFFNESS_RATIO:g}): their robot "
                "mass is the rotors-on-links bound, so their speeds are on the safe side"
            )
        return lines


def speed_map(
    folder: str | os.PathLike[str], region: BodyRegion, design: str | int = "recommended"
) -> SpeedMap:
    """The permissible approach speeds of a run's design against ``region``, over the run's contact samples.

    ``folder``: the output folder of ``crx run`` of an arm study; ``design``: ``"recommended"``, ``"chosen"``
    or the index of a Pareto design (as ``crx export`` names them).

    Raises
    ------
    ResultsMissing, ResultsDamaged: the folder's files are missing or damaged.
    InvalidParameter: an actuator study's folder, no design ``design``, or a region without a permissible
        transient force (ISO/TS 15066 gives none for the skull, forehead and face).
    """
    _transient_force(region)
    path = Path(folder) / DESIGNS
    data = read_saved_record(path)
    if data["kind"] != "arm":
        raise InvalidParameter(
            "folder", f"{folder} ({data['kind']!r} study)", "the folder of an arm study", "it has no arm"
        )
    results = checked_run_record(data, path)
    assert results["kind"] == "arm"
    label, record = pick_design(results, design)
    return contact_masses(StudyProblems.of_run(folder).setup, record, label).speeds(region)


@dataclass(frozen=True)
class ContactMasses:
    """A design's effective masses over its run's contact samples, what every region's speeds are made of.

    design: which design (its label); approach_velocity: the design's own approach speed [m/s]; q (n, nq) and
    directions (n, d): each sample's configuration [rad, m] and unit direction; finger_mass: the effective mass
    with the rotors behind the joint springs [kg]; coupled_mass: with the rotors on the links [kg];
    mechanical_stiffness: the joints' stiffness along the direction [N/m]; moving_mass and payload: what the
    ISO/TS 15066 estimate takes [kg].
    """

    design: str
    approach_velocity: float
    q: np.ndarray
    directions: np.ndarray
    finger_mass: np.ndarray
    coupled_mass: np.ndarray
    mechanical_stiffness: np.ndarray
    moving_mass: float
    payload: float

    def speeds(self, region: BodyRegion) -> SpeedMap:
        """The permissible speeds against ``region`` (one with a transient force)."""
        force = _transient_force(region)
        ratio = region.stiffness / self.mechanical_stiffness
        decoupled = ratio >= DECOUPLED_STIFFNESS_RATIO
        robot_mass = np.where(decoupled, self.finger_mass, self.coupled_mass)
        speed = np.zeros_like(robot_mass)
        movable = np.isfinite(robot_mass)  # an infinite mass (a singular direction) permits no speed
        speed[movable] = permissible_speed(force, robot_mass[movable], region.stiffness, region.mass)
        iso_mass = iso_robot_mass(self.moving_mass, self.payload)
        return SpeedMap(
            masses=self,
            region=region,
            robot_mass=robot_mass,
            exact=decoupled | (ratio <= COUPLED_STIFFNESS_RATIO),
            speed=speed,
            iso_mass=iso_mass,
            iso_speed=permissible_speed(force, iso_mass, region.stiffness, region.mass),
        )


def contact_masses(setup: ArmSetup, record: DesignRecord, label: str) -> ContactMasses:
    """The effective masses of the design ``record`` (called ``label``) over ``setup``'s contact samples."""
    chosen = record_design(record, setup.study.sensing.scheme)
    samples = setup.samples
    common = {
        "config_index": samples.config_index,
        "reflected_inertia": chosen.reflected_inertia,
        "stiffness": series_stiffness(chosen.mechanical_stiffness, chosen.software_stiffness),
        "mechanical_stiffness": chosen.mechanical_stiffness,
        "torque_limit": chosen.peak_torque,
        "motor_mass": chosen.actuator_mass,
    }
    loose = effective_parameters(samples.kinematics, samples.directions, **common)
    held = effective_parameters(
        samples.kinematics,
        samples.directions,
        finger_joint_inertia=formulas.finger_inertia(chosen.reflected_inertia, 1.0),
        **common,
    )
    finger, coupled, k_m = (np.asarray(x, dtype=float).ravel() for x in (loose.m_f, held.m_f, loose.k_m))
    return ContactMasses(
        design=label,
        approach_velocity=float(chosen.approach_velocity),
        q=samples.kinematics.q[samples.config_index],
        directions=samples.directions,
        finger_mass=finger,
        coupled_mass=coupled,
        mechanical_stiffness=k_m,
        moving_mass=_moving_mass(setup.arm, chosen.actuator_mass),
        payload=float(setup.constraints.payload),
    )


def human_contact_record(setup: ArmSetup, record: DesignRecord, label: str) -> HumanContactRecord:
    """What a run keeps of its design's permissible speeds against the standard's body regions (SI units).

    A study held to a body region also keeps whether the limit holds on the fresh configurations
    (:func:`.fresh.fresh_draw`), which no round of the solves has seen, searched as :mod:`.region_search` does.
    """
    masses = contact_masses(setup, record, label)
    regions = load_body_regions()
    rows: list[RegionSpeeds] = []
    for name, region in regions.items():
        if region.transient_force is None:
            continue
        speeds = masses.speeds(region)
        rows.append(
            {
                "region": name,
                "stiffness": region.stiffness,
                "mass": region.mass,
                "transient_force": region.transient_force,
                "slowest": float(np.min(speeds.speed)),
                "median": float(np.median(speeds.speed)),
                "fastest": float(np.max(speeds.speed)),
                "slowest_sample": int(np.argmin(speeds.speed)),
                "above_approach": int(np.sum(speeds.above_approach)),
                "bound_samples": int(np.sum(~speeds.exact)),
                "iso_speed": float(speeds.iso_speed),
            }
        )
    out: HumanContactRecord = {
        "design": label,
        "samples": int(masses.finger_mass.size),
        "approach_velocity": masses.approach_velocity,
        "moving_mass": masses.moving_mass,
        "payload": masses.payload,
        "iso_mass": float(iso_robot_mass(masses.moving_mass, masses.payload)),
        "regions": rows,
        "no_transient": [name for name, r in regions.items() if r.transient_force is None],
    }
    held = setup.constraints.body_region
    if held is not None:
        draw = fresh_draw(setup)
        found = (
            None
            if draw is None
            else search_region(
                setup, draw, {label: record_design(record, setup.study.sensing.scheme)}, SPEED_CAP_TOLERANCE
            )[label]
        )
        out["held_to"] = {
            "region": held.name,
            "fresh_samples": 0 if found is None else found.samples,
            "slowest": None if found is None else found.slowest,
            "below": 0 if found is None else found.below,
            "robot_mass": None if found is None else found.robot_mass,
            "link_mass": None if found is None else found.link_mass,
            "links_speed": None if found is None else found.links_speed,
        }
    return out


def _transient_force(region: BodyRegion) -> float:
    """The region's permissible transient force [N], or a refusal for a region the standard permits none."""
    if region.transient_force is None:
        raise InvalidParameter(
            "region",
            region.name,
            "a body region with a permissible transient force",
            f"ISO/TS 15066 permits no transient contact with {region.name}: keep the robot from moving into it",
        )
    return region.transient_force


def _moving_mass(arm: Any, actuator_mass: np.ndarray) -> float:
    """The mass of the arm's moving parts [kg]: every link but the base, and the actuators that ride on them.

    Actuator ``i`` sits on joint ``i``'s parent link: on the fixed base for a joint attached to it.
    """
    model = arm.model
    links = sum(float(inertia.mass) for inertia in model.inertias[1:])
    riding = [float(m) for i, m in enumerate(actuator_mass) if model.parents[i + 1] != 0]
    return links + math.fsum(riding)
