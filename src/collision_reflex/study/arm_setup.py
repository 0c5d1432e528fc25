"""An arm study translated into the optimiser's inputs, and a picklable builder of its design problems.

:class:`ArmSetup` holds the robot, motors, design space, actuator technology, constraints and contact samples,
every problem located in the study file. The picklable problem builder (:class:`StudyProblems`) rebuilds the
design problems from the resolved study text in any process (the setup and the problems are built once per
process).
"""

from __future__ import annotations

import dataclasses
import functools
import os
from collections.abc import Hashable, Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, TypedDict

import numpy as np

from ..arm.static_hold import worst_hold_poses
from ..errors import StudyFileError, StudyProblem
from ..optimize.blas import single_threaded_blas
from .duty import payload_of, study_duty_cycle, study_rating
from .load import LoadedStudy, parse_study
from .prepare import check_motors, gearbox_for, joint_actuators, per_joint_bounds
from .robot import load_arm
from .samples import configuration_samples, contact_domain, direction_samples, domain_draw
from .actuator_specs import DIRECT_DRIVE, PlacementRuleSpec, ScaledGearboxSpec
from .design_specs import PER_JOINT_DESIGN_VARIABLES
from .schema import ArmStudy
from .source import PathKey

if TYPE_CHECKING:
    from ..arm import Arm, DutyCycle
    from ..arm.domain import ContactDomain
    from ..arm.rating import Rating
    from ..hardware.gearboxes import CatalogueGearbox, ScaledGearbox
    from ..hardware.motors import Motor
    from ..optimize import ActuatorTechnology, Bounds, Constraints, ContactSamples, DesignProblem, DesignSpace

IPOPT_OPTIONS = {"ipopt.max_iter": 400}
"""Options over the optimiser's defaults for study runs (a cap keeps a hopeless Pareto point from stalling a run)."""


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


def _modules(
    loaded: LoadedStudy, study: ArmStudy, joints: list[str], actuators: list[Any]
) -> tuple[tuple[int, ...], ...]:
    """The study's actuator modules as joint indices; every problem located at ``actuators.modules``.

    A module is one part: its joints must name joints of the arm, each once, and share the motor and gearbox
    the study gives them (one reference motor, one gearbox).
    """
    problems = []
    seen: set[str] = set()
    out = []
    for k, group in enumerate(study.actuators.modules):
        path = ("actuators", "modules", k)
        unknown = [name for name in group if name not in joints]
        twice = [name for name in group if name in seen or group.count(name) > 1]
        seen |= set(group)
        if unknown:
            problems.append(
                loaded.problem(path, f"joint {unknown[0]!r}, not a joint of the arm", ", ".join(joints))
            )
        elif len(group) < 2 or twice:
            problems.append(
                loaded.problem(
                    path,
                    f"{group}" + (f": {twice[0]} in two modules or twice" if twice else ""),
                    "two or more joints, each in one module only",
                )
            )
        else:
            members = [joints.index(name) for name in group]
            parts = {(str(actuators[j].motor), str(actuators[j].gearbox)) for j in members}
            if len(parts) > 1:
                problems.append(
                    loaded.problem(
                        path,
                        f"joints {', '.join(group)} with different motors or gearboxes",
                        "one motor and one gearbox for every joint of a module (actuators.joints overrides "
                        "them per joint)",
                    )
                )
            out.append(tuple(members))
    if problems:
        raise StudyFileError(loaded.source.file, problems)
    return tuple(out)


def arm_setup(loaded: LoadedStudy) -> ArmSetup:
    """Load the robot and motors and translate the study into the optimiser's inputs; every problem located."""
    from ..optimize import ActuatorTechnology, Bounds, Constraints, ContactSamples, DesignSpace
    from ..optimize.technology import placements_from_stiffness

    study = loaded.study
    assert isinstance(study, ArmStudy)
    catalogue = check_motors(loaded)
    arm = load_arm(loaded)
    joints = list(arm.joint_names)
    actuators = joint_actuators(study, joints)
    _check_supported(loaded, study)
    reference_spec = study.actuators.motor
    reference = catalogue[reference_spec.reference]

    def nominal(name: str, values: list[float]) -> list[Any]:
        spec = getattr(study.design, name)
        if spec is None:
            return [Bounds.fixed(v, f"{name}[{j}]") for v, j in zip(values, joints, strict=True)]
        return [
            Bounds(lo, hi, f"{name}[{j}]")
            for (lo, hi), j in zip(per_joint_bounds(spec, joints), joints, strict=True)
        ]

    diameters = [a.motor.stator_diameter or reference.stator_diameter for a in actuators]
    stacks = [a.motor.stack_length or reference.stack_length for a in actuators]
    scheme = study.sensing.scheme
    threshold_spec = study.design.threshold if scheme == "force" else study.design.position_error
    velocity_spec = study.design.approach_velocity
    space = DesignSpace(
        stator_diameter=nominal("stator_diameter", diameters),
        stack_length=nominal("stack_length", stacks),
        gear_ratio=nominal("gear_ratio", [a.gear_ratio for a in actuators]),
        software_stiffness=nominal("software_stiffness", [a.software_stiffness for a in actuators]),
        threshold=Bounds(*threshold_spec.bounds, "threshold") if threshold_spec else study.sensing.value,
        approach_velocity=Bounds(*velocity_spec.bounds, "approach_velocity")
        if velocity_spec
        else study.approach_velocity,
        modules=_modules(loaded, study, joints, actuators),
    )
    gearboxes = _joint_gearboxes(loaded, study, joints, space.per_joint("gear_ratio", len(joints)))
    technology = ActuatorTechnology(
        reference_motor=reference,
        mechanical_stiffness=[a.mechanical_stiffness for a in actuators],
        scaling_law=reference_spec.scaling_law,
        sensing=scheme,
        reaction=study.reaction,
        reflected_inertia_in=_placements(study, joints),
        gearboxes=gearboxes,
        gearbox_inertia=study.actuators.gearbox_inertia,
    )
    duty_cycle = study_duty_cycle(loaded, arm)
    if duty_cycle is not None and study.constraints.torque_required is not None:
        raise StudyFileError(
            loaded.source.file,
            [
                loaded.problem(
                    ("constraints", "torque_required"),
                    "given torques with a duty cycle",
                    "one requirement: remove torque_required (the duty cycle's torques and the static hold "
                    "replace it) or the duty_cycle section",
                )
            ],
        )
    # The static hold's payload: the rated one, else the one the study carries (over its cycle, if any).
    payload = payload_of(study)
    held = study.rating.payload if study.rating.payload is not None else payload.mass if payload else 0.0
    hold = None
    if study.constraints.torque_required is None:  # each joint's worst static pose joins the samples'
        masses = _nominal_actuator_mass(space, technology, len(joints))
        hold = arm.kinematics(worst_hold_poses(arm, held, masses, np.random.default_rng(0)))
    constraints = Constraints(
        payload=held,
        safety_factor=study.constraints.safety_factor,
        torque_required=study.constraints.torque_required,
        threshold_floor=study.constraints.threshold_floor,
        duty_cycle=duty_cycle,
        rating=_study_rating(loaded, arm),
        hold_poses=hold,
    )
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
        duty_cycle=duty_cycle,
        domain_kept=kept,
        placement_ratios=placement_ratios,
    )


def _study_rating(loaded: LoadedStudy, arm: Arm) -> Rating | None:
    """The study's rating; refused at ``constraints.torque_required`` when it moves and torques are given."""
    rating = study_rating(loaded, arm)
    study = loaded.study
    assert isinstance(study, ArmStudy)
    if rating is not None and rating.moves and study.constraints.torque_required is not None:
        raise StudyFileError(
            loaded.source.file,
            [
                loaded.problem(
                    ("constraints", "torque_required"),
                    "given torques with a rated motion",
                    "one requirement: remove torque_required (the rated motion and the static hold replace it) "
                    "or the rating's speeds and accelerations",
                )
            ],
        )
    return rating


ExtraSamples = tuple[tuple[tuple[float, ...], tuple[float, ...]], ...]
"""Samples a worst-case search added, as plain data: ``((q, u), ...)``, q [rad] (nq,), u unit (task_dim,)."""


def with_extra_samples(setup: ArmSetup, extra: ExtraSamples) -> ArmSetup:
    """``setup`` with the samples ``extra`` appended (each its own configuration), in order."""
    from ..optimize import ContactSamples

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


def _check_supported(loaded: LoadedStudy, study: ArmStudy) -> None:
    """Refuse, at their lines, the study features the arm optimiser does not model."""
    problems: list[StudyProblem] = []
    base = study.actuators.motor
    for joint, override in study.actuators.joints.items():
        motor = override.motor
        if motor is not None and (motor.reference != base.reference or motor.scaling_law != base.scaling_law):
            problems.append(
                loaded.problem(
                    ("actuators", "joints", joint, "motor"),
                    "a different reference motor or law",
                    "the same reference motor and scaling law for every joint (the optimiser scales one "
                    "reference); override stator_diameter or stack_length only",
                )
            )
    if problems:
        raise StudyFileError(loaded.source.file, problems)


def _joint_gearboxes(
    loaded: LoadedStudy, study: ArmStudy, joints: list[str], ratio_bounds: list[Bounds]
) -> tuple[CatalogueGearbox | ScaledGearbox | None, ...] | None:
    """Each joint's gearbox (None: none), or None when no joint has one; every problem located.

    A name is a catalogue entry of ``designs/gearboxes.yaml`` (the schema checks it); figures (:class:`GearboxSpec`) become an entry
    whose ratios are the joint's gear-ratio bounds; ``scaled_from`` a :class:`ScaledGearbox` of that entry. A gearbox whose ratios miss the joint's gear-ratio bounds
    is refused here, at the gearbox's line.
    """
    from ..hardware.gearboxes import ScaledGearbox, load_gearbox_catalogue

    catalogue: dict[str, CatalogueGearbox] | None = None
    gearboxes: list[CatalogueGearbox | ScaledGearbox | None] = []
    problems: list[StudyProblem] = []
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
        if gearbox is not None:
            low, high = gearbox.ratio_range
            if max(low, bounds.lower) > min(high, bounds.upper):
                problems.append(
                    loaded.problem(
                        path,
                        f"{gearbox.name} (ratios {low:g} to {high:g}) at {joint}",
                        f"a gearbox whose ratios overlap the gear-ratio bounds of {joint}, "
                        f"{bounds.lower:g} to {bounds.upper:g} (design.gear_ratio, or actuators.gear_ratio "
                        "when it is fixed); widen them or choose another gearbox",
                    )
                )
        gearboxes.append(gearbox)
    if problems:
        raise StudyFileError(loaded.source.file, problems)
    return tuple(gearboxes) if any(g is not None for g in gearboxes) else None


def _gearbox_units(loaded: LoadedStudy, study: ArmStudy) -> dict[str, CatalogueGearbox]:
    """The gearboxes one can buy: the study's gearbox catalogue (``catalogue.gearboxes``), else the packaged one."""
    from ..hardware.gearboxes import load_gearbox_catalogue

    named = study.catalogue.gearboxes
    return load_gearbox_catalogue(None if named is None else loaded.path(named))


@functools.lru_cache(maxsize=4)
def setup_from_text(resolved_text: str, extra: ExtraSamples = ()) -> ArmSetup:
    """The setup of a resolved study with the searched samples ``extra``, built once per process."""
    if extra:
        return with_extra_samples(setup_from_text(resolved_text), extra)
    with single_threaded_blas():  # the same arithmetic in every process (see single_threaded_blas)
        return arm_setup(parse_study(resolved_text, "resolved study"))


def objective_key(objective: Mapping[str, float] | Mapping[Any, float]) -> Hashable:
    """A hashable form of a study's objective.

    Its name alone when it is a single unweighted objective, else sorted ``(name, weight)`` pairs.
    """
    if len(objective) == 1 and next(iter(objective.values())) == 1.0:
        return next(iter(objective))
    return tuple(sorted((str(k), float(v)) for k, v in objective.items()))


@dataclass(frozen=True)
class StudyProblems:
    """The design problems of a resolved study, built from its text in any process.

    Called as :func:`collision_reflex.optimize.pareto.pareto_front` builds them:
    ``StudyProblems(text)(objective, bounded)``, or on some of the samples (an active set)
    ``StudyProblems(text)(objective, bounded, samples)``. Plain text and numbers inside, so it crosses process
    boundaries. ``extra``: samples a worst-case search added to the study's (the exchange method).
    """

    resolved_text: str
    extra: ExtraSamples = ()

    @classmethod
    def of_run(cls, folder: str | os.PathLike[str]) -> StudyProblems:
        """The problems a finished run solved last: its resolved study and the samples its searches added.

        Read from the run folder's ``study.resolved.yaml`` and ``designs.json`` (``domain.searched``).
        """
        import json
        from pathlib import Path

        path = Path(folder)
        results = json.loads((path / "designs.json").read_text(encoding="utf-8"))
        extra = tuple((tuple(q), tuple(u)) for q, u in results["domain"]["searched"])
        return cls((path / "study.resolved.yaml").read_text(encoding="utf-8"), extra)

    def __call__(
        self, objective: Hashable, bounded: tuple[str, ...] = (), samples: ContactSamples | None = None
    ) -> DesignProblem:
        """The design problem for ``objective`` (an :func:`objective_key`), on ``samples`` (default all).

        The objectives named in ``bounded`` can be bounded per solve (epsilon-constraint Pareto sweeps).
        """
        from ..optimize import build_problem

        setup = self.setup
        weighted: Any = objective if isinstance(objective, str) else dict(objective)  # type: ignore[call-overload]
        return build_problem(
            setup.arm,
            setup.samples if samples is None else samples,
            setup.space,
            setup.technology,
            weighted,
            setup.constraints,
            bounded,
        )

    @property
    def setup(self) -> ArmSetup:
        """The study's setup, rebuilt from the resolved text (once per process)."""
        return setup_from_text(self.resolved_text, self.extra)

    @property
    def objective(self) -> Hashable:
        """The study's own objective (for :func:`collision_reflex.optimize.pareto.built_problem`)."""
        return objective_key(self.setup.study.objective)

    @property
    def active_set(self) -> str:
        """How the study's problems are solved: on active sets of the samples or not (``optimizer.active_set``)."""
        return self.setup.study.optimizer.active_set


class SampleLayout(TypedDict):
    """Where each contact sample comes from, as plain data (``designs.json``: ``samples``).

    ``configurations`` are joint positions [rad] (one row per configuration), ``directions`` unit contact
    directions; sample ``i`` is configuration ``config_index[i]`` hit along ``sample_directions[i]``.
    ``task_dim`` is the task-space dimension (2 for a planar arm, 3 otherwise).
    """

    configurations: list[list[float]]
    directions: list[list[float]]
    config_index: list[int]
    sample_directions: list[list[float]]
    joint_names: list[str]
    task_dim: int


def sample_layout(setup: ArmSetup) -> SampleLayout:
    """Where each sample comes from (for the report's surfaces): configuration index and direction per sample."""
    return {
        "configurations": setup.configurations.tolist(),
        "directions": setup.directions.tolist(),
        "config_index": setup.samples.config_index.tolist(),
        "sample_directions": setup.samples.directions.tolist(),
        "joint_names": list(setup.arm.joint_names),
        "task_dim": int(setup.arm.task_dim),
    }


def checked_setup(loaded: LoadedStudy, resolved_text: str) -> ArmSetup:
    """The setup of a study, with its problem built once.

    Every input problem (robot, frames, samples on which the arm cannot move, impossible bounds) is raised
    here, located in the study file, before a run writes anything.
    """
    from ..errors import InvalidParameter
    from ..optimize.pareto import built_problem

    setup = arm_setup(loaded)  # located errors for the robot, motors and names
    unreachable = _torque_out_of_reach(loaded, setup)
    if unreachable:
        raise StudyFileError(loaded.source.file, unreachable)
    try:
        problems = StudyProblems(resolved_text)
        built_problem(problems, problems.objective)
    except InvalidParameter as error:
        if " requirement of " in error.name:  # a motion's requirement: said in full, at what asks for it
            what, _, joint = error.name.rpartition(" requirement of ")
            constraint, _, margin = str(error.value).rpartition(": ")
            hint = f"; {error.hint}" if error.hint else ""
            raise loaded.fail(
                _motion_field(loaded.study, constraint),
                f"{joint}: {margin}",
                f"{error.allowed} ({what}){hint}",
            ) from None
        raise loaded.fail(_field_of(error.name), f"{error}", "inputs the design problem accepts") from None
    return setup


def _torque_out_of_reach(loaded: LoadedStudy, setup: ArmSetup) -> list[StudyProblem]:
    """The torque requirements no design within the bounds can meet.

    A requirement is unmet when the largest motor at the largest gear ratio (torque grows with motor size
    under every scaling law) is short of the safety factor times the need.
    """
    from ..hardware.motors import scaled_motor_quantities

    required = setup.study.constraints.torque_required
    if required is None:
        return []
    joints = list(setup.arm.joint_names)
    n = len(joints)
    references = setup.technology.joint_motors(n)
    diameters = setup.space.per_joint("stator_diameter", n)
    stacks = setup.space.per_joint("stack_length", n, setup.technology.default_stack_lengths(n))
    gears = setup.space.per_joint("gear_ratio", n)
    factor = setup.study.constraints.safety_factor
    problems = []
    for i, joint in enumerate(joints):
        motor = scaled_motor_quantities(
            references[i], diameters[i].upper, stacks[i].upper, setup.technology.scaling_law
        )
        reachable = gears[i].upper * float(motor.peak_torque)
        if factor * required[i] > reachable * (1 + 1e-9):
            problems.append(
                loaded.problem(
                    ("constraints", "torque_required", i),
                    f"{required[i]:g} N*m for {joint} (x {factor:g} safety)",
                    f"at most {reachable:.4g} N*m, the peak torque of the largest motor at the largest gear "
                    "ratio; widen design.stator_diameter or design.gear_ratio, or lower the requirement",
                )
            )
    return problems


def _motion_field(study: Any, constraint: str) -> tuple[str, ...]:
    """Where a motion requirement's refusal belongs: the gearbox, else the rating or the duty cycle."""
    if constraint.startswith("gearbox"):
        return ("actuators", "gearbox")
    rating = study.rating
    moves = rating.joint_speeds is not None or rating.joint_accelerations is not None
    return ("rating",) if moves else ("duty_cycle",)


def _field_of(name: str) -> tuple[str, ...]:
    """The study field an optimiser parameter comes from (for locating its errors)."""
    root = name.split("[")[0].split(" ")[0]
    if root in PER_JOINT_DESIGN_VARIABLES or root in ("threshold", "approach_velocity"):
        return ("design", root)
    if root in ("payload", "safety_factor", "torque_required", "threshold_floor"):
        return ("constraints", root)
    if root in ("sample", "directions", "config_index"):
        return ("samples",)
    return ()
