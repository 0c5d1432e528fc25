"""Gearboxes scaled by their laws, catalogue gearboxes, and gearboxes scaled to their motor.

The scaling laws (:mod:`collision_reflex.hardware.gearbox_scaling`, Saerens et al. 2019) say how a gearbox's
quantities change with its size relative to a reference gearbox. So a gearbox is described by a real one (its
own mass, inertia and rated torque at its size, with a source), and :meth:`Gearbox.scaled` moves it to another
size. No reference values are built in: gearbox data vary too much between makers for one default to be
honest, and the paper ignores gearbox inertia (as does :class:`~collision_reflex.hardware.actuators.Actuator`
unless asked).

Real gearboxes one can buy are :class:`CatalogueGearbox` entries of ``designs/gearboxes.yaml``
(:func:`load_gearbox_catalogue`), each figure with its source. A :class:`ScaledGearbox` is a joint's
transmission in a design optimisation: a catalogue unit of its kind scaled, by the same laws, to carry the
motor's peak output torque, so that its mass and inertia grow with the torque the design asks of it.

Inertia convention: ``inertia`` is the gearbox's own inertia seen at its input (motor) shaft [kg m^2], so its
reflected inertia at the output is ``N**2 inertia`` (the table's ``l r^4 N^2``); a ball screw's ``inertia`` is
already the reflected one (the table's ``l r^4``, without ``N``).

Figures per ratio: a datasheet may give a catalogue gearbox's inertia and torques per ratio. The entry's own
figures are then the least favourable over its ratios (safe at every ratio, what a design whose ratio is still
free between them is charged), and :meth:`CatalogueGearbox.at_ratio` is the gearbox as sold at one ratio, with
that ratio's figures: what a design at an offered ratio is charged.
"""

from __future__ import annotations

import math
import numbers
import os
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any, NamedTuple, Protocol

import numpy as np

from .. import _validate
from ..errors import InvalidParameter
from ..vocabulary import GEARBOX_KINDS, PER_RATIO_FIELDS
from .gearbox_scaling import GEARBOX_SCALING

__all__ = [
    "CatalogueGearbox",
    "Gearbox",
    "RatioFigures",
    "ScaledGearbox",
    "load_gearbox_catalogue",
]

_STAGED = ("parallel_shaft", "planetary")

RATIO_TOLERANCE = 1e-6
"""Relative difference within which a design's gear ratio is one of a gearbox's offered ratios [-] (a ratio
fixed at an offered one comes back from the solver equal to it, or within rounding)."""


@dataclass(frozen=True)
class Gearbox:
    """A gearbox of a given kind and size, with the figures of a real unit to scale from.

    Parameters
    ----------
    kind: one of :data:`~collision_reflex.vocabulary.GEARBOX_KINDS`.
    stages: number of stages ``a`` (parallel shaft and planetary only; 1 for the others).
    diameter: outer diameter ``r`` [m].
    length: length ``l`` [m].
    mass: mass [kg].
    inertia: inertia at the input shaft [kg m^2] (a ball screw: its reflected inertia, see the module).
    rated_torque: rated output torque [N m].
    source: where the figures come from.
    """

    kind: str
    stages: int = 1
    diameter: float = math.nan
    length: float = math.nan
    mass: float = math.nan
    inertia: float = math.nan
    rated_torque: float = math.nan
    source: str = ""

    def __post_init__(self) -> None:
        _validate.choice("Gearbox.kind", self.kind, GEARBOX_KINDS)
        if isinstance(self.stages, bool) or not isinstance(self.stages, numbers.Integral) or self.stages < 1:
            raise InvalidParameter("Gearbox.stages", self.stages, "an integer >= 1")
        if self.stages != 1 and self.kind not in _STAGED:
            raise InvalidParameter(
                "Gearbox.stages",
                self.stages,
                f"1 for a {self.kind} gearbox",
                "only parallel-shaft and planetary gearboxes have a number of stages in the scaling laws",
            )
        for field in ("diameter", "length", "mass", "inertia", "rated_torque"):
            value = getattr(self, field)
            if isinstance(value, bool) or not isinstance(value, numbers.Real):
                raise InvalidParameter(f"Gearbox.{field}", value, "a number (SI units)")
            if math.isnan(value):
                raise InvalidParameter(
                    f"Gearbox.{field}",
                    value,
                    "a finite number > 0",
                    "give the figures of a real gearbox of this kind (from its datasheet), then use "
                    ".scaled(...) to move it to another size",
                )
            _validate.positive(f"Gearbox.{field}", value)
            object.__setattr__(self, field, float(value))

    def reflected_inertia(self, gear_ratio: float | np.ndarray) -> float | np.ndarray:
        """Gearbox inertia seen at the output [kg m^2]: ``N**2 inertia`` (ball screw: ``inertia``)."""
        _validate.positive("gear_ratio", gear_ratio)
        return self.inertia if self.kind == "ball_screw" else gear_ratio**2 * self.inertia

    def scaled(
        self, diameter: float | None = None, length: float | None = None, stages: int | None = None
    ) -> Gearbox:
        """Return this gearbox moved to another diameter [m], length [m] and/or number of stages by its law."""
        new_diameter = self.diameter if diameter is None else diameter
        new_length = self.length if length is None else length
        new_stages = self.stages if stages is None else stages
        _validate.positive("diameter", new_diameter)
        _validate.positive("length", new_length)
        ratios = (new_length / self.length, new_diameter / self.diameter, new_stages / self.stages)
        mass_law, inertia_law, torque_law = GEARBOX_SCALING[self.kind]
        return Gearbox(
            kind=self.kind,
            stages=new_stages,
            diameter=float(new_diameter),
            length=float(new_length),
            mass=self.mass * mass_law.factor(*ratios),
            inertia=self.inertia * inertia_law.factor(*ratios),
            rated_torque=self.rated_torque * torque_law.factor(*ratios),
            source=f"scaled by the {self.kind} law of Saerens et al. 2019 from: {self.source}",
        )

    def catalogue_entry(
        self,
        name: str,
        ratio_range: tuple[float, float],
        peak_torque: float | None = None,
        efficiency: float | None = None,
        max_input_speed: float | None = None,
    ) -> CatalogueGearbox:
        """Make this gearbox a joint's gearbox entry, for the arm optimiser (one mechanism for every gearbox).

        Parameters
        ----------
        name : str
            What reports call it.
        ratio_range : (float, float)
            The ratios it may have [-], ``(min, max)``: a scaled gearbox has no list of ratios, so the design's
            gear-ratio bounds.
        peak_torque : float, optional
            Repeated peak output torque [N m]; default the rated torque (nothing known above it).
        efficiency : float, optional
            Efficiency in (0, 1] [-]; default 1 (lossless).
        max_input_speed : float, optional
            Maximum input speed [rad/s]; default none.
        """
        low, high = (float(r) for r in ratio_range)
        _validate.positive("ratio_range", np.array([low, high]))
        if low > high:
            raise InvalidParameter("ratio_range", ratio_range, "(min, max) with min <= max")
        return CatalogueGearbox(
            name=name,
            kind=self.kind,
            ratios=(low, high),
            continuous_ratio=True,
            rated_torque=self.rated_torque,
            peak_torque=self.rated_torque if peak_torque is None else float(peak_torque),
            mass=self.mass,
            inertia=self.inertia,
            source=self.source,
            efficiency=1.0 if efficiency is None else float(efficiency),
            stages=self.stages,
            max_input_speed=max_input_speed,
            diameter=self.diameter,
            length=self.length,
        )


class _Range(Protocol):
    """Bounds of a gear ratio [-] (e.g. :class:`collision_reflex.optimize.space.Bounds`)."""

    @property
    def lower(self) -> float: ...

    @property
    def upper(self) -> float: ...


class _OfferedRatios:
    """The ratios a gearbox is sold with: their range, and a gear-ratio range clipped to it."""

    ratios: tuple[float, ...]

    @property
    def ratio_range(self) -> tuple[float, float]:
        """The smallest and largest ratio offered [-]."""
        return self.ratios[0], self.ratios[-1]

    def clip(self, bounds: _Range) -> tuple[float, float]:
        """The gear-ratio ``bounds`` intersected with :attr:`ratio_range`: ``(lower, upper)`` [-].

        Empty (``lower > upper``) when they do not overlap: the caller says what that means for it.
        """
        low, high = self.ratio_range
        return max(bounds.lower, low), min(bounds.upper, high)


class RatioFigures(NamedTuple):
    """A catalogue gearbox's figures at one of its ratios (those of :data:`~collision_reflex.vocabulary.PER_RATIO_FIELDS`, SI).

    ratio [-]; rated_torque, peak_torque [N m]; momentary_torque [N m] or None; inertia at the input [kg m^2].
    """

    ratio: float
    rated_torque: float
    peak_torque: float
    momentary_torque: float | None
    inertia: float


@dataclass(frozen=True)
class CatalogueGearbox(_OfferedRatios):
    """A gearbox one can buy: a catalogue entry's figures (SI), as its datasheet states them.

    Parameters
    ----------
    name : str
        The catalogue key (maker's designation).
    kind : str
        One of :data:`~collision_reflex.vocabulary.GEARBOX_KINDS`.
    ratios : tuple of float
        The ratios offered [-], ascending; or ``(min, max)`` when ``continuous_ratio``.
    continuous_ratio : bool
        True when any ratio between ``ratios[0]`` and ``ratios[-1]`` can be had (a range, not a list).
    rated_torque : float
        Rated (continuous) output torque [N m].
    peak_torque : float
        Repeated peak output torque (acceleration/braking) [N m].
    mass : float
        Mass [kg], >= 0: 0 builds the neutral gearbox, which adds nothing to the joint (a catalogue file, which
        lists real units, needs > 0).
    inertia : float
        Inertia at the input (motor) shaft [kg m^2], >= 0 as ``mass``; reflected to the output it is
        ``N**2 inertia``.
    source : str
        Where the figures come from (the default source of every field).
    efficiency : float or None
        Efficiency in (0, 1] [-], or None when not given.
    stages : int
        Number of stages.
    momentary_torque : float or None
        Momentary (emergency-stop) output torque [N m], or None.
    max_input_speed : float or None
        Maximum input speed [rad/s], or None.
    diameter, length : float or None
        Outer diameter and length [m], or None.
    per_ratio : tuple of RatioFigures
        The figures at each offered ratio, in the order of ``ratios``, where the datasheet gives some per ratio;
        empty when the figures hold at every ratio. With them, ``rated_torque``, ``peak_torque``,
        ``momentary_torque`` and ``inertia`` are the least favourable over the ratios (see :meth:`at_ratio`).
    """

    name: str
    kind: str
    ratios: tuple[float, ...]
    continuous_ratio: bool
    rated_torque: float
    peak_torque: float
    mass: float
    inertia: float
    source: str
    efficiency: float | None = None
    stages: int = 1
    momentary_torque: float | None = None
    max_input_speed: float | None = None
    diameter: float | None = None
    length: float | None = None
    per_ratio: tuple[RatioFigures, ...] = ()

    def __post_init__(self) -> None:
        self._check_figures()
        if self.per_ratio and (
            self.continuous_ratio or tuple(f.ratio for f in self.per_ratio) != tuple(self.ratios)
        ):
            raise InvalidParameter(
                f"gearbox {self.name!r} per_ratio",
                tuple(f.ratio for f in self.per_ratio),
                f"the figures of each offered ratio, {tuple(self.ratios)}, in order (a ratio range has none)",
            )

    def _check_figures(self) -> None:
        """Raise :class:`InvalidParameter` naming the field unless each figure is as the catalogue file allows."""
        label = f"gearbox {self.name!r}"
        ratios = _validate.real(f"{label} ratios", self.ratios, "gear ratios >= 1, at least one")
        if ratios.ndim != 1 or not ratios.size or not np.all(np.isfinite(ratios) & (ratios >= 1)):
            raise InvalidParameter(f"{label} ratios", self.ratios, "gear ratios >= 1, at least one")
        if not isinstance(self.continuous_ratio, bool | np.bool_):
            raise InvalidParameter(f"{label} continuous_ratio", self.continuous_ratio, "True or False")
        optional = ("momentary_torque", "max_input_speed", "diameter", "length", "efficiency")
        for name in ("rated_torque", "peak_torque", "mass", "inertia", *optional):
            value = getattr(self, name)
            if value is None and name in optional:
                continue
            check = (
                _validate.non_negative if name in ("mass", "inertia") else _validate.positive
            )  # 0: the neutral gearbox
            if np.ndim(check(f"{label} {name}", value)) or (name == "efficiency" and value > 1):
                allowed = "a number in (0, 1], or None" if name == "efficiency" else "one finite number"
                raise InvalidParameter(f"{label} {name}", value, allowed)
        stages = self.stages
        if isinstance(stages, bool) or not isinstance(stages, numbers.Integral) or stages < 1:
            raise InvalidParameter(f"{label} stages", stages, "an integer >= 1")
        if not isinstance(self.per_ratio, tuple) or not all(
            isinstance(f, RatioFigures) for f in self.per_ratio
        ):
            raise InvalidParameter(f"{label} per_ratio", self.per_ratio, "a tuple of RatioFigures")

    def at_ratio(self, gear_ratio: float) -> CatalogueGearbox:
        """The gearbox as sold at ``gear_ratio`` [-]: that ratio's figures, and that ratio alone.

        Itself where its figures hold at every ratio (no per-ratio figures), and at a ratio it does not offer
        (a design whose ratio is free between its ratios): then its least favourable figures.
        """
        at = next(
            (f for f in self.per_ratio if math.isclose(f.ratio, gear_ratio, rel_tol=RATIO_TOLERANCE)), None
        )
        if at is None or len(self.per_ratio) == 1:
            return self
        figures = at._asdict()
        del figures["ratio"]
        return replace(self, ratios=(at.ratio,), per_ratio=(at,), **figures)

    def inertia_at(self, gear_ratio: float) -> float:
        """Inertia at the input [kg m^2] at ``gear_ratio`` [-] (see :meth:`at_ratio`)."""
        return self.at_ratio(gear_ratio).inertia

    def reflected_inertia(self, gear_ratio: float) -> float:
        """Gearbox inertia seen at the output [kg m^2]: ``N**2 J_g(N)``, ``J_g(N)`` :meth:`inertia_at` ``N``."""
        _validate.positive("gear_ratio", gear_ratio)
        return float(gear_ratio**2 * self.inertia_at(gear_ratio))


class ScaledFigures(NamedTuple):
    """A :class:`ScaledGearbox`'s figures at one size (NumPy arrays or CasADi expressions alike).

    mass [kg]; inertia: at the input [kg m^2]; rated_torque, peak_torque: output [N m]; max_input_speed
    [rad/s] (None when the reference gives none).
    """

    mass: Any
    inertia: Any
    rated_torque: Any
    peak_torque: Any
    max_input_speed: Any


@dataclass(frozen=True)
class ScaledGearbox(_OfferedRatios):
    """A gearbox of ``reference``'s kind sized to carry its motor's peak output torque ``N tau_p``.

    The size follows the kind's law of :data:`~collision_reflex.hardware.gearbox_scaling.GEARBOX_SCALING` at
    the reference's length and stages: the output torque scales as ``d**e_T`` in the outer diameter ``d``, so a
    unit whose repeated peak torque is ``T`` has ``d/d0 = (T/T0)**(1/e_T)``, mass ``m0 (d/d0)**e_m`` and input inertia ``J0 (d/d0)**e_J`` (a
    strain-wave unit: mass ``∝ T**(2/3)``, inertia ``∝ T**(4/3)``); rated torque and efficiency are the
    reference's, the rated torque in proportion. Sizing it to the motor's peak output torque (not to the
    requirement) is the rule that a gearbox survives whatever its motor can apply (the collision reaction brakes
    with the full ``N tau_p``). ESTIMATE: the maximum input speed, where the reference gives one, scales as
    ``1/d`` (a constant pitch-line speed of the gear mesh), which the table of laws does not give.

    reference: the catalogue unit scaled from (its kind, figures and source; where its figures vary with the
        ratio, its least favourable ones, as the scaled unit's ratio is free).
    ratios: the ratios the kind is sold with [-], ascending: a design relaxes them to the range between the
        first and the last; its catalogue design picks an offered one.
    largest: the largest unit of the kind one can buy (by repeated peak torque), or None: a design whose
        requirement is beyond its rating has no gearbox to buy, so its rating bounds the requirement.
    """

    reference: CatalogueGearbox
    ratios: tuple[float, ...]
    largest: CatalogueGearbox | None = None

    def __post_init__(self) -> None:
        if not isinstance(self.reference, CatalogueGearbox):
            raise InvalidParameter("ScaledGearbox.reference", self.reference, "a CatalogueGearbox")
        if self.reference.kind not in GEARBOX_SCALING:
            raise InvalidParameter(
                "ScaledGearbox.reference.kind", self.reference.kind, f"one of {GEARBOX_KINDS}"
            )
        given = _validate.real("ScaledGearbox.ratios", self.ratios, "ratios >= 1, at least one")
        ratios = tuple(sorted(given.tolist())) if given.ndim == 1 else ()
        if not ratios or not all(math.isfinite(r) and r >= 1 for r in ratios):
            raise InvalidParameter("ScaledGearbox.ratios", self.ratios, "ratios >= 1, at least one")
        object.__setattr__(self, "ratios", ratios)
        if self.largest is not None and self.largest.kind != self.kind:
            raise InvalidParameter(
                "ScaledGearbox.largest",
                self.largest.name,
                f"a {self.kind} gearbox, the kind of the reference",
            )

    @property
    def kind(self) -> str:
        """The kind of gearbox (the reference's)."""
        return self.reference.kind

    @property
    def name(self) -> str:
        """What reports call it."""
        largest = self.largest
        beyond = "" if largest is None else f" (at most {largest.name}'s {largest.peak_torque:.4g} N*m)"
        return f"{self.kind} scaled from {self.reference.name}{beyond}"

    @property
    def efficiency(self) -> float | None:
        """The reference's efficiency (None when it gives none)."""
        return self.reference.efficiency

    def figures(self, peak_torque: Any) -> ScaledFigures:
        """The unit whose repeated peak output torque is ``peak_torque`` [N m] (NumPy or CasADi)."""
        mass_law, inertia_law, torque_law = GEARBOX_SCALING[self.kind]
        scale = peak_torque / self.reference.peak_torque
        diameter = scale ** (1.0 / torque_law.diameter)
        speed = self.reference.max_input_speed
        return ScaledFigures(
            mass=self.reference.mass * diameter**mass_law.diameter,
            inertia=self.reference.inertia * diameter**inertia_law.diameter,
            rated_torque=self.reference.rated_torque * scale,
            peak_torque=peak_torque,
            max_input_speed=None if speed is None else speed / diameter,
        )

    def unit(self, peak_torque: float) -> CatalogueGearbox:
        """The unit at ``peak_torque`` [N m] as a catalogue entry (for the catalogue search and the report)."""
        figures = self.figures(float(peak_torque))
        reference = self.reference
        return CatalogueGearbox(
            name=f"{self.kind} scaled from {reference.name} to {float(peak_torque):.4g} N*m",
            kind=self.kind,
            ratios=self.ratio_range,
            continuous_ratio=True,
            rated_torque=float(figures.rated_torque),
            peak_torque=float(peak_torque),
            mass=float(figures.mass),
            inertia=float(figures.inertia),
            source=f"scaled by the {self.kind} law of Saerens et al. 2019 from: {reference.source}",
            efficiency=reference.efficiency,
            stages=reference.stages,
            max_input_speed=None if figures.max_input_speed is None else float(figures.max_input_speed),
        )


def load_gearbox_catalogue(path: str | os.PathLike[str] | None = None) -> dict[str, CatalogueGearbox]:
    """Gearboxes of a YAML catalogue file, by name (default: the packaged ``designs/gearboxes.yaml``).

    The file has a top-level ``gearboxes`` mapping from name to entry; each entry gives ``kind``, ``ratios``
    (a list) or ``ratio_range`` ([min, max]), ``rated_torque``, ``peak_torque``, ``mass``, ``inertia``
    (input side) and a ``source``, optionally ``efficiency``, ``stages``, ``momentary_torque``,
    ``max_input_speed``, ``diameter``, ``length``, and the per-field ``sources`` and ``estimates``. Numbers
    are plain SI or strings with units (``"0.13 kg*cm^2"``). Bad input raises
    :class:`~collision_reflex.errors.CatalogueError` naming the file, the line and the field.

    Parameters
    ----------
    path : str or path-like, optional
        The catalogue file; default the packaged one.
    """
    from .catalogue import packaged_catalogue_path, read_entries  # lazy: pydantic, yaml

    target = Path(path) if path is not None else packaged_catalogue_path("gearboxes.yaml")
    gearboxes = {}
    for name, entry in read_entries(target, "gearboxes").items():
        fields = dict(entry.fields)
        listed, low_high = fields.pop("ratios"), fields.pop("ratio_range")
        for provenance in ("sources", "estimates"):
            fields.pop(provenance)
        ratios = tuple(sorted(listed if listed is not None else low_high))
        per_ratio = _per_ratio_figures(fields, ratios)
        for field, least_favourable in _LEAST_FAVOURABLE.items():
            if isinstance(fields[field], dict):  # the entry's own figure: safe at every ratio
                fields[field] = least_favourable(fields[field].values())
        gearboxes[name] = CatalogueGearbox(
            name=name, ratios=ratios, continuous_ratio=listed is None, per_ratio=per_ratio, **fields
        )
    return gearboxes


# The least favourable of a field's per-ratio figures: the smallest torque rating, the largest inertia.
_LEAST_FAVOURABLE = {"rated_torque": min, "peak_torque": min, "momentary_torque": min, "inertia": max}


def _per_ratio_figures(fields: dict[str, Any], ratios: tuple[float, ...]) -> tuple[RatioFigures, ...]:
    """Each ratio's figures where an entry gives a field per ratio (a mapping ratio -> value); else ()."""
    if not any(isinstance(fields[field], dict) for field in PER_RATIO_FIELDS):
        return ()

    def at(field: str, ratio: float) -> Any:
        value = fields[field]
        return value[ratio] if isinstance(value, dict) else value

    return tuple(RatioFigures(ratio, *(at(field, ratio) for field in PER_RATIO_FIELDS)) for ratio in ratios)
