"""Gearbox scaling laws of tab:scaling_laws (Saerens et al. 2019) against hand computation."""

from __future__ import annotations

import pytest

import collision_reflex as cr

BASE = dict(diameter=0.05, length=0.04, mass=0.3, inertia=2e-6, rated_torque=10.0, source="test unit")

# kind -> exponents of (l, r, a) for mass, inertia (input side), torque, from tab:scaling_laws.
TABLE = {
    "parallel_shaft": ((1, 2, 0), (1, 4, -1), (1, 2, -1)),
    "planetary": ((1, 2, 0), (1, 4, -1), (1, 2, -1)),
    "harmonic": ((1, 2, 0), (1, 4, 0), (0, 3, 0)),
    "cycloidal": ((1, 2, 0), (1, 4, 0), (-1, 4, 0)),
    "ball_screw": ((1, 2, 0), (1, 4, 0), (0, 3, 0)),
}


@pytest.mark.parametrize("kind", TABLE, ids=TABLE.keys())
def test_gearbox_scaling_by_hand(kind):
    staged = kind in ("parallel_shaft", "planetary")
    gearbox = cr.Gearbox(kind, 2 if staged else 1, **BASE)
    new_stages = 3 if staged else 1
    scaled = gearbox.scaled(diameter=0.1, length=0.06, stages=new_stages)  # r x2, l x1.5, a x1.5 (staged)
    a_ratio = new_stages / gearbox.stages

    def factor(p, e, s):
        return 1.5**p * 2.0**e * a_ratio**s

    mass_e, inertia_e, torque_e = TABLE[kind]
    assert scaled.mass == pytest.approx(0.3 * factor(*mass_e), rel=1e-14)
    assert scaled.inertia == pytest.approx(2e-6 * factor(*inertia_e), rel=1e-14)
    assert scaled.rated_torque == pytest.approx(10.0 * factor(*torque_e), rel=1e-14)


@pytest.mark.parametrize("kind", TABLE, ids=TABLE.keys())
def test_reflected_gearbox_inertia(kind):
    gearbox = cr.Gearbox(kind, **BASE)
    expected = 2e-6 if kind == "ball_screw" else 49 * 2e-6  # the table: l r^4 (ball screw) vs l r^4 N^2
    assert gearbox.reflected_inertia(7.0) == pytest.approx(expected, rel=1e-15)


def test_gearbox_needs_reference_figures_and_valid_stages():
    with pytest.raises(cr.InvalidParameter, match="datasheet"):
        cr.Gearbox("planetary")
    with pytest.raises(cr.InvalidParameter, match="stages"):
        cr.Gearbox("harmonic", 2, **BASE)
    with pytest.raises(cr.InvalidParameter, match="kind"):
        cr.Gearbox("worm", **BASE)
