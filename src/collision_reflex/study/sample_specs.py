"""The sample sections of an arm study: configurations, contact directions, and the contact domain."""

from __future__ import annotations

import builtins
from typing import Annotated, Literal

from pydantic import Field, model_validator

from .quantities import JointPosition, JointSpeed, SingularValueFloor
from .spec_base import Spec, exactly_one

# Sample counts: a run evaluates every configuration in every direction, so more than these would take days;
# the bounds also keep a validation from allocating what the file merely names.
ConfigurationCount = Annotated[int, Field(ge=1, le=10_000, strict=True)]
DirectionCount = Annotated[int, Field(ge=1, le=10_000, strict=True)]
# A direction's components before normalisation: a bound keeps their squares finite.
Component = Annotated[float, Field(ge=-1e6, le=1e6, allow_inf_nan=False)]


class RandomConfigurations(Spec):
    """Configurations drawn at random within the joint limits."""

    count: ConfigurationCount = Field(
        description="number of configurations drawn uniformly within joint limits"
    )
    seed: int = Field(0, ge=0, lt=2**64, strict=True, description="seed of the numpy Generator (>= 0)")


class TrajectorySpec(Spec):
    """Configurations read from a trajectory file (joint positions [rad])."""

    file: str = Field(description="CSV of joint positions [rad], one row per time step, one column per joint")
    every: Annotated[int, Field(ge=1, le=1_000_000, strict=True)] = Field(1, description="use every n-th row")


class ConfigurationSamples(Spec):
    """Exactly one of ``random``, ``list`` or ``trajectory``."""

    random: RandomConfigurations | None = None
    list: builtins.list[builtins.list[JointPosition]] | None = Field(
        None, min_length=1, description="configurations [rad]"
    )
    trajectory: TrajectorySpec | None = None

    @model_validator(mode="after")
    def _one(self) -> ConfigurationSamples:
        exactly_one(self, ("random", "list", "trajectory"), "configurations")
        return self


class DirectionSamples(Spec):
    """The contact directions: exactly one of ``circle``, ``sphere``, ``named`` or ``list``.

    ``circle``: n directions in the plane (the arm's plane, or the world x-y plane); ``sphere``: n directions
    spread evenly over the sphere; ``named`` or ``list``: vectors, normalised.
    """

    circle: DirectionCount | None = None
    sphere: DirectionCount | None = None
    named: builtins.list[Literal["+x", "-x", "+y", "-y", "+z", "-z"]] | None = Field(None, min_length=1)
    list: builtins.list[builtins.list[Component]] | None = Field(None, min_length=1)

    @model_validator(mode="after")
    def _one(self) -> DirectionSamples:
        exactly_one(self, ("circle", "sphere", "named", "list"), "directions")
        for index, vector in enumerate(self.list or []):
            if not 2 <= len(vector) <= 3 or not any(vector) or not all(abs(x) < 1e300 for x in vector):
                raise ValueError(f"directions.list[{index}]: a non-zero finite vector of 2 or 3 components")
        return self


class DomainSpec(Spec):
    """Where contacts are considered: the domain a worst case is taken over.

    Configurations within the joint limits whose contact Jacobian has ``sigma_min(J_v)`` at least
    ``min_singular_value``, and directions along which the guarded move at the approach velocity stays within
    the joint speed limits (``J_v^+ u v0``). Random configurations are drawn in it.
    """

    min_singular_value: SingularValueFloor | None = Field(
        None,
        description="floor on the smallest singular value of the contact Jacobian [m]; null: a tenth of the "
        "arm's reach (the largest base-to-contact distance); 0: no floor (near singular poses the finger mass, "
        "and so the worst case, is unbounded)",
    )
    joint_speed_limit: JointSpeed | None = Field(
        None,
        description="joint speed limits of the guarded move [rad/s], one for all or by joint name; null: the "
        "URDF's velocity limits (a joint without one is not limited)",
    )


class SamplesSpec(Spec):
    """The contact samples: arm configurations crossed with contact directions, within the contact domain."""

    configurations: ConfigurationSamples
    directions: DirectionSamples
    domain: DomainSpec = Field(default_factory=DomainSpec)  # type: ignore[arg-type]
    error_tolerance: Annotated[float, Field(gt=0, le=1, allow_inf_nan=False)] = Field(
        0.02,
        description="largest relative sampling error (99 % bootstrap interval) of a mean impulse objective "
        "before the report warns and names the configurations that would meet it",
    )
    fresh: Annotated[int, Field(ge=0, le=65_536, strict=True)] = Field(
        4096,
        description="configurations drawn afresh in the contact domain (an independent stream of the random "
        "configurations' seed, with the study's directions) on which every reported design is checked after "
        "the solves: its largest impulse against its worst case, its mean and high quantile with their "
        "sampling errors; 0: no check (random configurations only)",
    )
