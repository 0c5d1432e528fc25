"""How an arm study's run goes, by the sections that say it.

The Pareto front, the catalogue snap, the worst-case search, the solver, the time-domain simulation, the
executor and the files written.
"""

from __future__ import annotations

import re
from typing import Annotated, Literal

from pydantic import Field, field_validator, model_validator

from ..simulate.validity import available_detections
from ..vocabulary import ActiveSetMode, ExecutorName, GearboxKind, ObjectiveName
from .spec_base import Spec


class ParetoSpec(Spec):
    """The Pareto front to trace: two or three objectives, the number of points, the anchors' start points."""

    objectives: list[ObjectiveName] = Field(min_length=2, max_length=3)
    points: Annotated[int, Field(ge=2, le=400, strict=True)] = 20
    anchor_starts: Annotated[
        int,
        Field(
            ge=1,
            le=50,
            strict=True,
            description="start points of each anchor's first solve (multi-start against local optima)",
        ),
    ] = 1

    @field_validator("objectives")
    @classmethod
    def _distinct(cls, value: list[str]) -> list[str]:
        if len(set(value)) != len(value):
            raise ValueError("different objectives")
        return value


class CatalogueSpec(Spec):
    """The catalogue the recommended design (and every Pareto design) is snapped to after the front.

    See :mod:`collision_reflex.optimize.snap`: per joint the ``candidates`` nearest catalogue motors within
    bounds; every combination re-solved when there are at most ``max_combinations``, else coordinate descent.
    """

    snap: bool = Field(True, description="snap the recommended and the Pareto designs to catalogue parts")
    motors: str | None = Field(
        None, description="motor catalogue file, relative to the study file; null: the packaged catalogue"
    )
    gearboxes: str | None = Field(
        None, description="gearbox catalogue file, relative to the study file; null: the packaged catalogue"
    )
    candidates: Annotated[int, Field(ge=1, le=20, strict=True)] = Field(
        3, description="catalogue motors considered per joint, the nearest to the continuous optimum first"
    )
    max_combinations: Annotated[int, Field(ge=1, le=10000, strict=True)] = Field(
        64, description="the most combinations re-solved exactly; beyond, a coordinate-descent heuristic"
    )
    gearbox_kinds: list[GearboxKind] | None = Field(
        None,
        description="the gearbox kinds a joint may take in the catalogue design, e.g. [harmonic, planetary]; "
        "null: the kind of its study gearbox",
    )


class OutputsSpec(Spec):
    """Which files a run writes besides the results: figure formats and the PDF report."""

    figures: list[Literal["png", "svg"]] = Field(default_factory=lambda: ["png", "svg"])  # type: ignore[arg-type]
    pdf: bool = Field(False, description="also write report.pdf (needs Chromium)")


class SimulateSpec(Spec):
    """Simulate the recommended (and optionally each Pareto) design on its worst contact samples.

    The time-domain arm simulation beside the closed form, samples outside its validity region flagged.
    """

    recommended: bool = Field(True, description="simulate the recommended design")
    pareto: bool = Field(False, description="also simulate each Pareto design")
    samples: Annotated[int, Field(ge=1, le=50, strict=True)] = Field(
        3, description="contact samples per design: those with the largest closed-form impulse"
    )
    detection: str | None = Field(
        None,
        description="the simulator's detection scheme; null: its default (spring_torque, the joint spring torques' force estimate)",
    )
    contact_stiffness_ratio: float = Field(
        100.0, ge=1, le=1e4, description="the wall's stiffness over the joints' stiffness along u [-]"
    )
    tolerance: float = Field(
        0.05, gt=0, le=1, description="relative difference beyond which a sample is flagged [-]"
    )

    @field_validator("detection")
    @classmethod
    def _known_detection(cls, value: str | None) -> str | None:
        if value is not None and value not in available_detections():
            raise ValueError(f"one of {', '.join(available_detections())} (found {value!r})")
        return value


class SearchSpec(Spec):
    """The adversarial search of the contact domain that certifies each design's worst case.

    After the solves, the impulse of each design is maximised over the domain from its worst samples and from
    random points; the maxima above the design's worst case by more than ``tolerance`` join the samples, and
    the solves are repeated (the exchange method), at most ``rounds`` times.
    """

    enabled: bool = Field(True, description="search the domain after the solves; false: samples only")
    starts: Annotated[int, Field(ge=1, le=64, strict=True)] = Field(
        6, description="local searches from the worst samples of each design"
    )
    random_starts: Annotated[int, Field(ge=0, le=64, strict=True)] = Field(
        4, description="local searches from random points of the domain, per design"
    )
    tolerance: Annotated[float, Field(gt=0, le=0.5, allow_inf_nan=False)] = Field(
        0.005,
        description="relative excess over the reported worst case that makes a searched point a violator",
    )
    rounds: Annotated[int, Field(ge=1, le=10, strict=True)] = Field(
        4, description="most solve-and-search rounds; a worst case still exceeded after them is reported so"
    )
    seed: int = Field(0, ge=0, lt=2**64, strict=True, description="seed of the random starts")


class OptimizerSpec(Spec):
    """How the optimiser solves the study's problems (the numbers agree within the solver's tolerance)."""

    worst_case_search: SearchSpec = Field(default_factory=SearchSpec)  # type: ignore[arg-type]

    active_set: ActiveSetMode = Field(
        "auto",
        description="solve the optimum and every Pareto point on active sets of the contact samples (a subset, "
        "grown by the samples found above its worst case until none is: exact for worst-case objectives): "
        "'auto' from 128 samples (ACTIVE_SET_THRESHOLD), 'always', or 'never' (all samples in one NLP)",
    )


class ExecutionSpec(Spec):
    """Where the independent work runs: in-process, a local process pool, or a Dask cluster."""

    executor: ExecutorName = "serial"
    # Local worker processes: more than 256 is more than the cores of any one machine (a Dask cluster scales
    # with a scheduler address instead).
    workers: Annotated[int, Field(ge=1, le=256, strict=True)] = 2
    scheduler: str | None = Field(None, description="Dask scheduler address, e.g. tcp://host:8786")

    @model_validator(mode="after")
    def _scheduler(self) -> ExecutionSpec:
        if self.scheduler is not None and not re.match(r"^(tcp|tls|inproc|ucx)://\S+$", self.scheduler):
            raise ValueError(f"a scheduler address such as tcp://host:8786 (found {self.scheduler!r})")
        return self
