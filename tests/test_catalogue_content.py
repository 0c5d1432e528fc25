"""The shipped motor and gearbox catalogues: coverage, provenance, datasheet spot checks and plausibility.

The spot checks hold the figures as the cited datasheets print them (in their own units) and convert them
here by hand, so a unit slip in the YAML or in the loader fails them.
"""

from __future__ import annotations

import math
import re

import pytest

import collision_reflex as cr
from collision_reflex.cli import main
from collision_reflex.hardware.catalogue import packaged_catalogue_path, read_entries
from collision_reflex.hardware.gearboxes import load_gearbox_catalogue

RPM = 2 * math.pi / 60  # rad/s per rpm
G_CM2 = 1e-7  # kg m^2 per g cm^2
KG_CM2 = 1e-4  # kg m^2 per kg cm^2


@pytest.fixture(scope="module")
def motors():
    return cr.hardware.load_catalogue()


@pytest.fixture(scope="module")
def motor_entries():
    return read_entries(packaged_catalogue_path("motors.yaml"), "motors")


@pytest.fixture(scope="module")
def gearboxes():
    return load_gearbox_catalogue()


def test_catalogue_covers_makers_kinds_and_sizes(motors, motor_entries):
    assert len(motors) >= 12
    makers = {entry.description.get("maker") for entry in motor_entries.values()}
    assert len(makers - {None}) >= 8
    kinds = {entry.description.get("construction") for entry in motor_entries.values()}
    assert kinds == {"frameless", "housed"}
    diameters = sorted(m.stator_diameter for m in motors.values())
    assert diameters[0] <= 0.020 and diameters[-1] >= 0.120  # ~20 mm to ~120 mm asked; 16 to 127 mm shipped
    assert {"OPN-060-013-A", "U8-KV100"} <= set(motors)  # the paper's reference motor and its U8


def test_gearbox_catalogue_has_harmonic_and_small_planetary_units(gearboxes):
    harmonic = [g for g in gearboxes.values() if g.kind == "harmonic"]
    assert {r for g in harmonic for r in g.ratios} >= {50.0, 100.0}
    assert min(g.rated_torque for g in gearboxes.values() if g.kind == "planetary") <= 20.0


def _header_methods(file):
    """The estimate methods a catalogue's header defines: its '# - NAME:' lines."""
    text = packaged_catalogue_path(file).read_text()
    return set(re.findall(r"^# - ([A-Z][A-Z ]+[A-Z]):", text, flags=re.MULTILINE))


def test_every_estimate_states_its_method(motor_entries):
    methods = _header_methods("motors.yaml")
    assert methods == {"STATOR OD OF A HOUSED MOTOR", "STACK BY THE SCALING LAW", "PART NUMBER"}
    estimated = 0
    for name, entry in motor_entries.items():
        for field, origin in entry.provenance.items():
            if not origin.startswith("ESTIMATE: "):
                continue
            estimated += 1
            method = origin.removeprefix("ESTIMATE: ")
            named = re.match(r"([A-Z][A-Z ]+[A-Z]) \(header\)", method)
            # Either a header method by its exact name, or a method spelled out in the entry.
            assert (named and named.group(1) in methods) or len(method.split()) >= 8, (name, field, method)
    assert estimated > 0


def test_housing_wall_estimate_only_for_housed_motors(motor_entries):
    # A frameless kit's stator OD is a drawing dimension; only housed motors need the housing-wall estimate.
    for name, entry in motor_entries.items():
        origin = entry.provenance["stator_diameter"]
        if "STATOR OD OF A HOUSED MOTOR" in origin:
            assert entry.description["construction"] == "housed", name


# --- spot checks, one motor per maker, against the cited figures ------------------------------------------


def test_celera_reference_motor(motors):
    motor = motors["OPN-060-013-A"]
    assert (motor.rotor_inertia, motor.peak_torque, motor.continuous_torque) == (2.21e-5, 1.3, 0.524)


def test_tmotor_u8(motors):
    # MGDB TMotor_U8_Lee2019.csv: k_t 0.14 N m/A, I_nom 7.6 A, inertia 1.20E-04 kg m2, 0.24 kg; Katz et al.:
    # stack 8.2 mm, air-gap radius 40.5 mm.
    u8 = motors["U8-KV100"]
    assert u8.rotor_inertia == pytest.approx(1.20e-4, rel=1e-12)
    assert u8.continuous_torque == pytest.approx(0.14 * 7.6, rel=1e-12)
    assert u8.stack_length == pytest.approx(8.2e-3, rel=1e-12)
    assert u8.stator_diameter == pytest.approx(2 * 40.5e-3, rel=1e-12)
    assert u8.max_speed == pytest.approx(100 * 36 * RPM, rel=1e-12)  # KV 100 rpm/V at 36 V


def test_kollmorgen_tbm(motors):
    # TBM(S)-6025-A: Jm 2.52E-05 kg-m2, Tp 2.56 N-m, Tc 0.706 N-m, 377 grams, 2900 RPM.
    tbm = motors["TBMS-6025-A"]
    assert (tbm.rotor_inertia, tbm.peak_torque, tbm.continuous_torque) == (2.52e-5, 2.56, 0.706)
    assert tbm.mass == pytest.approx(0.377, rel=1e-12)
    assert tbm.max_speed == pytest.approx(2900 * RPM, rel=1e-12)


def test_tq_ilm(motors):
    # ILM-E85x30: J 1.48 kg cm2, 822 g, kT 306 mN m/A, no-load 1290 rpm.
    ilm = motors["ILM-E85x30"]
    assert ilm.rotor_inertia == pytest.approx(1.48 * KG_CM2, rel=1e-12)
    assert ilm.mass == pytest.approx(0.822, rel=1e-12)
    assert ilm.torque_constant == pytest.approx(0.306, rel=1e-12)
    assert ilm.max_speed == pytest.approx(1290 * RPM, rel=1e-12)


def test_beckhoff_am8100(motors):
    # Parameter files: KT 81 mN m/A, I0 4.5 A, J 48 g cm2, 5100 rpm (AM8112); the 400 V AM8012 of the same
    # frame is listed with M0 0.38 N m and 0.0482 kg cm2 in the AM8000 manual: the two sources agree within
    # the +/- 10 % tolerance Beckhoff states for its data.
    am = motors["AM8112"]
    assert am.rotor_inertia == pytest.approx(48 * G_CM2, rel=1e-12)
    assert am.continuous_torque == pytest.approx(0.081 * 4.5, rel=1e-12)
    assert am.max_speed == pytest.approx(5100 * RPM, rel=1e-12)
    assert am.continuous_torque == pytest.approx(0.38, rel=0.10)
    assert am.rotor_inertia == pytest.approx(0.0482 * KG_CM2, rel=0.10)
    for name, m0, inertia in (("AM8111", 0.20, 0.0294), ("AM8113", 0.52, 0.0670)):
        assert motors[name].continuous_torque == pytest.approx(m0, rel=0.10), name
        assert motors[name].rotor_inertia == pytest.approx(inertia * KG_CM2, rel=0.10), name


def test_maxon(motors):
    # EC 45 flat 339281: 55.3 mNm, 239 mNm, 51 mNm/A, 92.5 gcm2, 4380 rpm; EC-i 40 488607: 44 gcm2, 390 g.
    flat = motors["EC45flat-339281"]
    assert (flat.continuous_torque, flat.peak_torque) == pytest.approx((0.0553, 0.239), rel=1e-12)
    assert flat.rotor_inertia == pytest.approx(92.5 * G_CM2, rel=1e-12)
    assert flat.torque_constant == pytest.approx(0.051, rel=1e-12)
    assert flat.max_speed == pytest.approx(4380 * RPM, rel=1e-12)
    eci = motors["EC-i40-488607"]
    assert eci.rotor_inertia == pytest.approx(44 * G_CM2, rel=1e-12) and eci.mass == pytest.approx(0.39)


def test_faulhaber(motors):
    # 2250 S 024 BX4: 10 gcm2, 106 g, 36.9 mNm/A, stall 149 mNm, continuous up to 23 mNm, up to 9000 rpm.
    bx4 = motors["2250S024BX4"]
    assert bx4.rotor_inertia == pytest.approx(10 * G_CM2, rel=1e-12)
    assert (bx4.mass, bx4.torque_constant) == pytest.approx((0.106, 0.0369), rel=1e-12)
    assert (bx4.continuous_torque, bx4.peak_torque) == pytest.approx((0.023, 0.149), rel=1e-12)
    assert bx4.max_speed == pytest.approx(9000 * RPM, rel=1e-12)


def test_allied_motion_continuous_torque_estimate(motors):
    # MGDB row AM_MF0095020_48V: k_t 0.14, R 0.25 ohm, Rth1 1.55 K/W; a 100 K rise, copper loss 1.5 I^2 R.
    current = math.sqrt(100 / (1.5 * 1.55 * 0.25))
    mf = motors["MF0095020-48V"]
    assert mf.continuous_torque == pytest.approx(0.14 * current, rel=5e-3)  # the YAML holds 3 figures
    assert (mf.rotor_inertia, mf.peak_torque, mf.mass) == (2.5e-4, 18.0, 0.68)


def test_gearbox_spot_checks(gearboxes):
    csf = gearboxes["CSF-17-100-2UH"]  # 24 / 54 / 108 N m, 0.68 kg, 0.079e-4 kg m2
    assert (csf.rated_torque, csf.peak_torque, csf.momentary_torque, csf.mass) == (24.0, 54.0, 108.0, 0.68)
    assert csf.inertia == pytest.approx(0.079e-4, rel=1e-12) and csf.ratios == (100.0,)
    assert csf.efficiency is None  # the catalogue gives curves, not a number: left out, not invented
    sp = gearboxes["SP060-MF-1"]  # T2N 21, T2B 36, 1.9 kg, J1 0.21 kg cm2 (hub B)
    assert (sp.rated_torque, sp.peak_torque, sp.mass) == (21.0, 36.0, 1.9)
    assert sp.inertia == pytest.approx(0.21 * KG_CM2, rel=1e-12)
    apex = gearboxes["AF042-2"]  # T2B = 60 % of the emergency stop torque, itself 3 x T2N (19 N m)
    assert apex.peak_torque == pytest.approx(0.6 * 3 * 19.0, rel=1e-12)


# --- plausibility: bounds that a unit slip (x 1e3 to 1e4, or rpm read as rad/s) leaves ---------------------


def test_rotor_inertia_against_mass_and_stator_radius(motors):
    # J / (m (D/2)^2): below 1 because the rotor is part of the mass and sits mostly inside the stator radius;
    # above 0.01 because even a slim inner rotor of a housed servo (the AM811x: 0.024) carries a few percent
    # of the mass near half the stator radius. kg*cm^2 for kg*m^2 (x 1e4) or g for kg (x 1e3) leaves the band.
    for name, motor in motors.items():
        ratio = motor.rotor_inertia / (motor.mass * (motor.stator_diameter / 2) ** 2)
        assert 0.01 < ratio < 1.0, (name, ratio)


def test_torque_density(motors):
    # Continuous torque per motor mass: housed servo motors ~0.3-1 N m/kg, frameless and large-gap motors up
    # to ~5 N m/kg (the U8: 4.4); peak torque per mass up to ~30 N m/kg. mN m read as N m (x 1e3) leaves both.
    for name, motor in motors.items():
        assert 0.1 < motor.continuous_torque / motor.mass < 10.0, name
        assert 0.5 < motor.peak_torque / motor.mass < 40.0, name
        assert motor.peak_torque / motor.continuous_torque < 15.0, name  # frameless torque motors reach ~10


def test_surface_speed(motors):
    # Stator surface speed at the maximum speed: 5-20 m/s for these motors; an rpm figure read as rad/s
    # (x 9.55) would exceed 50 m/s for every one of them.
    for name, motor in motors.items():
        assert 1.0 < motor.max_speed * motor.stator_diameter / 2 < 50.0, name


def test_gearbox_plausibility(gearboxes):
    # Rated torque per mass 2-100 N m/kg (planetary ~10-40, strain wave ~25-35); input inertia per mass
    # between 1e-7 and 1e-2 m^2 (a 0.6 mm to 100 mm radius of gyration): a kg*cm^2 slip leaves the band.
    for name, gearbox in gearboxes.items():
        assert 2.0 < gearbox.rated_torque / gearbox.mass < 100.0, name
        assert 1e-7 < gearbox.inertia / gearbox.mass < 1e-2, name
        assert gearbox.efficiency is None or 0.9 <= gearbox.efficiency <= 1.0, name


def test_crx_motors_lists_every_motor_with_its_source(capsys, motors):
    assert main(["motors", "--gearboxes"]) == 0
    out = capsys.readouterr().out
    rows = {line.split()[0] for line in out.splitlines() if line.strip()}
    assert set(motors) <= rows
    for name in motors:
        assert f"{name}: " in out  # the source line
    assert "CSF-17-100-2UH" in out and "harmonic" in out
