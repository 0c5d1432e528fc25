"""collision-reflex: design optimisation of robot actuators for a gentle collision reflex.

The collision reflex is the total impulse a robot transfers to a rigid object when it runs into it, detects the
contact and backs away (Bhatia, Mason and Johnson, "Reacting to Contact: Transparency and Collision Reflex in
Actuation"). This package evaluates it from structure, actuation, stiffness and sensing, for single actuators and
URDF arms, and optimises actuator designs against it.

The root holds the design workflow (load and run a study; build, solve, sweep a Pareto front, snap to catalogue
parts; export and report), its core types and its two most common errors. Everything else is in its subpackage:
:mod:`.arm`, :mod:`.hardware`, :mod:`.model`, :mod:`.optimize`, :mod:`.simulate`, :mod:`.study`, :mod:`.export`,
:mod:`.report`, :mod:`.experiments`, :mod:`.errors` and the closed vocabularies in :mod:`.vocabulary`.

Every name is imported on first use (PEP 562), so that ``import collision_reflex`` and the ``crx`` command start
without loading CasADi, SciPy, Pinocchio or Matplotlib.
"""

from __future__ import annotations

from ._lazy import lazy_attributes

__version__ = "0.1.0"

# The workflow's names, each from the subpackage (or, for run_study, the module) that exports it.
_WORKFLOW: dict[str, tuple[str, ...]] = {
    ".study": ("load_study",),
    ".study.runner": ("run_study",),
    ".optimize": (
        "ActuatorTechnology",
        "Constraints",
        "ContactSamples",
        "DesignProblem",
        "DesignResult",
        "DesignSpace",
        "ParetoSet",
        "build_problem",
        "pareto_front",
        "snap_to_catalogue",
        "solve",
    ),
    ".export": ("export_design",),
    ".report": ("render_report",),
    ".arm": ("Arm",),
    ".hardware": ("Actuator", "Motor", "reference_motor"),
    ".model": ("optimal_velocity", "total_impulse"),
    ".errors": ("CollisionReflexError", "InvalidParameter"),
}

__all__ = ["__version__", *sorted(name for names in _WORKFLOW.values() for name in names)]

__getattr__, __dir__ = lazy_attributes(
    globals(), {name: (package, name) for package, names in _WORKFLOW.items() for name in names}, __all__
)
