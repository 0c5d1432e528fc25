"""Actuator modules: joints built from one actuator share its motor and gear ratio and meet its largest need."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
import yaml

import collision_reflex as cr
from collision_reflex.errors import InvalidParameter, StudyFileError
from collision_reflex.optimize.layout import design_layout
from collision_reflex.optimize.snap import snap_to_catalogue
from collision_reflex.study.load import load_study
from test_snap import OBJECTIVE, ROOT, TWO_LINK, _catalogue, _two_link_inputs, two_link_problem

MODULE = ((0, 1),)


@pytest.fixture(scope="module")
def moduled():
    arm, free = two_link_problem()
    _, tied = two_link_problem(modules=MODULE)
    return arm, free, cr.solve(free, starts=3), tied, cr.solve(tied, starts=3)


def test_a_module_shares_one_variable_of_each_actuator_quantity_within_both_joints_bounds():
    space, technology, constraints = _two_link_inputs()
    space = dataclasses.replace(space, stator_diameter=[(0.02, 0.08), (0.05, 0.12)], modules=MODULE)
    layout = design_layout(space, technology, constraints, 2)
    for name in ("stator_diameter", "gear_ratio"):
        first, second = layout.slices[name]
        assert first is not None and first == second
    assert [(b.lower, b.upper) for b in layout.bounds["stator_diameter"]] == [(0.05, 0.08)] * 2
    # Each joint keeps its own software stiffness.
    assert len(set(layout.slices["software_stiffness"])) == 2
    # Without the module: four joint variables of each.
    assert (
        layout.size
        == design_layout(dataclasses.replace(space, modules=()), technology, constraints, 2).size - 2
    )


def test_a_module_whose_joints_share_no_size_is_refused_naming_them():
    space, technology, constraints = _two_link_inputs()
    space = dataclasses.replace(space, stator_diameter=[(0.02, 0.04), (0.05, 0.12)], modules=MODULE)
    with pytest.raises(InvalidParameter, match=r"stator_diameter bounds of the module joint1, joint2"):
        design_layout(space, technology, constraints, 2)


@pytest.mark.parametrize("modules", [((0,),), ((0, 1), (1, 2)), ((0, 0),), ((0, -1),)])
def test_bad_modules_are_refused(modules):
    space, _, _ = _two_link_inputs()
    with pytest.raises(InvalidParameter, match="modules"):
        dataclasses.replace(space, modules=modules)


def test_a_module_is_one_actuator_sized_for_the_most_demanding_of_its_joints(moduled):
    _, _, free_optimum, tied, optimum = moduled
    design = optimum.design
    for name in ("stator_diameter", "gear_ratio", "motor_peak_torque", "actuator_mass"):
        values = getattr(design, name)
        assert values[0] == pytest.approx(values[1], rel=1e-12), name
    # The given torques are 2 and 1 N m: the module must deliver the larger at both joints.
    own = np.asarray(tied.static_torque_function(design.actuator_mass)).ravel()
    assert own[1] < 0.9 * own[0]
    np.testing.assert_allclose(optimum.required_torque, [own.max()] * 2, rtol=1e-12)
    assert np.all(design.driving_peak_torque >= own.max() * (1 - 1e-6))
    # Tying two joints can only cost: never better than the free optimum (within the solver's tolerance).
    value = sum(OBJECTIVE[k] * optimum.numpy_objectives[k] for k in OBJECTIVE)
    free_value = sum(OBJECTIVE[k] * free_optimum.numpy_objectives[k] for k in OBJECTIVE)
    assert value >= free_value * (1 - 1e-5)
    # ... and the tie binds: free, the two joints take different gear ratios.
    ratios = free_optimum.design.gear_ratio
    assert abs(ratios[0] / ratios[1] - 1) > 0.1, ratios


def test_a_module_snaps_to_one_catalogue_part(moduled):
    arm, _, _, tied, optimum = moduled
    snapped = snap_to_catalogue(tied, optimum, _catalogue(), arm=arm, candidates=3)
    assert snapped.found
    first, second = snapped.parts
    assert first.motor.name == second.motor.name
    assert snapped.result.design.gear_ratio[0] == pytest.approx(
        snapped.result.design.gear_ratio[1], rel=1e-12
    )
    # Combinations were of the module's candidates alone, not of both joints' independently.
    assert len(snapped.tried) <= len(snapped.joints[0].parts) + 1
    assert all(trial.parts[0] == trial.parts[1] for trial in snapped.tried)


def _study_with(tmp_path, **actuators) -> object:
    study = yaml.safe_load((ROOT / "studies" / "two_link_paper.yaml").read_text())
    study["robot"]["urdf"] = str(TWO_LINK)
    study["actuators"].update(actuators)
    path = tmp_path / "study.yaml"
    path.write_text(yaml.safe_dump(study))
    return path


@pytest.mark.parametrize(
    ("modules", "found"),
    [
        ([["joint1", "elbow"]], "joint 'elbow', not a joint of the arm"),
        ([["joint1"]], "two or more joints"),
        ([["joint1", "joint2"], ["joint2", "joint1"]], "in two modules"),
    ],
)
def test_a_bad_module_in_a_study_is_refused_at_its_line(tmp_path, modules, found):
    from collision_reflex.study.arm_setup import arm_setup

    path = _study_with(tmp_path, modules=modules)
    with pytest.raises(StudyFileError, match=r"actuators\.modules") as error:
        arm_setup(load_study(path))
    assert found in str(error.value)


def test_a_module_of_joints_with_different_gearboxes_is_refused(tmp_path):
    from collision_reflex.study.arm_setup import arm_setup

    path = _study_with(
        tmp_path, modules=[["joint1", "joint2"]], joints={"joint2": {"gearbox": "CSF-17-50-2UH"}}
    )
    with pytest.raises(StudyFileError, match="different motors or gearboxes"):
        arm_setup(load_study(path))


def test_a_modules_shared_variables_count_once_in_the_study_summary():
    from collision_reflex.study.prepare import free_variables

    study = load_study(ROOT / "studies" / "ur5.yaml").study
    joints = [
        "shoulder_pan_joint",
        "shoulder_lift_joint",
        "elbow_joint",
        "wrist_1_joint",
        "wrist_2_joint",
        "wrist_3_joint",
    ]
    counts = free_variables(study, 6, joints)
    # Two modules: one motor size and one gear ratio each; every joint its own software stiffness.
    assert (counts["stator_diameter"], counts["gear_ratio"], counts["software_stiffness"]) == (2, 2, 6)
