"""``crx fit``: measured impulse and model fit for force-time traces, aggregated like ``tab:one_shot``."""

from __future__ import annotations

import argparse
import errno
import math
import os
import re
import sys
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING

from .._io import atomic_open
from .._units import QuantityError, check_unit, parse_quantity
from ..errors import CollisionReflexError
from ..experiments import analyse_files
from ..plots.impulse_velocity import plot_impulse_velocity
from ..plots.trace_fit import plot_trace_fit
from ..vocabulary import REACTION_MODES
from . import options

if TYPE_CHECKING:
    from ..experiments import ExperimentResults

_DEFAULT_K_M = 2e7  # N/m, the paper's ATI Mini40 along its sensing axis


_HELP = "impulse and model fit of measured force-time traces (CSV)"
_DESCRIPTION = """
For each trial in the CSV files: find the contact above the noise floor, integrate the impulse (adaptive
Gauss-Kronrod quadrature, trapezoid cross-check, uncertainty), and fit the model's force profile (m_f,
k_s, F_s, a and the impact time, with k_m given). Then per system: mean and std of the fitted parameters
(as the paper's table of one-shot fits) and the fit I(v) = A v + B/v + C with v*. Bad traces are reported
with the reason; the others are still processed. Files: '# velocity: 100 mm/s', '# system: NAME' and '#
sensor stiffness: 2e7 N/m' comment lines, then 'time [ms],force [N]' columns (a 'trial' column for many
trials per file).
"""


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add ``crx fit`` and its options to ``subparsers``."""
    parser = options.add_subcommand(subparsers, "fit", _HELP, _DESCRIPTION)
    add = parser.add_argument
    add("traces", nargs="+", metavar="TRACES", help="CSV files, or folders searched for *.csv")
    options.MECH_STIFFNESS.add(parser, _DEFAULT_K_M, note="the sensor's, for trials that do not give it")
    options.BANDWIDTH.add(parser, note="Butterworth", shown="unfiltered")
    options.APPROACH_VELOCITY.add(parser, note="for trials whose file does not give one")
    add("--system", default=None, metavar="NAME", help="system name for trials whose file gives none")
    add(
        "--time-unit",
        default="s",
        type=_unit_of("s"),
        metavar="UNIT",
        help="unit of a time column without one (default s)",
    )
    add(
        "--force-unit",
        default="N",
        type=_unit_of("N"),
        metavar="UNIT",
        help="unit of a force column without one (default N)",
    )
    options.NOISE_SIGMAS.add(parser, 5.0)
    add(
        "--reaction",
        choices=REACTION_MODES,
        default="at_rest",
        help="reaction model fitted (default %(default)s, the paper's)",
    )
    options.add_out_dir(parser, what="trials.csv, one_shot.csv, nshot.csv, rejected.csv and figures")
    add("--no-figures", action="store_true", help="with --out, write the tables only")
    add("--strict", action="store_true", help="exit with status 2 if any trace is rejected")
    parser.set_defaults(run=run)


def _unit_of(si_unit: str) -> Callable[[str], str]:
    """An argparse type: a unit of ``si_unit``'s kind (bounded grammar, dimension checked), or a usage error."""

    def unit(text: str) -> str:
        try:
            parse_quantity(f"1 {check_unit(text)}", si_unit)
        except QuantityError as error:
            raise argparse.ArgumentTypeError(
                f"{text!r:.60} is not a unit of {si_unit}'s kind: {error.reason}"
            ) from None
        return text

    return unit


def run(args: argparse.Namespace) -> int:
    """Run ``crx fit`` with parsed ``args``; return the exit status."""
    if args.out is not None:  # before the analysis: a bad folder loses nothing
        _output_folder(Path(args.out))
    results = analyse_files(
        args.traces,
        time_unit=args.time_unit,
        force_unit=args.force_unit,
        v0=args.v0,
        system=args.system,
        k_m=args.k_m,
        bandwidth=args.bandwidth,
        n_sigma=args.n_sigma,
        reaction=args.reaction,
    )
    for rejected in results.rejected:
        print(f"crx fit: skipped {rejected}", file=sys.stderr)
    if not results.trials:
        raise CollisionReflexError(
            f"no usable trial among {len(results.rejected)} rejected trace(s); see the reasons above"
        )
    _print_trials(results)
    for trial in results.trials:
        for note in trial.fit.notes if trial.fit is not None else ():
            print(f"crx fit: note: {trial.trace.source or trial.trace.label}: {note}", file=sys.stderr)
    _print_summary(results)
    if args.out is not None:
        _write_outputs(Path(args.out), results, figures=not args.no_figures)
    if args.strict and results.rejected:
        print(f"crx fit: error: {len(results.rejected)} trace(s) rejected (--strict)", file=sys.stderr)
        return 2
    return 0


def _print_trials(results: ExperimentResults) -> None:
    print(
        f"{'system':<12}{'trial':<22}{'v0 [m/s]':>10}{'I [N*s]':>12}{'+-':>10}{'trapz':>12}"
        f"{'m_f [kg]':>11}{'k_s [N/m]':>11}{'F_s [N]':>9}{'a [m/s^2]':>11}"
    )
    for t in results.trials:
        v0 = f"{t.trace.v0:>10.4g}" if t.trace.v0 is not None else f"{'-':>10}"
        line = (
            f"{t.trace.system[:11]:<12}{t.trace.label[:21]:<22}{v0}{t.impulse.value:>12.5g}"
            f"{t.impulse.uncertainty:>10.2g}{t.impulse.trapezoid:>12.5g}"
        )
        if t.fit is not None:
            line += f"{t.fit.m_f:>11.4g}{t.fit.k_s:>11.4g}{t.fit.F_s:>9.4g}{t.fit.a:>11.3g}"
        else:
            line += f"  ({t.fit_problem})"
        print(line)


def _print_summary(results: ExperimentResults) -> None:
    summary = results.one_shot_summary()
    print()
    print("one-shot fits, mean ± std over trials (as the paper's table of one-shot fits):")
    for system in results.systems:
        rows = summary[summary["system"] == system]
        parts = []
        for _, row in rows.iterrows():
            if row["trials"] == 0:
                continue
            std = "" if row["std"] is None or math.isnan(row["std"]) else f" ± {row['std']:.2g}"
            parts.append(f"{row['parameter']} = {row['mean']:.4g}{std} {row['unit']}")
        count = int(rows["trials"].max()) if len(rows) else 0
        print(f"  {system or '(no system)'} ({count} fits): " + ("; ".join(parts) if parts else "no fits"))
    fits, problems = results.velocity_laws()
    print()
    print("n-shot fit I(v) = A v + B/v + C:")
    for system in results.systems:
        if system in fits:
            f = fits[system]
            bound = f"  (at bound: {', '.join(f.at_bound)})" if f.at_bound else ""
            print(
                f"  {system or '(no system)'}: A = {f.A:.4g} ± {f.stderr_A:.2g} kg, B = {f.B:.4g} ± {f.stderr_B:.2g} "
                f"N*m, C = {f.C:.4g} ± {f.stderr_C:.2g} N*s, v* = {f.v_star:.4g} ± {f.stderr_v_star:.2g} m/s{bound}"
            )
        else:
            print(f"  {system or '(no system)'}: {problems[system]}")


def _output_folder(out: Path) -> None:
    """Make ``out`` (and its parents), or say in one line why it cannot be written to."""
    if out.exists() and not out.is_dir():
        raise CollisionReflexError(
            f"cannot write to {out}: it is a file, not a folder; give a folder for --out"
        )
    try:
        out.mkdir(parents=True, exist_ok=True)
        if not os.access(out, os.W_OK | os.X_OK):
            raise PermissionError(errno.EACCES, "permission denied")
    except OSError as error:
        raise CollisionReflexError(f"cannot write to {out}: {error.strerror or error}") from None


def _write_outputs(out: Path, results: ExperimentResults, figures: bool) -> None:

    tables = {
        "trials.csv": results.trial_table(),
        "one_shot.csv": results.one_shot_summary(),
        "nshot.csv": results.velocity_law_table(),
        "rejected.csv": results.rejected_table(),
    }
    for name, table in tables.items():
        with atomic_open(out / name) as handle:
            table.to_csv(handle, index=False)
    print(f"\nwrote {', '.join(str(out / name) for name in tables)}")
    if not figures:
        return

    for trial in results.trials:
        stem = re.sub(r"[^A-Za-z0-9_.-]+", "_", f"{trial.trace.system}_{trial.trace.label}".strip("_"))
        plot_trace_fit(out / "traces" / f"{stem}.png", trial)
    written = [f"{len(results.trials)} trace figures in {out / 'traces'}"]
    if any(t.trace.v0 is not None for t in results.trials):
        written.append(str(plot_impulse_velocity(out / "impulse_velocity.png", results)))
    print("wrote " + ", ".join(written))
