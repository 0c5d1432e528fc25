"""The collision reflex of an exported catalogue design run in MuJoCo gives the report's impulse (issue 32).

The UR5 smoke study's catalogue design is exported (MJCF and URDF, each loaded unmodified by MuJoCo and
Pinocchio); :mod:`collision_reflex.export.mujoco_reflex` runs it against a rigid plastic wall at one contact
sample, and its impulse must be the one ``designs.json`` predicts there within :data:`TOLERANCE`.

The sample is chosen by a stated rule, not by trial: the first sample where the closed form's own assumptions do
not move the prediction (:func:`~collision_reflex.export.reflex_sample.model_spread` within
:data:`~collision_reflex.export.reflex_sample.MODEL_SPREAD`: the robot mass still moving at detection, the links
moving along the wall, or, for a square Jacobian, blocked along it in the sensing phase, change the closed form
by less than 1 % there). Elsewhere the report's model is not what MuJoCo simulates (sample 6 of this run: the
joint-space model is 55 % above the report, MuJoCo 64 %). The same rule does not guarantee 2 % everywhere:
``benchmarks/results/export_mujoco.md`` lists the samples where it does not hold.
"""

from __future__ import annotations

import json
import shutil
import sys
from pathlib import Path

import pytest

from collision_reflex.export import export_design, read_run_design
from collision_reflex.export.mujoco_reflex import main, mujoco_reflex
from collision_reflex.export.reflex_sample import MODEL_SPREAD, contact_sample, joint_design, model_spread
from collision_reflex.simulate.design_closed_form import arm_closed_form

mujoco = pytest.importorskip("mujoco", reason="the mujoco extra is not installed")
pin = pytest.importorskip("pinocchio")

TOLERANCE = 0.02
"""The issue's criterion. At the chosen sample (measured: -0.18 %, benchmarks/results/export_mujoco.md) the wall's
stiffness (1e5 to 1e6 times the joints'), its damping (10 to 30 times critical) and the step move MuJoCo's
impulse by 0.6 % at most, and the closed form's variants move the prediction by less than 1 % (the rule): 2 %
holds both with a margin. The impact phase ``m_f v0`` is 98 % of the impulse there, so the check is mostly one
of the finger mass and the plastic impact; the rotors rigidly on the links change it by far more than 2 %."""

STUDY = "ur5"
REPO = Path(__file__).resolve().parents[1]


def _first_agreeing_sample(run) -> int:
    """The first sample where the closed form's variants agree with the report within MODEL_SPREAD."""
    count = len(json.loads((run / "designs.json").read_text())["samples"]["config_index"])
    return next(s for s in range(count) if model_spread(run, s) <= MODEL_SPREAD)


def test_mujoco_gives_the_reports_impulse_of_the_catalogue_design(smoke_runs, tmp_path):
    run = smoke_runs[STUDY]
    mjcf, urdf = tmp_path / "built.xml", tmp_path / "built.urdf"
    export_design(run, "catalogue", "mjcf", mjcf)
    export_design(run, "catalogue", "urdf", urdf)
    mujoco.MjModel.from_xml_path(str(mjcf))  # both files load as written
    mujoco.MjModel.from_xml_path(str(urdf))
    pin.buildModelsFromUrdf(str(urdf), str(tmp_path))
    sample = _first_agreeing_sample(run)
    result = mujoco_reflex(run, sample, mjcf)
    assert (
        result.predicted
        == json.loads((run / "designs.json").read_text())["catalogue"]["design"]["impulses"][sample]
    )
    assert abs(result.relative_difference) <= TOLERANCE, result
    assert result.detection_time < result.contact_end
    # A wrong model misses by far more: the rotors rigidly on the links (the 'finger' placement) at the same sample.
    design = read_run_design(run, "catalogue")
    point, joints = contact_sample(run, sample), joint_design(design)
    rigid = arm_closed_form(
        joints.on(design.arm), point.q, point.u, joints, placement="finger", reaction="at_rest"
    )
    assert abs(rigid.impulse(design.approach_velocity) / result.impulse - 1) > 5 * TOLERANCE


def _one_line(argv: list[str], capsys: pytest.CaptureFixture[str]) -> str:
    """Run the script expecting exit status 2, no output and a one-line error; return the line."""
    capsys.readouterr()  # what a smoke run printed when the fixture made it
    assert main(argv) == 2
    captured = capsys.readouterr()
    lines = captured.err.strip().splitlines()
    assert captured.out == "" and len(lines) == 1, captured.err
    return lines[0]


def test_bad_inputs_are_one_line_errors(smoke_runs, tmp_path, capsys, monkeypatch):
    run = smoke_runs[STUDY]
    assert "sample index 0 to" in _one_line([str(run), "--sample", "999"], capsys)
    assert "invalid int" in _one_line([str(run), "--sample", "two"], capsys)
    assert "designs.json" in _one_line([str(tmp_path), "--sample", "0"], capsys)
    assert "actuator study" in _one_line([str(smoke_runs["direct_drive_vs_geared"]), "--sample", "0"], capsys)
    bare = tmp_path / "bare"
    shutil.copytree(run, bare)
    data = json.loads((bare / "designs.json").read_text())
    del data["catalogue"]  # as a run with catalogue.snap off writes it
    (bare / "designs.json").write_text(json.dumps(data))
    assert "no catalogue design" in _one_line([str(bare), "--sample", "0"], capsys)
    monkeypatch.setitem(sys.modules, "mujoco", None)  # as if the extra were not installed
    assert "pip install" in _one_line([str(run), "--sample", "0"], capsys)


def test_the_blocked_stiffness_is_the_papers_form():
    """``arm_closed_form(..., stiffness_form="paper")`` (used by the sample rule) has the sensing stiffness
    ``u^T J^-T K J^-1 u`` of the planar two-link arm, above the compliance form ``1 / (u^T J K^-1 J^T u)`` (the
    links free along the wall)."""
    import numpy as np

    from collision_reflex import Arm
    from collision_reflex.simulate.design_closed_form import JointDesign

    arm = Arm.from_urdf(str(REPO / "designs" / "planar_two_link.urdf"), "tip")
    q, u = np.array([0.3, 0.9]), np.array([0.6, 0.8])
    stiffness = np.array([400.0, 150.0])
    joints = JointDesign(stiffness, 1e-3, 50.0, 3.0)
    jac = arm.kinematics(q[None]).jacobian[0]
    inverse = np.linalg.inv(jac)
    blocked = arm_closed_form(arm, q, u, joints, stiffness_form="paper")
    free = arm_closed_form(arm, q, u, joints)
    # The lumped stiffness k of the sensing phase (the software spring infinite here: k is the joints' own).
    assert blocked.k == pytest.approx(u @ inverse.T @ np.diag(stiffness) @ inverse @ u, rel=1e-12)
    assert free.k == pytest.approx(1 / (u @ jac @ np.diag(1 / stiffness) @ jac.T @ u), rel=1e-12)
    assert blocked.k > free.k


def _edited_model(run, tmp_path, **numerics: str):
    """The catalogue design's MJCF with controller numerics replaced (``None``: removed)."""
    import xml.etree.ElementTree as ET

    path = tmp_path / "edited.xml"
    export_design(run, "catalogue", "mjcf", path)
    root = ET.parse(path).getroot()
    custom = root.find("custom")
    for name, value in numerics.items():
        element = custom.find(f"numeric[@name='collision_reflex_{name}']")
        if value is None:
            custom.remove(element)
        else:
            element.set("data", value)
    ET.ElementTree(root).write(path)
    return path


def test_the_script_runs_the_controller_the_model_carries(smoke_runs, tmp_path, capsys):
    """Position sensing set in the MJCF's controller block: the finger stops at the impact and the commanded path
    runs on at v0, so the error reaches e_th after e_th / v0 (within 2 %: the links still move a little); a
    model without a number of the block is a one-line error."""
    run = smoke_runs[STUDY]
    error = 2e-4  # [m]
    model = _edited_model(run, tmp_path, position_sensing="1", threshold=repr(error))
    result = mujoco_reflex(run, 2, model)
    v0 = read_run_design(run, "catalogue").approach_velocity
    assert result.detection_time == pytest.approx(error / v0, rel=0.02)
    broken = _edited_model(run, tmp_path, approach_velocity=None)
    assert "approach_velocity" in _one_line([str(run), "--sample", "2", "--model", str(broken)], capsys)
