"""Collision experiments: force-time traces, the measured impulse, and the model fitted to them.

The paper's experiment pipeline (Bhatia, Mason and Johnson, "Reacting to Contact: Transparency and Collision
Reflex in Actuation", §Experiments): force-time traces read from CSV (:mod:`.traces`), the contact window
above the noise floor (:mod:`.window`), the impulse by adaptive Gauss-Kronrod quadrature with a trapezoid
cross-check and an uncertainty (:mod:`.quadrature`), the sensor as it samples the model (:mod:`.sensor`), the
one-shot least-squares fit of the model's force profile (:mod:`.fit`), the n-shot fit of ``I(v)``
(:mod:`.nshot`), the run over many trials with aggregation (:mod:`.analysis`), and synthetic traces
(:mod:`.synthetic`).

Every public name is imported on first use (PEP 562): a module that needs :mod:`.traces` alone (the duty
cycle's CSV units) does not load the fits and the analysis.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from .._lazy import lazy_attributes

if TYPE_CHECKING:  # the names as type checkers and IDEs see them; at run time `__getattr__` imports them
    from .analysis import (
        ExperimentResults,
        Rejected,
        TrialResult,
        analyse_files,
        analyse_trace,
        analyse_traces,
    )
    from .fit import PAPER_SENSOR_STIFFNESS, PARAMETERS, OneShotFit, fit_one_shot
    from .nshot import VelocityLawFit, fit_velocity_law
    from .quadrature import ImpulseEstimate, measure_impulse
    from .sensor import SensorModel, model_samples
    from .synthetic import (
        MINI40_NOISE,
        PAPER_SYSTEMS,
        TrueParameters,
        synthetic_trace,
        write_example_dataset,
    )
    from .traces import Trace, read_traces, write_trace
    from .window import ContactWindow, NoiseFloor, find_contact

# Where each public name is defined (module relative to this package: names).
_EXPORTS: dict[str, tuple[str, ...]] = {
    ".analysis": (
        "ExperimentResults",
        "Rejected",
        "TrialResult",
        "analyse_files",
        "analyse_trace",
        "analyse_traces",
    ),
    ".fit": (
        "PAPER_SENSOR_STIFFNESS",
        "PARAMETERS",
        "OneShotFit",
        "fit_one_shot",
    ),
    ".nshot": (
        "VelocityLawFit",
        "fit_velocity_law",
    ),
    ".quadrature": (
        "ImpulseEstimate",
        "measure_impulse",
    ),
    ".sensor": (
        "SensorModel",
        "model_samples",
    ),
    ".synthetic": (
        "MINI40_NOISE",
        "PAPER_SYSTEMS",
        "TrueParameters",
        "synthetic_trace",
        "write_example_dataset",
    ),
    ".traces": (
        "Trace",
        "read_traces",
        "write_trace",
    ),
    ".window": (
        "ContactWindow",
        "NoiseFloor",
        "find_contact",
    ),
}

__all__ = [
    "MINI40_NOISE",
    "PAPER_SENSOR_STIFFNESS",
    "PAPER_SYSTEMS",
    "PARAMETERS",
    "ContactWindow",
    "ExperimentResults",
    "ImpulseEstimate",
    "NoiseFloor",
    "OneShotFit",
    "Rejected",
    "SensorModel",
    "Trace",
    "TrialResult",
    "TrueParameters",
    "VelocityLawFit",
    "analyse_files",
    "analyse_trace",
    "analyse_traces",
    "find_contact",
    "fit_one_shot",
    "fit_velocity_law",
    "measure_impulse",
    "model_samples",
    "read_traces",
    "synthetic_trace",
    "write_example_dataset",
    "write_trace",
]

if not TYPE_CHECKING:  # hidden from type checkers, so that a misspelt name is still an error for them
    __getattr__, __dir__ = lazy_attributes(
        globals(), {name: (module, name) for module, names in _EXPORTS.items() for name in names}, __all__
    )
