"""``crx fit`` on hostile files and hard traces: located errors, a noise floor where there is no contact, fits
that say when the model does not describe a trace or a parameter is not identifiable, and an impact time found
however far the centroid guess is off.

Tolerances come from the noise: the reported one-sigma uncertainties (of the impulse, of ``m_f``), with
four of them allowed, so that the 26 % and 27-36 % errors of the reproductions fail by orders of magnitude.
"""

from __future__ import annotations

import math
import shutil
from pathlib import Path

import numpy as np
import pytest

import collision_reflex as cr
import collision_reflex.experiments as ex
from collision_reflex.cli import main
from collision_reflex.errors import TraceError
from collision_reflex.experiments.fit import RESIDUAL_LIMIT

GOOD = Path(__file__).resolve().parents[1] / "studies" / "traces" / "u8_soft" / "u8_soft_v30mm.csv"
SIGMAS = 4.0  # allowed deviation in reported standard deviations: 6e-5 two-sided for a Gaussian
# The reproduction's U8-like system whose impact pulse is resolved (~21 samples at 3.5 kHz).
RESOLVED = ex.TrueParameters(m_f=0.19, k_s=4460.0, F_s=6.76, a=25.9, k_m=13245.0)


def exact_impulse(truth: ex.TrueParameters, v0: float) -> float:
    return float(cr.total_impulse(truth.m_f, truth.k, truth.k_m, truth.F_s, truth.a, v0))


def test_a_malformed_header_is_located_and_the_good_file_still_processed(tmp_path, capsys) -> None:
    bad = tmp_path / "x.csv"
    bad.write_text("time [ms,force [N]\n0,0\n")
    shutil.copy(GOOD, tmp_path / "good.csv")
    assert main(["fit", str(bad), str(tmp_path / "good.csv")]) == 0
    out, err = capsys.readouterr()
    assert err.splitlines()[0] == (
        f"crx fit: skipped {bad}, line 1: column header 'time [ms' is not a name with an optional unit in "
        "brackets, e.g. 'time [ms]'"
    )
    assert "Traceback" not in err and "U8 soft" in out  # the good file was fitted


def test_random_printable_headers_never_crash(tmp_path) -> None:
    rng = np.random.default_rng(15)
    printable = np.array([chr(c) for c in range(32, 127)])
    for i in range(200):
        header = "".join(rng.choice(printable, size=int(rng.integers(1, 30))))
        path = tmp_path / f"r{i}.csv"
        path.write_text(header + "\n0,0\n1,2\n")
        try:
            ex.read_traces(path)
        except TraceError as error:
            assert "\n" not in str(error)


def test_a_slow_approach_is_measured_against_the_floor_before_the_pulse() -> None:
    # Reproduction: at 5 mm/s the ramp fills 90 % of the trace; the first quarter was taken as the floor and the
    # trace was rejected as "no contact".
    truth = ex.PAPER_SYSTEMS["U8 soft"]
    trace = ex.synthetic_trace(
        truth, 0.005, ex.SensorModel(3500.0, bandwidth=1000.0), np.random.default_rng(0), noise=0.05
    )
    result = ex.analyse_trace(trace, bandwidth=1000.0)
    floor = result.window.floor
    assert abs(floor.level) < SIGMAS * floor.sigma / math.sqrt(floor.samples)  # the true level is 0
    assert floor.sigma == pytest.approx(0.05, rel=0.3)  # the filter lowers white noise a little
    assert abs(result.impulse.value - exact_impulse(truth, 0.005)) < SIGMAS * result.impulse.uncertainty
    assert result.fit is not None and not result.fit.notes


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_resolved_pulse_impulse_and_finger_mass_within_their_noise(seed: int) -> None:
    # Reproduction: impulse 0.338 against 0.459 (-26 %, floor from the ramp), then m_f 27-36 % high with
    # residuals 1.4-3.8 x the noise (the impact time searched +-3 samples around a wrong centroid guess).
    trace = ex.synthetic_trace(
        RESOLVED, 0.016, ex.SensorModel(3500.0), np.random.default_rng(seed), noise=0.029
    )
    result = ex.analyse_trace(trace, k_m=RESOLVED.k_m)
    assert abs(result.impulse.value - exact_impulse(RESOLVED, 0.016)) < SIGMAS * result.impulse.uncertainty
    fit = result.fit
    assert fit is not None and not fit.notes
    assert abs(fit.m_f - RESOLVED.m_f) < SIGMAS * fit.stderr["m_f"]
    assert fit.stderr["m_f"] < 0.02 * RESOLVED.m_f  # and that uncertainty is a tight one
    assert fit.residual_rms < RESIDUAL_LIMIT * result.window.floor.sigma


@pytest.mark.parametrize("seed", [4, 49, 74])
def test_a_clean_resolved_trace_is_fitted_down_to_its_noise(seed: int) -> None:
    # Reproduction (issue 33): of 50 seeded clean traces (seeds 0-49) the fit stopped in a poorer local optimum
    # on seeds 4 and 49, residual 1.34 and 1.26 x the noise where the true parameters give 1.01 and 0.98 (seed 4's
    # impact time 0.5 samples late), and said nothing; seed 74 (of seeds 50-199) at 1.51, 1.47 x its floor.
    # The pulse's end sat on a sample boundary, where its jump kinks the sampled cost.
    noise, sensor = 0.029, ex.SensorModel(3500.0)
    trace = ex.synthetic_trace(RESOLVED, 0.016, sensor, np.random.default_rng(seed), noise=noise)
    fit = ex.analyse_trace(trace, k_m=RESOLVED.k_m).fit
    assert fit is not None and not fit.notes
    impact = float(trace.metadata["synthetic"].split()[2])
    exact = ex.model_samples(
        trace.time, RESOLVED.m_f, RESOLVED.k, RESOLVED.k_m, RESOLVED.F_s, RESOLVED.a, 0.016, impact, sensor
    )
    truth_rms = float(np.sqrt(np.mean((trace.force - exact) ** 2)))
    # Least squares is no worse than the true parameters, one point of its search (1e-3: the solver's stop) ...
    assert fit.residual_rms <= 1.001 * truth_rms
    # ... and at the noise floor: an rms of n samples of the noise is sigma within sigma / sqrt(2 n).
    assert fit.residual_rms < noise * (1 + SIGMAS / math.sqrt(2 * trace.time.size))
    assert abs(fit.m_f - RESOLVED.m_f) < SIGMAS * fit.stderr["m_f"]
    assert abs(fit.impact_time - impact) < SIGMAS * fit.stderr["impact_time"]


def test_a_fit_far_above_the_noise_is_flagged() -> None:
    # A resonance the model does not have: a 20-sigma ringing at 300 Hz through the contact.
    trace = ex.synthetic_trace(RESOLVED, 0.016, ex.SensorModel(3500.0), np.random.default_rng(0), noise=0.029)
    window = ex.find_contact(trace)
    ringing = np.zeros_like(trace.force)
    span = trace.time[window.slice] - trace.time[window.start]
    ringing[window.slice] = 20 * 0.029 * np.sin(2 * np.pi * 300.0 * span)
    hostile = ex.Trace(trace.time, trace.force + ringing, v0=trace.v0, k_m=trace.k_m)
    fit = ex.analyse_trace(hostile, k_m=RESOLVED.k_m).fit
    assert fit is not None
    assert fit.residual_rms > RESIDUAL_LIMIT * ex.find_contact(hostile).floor.sigma
    assert any("times the noise floor" in note for note in fit.notes)


@pytest.mark.parametrize("seed", [0, 1, 2, 3])
def test_a_reaction_inside_one_sample_is_not_identifiable(seed: int) -> None:
    # Reproduction: the reaction (4e-5 s) falls into one 2.9e-4 s sample with detection; pinv dropped the
    # direction and reported a = 24 +- 1.4e-5 against a true 210.
    truth = ex.TrueParameters(m_f=0.1, k_s=440.0, F_s=3.0, a=210.0)
    trace = ex.synthetic_trace(truth, 0.1, ex.SensorModel(3500.0), np.random.default_rng(seed), noise=0.02)
    fit = ex.analyse_trace(trace).fit
    assert fit is not None
    assert fit.stderr["a"] == math.inf
    assert fit.phase_stderr["reaction"] == math.inf and fit.phase_stderr["total"] == math.inf
    assert any(note.startswith("not identifiable: a") for note in fit.notes)
    # What the samples do determine stays determined: m_f from the pulse's area, k_s from the ramp.
    assert abs(fit.m_f - truth.m_f) < SIGMAS * fit.stderr["m_f"] < 0.01 * truth.m_f
    assert abs(fit.k_s - truth.k_s) < SIGMAS * fit.stderr["k_s"]


def test_an_unidentifiable_parameter_is_left_out_of_the_system_mean() -> None:
    truth = ex.TrueParameters(m_f=0.1, k_s=440.0, F_s=3.0, a=210.0)
    traces = [
        ex.synthetic_trace(
            truth, 0.1, ex.SensorModel(3500.0), np.random.default_rng(s), noise=0.02, system="S"
        )
        for s in (0, 2)
    ]
    summary = ex.analyse_traces(traces).one_shot_summary().set_index("parameter")
    assert summary.loc["a", "trials"] == 0 and summary.loc["m_f", "trials"] == 2


TRACE = Path(__file__).resolve().parents[1] / "studies" / "traces" / "u8_soft" / "u8_soft_v120mm.csv"


@pytest.mark.parametrize(
    ("unit", "words"),
    [
        ("9**9**9 s", "not a unit"),  # pint would evaluate the power and not finish
        ("1 m**0", "not a unit"),  # pint's KeyError 'meter' before
        ("m", "[length], not [time]"),
        ("0 s", "without the number '0' in front"),  # said 'powers of at most two digits' before
        ("-1 ms", "without the number '-1' in front"),
    ],
)
def test_a_bad_time_unit_is_a_usage_error_before_any_file_is_read(unit, words, capsys) -> None:
    assert main(["fit", str(TRACE), "--time-unit", unit]) == 2
    err = capsys.readouterr().err
    assert words in err and "--time-unit" in err and len(err.strip().splitlines()) == 1


def test_an_out_that_is_a_file_is_refused_before_the_analysis(tmp_path, capsys) -> None:
    taken = tmp_path / "taken"
    taken.write_text("not a folder")
    assert main(["fit", str(TRACE), "--out", str(taken)]) == 2
    captured = capsys.readouterr()
    assert "it is a file, not a folder" in captured.err and captured.out == ""
    assert main(["fit", str(TRACE), "--out", str(taken / "inside")]) == 2
    assert "cannot write to" in capsys.readouterr().err
