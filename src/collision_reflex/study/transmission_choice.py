"""The transmission as a design choice: one of a study's gearbox options per actuator module (or joint).

A study may list two to four gearboxes as ``actuators.gearbox`` (strain-wave, planetary, ... each a catalogue
unit, figures or a unit scaled to its motor; or ``direct_drive``, no gearbox at N = 1). A kind is discrete, so the run tries every assignment of an option
to each module (each joint outside a module, without a gearbox of its own), solves the study's optimum for each
and goes on with the best by the study's objective: its front, catalogue design and report. Every assignment
tried, with its objective or why it has none, is kept for the report.
"""

from __future__ import annotations

import copy
import itertools
from typing import Any

from ..errors import InvalidParameter, SolverFailed, StudyFileError
from ..optimize.catalogue_search import objective_value
from ..optimize.optimum import single_optimum
from ..optimize.pieces import built_problem
from .actuator_specs import DIRECT_DRIVE
from .load import LoadedStudy
from .problems import StudyProblems, checked_setup
from .resolve import ResolvedStudy
from .robot import load_arm

MAX_ASSIGNMENTS = 16
"""Most assignments of gearbox options tried (each one solve of the study's optimum)."""


def gearbox_groups(resolved: dict[str, Any], joints: list[str]) -> list[list[str]]:
    """The joints that take one option together: each module, and each other joint without its own gearbox."""
    actuators = resolved["actuators"]
    own = {j for j, spec in actuators.get("joints", {}).items() if (spec or {}).get("gearbox") is not None}
    modules = [list(group) for group in actuators.get("modules") or []]
    grouped = {j for group in modules for j in group}
    return [g for g in modules if not own & set(g)] + [[j] for j in joints if j not in grouped | own]


def _assign(variant: dict[str, Any], joint: str, option: Any) -> None:
    """Give ``joint`` the gearbox ``option`` in the resolved study ``variant``; direct drive fixes its N at 1."""
    joints = variant["actuators"].setdefault("joints", {})
    spec = joints.get(joint) or {}
    if option != DIRECT_DRIVE:
        joints[joint] = {**spec, "gearbox": option}
        return
    joints[joint] = {**spec, "gearbox": None, "gear_ratio": 1.0}
    ratio = (variant.get("design") or {}).get("gear_ratio")
    if ratio is not None:
        ratio.setdefault("joints", {})[joint] = {"value": 1.0}


def option_name(option: Any) -> str:
    """A gearbox option in a few words: its catalogue name, the unit it is scaled from, or its kind."""
    if option == DIRECT_DRIVE:
        return "direct drive"
    if isinstance(option, str):
        return option
    if "scaled_from" in option:
        return f"{option['scaled_from']} scaled"
    return str(option.get("name") or f"{option['kind']} figures")


def choose_transmissions(
    loaded: LoadedStudy, resolved: ResolvedStudy, saved: dict[str, Any] | None = None
) -> tuple[ResolvedStudy, list[dict[str, Any]]]:
    """The resolved study with the best assignment of its gearbox options, and every assignment tried.

    ``loaded``: the study as written, where problems are located; ``resolved``: what the run solves;
    ``saved``: a :func:`choice_record` of an earlier run, reused when it was made of the same study (a resumed
    run does not solve the assignments again).

    Each entry: ``assignment`` (per group of joints the option's name), ``objective`` (the study's objective at
    the optimum, None without one), ``actuator_mass`` [kg] (None without one), ``status`` and ``chosen``.

    Raises
    ------
    StudyFileError: more than :data:`MAX_ASSIGNMENTS` assignments, or none with a design (the first
        assignment's own refusal when every one is refused, located in the file; else at ``actuators.gearbox``).
    KeyboardInterrupt: Ctrl-C, from any solve.
    """
    options = resolved.data["actuators"]["gearbox"]
    groups = gearbox_groups(resolved.data, list(load_arm(loaded).joint_names))
    assignments = list(itertools.product(range(len(options)), repeat=len(groups)))
    if len(assignments) > MAX_ASSIGNMENTS:
        raise loaded.fail(
            ("actuators", "gearbox"),
            f"{len(options)} gearbox options for {len(groups)} modules or joints: {len(assignments)} assignments",
            f"at most {MAX_ASSIGNMENTS}: group joints into actuators.modules, or list fewer options",
        )

    def variant(assignment: tuple[int, ...]) -> dict[str, Any]:
        data = copy.deepcopy(resolved.data)
        data["actuators"]["gearbox"] = None
        for group, k in zip(groups, assignment, strict=True):
            for joint in group:
                _assign(data, joint, options[k])
        return data

    tried = _reused(saved, resolved, len(assignments))
    if tried is not None:
        chosen_index = next(i for i, entry in enumerate(tried) if entry["chosen"])
        return ResolvedStudy.of(loaded, variant(assignments[chosen_index])), tried
    tried = []
    studies: list[ResolvedStudy | None] = []  # each assignment's, None where it is refused as data
    refusals: list[Exception] = []
    for assignment in assignments:
        entry: dict[str, Any] = {
            "assignment": {
                ", ".join(g): option_name(options[k]) for g, k in zip(groups, assignment, strict=True)
            },
            "objective": None,
            "actuator_mass": None,
            "chosen": False,
        }
        study = None
        try:
            study = ResolvedStudy.of(loaded, variant(assignment))
            checked_setup(loaded, study)  # every problem of this assignment, located in the file as written
            problems = StudyProblems(study)
            optimum, _ = single_optimum(problems, problems.objective, starts=1)
            entry["objective"] = objective_value(
                built_problem(problems, problems.objective), optimum.numpy_objectives
            )
            entry["actuator_mass"] = float(optimum.numpy_objectives["actuator_mass"])
            entry["status"] = optimum.status
        except SolverFailed as error:
            entry["status"] = error.status
        except (InvalidParameter, StudyFileError) as error:  # refused before solving
            entry["status"] = f"refused: {error}"
            refusals.append(error)
        tried.append(entry)
        studies.append(study)
    feasible = [i for i, entry in enumerate(tried) if entry["objective"] is not None]
    if not feasible and len(refusals) == len(tried) and isinstance(refusals[0], StudyFileError):
        raise refusals[0]  # as a study of one gearbox would be refused, at its lines
    if not feasible:
        raise loaded.fail(
            ("actuators", "gearbox"),
            "no gearbox option gives a design: " + "; ".join(str(entry["status"]) for entry in tried[:2]),
            "gearbox options that can carry the study's requirements",
        )
    best = min(feasible, key=lambda i: tried[i]["objective"])
    tried[best]["chosen"] = True
    chosen = studies[best]
    assert chosen is not None  # it has a design
    return chosen, tried


def choice_record(resolved: ResolvedStudy, tried: list[dict[str, Any]]) -> dict[str, Any]:
    """What a run folder keeps of a transmission choice: the assignments tried, for the study as it was written."""
    return {"key": resolved.fingerprint, "tried": tried}


def _reused(saved: dict[str, Any] | None, resolved: ResolvedStudy, count: int) -> list[dict[str, Any]] | None:
    """The assignments tried that ``saved`` holds when it is this study's choice with one chosen, else None."""
    if saved is None or saved.get("key") != resolved.fingerprint:
        return None
    tried = saved.get("tried")
    if not isinstance(tried, list) or len(tried) != count or not all(isinstance(e, dict) for e in tried):
        return None
    if [entry.get("chosen") for entry in tried].count(True) != 1:
        return None
    return tried
