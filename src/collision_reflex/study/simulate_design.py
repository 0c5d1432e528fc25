"""The recommended design (and optionally each Pareto design) simulated on its worst contact samples.

The study's ``simulate`` section asks for it. For each design, the samples with the largest closed-form
impulse are simulated in the time domain (:func:`collision_reflex.simulate.simulate_arm_collision`: elastic
joints, Pinocchio's forward dynamics, a stiff wall ``contact_stiffness_ratio`` times the joints' stiffness
along ``u``), and the closed form the optimiser used is set beside the simulated impulse. A sample whose two
impulses differ by more than ``tolerance`` lies outside the closed form's validity region and is flagged: the
optimiser's number for it is not to be trusted as it stands (see the validity map,
:mod:`collision_reflex.simulate.validity`).

Each design's simulations are one piece of work of the run folder (``simulation-recommended-<settings>``,
``simulation-pareto-<i>-<settings>``, keyed by a hash of the ``simulate`` section): a resumed run finds them
and does not simulate again; the section is no part of the run's fingerprint, so that a finished run can be
simulated afterwards without solving again.
"""

from __future__ import annotations

import hashlib
import math
from typing import TYPE_CHECKING, Any

import numpy as np

from ..model.impulse import optimal_velocity
from ..optimize.evaluate import design_collision_parameters, evaluate_design
from ..optimize.pieces import built_problem
from ..record.run import DesignSimulation, SimulatedSample
from ..simulate.design_closed_form import JointDesign, arm_closed_form
from ..simulate.validity import MAX_STEPS, available_detections, simulated_impulse

if TYPE_CHECKING:
    from ..optimize import DesignProblem, DesignResult, ParetoSet
    from .problems import StudyProblems
    from .run_specs import SimulateSpec
    from .store import RunFolder


def simulate_designs(
    problems: StudyProblems,
    recommended: DesignResult,
    front: ParetoSet | None,
    spec: SimulateSpec,
    folder: RunFolder,
) -> dict[str, Any]:
    """The ``simulation`` part of ``designs.json``: ``recommended`` and ``pareto`` (one per front point).

    Each design's simulations are saved in ``folder`` as they finish and found again when the run resumes.
    """
    problem = built_problem(problems, problems.objective)
    out: dict[str, Any] = {"recommended": None, "pareto": []}
    jobs: list[tuple[str, DesignResult]] = []
    if spec.recommended:
        jobs.append(("recommended", recommended))
    if spec.pareto and front is not None:
        jobs.extend((f"pareto-{i}", result) for i, result in enumerate(front.points))
    # Keyed by the settings too: a run resumed with other ones simulates again, and keeps the solved designs.
    settings = hashlib.sha256(spec.model_dump_json().encode()).hexdigest()[:8]
    for name, result in jobs:
        key = f"simulation-{name}-{settings}"
        saved = folder.finished(key)
        if saved is None:
            saved = dict(simulate_design(problems, problem, result, spec, name))
            folder.save(key, saved)
        if name == "recommended":
            out["recommended"] = saved
        else:
            out["pareto"].append(saved)
    return out


def simulate_design(
    problems: StudyProblems, problem: DesignProblem, result: DesignResult, spec: SimulateSpec, name: str
) -> DesignSimulation:
    """Simulate one design on its ``spec.samples`` worst contact samples (largest closed-form impulse)."""
    setup = problems.setup
    design = result.design
    detection = spec.detection or available_detections()[0]
    params, threshold = design_collision_parameters(problem, design)
    closed = np.asarray(evaluate_design(problem, design), dtype=float)
    worst = np.argsort(-closed, kind="stable")[: spec.samples]
    rows: list[SimulatedSample] = []
    for s in (int(i) for i in worst):
        joints = JointDesign(
            mechanical_stiffness=design.mechanical_stiffness,
            reflected_inertia=design.reflected_inertia,
            torque_limit=design.peak_torque,
            threshold=float(threshold[s]),
            software_stiffness=design.software_stiffness,
            motor_mass=design.actuator_mass,
        )
        rows.append(
            _sample(
                setup,
                s,
                joints,
                design.approach_velocity,
                float(closed[s]),
                spec.contact_stiffness_ratio * float(params.k_m[s]),
                detection,
                spec.tolerance,
                problem.technology.reaction,
            )
        )
    return {"design": name, "detection": detection, "tolerance": spec.tolerance, "samples": rows}


def _sample(
    setup: Any,
    s: int,
    joints: Any,
    approach_velocity: float,
    closed_form: float,
    contact_stiffness: float,
    detection: str,
    tolerance: float,
    reaction: str,
) -> SimulatedSample:
    """Simulate sample ``s`` of the study; the closed form [N*s] is the optimiser's."""
    config = int(setup.samples.config_index[s])
    q = np.asarray(setup.configurations[config], dtype=float)
    u = np.asarray(setup.samples.directions[s], dtype=float)
    reference = arm_closed_form(setup.arm, q, u, joints, "robot", math.inf, "moving")
    v_star = float(optimal_velocity(reference.m_f, reference.k, joints.threshold))
    run = simulated_impulse(
        setup.arm,
        q,
        u,
        joints,
        approach_velocity,
        contact_stiffness,
        detection,
        reaction,
        MAX_STEPS,
    )
    simulated = None if run.error else run.impulse
    error = run.error
    difference = None if simulated is None else simulated / closed_form - 1
    return {
        "sample": s,
        "configuration": config,
        "q": q.tolist(),
        "u": u.tolist(),
        "approach_velocity": float(approach_velocity),
        "velocity_ratio": float(approach_velocity) / v_star,
        "contact_stiffness": contact_stiffness,
        "closed_form": closed_form,
        "simulated": simulated,
        "difference": difference,
        "valid": difference is not None and abs(difference) <= tolerance,
        "error": error,
    }
