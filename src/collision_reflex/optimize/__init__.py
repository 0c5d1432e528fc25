"""Actuator design optimisation for a URDF arm, and Pareto sets by epsilon-constraint sweeps.

CasADi + IPOPT choose motor size, gear ratio, stiffness, threshold and approach velocity.

Build and solve are separate: :func:`build_problem` returns an inspectable :class:`DesignProblem`,
:func:`solve` runs IPOPT and returns a :class:`DesignResult`; :func:`pareto_front` sweeps objectives into a
:class:`ParetoSet` (in-process or through any executor); :mod:`.results` makes the one result record and table
row of a design; :mod:`.duty` turns a duty cycle into peak, RMS and speed constraints; :func:`snap_to_catalogue` builds the best design
from catalogue parts near a continuous optimum (:class:`CatalogueDesign`).
"""

from .build import build_problem
from .constraints import Constraints
from .design import Design, design_at
from .design_result import DesignResult
from .dominance import hypervolume
from .objectives import OBJECTIVES
from .pareto import ParetoSet, pareto_front
from .problem import DesignProblem
from .samples import ContactSamples
from .snap import CatalogueDesign, snap_to_catalogue
from .solve import solve
from .space import Bounds, DesignSpace
from .technology import ActuatorTechnology

__all__ = [
    "OBJECTIVES",
    "ActuatorTechnology",
    "Bounds",
    "CatalogueDesign",
    "Constraints",
    "ContactSamples",
    "Design",
    "DesignProblem",
    "DesignResult",
    "DesignSpace",
    "ParetoSet",
    "build_problem",
    "design_at",
    "hypervolume",
    "pareto_front",
    "snap_to_catalogue",
    "solve",
]
