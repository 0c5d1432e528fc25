"""`crx run` and `crx report` end to end: every example study runs (small counts), the report is self-contained,
opens in headless Chromium without console errors and shows the numbers of pareto.csv; runs resume, repeat and
scale out to Dask with the same numbers; bad input writes nothing."""

from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys
import textwrap
import threading
from html import escape, unescape
from html.parser import HTMLParser
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml

from collision_reflex.cli import main
from collision_reflex.errors import StudyFileError
from collision_reflex.optimize import pareto, pieces
from collision_reflex.optimize.dominance import MERGE_TOLERANCE
from collision_reflex.optimize.optimum import OPTIMUM_STARTS, known_optima, single_optimum
from collision_reflex.optimize.pareto import pareto_front
from collision_reflex.optimize.recommend import RESOLUTION
from collision_reflex.optimize.results import SweepPoint
from collision_reflex.report.html import SOLVER_TOLERANCE
from collision_reflex.report.pdf import find_browser, headless_flags
from collision_reflex.study.runner import run_study

ROOT = Path(__file__).resolve().parents[1]
STUDIES = sorted((ROOT / "studies").glob("*.yaml"))
TWO_LINK = ROOT / "studies" / "two_link_paper.yaml"
ACTUATORS = ROOT / "studies" / "direct_drive_vs_geared.yaml"
SOLVER_COLUMNS = ("solve_time [s]",)  # wall times differ between runs; everything else must not


@pytest.fixture(scope="module")
def runs(smoke_runs):
    """Each example study run once (smoke size), shared by the tests that inspect the outputs."""
    return smoke_runs


@pytest.mark.parametrize("name", [p.stem for p in STUDIES], ids=[p.stem for p in STUDIES])
def test_every_example_study_runs(runs, name):
    folder = runs[name]
    for file in ("study.resolved.yaml", "run.json", "pareto.csv", "designs.json", "report.html"):
        assert (folder / file).is_file(), file
    assert json.loads((folder / "run.json").read_text())["status"] == "finished"
    figures = sorted(p.name for p in (folder / "figures").iterdir())
    assert any(f.endswith(".png") for f in figures) and any(f.endswith(".svg") for f in figures)
    assert not [p for p in folder.rglob(".*") if p.is_file()]  # no temporary files left behind
    table = pd.read_csv(folder / "pareto.csv")
    assert len(table) >= 1
    # A margin is empty (None) only where nothing is required of the joint (a rating without a cycle: no RMS).
    margins = {"rms_margin": "required_rms_torque", "speed_margin": "max_motor_speed"}
    for column in [c for c in table if c.split("[")[0] in margins]:
        name, joint = column.split("[")[0], column[column.index("[") : column.index("]") + 1]
        required = next(c for c in table if c.startswith(margins[name] + joint))
        assert (table[column].notna() | (table[required] == 0)).all(), column
    numbers = table.drop(columns=[c for c in table if c.split("[")[0] in margins]).select_dtypes("number")
    assert (numbers.to_numpy() == numbers.to_numpy()).all()  # no NaN anywhere else in the results


@pytest.mark.parametrize("name", [p.stem for p in STUDIES], ids=[p.stem for p in STUDIES])
def test_pareto_csv_is_what_pandas_writes_of_the_same_rows(runs, name, tmp_path):
    # pareto.csv is written without pandas (its import cost a run 0.25 s): the same bytes as pandas' writer.
    from collision_reflex.report.outputs import _read_results, _write_csv, pareto_rows

    rows = pareto_rows(_read_results(runs[name]))
    expected = pd.DataFrame(rows).to_csv(index=False, float_format="%.10g", lineterminator="\n")
    assert (runs[name] / "pareto.csv").read_text(encoding="utf-8") == expected
    # Cells pandas writes specially: NaN, None and missing keys empty, inf, bools, ints among floats, quoting.
    odd = [
        {"a [m]": 1.5, "b": True, "c": 2, "d": float("inf"), "e": None, "f": 'say "hi", twice'},
        {"a [m]": float("nan"), "b": False, "c": 3, "d": -0.1 + 0.2, "g": 1e-30},
    ]
    _write_csv(tmp_path / "odd.csv", odd)
    expected = pd.DataFrame(odd).to_csv(index=False, float_format="%.10g", lineterminator="\n")
    assert (tmp_path / "odd.csv").read_text(encoding="utf-8") == expected


@pytest.mark.parametrize("name", [p.stem for p in STUDIES], ids=[p.stem for p in STUDIES])
def test_timings_hold_every_stage_of_the_run_within_its_wall_time(runs, name):
    folder = runs[name]
    timings = json.loads((folder / "timings.json").read_text())
    stages = {k.split("/")[1] for k in timings if k.startswith("stages/")}
    expected = {"load", "prepare", "result files", "figures", "report"}
    expected |= {"actuators"} if name == ACTUATORS.stem else {"optimum", "results"}
    assert expected <= stages
    walls = [v for k, v in timings.items() if k.startswith("stages/") and k.endswith("/wall")]
    assert all(v >= 0 for v in walls)
    # The stages do not overlap: together they fit in the run's wall time (the manifest's, taken after them).
    assert sum(walls) <= json.loads((folder / "run.json").read_text())["elapsed"]


class _Tables(HTMLParser):
    """The text of every cell of the table with a given id."""

    def __init__(self, table_id: str) -> None:
        super().__init__()
        self.table_id, self.inside, self.rows, self.cell = table_id, False, [], None

    def handle_starttag(self, tag, attrs):
        if tag == "table" and dict(attrs).get("id") == self.table_id:
            self.inside = True
        elif self.inside and tag == "tr":
            self.rows.append([])
        elif self.inside and tag in ("td", "th"):
            self.cell = ""

    def handle_endtag(self, tag):
        if tag == "table":
            self.inside = False
        elif self.inside and tag in ("td", "th") and self.cell is not None:
            self.rows[-1].append(self.cell.strip())
            self.cell = None

    def handle_data(self, data):
        if self.cell is not None:
            self.cell += data


@pytest.mark.parametrize("name", [p.stem for p in STUDIES], ids=[p.stem for p in STUDIES])
def test_report_tables_hold_the_numbers_of_pareto_csv(runs, name):
    """The actuator report's table is pareto.csv; the arm report's front table holds its objectives, mass,
    threshold and approach velocity for every Pareto design (pareto.csv has every column)."""
    folder = runs[name]
    parser = _Tables("pareto-table")
    html = (folder / "report.html").read_text()
    parser.feed(html)
    table = pd.read_csv(folder / "pareto.csv")
    results = json.loads((folder / "designs.json").read_text())
    if results["kind"] == "arm" and len(results["pareto"]["points"]) < 2:
        assert 'id="pareto-table"' not in html  # a front of one design is no table: the verdict says why
        return
    header, *body = parser.rows
    assert len(body) == len(table)
    if results["kind"] == "arm":
        # "worst case impulse [N·s]" is pareto.csv's "worst_case_impulse [N*s]".
        columns = {
            i: re.sub(r"^(.*?) \[", lambda m: m.group(1).replace(" ", "_") + " [", h).replace("·", "*")
            for i, h in enumerate(header)
            if "[" in h
        }
        assert set(columns.values()) <= set(table.columns), columns
    else:
        assert header == list(table.columns)
        columns = dict(enumerate(header))
    for row, (_, expected) in zip(body, table.iterrows(), strict=True):
        for index, column in columns.items():
            text, value = row[index], expected[column]
            if isinstance(value, (bool, str)) or column in (
                "label",
                "status",
                "actuator",
                "motor",
                "pareto_optimal",
            ):
                assert text == str(value), column
            else:
                # The report prints 4 significant digits: equal within half a unit of the 4th digit; a
                # required torque (beside the peak torque) or margin within the solver's tolerance of zero
                # prints as 0.
                scale = (
                    1.0 if "margin[" in column else expected.get(column.replace("required_", "peak_"), 0.0)
                )
                noise = SOLVER_TOLERANCE * abs(scale)
                assert float(text.replace(",", "")) == pytest.approx(float(value), rel=5e-4, abs=noise), (
                    column
                )


def test_report_is_self_contained(runs):
    for folder in runs.values():
        html = (folder / "report.html").read_text()
        assert "<svg" in html
        # No resource is fetched: inline scripts only (no src), no stylesheets, images or frames from anywhere
        # (SVG's xmlns are names, not loads).
        assert not re.search(r"<script\b[^>]*\bsrc\s*=", html)
        assert not re.search(r"<(link|img|iframe)\b", html)
        assert not re.search(r"""(src|href)\s*=\s*["'](https?:|//|file:)""", html)


@pytest.fixture(scope="module")
def browser():
    path = find_browser()
    if path is None:
        pytest.skip("no Chromium installed (apt-get install chromium); .ci/run installs it where it can")
    return path


def test_report_opens_in_headless_chromium_without_console_errors(runs, browser, tmp_path):
    for name, folder in runs.items():
        completed = subprocess.run(
            [
                browser,
                *headless_flags(str(tmp_path / f"profile-{name}")),
                "--enable-logging=stderr",
                "--v=0",
                "--dump-dom",
                (folder / "report.html").as_uri(),
            ],
            capture_output=True,
            text=True,
            timeout=120,
            check=False,
        )
        assert completed.returncode == 0, completed.stderr[-2000:]
        assert 'id="assumptions-table"' in completed.stdout  # the page loaded and rendered its tables
        console = [
            line for line in completed.stderr.splitlines() if "CONSOLE" in line or "Failed to load" in line
        ]
        assert not console, console


def _numbers(folder: Path) -> pd.DataFrame:
    return pd.read_csv(folder / "pareto.csv").drop(columns=list(SOLVER_COLUMNS), errors="ignore")


def test_interrupted_run_resumes_from_finished_points(runs, tmp_path, monkeypatch):
    folder = tmp_path / "interrupted"
    original = pareto.solve_point  # as pareto_front submits it
    calls = {"n": 0}

    def interrupt_second_point(*args, **kwargs):
        calls["n"] += 1
        if calls["n"] == 2:
            raise KeyboardInterrupt  # as Ctrl-C in the middle of the sweep
        return original(*args, **kwargs)

    monkeypatch.setattr(pareto, "solve_point", interrupt_second_point)
    with pytest.raises(KeyboardInterrupt):
        run_study(TWO_LINK, folder, quiet=True, figures=False, smoke=True, executor="serial")
    assert json.loads((folder / "run.json").read_text())["status"] == "interrupted"
    assert not (folder / "pareto.csv").exists()  # no results until the run has finished
    finished = sorted(p.name for p in (folder / "points").iterdir())
    # The first point solved is kept, the interrupted one is not (points go out from the far end of the grid).
    assert len([name for name in finished if name.startswith("point-")]) == 1, finished

    monkeypatch.setattr(pareto, "solve_point", original)
    result = run_study(TWO_LINK, folder, quiet=True, figures=False, smoke=True, executor="serial")
    assert result.resumed and result.reused == len(finished) and result.computed >= 1
    pd.testing.assert_frame_equal(_numbers(folder), _numbers(runs["two_link_paper"]))


def test_dask_cluster_gives_the_serial_result(runs, tmp_path):
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(
        n_workers=1, threads_per_worker=2, processes=False, dashboard_address=None
    ) as cluster:  # as crx run --scheduler ADDRESS runs it (the option: test_cli_options)
        run_study(
            TWO_LINK,
            tmp_path / "dask",
            quiet=True,
            figures=False,
            smoke=True,
            scheduler=cluster.scheduler_address,
        )
    # The same solves from the same start points with single-threaded BLAS: the same numbers, to the last bit.
    pd.testing.assert_frame_equal(
        _numbers(tmp_path / "dask"), _numbers(runs["two_link_paper"]), check_exact=True
    )


def test_crx_run_hands_its_scheduler_and_executor_options_to_the_run(monkeypatch, capsys):
    """What ``crx run`` passes on (the run itself through a cluster: the test above)."""
    from collision_reflex.study import runner

    seen = {}

    def recorded(study, out, **options):
        seen.update(options, study=study, out=out)
        raise SystemExit(0)

    monkeypatch.setattr(runner, "run_study", recorded)
    with pytest.raises(SystemExit):
        main(["run", str(TWO_LINK), "--scheduler", "tcp://cluster:8786", "--workers", "3", "--smoke"])
    assert seen["scheduler"] == "tcp://cluster:8786" and seen["workers"] == 3 and seen["smoke"] is True
    assert seen["study"] == str(TWO_LINK) and seen["executor"] is None


def test_local_dask_cluster_gives_the_serial_result(runs, tmp_path):
    """A local cluster's workers (started without Dask's malloc trimming and profiler, warmed at once)."""
    pytest.importorskip("distributed")
    run_study(TWO_LINK, tmp_path / "dask", quiet=True, figures=False, smoke=True, executor="dask", workers=2)
    pd.testing.assert_frame_equal(
        _numbers(tmp_path / "dask"), _numbers(runs["two_link_paper"]), check_exact=True
    )


_THREADS_AT_FORK: list[int] | None = None


def _record_threads_at_fork() -> None:
    if _THREADS_AT_FORK is not None:
        _THREADS_AT_FORK.append(threading.active_count())


def test_a_process_pool_gives_the_serial_result_files_and_forks_before_the_run_starts_a_thread(
    runs, tmp_path
):
    """Forking copies only the forking thread: the progress bars' thread must not exist yet (fork safety).

    Workers are forked on Linux only: elsewhere the fork is not checked.
    """
    global _THREADS_AT_FORK
    forked = sys.platform.startswith("linux")
    # A process-wide hook (it cannot be removed): it records only while a list is set.
    os.register_at_fork(before=_record_threads_at_fork)
    before, _THREADS_AT_FORK = threading.active_count(), []
    try:
        command = [
            "run",
            str(TWO_LINK),
            "--out",
            str(tmp_path / "pool"),
            "--smoke",
            "--executor",
            "processes",
        ]
        assert (
            main([*command, "--workers", "2"]) == 0
        )  # with progress bars: their thread starts after the fork
        forks = _THREADS_AT_FORK
    finally:
        _THREADS_AT_FORK = None
    assert not forked or (len(forks) == 2 and set(forks) == {before})
    # Every number, the catalogue design and its snap included (designs.json), to the last bit.
    serial = runs["two_link_paper"]
    for name in ("pareto.csv", "designs.json"):
        assert (tmp_path / "pool" / name).read_bytes() == (serial / name).read_bytes(), name
    assert "solve_time" not in (serial / "designs.json").read_text()
    assert "solve_time" in (serial / "timings.json").read_text()


def test_crx_report_re_renders_from_saved_results(runs, tmp_path, capsys):
    folder = tmp_path / "copy"
    shutil.copytree(runs["direct_drive_vs_geared"], folder)
    before = (folder / "report.html").read_text()
    (folder / "report.html").unlink()
    shutil.rmtree(folder / "figures")
    assert main(["report", str(folder)]) == 0
    assert (folder / "report.html").read_text() == before
    assert (folder / "figures" / "velocity_sweep.png").is_file()
    assert main(["report", str(tmp_path / "nothing-here")]) == 2
    assert "run the study first" in capsys.readouterr().err


STUDY = textwrap.dedent(
    """\
    name: bad-input
    robot:
      example_robot_data: double_pendulum
      contact_frame: link2
      contact_offset: [0, 0, 0.2]
    actuators:
      mechanical_stiffness: 1000 N*m/rad
      software_stiffness: 100 N*m/rad
    sensing: {scheme: force, threshold: 3 N}
    approach_velocity: 0.5 m/s
    samples:
      configurations: {list: [[0 rad, 0.8 rad]]}
      directions: {circle: 4}
    design:
      gear_ratio: {min: 1, max: 50}
    """
)


@pytest.mark.parametrize(
    ("edit", "line", "words"),
    [
        (None, 0, ["no such file"]),
        (("contact_frame: link2", "contact_frame: [link2"), 5, ["invalid YAML", "flow sequence"]),
        (("double_pendulum", "double_pendulm"), 3, ["'double_pendulum'", "not an example-robot-data model"]),
        (("contact_frame: link2", "contact_frame: link9"), 4, ["link9"]),
        (("{min: 1, max: 50}", "{min: 50, max: 1}"), 15, ["min <= max"]),
        (("1000 N*m/rad", "3 kg"), 7, ["[mass]", "N*m/rad"]),
    ],
    ids=[
        "missing-file",
        "yaml-syntax",
        "unknown-robot",
        "unknown-frame",
        "impossible-bounds",
        "wrong-dimension",
    ],
)
def test_bad_input_is_one_located_message_exit_2_and_nothing_written(tmp_path, capsys, edit, line, words):
    study = tmp_path / "study.yaml"
    if edit is not None:
        study.write_text(STUDY.replace(*edit))
    out = tmp_path / "out"
    assert main(["run", str(study), "--out", str(out), "--quiet"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    assert err[0].startswith(
        f"crx run: error: {study}:{line}:" if line else f"crx run: error: {study}: found"
    )
    for word in words:
        assert word in err[0]
    assert "Traceback" not in err[0]
    assert not out.exists()


def test_report_pdf_is_printed_by_chromium(runs, browser, tmp_path):
    folder = tmp_path / "pdf"
    shutil.copytree(runs["direct_drive_vs_geared"], folder)
    assert main(["report", str(folder), "--pdf"]) == 0
    assert (folder / "report.pdf").read_bytes().startswith(b"%PDF")


def test_validate_checks_the_robot_with_lines(tmp_path, capsys):
    assert main(["validate", *map(str, STUDIES)]) == 0
    assert capsys.readouterr().out.count(": valid") == len(STUDIES)
    study = tmp_path / "study.yaml"
    study.write_text(
        STUDY.replace("contact_frame: link2", "contact_frame: lnk2").replace(
            "configurations: {list: [[0 rad, 0.8 rad]]}",
            "configurations: {list: [[0 rad, 0.8 rad, 0.1 rad]]}",
        )
    )
    assert main(["validate", str(study)]) == 2
    err = capsys.readouterr().err
    assert f"{study}:4:3: robot.contact_frame: found frame 'lnk2', not in the robot; expected 'link2'?" in err


def test_readme_main_command_runs_an_example_study(runs):
    """The README's main command is `crx run` on one of the example studies (each of which runs above)."""
    readme = (ROOT / "README.md").read_text()
    commands = re.findall(r"pip install -e \. && crx run (\S+)", readme)
    assert commands, "the README's main command does not run a study"
    assert (ROOT / commands[0]).resolve() in {p.resolve() for p in STUDIES}
    assert Path(commands[0]).stem in runs


def test_unreachable_torque_requirement_is_located_before_anything_is_written(tmp_path, capsys):
    # 1.3 N*m reference motor at 60 mm; at most 80 mm and a 2:1 gear reach 2 x 1.3 x (80/60)^2.5 = 5.337 N*m
    # (Haddadin law, torque exponent 2.5).
    study = tmp_path / "study.yaml"
    study.write_text(
        STUDY.replace(
            "gear_ratio: {min: 1, max: 50}",
            "gear_ratio: {min: 1, max: 2}\n  stator_diameter: {min: 20 mm, max: 80 mm}",
        )
        + "constraints: {torque_required: [1 N*m, 6 N*m]}\n"
    )
    assert main(["run", str(study), "--out", str(tmp_path / "out"), "--quiet"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith(f"crx run: error: {study}:17:")
    assert "constraints.torque_required[1]" in err and "at most 5.337 N*m" in err
    assert not (tmp_path / "out").exists()


def test_trajectory_configurations_come_from_the_csv_by_joint_name(tmp_path):
    from collision_reflex.study import load_study
    from collision_reflex.study.robot import load_arm
    from collision_reflex.study.samples import configuration_samples

    # Columns in another order than the joints, plus a time column that is ignored.
    (tmp_path / "traj.csv").write_text(
        "t,joint2 [rad],joint1 [rad]\n0,0.1,1.0\n0.1,0.2,1.1\n0.2,0.3,1.2\n0.3,0.4,1.3\n"
    )
    study = tmp_path / "study.yaml"
    study.write_text(
        STUDY.replace(
            "configurations: {list: [[0 rad, 0.8 rad]]}",
            "configurations: {trajectory: {file: traj.csv, every: 2}}",
        )
    )
    loaded = load_study(study)
    arm = load_arm(loaded)
    q = configuration_samples(loaded, arm)
    # Rows 0 and 2, joints in the arm's order (the double pendulum's joints are bounded: q holds the angles).
    np.testing.assert_allclose(arm.joint_coordinates(q), [[1.0, 0.1], [1.2, 0.3]], atol=1e-12)  # exact copies
    (tmp_path / "traj.csv").write_text("t,joint1 [rad]\n0,0.1\n")
    with pytest.raises(StudyFileError, match=r"no column for joint\(s\) joint2") as caught:
        configuration_samples(loaded, arm)
    assert caught.value.problems[0].line == 12


def test_smoke_runs_locate_problems_in_the_file_as_written(tmp_path, capsys):
    study = tmp_path / "study.yaml"
    study.write_text("# a comment that the resolved study does not have\n" + STUDY.replace("link2", "link9"))
    assert main(["run", str(study), "--out", str(tmp_path / "out"), "--quiet", "--smoke"]) == 2
    assert capsys.readouterr().err.startswith(f"crx run: error: {study}:5:3: robot.contact_frame")


ARM_STUDIES = [p.stem for p in STUDIES if p.stem != ACTUATORS.stem]


@pytest.mark.parametrize("name", ARM_STUDIES, ids=ARM_STUDIES)
def test_study_sweep_is_the_library_sweep(runs, name):
    """The run's front is what the optimiser's pareto_front gives on the same problem, called directly.

    As the run does, the anchor of the study's own objective takes the study's optimum (``known_optima``).
    """
    from collision_reflex.study.problems import IPOPT_OPTIONS, StudyProblems

    folder = runs[name]
    results = json.loads((folder / "designs.json").read_text())
    saved, spec = results["pareto"], results["resolved"]["pareto"]
    problems = StudyProblems.of_run(folder)
    rounds = sorted(
        (folder / "points").glob("round-*-optimum*.json"), key=lambda p: int(p.name.split("-")[1])
    )
    if rounds:  # an exchange round's optimum starts from the last round's: the run's own is the known one
        optimum = SweepPoint.from_json(json.loads(rounds[-1].read_text())).result
    else:
        optimum, _ = single_optimum(problems, problems.objective, IPOPT_OPTIONS)
    front = pareto_front(
        problems,
        spec["objectives"],
        spec["points"],
        IPOPT_OPTIONS,
        anchor_starts=spec["anchor_starts"],
        known=known_optima(problems.objective, optimum, spec["anchor_starts"]),
    )
    assert len(front.points) == len(saved["points"]) >= 1
    # Repeats of a point are merged and dominated points set aside (the smoke Panda front is one design): the
    # sweep still solved several.
    assert front.merged == saved["merged"] and len(front.dominated) == len(saved["dominated"])
    assert len(front.points) + front.merged + len(front.dominated) >= 2
    assert [f.as_dict() for f in front.failed] == saved["failed"]
    for ours, theirs in zip(front.records(), saved["points"], strict=True):
        assert ours["label"] == theirs["label"]
        for objective, value in theirs["objectives"].items():
            assert ours["objectives"][objective] == pytest.approx(value, rel=1e-9, abs=0), objective
        for mine, other in zip(ours["joints"], theirs["joints"], strict=True):
            for key in ("stator_diameter", "gear_ratio", "software_stiffness", "peak_torque", "motor_mass"):
                assert mine[key] == pytest.approx(other[key], rel=1e-9, abs=0), (mine["joint"], key)
        assert ours["threshold"] == pytest.approx(theirs["threshold"], rel=1e-9, abs=0)


def _dominates(a, b, names, senses, tolerance=1e-9, scale=None):
    """Brute force: ``a`` no worse than ``b`` in every objective and better in one (by more than
    ``tolerance`` relative: values closer than that count as equal), relative to the larger of the two or to
    ``scale[name]`` (the front's largest magnitude, as the sweep's dominance is measured)."""
    better = worse = False
    for name, sense in zip(names, senses, strict=True):
        size = scale[name] if scale is not None else max(abs(a[name]), abs(b[name]))
        gap = sense * (b[name] - a[name]) / size
        better, worse = better or gap > tolerance, worse or gap < -tolerance
    return better and not worse


@pytest.mark.parametrize("name", ARM_STUDIES, ids=ARM_STUDIES)
def test_chosen_design_says_whether_a_pareto_design_dominates_it(runs, name):
    from collision_reflex.optimize import OBJECTIVES

    results = json.loads((runs[name] / "designs.json").read_text())
    names = results["pareto"]["objectives"]
    senses = [OBJECTIVES[n][0] for n in names]
    chosen = results["chosen"]["objectives"]
    points = [p["objectives"] for p in results["pareto"]["points"]]
    scale = {n: max(abs(v[n]) for v in [*points, chosen]) for n in names}
    beaten = [
        i
        for i, p in enumerate(points)
        # The solver tolerance of the recommendation (MERGE_TOLERANCE, 1e-5) of each objective's largest
        # magnitude: an optimum better than a much lighter front point by less than that is dominated by it.
        if _dominates(p, chosen, names, senses, tolerance=1e-5, scale=scale)
    ]
    assert results["chosen"]["dominated_by"] == (beaten[0] if beaten else None)


def test_a_dominated_chosen_design_is_flagged_in_the_report(runs, tmp_path):
    folder = tmp_path / "flagged"
    shutil.copytree(runs["two_link_paper"], folder)
    results = json.loads((folder / "designs.json").read_text())
    # The chosen design equal to the first Pareto design: not flagged.
    results["chosen"]["objectives"] = dict(results["pareto"]["points"][0]["objectives"])
    results["chosen"]["dominated_by"] = None
    (folder / "designs.json").write_text(json.dumps(results))
    assert main(["report", str(folder)]) == 0
    assert "not Pareto-optimal" not in (folder / "report.html").read_text()
    # The chosen design made heavier than the first Pareto design at the same impulse: that design dominates it.
    first = results["pareto"]["points"][0]["objectives"]
    results["chosen"]["objectives"] = {**first, "actuator_mass": 2 * first["actuator_mass"]}
    results["chosen"]["dominated_by"] = 0
    (folder / "designs.json").write_text(json.dumps(results))
    assert main(["report", str(folder)]) == 0
    html = (folder / "report.html").read_text()
    assert "The single-objective optimum is not Pareto-optimal: Pareto design" in " ".join(html.split())
    assert "Pareto design 0 is no worse" in " ".join(html.split())
    assert "worst case impulse and actuator mass" in html


def test_a_study_asks_for_multi_start_anchors(tmp_path, monkeypatch):
    study = tmp_path / "two_link.yaml"
    data = yaml.safe_load(TWO_LINK.read_text().replace("../designs/", f"{ROOT / 'designs'}/"))
    data["pareto"].update(points=4, anchor_starts=2)
    data["optimizer"] = {"worst_case_search": {"enabled": False}}  # one round of solves: counted below
    data["actuators"]["gearbox"] = data["actuators"]["gearbox"][-1]  # one gearbox: no choice solves them
    study.write_text(yaml.safe_dump(data))
    starts = []
    original = pieces.solve  # every solve of a run goes through it

    def spy(problem, *args, **kwargs):
        starts.append(kwargs.get("starts", 1))
        return original(problem, *args, **kwargs)

    monkeypatch.setattr(pieces, "solve", spy)
    result = run_study(study, tmp_path / "out", quiet=True, figures=False, smoke=True, executor="serial")
    results = json.loads((result.folder / "designs.json").read_text())
    assert results["resolved"]["pareto"]["anchor_starts"] == 2
    # The study's optimum from OPTIMUM_STARTS starts (at least the 2 asked), which is the anchor of the study's
    # objective (worst case impulse), so only the other anchor is started twice; then one lexicographic step
    # each and two points from one start.
    assert sorted(starts) == sorted([1, 1, 1, 1, 2, OPTIMUM_STARTS])
    assert results["pareto"]["points"][0]["label"] == "anchor: worst_case_impulse"


@pytest.mark.parametrize("name", ARM_STUDIES, ids=ARM_STUDIES)
def test_saved_arm_results_have_the_declared_record_types(runs, name):
    # The TypedDicts are what the report reads; a key written but not declared (or declared, never written)
    # means the declaration and designs.json have drifted apart.
    from typing import get_type_hints

    from collision_reflex.study.arm_results import ArmResults, ParetoRecord, SampleLayout

    results = json.loads((runs[name] / "designs.json").read_text())
    for record, declared in (
        (results, ArmResults),
        (results["pareto"], ParetoRecord),
        (results["samples"], SampleLayout),
    ):
        assert set(get_type_hints(declared)) <= set(record), declared.__name__
    assert set(results["pareto"]) == set(get_type_hints(ParetoRecord))
    assert set(results["samples"]) == set(get_type_hints(SampleLayout))
    samples = results["samples"]
    n_samples = len(samples["config_index"])
    assert n_samples == len(samples["sample_directions"]) >= 1
    assert all(
        isinstance(i, int) and 0 <= i < len(samples["configurations"]) for i in samples["config_index"]
    )
    assert all(len(d) == samples["task_dim"] for d in samples["sample_directions"])
    assert all(len(q) == len(samples["joint_names"]) for q in samples["configurations"])


@pytest.mark.parametrize("name", ARM_STUDIES, ids=ARM_STUDIES)
def test_the_recommended_design_is_not_dominated_and_the_verdict_says_it(runs, name):
    from collision_reflex.optimize import OBJECTIVES

    results = json.loads((runs[name] / "designs.json").read_text())
    # Judged as the recommendation judges: on the front's objectives and the study objective's own terms (a
    # front end that is a little better in impulse at many times the mass does not beat a weighted optimum).
    names = list(dict.fromkeys([*results["pareto"]["objectives"], *results["resolved"]["objective"]]))
    senses = [OBJECTIVES[n][0] for n in names]
    recommended = results["recommended"]
    for point in results["pareto"]["points"]:
        assert not _dominates(point["objectives"], recommended["objectives"], names, senses), point["label"]
    # As good in the study's objective as the single-objective solve within the recommendation's resolution,
    # and lighter where it is worse at all (a weighted objective: dominance alone decides).
    objective = next(iter(results["resolved"]["objective"]))
    sense = OBJECTIVES[objective][0]
    single = len(results["resolved"]["objective"]) == 1
    if single and objective in names and recommended["source"] != "optimum":
        chosen = results["chosen"]["objectives"]
        worse = sense * (recommended["objectives"][objective] - chosen[objective])
        assert worse <= RESOLUTION * abs(chosen[objective])
        if worse > MERGE_TOLERANCE * abs(chosen[objective]):
            assert recommended["objectives"]["actuator_mass"] < chosen["actuator_mass"]
            assert "the lighter design is recommended" in recommended["reason"]
    verdict = results["verdict"]
    assert 2 <= len(verdict) <= 10
    said = f"Continuous optimum ({recommended['source']}): " if results.get("catalogue") else "Build: "
    assert any(line.startswith(said) for line in verdict[:2]), verdict[:2]
    html = (runs[name] / "report.html").read_text()
    for line in verdict:
        assert escape(line, quote=False) in html.replace("&#39;", "'"), line
    assert html.index('id="verdict"') < html.index('id="recommended"')


def test_crx_run_prints_the_verdict_into_its_default_folder_with_the_umask_and_the_same_numbers(
    runs, tmp_path, capsys, monkeypatch
):
    """A smoke run without ``--out`` writes ``results/NAME-smoke``, its files with the umask's mode; the same
    study gives the same numbers; the verdict is printed, and not with ``--quiet``."""
    monkeypatch.chdir(tmp_path)
    previous = os.umask(0o027)
    try:
        assert main(["run", str(TWO_LINK), "--smoke", "--executor", "serial"]) == 0
    finally:
        os.umask(previous)
    assert [p.name for p in (tmp_path / "results").iterdir()] == ["two-link-paper-smoke"]
    out = tmp_path / "results" / "two-link-paper-smoke"
    files = [p for p in out.rglob("*") if p.is_file()]
    assert files and {p.stat().st_mode & 0o777 for p in files} == {0o640}
    pd.testing.assert_frame_equal(_numbers(out), _numbers(runs["two_link_paper"]), check_exact=True)
    printed = capsys.readouterr().out
    verdict = json.loads((out / "designs.json").read_text())["verdict"]
    assert verdict and all(line in printed for line in verdict)
    assert main(["run", str(TWO_LINK), "--out", str(out), "--smoke", "--quiet"]) == 0
    assert verdict[0] not in capsys.readouterr().out


@pytest.mark.parametrize("name", ARM_STUDIES, ids=ARM_STUDIES)
def test_recommended_design_has_no_oversized_joint_unless_at_the_smallest_motor(runs, name):
    """Issue bar: a peak-torque margin above 3x (margin > 2) only where the motor is at its smallest size (the
    verdict then says so); every joint with a requirement reports its margin."""
    results = json.loads((runs[name] / "designs.json").read_text())
    recommended = results["recommended"]
    smallest = {joint: bounds[0] for joint, bounds in results["bounds"]["stator_diameter"].items()}
    verdict = "\n".join(results["verdict"])
    for joint in recommended["joints"]:
        required = joint["required_torque"]
        if required is None or required == 0:
            assert joint["torque_margin"] is None, joint["joint"]
            continue
        assert joint["torque_margin"] is not None and joint["torque_margin"] >= -1e-6, joint["joint"]
        if joint["torque_margin"] > 2.0:
            assert joint["stator_diameter"] <= smallest[joint["joint"]] * (1 + 1e-6), joint["joint"]
            assert "motor at its smallest size" in verdict and joint["joint"] in verdict


@pytest.mark.parametrize("name", ARM_STUDIES, ids=ARM_STUDIES)
def test_torque_speed_figure_exactly_where_a_motion_sizes_the_joints(runs, name):
    from collision_reflex.optimize.constraints import DUTY_REQUIREMENT, RATED_REQUIREMENT

    folder = runs[name]
    results = json.loads((folder / "designs.json").read_text())
    html = (folder / "report.html").read_text()
    recommended = results["recommended"]
    if results["requirement"] in (DUTY_REQUIREMENT, RATED_REQUIREMENT):  # a motion sizes the joints
        saved = recommended["torque_speed"]
        assert [e["joint"] for e in saved] == [j["joint"] for j in recommended["joints"]]
        # The record's margins are the saved points' (motor side: peak torque over the largest torque of the
        # cycle and the rated motion) where a motion sets the requirement; where the static hold does, they ask
        # less.
        factor = results["resolved"]["constraints"]["safety_factor"]
        for entry, joint in zip(saved, recommended["joints"], strict=True):
            output = joint["gear_ratio"] * joint.get("gearbox_efficiency", 1.0)  # per motor torque
            largest = factor * max(abs(t) for t in entry["torque"]) * output
            if joint["required_by"] in ("duty cycle", "rated motion", "braking"):
                assert largest == pytest.approx(joint["required_torque"], rel=1e-6), joint["joint"]
            else:  # the static hold, or another joint of its module, asks more than its own motion
                assert joint["required_by"] == "static hold" or " of " in joint["required_by"]
                assert largest <= joint["required_torque"] * (1 + 1e-6), joint["joint"]
        assert (folder / "figures" / "torque_speed.png").is_file()
        assert 'id="torque-speed"' in html
    else:
        assert "torque_speed" not in recommended
        assert not (folder / "figures" / "torque_speed.png").exists()
        assert 'id="torque-speed-none"' in html


@pytest.mark.parametrize("name", ARM_STUDIES, ids=ARM_STUDIES)
def test_the_speed_limit_assumption_is_stated_exactly_when_a_motion_uses_it(runs, name):
    """Stated once, in the assumptions, not in the verdict."""
    from collision_reflex.hardware.motors import CONSTANT_SURFACE_SPEED
    from collision_reflex.optimize.constraints import DUTY_REQUIREMENT, RATED_REQUIREMENT

    results = json.loads((runs[name] / "designs.json").read_text())
    html = unescape((runs[name] / "report.html").read_text())
    assumptions = html[html.index('id="assumptions"') :]
    assert not any("Speed limits" in line for line in results["verdict"])
    if results["requirement"] in (DUTY_REQUIREMENT, RATED_REQUIREMENT):  # a motion's speeds bound the motors
        assert "the reference motor" in assumptions and CONSTANT_SURFACE_SPEED.source[:60] in assumptions
        assert html.count(CONSTANT_SURFACE_SPEED.source[:60]) == 1
    else:
        assert results["speed_limits"] is None and "speed limits" not in assumptions
