"""The one result record of a design, and the one table row made from it.

The record holds a design's objectives, per-joint quantities, margins and solver status as plain data (JSON
types, SI units); the row is what ``ParetoSet.to_frame``, ``pareto.csv`` and the report's tables show.

A sweep's finished pieces (:class:`SweepPoint`) round-trip through JSON exactly (floats are written with
``repr``), so that a run resumed from saved points gives the numbers of an uninterrupted one.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, cast

import numpy as np

from ..errors import InvalidParameter
from ..model.impulse import optimal_velocity, phase_impulses, series_stiffness
from ..record.design import (
    AttemptRecord,
    DesignRecord,
    Estimate,
    JointRecord,
    PointFailureRecord,
    QuickSnap,
    SolvedJoint,
    SolvedRecord,
)
from ..vocabulary import GLOBAL_VARIABLES
from .active_set_result import ActiveSetResult, solve_method, with_active_set
from .candidates import motor_distance
from .constraints import DUTY_REQUIREMENT, RATED_REQUIREMENT, STATIC_REQUIREMENT
from .design import Design, design_at
from .design_result import DesignResult
from .evaluate import design_collision_parameters, evaluate_design
from .ipopt import Attempt
from .objectives import OBJECTIVES
from .statistics import QUANTILE, impulse_statistics

if TYPE_CHECKING:
    from ..hardware.motors import Motor
    from .problem import DesignProblem

JOINT_COLUMNS = (
    ("stator_diameter", "m"),
    ("stack_length", "m"),
    ("gear_ratio", "-"),
    ("software_stiffness", "N*m/rad"),
    ("reflected_inertia", "kg*m^2"),
    ("peak_torque", "N*m"),
    ("required_torque", "N*m"),
    ("motor_mass", "kg"),
)
"""Per-joint columns of a design's table row: (record key, unit)."""
GEARBOX_COLUMNS = (
    ("gearbox", "-"),
    ("gearbox_mass", "kg"),
    ("gearbox_inertia", "kg*m^2"),
    ("gearbox_efficiency", "-"),
    ("actuator_mass", "kg"),
)
"""Per-joint columns a design with a gearbox at any joint adds to its row: (record key, unit). ``gearbox`` is
the catalogue name (empty for none), ``gearbox_inertia`` its input-side inertia, ``actuator_mass`` the motor's
and the gearbox's mass together."""
DUTY_COLUMNS = (
    ("torque_margin", "-"),
    ("required_rms_torque", "N*m"),
    ("rms_margin", "-"),
    ("max_motor_speed", "rad/s"),
    ("speed_limit", "rad/s"),
    ("speed_margin", "-"),
)
"""Per-joint columns a design sized by a duty cycle adds to its row: (record key, unit). A margin without a
requirement (a joint the cycle neither loads nor moves) is None, an empty cell in a CSV file."""
DUTY_ARRAYS = ("required_rms_torque", "rms_margin", "max_motor_speed", "speed_limit", "speed_margin")
"""The per-joint results of a duty cycle's requirements (None without one)."""


def threshold_unit(sensing: str) -> str:
    """The unit of a design's threshold: a force [N] for force sensing, a position error [m] otherwise."""
    return "N" if sensing == "force" else "m"


@dataclass(frozen=True)
class PointFailure:
    """A solve of a sweep that did not succeed: which objective was minimised under which bounds, and why.

    objective: the minimised objective; epsilon: the bounds on the others [their units] (empty for an anchor's
    first solve); status: the solver's return status; message: its explanation.
    """

    objective: str
    epsilon: dict[str, float]
    status: str
    message: str

    def as_dict(self) -> PointFailureRecord:
        """The failure as JSON types."""
        return {
            "objective": self.objective,
            "epsilon": dict(self.epsilon),
            "status": self.status,
            "message": self.message,
        }

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> PointFailure:
        """The failure written by :meth:`as_dict`."""
        return cls(str(data["objective"]), dict(data["epsilon"]), str(data["status"]), str(data["message"]))


@dataclass(frozen=True)
class SweepPoint:
    """One finished piece of a Pareto sweep.

    label: what was solved (``"anchor: actuator_mass"``, ``"epsilon: actuator_mass <= 0.1"``, ``"optimum"``);
    result: the design found, or None if the solve failed; failures: the solves that failed on the way (a failed
    point's own solve, or an anchor's lexicographic steps, whose anchor then is the one found so far);
    start: for the first objective's anchor, its solution on the sweep's own problem (point and multipliers),
    from which every epsilon point starts; None otherwise.
    """

    label: str
    result: DesignResult | None
    failures: tuple[PointFailure, ...] = field(default=())
    start: DesignResult | None = None

    def to_json(self) -> dict[str, Any]:
        """The piece as JSON types (floats round-trip exactly)."""
        return {
            "label": self.label,
            "result": None if self.result is None else result_to_json(self.result),
            "failures": [f.as_dict() for f in self.failures],
            "start": None if self.start is None else result_to_json(self.start),
        }

    @classmethod
    def from_json(cls, data: Mapping[str, Any]) -> SweepPoint:
        """The piece written by :meth:`to_json` (bitwise the same numbers)."""
        result, start = data["result"], data.get("start")
        return cls(
            str(data["label"]),
            None if result is None else result_from_json(result),
            tuple(PointFailure.from_dict(f) for f in data["failures"]),
            None if start is None else result_from_json(start),
        )


_DESIGN_ARRAYS = (
    "stator_diameter",
    "stack_length",
    "gear_ratio",
    "software_stiffness",
    "mechanical_stiffness",
    "rotor_inertia",
    "reflected_inertia",
    "motor_peak_torque",
    "peak_torque",
    "motor_mass",
)
_GEARBOX_ARRAYS = ("gearbox_mass", "gearbox_inertia", "gearbox_efficiency")
"""The design's gearbox arrays; a result saved before gearboxes has none (no gearbox at any joint)."""


def result_to_json(result: DesignResult) -> dict[str, Any]:
    """A :class:`DesignResult` as JSON types, with its solver attempts and multipliers (for warm starts)."""
    multipliers = result.multipliers
    return {
        "design": result.design.as_dict(),
        "objectives": dict(result.objectives),
        "numpy_objectives": dict(result.numpy_objectives),
        "impulses": np.asarray(result.impulses, dtype=float).tolist(),
        "required_torque": np.asarray(result.required_torque, dtype=float).tolist(),
        "torque_margin": np.asarray(result.torque_margin, dtype=float).tolist(),
        "status": result.status,
        "success": bool(result.success),
        "iterations": int(result.iterations),
        "solve_time": float(result.solve_time),
        "build_time": float(result.build_time),
        "epsilon": {k: float(v) for k, v in result.epsilon.items()},
        "requirement": result.requirement,
        **{name: _optional_list(getattr(result, name)) for name in DUTY_ARRAYS},
        "x": np.asarray(result.x, dtype=float).tolist(),
        "attempts": attempt_records(result.attempts),
        "multipliers": None
        if multipliers is None
        else [np.asarray(m, dtype=float).tolist() for m in multipliers],
        **({"active_set": _active_set_json(result)} if isinstance(result, ActiveSetResult) else {}),
    }


def attempt_records(attempts: tuple[Attempt, ...]) -> list[AttemptRecord]:
    """Every IPOPT run of a solve (retries included) as JSON: name, status, iterations, ``solve_time`` [s]."""
    return [
        {
            "name": a.name,
            "status": a.status,
            "iterations": int(a.iterations),
            "solve_time": float(a.solve_time),
        }
        for a in attempts
    ]


def _optional_list(values: np.ndarray | None) -> list[float | None] | None:
    """An optional per-joint array as a JSON list; an infinite margin (no requirement) as None (JSON has no inf)."""
    if values is None:
        return None
    return [float(v) if math.isfinite(v) else None for v in np.asarray(values, dtype=float)]


def _optional_array(values: list[float | None] | None) -> np.ndarray | None:
    """The array written by :func:`_optional_list` (None entries back to inf)."""
    if values is None:
        return None
    return np.array([math.inf if v is None else v for v in values], dtype=float)


def result_from_json(data: Mapping[str, Any]) -> DesignResult:
    """The :class:`DesignResult` written by :func:`result_to_json` (bitwise the same numbers)."""
    saved = data["design"]
    result = _result_from_json(data, saved)
    active = data.get("active_set")
    if active is None:
        return result
    last = active.get("last_round")
    return with_active_set(result, active, None if last is None else result_from_json(last))


def _active_set_json(result: ActiveSetResult) -> dict[str, Any]:
    """The active set of a result as JSON types, with its last NLP's result (a warm start of the next)."""
    last = result.last_round
    return {**result.active_set_json(), "last_round": None if last is None else result_to_json(last)}


def _result_from_json(data: Mapping[str, Any], saved: Mapping[str, Any]) -> DesignResult:
    design = Design(
        joint_names=tuple(saved["joint_names"]),
        **{name: np.asarray(saved[name], dtype=float) for name in _DESIGN_ARRAYS},
        threshold=float(saved["threshold"]),
        approach_velocity=float(saved["approach_velocity"]),
        sensing=str(saved["sensing"]),
        gearbox=tuple(saved.get("gearbox", ())),
        **{name: np.asarray(saved.get(name, ()), dtype=float) for name in _GEARBOX_ARRAYS},
    )
    return DesignResult(
        design=design,
        objectives=dict(data["objectives"]),
        numpy_objectives=dict(data["numpy_objectives"]),
        impulses=np.asarray(data["impulses"], dtype=float),
        required_torque=np.asarray(data["required_torque"], dtype=float),
        torque_margin=np.asarray(data["torque_margin"], dtype=float),
        status=str(data["status"]),
        success=bool(data["success"]),
        iterations=int(data["iterations"]),
        solve_time=float(data["solve_time"]),
        build_time=float(data["build_time"]),
        epsilon=dict(data["epsilon"]),
        requirement=str(data.get("requirement", STATIC_REQUIREMENT)),
        required_rms_torque=_optional_array(data.get("required_rms_torque")),
        rms_margin=_optional_array(data.get("rms_margin")),
        max_motor_speed=_optional_array(data.get("max_motor_speed")),
        speed_limit=_optional_array(data.get("speed_limit")),
        speed_margin=_optional_array(data.get("speed_margin")),
        x=np.asarray(data["x"], dtype=float),
        multipliers=(
            None
            if data.get("multipliers") is None
            else (
                np.asarray(data["multipliers"][0], dtype=float),
                np.asarray(data["multipliers"][1], dtype=float),
            )
        ),
        attempts=tuple(
            Attempt(str(a["name"]), str(a["status"]), int(a["iterations"]), float(a["solve_time"]))
            for a in data.get("attempts", ())
        ),
    )


def record_design(record: SolvedRecord | DesignRecord, sensing: str) -> Design:
    """The :class:`~.solve.Design` a design record holds, to evaluate it anew.

    ``record``: as :func:`result_record` writes it (``designs.json``); ``sensing``: the study's scheme
    (``force`` or ``position``).
    """
    joints: Sequence[Mapping[str, Any]] = record["joints"]

    def column(name: str) -> np.ndarray:
        return np.array([joint[name] for joint in joints], dtype=float)

    names = (
        "stator_diameter stack_length gear_ratio software_stiffness mechanical_stiffness rotor_inertia "
        "reflected_inertia motor_peak_torque peak_torque motor_mass gearbox_mass gearbox_inertia "
        "gearbox_efficiency"
    ).split()
    return Design(
        joint_names=tuple(joint["joint"] for joint in joints),
        threshold=float(record["threshold"]),
        approach_velocity=float(record["approach_velocity"]),
        sensing=sensing,
        gearbox=tuple(joint["gearbox"] for joint in joints),
        **{name: column(name) for name in names},
    )


def result_record(result: DesignResult, label: str) -> SolvedRecord:
    """A design and its solve as plain data: objectives, per-joint quantities and margins, solver status."""
    design = result.design
    method, active = solve_method(result)
    joints: list[SolvedJoint] = []
    for i, name in enumerate(design.joint_names):
        joints.append(
            {
                "joint": name,
                "stator_diameter": float(design.stator_diameter[i]),
                "stack_length": float(design.stack_length[i]),
                "gear_ratio": float(design.gear_ratio[i]),
                "rotor_inertia": float(design.rotor_inertia[i]),
                "reflected_inertia": float(design.reflected_inertia[i]),
                "motor_peak_torque": float(design.motor_peak_torque[i]),
                "peak_torque": float(design.peak_torque[i]),
                "required_torque": float(result.required_torque[i]),
                # No requirement (a joint gravity does not load): a margin is meaningless, not a huge number.
                "torque_margin": (
                    float(result.torque_margin[i])
                    if result.required_torque[i] > 1e-9 * design.driving_peak_torque[i]
                    else None
                ),
                "mechanical_stiffness": float(design.mechanical_stiffness[i]),
                "software_stiffness": float(design.software_stiffness[i]),
                "stiffness": float(
                    series_stiffness(design.mechanical_stiffness[i], design.software_stiffness[i])
                ),
                "motor_mass": float(design.motor_mass[i]),
                "gearbox": design.gearbox[i],
                "gearbox_mass": float(design.gearbox_mass[i]),
                "gearbox_inertia": float(design.gearbox_inertia[i]),
                "gearbox_efficiency": float(design.gearbox_efficiency[i]),
                "actuator_mass": float(design.actuator_mass[i]),
                "required_rms_torque": _finite_entry(result.required_rms_torque, i),
                "rms_margin": _finite_entry(result.rms_margin, i),
                "max_motor_speed": _finite_entry(result.max_motor_speed, i),
                "speed_limit": _finite_entry(result.speed_limit, i),
                "speed_margin": _finite_entry(result.speed_margin, i),
            }
        )
    return {
        "label": label,
        "requirement": result.requirement,
        "objectives": {k: float(v) for k, v in result.numpy_objectives.items()},
        "casadi_objectives": {k: float(v) for k, v in result.objectives.items()},
        "threshold": float(design.threshold),
        "sensing": design.sensing,
        "approach_velocity": float(design.approach_velocity),
        "joints": joints,
        "impulses": np.asarray(result.impulses, dtype=float).tolist(),
        "solver": {
            "status": result.status,
            "iterations": int(result.iterations),
            "solve_time": float(result.solve_time),
            "build_time": float(result.build_time),
            "epsilon": {k: float(v) for k, v in result.epsilon.items()},
            "attempts": attempt_records(result.attempts),
            "method": method,
            "active_samples": active,
        },
    }


def _finite_entry(values: np.ndarray | None, index: int) -> float | None:
    """Entry ``index`` of an optional per-joint array; None where there is no array or no requirement (inf)."""
    if values is None or not math.isfinite(values[index]):
        return None
    return float(values[index])


def design_record(
    problem: DesignProblem,
    result: DesignResult,
    label: str,
    catalogue: Mapping[str, Motor] | None = None,
) -> DesignRecord:
    """:func:`result_record` with what a report shows about the collisions.

    That is the impulse phases [N*s] and the optimal approach velocity [m/s] per sample (from ``problem``'s
    samples), the mean and the :data:`~.statistics.QUANTILE` quantile of the impulse over the drawn samples with
    their sampling errors (``statistics``, :func:`~.statistics.impulse_statistics`), and per joint what sets
    its required peak torque (``required_by``, :func:`required_by`) and
    its nearest catalogue motor.
    """
    solved = result_record(result, label)
    design = result.design
    reaction = problem.technology.reaction
    params, threshold = design_collision_parameters(problem, design)
    phases = phase_impulses(
        params.m_f, params.k, params.k_m, threshold, params.a, design.approach_velocity, reaction
    )
    v_star = optimal_velocity(params.m_f, params.k, threshold, reaction, params.k_m, params.a)
    drawn = np.asarray(problem.samples.drawn)
    statistics = {
        name: cast("Estimate", estimate.to_json())
        for name, estimate in impulse_statistics(
            np.asarray(result.impulses)[drawn], problem.samples.config_index[drawn]
        ).items()
    }
    statistics["quantile_impulse"]["quantile"] = QUANTILE
    sizing = required_by(problem, design, np.asarray(result.required_torque, dtype=float))
    owner = problem.space.module_of(len(solved["joints"]))
    joints: list[JointRecord] = []
    for i, joint in enumerate(solved["joints"]):
        nearest = (
            nearest_catalogue_motor(
                catalogue, float(design.motor_peak_torque[i]), float(design.rotor_inertia[i])
            )
            if catalogue
            else None
        )
        module = [problem.joint_names[k] for k, o in enumerate(owner) if o == owner[i]]
        if len(module) > 1:
            joints.append(
                {**joint, "required_by": sizing[i], "module": module, "nearest_catalogue_motor": nearest}
            )
        else:
            joints.append({**joint, "required_by": sizing[i], "nearest_catalogue_motor": nearest})
    return {
        **solved,
        "joints": joints,
        "phases": {
            "initial": np.broadcast_to(phases.initial, params.m_f.shape).tolist(),
            "sensing": np.broadcast_to(phases.sensing, params.m_f.shape).tolist(),
            "reaction": np.broadcast_to(phases.reaction, params.m_f.shape).tolist(),
        },
        "optimal_velocity": np.asarray(v_star, dtype=float).tolist(),
        "statistics": statistics,
    }


def required_by(problem: DesignProblem, design: Design, required: np.ndarray) -> list[str | None]:
    """Per joint what sets its required peak torque ``required`` [N m], None where nothing is required.

    One of ``static hold`` (or ``given torque``), ``duty cycle``, ``rated motion``, ``braking``: the requirement
    whose own peak (safety factor included) is the largest at ``design``; for a joint of a module whose
    requirement comes from another of its joints, ``"braking of <joint>"``.
    """
    static = np.asarray(problem.static_torque_function(design.actuator_mass), dtype=float).ravel()
    given = problem.constraints.torque_required is not None
    peaks = {"given torque" if given else "static hold": static}
    duty = problem.duty
    if duty is not None:
        demand = np.abs(duty.demand(design.actuator_mass, design.reflected_inertia))
        sources = np.array(duty.torques.sources)
        for source in dict.fromkeys(duty.torques.sources):
            peaks[source] = duty.safety_factor * demand[sources == source].max(axis=0)
    names, values = list(peaks), np.array(list(peaks.values()))
    own = values.max(axis=0)
    owner = problem.space.module_of(required.size)
    out: list[str | None] = []
    for j in range(required.size):
        # A module meets the largest requirement of its joints: name the joint it comes from.
        k = max((m for m in range(required.size) if owner[m] == owner[j]), key=lambda m: own[m])
        source = names[int(np.argmax(values[:, k]))]
        out.append(
            None if required[j] <= 0 else source if k == j else f"{source} of {problem.joint_names[k]}"
        )
    return out


UNDECIDED_TOLERANCE = 1e-9
"""Largest relative change of any sample's impulse, and of the actuator mass, with which a design variable
moved over its bounds decides nothing (:func:`undecided_variables`): far below the solver's tolerance (1e-8 on
its scaled optimality error, about 1e-7 on the objectives), far above round-off."""
UNDECIDED_PROBES = 5
"""Values per variable tried by :func:`undecided_variables`: its bounds first, then evenly spaced in between (in
its logarithm, as the optimiser sees it)."""


def undecided_variables(problem: DesignProblem, x: np.ndarray) -> list[tuple[str, int | None]]:
    """The design variables of ``x`` that no objective decides, as ``(variable, joint index)`` pairs.

    Moving one anywhere within its bounds, with the rest of the design held, changes no sample's impulse and not
    the actuator mass. The objectives (every impulse statistic, the actuator mass and the approach velocity)
    then take the same values whatever the variable is, so the optimiser leaves it where its start put it. A
    joint that no contact sample loads (its axis through every contact point, as a last wrist joint's often is)
    has such a software stiffness and gear ratio. Each free variable (bounds not equal) is tried at
    :data:`UNDECIDED_PROBES` values, the bounds first, and counts as undecided when every change is within
    :data:`UNDECIDED_TOLERANCE` (NumPy path, :func:`collision_reflex.optimize.evaluate.evaluate_design`). The
    joint index is None for a global variable (threshold, approach velocity).
    """
    x = np.asarray(x, dtype=float)

    def outcome(point: np.ndarray) -> tuple[np.ndarray, float]:
        design = design_at(problem, point)
        with np.errstate(all="ignore"):
            return evaluate_design(problem, design), float(np.sum(design.actuator_mass))

    impulses, mass = outcome(x)

    def unchanged(index: int, value: float) -> bool:
        moved = x.copy()
        moved[index] = value
        try:
            other_impulses, other_mass = outcome(moved)
        except (InvalidParameter, ValueError, ArithmeticError):  # a design the model refuses: not unchanged
            return False
        return bool(
            np.all(np.abs(other_impulses - impulses) <= UNDECIDED_TOLERANCE * np.abs(impulses))
            and abs(other_mass - mass) <= UNDECIDED_TOLERANCE * abs(mass)
        )

    found: list[tuple[str, int | None]] = []
    for name, indices in problem.layout.slices.items():
        for joint, index in enumerate(indices):
            if index is None or problem.lbx[index] == problem.ubx[index]:
                continue
            inner = np.linspace(problem.lbx[index], problem.ubx[index], UNDECIDED_PROBES)
            values = [inner[0], inner[-1], *inner[1:-1]]
            if all(unchanged(index, float(value)) for value in values):
                found.append((name, None if name in GLOBAL_VARIABLES else joint))
    return found


def nearest_catalogue_motor(catalogue: Mapping[str, Motor], peak_torque: float, rotor_inertia: float) -> str:
    """The catalogue motor closest to a scaled motor (peak torque [N*m], rotor inertia [kg*m^2]).

    Closest in (log peak torque, log rotor inertia): the off-the-shelf part a designer would start from.
    """
    best, best_distance = "", math.inf
    for name, motor in catalogue.items():
        distance = motor_distance(motor, peak_torque, rotor_inertia)
        if distance < best_distance:
            best, best_distance = name, distance
    return best


def record_row(record: SolvedRecord | DesignRecord, index: int) -> dict[str, Any]:
    """The table row of a design record, every column name with its unit.

    ``pareto.csv``, the report's table and :meth:`ParetoSet.to_frame` are made of these.
    """
    row: dict[str, Any] = {"point": index, "label": record["label"]}
    for name, value in record["objectives"].items():
        row[f"{name} [{OBJECTIVES[name][1]}]"] = value
    geared = any(joint.get("gearbox") for joint in record["joints"])
    columns = (
        JOINT_COLUMNS
        + (GEARBOX_COLUMNS if geared else ())
        + (DUTY_COLUMNS if record.get("requirement") in (DUTY_REQUIREMENT, RATED_REQUIREMENT) else ())
    )
    joints: Sequence[Mapping[str, Any]] = record["joints"]  # the columns' keys, by name
    for key, unit in columns:
        for joint in joints:
            row[f"{key}[{joint['joint']}] [{unit}]"] = joint[key]
    row[f"threshold [{threshold_unit(record['sensing'])}]"] = record["threshold"]
    row.update(catalogue_columns(record))
    row["status"] = record["solver"]["status"]
    row["iterations"] = record["solver"]["iterations"]
    row["solve_time [s]"] = record["solver"]["solve_time"]
    return row


NO_PART = "none within bounds"
"""A catalogue-part cell of a joint with no catalogue part within the design's bounds."""


def catalogue_columns(record: SolvedRecord | DesignRecord) -> dict[str, Any]:
    """A design's catalogue snap as table columns (none when the record has no snap).

    Per joint the catalogue part (``catalogue_part[joint1]``, :data:`NO_PART` when none is within bounds), then
    whether the catalogue design meets every requirement as snapped and its objectives [their units], empty
    without parts (:func:`collision_reflex.study.catalogue_snap.quick_snap_record`).
    """
    snapped = cast("QuickSnap | None", record.get("catalogue"))  # a solved record has none
    if snapped is None:
        return {}
    row: dict[str, Any] = {}
    for joint, part in zip(record["joints"], snapped["parts"], strict=True):
        row[f"catalogue_part[{joint['joint']}]"] = NO_PART if part is None else part
    row["catalogue_feasible"] = snapped["feasible"]
    for name, (_, unit, _) in OBJECTIVES.items():
        row[f"catalogue_{name} [{unit}]"] = snapped["objectives"].get(name)
    return row
