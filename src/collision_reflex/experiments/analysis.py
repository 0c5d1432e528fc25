"""The experiment pipeline over many trials: read, check, measure, fit, aggregate, tabulate.

Every trial is processed on its own: a bad trace (unreadable file, too short, NaNs, time not increasing, no
contact, clipped, contact not finished, fit failure) is recorded with its reason and the others go on.
"""

from __future__ import annotations

import os
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import CollisionReflexError, TraceError
from .fit import PAPER_SENSOR_STIFFNESS, PARAMETER_UNITS, PARAMETERS, OneShotFit, fit_one_shot
from .nshot import VelocityLawFit, fit_velocity_law
from .quadrature import ImpulseEstimate, measure_impulse
from .traces import Trace, read_traces
from .window import ContactWindow, find_contact


@dataclass(frozen=True)
class Rejected:
    """A trace (or a whole file) that could not be analysed.

    Attributes
    ----------
    source: the file. trial: the trial's name (``""`` for the whole file or a one-trial file).
    reason: why. line: the file line concerned, if one is.
    """

    source: str
    trial: str
    reason: str
    line: int | None = None

    def __str__(self) -> str:
        return str(TraceError(self.source, self.trial, self.reason, self.line))


@dataclass(frozen=True)
class TrialResult:
    """One analysed trial: its trace, contact window, measured impulse, and (if ``v0`` is known) its fit.

    ``fit_problem`` says why there is no fit (no velocity given, or the fit failed).
    """

    trace: Trace
    window: ContactWindow
    impulse: ImpulseEstimate
    fit: OneShotFit | None = None
    fit_problem: str = ""


@dataclass(frozen=True)
class ExperimentResults:
    """All trials of a run: the analysed ones and the rejected ones."""

    trials: tuple[TrialResult, ...]
    rejected: tuple[Rejected, ...]

    @property
    def systems(self) -> list[str]:
        """System names in order of first appearance."""
        return list(dict.fromkeys(t.trace.system for t in self.trials))

    def trial_table(self) -> Any:
        """One row per analysed trial (a pandas DataFrame): impulse, its uncertainty, fitted parameters."""
        import pandas as pd

        rows = []
        for t in self.trials:
            row: dict[str, Any] = {
                "system": t.trace.system,
                "trial": t.trace.label,
                "source": t.trace.source,
                "velocity [m/s]": t.trace.v0,
                "impulse [N*s]": t.impulse.value,
                "impulse trapezoid [N*s]": t.impulse.trapezoid,
                "impulse stderr [N*s]": t.impulse.uncertainty,
                "contact [s]": t.impulse.duration,
                "noise [N]": t.window.floor.sigma,
            }
            if t.fit is not None:
                for name in (*PARAMETERS, "impact_time"):
                    unit = PARAMETER_UNITS[name]
                    row[f"{name} [{unit}]"] = getattr(t.fit, name)
                    row[f"{name} stderr [{unit}]"] = t.fit.stderr[name]
                phases = t.fit.phases
                for name in ("initial", "sensing", "reaction", "total"):
                    row[f"model {name} [N*s]"] = float(getattr(phases, name))
                row["k_m [N/m]"] = t.fit.k_m
                row["fit rms [N]"] = t.fit.residual_rms
            row["fit note"] = "; ".join([t.fit_problem] if t.fit is None else t.fit.notes)
            rows.append(row)
        return pd.DataFrame(rows)

    def one_shot_summary(self) -> Any:
        """Mean and standard deviation of each fitted parameter over the trials of each system.

        As the paper's ``tab:one_shot`` (a pandas DataFrame, one row per system and parameter). A parameter
        that a trial's fit could not identify (infinite uncertainty) is left out of that parameter's mean.
        """
        import pandas as pd

        rows = []
        for system in self.systems:
            fits = [t.fit for t in self.trials if t.trace.system == system and t.fit is not None]
            for name in PARAMETERS:
                values = np.array([getattr(f, name) for f in fits if np.isfinite(f.stderr[name])])
                rows.append(
                    {
                        "system": system,
                        "parameter": name,
                        "unit": PARAMETER_UNITS[name],
                        "mean": float(values.mean()) if values.size else None,
                        "std": float(values.std(ddof=1)) if values.size > 1 else None,
                        "trials": int(values.size),
                    }
                )
        return pd.DataFrame(rows)

    def velocity_law(self, system: str) -> VelocityLawFit:
        """The n-shot fit ``I(v) = A v + B/v + C`` over the measured impulses of ``system``'s trials."""
        chosen = [t for t in self.trials if t.trace.system == system and t.trace.v0 is not None]
        return fit_velocity_law(
            np.array([t.trace.v0 for t in chosen], dtype=float),
            np.array([t.impulse.value for t in chosen]),
            np.array([t.impulse.uncertainty for t in chosen]),
        )

    def velocity_laws(self) -> tuple[dict[str, VelocityLawFit], dict[str, str]]:
        """The n-shot fit of every system that has one, and why the others have none."""
        fits, problems = {}, {}
        for system in self.systems:
            try:
                fits[system] = self.velocity_law(system)
            except CollisionReflexError as error:
                problems[system] = str(error)
        return fits, problems

    def velocity_law_table(self) -> Any:
        """The n-shot fits as a pandas DataFrame, one row per system."""
        import pandas as pd

        fits, problems = self.velocity_laws()
        rows = []
        for system in self.systems:
            if system in fits:
                f = fits[system]
                rows.append(
                    {
                        "system": system,
                        "A [kg]": f.A,
                        "A stderr [kg]": f.stderr_A,
                        "B [N*m]": f.B,
                        "B stderr [N*m]": f.stderr_B,
                        "C [N*s]": f.C,
                        "C stderr [N*s]": f.stderr_C,
                        "v* [m/s]": f.v_star,
                        "v* stderr [m/s]": f.stderr_v_star,
                        "trials": f.trials,
                        "note": ("at bound: " + ", ".join(f.at_bound)) if f.at_bound else "",
                    }
                )
            else:
                rows.append({"system": system, "note": problems[system]})
        return pd.DataFrame(rows)

    def rejected_table(self) -> Any:
        """The rejected traces as a pandas DataFrame."""
        import pandas as pd

        return pd.DataFrame(
            [
                {"source": r.source, "trial": r.trial, "line": r.line, "reason": r.reason}
                for r in self.rejected
            ],
            columns=["source", "trial", "line", "reason"],
        )


def analyse_trace(
    trace: Trace,
    *,
    k_m: float = PAPER_SENSOR_STIFFNESS,
    bandwidth: float | None = None,
    n_sigma: float = 5.0,
    reaction: str = "at_rest",
) -> TrialResult:
    """Contact window, impulse and (when ``trace.v0`` is known) one-shot fit of one trace.

    Parameters
    ----------
    trace: the trial.
    k_m: sensor stiffness [N/m] when the trace does not give its own.
    bandwidth: the sensor's low-pass cutoff [Hz], ``None`` for unfiltered samples.
    n_sigma: contact threshold above the noise floor, in noise standard deviations.
    reaction: the model's reaction, ``"at_rest"`` (the paper's) or ``"moving"``.

    Raises
    ------
    TraceError: the trace cannot be measured (see :func:`find_contact`).
    """
    window = find_contact(trace, n_sigma)
    impulse = measure_impulse(trace, window)
    if trace.v0 is None:
        return TrialResult(trace, window, impulse, None, "no pre-impact velocity: impulse only")
    try:
        fit = fit_one_shot(trace, window, k_m=k_m, bandwidth=bandwidth, reaction=reaction)
    except CollisionReflexError as error:
        return TrialResult(trace, window, impulse, None, str(error))
    return TrialResult(trace, window, impulse, fit)


def analyse_traces(traces: Iterable[Trace], **options: Any) -> ExperimentResults:
    """:func:`analyse_trace` on each trace; those that fail are listed in ``rejected`` with their reason."""
    done, rejected = [], []
    for trace in traces:
        try:
            done.append(analyse_trace(trace, **options))
        except TraceError as error:
            rejected.append(Rejected(error.source, error.trial, error.reason, error.line))
    return ExperimentResults(tuple(done), tuple(rejected))


def analyse_files(
    paths: Sequence[str | os.PathLike[str]],
    *,
    time_unit: str = "s",
    force_unit: str = "N",
    v0: float | None = None,
    system: str | None = None,
    **options: Any,
) -> ExperimentResults:
    """Read every file (a folder: its ``*.csv`` files, sorted) and analyse every trial.

    ``time_unit``, ``force_unit``, ``v0`` (pre-impact velocity [m/s]) and
    ``system`` are passed to :func:`read_traces`;
    the other options (``k_m``, ``bandwidth``, ``n_sigma``, ``reaction``) to :func:`analyse_trace`.
    An unreadable file is rejected as a whole; the other files are still processed.
    """
    traces: list[Trace] = []
    rejected: list[Rejected] = []
    for path in _expand(paths):
        try:
            traces.extend(
                read_traces(
                    path,
                    time_unit=time_unit,
                    force_unit=force_unit,
                    v0=v0,
                    system=system,
                    k_m=options.get("k_m"),
                )
            )
        except TraceError as error:
            rejected.append(Rejected(error.source, error.trial, error.reason, error.line))
    options = {key: value for key, value in options.items() if value is not None}
    results = analyse_traces(traces, **options)
    return ExperimentResults(results.trials, tuple(rejected) + results.rejected)


def _expand(paths: Sequence[str | os.PathLike[str]]) -> list[Path]:
    expanded: list[Path] = []
    for path in map(Path, paths):
        expanded.extend(sorted(path.rglob("*.csv")) if path.is_dir() else [path])
    return expanded
