"""Reading traces (units, metadata, many trials per file), bad traces with their reasons, and `crx fit`."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import collision_reflex as cr
from collision_reflex.cli import main
from collision_reflex.experiments import (
    PAPER_SYSTEMS,
    SensorModel,
    analyse_files,
    read_traces,
    synthetic_trace,
    write_example_dataset,
    write_trace,
)

RATE = 3500.0
SHIPPED = Path(__file__).resolve().parents[1] / "studies" / "traces"


def _trace(v0=0.08, seed=1, **kwargs):
    return synthetic_trace(
        PAPER_SYSTEMS["U8 stiff"], v0, SensorModel(RATE), np.random.default_rng(seed), **kwargs
    )


def test_units_in_headers_and_metadata_are_converted(tmp_path):
    trace = _trace()
    path = tmp_path / "trial.csv"
    lines = [
        "# velocity: 80 mm/s",
        "# system: U8 stiff",
        "# sensor stiffness: 20 N/um",
        "# operator: someone",
        "Time (ms), Force [mN]",
    ]
    lines += [f"{t * 1e3:.9g},{f * 1e3:.9g}" for t, f in zip(trace.time, trace.force, strict=True)]
    path.write_text("\n".join(lines) + "\n")
    (read,) = read_traces(path)
    np.testing.assert_allclose(read.time, trace.time, rtol=1e-8, atol=1e-15)
    np.testing.assert_allclose(read.force, trace.force, rtol=1e-8, atol=1e-12)
    assert (read.v0, read.system, read.k_m) == (pytest.approx(0.08), "U8 stiff", pytest.approx(2e7))
    assert read.metadata == {"operator": "someone"}
    assert read.lines[0] == 6  # the first sample is on the file's sixth line


def test_units_given_by_the_caller_and_many_trials_per_file(tmp_path):
    rows = []
    for name, v0 in (("slow", 0.05), ("fast", 0.12)):
        trace = _trace(v0)
        rows.append(
            pd.DataFrame(
                {
                    "trial": name,
                    "time": trace.time * 1e3,
                    "force": trace.force,
                    "velocity [mm/s]": v0 * 1e3,
                    "system": "U8 stiff",
                }
            )
        )
    path = tmp_path / "many.csv"
    pd.concat(rows).to_csv(path, index=False)
    traces = read_traces(path, time_unit="ms")
    assert [t.name for t in traces] == ["slow", "fast"]
    assert [t.v0 for t in traces] == [pytest.approx(0.05), pytest.approx(0.12)]
    assert traces[0].time[1] == pytest.approx(1 / RATE)


def _write_bad_traces(folder: Path) -> dict[str, str]:
    """One good trial and one of each kind of bad trace; returns file name -> expected reason."""
    good = _trace(seed=2)
    write_trace(folder / "good.csv", good)
    write_trace(folder / "short.csv", cr.experiments.Trace(good.time[:12], good.force[:12], v0=0.08))
    quiet = _trace(seed=3)
    write_trace(folder / "no_contact.csv", cr.experiments.Trace(quiet.time[:60], quiet.force[:60], v0=0.08))
    clipped = _trace(seed=4, noise=0.05)
    clipped_sensor = SensorModel(RATE, 1000.0, full_scale=2.5)  # saturates below F_s = 3.03 N
    clipped = synthetic_trace(PAPER_SYSTEMS["U8 stiff"], 0.08, clipped_sensor, np.random.default_rng(4))
    write_trace(folder / "clipped.csv", clipped)
    backwards = good.time.copy()
    backwards[100], backwards[101] = backwards[101], backwards[100]
    write_trace(folder / "time.csv", cr.experiments.Trace(backwards, good.force, v0=0.08))
    holes = good.force.copy()
    holes[50] = np.nan
    write_trace(folder / "nan.csv", cr.experiments.Trace(good.time, holes, v0=0.08))
    cut = _trace(seed=5)
    write_trace(folder / "unfinished.csv", cr.experiments.Trace(cut.time[:150], cut.force[:150], v0=0.08))
    (folder / "columns.csv").write_text("seconds,newtons\n0,1\n")
    (folder / "unit.csv").write_text((folder / "good.csv").read_text().replace("time [ms]", "time [kg]"))
    (folder / "text.csv").write_text(
        (folder / "good.csv").read_text().replace("\n0.571428571,", "\n0.571428571,oops\n0.6,", 1)
    )
    return {
        "short.csv": "too short: 12 samples",
        "no_contact.csv": "no contact",
        "clipped.csv": "clipped",
        "time.csv": "non-monotonic time",
        "nan.csv": "missing or non-numeric force",
        "unfinished.csv": "contact still on at the end",
        "columns.csv": "no time column",
        "unit.csv": "unit 'kg' is not a unit of s's kind",
        "text.csv": "missing or non-numeric",
    }


def test_each_bad_trace_gets_its_reason_and_the_good_one_is_processed(tmp_path):
    expected = _write_bad_traces(tmp_path)
    results = analyse_files([tmp_path])
    assert [Path(t.trace.source).name for t in results.trials] == ["good.csv"]
    assert results.trials[0].fit is not None
    reasons = {Path(r.source).name: r for r in results.rejected}
    assert set(reasons) == set(expected)
    for name, phrase in expected.items():
        assert phrase in reasons[name].reason, (name, reasons[name].reason)
    # Where the problem is one line, the line is given: the swapped sample sits on data row 101.
    for name, row in (("time.csv", 101), ("nan.csv", 50)):
        header = 1 + sum(line.startswith("#") for line in (tmp_path / name).read_text().splitlines())
        assert reasons[name].line == header + 1 + row


def test_cli_reports_bad_traces_and_writes_outputs(tmp_path):
    _write_bad_traces(tmp_path / "in")
    out = tmp_path / "out"
    done = subprocess.run(
        [sys.executable, "-m", "collision_reflex", "fit", str(tmp_path / "in"), "--out", str(out)],
        capture_output=True,
        text=True,
    )
    assert done.returncode == 0, done.stderr
    skipped = [line for line in done.stderr.splitlines() if line.startswith("crx fit: skipped")]
    assert len(skipped) == 9 and "Traceback" not in done.stderr
    assert "good" in done.stdout and "table of one-shot fits" in done.stdout
    trials = pd.read_csv(out / "trials.csv")
    assert list(trials["trial"]) == ["good"]
    assert len(pd.read_csv(out / "rejected.csv")) == 9
    assert (out / "traces").is_dir() and any((out / "traces").iterdir())
    # --strict: the same report, but a rejected trace makes the exit status 2.
    small = tmp_path / "small"
    small.mkdir()
    for name in ("good.csv", "short.csv"):
        (small / name).write_text((tmp_path / "in" / name).read_text())
    assert main(["fit", str(small), "--strict"]) == 2


def test_cli_with_no_usable_trace_exits_2_with_one_line(tmp_path):
    (tmp_path / "bad.csv").write_text("time,force\n0,nan\n")
    done = subprocess.run(
        [sys.executable, "-m", "collision_reflex", "fit", str(tmp_path / "bad.csv")],
        capture_output=True,
        text=True,
    )
    assert done.returncode == 2
    assert done.stderr.count("\n") == 2  # the skipped trace, then the error
    assert "crx fit: error: no usable trial" in done.stderr and "Traceback" not in done.stderr


def test_cli_on_the_shipped_example_recovers_the_paper_systems(tmp_path, capsys):
    assert (
        main(["fit", str(SHIPPED / "u8_soft"), "--bandwidth", "1000", "--out", str(tmp_path), "--no-figures"])
        == 0
    )
    summary = pd.read_csv(tmp_path / "one_shot.csv").set_index("parameter")
    truth = PAPER_SYSTEMS["U8 soft"]
    # Trials scatter by a lognormal 10 % around the system (EXAMPLE_SPREAD): 5 trials put the mean within
    # ~3 standard errors, i.e. 3 * 10 % / sqrt(5) = 13 %.
    for name in ("m_f", "k_s", "F_s", "a"):
        assert summary.loc[name, "mean"] == pytest.approx(getattr(truth, name), rel=0.13)
    nshot = pd.read_csv(tmp_path / "nshot.csv")
    assert nshot.loc[0, "trials"] == 5


def test_shipped_example_dataset_is_what_the_generator_writes(tmp_path):
    written = write_example_dataset(tmp_path)
    assert len(written) == len(list(SHIPPED.rglob("*.csv")))
    for path in written:
        shipped = SHIPPED / path.relative_to(tmp_path)
        # Same seed, same files: numbers agree to the 6 significant digits written.
        ours, theirs = (pd.read_csv(p, comment="#").to_numpy() for p in (path, shipped))
        np.testing.assert_allclose(ours, theirs, rtol=1e-5, atol=1e-6)


def test_help_names_units():
    done = subprocess.run(
        [sys.executable, "-m", "collision_reflex", "fit", "--help"],
        capture_output=True,
        text=True,
        check=True,
    )
    for unit in ("[N/m]", "[Hz]", "[m/s]"):
        assert unit in done.stdout
