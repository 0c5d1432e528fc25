"""The motion sections of an arm study: the duty cycle it must make (with its payload), and what it is rated for."""

from __future__ import annotations

import builtins
import itertools
from typing import Any

from pydantic import Field, model_validator

from ..arm.duty_cycle import Payload
from ..errors import InvalidParameter
from .quantities import (
    Dwell,
    JointAcceleration,
    JointPosition,
    JointSpeed,
    PartInertia,
    PartMass,
    Rate,
    StoppingTime,
)
from .quantities import Payload as PayloadMass
from .spec_base import Spec, exactly_one

DEFAULT_DWELL = 0.0
DEFAULT_RATE = 1000.0
_VIA_ONLY = ("max_speed", "max_acceleration", "dwell", "rate")


class PayloadSpec(Spec):
    """The payload the arm carries over its duty cycle, its centre of mass at the contact point."""

    mass: PartMass = Field(gt=0, description="payload mass [kg]")
    inertia: tuple[
        tuple[PartInertia, PartInertia, PartInertia],
        tuple[PartInertia, PartInertia, PartInertia],
        tuple[PartInertia, PartInertia, PartInertia],
    ] = Field(
        ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0), (0.0, 0.0, 0.0)),
        description="3x3 inertia about the centre of mass, contact-frame axes [kg m^2]; default a point mass",
    )

    @model_validator(mode="after")
    def _physical(self) -> PayloadSpec:
        try:
            Payload(self.mass, self.inertia)  # type: ignore[arg-type]
        except InvalidParameter as error:
            raise ValueError(f"payload {error.name}: {error.allowed}") from None
        return self


class DutyCycleSpec(Spec):
    """The motion the arm must make: a trajectory file, or a motion through via configurations.

    ``file``: a CSV with a time column and one position column per joint (named by the joint, units in the
    header, e.g. ``time [s]``, ``shoulder [deg]``), relative to the study file; columns of other names are
    ignored. ``via``: configurations [rad] passed through at rest, joined by synchronised trapezoidal profiles
    within ``max_speed`` and ``max_acceleration`` (one value for every joint, or a mapping by joint name), with
    ``dwell`` at each via point and sampled at ``rate``.
    """

    file: str | None = Field(None, description="trajectory CSV, relative to the study file")
    via: builtins.list[builtins.list[JointPosition]] | None = Field(
        None, min_length=2, description="via configurations [rad], one position per joint, at least 2"
    )
    max_speed: JointSpeed | None = Field(
        None, description="joint speed limit [rad/s] (via only): one for all joints or by joint name"
    )
    max_acceleration: JointAcceleration | None = Field(
        None, description="joint acceleration limit [rad/s^2] (via only): one for all joints or by joint name"
    )
    dwell: Dwell | None = Field(
        None, description=f"rest at each via point [s] (via only; default {DEFAULT_DWELL:g} s)"
    )
    rate: Rate | None = Field(
        None, gt=0, description=f"sampling rate [Hz] (via only; default {DEFAULT_RATE:g} Hz)"
    )
    payload: PayloadSpec | None = Field(
        None, description="payload carried (default: constraints.payload as a point mass, if any)"
    )

    @model_validator(mode="after")
    def _one_source(self) -> DutyCycleSpec:
        exactly_one(self, ("file", "via"), "the duty cycle")
        if self.file is not None:
            given = [name for name in _VIA_ONLY if getattr(self, name) is not None]
            if given:
                raise ValueError(
                    f"{', '.join(given)} only with via points (a trajectory file gives the motion)"
                )
            return self
        missing = [name for name in ("max_speed", "max_acceleration") if getattr(self, name) is None]
        if missing:
            raise ValueError(f"{' and '.join(missing)} for a motion through via points")
        dwell = self.dwell if self.dwell is not None else DEFAULT_DWELL
        if isinstance(dwell, builtins.list) and len(dwell) != len(self.via or []):
            raise ValueError(
                f"dwell: one time for all via points or one per via point ({len(self.via or [])})"
            )
        rate = self.rate if self.rate is not None else DEFAULT_RATE
        samples = _motion_duration_bound(self.via or [], self.max_speed, self.max_acceleration, dwell) * rate
        if samples > MAX_CYCLE_SAMPLES:
            raise ValueError(
                f"a motion of at most {MAX_CYCLE_SAMPLES:.0e} samples (these via points, limits and rate may "
                f"need up to {samples:.2g}): raise max_speed or max_acceleration, or lower the rate"
            )
        # The defaults become explicit (the resolved study shows them).
        object.__setattr__(self, "dwell", dwell)
        object.__setattr__(self, "rate", rate)
        return self


MAX_CYCLE_SAMPLES = 500_000
"""Most samples of a via-point motion: 500 s at 1 kHz; each sample costs the dynamics of every joint."""


def _motion_duration_bound(via: Any, speed: Any, acceleration: Any, dwell: Any) -> float:
    """An upper bound of a via-point motion's duration [s], before the joints are known.

    A rest-to-rest move of distance d within speed v and acceleration a takes at most d/v + v/a (less when it
    never reaches v). Bounded with the largest step between via points, the lowest speed limit and the highest
    speed over the lowest acceleration limit.
    """
    speeds = list(speed.values()) if isinstance(speed, dict) else [speed]
    accelerations = list(acceleration.values()) if isinstance(acceleration, dict) else [acceleration]
    if not speeds or not accelerations:
        return 0.0
    v_min, v_max, a_min = min(speeds), max(speeds), min(accelerations)
    steps = [
        max((abs(b - a) for a, b in zip(start, end, strict=False)), default=0.0)
        for start, end in itertools.pairwise(via)
    ]
    rests = sum(dwell) if isinstance(dwell, builtins.list) else dwell * len(via)
    return sum(step / v_min + v_max / a_min for step in steps) + rests


class RatingSpec(Spec):
    """What the robot is rated for, as its datasheet gives it (each figure optional).

    At every sampled configuration the joints must hold the payload still (the static hold), move at their rated
    speeds while accelerating at their rated accelerations (the rated motion) and stop from their rated speeds
    within their stopping times (braking), all with the rated payload; the motors and gearboxes must turn at the
    rated speeds. Speeds, accelerations and stopping times: one value for every joint or a mapping by joint name.
    """

    payload: PayloadMass | None = Field(
        None,
        ge=0,
        description="rated payload [kg], held still at every sampled configuration (the static hold) and carried "
        "in the rated motion; null: the payload the study carries (duty_cycle.payload or constraints.payload)",
    )
    joint_speeds: JointSpeed | None = Field(
        None, description="rated joint speeds [rad/s]: one for all joints or by joint name"
    )
    joint_accelerations: JointAcceleration | None = Field(
        None, description="rated joint accelerations [rad/s^2]: one for all joints or by joint name"
    )
    stopping_time: StoppingTime | None = Field(
        None, description="time to stop from the rated speed [s] (needs joint_speeds): one or by joint name"
    )

    @model_validator(mode="after")
    def _stops_from_a_speed(self) -> RatingSpec:
        if self.stopping_time is not None and self.joint_speeds is None:
            raise ValueError("stopping_time needs the joint_speeds it stops from")
        return self
