"""Runs and their files under interrupts and faults: Ctrl-C, unusable output folders, damaged run folders, file
modes, smoke folders, stale temporary files, orphaned workers, byte-identical results, closed pipes."""

from __future__ import annotations

import os
import resource
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

import collision_reflex as cr
from collision_reflex.cli import main

ROOT = Path(__file__).resolve().parents[1]
PANDA = ROOT / "studies" / "panda.yaml"
TWO_LINK = ROOT / "studies" / "two_link_paper.yaml"
RESULT_FILES = ("pareto.csv", "designs.json")
CRX = [sys.executable, "-c", "import sys; from collision_reflex.cli import main; sys.exit(main())"]


def _environment() -> dict[str, str]:
    src = str(ROOT / "src")
    path = os.environ.get("PYTHONPATH")
    return {**os.environ, "PYTHONPATH": src if not path else f"{src}{os.pathsep}{path}"}


def _crx(*args: str, **kwargs) -> subprocess.CompletedProcess:
    return subprocess.run(
        [*CRX, *args], capture_output=True, text=True, env=_environment(), timeout=300, **kwargs
    )


@pytest.fixture(scope="module")
def panda_run(smoke_runs):
    """The Panda smoke study run once without interruption (serial)."""
    return smoke_runs["panda"]


def _same_results(folder: Path, reference: Path) -> None:
    for name in RESULT_FILES:
        assert (folder / name).read_bytes() == (reference / name).read_bytes(), name


def test_ctrl_c_stops_a_run_saves_its_points_and_the_resumed_run_equals_an_uninterrupted_one(
    panda_run, tmp_path
):
    folder = tmp_path / "out"
    command = [*CRX, "run", str(PANDA), "--smoke", "--quiet", "--executor", "serial", "--out", str(folder)]
    process = subprocess.Popen(command, stderr=subprocess.PIPE, text=True, env=_environment())
    # Interrupt in the middle of the sweep: once the first pieces are saved.
    deadline = time.monotonic() + 120

    def finished() -> int:  # saved points, not a temporary file of a write under way
        points = folder / "points"
        return len([p for p in points.glob("*.json") if not p.name.startswith(".")]) if points.exists() else 0

    while finished() < 2:
        assert process.poll() is None and time.monotonic() < deadline, "the run ended before the interrupt"
        time.sleep(0.05)
    before = _cpu_seconds(process.pid)
    children = resource.getrusage(resource.RUSAGE_CHILDREN)
    process.send_signal(signal.SIGINT)
    sent = time.monotonic()
    _, stderr = process.communicate(timeout=60)
    if before is None:  # no /proc: the wall time, which a loaded machine stretches
        assert time.monotonic() - sent < 2.0
    else:  # the CPU time the run spent after the interrupt: what stopping costs, however loaded the machine
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        spent = after.ru_utime + after.ru_stime - children.ru_utime - children.ru_stime - before
        assert spent < 2.0, f"{spent:.1f} s of CPU after the interrupt"
        assert time.monotonic() - sent < 30.0  # and no wait without work (a hang)
    assert process.returncode == 130
    assert stderr.strip().splitlines()[-1] == "crx run: interrupted; rerun the same command to resume"
    assert "Traceback" not in stderr
    assert '"status": "interrupted"' in (folder / "run.json").read_text()
    saved = {p.name for p in (folder / "points").iterdir() if p.suffix == ".json"}
    assert len(saved) >= 2 and not (folder / "pareto.csv").exists()
    for point in saved:  # an interrupted solve is never recorded
        assert "NonIpopt" not in (folder / "points" / point).read_text()

    # Resumed in this process (the interrupted one was a process of its own, as a user's is).
    assert main(["run", str(PANDA), "--smoke", "--quiet", "--executor", "serial", "--out", str(folder)]) == 0
    _same_results(folder, panda_run)


def _cpu_seconds(pid: int) -> float | None:
    """The CPU time (user and system) process ``pid`` has used so far [s], from /proc; None without it."""
    try:
        fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    except OSError:
        return None
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")  # utime, stime: fields 14, 15


def _pendulum_inputs():
    """A small design problem's inputs: the double pendulum, 2 configurations x 2 directions, space, technology."""
    pendulum = cr.Arm.from_example_robot_data("double_pendulum")
    q = np.array([[0.3, -0.5], [1.0, 0.4]])
    samples = cr.ContactSamples.grid(pendulum.kinematics(q), np.array([[1.0, 0.0], [0.0, 1.0]]))
    space = cr.DesignSpace(
        stator_diameter=(0.02, 0.12),
        gear_ratio=(1, 30),
        software_stiffness=300.0,
        threshold=(3, 20),
        approach_velocity=(0.02, 2.0),
    )
    technology = cr.ActuatorTechnology(cr.reference_motor(), mechanical_stiffness=[600.0, 400.0])
    return pendulum, samples, space, technology


def test_an_interrupted_ipopt_run_raises_keyboard_interrupt_and_is_not_retried(monkeypatch):
    problem = cr.build_problem(*_pendulum_inputs(), "worst_case_impulse")
    calls = []

    class Interrupted:
        """What CasADi's IPOPT returns after it caught Ctrl-C in a callback."""

        def __call__(self, **kwargs):
            calls.append(kwargs)
            return {"x": kwargs["x0"], "lam_x": kwargs["x0"], "lam_g": np.zeros(0)}

        def stats(self):
            return {"return_status": "NonIpopt_Exception_Thrown", "iter_count": 3}

    # Every IPOPT solver of a problem comes from DesignProblem.solver.
    monkeypatch.setattr(type(problem), "solver", lambda self, *args, **kwargs: Interrupted())
    with pytest.raises(KeyboardInterrupt):
        cr.solve(problem)
    assert len(calls) == 1  # neither retried nor followed by a feasibility solve


def _run(folder: Path, *extra: str, study: Path = TWO_LINK) -> int:
    return main(
        ["run", str(study), "--smoke", "--quiet", "--executor", "serial", "--out", str(folder), *extra]
    )


@pytest.fixture(scope="module")
def two_link_run(smoke_runs):
    """The two-link smoke study run once in-process (serial)."""
    return smoke_runs["two_link_paper"]


def _error_line(capsys) -> str:
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 1, lines
    return lines[0]


def test_a_read_only_parent_is_one_line_exit_2(tmp_path, capsys, monkeypatch):
    parent = tmp_path / "read-only"
    mkdir = Path.mkdir

    def refused(self, *args, **kwargs):  # as a read-only folder does (also when the tests run as root)
        if parent in self.parents:
            raise PermissionError(13, "Permission denied", str(self))
        return mkdir(self, *args, **kwargs)

    monkeypatch.setattr(Path, "mkdir", refused)
    assert _run(parent / "out") == 2
    line = _error_line(capsys)
    assert str(parent / "out") in line and "Permission denied" in line


@pytest.mark.parametrize("below", [False, True], ids=["a file", "below a file"])
def test_out_naming_a_file_or_below_one_is_one_line_exit_2(tmp_path, capsys, below):
    regular = tmp_path / "file"
    regular.write_text("mine\n")
    out = regular / "below" if below else regular
    assert _run(out) == 2
    line = _error_line(capsys)
    assert f"cannot write {out}" in line
    assert regular.read_text() == "mine\n"


def test_a_full_disk_during_the_solves_is_one_line_exit_1_and_keeps_finished_points(
    tmp_path, capsys, monkeypatch
):
    import errno

    from collision_reflex.study import store

    write_json = store.write_json
    saved = []

    def full_after_the_first_point(path, data):
        if Path(path).parent.name == "points":
            if saved:
                raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC), str(path))
            saved.append(path)
        write_json(path, data)

    monkeypatch.setattr(store, "write_json", full_after_the_first_point)
    folder = tmp_path / "out"
    assert _run(folder) == 1
    line = _error_line(capsys)
    assert "No space left on device" in line and str(folder / "points") in line
    assert [p.name for p in (folder / "points").iterdir()] == [Path(saved[0]).name]
    assert '"status": "failed"' in (folder / "run.json").read_text()


@pytest.mark.parametrize(
    "damage", ["{}", "[]", '{"label": "anchor: mass", "res'], ids=["{}", "[]", "truncated"]
)
def test_a_damaged_point_file_is_reported_and_recomputed(two_link_run, tmp_path, capsys, damage):
    import shutil

    folder = tmp_path / "out"
    shutil.copytree(two_link_run, folder)
    point = sorted((folder / "points").glob("point-*.json"))[0]
    point.write_text(damage)
    capsys.readouterr()
    assert _run(folder) == 0
    assert f"warning: {point} is " in capsys.readouterr().err
    assert "label" in point.read_text()  # recomputed and saved again
    _same_results(folder, two_link_run)


def test_a_resumed_run_reuses_its_gearbox_choice_and_worst_case_searches(two_link_run, tmp_path, monkeypatch):
    """Nothing of a finished run is solved or searched again; a choice saved for another study is not reused."""
    import json
    import shutil

    from collision_reflex.study import transmission_choice, worst_case

    folder = tmp_path / "out"
    shutil.copytree(two_link_run, folder)
    searches = sorted((folder / "points").glob("search-*.json"))
    assert searches  # one per design and round, each named by its inputs
    calls = {"solves": 0, "searches": 0}
    single_optimum, search = transmission_choice.single_optimum, worst_case.search_worst_case

    def counted(key, function):
        def call(*args, **kwargs):
            calls[key] += 1
            return function(*args, **kwargs)

        return call

    monkeypatch.setattr(transmission_choice, "single_optimum", counted("solves", single_optimum))
    monkeypatch.setattr(worst_case, "search_worst_case", counted("searches", search))
    assert _run(folder) == 0
    assert calls == {"solves": 0, "searches": 0}
    _same_results(folder, two_link_run)

    saved = folder / "points" / "transmissions.json"
    record = json.loads(saved.read_text())
    assert [entry["chosen"] for entry in record["tried"]].count(True) == 1
    saved.write_text(json.dumps({**record, "key": "another study"}))
    searches[0].write_text('{"fields": ["impulse"], "values": {"impulse": 0.0}}')  # another version's
    assert _run(folder) == 0
    assert calls == {"solves": len(record["tried"]), "searches": 1}
    _same_results(folder, two_link_run)


def test_a_resumed_run_removes_stale_temporary_files(two_link_run, tmp_path):
    import shutil

    folder = tmp_path / "out"
    shutil.copytree(two_link_run, folder)
    stale = [folder / ".tmp-designs.k1ll3d.json", folder / "points" / ".tmp-point-000.x.json"]
    for path in stale:
        path.write_text('{"half": ')
        os.utime(path, (time.time() - 120, time.time() - 120))  # left by a run killed two minutes ago
    fresh = folder / ".tmp-report.in-progress.html"  # another writer's, just begun: kept
    fresh.write_text("<html>")
    assert _run(folder) == 0
    assert not any(path.exists() for path in stale)
    assert fresh.exists()


@pytest.mark.parametrize(
    ("edit", "words"),
    [
        (lambda d: d.update(kind="tampered"), "field 'kind' is 'tampered'"),
        (lambda d: d.pop("study"), "field 'study' is missing"),
        (lambda d: d["recommended"].pop("joints"), "field 'joints' is missing"),
        (lambda d: d["recommended"].update(approach_velocity="fast"), "wrong kind"),
    ],
    ids=["kind", "study", "joints", "a string for a number"],
)
def test_crx_report_on_altered_designs_says_which_file_and_field(two_link_run, tmp_path, capsys, edit, words):
    import json
    import shutil

    folder = tmp_path / "out"
    shutil.copytree(two_link_run, folder)
    designs = json.loads((folder / "designs.json").read_text())
    edit(designs)
    (folder / "designs.json").write_text(json.dumps(designs))
    capsys.readouterr()
    assert main(["report", str(folder)]) == 2
    line = _error_line(capsys)
    assert line.startswith(f"crx report: error: {folder / 'designs.json'}: ") and words in line, line


@pytest.mark.skipif(not Path("/proc/self/task").is_dir(), reason="reads a process's children from /proc")
def test_pool_workers_die_with_a_killed_run(tmp_path):
    folder = tmp_path / "out"
    command = [*CRX, "run", str(PANDA), "--smoke", "--quiet", "--executor", "processes", "--out", str(folder)]
    process = subprocess.Popen(command, stderr=subprocess.DEVNULL, env=_environment())
    children: set[int] = set()
    deadline = time.monotonic() + 120
    while len(children) < 2:  # the resource tracker and at least one worker
        assert process.poll() is None and time.monotonic() < deadline, "the run ended before the kill"
        time.sleep(0.1)
        task = Path(f"/proc/{process.pid}/task/{process.pid}/children")
        children = {int(pid) for pid in task.read_text().split()}
    process.kill()
    process.wait()
    deadline = time.monotonic() + 10
    while any(Path(f"/proc/{pid}").exists() and _state(pid) != "Z" for pid in children):
        assert time.monotonic() < deadline, "a worker outlived the killed run"
        time.sleep(0.1)


def _state(pid: int) -> str:
    try:
        return Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except (FileNotFoundError, IndexError):
        return "gone"


def test_piping_into_head_gives_no_traceback():
    process = subprocess.Popen(
        [*CRX, "impulse", "--velocities", "0.01:1:20000"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=_environment(),
    )
    assert process.stdout is not None and process.stdout.readline()
    process.stdout.close()  # as `head -1` does after its line
    _, stderr = process.communicate(timeout=60)
    assert process.returncode == 0 and stderr == "", stderr


def _swallowed_ctrl_c() -> None:
    """A Ctrl-C whose KeyboardInterrupt is caught and dropped, as CasADi's overload tests drop it."""
    try:
        os.kill(os.getpid(), signal.SIGINT)
        time.sleep(0.01)  # the handler runs here at the latest
    except KeyboardInterrupt:
        pass


def test_a_ctrl_c_lost_inside_an_interruptible_block_is_raised_when_it_ends():
    from collision_reflex._interrupt import interruptible

    before = signal.getsignal(signal.SIGINT)
    with pytest.raises(KeyboardInterrupt):
        with interruptible():
            _swallowed_ctrl_c()
    assert signal.getsignal(signal.SIGINT) is before  # the handler in place is restored
    # An error the interrupt caused (a conversion left with the exception set, an import cut short) is the
    # interrupt, with that error as its cause; without an interrupt errors and results pass unchanged.
    with pytest.raises(KeyboardInterrupt) as caught:
        with interruptible():
            _swallowed_ctrl_c()
            raise SystemError("returned a result with an exception set")
    assert isinstance(caught.value.__cause__, SystemError)
    with pytest.raises(ValueError), interruptible():
        raise ValueError("not an interrupt")
    with interruptible():
        pass


def test_an_ignored_or_handled_ctrl_c_stays_so_inside_an_interruptible_block():
    from collision_reflex._interrupt import interruptible

    calls = []
    for handler in (signal.SIG_IGN, lambda signum, frame: calls.append(signum)):
        previous = signal.signal(signal.SIGINT, handler)
        try:
            with interruptible():
                os.kill(os.getpid(), signal.SIGINT)
                time.sleep(0.01)
        finally:
            signal.signal(signal.SIGINT, previous)
    assert calls == [signal.SIGINT]  # the caller's handler ran, and nothing was raised


def test_solves_and_problem_builds_raise_a_ctrl_c_their_casadi_code_lost(monkeypatch):
    from collision_reflex.optimize import nlp
    from collision_reflex.optimize import problem as problems

    inputs = _pendulum_inputs()
    problem = cr.build_problem(*inputs, "worst_case_impulse")
    original = problems.DesignProblem.solver

    def solver(self, *args, **kwargs):
        _swallowed_ctrl_c()
        return original(self, *args, **kwargs)

    monkeypatch.setattr(problems.DesignProblem, "solver", solver)
    with pytest.raises(KeyboardInterrupt):
        cr.solve(problem)
    original_structure = nlp._sample_structure

    def structure(*args, **kwargs):
        _swallowed_ctrl_c()
        return original_structure(*args, **kwargs)

    monkeypatch.setattr(nlp, "_sample_structure", structure)
    built = cr.build_problem(*inputs, "worst_case_impulse")  # its CasADi graph is built on first use
    with pytest.raises(KeyboardInterrupt):
        built.nlp  # noqa: B018


def test_an_error_a_ctrl_c_caused_ends_crx_as_interrupted(monkeypatch, capsys):
    from collision_reflex._interrupt import caused_by_interrupt
    from collision_reflex.cli import run as run_command

    def cut_short(args):
        try:
            raise KeyboardInterrupt
        except KeyboardInterrupt:
            raise ImportError("initialization failed") from None

    # ``from None`` hides the cause from the traceback but keeps the context.
    try:
        cut_short(None)
    except ImportError as error:
        assert caused_by_interrupt(error)
    assert not caused_by_interrupt(ValueError("plain"))
    monkeypatch.setattr(run_command, "run", cut_short)
    assert main(["run", str(TWO_LINK)]) == 130
    assert capsys.readouterr().err.strip() == "crx run: interrupted; rerun the same command to resume"


def test_a_killed_writer_s_temporary_file_goes_at_once_a_live_one_s_stays(tmp_path):
    """A run killed (kill -9) while it wrote a point leaves ``.tmp-*``; resumed at once, it must go: its writer's
    process id (in the name) is gone. A live process's (this one's) stays until it is old."""
    import subprocess

    from collision_reflex._io import TEMPORARY_PREFIX, atomic_path, remove_temporary_files

    finished = subprocess.Popen(["true"])
    finished.wait()
    dead = tmp_path / f"{TEMPORARY_PREFIX}point-003.{finished.pid}.k1l2m3n4.json"
    live = tmp_path / f"{TEMPORARY_PREFIX}point-004.{os.getpid()}.k1l2m3n4.json"
    for path in (dead, live):
        path.write_text("{")
    assert remove_temporary_files(tmp_path) == [dead]
    assert live.exists() and not dead.exists()
    with atomic_path(tmp_path / "point-005.json") as written:  # the writer's own id is in the name
        assert f".{os.getpid()}." in written.name
