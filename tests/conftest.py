"""Shared test settings and set-ups: figures render off-screen; the Panda case of the active-set tests; one smoke
run of each shipped study, shared by every test (and every pytest-xdist worker) that reads one."""

import contextlib
import os
import shutil
from collections.abc import Callable, Iterator, Mapping
from pathlib import Path
from typing import NamedTuple

import matplotlib
import numpy as np
import pytest

import collision_reflex as cr
from collision_reflex.cli import main

matplotlib.use("Agg")

STUDIES = Path(__file__).resolve().parents[1] / "studies"

try:
    import fcntl
except ImportError:  # not POSIX: each worker makes its own copy of a shared set-up
    fcntl = None


class DesignCase(NamedTuple):
    """An arm, its contact samples and the optimiser's inputs: ``build_problem`` takes them in this order."""

    arm: cr.Arm
    samples: cr.ContactSamples
    space: cr.DesignSpace
    technology: cr.ActuatorTechnology
    constraints: cr.Constraints


@pytest.fixture(scope="session")
def panda_case():
    """``panda_case(configurations)``: the Panda on ``configurations`` random configurations x 4 random
    directions (seed 7), motors scaled from the reference motor with their reflected inertia on the finger, a
    1 kg payload; the active-set tests' case, at the size each needs."""

    def case(configurations: int) -> DesignCase:
        rng = np.random.default_rng(7)
        arm = cr.Arm.from_example_robot_data("panda")
        samples = cr.ContactSamples.grid(
            arm.kinematics(arm.sample_configurations(configurations, rng)), rng.normal(size=(4, 3))
        )
        space = cr.DesignSpace(
            stator_diameter=(0.02, 0.15),
            gear_ratio=(1.0, 100.0),
            software_stiffness=(100.0, 1e4),
            threshold=(5.0, 40.0),
            approach_velocity=(0.05, 1.0),
        )
        technology = cr.ActuatorTechnology(
            cr.reference_motor(), mechanical_stiffness=5000.0, reflected_inertia_in="finger"
        )
        constraints = cr.Constraints(payload=1.0, safety_factor=1.5, threshold_floor=5.0)
        return DesignCase(arm, samples, space, technology, constraints)

    return case


@contextlib.contextmanager
def _locked(path: Path) -> Iterator[None]:
    """Hold an exclusive lock on ``path`` (a file next to what it guards) while the block runs."""
    with open(path, "w") as lock:
        if fcntl is not None:
            fcntl.flock(lock, fcntl.LOCK_EX)
        yield


@pytest.fixture(scope="session")
def shared_folder(tmp_path_factory: pytest.TempPathFactory) -> Callable[[str, Callable[[Path], None]], Path]:
    """``shared_folder(key, make)``: a folder filled once by ``make(folder)`` and shared by the whole test run.

    Under pytest-xdist the workers share it: the first to ask makes it, the others wait for it and read it; after
    a ``make`` that failed, the next asker starts again. Tests must not change the folder: copy it first.
    """
    base = tmp_path_factory.getbasetemp()
    if os.environ.get("PYTEST_XDIST_WORKER") and fcntl is not None:
        base = base.parent  # the run's temporary folder, above each worker's own
    root = base / "shared"
    root.mkdir(exist_ok=True)

    def folder(key: str, make: Callable[[Path], None]) -> Path:
        path, done = root / key, root / f"{key}.done"
        with _locked(root / f"{key}.lock"):
            if not done.exists():
                shutil.rmtree(path, ignore_errors=True)
                path.mkdir()
                make(path)
                done.touch()
        return path

    return folder


class SmokeRuns(Mapping):
    """The shipped studies' smoke runs by study name (the file's stem), each run when first looked up."""

    def __init__(self, shared_folder: Callable[[str, Callable[[Path], None]], Path]) -> None:
        self._shared_folder = shared_folder
        self._names = sorted(path.stem for path in STUDIES.glob("*.yaml"))

    def __getitem__(self, study: str) -> Path:
        if study not in self._names:
            raise KeyError(study)

        def make(folder: Path) -> None:
            command = ["run", str(STUDIES / f"{study}.yaml"), "--out", str(folder / "out"), "--quiet"]
            assert main([*command, "--smoke", "--executor", "serial"]) == 0

        return self._shared_folder(f"smoke-{study}", make) / "out"

    def __iter__(self) -> Iterator[str]:
        return iter(self._names)

    def __len__(self) -> int:
        return len(self._names)


@pytest.fixture(scope="session")
def smoke_runs(shared_folder) -> SmokeRuns:
    """``smoke_runs[study]``: the output folder of ``studies/<study>.yaml`` run once at smoke size, serial and
    in-process, as ``crx run STUDY --out FOLDER --quiet --smoke --executor serial`` runs it. Read-only: a test
    that changes a run's files works on a copy (``shutil.copytree``)."""
    return SmokeRuns(shared_folder)
