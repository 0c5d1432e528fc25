"""Gearboxes in arm designs: against Pinocchio models with the masses and armature added, and their ratings."""

from __future__ import annotations

import csv
import dataclasses
import json
from pathlib import Path

import casadi as ca
import numpy as np
import pinocchio as pin
import pytest

import collision_reflex as cr
from collision_reflex.arm import Arm
from collision_reflex.arm.duty_cycle import DutyCycle, Payload
from collision_reflex.errors import InvalidParameter, StudyFileError
from collision_reflex.hardware.gearboxes import CatalogueGearbox
from collision_reflex.optimize.design import design_at

ROOT = Path(__file__).resolve().parents[1]
TWO_LINK = ROOT / "designs" / "planar_two_link.urdf"


def _gearbox(name: str, mass: float, inertia: float, peak: float = 1e6, efficiency: float = 1.0, **extra):
    return CatalogueGearbox(
        name=name,
        kind="planetary",
        ratios=(1.0, 1000.0),
        continuous_ratio=True,
        rated_torque=extra.pop("rated", peak),
        peak_torque=peak,
        mass=mass,
        inertia=inertia,
        source="test figures",
        efficiency=efficiency,
        **extra,
    )


def _motor() -> cr.Motor:
    return cr.reference_motor()


@pytest.fixture(scope="module")
def ur5() -> Arm:
    return Arm.from_example_robot_data("ur5", "tool0")


@pytest.fixture(scope="module")
def two_link() -> Arm:
    return Arm.from_urdf(TWO_LINK, "tip")


def _two_link_samples(arm: Arm) -> cr.ContactSamples:
    kin = arm.kinematics(arm.sample_configurations(3, np.random.default_rng(0)))
    angles = np.linspace(0, 2 * np.pi, 4, endpoint=False) + 0.3
    return cr.ContactSamples.grid(kin, np.c_[np.cos(angles), np.sin(angles)])


TWO_LINK_SPACE = cr.DesignSpace(
    stator_diameter=(0.02, 0.12),
    gear_ratio=(1, 30),
    software_stiffness=(5, 500),
    threshold=(1, 10),
    approach_velocity=(0.05, 1.0),
)
GIVEN = cr.Constraints(torque_required=[1.3, 1.3])


@pytest.mark.parametrize("placement", ["robot", "finger"])
def test_masses_and_armature_against_pinocchio(ur5, placement):
    """m_f, m_r, a, the gravity requirement and the actuator mass equal a Pinocchio model with the parts added."""
    rng = np.random.default_rng(3)
    q = ur5.sample_configurations(3, rng)
    directions = rng.normal(size=(4, 3))
    directions /= np.linalg.norm(directions, axis=1, keepdims=True)
    samples = cr.ContactSamples.grid(ur5.kinematics(q), directions)
    gearboxes = (
        _gearbox("g1", 2.0, 3e-5),
        _gearbox("g2", 1.5, 2e-5),
        None,
        _gearbox("g4", 0.7, 1e-5, efficiency=0.8),
        _gearbox("g5", 0.4, 5e-6),
        _gearbox("g6", 0.3, 4e-6),
    )
    technology = cr.ActuatorTechnology(
        _motor(), mechanical_stiffness=3000.0, gearboxes=gearboxes, reflected_inertia_in=placement
    )
    space = cr.DesignSpace(
        stator_diameter=(0.03, 0.15),
        gear_ratio=(5, 150),
        software_stiffness=(50, 5000),
        threshold=(2, 20),
        approach_velocity=(0.05, 1.0),
    )
    constraints = cr.Constraints(safety_factor=1.5)
    problem = cr.build_problem(ur5, samples, space, technology, "worst_case_impulse", constraints)
    x = problem.x0.copy()
    x[: problem.layout.size] += rng.uniform(-0.3, 0.3, problem.layout.size)  # any design within reach
    design = design_at(problem, x)
    gear = design.gear_ratio
    motor = technology.motor_quantities(design.stator_diameter, design.stack_length)
    gearbox_mass = np.array([0.0 if g is None else g.mass for g in gearboxes])
    gearbox_inertia = np.array([0.0 if g is None else g.inertia for g in gearboxes])
    carried = np.asarray(motor.mass) + gearbox_mass
    armature = gear**2 * (np.asarray(motor.rotor_inertia) + gearbox_inertia)

    model = ur5.model.copy()
    for j in range(1, model.njoints):  # each joint's motor and gearbox on its parent link, at the joint
        point = pin.Inertia(carried[j - 1], model.jointPlacements[j].translation, np.zeros((3, 3)))
        model.inertias[model.parents[j]] = model.inertias[model.parents[j]] + point
    model.armature = armature if placement == "finger" else np.zeros(model.nv)
    data = model.createData()
    frame = model.getFrameId("tool0")
    found = problem.sample_parameters(x)
    gravity = []
    for s in range(samples.size):
        config = q[samples.config_index[s]]
        pin.computeJointJacobians(model, data, config)
        pin.updateFramePlacements(model, data)
        jacobian = pin.getFrameJacobian(model, data, frame, pin.LOCAL_WORLD_ALIGNED)[:3]
        w = jacobian.T @ samples.directions[s]
        m_f = 1.0 / (w @ np.linalg.solve(pin.crba(model, data, config), w))
        m_r = 1.0 / (w @ (w / armature))
        reaction = np.min(design.peak_torque / np.abs(w))  # N tau_p: the reaction is not derated by eta
        # Sums and one solve of O(1)-conditioned 6x6 systems: agreement to rounding.
        np.testing.assert_allclose(found["m_f"][s], m_f, rtol=1e-9)
        np.testing.assert_allclose(found["m_r"][s], m_r, rtol=1e-9)
        np.testing.assert_allclose(found["a"][s], reaction / m_r, rtol=1e-9)
    for config in q:
        gravity.append(pin.computeGeneralizedGravity(model, data, config).copy())
    required = 1.5 * np.abs(np.array(gravity)).max(axis=0)
    evaluated = problem.evaluate(problem.exact_point(x))
    # Joints gravity does not load (base yaw, last wrist) are rounding noise: tolerance relative to the largest.
    np.testing.assert_allclose(
        np.asarray(evaluated[4]).ravel(), required, rtol=1e-9, atol=1e-12 * required.max()
    )
    np.testing.assert_allclose(float(evaluated[1]), carried.sum(), rtol=1e-12)
    np.testing.assert_allclose(design.reflected_inertia, armature, rtol=1e-12)
    np.testing.assert_array_equal(design.motor_mass, np.asarray(motor.mass))  # the motor's own
    np.testing.assert_array_equal(design.gearbox, ("g1", "g2", "", "g4", "g5", "g6"))
    assert gearbox_mass.sum() > 0.5 * carried.sum() - gearbox_mass.sum()  # the gearboxes weigh in the test


def _solve_two_link(arm, gearboxes=None, constraints=GIVEN, **technology):
    tech = cr.ActuatorTechnology(_motor(), mechanical_stiffness=1000.0, gearboxes=gearboxes, **technology)
    problem = cr.build_problem(
        arm, _two_link_samples(arm), TWO_LINK_SPACE, tech, "worst_case_impulse", constraints
    )
    return problem, cr.solve(problem)


def test_a_neutral_gearbox_reproduces_the_design_without_one(two_link):
    _, plain = _solve_two_link(two_link)
    neutral = (_gearbox("none", 0.0, 0.0), _gearbox("none", 0.0, 0.0))
    _, same = _solve_two_link(two_link, neutral)
    ignored = (_gearbox("light", 0.0, 1e-3), _gearbox("light", 0.0, 1e-3))
    _, paper = _solve_two_link(two_link, ignored, gearbox_inertia=False)
    for result in (same, paper):
        for name, value in plain.objectives.items():
            assert result.objectives[name] == pytest.approx(value, rel=1e-9)
        np.testing.assert_allclose(result.x[: len(plain.x)], plain.x, rtol=1e-9, atol=1e-12)
    assert paper.design.gearbox_inertia[0] == 1e-3  # reported, though not counted


def test_efficiency_half_doubles_the_motor_torque_needed(two_link):
    _, full = _solve_two_link(two_link, (_gearbox("a", 0.1, 1e-6), _gearbox("b", 0.1, 1e-6)))
    _, half = _solve_two_link(
        two_link, (_gearbox("a", 0.1, 1e-6, efficiency=0.5), _gearbox("b", 0.1, 1e-6, efficiency=0.5))
    )
    # The given requirement nearly binds at both optima (the impulse grows with the motor's size), so the
    # output torque N tau_p the motor must give is required / eta: twice as much at eta = 0.5.
    for result, efficiency in ((full, 1.0), (half, 0.5)):
        assert np.all(result.torque_margin > -1e-8) and np.all(result.torque_margin < 5e-3)
        np.testing.assert_allclose(result.design.driving_peak_torque, efficiency * result.design.peak_torque)
    np.testing.assert_allclose(half.design.peak_torque / full.design.peak_torque, 2.0, rtol=1e-2)


def test_a_rating_below_the_requirement_is_refused(two_link):
    weak = (_gearbox("weak", 0.1, 1e-6, peak=1.0), None)
    with pytest.raises(InvalidParameter, match=r"gearbox weak of joint1.*1 N\*m.*>= 1.3 N\*m"):
        _solve_two_link(two_link, weak)


@pytest.fixture(scope="module")
def cycle(two_link):
    # A loaded, fast cycle: the lightest design's joint 1 is sized by its peak and RMS torque.
    return DutyCycle.through_via_points(
        [[0.0, 0.0], [1.2, -1.0], [0.3, 0.6]],
        two_link.joint_names,
        [15.0, 20.0],
        [80.0, 100.0],
        rate=100.0,
        dwell=0.05,
        payload=Payload(2.0),
    )


def _lightest_with_duty(arm, cycle, gearbox):
    kinematics = arm.kinematics(arm.sample_configurations(2, np.random.default_rng(0)))
    angles = np.linspace(0, 2 * np.pi, 3, endpoint=False) + 0.3
    samples = cr.ContactSamples.grid(kinematics, np.c_[np.cos(angles), np.sin(angles)])
    space = cr.DesignSpace(
        stator_diameter=(0.02, 0.12),
        gear_ratio=(1.0, 100.0),
        software_stiffness=100.0,
        threshold=5.0,
        approach_velocity=0.2,
    )
    tech = cr.ActuatorTechnology(_motor(), mechanical_stiffness=200.0, gearboxes=(gearbox, None))
    constraints = cr.Constraints(safety_factor=1.2, duty_cycle=cycle)
    problem = cr.build_problem(arm, samples, space, tech, "actuator_mass", constraints)
    return problem, cr.solve(problem)


@pytest.mark.parametrize("rating", ["peak", "rms", "speed"])
def test_a_rating_below_the_lightest_design_moves_the_optimum_onto_it(two_link, cycle, rating):
    """Capping what the lightest design asks of its gearbox by 5 % gives a heavier design that uses it all."""
    _, free = _lightest_with_duty(two_link, cycle, _gearbox("g", 0.3, 1e-5))
    asked = {
        "peak": ("peak", free.required_torque[0]),
        "rms": ("rated", free.required_rms_torque[0]),
        "speed": ("max_input_speed", free.max_motor_speed[0]),
    }
    field, value = asked[rating]
    capped_box = _gearbox(
        "g", 0.3, 1e-5, **{field: 0.95 * value, **({} if field == "peak" else {"peak": 1e6})}
    )
    problem, capped = _lightest_with_duty(two_link, cycle, capped_box)
    used = {
        "peak": capped.required_torque,
        "rms": capped.required_rms_torque,
        "speed": capped.max_motor_speed,
    }
    assert used[rating][0] == pytest.approx(0.95 * value, rel=1e-6)  # on the rating (IPOPT's tolerance)
    assert capped.objectives["actuator_mass"] > free.objectives["actuator_mass"] * (1 + 1e-3)
    constraint = ca.Function("g", [problem.nlp["x"], problem.nlp["p"]], [problem.nlp["g"]])
    g = np.asarray(constraint(problem.exact_point(capped.x), problem.parameters())).ravel()
    rows = [i for i, label in enumerate(problem.constraint_labels) if label.startswith("gearbox g of joint1")]
    # A peak row (or more), the RMS row and, with a maximum input speed, the cycle's and the approach's speed rows.
    assert len(rows) >= (4 if rating == "speed" else 2)
    slack = np.minimum(g[rows] - problem.lbg[rows], problem.ubg[rows] - g[rows])
    assert slack.min() == pytest.approx(0.0, abs=1e-6)  # a gearbox row is active, the others met


def test_a_duty_cycle_beyond_the_gearbox_rating_is_refused_before_solving(two_link, cycle):
    # The lightest design needs ~53 N*m (safety factor included) at joint 1: a 10 N*m rating is far short.
    weak = _gearbox("weak", 0.3, 1e-5, peak=10.0)
    with pytest.raises(
        InvalidParameter, match=r"joint1.*gearbox weak peak rating: best margin reachable -7\d"
    ):
        _lightest_with_duty(two_link, cycle, weak)


def test_the_gearbox_fields_survive_the_saved_result(two_link):
    from collision_reflex.optimize.results import result_from_json, result_to_json

    box = _gearbox("NPS", 0.25, 2e-6, efficiency=0.9)
    _, result = _solve_two_link(two_link, (box, None))
    again = result_from_json(json.loads(json.dumps(result_to_json(result)))).design
    assert again.gearbox == ("NPS", "")
    for name in (
        "gearbox_mass",
        "gearbox_inertia",
        "gearbox_efficiency",
        "actuator_mass",
        "reflected_inertia",
    ):
        np.testing.assert_array_equal(getattr(again, name), getattr(result.design, name))
    np.testing.assert_array_equal(again.gearbox_efficiency, [0.9, 1.0])


def test_ratio_ranges_are_intersected_and_a_miss_is_named(two_link):
    box = dataclasses.replace(_gearbox("NPS", 0.1, 1e-6), ratios=(3.0, 10.0))
    problem, result = _solve_two_link(two_link, (box, box))
    assert problem.layout.bounds["gear_ratio"][0].lower == 3.0
    ratios = result.design.gear_ratio
    assert np.all((ratios >= 3 * (1 - 1e-7)) & (ratios <= 10 * (1 + 1e-7)))  # IPOPT relaxes bounds by 1e-8
    far = dataclasses.replace(box, ratios=(50.0, 100.0))
    with pytest.raises(InvalidParameter, match=r"gear_ratio bounds of joint1.*'NPS', 50 to 100"):
        _solve_two_link(two_link, (far, None))


STUDY = ROOT / "studies" / "two_link_planetary.yaml"


def _study_text(**replacements: str) -> str:
    text = STUDY.read_text()
    for old, new in replacements.items():
        assert old in text
        text = text.replace(old, new)
    return text.replace("../designs/", str(ROOT / "designs") + "/")


def test_a_catalogue_gearbox_study_runs_and_reports_its_gearboxes(tmp_path):
    from collision_reflex.study.runner import run_study

    run_study(STUDY, tmp_path / "out", quiet=True, smoke=True, executor="serial", figures=False)
    rows = list(csv.DictReader((tmp_path / "out" / "pareto.csv").open()))
    catalogue = cr.hardware.gearboxes.load_gearbox_catalogue()["NPS015-MF-1"]
    for row in rows:
        for joint in ("joint1", "joint2"):
            assert row[f"gearbox[{joint}] [-]"] == "NPS015-MF-1"
            assert float(row[f"gearbox_mass[{joint}] [kg]"]) == catalogue.mass
            motor, total = float(row[f"motor_mass[{joint}] [kg]"]), float(row[f"actuator_mass[{joint}] [kg]"])
            # pareto.csv holds 10 significant digits.
            assert total == pytest.approx(motor + catalogue.mass, rel=1e-9)
            # IPOPT may relax a bound by 1e-8 relative.
            assert 3 * (1 - 1e-7) <= float(row[f"gear_ratio[{joint}] [-]"]) <= 10 * (1 + 1e-7)
            # The rating holds (safety factor included) and the driving torque covers the requirement.
            assert float(row[f"required_torque[{joint}] [N*m]"]) <= catalogue.peak_torque * (1 + 1e-6)
            assert float(row[f"required_rms_torque[{joint}] [N*m]"]) <= catalogue.rated_torque * (1 + 1e-6)
        masses = sum(float(row[f"actuator_mass[{j}] [kg]"]) for j in ("joint1", "joint2"))
        assert float(row["actuator_mass [kg]"]) == pytest.approx(masses, rel=1e-9)
    report = (tmp_path / "out" / "report.html").read_text()
    assert "gearbox inertia ignored" not in report  # counted here


def test_gearbox_inertia_false_is_stated_in_the_report(tmp_path):
    from collision_reflex.study.runner import run_study

    study = tmp_path / "study.yaml"
    study.write_text(_study_text(**{"gearbox_inertia: true": "gearbox_inertia: false"}))
    run_study(study, tmp_path / "out", quiet=True, smoke=True, executor="serial", figures=False)
    assert "Gearbox inertia ignored, as in the paper" in (tmp_path / "out" / "report.html").read_text()


@pytest.mark.parametrize(
    "old, new, line, message",
    [
        (
            "gearbox: NPS015-MF-1",
            "gearbox: NPS999",
            16,
            r"actuators\.gearbox: found 'NPS999'; expected a gearbox of the catalogue.*'NPS015-MF-1'.*'SP100-MF-1'",
        ),
        (
            "  mechanical_stiffness",
            "  joints: {joint2: {gearbox: SP10}}\n  mechanical_stiffness",
            19,
            r"actuators\.joints\.joint2\.gearbox: found 'SP10'",
        ),
        ("gear_ratio: {min: 1, max: 10}", "gear_ratio: {min: 20, max: 50}", 16, r"ratios 3 to 10.*20 to 50"),
    ],
    ids=["unknown name", "unknown name at a joint", "ratio range missed"],
)
def test_bad_gearboxes_are_located(tmp_path, old, new, line, message):
    from collision_reflex.study.arm_setup import arm_setup
    from collision_reflex.study.load import parse_study

    with pytest.raises(StudyFileError, match=message) as caught:  # the schema, or the setup with the bounds
        arm_setup(parse_study(_study_text(**{old: new}), "study.yaml", ROOT / "studies"))
    assert caught.value.problems[0].line == line
    assert len({str(p) for p in caught.value.problems}) == len(caught.value.problems)  # each once


def test_a_per_joint_gearbox_of_figures_is_scaled_into_a_joint_gearbox():
    from collision_reflex.study.arm_setup import arm_setup
    from collision_reflex.study.load import parse_study

    figures = (
        "  joints:\n    joint2:\n      gearbox: {kind: harmonic, diameter: 50 mm, length: 30 mm, mass: 0.4 kg,"
        " inertia: 0.02 kg*cm^2, rated_torque: 20 N*m, efficiency: 0.8, name: HD-test}\n"
        "  mechanical_stiffness"
    )
    text = _study_text(**{"  mechanical_stiffness": figures})
    setup = arm_setup(parse_study(text, "study.yaml", ROOT / "studies"))
    first, second = setup.technology.gearboxes
    assert first.name == "NPS015-MF-1"
    assert (second.name, second.mass, second.peak_torque, second.efficiency) == ("HD-test", 0.4, 20.0, 0.8)
    assert second.ratio_range == (1.0, 10.0)  # the design's gear-ratio bounds
    assert second.inertia == pytest.approx(2e-6, rel=1e-12)


def test_a_joint_fixed_at_an_offered_ratio_has_that_ratios_figures():
    """A study fixing N = 5 with the NPS015: J1 0.17 kg cm^2, T2N 21 and T2B 40 N m at i = 5 (Beckhoff AG3300
    manual), not the least favourable 0.25 kg cm^2, 17 and 32 N m of its ratio 3; a free ratio keeps those."""
    from collision_reflex.study.arm_setup import arm_setup
    from collision_reflex.study.load import parse_study

    free = arm_setup(parse_study(_study_text(), "study.yaml", ROOT / "studies")).technology.gearboxes
    assert all(g.inertia == pytest.approx(0.25e-4, rel=1e-12) for g in free)
    fixed_text = _study_text(**{"  gear_ratio: {min: 1, max: 10}": "  gear_ratio: {min: 5, max: 5}"})
    fixed = arm_setup(parse_study(fixed_text, "study.yaml", ROOT / "studies")).technology.gearboxes
    for gearbox in fixed:
        assert gearbox.ratios == (5.0,) and (gearbox.rated_torque, gearbox.peak_torque) == (21.0, 40.0)
        assert gearbox.inertia == pytest.approx(0.17e-4, rel=1e-12)


# --- gearboxes scaled to their motor ----------------------------------------------------------------------------


def _scaled(kind: str = "harmonic", ratios: tuple[float, ...] = (30, 50, 100)):
    from collision_reflex.hardware.gearboxes import ScaledGearbox

    reference = dataclasses.replace(_gearbox("ref", 0.5, 2e-6, peak=40.0, rated=20.0), kind=kind)
    return ScaledGearbox(reference, ratios)


@pytest.mark.parametrize(
    ("kind", "mass_exponent", "inertia_exponent"), [("harmonic", 2 / 3, 4 / 3), ("planetary", 1, 2)]
)
def test_a_scaled_gearbox_follows_its_kind_law_by_hand(kind, mass_exponent, inertia_exponent):
    # Torque ~ d^3 (strain wave) or d^2 (planetary, fixed length) and mass ~ d^2, inertia ~ d^4 (Saerens et al.
    # 2019 as tabulated in the paper): at 3x the torque, mass 3^(2/3) or 3x, inertia 3^(4/3) or 9x.
    unit = _scaled(kind).unit(120.0)
    assert unit.mass == pytest.approx(0.5 * 3**mass_exponent, rel=1e-12)
    assert unit.inertia == pytest.approx(2e-6 * 3**inertia_exponent, rel=1e-12)
    assert (unit.peak_torque, unit.rated_torque) == pytest.approx((120.0, 60.0), rel=1e-12)
    assert unit.ratio_range == (30.0, 100.0) and unit.continuous_ratio
    symbolic = _scaled(kind).figures(ca.DM(120.0))
    assert float(symbolic.mass) == pytest.approx(unit.mass, rel=1e-12)


def test_a_scaled_strain_wave_unit_is_the_next_catalogue_size():
    # Harmonic Drive CSF-17-50 scaled to the repeated peak torque of the CSF-25-50 (98 N m, both in
    # designs/gearboxes.yaml): the law predicts the real unit's mass within 10 % and its input inertia within 25 %
    # (the table's exponents are a fit over a range of sizes; measured -8 % and -22 %).
    from collision_reflex.hardware.gearboxes import ScaledGearbox, load_gearbox_catalogue

    catalogue = load_gearbox_catalogue()
    small, large = catalogue["CSF-17-50-2UH"], catalogue["CSF-25-50-2UH"]
    unit = ScaledGearbox(small, small.ratios).unit(large.peak_torque)
    assert unit.mass == pytest.approx(large.mass, rel=0.10)
    assert unit.inertia == pytest.approx(large.inertia, rel=0.25)


def test_a_scaled_gearbox_is_sized_to_its_motor_in_a_design(two_link):
    scaled = _scaled(ratios=(3, 5, 10, 30))
    problem, result = _solve_two_link(two_link, (scaled, scaled))
    design = result.design
    # At the solution each joint's gearbox is the unit that carries N tau_p: its mass in the actuator mass, its
    # input inertia in N^2 (J_m + J_g) (written out from the unit, not from the technology's formula).
    for j in range(2):
        unit = scaled.unit(float(design.peak_torque[j]))
        assert design.gearbox_mass[j] == pytest.approx(unit.mass, rel=1e-12)
        assert design.actuator_mass[j] == pytest.approx(design.motor_mass[j] + unit.mass, rel=1e-12)
        expected = design.gear_ratio[j] ** 2 * (design.rotor_inertia[j] + unit.inertia)
        assert design.reflected_inertia[j] == pytest.approx(expected, rel=1e-12)
    evaluated = problem.evaluate(problem.exact_point(result.x))
    assert float(evaluated[1]) == pytest.approx(design.actuator_mass.sum(), rel=1e-12)  # the NLP's own mass
    # The ratios within the gearbox's 3 to 30 (IPOPT may relax a bound by 1e-8 relative).
    assert 3 * (1 - 1e-7) <= design.gear_ratio.min() and design.gear_ratio.max() <= 30 * (1 + 1e-7)
