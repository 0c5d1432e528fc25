"""Arm loading and batched kinematics, against closed forms and independent Pinocchio computations."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

from collision_reflex.arm import Arm, JointParameters
from collision_reflex.errors import FrameNotFound, InvalidParameter, UrdfError

DESIGNS = Path(__file__).resolve().parents[1] / "designs"
TWO_LINK = DESIGNS / "planar_two_link.urdf"

# The planar two-link design (designs/planar_two_link.urdf): lengths [m], masses [kg], inertias about z [kg m^2].
L1, L2, M1, M2 = 0.30, 0.25, 0.20, 0.15
LC1, LC2 = L1 / 2, L2 / 2
I1, I2 = M1 * L1**2 / 12, M2 * L2**2 / 12


@pytest.fixture(scope="module")
def two_link() -> Arm:
    return Arm.from_urdf(TWO_LINK, "tip")


@pytest.fixture(scope="module")
def panda() -> Arm:
    return Arm.from_example_robot_data("panda")


@pytest.fixture(scope="module")
def ur5() -> Arm:
    return Arm.from_example_robot_data("ur5")


def _closed_form_2r(q1: float, q2: float) -> tuple[np.ndarray, np.ndarray]:
    """Textbook mass matrix and tip Jacobian of a planar 2R arm with slender links."""
    c2 = np.cos(q2)
    m11 = I1 + I2 + M1 * LC1**2 + M2 * (L1**2 + LC2**2 + 2 * L1 * LC2 * c2)
    m12 = I2 + M2 * (LC2**2 + L1 * LC2 * c2)
    m22 = I2 + M2 * LC2**2
    s1, c1, s12, c12 = np.sin(q1), np.cos(q1), np.sin(q1 + q2), np.cos(q1 + q2)
    jac = np.array([[-L1 * s1 - L2 * s12, -L2 * s12], [L1 * c1 + L2 * c12, L2 * c12]])
    return np.array([[m11, m12], [m12, m22]]), jac


CONFIGS_2R = [(0.0, 0.0), (0.3, np.pi / 4), (-1.2, 2.0), (2.5, -0.7)]


@pytest.mark.parametrize("q", CONFIGS_2R, ids=[f"q={q1:.2f},{q2:.2f}" for q1, q2 in CONFIGS_2R])
def test_two_link_matches_closed_form(two_link, q):
    samples = two_link.kinematics(np.array([q]))
    mass, jac = _closed_form_2r(*q)
    # Same formulas evaluated two ways in double precision: agreement to rounding.
    np.testing.assert_allclose(samples.mass_matrix[0], mass, rtol=1e-12, atol=1e-14)
    np.testing.assert_allclose(samples.jacobian[0], jac, rtol=1e-12, atol=1e-14)
    tip = [L1 * np.cos(q[0]) + L2 * np.cos(q[0] + q[1]), L1 * np.sin(q[0]) + L2 * np.sin(q[0] + q[1]), 0.0]
    np.testing.assert_allclose(samples.contact_position[0], tip, atol=1e-14)


def test_planar_detection():
    assert Arm.from_urdf(TWO_LINK, "tip").task_dim == 2
    pendulum = Arm.from_example_robot_data("double_pendulum")  # axes along x: the y-z plane
    assert pendulum.task_dim == 2
    np.testing.assert_allclose(np.abs(pendulum.plane), [[0, 0], [1, 0], [0, 1]], atol=1e-12)
    assert Arm.from_example_robot_data("ur5").task_dim == 3


def test_panda_fingers_locked_by_default(panda):
    assert (panda.nq, panda.nv, panda.task_dim) == (7, 7, 3)
    assert "panda_finger_joint1" not in panda.joint_names
    unlocked = Arm.from_example_robot_data("panda", locked_joints=())
    assert unlocked.nv == 9


@pytest.mark.parametrize("robot", ["panda", "ur5", "two_link"], ids=str)
def test_jacobian_matches_pinocchio_frame_jacobian(robot, request, panda, ur5, two_link):
    arm = {"panda": panda, "ur5": ur5, "two_link": two_link}[robot]
    q = arm.sample_configurations(4, np.random.default_rng(3))
    samples = arm.kinematics(q)
    model, data = arm.model, arm.model.createData()
    frame = model.getFrameId(arm.contact_frame)
    for s in range(q.shape[0]):
        pin.computeJointJacobians(model, data, q[s])
        pin.updateFramePlacements(model, data)
        expected = pin.getFrameJacobian(model, data, frame, pin.LOCAL_WORLD_ALIGNED)[:3]
        full = samples.jacobian[s] if arm.plane is None else arm.plane @ samples.jacobian[s]
        # Both are sums of a few products of O(1) numbers: rounding-level agreement.
        np.testing.assert_allclose(full, expected, atol=1e-12)
        np.testing.assert_allclose(samples.contact_position[s], data.oMf[frame].translation, atol=1e-12)


def test_contact_offset_moves_the_point(two_link):
    shifted = Arm.from_urdf(TWO_LINK, "link2", contact_offset=[L2, 0.0, 0.0])
    q = np.array([[0.4, -0.9]])
    np.testing.assert_allclose(shifted.kinematics(q).jacobian, two_link.kinematics(q).jacobian, atol=1e-14)


def _with_point_masses(model, masses):
    """A copy of ``model`` with a point mass at every joint's origin, attached to the parent link."""
    loaded = model.copy()
    for j in range(1, model.njoints):
        parent = model.parents[j]
        point = pin.Inertia(masses[j - 1], model.jointPlacements[j].translation, np.zeros((3, 3)))
        loaded.inertias[parent] = loaded.inertias[parent] + point
    return loaded


@pytest.mark.parametrize("robot", ["panda", "ur5", "two_link"], ids=str)
def test_motor_mass_terms_equal_a_model_with_point_masses(robot, panda, ur5, two_link):
    arm = {"panda": panda, "ur5": ur5, "two_link": two_link}[robot]
    rng = np.random.default_rng(7)
    masses = rng.uniform(0.2, 2.0, arm.nv)
    loaded = _with_point_masses(arm.model, masses)
    loaded.armature = np.zeros(arm.nv)
    data = loaded.createData()
    q = arm.sample_configurations(5, rng)
    samples = arm.kinematics(q)
    predicted_mass = samples.structure_mass_matrix(masses)
    predicted_gravity = samples.gravity + np.einsum("i,sij->sj", masses, samples.motor_gravity)
    for s in range(q.shape[0]):
        # Pinocchio with the bodies actually added; rounding-level agreement relative to O(1) entries.
        np.testing.assert_allclose(predicted_mass[s], pin.crba(loaded, data, q[s]), atol=1e-11)
        np.testing.assert_allclose(
            predicted_gravity[s], pin.computeGeneralizedGravity(loaded, data, q[s]), atol=1e-10
        )
    assert np.any(np.abs(samples.motor_mass_influence) > 1e-3)  # the test is not vacuous


def test_motor_at_the_base_has_no_influence(two_link):
    samples = two_link.kinematics(np.array([[0.3, 0.8]]))
    # Joint 1's motor sits on the fixed base: it never moves.
    assert np.all(samples.motor_mass_influence[0, 0] == 0)
    # Joint 2's motor is a point at distance L1 moved by joint 1 only: A_2 = diag(L1^2, 0).
    np.testing.assert_allclose(samples.motor_mass_influence[0, 1], [[L1**2, 0], [0, 0]], atol=1e-15)


def test_contact_gravity_is_a_payload_point_mass(ur5):
    q = ur5.sample_configurations(3, np.random.default_rng(11))
    samples = ur5.kinematics(q)
    model = ur5.model.copy()
    frame = model.frames[model.getFrameId(ur5.contact_frame)]
    model.inertias[frame.parentJoint] += pin.Inertia(1.0, frame.placement.translation, np.zeros((3, 3)))
    data = model.createData()
    for s in range(3):
        expected = pin.computeGeneralizedGravity(model, data, q[s]) - samples.gravity[s]
        np.testing.assert_allclose(samples.contact_gravity[s], expected, atol=1e-10)


def test_armature_is_the_reflected_inertia():
    reflected = np.array([2.21e-5 * 9.0**2, 1.33e-4])  # N^2 J_m for two gear ratios
    params = JointParameters(reflected, [1.3, 1.3], np.inf, np.inf, [0.1, 0.1])
    arm = Arm.from_urdf(TWO_LINK, "tip", actuators=params)
    np.testing.assert_array_equal(arm.model.armature, reflected)
    q = arm.sample_configurations(3, np.random.default_rng(0))
    samples = arm.kinematics(q)
    data = arm.model.createData()
    for s in range(3):
        difference = pin.crba(arm.model, data, q[s]) - samples.mass_matrix[s]
        # Entries of order 1e-2 minus themselves: rounding leaves ~1e-17; the armature itself is exact.
        np.testing.assert_allclose(difference, np.diag(reflected), rtol=1e-9, atol=1e-15)


class _FakeActuator:
    """The attributes Arm reads from an Actuator."""

    def __init__(self, reflected_inertia, peak_torque, stiffness, mechanical_stiffness, mass):
        self.reflected_inertia, self.peak_torque, self.mass = reflected_inertia, peak_torque, mass
        self.stiffness, self.mechanical_stiffness = stiffness, mechanical_stiffness


def test_one_actuator_for_all_joints(ur5):
    actuator = _FakeActuator(1e-3, 50.0, 200.0, 1000.0, 0.5)
    arm = ur5.with_actuators(actuator)
    np.testing.assert_array_equal(arm.model.armature, np.full(6, 1e-3))
    np.testing.assert_array_equal(arm.joint_parameters.motor_mass, np.full(6, 0.5))
    with pytest.raises(InvalidParameter, match="one per joint"):
        ur5.with_actuators([actuator, actuator])


def test_sampling_is_reproducible_and_within_limits(panda):
    first = panda.sample_configurations(200, np.random.default_rng(5))
    again = panda.sample_configurations(200, np.random.default_rng(5))
    np.testing.assert_array_equal(first, again)
    lower, upper = panda.joint_limits()
    assert np.all((first >= lower) & (first <= upper))
    with pytest.raises(InvalidParameter, match="Generator"):
        panda.sample_configurations(3, 42)


def test_unknown_frame_lists_the_frames():
    with pytest.raises(FrameNotFound) as caught:
        Arm.from_urdf(TWO_LINK, "gripper")
    assert "gripper" in str(caught.value) and "tip" in caught.value.available
    assert isinstance(caught.value, ValueError)


def test_unknown_locked_joint_lists_the_joints():
    with pytest.raises(FrameNotFound, match="panda_joint1"):
        Arm.from_example_robot_data("panda", locked_joints=["finger"])


@pytest.mark.parametrize(
    "text, reason",
    [
        ('<robot name="x"><link name="a"></robot>', "mismatched tag: line 1"),
        (
            '<robot name="x"><link name="a"/><link name="b"/><joint name="j" type="revolute">'
            '<parent link="a"/><child link="b"/></joint></robot>',
            "does not specify limits",
        ),
    ],
    ids=["malformed-xml", "revolute-without-limits"],
)
def test_bad_urdf_gives_the_parser_reason(tmp_path, text, reason):
    path = tmp_path / "bad.urdf"
    path.write_text(text)
    with pytest.raises(UrdfError) as caught:
        Arm.from_urdf(path, "b")
    assert reason in str(caught.value) and str(path) in str(caught.value)


def test_missing_urdf(tmp_path):
    with pytest.raises(UrdfError, match="no such file"):
        Arm.from_urdf(tmp_path / "none.urdf", "tip")


def test_unbounded_joints_stored_as_cosine_and_sine():
    arm = Arm.from_example_robot_data("double_pendulum_continuous", "link2", [0.0, 0.0, 0.2])
    assert (arm.nq, arm.nv) == (4, 2)
    angles = np.array([[0.3, -1.2], [2.0, 0.5]])
    q = arm.configuration(angles)
    np.testing.assert_allclose(arm.joint_coordinates(q), angles, atol=1e-15)
    samples = arm.kinematics(q)
    model, data = arm.model, arm.model.createData()
    frame = model.getFrameId("link2")
    for s in range(2):
        pin.computeJointJacobians(model, data, q[s])
        pin.updateFramePlacements(model, data)
        jac = pin.getFrameJacobian(model, data, frame, pin.LOCAL_WORLD_ALIGNED)
        offset = data.oMf[frame].rotation @ np.array([0.0, 0.0, 0.2])
        expected = jac[:3] + np.cross(jac[3:].T, offset).T  # the offset point moves with the link
        np.testing.assert_allclose(arm.plane @ samples.jacobian[s], expected, atol=1e-12)


def test_visual_model_of_a_urdf_without_meshes(two_link):
    assert two_link.visual_model().ngeoms == 0


def test_visual_model_resolves_package_meshes():
    ur5 = Arm.from_example_robot_data("ur5")
    assert ur5.visual_model().ngeoms > 0  # meshes found through the package directory
    bare = Arm.from_urdf(ur5.urdf_path, "tool0")  # no package directories: the parser's reason
    with pytest.raises(UrdfError, match="could not be found"):
        bare.visual_model()


@pytest.mark.parametrize(
    "name, nv, task_dim, frame",
    [
        ("ur5", 6, 3, "tool0"),
        ("panda", 7, 3, "panda_hand_tcp"),
        ("double_pendulum", 2, 2, "link2"),
        ("solo12", 12, 3, "FL_FOOT"),
        ("a1", 12, 3, "FL_foot"),
    ],
    ids=["ur5", "panda", "double_pendulum", "solo12", "a1"],
)
def test_example_robots_load_with_default_contacts(name, nv, task_dim, frame):
    arm = Arm.from_example_robot_data(name)  # legged robots: base fixed to the world
    assert (arm.nv, arm.task_dim, arm.contact_frame) == (nv, task_dim, frame)
    samples = arm.kinematics(arm.sample_configurations(2, np.random.default_rng(1)))
    assert np.all(np.isfinite(samples.jacobian)) and np.any(samples.jacobian != 0)


def test_sensing_options_need_one_kind_of_threshold(two_link):
    """Force thresholds must agree and cannot be mixed with joint-side schemes; joint-side ones give torques."""
    from collision_reflex.hardware.actuators import CurrentThreshold, ForceThreshold

    with pytest.raises(InvalidParameter, match="give the threshold explicitly"):
        two_link.sensing_options()  # URDF defaults: no actuator objects
    forced = two_link.with_scaled_motors(0.060, 1.3, sensing=ForceThreshold(4.0))
    assert forced.sensing_options() == {"sensing": "force", "threshold": 4.0}
    uneven = forced.with_actuators(
        [forced.actuators[0], replace(forced.actuators[1], sensing=ForceThreshold(5.0))]
    )
    with pytest.raises(InvalidParameter, match="one contact-force threshold"):
        uneven.sensing_options()
    current = two_link.with_scaled_motors(0.060, 1.3, sensing=CurrentThreshold(0.01))
    mixed = current.with_actuators([forced.actuators[0], current.actuators[1]])
    with pytest.raises(InvalidParameter, match="force thresholds at every joint or at none"):
        mixed.sensing_options()
    options = current.sensing_options()
    assert options["sensing"] == "current"
    expected = [a.gear_ratio * 0.01 for a in current.actuators]  # N tau_s per joint [N m]
    np.testing.assert_allclose(options["joint_threshold"], expected, rtol=1e-12)  # one product: rounding
