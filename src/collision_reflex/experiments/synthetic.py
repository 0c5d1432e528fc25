"""Synthetic force-time traces from the model, as a sensor would record them.

Used by the tests (parameter recovery with known truth) and to make the example data set shipped with the
toolkit. The force profile is :func:`collision_reflex.model.force_profile`; the sensor is
:class:`~collision_reflex.experiments.SensorModel` (interval means, optional low-pass, optional saturation).
On top come a constant bias and white Gaussian noise drawn from an explicit ``numpy.random.Generator``.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .. import _validate
from ..model.impulse import collision_times, series_stiffness
from .fit import PAPER_SENSOR_STIFFNESS
from .sensor import SensorModel, model_samples
from .traces import Trace, write_trace

MINI40_NOISE = 0.05
"""Noise used for realistic traces [N], one standard deviation: a few counts of the ATI Mini40's force
resolution (1/50 N in Fz for its SI-40-2 calibration, ATI's datasheet), as streamed over a network link."""


@dataclass(frozen=True)
class TrueParameters:
    """Model parameters of a synthetic system.

    Attributes
    ----------
    m_f: finger mass [kg]. k_s: software stiffness [N/m]. F_s: sensing threshold [N].
    a: reaction acceleration [m/s^2]. k_m: mechanical (sensor) stiffness [N/m].
    """

    m_f: float
    k_s: float
    F_s: float
    a: float
    k_m: float = PAPER_SENSOR_STIFFNESS

    def __post_init__(self) -> None:
        for name in ("m_f", "k_s", "F_s", "a", "k_m"):
            _validate.positive(name, getattr(self, name))

    @property
    def k(self) -> float:
        """Lumped sensing stiffness [N/m]."""
        return float(series_stiffness(self.k_m, self.k_s))


PAPER_SYSTEMS: Mapping[str, TrueParameters] = {
    # Means of the paper's tab:one_shot (its a row is in mm/s^2, its k_s row in N/mm).
    "U8 soft": TrueParameters(m_f=0.1, k_s=440.0, F_s=3.00, a=4.7e-5),
    "U8 stiff": TrueParameters(m_f=0.145, k_s=1070.0, F_s=3.03, a=7.0e-3),
    "A8": TrueParameters(m_f=20.04, k_s=23.7e3, F_s=40.85, a=3.1e-3),
}
"""The systems of the paper's 1D experiments, with the mean parameters of its one-shot fits."""


def synthetic_trace(
    truth: TrueParameters,
    v0: float,
    sensor: SensorModel,
    rng: np.random.Generator,
    *,
    noise: float = MINI40_NOISE,
    bias: float = 0.0,
    impact_time: float | None = None,
    pre_impact: float = 0.02,
    post_contact: float = 0.02,
    reaction: str = "at_rest",
    system: str = "",
    name: str = "",
) -> Trace:
    """A trace of one collision of ``truth`` at ``v0`` as ``sensor`` records it.

    Parameters
    ----------
    truth: the model parameters.
    v0: pre-impact velocity [m/s].
    sensor: sampling rate [Hz], bandwidth [Hz] and range [N] of the sensor.
    rng: the random generator for the noise and the impact's sub-sample phase.
    noise: standard deviation of the white measurement noise [N].
    bias: constant sensor offset [N] (the noise floor's level).
    impact_time: time of impact on the trace's clock [s]; default ``pre_impact`` plus a random fraction of a
        sample, so the impact falls anywhere within a sampling interval.
    pre_impact: recording time before the impact [s].
    post_contact: recording time after the contact ends [s] (also lets the filter settle).
    reaction: the reaction model, ``"at_rest"`` or ``"moving"``.
    system, name: labels stored in the trace.
    """
    _validate.positive("v0", v0)
    _validate.non_negative("noise", noise)
    _validate.non_negative("pre_impact", pre_impact)
    _validate.non_negative("post_contact", post_contact)
    if impact_time is None:
        impact_time = pre_impact + float(rng.uniform(0.0, sensor.period))
    model = (truth.m_f, truth.k, truth.k_m, truth.F_s, truth.a, v0)
    _, t2 = collision_times(*model, reaction)
    count = int(np.ceil((impact_time + float(t2) + post_contact) * sensor.sampling_rate)) + 1
    time = np.arange(count) * sensor.period
    force = model_samples(time, *model, impact_time, sensor, reaction)
    force = sensor.saturated(force + bias + rng.normal(0.0, noise, count) if noise > 0 else force + bias)
    return Trace(
        time,
        force,
        v0=v0,
        system=system,
        name=name,
        k_m=truth.k_m,
        metadata={"synthetic": f"impact at {impact_time:.9g} s, noise {noise:g} N"},
    )


EXAMPLE_VELOCITIES: Mapping[str, tuple[float, ...]] = {
    # Below each system's v* (the paper: "both systems are operating at v0 < v*"), spread over a decade.
    "U8 soft": (0.03, 0.05, 0.08, 0.12, 0.2),
    "U8 stiff": (0.03, 0.05, 0.08, 0.12, 0.2),
    "A8": (0.004, 0.006, 0.01, 0.015, 0.025),
}
EXAMPLE_SEED = 20210607
EXAMPLE_SAMPLING_RATE = 3500.0  # Hz, the paper's
EXAMPLE_BANDWIDTH = 1000.0  # Hz, low-pass of the example sensor
EXAMPLE_SPREAD = 0.1  # trial-to-trial spread of the parameters (lognormal sigma): repeated trials differ


def write_example_dataset(directory: str | os.PathLike[str], seed: int = EXAMPLE_SEED) -> list[Path]:
    """Write the example data set: one CSV per trial, a folder per system of :data:`PAPER_SYSTEMS`.

    Traces at 3500 Hz through a 1 kHz second-order low-pass with :data:`MINI40_NOISE` noise and a small
    bias, at the velocities of :data:`EXAMPLE_VELOCITIES`. Each trial's parameters scatter around the system's
    by a lognormal factor of sigma :data:`EXAMPLE_SPREAD` (real trials repeat imperfectly), so the aggregated
    fits have a spread as in ``tab:one_shot``. The same seed gives the same files.
    """
    rng = np.random.default_rng(seed)
    sensor = SensorModel(EXAMPLE_SAMPLING_RATE, EXAMPLE_BANDWIDTH)
    written = []
    for system, truth in PAPER_SYSTEMS.items():
        folder = Path(directory) / system.lower().replace(" ", "_")
        for velocity in EXAMPLE_VELOCITIES[system]:
            name = f"{system.lower().replace(' ', '_')}_v{velocity * 1000:g}mm"
            factors = np.exp(rng.normal(0.0, EXAMPLE_SPREAD, 4))
            trial_truth = TrueParameters(
                truth.m_f * factors[0],
                truth.k_s * factors[1],
                truth.F_s * factors[2],
                truth.a * factors[3],
                truth.k_m,
            )
            trace = synthetic_trace(
                trial_truth,
                velocity,
                sensor,
                rng,
                bias=float(rng.normal(0.0, 0.2)),
                system=system,
                name=name,
            )
            written.append(write_trace(folder / f"{name}.csv", trace))
    return written
