"""The gearbox scaling laws, by kind of gearbox: the kinds the package knows.

The laws are Saerens et al. 2019's, as tabulated in ``tab:scaling_laws`` of "Reacting to Contact: Transparency
and Collision Reflex in Actuation". A scaling law says how a quantity changes with the gearbox's outer diameter
``r``, length ``l`` and number of stages ``a``, relative to a reference gearbox: ``q = q0 (l/l0)**p (r/r0)**e
(a/a0)**s``. Kept apart from :mod:`collision_reflex.hardware.gearboxes` so that the catalogue reader
(:mod:`collision_reflex.hardware.catalogue`) checks a gearbox's kind without importing the gearboxes.
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["GEARBOX_SCALING", "GearboxScaling"]


@dataclass(frozen=True)
class GearboxScaling:
    """Exponents ``(p, e, s)`` of length, diameter and stages for one quantity of one kind of gearbox."""

    length: float
    diameter: float
    stages: float

    def factor(self, length_ratio: float, diameter_ratio: float, stages_ratio: float) -> float:
        """Scale factor ``(l/l0)**p (r/r0)**e (a/a0)**s`` for the given ratios to the reference [-]."""
        return length_ratio**self.length * diameter_ratio**self.diameter * stages_ratio**self.stages


# kind -> (mass, inertia, torque) exponents, from tab:scaling_laws (Saerens et al. 2019).
GEARBOX_SCALING: dict[str, tuple[GearboxScaling, GearboxScaling, GearboxScaling]] = {
    "parallel_shaft": (GearboxScaling(1, 2, 0), GearboxScaling(1, 4, -1), GearboxScaling(1, 2, -1)),
    "planetary": (GearboxScaling(1, 2, 0), GearboxScaling(1, 4, -1), GearboxScaling(1, 2, -1)),
    "harmonic": (GearboxScaling(1, 2, 0), GearboxScaling(1, 4, 0), GearboxScaling(0, 3, 0)),
    "cycloidal": (GearboxScaling(1, 2, 0), GearboxScaling(1, 4, 0), GearboxScaling(-1, 4, 0)),
    "ball_screw": (GearboxScaling(1, 2, 0), GearboxScaling(1, 4, 0), GearboxScaling(0, 3, 0)),
}
