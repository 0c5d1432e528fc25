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
    gearbox = cr.hardware.Gearbox(kind, 2 if staged else 1, **BASE)
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
    gearbox = cr.hardware.Gearbox(kind, **BASE)
    expected = 2e-6 if kind == "ball_screw" else 49 * 2e-6  # the table: l r^4 (ball screw) vs l r^4 N^2
    assert gearbox.reflected_inertia(7.0) == pytest.approx(expected, rel=1e-15)


def test_gearbox_needs_reference_figures_and_valid_stages():
    with pytest.raises(cr.InvalidParameter, match="datasheet"):
        cr.hardware.Gearbox("planetary")
    with pytest.raises(cr.InvalidParameter, match="stages"):
        cr.hardware.Gearbox("harmonic", 2, **BASE)
    with pytest.raises(cr.InvalidParameter, match="kind"):
        cr.hardware.Gearbox("worm", **BASE)


GEARBOX = """\
gearboxes:
  small:
    kind: planetary
    ratios: [3, 5, 10]
    rated_torque: 17 N*m
    peak_torque: 32
    mass: 1800 g
    inertia: 0.25 kg*cm^2
    efficiency: 0.97
    max_input_speed: 8000 rpm
    source: a test entry
"""


def _catalogue(tmp_path, text):
    from collision_reflex.hardware.gearboxes import load_gearbox_catalogue

    path = tmp_path / "gearboxes.yaml"
    path.write_text(text)
    return path, lambda: load_gearbox_catalogue(path)


def test_gearbox_catalogue_units_to_si(tmp_path):
    _, load = _catalogue(tmp_path, GEARBOX)
    gearbox = load()["small"]
    assert gearbox.inertia == pytest.approx(0.25e-4, rel=1e-12)  # 1 kg cm^2 = 1e-4 kg m^2
    assert gearbox.mass == pytest.approx(1.8, rel=1e-12)
    assert gearbox.max_input_speed == pytest.approx(8000 * 2 * 3.141592653589793 / 60, rel=1e-12)
    assert gearbox.ratios == (3.0, 5.0, 10.0) and not gearbox.continuous_ratio
    assert gearbox.reflected_inertia(10.0) == pytest.approx(100 * 0.25e-4, rel=1e-12)


def test_gearbox_ratio_range(tmp_path):
    _, load = _catalogue(tmp_path, GEARBOX.replace("ratios: [3, 5, 10]", "ratio_range: [50, 160]"))
    gearbox = load()["small"]
    assert gearbox.continuous_ratio and gearbox.ratio_range == (50.0, 160.0)


PER_RATIO = GEARBOX.replace(
    "inertia: 0.25 kg*cm^2", "inertia: {3: 0.25 kg*cm^2, 5: 0.17 kg*cm^2, 10: 0.13 kg*cm^2}"
).replace("rated_torque: 17 N*m", "rated_torque: {3: 17 N*m, 5: 21, 10: 19 N*m}")


def test_gearbox_figures_per_ratio(tmp_path):
    """A mapping gives each ratio its figure; the entry's own is the least favourable, safe at every ratio."""
    _, load = _catalogue(tmp_path, PER_RATIO)
    gearbox = load()["small"]
    assert gearbox.inertia == pytest.approx(0.25e-4, rel=1e-12) and gearbox.rated_torque == 17.0
    at_ten = gearbox.at_ratio(10.0)
    assert at_ten.ratios == (10.0,) and at_ten.rated_torque == 19.0 and at_ten.peak_torque == 32.0
    assert gearbox.inertia_at(10.0) == pytest.approx(0.13e-4, rel=1e-12)
    assert gearbox.reflected_inertia(10.0) == pytest.approx(100 * 0.13e-4, rel=1e-12)
    at_five = gearbox.at_ratio(5.0)
    assert at_five.rated_torque == 21.0 and at_five.at_ratio(5.0) is at_five
    # A ratio it does not offer (a design still free between them): the least favourable figures.
    assert gearbox.at_ratio(7.0) is gearbox and gearbox.inertia_at(7.0) == gearbox.inertia
    # One number keeps meaning that figure at every ratio.
    _, plain = _catalogue(tmp_path, GEARBOX)
    same = plain()["small"]
    assert same.at_ratio(10.0) is same and same.reflected_inertia(10.0) == pytest.approx(
        100 * 0.25e-4, rel=1e-12
    )


def test_packaged_gearboxes_match_their_datasheets():
    from collision_reflex.hardware.gearboxes import load_gearbox_catalogue

    gearboxes = load_gearbox_catalogue()
    # Beckhoff AG3300 NPS015 MF, 1-stage, its mechanical data table: 1.8 kg; per ratio i = 3, 4, 5, 7, 8, 10
    # T2N 17, 18, 21, 21, 19, 19 N m, T2B 32, 35, 40, 40, 35, 35 N m, J1 (9 mm hub) 0.25, 0.19, 0.17, 0.14, 0.14,
    # 0.13 kg cm^2.
    nps = gearboxes["NPS015-MF-1"]
    assert (nps.rated_torque, nps.peak_torque, nps.mass) == (17.0, 32.0, 1.8)  # the least favourable
    assert nps.inertia == pytest.approx(0.25e-4, rel=1e-12) and nps.efficiency == 0.97
    table = {3: (17, 32, 0.25), 4: (18, 35, 0.19), 5: (21, 40, 0.17), 7: (21, 40, 0.14), 8: (19, 35, 0.14)}
    table[10] = (19, 35, 0.13)
    for ratio, (rated, peak, inertia) in table.items():
        at = nps.at_ratio(ratio)
        assert (at.rated_torque, at.peak_torque) == (rated, peak), ratio
        assert at.inertia == pytest.approx(inertia * 1e-4, rel=1e-12) and at.momentary_torque == 80.0, ratio
    # Beckhoff AG2400 TP010 MF, 1-stage, J1 (14 mm hub) at i = 4 and 10: 0.78 and 0.40 kg cm^2.
    assert gearboxes["TP010-MF-1"].inertia_at(4) == pytest.approx(0.78e-4, rel=1e-12)
    assert gearboxes["TP010-MF-1"].inertia_at(10) == pytest.approx(0.40e-4, rel=1e-12)
    assert all(
        g.kind in cr.vocabulary.GEARBOX_KINDS
        and all(f.rated_torque <= f.peak_torque for f in (g, *g.per_ratio))
        for g in gearboxes.values()
    )


def test_nps015_at_n_10_reflects_its_own_j1():
    """At N = 10 the reflected inertia is N^2 x the table's J1 at i = 10 (0.13 kg cm^2), not J1 at i = 3 (0.25)."""
    from collision_reflex.hardware.gearboxes import load_gearbox_catalogue

    nps = load_gearbox_catalogue()["NPS015-MF-1"]
    assert nps.reflected_inertia(10.0) == pytest.approx(10.0**2 * 0.13e-4, rel=1e-12)
    assert nps.reflected_inertia(3.0) == pytest.approx(3.0**2 * 0.25e-4, rel=1e-12)


GEARBOX_BAD = {
    "no-source": (GEARBOX.replace("a test entry", "''"), 11, "gearboxes.small.source", "cite"),
    "missing-mass": (GEARBOX.replace("    mass: 1800 g\n", ""), 2, "gearboxes.small.mass", "missing"),
    "mistyped": (GEARBOX.replace("rated_torque: 17 N*m", "rated_torque: [17]"), 5, "rated_torque", ""),
    "wrong-unit": (GEARBOX.replace("1800 g", "1800 N*m"), 7, "gearboxes.small.mass", "cannot be converted"),
    "zero-inertia": (GEARBOX.replace("0.25 kg*cm^2", "0"), 8, "gearboxes.small.inertia", "> 0"),
    "rated-above-peak": (GEARBOX.replace("peak_torque: 32", "peak_torque: 10"), 5, "rated_torque", "peak"),
    "range-inverted": (
        GEARBOX.replace("ratios: [3, 5, 10]", "ratio_range: [160, 50]"),
        4,
        "gearboxes.small.ratio_range",
        "min <= max",
    ),
    "efficiency-above-one": (GEARBOX.replace("0.97", "1.2"), 9, "gearboxes.small.efficiency", "(0, 1]"),
    "efficiency-zero": (GEARBOX.replace("0.97", "0"), 9, "gearboxes.small.efficiency", "(0, 1]"),
    "ratio-below-one": (GEARBOX.replace("[3, 5, 10]", "[0.5, 5]"), 4, "gearboxes.small.ratios", ">= 1"),
    "ratio-zero": (GEARBOX.replace("[3, 5, 10]", "[0, 5]"), 4, "gearboxes.small.ratios", ">= 1"),
    "ratio-negative": (GEARBOX.replace("[3, 5, 10]", "[-3]"), 4, "gearboxes.small.ratios", ">= 1"),
    "range-negative": (
        GEARBOX.replace("ratios: [3, 5, 10]", "ratio_range: [-10, 50]"),
        4,
        "gearboxes.small.ratio_range",
        ">= 1",
    ),
    "empty-maker": (
        GEARBOX.replace("    source:", "    maker: ' '\n    source:"),
        11,
        "gearboxes.small.maker",
        "empty",
    ),
    "both-ratio-forms": (
        GEARBOX.replace("ratios: [3, 5, 10]", "ratios: [3]\n    ratio_range: [3, 10]"),
        2,
        "gearboxes.small.ratios",
        "exactly one",
    ),
    "unknown-kind": (GEARBOX.replace("planetary", "worm"), 3, "gearboxes.small.kind", "one of"),
    "per-ratio-misses-a-ratio": (
        PER_RATIO.replace(", 10: 0.13 kg*cm^2", ""),
        8,
        "gearboxes.small.inertia",
        "no figure for ratio 10",
    ),
    "per-ratio-adds-a-ratio": (
        PER_RATIO.replace("10: 0.13 kg*cm^2}", "10: 0.13 kg*cm^2,\n      7: 0.14 kg*cm^2}"),
        9,
        "gearboxes.small.inertia.7",
        "not one of the ratios offered (3, 5, 10)",
    ),
    "per-ratio-with-a-range": (
        PER_RATIO.replace("ratios: [3, 5, 10]", "ratio_range: [3, 10]"),
        5,
        "gearboxes.small.rated_torque",
        "needs the list 'ratios'",
    ),
    "per-ratio-twice": (
        PER_RATIO.replace("10: 0.13 kg*cm^2}", "10: 0.13 kg*cm^2, 3.0: 0.2 kg*cm^2}"),
        8,
        "gearboxes.small.inertia.3.0",
        "ratio 3 given twice",
    ),
    "per-ratio-key-not-a-ratio": (
        PER_RATIO.replace("5: 0.17", "five: 0.17"),
        8,
        "gearboxes.small.inertia",
        "keyed by its gear ratio",
    ),
    "per-ratio-figure-bad-unit": (
        PER_RATIO.replace("5: 0.17 kg*cm^2", "5: 0.17 kg"),
        8,
        "gearboxes.small.inertia",
        "cannot be converted",
    ),
    "per-ratio-rated-above-peak": (
        PER_RATIO.replace("10: 19 N*m", "10: 40 N*m"),
        5,
        "gearboxes.small.rated_torque",
        "exceeds the peak torque 32 N m at ratio 10",
    ),
    "per-ratio-mass": (GEARBOX.replace("mass: 1800 g", "mass: {3: 1.8, 5: 1.8, 10: 1.8}"), 7, "mass", ""),
    "unknown-field": (
        GEARBOX.replace("    source:", "    colour: red\n    source:"),
        11,
        "colour",
        "unknown",
    ),
}


@pytest.mark.parametrize("text, line, field, words", GEARBOX_BAD.values(), ids=GEARBOX_BAD.keys())
def test_bad_gearbox_catalogue_names_field_and_line(tmp_path, text, line, field, words):
    path, load = _catalogue(tmp_path, text)
    with pytest.raises(cr.errors.CatalogueError) as info:
        load()
    assert info.value.line == line and field in info.value.field
    assert f"{path}:{line}" in str(info.value) and words in str(info.value)
