"""One design of a run folder, with the arm and the catalogue parts it was designed for.

A run folder of ``crx run`` holds the design records (``designs.json``) and the study as it was run
(``study.resolved.yaml``); this module reads one design out of them and rebuilds what the record does not hold:
the arm (from the resolved study's robot) and each motor's maximum speed (the reference motor scaled to the
design's size, as the optimiser scales it).
"""

from __future__ import annotations

import math
import os
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ..errors import CollisionReflexError, InvalidParameter
from ..hardware.gearboxes import load_gearbox_catalogue
from ..hardware.motors import scaled_motor_quantities
from ..record.checked import ResultsDamaged, ResultsMissing
from ..record.design import DesignRecord, JointRecord, QuickSnap
from ..record.read import checked_run_record, pick_design, read_saved_record
from ..record.run import ArmRunRecord
from ..report.files import DESIGNS
from ..study.load import parse_study
from ..study.prepare import check_motors
from ..study.robot import load_arm
from ..study.schema import ArmStudy

if TYPE_CHECKING:
    from ..arm import Arm

RESOLVED = "study.resolved.yaml"


@dataclass(frozen=True)
class JointActuator:
    """One joint's actuator as the design gives it (SI units, joint side unless named motor).

    joint: the joint's name; gear_ratio ``N`` [-]; rotor_inertia ``J_m`` [kg m^2]; gearbox_inertia: the gearbox's
    input-side inertia ``J_g`` as the design's reflected inertia counts it [kg m^2] (0 without a gearbox or when
    the study leaves it out); reflected_inertia ``N^2 (J_m + J_g)`` [kg m^2]; peak_torque ``N tau_p`` [N m];
    motor_peak_torque ``tau_p`` [N m]; motor_mass, gearbox_mass [kg]; gearbox: its catalogue name ("" for
    none); gearbox_efficiency [-]; motor_max_speed ``omega_max`` [rad/s] (None when the catalogue gives none);
    gearbox_max_speed: the catalogue gearbox's maximum input speed [rad/s] (None for none or not known);
    stator_diameter, stack_length [m]; nearest_motor: the nearest catalogue motor ("" for none); motor: the
    catalogue motor the joint is built from ("" for a motor scaled from the reference); gearbox_peak_torque: the
    catalogue gearbox's repeated peak torque [N m] (None for none or a gearbox the catalogue lacks);
    mechanical_stiffness: the joint's spring between link and rotor [N m/rad] (``inf``: rigid); software_stiffness:
    the controller's joint stiffness ``k_s`` [N m/rad].
    """

    joint: str
    gear_ratio: float
    rotor_inertia: float
    gearbox_inertia: float
    reflected_inertia: float
    peak_torque: float
    motor_peak_torque: float
    motor_mass: float
    gearbox_mass: float
    gearbox: str
    gearbox_efficiency: float
    motor_max_speed: float | None
    gearbox_max_speed: float | None
    stator_diameter: float
    stack_length: float
    nearest_motor: str
    motor: str = ""
    gearbox_peak_torque: float | None = None
    mechanical_stiffness: float = float("inf")
    software_stiffness: float = float("inf")

    @property
    def driving_peak_torque(self) -> float:
        """The peak torque the joint delivers at its output [N m]: ``eta N tau_p``, as the optimiser sizes it.

        At most the catalogue gearbox's repeated peak torque, which the optimiser also holds the requirement to.
        """
        driving = self.gearbox_efficiency * self.peak_torque
        return driving if self.gearbox_peak_torque is None else min(driving, self.gearbox_peak_torque)

    @property
    def actuator_mass(self) -> float:
        """The mass carried by the parent link at the joint [kg]: the motor's and the gearbox's."""
        return self.motor_mass + self.gearbox_mass

    @property
    def max_speed(self) -> float | None:
        """The joint's speed limit [rad/s]: the motor's ``omega_max`` (or the gearbox's input limit, if lower) / N.

        None when neither is known.
        """
        known = [s for s in (self.motor_max_speed, self.gearbox_max_speed) if s is not None]
        return min(known) / self.gear_ratio if known else None


@dataclass(frozen=True)
class RunDesign:
    """A design of a run folder and what an export needs about it.

    study: the study's name; label: which design (``"recommended design (Pareto design 0)"``); arm: the arm
    as the study loads it (locked joints removed, contact point set); joints: one :class:`JointActuator` per
    joint of the arm, in its order; parts: provenance lines (catalogue parts and their sources);
    catalogue: the design record's ``catalogue`` entry (its quick snap) where it has one (None otherwise);
    placement: where the study placed the reflected inertia in the impact (``reflected_inertia_in``, as its
    resolved study writes it); sensing, threshold and approach_velocity: the design's detection (its scheme and
    threshold, a force [N] or a position error [m]) and approach speed [m/s].
    """

    study: str
    label: str
    arm: Arm
    joints: tuple[JointActuator, ...]
    parts: tuple[str, ...]
    catalogue: QuickSnap | None = None
    placement: str = "robot"
    sensing: str = "force"
    threshold: float = float("nan")
    approach_velocity: float = float("nan")


def read_run_design(run_dir: str | os.PathLike[str], design: str | int = "recommended") -> RunDesign:
    """The design ``design`` of the run folder ``run_dir``.

    Parameters
    ----------
    run_dir: the output folder of ``crx run`` of an arm study.
    design: ``"catalogue"`` (the design built from catalogue parts), ``"recommended"``, ``"chosen"`` (the
        single-objective optimum) or the index of a Pareto design (as ``pareto.csv``'s ``point`` column numbers
        them).

    Raises
    ------
    ResultsMissing: the folder has no ``designs.json`` or no resolved study.
    ResultsDamaged: ``designs.json`` cannot be read or lacks a field the export needs.
    InvalidParameter: the study is not an arm study, or it has no design ``design``.
    """
    folder = Path(run_dir)
    path = folder / DESIGNS
    data = read_saved_record(path)
    if data["kind"] != "arm":
        raise InvalidParameter(
            "run_dir",
            f"{folder} ({data['kind']!r} study)",
            "the folder of an arm study",
            "an actuator study has no arm to export",
        )
    results = checked_run_record(data, path)
    assert results["kind"] == "arm"  # checked above
    label, record = pick_design(results, design)
    resolved = folder / RESOLVED
    if not resolved.is_file():
        raise ResultsMissing(f"{folder} has no {RESOLVED}: run the study again")
    try:
        return _run_design(results, record, label, resolved, design == "catalogue")
    except ResultsDamaged as error:
        raise ResultsDamaged(f"{path}: {error}; run the study again") from None
    except (KeyError, TypeError, ValueError, AttributeError) as error:
        if isinstance(error, CollisionReflexError):
            raise
        what = f"field {error.args[0]!r} is missing" if isinstance(error, KeyError) else str(error)
        raise ResultsDamaged(f"{path}: {' '.join(what.split())}; run the study again") from None


def _run_design(
    results: ArmRunRecord, record: DesignRecord, label: str, resolved: Path, built: bool
) -> RunDesign:
    """The :class:`RunDesign` of a design record, with the arm and motors of the resolved study.

    ``built``: the record is the catalogue design, each joint's motor the catalogue part it names (its own
    maximum speed), not a motor scaled from the reference.
    """
    loaded = parse_study(resolved.read_text(encoding="utf-8"), str(resolved), resolved.parent)
    study = loaded.study
    if not isinstance(study, ArmStudy):
        raise InvalidParameter("run_dir", str(resolved.parent), "the folder of an arm study")
    catalogue = check_motors(loaded)
    reference = catalogue[study.actuators.motor.reference]
    law = study.actuators.motor.scaling_law
    arm = load_arm(loaded)
    by_name = {str(j["joint"]): j for j in record["joints"]}
    gearboxes = _gearbox_catalogue(by_name.values())
    missing = [name for name in arm.joint_names if name not in by_name]
    if missing:
        raise ResultsDamaged(f"the design has no actuator for joint(s) {', '.join(missing)}")
    joints = []
    for name in arm.joint_names:
        saved = by_name[name]
        diameter, stack = float(saved["stator_diameter"]), float(saved["stack_length"])
        motor = str(saved.get("nearest_catalogue_motor") or "") if built else ""
        if built and motor not in catalogue:
            raise ResultsDamaged(f"the catalogue design's motor {motor!r} of {name} is in no motor catalogue")
        speed = (
            catalogue[motor].max_speed
            if built
            else scaled_motor_quantities(reference, diameter, stack, law).max_speed
        )
        rotor, ratio = float(saved["rotor_inertia"]), float(saved["gear_ratio"])
        reflected = float(saved["reflected_inertia"])
        gearbox = str(saved.get("gearbox") or "")
        # A catalogue design's gearbox is sold at its ratio (its figures there); a continuous design's ratio was
        # free between the offered ones, and the optimiser charged it the entry's figures.
        sold_at = ratio if built else None
        joints.append(
            JointActuator(
                joint=name,
                gear_ratio=ratio,
                rotor_inertia=rotor,
                gearbox_inertia=_counted_gearbox_inertia(saved, ratio, rotor, reflected),
                reflected_inertia=reflected,
                peak_torque=float(saved["peak_torque"]),
                motor_peak_torque=float(saved["motor_peak_torque"]),
                motor_mass=float(saved["motor_mass"]),
                gearbox_mass=float(saved.get("gearbox_mass", 0.0)),
                gearbox=gearbox,
                gearbox_efficiency=float(saved.get("gearbox_efficiency", 1.0)),
                motor_max_speed=None if speed is None or not math.isfinite(speed) else float(speed),
                gearbox_max_speed=_gearbox_figure(gearbox, sold_at, gearboxes, "max_input_speed"),
                stator_diameter=diameter,
                stack_length=stack,
                nearest_motor=str(saved.get("nearest_catalogue_motor") or ""),
                motor=motor,
                gearbox_peak_torque=_gearbox_figure(gearbox, sold_at, gearboxes, "peak_torque"),
                mechanical_stiffness=float(saved["mechanical_stiffness"]),
                software_stiffness=float(saved["software_stiffness"]),
            )
        )
    return RunDesign(
        study=str(results.get("study", study.name)),
        label=label,
        arm=arm,
        joints=tuple(joints),
        parts=_parts(joints, catalogue, gearboxes, reference.name, law),
        catalogue=record.get("catalogue"),
        sensing=str(record["sensing"]),
        threshold=float(record["threshold"]),
        approach_velocity=float(record["approach_velocity"]),
        placement=str(
            study.reflected_inertia_in if isinstance(study.reflected_inertia_in, str) else "a rule"
        ),
    )


def _counted_gearbox_inertia(saved: JointRecord, ratio: float, rotor: float, reflected: float) -> float:
    """What the reflected inertia ``N^2 (J_m + J_g)`` counts beyond the rotor [kg m^2]: ``J_g``, or 0.

    0 where the study leaves the gearbox inertia out. The record's own ``gearbox_inertia`` (the figure the design
    was charged at its ratio) where the reflected inertia counts it, so that the export shows designs.json's figure
    digit for digit; else what the reflected inertia implies.
    """
    implied = max(0.0, reflected / ratio**2 - rotor)
    recorded = float(saved.get("gearbox_inertia", 0.0))
    return recorded if math.isclose(implied, recorded, rel_tol=1e-9, abs_tol=1e-12 * rotor) else implied


def _gearbox_figure(
    name: str, ratio: float | None, gearboxes: Mapping[str, Any], figure: str
) -> float | None:
    """A catalogue gearbox's ``figure`` (SI) as sold at gear ratio ``ratio`` [-] (None: the entry's own figure).

    None without a gearbox, one the catalogue lacks, or no figure.
    """
    gearbox = gearboxes.get(name) if name else None
    if gearbox is not None and ratio is not None:
        gearbox = gearbox.at_ratio(ratio)
    value = getattr(gearbox, figure, None)
    return float(value) if value is not None and math.isfinite(value) else None


def _gearbox_catalogue(joints: Iterable[JointRecord]) -> Mapping[str, Any]:
    """The gearbox catalogue by name where a joint has a gearbox (empty otherwise: no file read)."""
    if not any(j.get("gearbox") for j in joints):
        return {}
    return load_gearbox_catalogue()


def _parts(
    joints: list[JointActuator],
    catalogue: Mapping[str, Any],
    gearboxes: Mapping[str, Any],
    reference: str,
    law: str,
) -> tuple[str, ...]:
    """Provenance lines of the motors and gearboxes, with their sources.

    The catalogue motors a catalogue design is built from, or else the reference motor and each nearest
    catalogue motor; then each gearbox.
    """
    built = sorted({j.motor for j in joints if j.motor})
    if built:
        lines = [f"catalogue motor {name}: {catalogue[name].source}" for name in built]
    else:
        lines = [
            f"motors scaled from {reference} by the {law} law; {reference}: {catalogue[reference].source}"
        ]
        nearest = {
            j.nearest_motor for j in joints if j.nearest_motor in catalogue and j.nearest_motor != reference
        }
        lines += [f"nearest catalogue motor {name}: {catalogue[name].source}" for name in sorted(nearest)]
    for name in sorted({j.gearbox for j in joints if j.gearbox}):
        source = getattr(gearboxes.get(name), "source", "") or "figures given in the study"
        lines.append(f"gearbox {name}: {source}")
    return tuple(lines)
