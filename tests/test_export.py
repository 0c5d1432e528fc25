"""``crx export`` and :func:`collision_reflex.export.export_design`: the exported robot models reproduce the model
the optimiser uses.

The reference is Pinocchio (and MuJoCo) reading the exported files back, against collision-reflex's own arm
model of the design: the structure mass matrix with the motor masses ``M_bb(q; m)`` and the finger-mode
effective mass (the reflected inertia on the link side). Both sides compute the same mass matrix in double
precision from the same inertial figures (the exported numbers read back to the same doubles), so they agree to
rounding, ``1e-10`` relative; a motor mass misplaced by one link, a missing armature or a gear ratio in the
wrong power changes them by far more (checked below for each robot).
"""

from __future__ import annotations

import json
import math
import os
import stat
import sysconfig
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest

from collision_reflex.arm import effective_parameters
from collision_reflex.cli import main
from collision_reflex.export import companion_path, export_design, read_run_design, set_armature
from collision_reflex.export.mjcf import TOKEN_INERTIA, MujocoMissing
from collision_reflex.report.files import write_json
from collision_reflex.study import load_study, resolved_yaml

pin = pytest.importorskip("pinocchio")

REPO = Path(__file__).resolve().parents[1]
TOLERANCE = 1e-10
"""Relative agreement of two double-precision evaluations of the same mass matrix (rounding only)."""
DRAKE = "{http://drake.mit.edu}"


def _joint_record(rng: np.random.Generator, name: str, gearbox: str = "") -> dict[str, object]:
    """A plausible joint of a design record (SI units), the fields ``crx run`` writes."""
    ratio = float(rng.uniform(5, 120))
    rotor = float(rng.uniform(1e-6, 1e-4))
    gear_inertia = float(rng.uniform(1e-6, 1e-5)) if gearbox else 0.0
    motor_torque = float(rng.uniform(0.2, 2.0))
    motor_mass, gearbox_mass = (
        float(rng.uniform(0.1, 1.0)),
        (float(rng.uniform(0.2, 1.5)) if gearbox else 0.0),
    )
    return {
        "joint": name,
        "stator_diameter": 0.06,  # the reference motor's size: its maximum speed is the catalogue's
        "stack_length": 0.0125,
        "gear_ratio": ratio,
        "rotor_inertia": rotor,
        "reflected_inertia": ratio**2 * (rotor + gear_inertia),
        "motor_peak_torque": motor_torque,
        "peak_torque": ratio * motor_torque,
        "motor_mass": motor_mass,
        "gearbox": gearbox,
        "gearbox_mass": gearbox_mass,
        "gearbox_inertia": gear_inertia,
        "gearbox_efficiency": 0.97 if gearbox else 1.0,
        "actuator_mass": motor_mass + gearbox_mass,
        "nearest_catalogue_motor": "OPN-060-013-A",
        **_UNREAD_JOINT,
    }


# What a run's record holds beside what the export reads: designs.json is checked against its type when read.
_UNREAD_JOINT = {
    "required_torque": 1.0,
    "torque_margin": None,
    "mechanical_stiffness": 5000.0,
    "software_stiffness": 500.0,
    "stiffness": 454.5,
    **dict.fromkeys(["required_rms_torque", "rms_margin", "max_motor_speed", "speed_limit", "speed_margin"]),
    "required_by": None,
}
_UNREAD_DESIGN = {
    "requirement": "static (gravity only)",
    "objectives": {},
    "casadi_objectives": {},
    "threshold": 5.0,
    "sensing": "force",
    "approach_velocity": 0.25,
    "impulses": [],
    "solver": {
        "status": "Solve_Succeeded",
        "iterations": 1,
        "epsilon": {},
        "attempts": [],
        "method": "full NLP",
        "active_samples": 1,
    },
    "phases": {"initial": [], "sensing": [], "reaction": []},
    "optimal_velocity": [],
    "statistics": {},
}
_UNREAD_RUN = {
    "description": "",
    "resolved": {},
    "samples": {
        "configurations": [],
        "directions": [],
        "config_index": [],
        "sample_directions": [],
        "joint_names": [],
        "task_dim": 3,
    },
    "domain": {
        "min_singular_value": 0.0,
        "reach": 1.0,
        "joint_speed_limit": [],
        "joint_lower": [],
        "joint_upper": [],
        "kept": None,
        "sampling_velocity": 1.0,
        "searched_samples": 0,
        "searched": [],
    },
    "bounds": {
        **{key: {} for key in ["stator_diameter", "stack_length", "gear_ratio", "software_stiffness"]},
        "threshold": [1.0, 20.0],
        "approach_velocity": [0.05, 1.0],
    },
    "requirement": "static (gravity only)",
    "speed_limits": None,
    "transmissions": [],
    "verdict": [],
}


def synthetic_run(folder: Path, study: Path, seed: int, gearbox: str = "") -> Path:
    """A run folder of ``study`` with three random designs (no solve: the export reads the records only)."""
    from collision_reflex.study.robot import load_arm

    loaded = load_study(study)
    names = load_arm(loaded).joint_names
    rng = np.random.default_rng(seed)
    points = [
        {
            "label": f"point {p}",
            "joints": [_joint_record(rng, n, gearbox if i % 2 == 0 else "") for i, n in enumerate(names)],
            **_UNREAD_DESIGN,
        }
        for p in range(3)
    ]
    folder.mkdir(parents=True)
    (folder / "study.resolved.yaml").write_text(resolved_yaml(loaded), encoding="utf-8")
    results = {
        **_UNREAD_RUN,
        "kind": "arm",
        "study": loaded.study.name,
        "chosen": points[0],
        "recommended": {**points[1], "source": "Pareto design 1", "pareto_index": 1},
        "pareto": {"objectives": [], "points": points, "failed": [], "dominated": [], "merged": 0},
    }
    write_json(folder / "designs.json", results)
    return folder


@pytest.fixture(scope="module")
def runs(tmp_path_factory: pytest.TempPathFactory, smoke_runs) -> dict[str, Path]:
    """A real smoke run of the planar two-link study and synthetic runs of the UR5 and Panda studies."""
    root = tmp_path_factory.mktemp("runs")
    return {
        "planar": smoke_runs["two_link_paper"],
        "ur5": synthetic_run(root / "ur5", REPO / "studies" / "ur5.yaml", 1, gearbox="NPS015-MF-1"),
        "panda": synthetic_run(root / "panda", REPO / "studies" / "panda.yaml", 2),
    }


ROBOTS = ["planar", "ur5", "panda"]


def _design_arrays(design) -> tuple[np.ndarray, np.ndarray]:
    """Per joint the mass carried at the joint [kg] and the armature [kg m^2] of a :class:`RunDesign`."""
    mass = np.array([j.actuator_mass for j in design.joints])
    armature = np.array([j.reflected_inertia for j in design.joints])
    return mass, armature


def _pinocchio_matrices(model, arm, q: np.ndarray, directions: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The joint-space inertia (with armature) of the reloaded model, in the arm's joint order, and ``m_f``."""
    data = model.createData()
    order = [model.joints[model.getJointId(n)].idx_v for n in arm.joint_names]
    frame = model.getFrameId(arm.contact_frame)
    mass = np.empty((len(q), arm.nv, arm.nv))
    finger = np.empty((len(q), len(directions)))
    for s, angles in enumerate(arm.joint_coordinates(q)):
        qs = pin.neutral(model)
        for name, angle in zip(arm.joint_names, angles, strict=True):
            joint = model.joints[model.getJointId(name)]
            if joint.nq == 1:
                qs[joint.idx_q] = angle
            else:
                qs[joint.idx_q : joint.idx_q + 2] = math.cos(angle), math.sin(angle)
        full = pin.crba(model, data, qs)
        full = np.triu(full) + np.triu(full, 1).T
        mass[s] = full[np.ix_(order, order)]
        jacobian = pin.computeFrameJacobian(model, data, qs, frame, pin.LOCAL_WORLD_ALIGNED)
        lever = data.oMf[frame].rotation @ arm.contact_offset
        point = (jacobian[:3] - pin.skew(lever) @ jacobian[3:])[:, order]
        if arm.plane is not None:
            point = arm.plane.T @ point
        task = point @ np.linalg.solve(mass[s], point.T)
        finger[s] = 1 / np.einsum("da,ab,db->d", directions, task, directions)
    return mass, finger


@pytest.mark.parametrize("robot", ROBOTS)
def test_urdf_gives_the_optimisers_mass_matrix_and_finger_mass(runs, robot, tmp_path):
    out = tmp_path / f"{robot}.urdf"
    written = export_design(runs[robot], "recommended", "urdf", out)
    assert written[:2] == [out, companion_path(out)]
    meshes = {m.get("filename") for m in ET.parse(out).getroot().iter("mesh")}
    assert {p.relative_to(tmp_path).as_posix() for p in written[2:]} == meshes  # every mesh copied beside it
    design = read_run_design(runs[robot], "recommended")
    arm = design.arm
    motor_mass, armature = _design_arrays(design)
    rng = np.random.default_rng(7)
    q = arm.sample_configurations(6, rng)
    directions = rng.normal(size=(5, arm.task_dim))
    directions /= np.linalg.norm(directions, axis=1, keepdims=True)
    samples = arm.kinematics(q)
    expected_mass = samples.structure_mass_matrix(motor_mass)
    expected_finger = effective_parameters(
        samples,
        directions,
        reflected_inertia=armature,
        stiffness=1e3,
        mechanical_stiffness=1e3,
        torque_limit=np.inf,
        motor_mass=motor_mass,
        finger_joint_inertia=armature,
    ).m_f

    model = set_armature(pin.buildModelFromUrdf(str(out)), companion_path(out))
    assert model.nv == arm.nv
    mass, finger = _pinocchio_matrices(model, arm, q, directions)
    scale = np.abs(expected_mass).max(axis=(1, 2), keepdims=True)
    np.testing.assert_array_less(np.abs(mass - np.diag(armature) - expected_mass) / scale, TOLERANCE)
    np.testing.assert_allclose(finger, expected_finger, rtol=TOLERANCE)
    # What the check guards is large: the motors and the armature move the matrix by far more than the tolerance.
    assert np.abs(expected_mass - samples.mass_matrix).max() / scale.max() > 1e-4
    assert armature.max() / scale.max() > 1e-4


@pytest.mark.parametrize("robot", ROBOTS)
def test_urdf_limits_transmissions_and_companion(runs, robot, tmp_path):
    from collision_reflex.hardware.motors import load_catalogue

    out = tmp_path / f"{robot}.urdf"
    export_design(runs[robot], 0, "urdf", out)
    record = json.loads((runs[robot] / "designs.json").read_text())["pareto"]["points"][0]
    root = ET.parse(out).getroot()
    joints = {j.get("name"): j for j in root.findall("joint")}
    transmissions = {t.find("joint").get("name"): t for t in root.findall("transmission")}
    companion = json.loads(companion_path(out).read_text())["joints"]
    reference = load_catalogue()["OPN-060-013-A"]
    for saved in record["joints"]:
        name, ratio = saved["joint"], saved["gear_ratio"]
        limit = joints[name].find("limit")
        assert float(limit.get("effort")) == pytest.approx(_effort(saved), rel=1e-12)
        if (
            saved["stator_diameter"] == reference.stator_diameter
            and saved["stack_length"] == reference.stack_length
        ):
            assert float(limit.get("velocity")) == pytest.approx(reference.max_speed / ratio, rel=1e-12)
        actuator = transmissions[name].find("actuator")
        assert float(actuator.find("mechanicalReduction").text) == ratio
        rotor = float(actuator.find(f"{DRAKE}rotor_inertia").get("value"))
        assert rotor == pytest.approx(saved["rotor_inertia"] + saved["gearbox_inertia"], rel=1e-12)
        assert companion[name]["armature"] == saved["reflected_inertia"]
        assert companion[name]["armature"] == pytest.approx(ratio**2 * rotor, rel=1e-12)
        mount = joints[f"{name}_actuator_mount"]
        assert mount.get("type") == "fixed"
        assert mount.find("parent").get("link") == joints[name].find("parent").get("link")
        mass = root.find(f"link[@name='{name}_actuator']/inertial/mass")
        assert float(mass.get("value")) == pytest.approx(
            saved["motor_mass"] + saved["gearbox_mass"], rel=1e-15
        )
    if robot == "panda":  # the locked fingers are fixed joints
        assert joints["panda_finger_joint1"].get("type") == "fixed"
        assert all(m.get("filename").startswith("panda_meshes/") for m in root.iter("mesh"))


def _effort(saved, catalogue_design: bool = False) -> float:
    """A joint's driving peak output torque: eta N tau_p, at most its catalogue gearbox's repeated peak [N m].

    A catalogue design's gearbox is sold at its ratio: the peak there (the entry's own for a continuous design).
    """
    from collision_reflex.hardware.gearboxes import load_gearbox_catalogue

    driving = saved.get("gearbox_efficiency", 1.0) * saved["peak_torque"]
    gearbox = load_gearbox_catalogue().get(saved.get("gearbox") or "")
    if gearbox is not None and catalogue_design:
        gearbox = gearbox.at_ratio(saved["gear_ratio"])
    return driving if gearbox is None else min(driving, gearbox.peak_torque)


def test_the_catalogue_design_exports_with_its_parts_and_loads(smoke_runs, tmp_path):
    """``--design catalogue``: the parts the snap chose, each named with its source, efforts within the gearbox's
    repeated peak, the motor's own speed limit; Pinocchio and MuJoCo load the files; no NumPy repr leaks."""
    import mujoco
    import pinocchio as pin

    from collision_reflex.hardware.motors import load_catalogue

    run = smoke_runs["ur5"]
    catalogue = json.loads((run / "designs.json").read_text())["catalogue"]
    out = tmp_path / "built.urdf"
    export_design(run, "catalogue", "urdf", out)
    text = out.read_text()
    assert "catalogue design (from " in text and "np.float64" not in text
    root = ET.parse(out).getroot()
    joints = {j.get("name"): j for j in root.findall("joint")}
    motors = load_catalogue()
    for chosen, saved in zip(catalogue["joints"], catalogue["design"]["joints"], strict=True):
        assert f"catalogue motor {chosen['motor']}: {motors[chosen['motor']].source[:40]}" in text
        limit = joints[saved["joint"]].find("limit")
        assert float(limit.get("effort")) == pytest.approx(_effort(saved, True), rel=1e-12)
        speed = motors[chosen["motor"]].max_speed
        if speed is not None:
            assert float(limit.get("velocity")) <= speed / saved["gear_ratio"] * (1 + 1e-12)
    for saved in catalogue["design"]["joints"]:  # the header's figures are designs.json's, digit for digit
        line = next(x for x in text.splitlines() if x.strip().startswith(saved["joint"] + ":"))
        for key in ("motor_mass", "gear_ratio", "gearbox_mass"):
            assert repr(float(saved[key])) in line, (key, line)
    pin.buildModelsFromUrdf(str(out), str(tmp_path))  # with its meshes, copied beside it
    assert mujoco.MjModel.from_xml_path(str(out)).nmesh > 0  # MuJoCo reads the URDF as written
    mjcf = tmp_path / "built.xml"
    export_design(run, "catalogue", "mjcf", mjcf)
    assert "as the study was optimised (reflected_inertia_in = robot)" in mjcf.read_text()  # the placement
    model = mujoco.MjModel.from_xml_path(str(mjcf))
    built = catalogue["design"]  # the controller block: the design's figures, digit for digit
    assert model.numeric("collision_reflex_threshold").data[0] == built["threshold"]
    assert model.numeric("collision_reflex_approach_velocity").data[0] == built["approach_velocity"]
    assert model.numeric("collision_reflex_position_sensing").data[0] == (built["sensing"] == "position")
    for saved in built["joints"]:
        stiffness = model.numeric(f"collision_reflex_{saved['joint']}_software_stiffness").data[0]
        assert stiffness == saved["software_stiffness"]
    for saved in built["joints"]:  # the output torque range on the rotor, behind the joint spring
        joint = model.joint(saved["joint"] + "_rotor")
        assert model.jnt_actfrcrange[joint.id][1] == pytest.approx(_effort(saved, True), rel=1e-12)


def test_a_catalogue_design_is_charged_its_gearboxs_inertia_at_its_ratio(smoke_runs, tmp_path):
    """two_link_planetary's catalogue design: each NPS015-MF-1 carries the datasheet's J1 at its own ratio in
    designs.json, and the export's armature is N^2 (J_m + J_g(N)), its figures designs.json's digit for digit."""
    # Beckhoff AG3300 manual, NPS015 MF mechanical data (1-stage): J1 with the 9 mm clamping hub per ratio.
    table = {3.0: 0.25e-4, 4.0: 0.19e-4, 5.0: 0.17e-4, 7.0: 0.14e-4, 8.0: 0.14e-4, 10.0: 0.13e-4}
    run = smoke_runs["two_link_planetary"]
    built = json.loads((run / "designs.json").read_text())["catalogue"]["design"]
    assert {j["gearbox"] for j in built["joints"]} == {"NPS015-MF-1"}
    assert any(j["gear_ratio"] != 3.0 for j in built["joints"])  # a ratio below the least favourable J1
    out = tmp_path / "built.urdf"
    export_design(run, "catalogue", "urdf", out)
    companion = json.loads(companion_path(out).read_text())["joints"]
    text = out.read_text()
    for saved in built["joints"]:
        ratio, name = saved["gear_ratio"], saved["joint"]
        assert saved["gearbox_inertia"] == pytest.approx(table[ratio], rel=1e-12)
        assert saved["reflected_inertia"] == pytest.approx(
            ratio**2 * (saved["rotor_inertia"] + table[ratio]), rel=1e-12
        )
        assert companion[name]["armature"] == saved["reflected_inertia"]
        assert companion[name]["gearbox_inertia"] == saved["gearbox_inertia"]
        armature = f"{ratio!r}^2 x ({saved['rotor_inertia']!r} + {saved['gearbox_inertia']!r}) = "
        assert f"{name}: armature N^2 (J_m + J_g) = {armature}{saved['reflected_inertia']!r} kg m^2" in text


def test_the_documented_armature_loop_is_set_armature(runs, tmp_path):
    """The README's hand-written loop over the companion and :func:`set_armature` set the same armature."""
    out = tmp_path / "ur5.urdf"
    export_design(runs["ur5"], "recommended", "urdf", out)
    model = pin.buildModelFromUrdf(str(out))
    for name, joint in json.loads(companion_path(out).read_text())["joints"].items():
        model.armature[model.joints[model.getJointId(name)].idx_v] = joint["armature"]
    by_function = set_armature(pin.buildModelFromUrdf(str(out)), companion_path(out))
    np.testing.assert_array_equal(model.armature, by_function.armature)
    design = read_run_design(runs["ur5"], "recommended")
    np.testing.assert_array_equal(model.armature, [j.reflected_inertia for j in design.joints])


def _full_inertia(mujoco, model, data) -> np.ndarray:
    """MuJoCo's dense joint-space inertia (the ``mj_fullM`` signature changed with MuJoCo 4)."""
    full = np.zeros((model.nv, model.nv))
    try:
        mujoco.mj_fullM(model, data, full)
    except TypeError:
        mujoco.mj_fullM(model, full, data.qM)
    return full


@pytest.mark.parametrize("robot", ROBOTS)
def test_mjcf_full_inertia_is_the_same_matrix_with_armature(runs, robot, tmp_path):
    """The study placed the rotors behind the joint springs (``robot``): each is a DOF of its own with the armature,
    joined to its link by a tendon spring of the joint's stiffness, so the links' block of MuJoCo's inertia is the
    structure with the motor masses (the finger mass the optimiser used, exactly) and the rotors' block is the
    armature; rigidly coupled, the two add up to the model with the armature on the joints."""
    mujoco = pytest.importorskip("mujoco", reason="the mujoco extra is not installed")
    out = tmp_path / f"{robot}.xml"
    export_design(runs[robot], "recommended", "mjcf", out)
    design = read_run_design(runs[robot], "recommended")
    assert design.placement == "robot"
    arm = design.arm
    motor_mass, armature = _design_arrays(design)
    q = arm.sample_configurations(6, np.random.default_rng(3))
    expected = arm.kinematics(q).structure_mass_matrix(motor_mass)
    model = mujoco.MjModel.from_xml_path(str(out))
    assert model.opt.integrator == mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    urdf_joints = {j.get("name"): j for j in ET.parse(arm.urdf_path).getroot().findall("joint")}
    for name in arm.joint_names:  # the URDF's joint damping kept (the Panda's 0.003 N m s/rad, the UR5's 0)
        dynamics = urdf_joints[name].find("dynamics")
        damping = float(dynamics.get("damping", 0.0)) if dynamics is not None else 0.0
        assert model.dof_damping[model.joint(name).dofadr[0]] == damping
    data = mujoco.MjData(model)
    links = [model.joint(n).id for n in arm.joint_names]
    rotors = [model.joint(f"{n}_rotor").id for n in arm.joint_names]
    link_dofs, rotor_dofs = ([model.jnt_dofadr[j] for j in ids] for ids in (links, rotors))
    for expected_s, angles in zip(expected, arm.joint_coordinates(q), strict=True):
        for ids in (links, rotors):
            data.qpos[[model.jnt_qposadr[j] for j in ids]] = angles
        mujoco.mj_forward(model, data)
        full = _full_inertia(mujoco, model, data)
        block = full[np.ix_(link_dofs, link_dofs)]
        assert np.abs(block - expected_s).max() / np.abs(expected_s).max() < TOLERANCE
        np.testing.assert_allclose(np.diag(full)[rotor_dofs], armature, rtol=1e-12, atol=2 * TOKEN_INERTIA)
        assert np.abs(full[np.ix_(link_dofs, rotor_dofs)]).max() < 1e-9  # a rotor moves no link mass
    for joint, tendon in zip(design.joints, range(model.ntendon), strict=True):
        assert model.tendon(tendon).name == f"{joint.joint}_spring"
        assert model.tendon_stiffness[tendon] == joint.mechanical_stiffness
    for joint in design.joints:
        actuator = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_ACTUATOR, f"{joint.joint}_motor")
        assert model.actuator_trnid[actuator, 0] == model.joint(f"{joint.joint}_rotor").id  # drives the rotor
        assert model.actuator_gear[actuator, 0] == joint.gear_ratio
        np.testing.assert_array_equal(
            model.actuator_ctrlrange[actuator], [-joint.motor_peak_torque, joint.motor_peak_torque]
        )
        driving = joint.driving_peak_torque  # eta N tau_p, within the catalogue gearbox's repeated peak
        assert driving == min(
            joint.gearbox_efficiency * joint.peak_torque, joint.gearbox_peak_torque or np.inf
        )
        rotor = model.joint(f"{joint.joint}_rotor").id
        np.testing.assert_array_equal(model.jnt_actfrcrange[rotor], [-driving, driving])


def test_no_absolute_path_in_the_exported_files(runs, tmp_path):
    forbidden = [str(REPO), sysconfig.get_paths()["purelib"], str(tmp_path)]
    written = []
    for robot in ROBOTS:
        written += export_design(runs[robot], "recommended", "urdf", tmp_path / f"{robot}.urdf")
        forbidden.append(str(runs[robot]))
        try:
            written += export_design(runs[robot], "recommended", "mjcf", tmp_path / f"{robot}.xml")
        except MujocoMissing:
            pass  # the mujoco extra is not installed: the URDF is checked
    for path in written:
        if path.suffix in (".urdf", ".xml", ".json"):  # the models, not the copied meshes
            text = path.read_text()
            assert not [f for f in forbidden if f in text], path


def test_a_mesh_is_copied_beside_the_output_or_its_reference_kept_when_missing(tmp_path):
    robot = tmp_path / "robot"
    robot.mkdir()
    urdf = (REPO / "designs" / "planar_two_link.urdf").read_text()
    mesh = '<visual><geometry><mesh filename="meshes/link1.stl"/></geometry></visual>'
    (robot / "arm.urdf").write_text(urdf.replace('<link name="link1">', f'<link name="link1">{mesh}', 1))
    study = (REPO / "studies" / "two_link_paper.yaml").read_text()
    (tmp_path / "study.yaml").write_text(study.replace("../designs/planar_two_link.urdf", "robot/arm.urdf"))
    run = synthetic_run(tmp_path / "run", tmp_path / "study.yaml", 4)
    (tmp_path / "out").mkdir()
    export_design(run, "recommended", "urdf", tmp_path / "out" / "arm.urdf")
    (written,) = ET.parse(tmp_path / "out" / "arm.urdf").getroot().iter("mesh")
    assert written.get("filename") == "../robot/meshes/link1.stl"  # not there: the reference is kept
    assert (
        "Meshes not found, references kept: meshes/link1.stl" in (tmp_path / "out" / "arm.urdf").read_text()
    )
    (robot / "meshes").mkdir()
    (robot / "meshes" / "link1.stl").write_bytes(b"solid link1\nendsolid link1\n")
    files = export_design(run, "recommended", "urdf", tmp_path / "out" / "arm.urdf")
    (written,) = ET.parse(tmp_path / "out" / "arm.urdf").getroot().iter("mesh")
    assert written.get("filename") == "arm_meshes/link1.stl"  # copied beside the URDF
    assert tmp_path / "out" / "arm_meshes" / "link1.stl" in files
    assert (tmp_path / "out" / "arm_meshes" / "link1.stl").read_bytes() == b"solid link1\nendsolid link1\n"


@pytest.mark.parametrize("name", ['--><link name="INJECTED"/><!--', "bad\ud800name", "a\x01b-"])
def test_a_hostile_name_in_the_run_folder_stays_inside_its_comment(tmp_path, name):
    """A gearbox name in designs.json is input: ``-->`` cannot close the header comment and add a link, a
    lone surrogate or a control character cannot break the file; URDF and MJCF parse, with nothing added."""
    run = synthetic_run(tmp_path / "run", REPO / "studies" / "two_link_paper.yaml", 5, gearbox=name)
    for fmt, out in (("urdf", tmp_path / "arm.urdf"), ("mjcf", tmp_path / "arm.xml")):
        try:
            export_design(run, "recommended", fmt, out)
        except MujocoMissing:
            continue
        root = ET.parse(out).getroot()
        assert not [e for e in root.iter() if e.get("name") == "INJECTED"]
        assert out.read_text(encoding="utf-8").count("<!--") == out.read_text(encoding="utf-8").count("-->")


def _one_line_error(argv: list[str], capsys: pytest.CaptureFixture[str]) -> str:
    """Run ``crx`` expecting exit status 2, no output and a one-line error; return the line."""
    assert main(argv) == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    lines = captured.err.strip().splitlines()
    assert len(lines) == 1, captured.err
    return lines[0]


def test_bad_inputs_are_one_line_and_exit_2(runs, tmp_path, capsys):
    out = str(tmp_path / "arm.urdf")
    planar = str(runs["planar"])
    assert "Pareto design" in _one_line_error(
        ["export", planar, "--design", "99", "--format", "urdf", "--out", out], capsys
    )
    assert "recommended" in _one_line_error(
        ["export", planar, "--design", "best", "--format", "urdf", "--out", out], capsys
    )
    assert "designs.json" in _one_line_error(
        ["export", str(tmp_path), "--format", "urdf", "--out", out], capsys
    )
    blocker = tmp_path / "a_file"
    blocker.write_text("")
    assert "not a folder" in _one_line_error(
        ["export", planar, "--format", "urdf", "--out", str(blocker / "x.urdf")], capsys
    )
    assert "folder" in _one_line_error(["export", planar, "--format", "urdf", "--out", str(tmp_path)], capsys)

    actuator = tmp_path / "actuator"
    actuator.mkdir()
    write_json(actuator / "designs.json", {"kind": "actuator", "study": "x"})
    assert "arm study" in _one_line_error(["export", str(actuator), "--format", "urdf", "--out", out], capsys)

    damaged = tmp_path / "damaged"
    damaged.mkdir()
    (damaged / "study.resolved.yaml").write_text((runs["planar"] / "study.resolved.yaml").read_text())
    (damaged / "designs.json").write_text('{"kind": "arm", "pareto": {"poi')
    assert "cannot be read" in _one_line_error(
        ["export", str(damaged), "--format", "urdf", "--out", out], capsys
    )
    record = json.loads((runs["planar"] / "designs.json").read_text())
    del record["recommended"]["joints"][0]["gear_ratio"]
    write_json(damaged / "designs.json", record)
    assert "'gear_ratio'" in _one_line_error(
        ["export", str(damaged), "--format", "urdf", "--out", out], capsys
    )
    assert not Path(out).exists()


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="named pipes are POSIX")
def test_an_output_that_is_a_device_or_a_pipe_is_refused_not_replaced(runs, tmp_path, capsys):
    """--out /dev/zero (as root) renamed the export over the device node; a pipe stands in for it here."""
    pipe = tmp_path / "pipe.urdf"
    os.mkfifo(pipe)
    planar = str(runs["planar"])
    assert "not a regular file" in _one_line_error(
        ["export", planar, "--format", "urdf", "--out", str(pipe)], capsys
    )
    assert stat.S_ISFIFO(pipe.lstat().st_mode)
    too_long = str(tmp_path / ("a" * 300 + ".urdf"))  # a traceback (ENAMETOOLONG) before
    assert "cannot write" in _one_line_error(
        ["export", planar, "--format", "urdf", "--out", too_long], capsys
    )


def test_cli_writes_the_model_and_its_companion(runs, tmp_path, capsys):
    out = tmp_path / "arm.urdf"
    assert (
        main(["export", str(runs["planar"]), "--design", "chosen", "--format", "urdf", "--out", str(out)])
        == 0
    )
    assert capsys.readouterr().out.split() == [str(out), str(companion_path(out))]
    header = out.read_text()
    assert "two-link-paper" in header and "chosen design" in header and "OPN-060-013-A" in header
