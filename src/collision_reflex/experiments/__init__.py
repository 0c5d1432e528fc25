"""Collision experiments: force-time traces, the measured impulse, and the model fitted to them.

The paper's experiment pipeline (Bhatia, Mason and Johnson, "Reacting to Contact: Transparency and Collision
Reflex in Actuation", §Experiments): force-time traces read from CSV (:mod:`.traces`), the contact window
above the noise floor (:mod:`.window`), the impulse by adaptive Gauss-Kronrod quadrature with a trapezoid
cross-check and an uncertainty (:mod:`.quadrature`), the sensor as it samples the model (:mod:`.sensor`), the
one-shot least-squares fit of the model's force profile (:mod:`.fit`), the n-shot fit of ``I(v)``
(:mod:`.nshot`), the run over many trials with aggregation (:mod:`.analysis`), and synthetic traces
(:mod:`.synthetic`).
"""

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
from .sensor import SensorModel, model_samples, pulse_duration
from .synthetic import (
    MINI40_NOISE,
    PAPER_SYSTEMS,
    TrueParameters,
    synthetic_trace,
    write_example_dataset,
)
from .traces import Trace, read_traces, write_trace
from .window import ContactWindow, NoiseFloor, find_contact

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
    "pulse_duration",
    "read_traces",
    "synthetic_trace",
    "write_example_dataset",
    "write_trace",
]
