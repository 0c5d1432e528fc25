"""An arm study translated into the optimiser's inputs.

:class:`ArmSetup` holds the robot, motors, design space, actuator technology, constraints and contact samples,
every problem located in the study file (:mod:`.checks` says what is refused). :mod:`.problems` builds the
design problems from it, once per process.
"""

from __future__ import annotations

import dataclasses
import hashlib
import pickle
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from ..arm.static_hold import worst_hold_poses
from ..hardware.gearboxes import ScaledGearbox, load_gearbox_catalogue
from ..optimize import ActuatorTechnology, Bounds, Constraints, ContactSamples, DesignSpace
from ..optimize.blas import single_threaded_blas
from ..optimize.technology import placements_from_stiffness
from .actuator_specs import DIRECT_DRIVE, PlacementRuleSpec, ScaledGearboxSpec
from .body_regions import transient_regions
from .checks import (
    gearbox_ratio_problems,
    module_problems,
    raise_problems,
    requirement_problems,
    unsupported_features,
)
from .duty import payload_of, study_duty_cycle, study_rating
from .load import LoadedStudy
from .prepare import JointActuatorValues, check_motors, gearbox_for, joint_actuators, per_joint_bounds
from .robot import load_arm
from .samples import configuration_samples, contact_domain, direction_samples, domain_draw
from .schema import ArmStudy
from .source import PathKey

if TYPE_CHECKING:
    from ..arm import Arm, DutyCycle
    from ..arm.domain import ContactDomain
    from ..hardware.gearboxes import CatalogueGearbox
    from ..hardware.motors import Motor

ExtraSamples = tuple[tuple[tuple[float, ...], tuple[float, ...]], ...]
"""Samples a worst-case search added, as plain data: ``((q, u), ...)``, q [rad] (nq,), u unit (task_dim,)."""


@dataclass(frozen=True)
class ArmSetup:
    """Everything an arm study's solves need, built once per process.

    arm: the robot; catalogue: the motor catalogue by name; configurations: (n, nq) [rad]; directions:
    (m, task_dim) unit vectors; samples: the optimiser's contact samples (each configuration with the
    directions feasible there, then the points a worst-case search added); space, technology, constraints: the
    optimiser's inputs; duty_cycle: the motion the arm must make (with its payload), or ``None`` when the study
    gives none (:attr:`static_torque_requirement`); domain: where contacts are considered; domain_kept: the
    fraction of the joint-limit box's (configuration, direction) pairs in it at ``sampling_velocity`` [m/s],
    the fastest approach of the design space (None when the configurations are listed, not drawn); searched:
    how many samples a worst-case search added (the last ones); placement_ratios: per joint the contact's
    stiffness seen at the joint over its transmission's (:func:`collision_reflex.optimize.technology.
    placements_from_stiffness`), when the study places the reflected inertias by that rule, else None.
    """

    study: ArmStudy
    arm: Arm
    catalogue: dict[str, Motor]
    configurations: np.ndarray
    directions: np.ndarray
    samples: ContactSamples
    space: DesignSpace
    technology: ActuatorTechnology
    constraints: Constraints
    domain: ContactDomain
    sampling_velocity: float
    duty_cycle: DutyCycle | None = None
    domain_kept: float | None = None
    searched: int = 0
    placement_ratios: np.ndarray | None = None

    @property
    def static_torque_requirement(self) -> bool:
        """True when the torque requirement is the static (gravity-only) one: the study gives no duty cycle."""
        return self.duty_cycle is None


def arm_setup(loaded: LoadedStudy) -> ArmSetup:
    """Load the robot and motors and translate the study into the optimiser's inputs; every problem located.

    With every BLAS on one thread: the same arithmetic in every process (see
    :func:`~collision_reflex.optimize.blas.single_threaded_blas`), and the hold-pose search's many small
    quasi-Newton steps are several times faster than with idle BLAS threads woken at each.
    """
    with single_threaded_blas():
        return _arm_setup(loaded)


def _arm_setup(loaded: LoadedStudy) -> ArmSetup:
    study = loaded.study
    assert isinstance(study, ArmStudy)
    catalogue = check_motors(loaded)
    arm = load_arm(loaded)
    joints = list(arm.joint_names)
    actuators = joint_actuators(study, joints)
    raise_problems(loaded, unsupported_features(loaded, study))
    reference = catalogue[study.actuators.motor.reference]
    space = _design_space(loaded, study, joints, actuators, reference)
    technology = ActuatorTechnology(
        reference_motor=reference,
        mechanical_stiffness=[a.mechanical_stiffness for a in actuators],
        scaling_law=study.actuators.motor.scaling_law,
        sensing=study.sensing.scheme,
        reaction=study.reaction,
        reflected_inertia_in=_placements(study, joints),
        gearboxes=_joint_gearboxes(loaded, study, joints, space.per_joint("gear_ratio", len(joints))),
        gearbox_inertia=study.actuators.gearbox_inertia,
    )
    constraints = _constraints(loaded, arm, space, technology)
    directions = direction_samples(loaded, arm)
    domain = contact_domain(loaded, arm)
    sampling_velocity = float(space.global_bounds("approach_velocity").upper)  # the fastest approach allowed
    kept = None
    if study.samples.configurations.random is not None:
        draw = domain_draw(loaded, arm, domain, directions, sampling_velocity)
        configurations, kept = draw.q, draw.samples_kept
        config_index, direction_index = np.nonzero(draw.feasible)
        samples = ContactSamples(arm.kinematics(configurations), directions[direction_index], config_index)
    else:
        configurations = configuration_samples(loaded, arm)
        samples = ContactSamples.grid(arm.kinematics(configurations), directions)
    placement_ratios = None
    if isinstance(study.reflected_inertia_in, PlacementRuleSpec):  # per joint, from the stiffnesses
        ruled, placement_ratios = placements_from_stiffness(
            samples.joint_moment_arms,
            technology.joint_mechanical_stiffness(len(joints)),
            study.reflected_inertia_in.contact_stiffness,
        )
        own = _own_placements(study)  # a joint's own choice stands
        chosen = tuple(own.get(j, r) for j, r in zip(joints, ruled, strict=True))
        technology = dataclasses.replace(technology, reflected_inertia_in=chosen)
    return ArmSetup(
        study,
        arm,
        catalogue,
        configurations,
        directions,
        samples,
        space,
        technology,
        constraints,
        domain,
        sampling_velocity,
        duty_cycle=constraints.duty_cycle,
        domain_kept=kept,
        placement_ratios=placement_ratios,
    )


def _design_space(
    loaded: LoadedStudy,
    study: ArmStudy,
    joints: list[str],
    actuators: list[JointActuatorValues],
    reference: Motor,
) -> DesignSpace:
    """The design variables' bounds: the study's ``design`` where it gives them, else its nominal values."""

    def nominal(name: str, values: list[float]) -> list[Any]:
        spec = getattr(study.design, name)
        if spec is None:
            return [Bounds.fixed(v, f"{name}[{j}]") for v, j in zip(values, joints, strict=True)]
        return [
            Bounds(lo, hi, f"{name}[{j}]")
            for (lo, hi), j in zip(per_joint_bounds(spec, joints), joints, strict=True)
        ]

    threshold = study.design.threshold if study.sensing.scheme == "force" else study.design.position_error
    velocity = study.design.approach_velocity
    raise_problems(loaded, module_problems(loaded, study, joints, actuators))
    return DesignSpace(
        stator_diameter=nominal(
            "stator_diameter", [a.motor.stator_diameter or reference.stator_diameter for a in actuators]
        ),
        stack_length=nominal(
            "stack_length", [a.motor.stack_length or reference.stack_length for a in actuators]
        ),
        gear_ratio=nominal("gear_ratio", [a.gear_ratio for a in actuators]),
        software_stiffness=nominal("software_stiffness", [a.software_stiffness for a in actuators]),
        threshold=Bounds(*threshold.bounds, "threshold") if threshold else study.sensing.value,
        approach_velocity=Bounds(*velocity.bounds, "approach_velocity")
        if velocity
        else study.approach_velocity,
        modules=tuple(tuple(joints.index(name) for name in group) for group in study.actuators.modules),
    )


def _constraints(
    loaded: LoadedStudy, arm: Arm, space: DesignSpace, technology: ActuatorTechnology
) -> Constraints:
    """The study's constraints: its duty cycle, rating and static hold (each joint's worst pose), or given torques."""
    study = loaded.study
    assert isinstance(study, ArmStudy)
    duty_cycle = study_duty_cycle(loaded, arm)
    raise_problems(loaded, requirement_problems(loaded, study, duty_cycle is not None, None))
    # The static hold's payload: the rated one, else the one the study carries (over its cycle, if any).
    payload = payload_of(study)
    held = study.rating.payload if study.rating.payload is not None else payload.mass if payload else 0.0
    hold = None
    if study.constraints.torque_required is None:  # each joint's worst static pose joins the samples'
        masses = _nominal_actuator_mass(space, technology, len(arm.joint_names))
        hold = arm.kinematics(_worst_hold_poses(arm, held, masses))
    rating = study_rating(loaded, arm)
    raise_problems(loaded, requirement_problems(loaded, study, False, rating))
    return Constraints(
        payload=held,
        safety_factor=study.constraints.safety_factor,
        torque_required=study.constraints.torque_required,
        threshold_floor=study.constraints.threshold_floor,
        duty_cycle=duty_cycle,
        rating=rating,
        hold_poses=hold,
        body_region=None
        if study.constraints.body_region is None
        else transient_regions()[study.constraints.body_region],
    )


_HOLD_POSES: dict[bytes, np.ndarray] = {}
"""Hold poses found, by the arm's fingerprint, the payload and the actuator masses: a run sets its study up several times (as written, as solved, per
gearbox option), and the search is a few thousand kinematics evaluations."""


def _worst_hold_poses(arm: Arm, payload: float, actuator_mass: np.ndarray) -> np.ndarray:
    """:func:`~collision_reflex.arm.static_hold.worst_hold_poses` from the seed 0, found once per arm and load."""
    key = hashlib.sha256(pickle.dumps((arm.fingerprint, payload, actuator_mass))).digest()
    if key not in _HOLD_POSES:
        if len(_HOLD_POSES) >= 32:
            _HOLD_POSES.pop(next(iter(_HOLD_POSES)))
        _HOLD_POSES[key] = worst_hold_poses(arm, payload, actuator_mass, np.random.default_rng(0))
    return _HOLD_POSES[key].copy()


def _nominal_actuator_mass(space: DesignSpace, technology: ActuatorTechnology, n: int) -> np.ndarray:
    """The actuator masses [kg] at the middle of the design space (log midpoints), where hold poses are sought."""
    stacks = technology.default_stack_lengths(n)
    middle = {
        name: np.array([b.midpoint for b in space.per_joint(name, n, default)])
        for name, default in (("stator_diameter", None), ("stack_length", stacks), ("gear_ratio", None))
    }
    joint = technology.joint_quantities(
        middle["stator_diameter"], middle["stack_length"], middle["gear_ratio"]
    )
    return np.asarray(joint.actuator_mass, dtype=float)


def _own_placements(study: ArmStudy) -> dict[str, str]:
    """The joints that state their own reflected-inertia placement (``actuators.joints.NAME``), with it."""
    return {
        j: spec.reflected_inertia_in
        for j, spec in study.actuators.joints.items()
        if spec.reflected_inertia_in
    }


def _placements(study: ArmStudy, joints: list[str]) -> tuple[str, ...]:
    """Each joint's reflected-inertia placement as the study gives it (a rule's joints: ``robot`` until ruled)."""
    default = study.reflected_inertia_in if isinstance(study.reflected_inertia_in, str) else "robot"
    own = _own_placements(study)
    return tuple(own.get(j, default) for j in joints)


def with_extra_samples(setup: ArmSetup, extra: ExtraSamples) -> ArmSetup:
    """``setup`` with the samples ``extra`` appended (each its own configuration), in order."""
    if not extra:
        return setup
    q_extra = np.array([q for q, _ in extra], dtype=float)
    u_extra = np.array([u for _, u in extra], dtype=float)
    configurations = np.vstack([setup.configurations, q_extra])
    base = setup.samples
    kinematics = setup.arm.kinematics(configurations)
    n_base = setup.configurations.shape[0]
    caps = setup.domain.speed_caps(kinematics.jacobian[n_base:], u_extra)
    samples = ContactSamples(
        kinematics,
        np.vstack([base.directions, u_extra]),
        np.concatenate([base.config_index, n_base + np.arange(len(extra))]),
        speed_cap=np.concatenate([np.asarray(base.speed_cap), caps]),
        drawn=np.concatenate([np.asarray(base.drawn), np.zeros(len(extra), dtype=bool)]),
    )
    return dataclasses.replace(setup, configurations=configurations, samples=samples, searched=len(extra))


def _joint_gearboxes(
    loaded: LoadedStudy, study: ArmStudy, joints: list[str], ratio_bounds: list[Bounds]
) -> tuple[CatalogueGearbox | ScaledGearbox | None, ...] | None:
    """Each joint's gearbox (None: none), or None when no joint has one; every problem located.

    A name is a catalogue entry of ``designs/gearboxes.yaml`` (the schema checks it); figures
    (:class:`~.actuator_specs.GearboxSpec`) become an entry whose ratios are the joint's gear-ratio bounds;
    ``scaled_from`` a :class:`ScaledGearbox` of that entry. A gearbox whose ratios miss the joint's gear-ratio
    bounds is refused, at the gearbox's line (:func:`.checks.gearbox_ratio_problems`).
    """
    catalogue: dict[str, CatalogueGearbox] | None = None
    gearboxes: list[CatalogueGearbox | ScaledGearbox | None] = []
    paths: list[PathKey] = []
    for joint, bounds in zip(joints, ratio_bounds, strict=True):
        override = study.actuators.joints.get(joint)
        path: PathKey = ("actuators", "gearbox")
        spec = study.actuators.gearbox
        if isinstance(spec, list):  # options a run chooses among (transmission_choice); checked as the first
            first = next(i for i, option in enumerate(spec) if option != DIRECT_DRIVE)  # no two direct drives
            path, spec = ("actuators", "gearbox", first), spec[first]
        if override is not None and override.gearbox is not None:
            path, spec = ("actuators", "joints", joint, "gearbox"), override.gearbox
        gearbox: CatalogueGearbox | ScaledGearbox | None = None
        if isinstance(spec, str):  # a catalogue name, checked by the schema
            catalogue = catalogue if catalogue is not None else load_gearbox_catalogue()
            gearbox = catalogue[spec]
            if bounds.is_fixed:  # a joint fixed at one of its ratios has that ratio's figures
                gearbox = gearbox.at_ratio(bounds.lower)
        elif isinstance(spec, ScaledGearboxSpec):
            catalogue = catalogue if catalogue is not None else load_gearbox_catalogue()
            reference = catalogue[spec.scaled_from]
            units = _gearbox_units(loaded, study)
            kind = [unit for unit in units.values() if unit.kind == reference.kind]
            largest = max(kind, key=lambda unit: unit.peak_torque) if kind else None
            gearbox = ScaledGearbox(reference, tuple(spec.ratios or reference.ratios), largest)
        elif spec is not None:
            scaled = gearbox_for(spec)
            assert scaled is not None  # a spec gives a gearbox
            gearbox = scaled.catalogue_entry(
                spec.name or f"{spec.kind} gearbox of {joint}",
                (bounds.lower, bounds.upper),
                peak_torque=spec.peak_torque,
                efficiency=spec.efficiency,
                max_input_speed=spec.max_input_speed,
            )
        gearboxes.append(gearbox)
        paths.append(path)
    raise_problems(loaded, gearbox_ratio_problems(loaded, joints, gearboxes, paths, ratio_bounds))
    return tuple(gearboxes) if any(g is not None for g in gearboxes) else None


def _gearbox_units(loaded: LoadedStudy, study: ArmStudy) -> dict[str, CatalogueGearbox]:
    """The gearboxes one can buy: the study's gearbox catalogue (``catalogue.gearboxes``), else the packaged one."""
    named = study.catalogue.gearboxes
    return load_gearbox_catalogue(None if named is None else loaded.path(named))
