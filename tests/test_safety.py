"""Permissible approach speeds of a run's design against a body region (``crx safety``): the effective masses
against the planar two-link arm's textbook dynamics, the ISO/TS 15066 estimate against the URDF's masses, the
choice of mass by stiffness ratio, and the command's output and refusals."""

from __future__ import annotations

import csv
import json
import math
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest

from collision_reflex.cli import main
from collision_reflex.errors import CatalogueError, InvalidParameter
from collision_reflex.model.contact import BodyRegion
from collision_reflex.study.body_regions import load_body_regions
from collision_reflex.study.safety import speed_map

pytestmark = pytest.mark.xdist_group("test_safety")  # one pytest-xdist worker: the speed map read once

ROOT = Path(__file__).resolve().parents[1]
URDF = ROOT / "designs" / "planar_two_link.urdf"
CHEST = BodyRegion("chest", 25e3, 40.0, 280.0)  # 25 N/mm, 40 kg, 280 N: the standard's chest


@pytest.fixture(scope="module")
def run(smoke_runs) -> Path:
    return smoke_runs["two_link_paper"]


@pytest.fixture(scope="module")
def chest(run):
    """The recommended design's speeds against the chest, read from the run folder as ``crx safety`` reads it."""
    return speed_map(run, CHEST)


def _recommended_joints(run: Path) -> list[dict]:
    return json.loads((run / "designs.json").read_text())["recommended"]["joints"]


def _two_link_masses(q: np.ndarray, u: np.ndarray, joints: list[dict]) -> tuple[float, float]:
    """The tip's effective mass along ``u`` of the planar two-link arm, worked from its textbook dynamics:
    rotors behind the joint springs, and rotors on the links (their ``N^2 J`` added to the joint inertias)."""
    m1, m2, l1, l1c, l2, l2c, i1, i2 = 0.20, 0.15, 0.30, 0.15, 0.25, 0.125, 1.5e-3, 7.8125e-4  # the URDF's
    motor2 = joints[1]["motor_mass"] + joints[1]["gearbox_mass"]  # joint 2's actuator rides on link 1's tip
    c2 = math.cos(q[1])
    m11 = i1 + m1 * l1c**2 + i2 + m2 * (l1**2 + l2c**2 + 2 * l1 * l2c * c2) + motor2 * l1**2
    m12 = i2 + m2 * (l2c**2 + l1 * l2c * c2)
    m22 = i2 + m2 * l2c**2
    mass = np.array([[m11, m12], [m12, m22]])
    s1, c1, s12, c12 = math.sin(q[0]), math.cos(q[0]), math.sin(q[0] + q[1]), math.cos(q[0] + q[1])
    jacobian = np.array([[-l1 * s1 - l2 * s12, -l2 * s12], [l1 * c1 + l2 * c12, l2 * c12]])
    rotors = np.diag([j["reflected_inertia"] for j in joints])

    def along(m: np.ndarray) -> float:
        w = jacobian.T @ u
        return 1 / float(w @ np.linalg.solve(m, w))

    return along(mass), along(mass + rotors)


def test_each_sample_s_masses_and_speed_are_the_hand_calculation(run, chest):
    result = chest
    joints = _recommended_joints(run)
    assert result.speed.size == result.masses.q.shape[0] >= 8
    for s in range(result.speed.size):
        finger, coupled = _two_link_masses(result.masses.q[s], result.masses.directions[s], joints)
        assert result.masses.finger_mass[s] == pytest.approx(finger, rel=1e-9)
        assert result.masses.coupled_mass[s] == pytest.approx(coupled, rel=1e-9)
        # Rotors on the links only add mass, and the region meets the coupled mass unless it is much stiffer.
        assert coupled >= finger
        ratio = CHEST.stiffness / result.masses.mechanical_stiffness[s]
        expected = finger if ratio >= 100 else coupled
        assert result.robot_mass[s] == pytest.approx(expected, rel=1e-9)
        assert bool(result.exact[s]) == (ratio >= 100 or ratio <= 0.01)
        mu = expected * CHEST.mass / (expected + CHEST.mass)
        assert result.speed[s] == pytest.approx(
            CHEST.transient_force / math.sqrt(mu * CHEST.stiffness), rel=1e-9
        )


def test_the_iso_estimate_is_half_the_moving_mass_plus_the_payload(run, chest):
    result = chest
    links = {
        link.get("name"): float(link.find("inertial/mass").get("value"))
        for link in ET.parse(URDF).getroot().iter("link")
        if link.find("inertial") is not None
    }
    joints = _recommended_joints(run)
    # Every link but the fixed base, and joint 2's actuator (joint 1's sits on the base).
    moving = sum(m for name, m in links.items() if name != "base_link")
    moving += joints[1]["motor_mass"] + joints[1]["gearbox_mass"]
    assert result.masses.moving_mass == pytest.approx(moving, rel=1e-12)
    assert result.iso_mass == pytest.approx(moving / 2 + result.masses.payload, rel=1e-12)
    mu = result.iso_mass * CHEST.mass / (result.iso_mass + CHEST.mass)
    assert result.iso_speed == pytest.approx(280.0 / math.sqrt(mu * 25e3), rel=1e-12)


def test_a_much_stiffer_region_meets_the_finger_and_a_much_softer_one_the_coupled_mass(chest):
    masses = chest.masses  # the same masses serve every region
    k_m = masses.mechanical_stiffness
    stiff = masses.speeds(BodyRegion("stiff", 1e3 * float(np.max(k_m)), 40.0, 280.0))
    soft = masses.speeds(BodyRegion("soft", 1e-3 * float(np.min(k_m)), 40.0, 280.0))
    assert stiff.exact.all() and np.array_equal(stiff.robot_mass, stiff.masses.finger_mass)
    assert soft.exact.all() and np.array_equal(soft.robot_mass, soft.masses.coupled_mass)
    # The speed is linear in the force limit.
    doubled = masses.speeds(BodyRegion("chest", 25e3, 40.0, 560.0))
    np.testing.assert_allclose(doubled.speed, 2 * chest.speed, rtol=1e-12)


def test_crx_safety_prints_the_summary_and_writes_one_row_per_sample(run, chest, tmp_path, capsys):
    table = tmp_path / "chest.csv"
    args = [
        "safety",
        str(run),
        "--region",
        "chest",
        "--region-stiffness",
        "25 N/mm",
        "--region-mass",
        "40 kg",
    ]
    assert main([*args, "--transient-force", "280 N", "--csv", str(table)]) == 0
    printed = capsys.readouterr().out
    result = chest
    assert f"permissible speed {np.min(result.speed):.3g} to {np.max(result.speed):.3g} m/s" in printed
    assert f"permissible speed {result.iso_speed:.3g} m/s" in printed and "ISO/TS 15066" in printed
    rows = list(csv.DictReader(table.open()))
    assert len(rows) == result.speed.size
    assert [float(r["permissible_speed [m/s]"]) for r in rows] == result.speed.tolist()


@pytest.mark.parametrize(
    ("extra", "words"),
    [
        (["--design", "99"], "design = 99"),
        (["--region-mass", "-1 kg"], "--region-mass"),
        (["--transient-force", "3 m"], "--transient-force"),
    ],
)
def test_crx_safety_refuses_bad_input_in_one_line_exit_2(run, capsys, extra, words):
    args = [
        "safety",
        str(run),
        "--region-stiffness",
        "25 N/mm",
        "--region-mass",
        "40 kg",
        "--transient-force",
        "1 N",
    ]
    assert main([*args, *extra]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and words in err[0]


def test_an_actuator_study_or_an_empty_folder_is_refused(smoke_runs, tmp_path):
    with pytest.raises(InvalidParameter, match="arm study"):
        speed_map(smoke_runs["direct_drive_vs_geared"], CHEST)
    assert (
        main(
            [
                "safety",
                str(tmp_path),
                "--region-stiffness",
                "1",
                "--region-mass",
                "1",
                "--transient-force",
                "1",
            ]
        )
        == 2
    )


def test_a_body_region_refuses_non_physical_figures():
    with pytest.raises(InvalidParameter, match="stiffness"):
        BodyRegion("hand", 0.0, 0.6, 280.0)
    with pytest.raises(InvalidParameter, match="transient_force"):
        BodyRegion("hand", 75e3, 0.6, math.nan)


def test_the_standard_s_regions_are_its_tables():
    regions = load_body_regions()
    # ISO/TS 15066:2016 Annex A: Table A.3 (k [N/mm], m_H [kg]) and Table A.2 (quasi-static force [N]); the
    # transient force twice it, none for the skull and forehead and the face.
    table = {
        "skull_forehead": (150, 4.4, 130),
        "face": (75, 4.4, 65),
        "neck": (50, 1.2, 150),
        "back_shoulders": (35, 40, 210),
        "chest": (25, 40, 140),
        "abdomen": (10, 40, 110),
        "pelvis": (25, 40, 180),
        "upper_arm_elbow": (30, 3, 150),
        "lower_arm_wrist": (40, 2, 160),
        "hand_finger": (75, 0.6, 140),
        "thigh_knee": (50, 75, 220),
        "lower_leg": (60, 75, 130),
    }
    assert list(regions) == list(table)
    for name, (k, m, force) in table.items():
        region = regions[name]
        assert (region.stiffness, region.mass, region.quasi_static_force) == (k * 1e3, m, force)
        head = name in ("skull_forehead", "face")
        assert region.transient_force == (None if head else 2 * force)
    assert regions["chest"] == BodyRegion("chest", 25e3, 40.0, 280.0, 140.0)


@pytest.mark.parametrize(
    ("entry", "line", "field", "words"),
    [
        ("    mass: 0.6 kg\n    quasi_static_force: 140 N\n    source: s\n", 2, "stiffness", "missing"),
        (
            "    stiffness: -75 N/mm\n    mass: 0.6 kg\n    quasi_static_force: 140 N\n    source: s\n",
            3,
            "stiffness",
            "finite number > 0",
        ),
        (
            "    stiffness: 75 kg\n    mass: 0.6 kg\n    quasi_static_force: 140 N\n    source: s\n",
            3,
            "stiffness",
            "cannot be converted",
        ),
        (
            "    stiffness: 75 N/mm\n    mass: 0.6 kg\n    quasi_static_force: 140 N\n    transient_force: 100 N\n"
            "    source: s\n",
            6,
            "transient_force",
            "below the quasi-static force",
        ),
        (
            "    stiffness: 75 N/mm\n    mass: 0.6 kg\n    quasi_static_force: 140 N\n    source: ' '\n",
            6,
            "source",
            "cite its source",
        ),
        (
            "    stiffness: 75 N/mm\n    mass: 0.6 kg\n    quasi_static_force: 140 N\n    colour: red\n"
            "    source: s\n",
            6,
            "colour",
            "unknown field",
        ),
    ],
)
def test_a_malformed_region_file_is_refused_at_its_line_and_field(tmp_path, entry, line, field, words):
    path = tmp_path / "regions.yaml"
    path.write_text("body_regions:\n  hand:\n" + entry)
    with pytest.raises(CatalogueError) as caught:
        load_body_regions(path)
    message = str(caught.value)
    assert f"{path}:{line}" in message and f"body_regions.hand.{field}" in message and words in message


def test_crx_safety_takes_a_named_region_and_refuses_one_without_a_transient_force(run, capsys):
    assert main(["safety", str(run), "--region", "chest"]) == 0
    assert "against chest (k_c = 25 N/mm, m_H = 40 kg, F_T = 280 N)" in capsys.readouterr().out
    assert main(["safety", str(run), "--region", "face"]) == 2
    assert "permits no transient contact with face" in capsys.readouterr().err
    assert main(["safety", "--list-regions"]) == 0
    assert "hand_finger: k_c 75 N/mm, m_H 0.6 kg, F_T 280 N" in capsys.readouterr().out


@pytest.mark.parametrize("name", ["ur5", "panda"])
def test_an_arm_study_s_run_keeps_every_region_and_its_report_shows_the_most_limiting(smoke_runs, name):
    folder = smoke_runs[name]
    record = json.loads((folder / "designs.json").read_text())["human_contact"]
    regions = load_body_regions()
    assert [row["region"] for row in record["regions"]] == [
        n for n, r in regions.items() if r.transient_force is not None
    ]
    assert record["no_transient"] == ["skull_forehead", "face"]
    chest = next(row for row in record["regions"] if row["region"] == "chest")
    again = speed_map(folder, regions["chest"])  # what crx safety computes from the folder
    assert chest["slowest"] == pytest.approx(float(np.min(again.speed)), rel=1e-12)
    assert chest["iso_speed"] == pytest.approx(again.iso_speed, rel=1e-12)
    assert chest["above_approach"] == int(np.sum(again.masses.approach_velocity > again.speed * (1 + 1e-6)))
    report = (folder / "report.html").read_text()
    start = report.index('id="human-contact"')
    section = " ".join(report[start : report.index("</figure>", start)].split())
    limiting = min(record["regions"], key=lambda row: row["slowest"])
    assert f"Most limiting: the {limiting['region'].replace('_', ' ')}" in section
    assert (
        f"{record['samples']} contact samples" in section and "half the moving mass plus payload" in section
    )
    assert (
        'id="permissible-speeds"' in section and "<svg" in section
    )  # every region, with the estimate beside
