"""Kinematics of templates/robots/sawyer.urdf.xacro (Rethink Sawyer) against the facts in
shared/reference/robot-kinematics.md ("Rethink Sawyer") and paper §III-A: joint
origins, limits, efforts and masses, PyBullet forward kinematics against the published standard
DH table, the standard URDF checks, the library part, the floor height, the spoon grip, and a
hold-still check under position control.

Relation between the URDF and the DH table (worked out for this test):

* DH frame 0 is the URDF base frame (`base` = right_arm_base_link's frame): d1 = 0.317 is
  0.08 (right_j0) + 0.237 (right_j1 height), a1 = -0.081 with theta offset pi is right_j1's
  0.081 m forward offset.
* Joint angles: theta_i = q_i + offset_i with the table's offsets [pi, -pi/2, pi, pi, pi, pi, -pi/2].
* The table's frame 7 is the flange `right_hand` turned back by right_j6's published -0.17453 rad
  pitch (a turn about j6's own axis): R_urdf(right_hand) = R_dh Rz(-0.17453).
* d7 = 0.13375 is 0.75 mm shorter than the URDF's 0.11 (j6 origin) + 0.0245 (right_hand) =
  0.1345 along the flange axis, so the table reproduces `right_hand` within 0.75 mm; with d7 =
  0.1345 it reproduces it exactly (3.1416 in right_j6's rpy is the only other difference). Both
  are checked.
"""

from __future__ import annotations

import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pybullet as pb
import pytest
import xacro
import yourdfpy
from frames import body_indices, origin_matrix, rot_z

from assistive_compiler.compile.external_checks import captured_c_output
from assistive_compiler.compile.lint import lint_urdf
from assistive_compiler.library import Library

ROOT = Path(__file__).resolve().parents[2]
TEMPLATE = ROOT / "templates" / "robots" / "sawyer.urdf.xacro"
SPOON_TEMPLATE = ROOT / "templates" / "tools" / "spoon.urdf.xacro"
CHECK_URDF = Path(sys.executable).parent / "check_urdf"
PI = math.pi

ARM_JOINTS = [f"right_j{i}" for i in range(7)]
ARM_LINKS = [f"right_l{i}" for i in range(7)]
FINGER_JOINTS = ["r_gripper_l_finger_joint", "r_gripper_r_finger_joint"]

# (joint, parent, child, xyz, rpy) from the Sawyer table (facts), plus the gripper frames
# (the reference's sawyer.urdf: right_hand -> right_gripper_base +0.025 z -> right_gripper +0.1327 z).
JOINT_ORIGINS = {
    "right_arm_mount": ("base", "right_arm_base_link", (0, 0, 0), (0, 0, 0)),
    "right_j0": ("right_arm_base_link", "right_l0", (0, 0, 0.08), (0, 0, 0)),
    "head_pan": ("right_l0", "head", (0, 0, 0.2965), (0, 0, 0)),
    "right_j1": ("right_l0", "right_l1", (0.081, 0.05, 0.237), (-PI / 2, PI / 2, 0)),
    "right_j2": ("right_l1", "right_l2", (0, -0.14, 0.1425), (PI / 2, 0, 0)),
    "right_j3": ("right_l2", "right_l3", (0, -0.042, 0.26), (-PI / 2, 0, 0)),
    "right_j4": ("right_l3", "right_l4", (0, -0.125, -0.1265), (PI / 2, 0, 0)),
    "right_j5": ("right_l4", "right_l5", (0, 0.031, 0.275), (-PI / 2, 0, 0)),
    "right_j6": ("right_l5", "right_l6", (0, -0.11, 0.1053), (-PI / 2, -0.17453, 3.1416)),
    "right_hand": ("right_l6", "right_hand", (0, 0, 0.0245), (0, 0, PI / 2)),
    "right_gripper_base": ("right_hand", "right_gripper_base", (0, 0, 0.025), (0, 0, 0)),
    "right_endpoint": ("right_gripper_base", "right_gripper", (0, 0, 0.1327), (0, 0, 0)),
}

# joint: (lower, upper, effort, velocity) from the Sawyer table (facts).
LIMITS = {
    "right_j0": (-3.0503, 3.0503, 80, 1.74),
    "head_pan": (-5.0952, 0.9064, 8, 1.8),
    "right_j1": (-3.8095, 2.2736, 80, 1.328),
    "right_j2": (-3.0426, 3.0426, 40, 1.957),
    "right_j3": (-3.0439, 3.0439, 40, 1.957),
    "right_j4": (-2.9761, 2.9761, 9, 3.485),
    "right_j5": (-2.9761, 2.9761, 9, 3.485),
    "right_j6": (-4.7124, 4.7124, 9, 4.545),
}
# The reference's ranges (paper §III-A), rounded there to 3 decimals.
REFERENCE_RANGES = [
    (-3.05, 3.05),
    (-3.818, 2.282),
    (-3.051, 3.051),
    (-3.051, 3.051),
    (-2.984, 2.984),
    (-2.984, 2.984),
    (-4.71, 4.71),
]
REFERENCE_EFFORTS = [80, 80, 40, 40, 9, 9, 9]

# Child masses from the Sawyer table (facts); pedestal 60.864 kg at z -0.5.
LINK_MASSES = {
    "right_arm_base_link": 2.0687,
    "right_l0": 5.3213,
    "head": 1.5795,
    "right_l1": 4.505,
    "right_l2": 1.745,
    "right_l3": 2.5097,
    "right_l4": 1.1136,
    "right_l5": 1.5625,
    "right_l6": 0.3292,
    "pedestal": 60.864,
}
ARM_MASS_LINKS = ["right_arm_base_link"] + ARM_LINKS

# Standard DH (facts): T_i = Rz(theta_i) Tz(d_i) Tx(a_i) Rx(alpha_i).
DH_D = [0.317, 0.1925, 0.4, -0.1685, 0.4, 0.1363, 0.13375]
DH_D_EXACT = DH_D[:6] + [0.11 + 0.0245]
DH_A = [-0.081, 0, 0, 0, 0, 0, 0]
DH_ALPHA = [PI / 2] * 6 + [0.0]
DH_OFFSET = [PI, -PI / 2, PI, PI, PI, PI, -PI / 2]
J6_PITCH = -0.17453

BASE_HEIGHT = 0.975  # the reference's load height (paper §III-A)
SPOON_HANDLE_END = "spoon_handle_end"


# --------------------------------------------------------------------------------------------
# helpers


def dh_fk(q, d) -> np.ndarray:
    """Flange pose in the base frame according to the standard DH table."""
    t = np.eye(4)
    for qi, di, ai, alpha, off in zip(q, d, DH_A, DH_ALPHA, DH_OFFSET):
        th = qi + off
        ct, st = math.cos(th), math.sin(th)
        ca, sa = math.cos(alpha), math.sin(alpha)
        t = t @ np.array(
            [
                [ct, -st * ca, st * sa, ai * ct],
                [st, ct * ca, -ct * sa, ai * st],
                [0.0, sa, ca, di],
                [0.0, 0.0, 0.0, 1.0],
            ]
        )
    fix = np.eye(4)
    fix[:3, :3] = rot_z(J6_PITCH)
    return t @ fix


def random_configs(n=30, seed=0):
    """Seeded arm configurations within the joint limits."""
    rng = np.random.default_rng(seed)
    lo = [LIMITS[j][0] for j in ARM_JOINTS]
    hi = [LIMITS[j][1] for j in ARM_JOINTS]
    return [rng.uniform(lo, hi) for _ in range(n)]


# --------------------------------------------------------------------------------------------
# fixtures


@pytest.fixture(scope="module")
def bullet(urdf_path):
    """(client, body, joint index by joint name, link index by link name, load output)."""
    cid = pb.connect(pb.DIRECT)
    # Loaded at the origin with identity orientation: world frame == URDF base frame.
    with captured_c_output() as out:
        body = pb.loadURDF(str(urdf_path), [0, 0, 0], [0, 0, 0, 1], useFixedBase=True, physicsClientId=cid)
    joints, links = body_indices(cid, body)
    yield cid, body, joints, links, out[0]
    pb.disconnect(cid)


def set_arm(bullet, q) -> None:
    cid, body, joints, _, _ = bullet
    for name, v in zip(ARM_JOINTS, q):
        pb.resetJointState(body, joints[name], float(v), physicsClientId=cid)


def link_pose(bullet, link: str) -> np.ndarray:
    cid, body, _, links, _ = bullet
    ls = pb.getLinkState(body, links[link], computeForwardKinematics=True, physicsClientId=cid)
    t = np.eye(4)
    t[:3, :3] = np.array(pb.getMatrixFromQuaternion(ls[5])).reshape(3, 3)
    t[:3, 3] = ls[4]
    return t


# --------------------------------------------------------------------------------------------
# structure and facts


def test_names_and_tree(model):
    assert model.base_link == "base"
    for name, (parent, child, _, _) in JOINT_ORIGINS.items():
        j = model.joint_map[name]
        assert (j.parent, j.child) == (parent, child), name
    for name in ARM_JOINTS + ["head_pan"]:
        assert model.joint_map[name].type == "revolute"
        np.testing.assert_allclose(model.joint_map[name].axis, [0, 0, 1])
    for name in ("right_arm_mount", "right_hand", "right_gripper_base", "right_endpoint"):
        assert model.joint_map[name].type == "fixed"
    # Two prismatic fingers on the tool mount, opening outwards along its y.
    for name, axis in zip(FINGER_JOINTS, ([0, 1, 0], [0, -1, 0])):
        j = model.joint_map[name]
        assert j.type == "prismatic" and j.parent == "right_gripper_base"
        np.testing.assert_allclose(j.axis, axis)
    # Every movable joint is an arm joint, head_pan or a finger.
    movable = {n for n, j in model.joint_map.items() if j.type != "fixed"}
    assert movable == set(ARM_JOINTS) | {"head_pan"} | set(FINGER_JOINTS)


def test_joint_origins_exact(model):
    for name, (_, _, xyz, rpy) in JOINT_ORIGINS.items():
        np.testing.assert_allclose(model.joint_map[name].origin, origin_matrix(xyz, rpy), atol=1e-9, err_msg=name)
    for name, y in zip(FINGER_JOINTS, (-0.0015, 0.0015)):
        np.testing.assert_allclose(
            model.joint_map[name].origin, origin_matrix((0, y, 0.02), (0, 0, 0)), atol=1e-12, err_msg=name
        )


def test_joint_limits_efforts_velocities(model):
    for name, (lo, hi, effort, vel) in LIMITS.items():
        lim = model.joint_map[name].limit
        assert (lim.lower, lim.upper) == pytest.approx((lo, hi), abs=1e-9), name
        assert (lim.effort, lim.velocity) == pytest.approx((effort, vel), abs=1e-9), name
    # Within 0.01 rad of the reference's (slightly different) ranges, same efforts.
    for name, (lo, hi), effort in zip(ARM_JOINTS, REFERENCE_RANGES, REFERENCE_EFFORTS):
        lim = model.joint_map[name].limit
        assert abs(lim.lower - lo) < 0.01 and abs(lim.upper - hi) < 0.01, name
        assert lim.effort == effort
    for name in FINGER_JOINTS:
        lim = model.joint_map[name].limit
        assert (lim.lower, lim.upper) == pytest.approx((0.0, 0.020833))
        assert lim.effort > 0 and lim.velocity > 0


def test_link_masses(model):
    for name, mass in LINK_MASSES.items():
        assert model.link_map[name].inertial.mass == pytest.approx(mass, abs=1e-9), name
    np.testing.assert_allclose(model.link_map["pedestal"].inertial.origin[:3, 3], [0, 0, -0.5])
    arm = sum(model.link_map[n].inertial.mass for n in ARM_MASS_LINKS)
    assert arm == pytest.approx(19.16, abs=0.01)  # facts: base_link ... l6 = 19.16 kg
    gripper = sum(
        model.link_map[n].inertial.mass for n in ("right_gripper_base", "r_gripper_l_finger", "r_gripper_r_finger")
    )
    assert gripper == pytest.approx(0.36, abs=1e-9)  # 0.3 body + 2 x (0.02 finger + 0.01 tip)
    total = sum(link.inertial.mass for link in model.robot.links)
    assert total == pytest.approx(60.864 + 19.155 + 1.5795 + 0.36, abs=0.01)


def test_collision_shapes_follow_upstream(model):
    """A sample of the upstream primitive collision shapes, in their links' frames."""

    def shapes(link):
        out = []
        for c in model.link_map[link].collisions:
            g = c.geometry
            xyz = tuple(np.round(c.origin[:3, 3], 6))
            if g.sphere is not None:
                out.append(("sphere", g.sphere.radius, xyz))
            elif g.cylinder is not None:
                out.append(("cylinder", g.cylinder.radius, g.cylinder.length, xyz))
            else:
                out.append(("box", tuple(g.box.size), xyz))
        return out

    assert ("cylinder", 0.08, 0.24, (0, 0, 0.12)) in shapes("right_arm_base_link")
    assert ("sphere", 0.07, (0.08, 0, 0.23)) in shapes("right_l0")
    assert ("sphere", 0.18, (0, 0, 0.08)) in shapes("head")
    assert ("cylinder", 0.07, 0.14, (0, 0, 0.035)) in shapes("right_l1")
    assert ("cylinder", 0.06, 0.34, (0, 0, 0.08)) in shapes("right_l2")
    assert ("sphere", 0.06, (0, 0, 0.26)) in shapes("right_l2")
    assert ("sphere", 0.06, (0, -0.01, -0.12)) in shapes("right_l3")
    assert ("cylinder", 0.045, 0.30, (0, 0, 0.11)) in shapes("right_l4")
    assert ("sphere", 0.06, (0, 0.01, 0.26)) in shapes("right_l4")
    assert ("sphere", 0.06, (0, 0, 0.1)) in shapes("right_l5")
    assert ("cylinder", 0.055, 0.05, (0, 0.015, -0.01)) in shapes("right_l6")
    assert ("cylinder", 0.035, 0.03, (0, 0, 0.02)) in shapes("right_hand")
    assert ("cylinder", 0.18, 0.62, (-0.02, 0, -0.29)) in shapes("pedestal")
    assert ("box", (0.22, 0.40, 0.53), (-0.325, 0, -0.38)) in shapes("pedestal")


# --------------------------------------------------------------------------------------------
# forward kinematics


def test_fk_matches_dh_table_within_2mm(bullet):
    worst_p, worst_r = 0.0, 0.0
    for q in random_configs():
        set_arm(bullet, q)
        t_pb = link_pose(bullet, "right_hand")
        t_dh = dh_fk(q, DH_D)
        worst_p = max(worst_p, float(np.linalg.norm(t_pb[:3, 3] - t_dh[:3, 3])))
        worst_r = max(worst_r, float(np.abs(t_pb[:3, :3] - t_dh[:3, :3]).max()))
    assert worst_p < 0.002
    assert worst_p < 0.0008  # the table's d7 is 0.75 mm short of the flange (module docstring)
    assert worst_r < 1e-4


def test_fk_matches_dh_exactly_with_flange_d7(bullet):
    worst_p, worst_r = 0.0, 0.0
    for q in random_configs(seed=1):
        set_arm(bullet, q)
        t_pb = link_pose(bullet, "right_hand")
        t_dh = dh_fk(q, DH_D_EXACT)
        worst_p = max(worst_p, float(np.linalg.norm(t_pb[:3, 3] - t_dh[:3, 3])))
        worst_r = max(worst_r, float(np.abs(t_pb[:3, :3] - t_dh[:3, :3]).max()))
    assert worst_p < 1e-4
    assert worst_r < 1e-4


def test_tool_mount_and_end_effector_on_the_approach_axis(bullet):
    for q in random_configs(n=5, seed=2):
        set_arm(bullet, q)
        hand = link_pose(bullet, "right_hand")
        mount = link_pose(bullet, "right_gripper_base")
        ee = link_pose(bullet, "right_gripper")
        np.testing.assert_allclose(mount, hand @ origin_matrix((0, 0, 0.025), (0, 0, 0)), atol=1e-6)
        np.testing.assert_allclose(ee, hand @ origin_matrix((0, 0, 0.025 + 0.1327), (0, 0, 0)), atol=1e-6)


# --------------------------------------------------------------------------------------------
# standard URDF checks, library part


def test_check_urdf_passes(urdf_path):
    res = subprocess.run([str(CHECK_URDF), str(urdf_path)], capture_output=True, text=True, timeout=30)
    assert res.returncode == 0, res.stdout + res.stderr
    assert "Successfully Parsed XML" in res.stdout


def test_pybullet_loads_without_warnings(bullet):
    _, body, joints, _, text = bullet
    assert body >= 0
    assert "warning" not in text.lower(), text
    assert "error" not in text.lower(), text
    assert len(joints) == 15


def test_yourdfpy_validates(model):
    assert model.validate()


def test_lint_clean(urdf_text):
    assert lint_urdf(urdf_text, template="robots/sawyer.urdf.xacro") == []


def test_library_part():
    loaded = Library().get("robots", "sawyer")
    part = loaded.part
    assert part.title == "Sawyer" and part.base_link == "base"
    arm = part.arms["right"]
    assert arm.joints == ARM_JOINTS
    assert (arm.end_effector, arm.tool_mount) == ("right_gripper", "right_gripper_base")
    assert part.gripper["right"].joints == FINGER_JOINTS
    assert {k: part.gripper["right"].positions[k] for k in ("spoon", "none")} == {
        "spoon": 0.0,
        "none": 0.0,
    }  # facts: feeding 0
    assert not part.mountable
    assert part.base_height_m == BASE_HEIGHT


def test_stands_on_the_floor_at_the_reference_height(urdf_path):
    """Loaded with `base` at z 0.975 (the reference's load height), the pedestal's lowest
    point is on the floor, and right_j1 (the shoulder) is 0.975 + 0.317 m up."""
    cid = pb.connect(pb.DIRECT)
    try:
        body = pb.loadURDF(str(urdf_path), [0, 0, BASE_HEIGHT], [0, 0, 0, 1], useFixedBase=True, physicsClientId=cid)
        pb.performCollisionDetection(physicsClientId=cid)
        n = pb.getNumJoints(body, physicsClientId=cid)
        lowest = min(pb.getAABB(body, j, physicsClientId=cid)[0][2] for j in range(-1, n))
        # PyBullet pads AABBs by its collision margin (about 1 mm).
        assert -0.003 < lowest <= 0.0
        names = {pb.getJointInfo(body, j, physicsClientId=cid)[12].decode(): j for j in range(n)}
        l1 = pb.getLinkState(body, names["right_l1"], physicsClientId=cid)[4]
        assert l1[2] == pytest.approx(BASE_HEIGHT + 0.317, abs=1e-6)
    finally:
        pb.disconnect(cid)


# --------------------------------------------------------------------------------------------
# spoon grip


def test_spoon_grip_centres_the_handle_end_between_the_fingertips(bullet, tmp_path):
    part = Library().get("robots", "sawyer").part
    grip = part.grips["spoon"]
    spoon_path = tmp_path / "spoon.urdf"
    spoon_path.write_text(xacro.process_file(str(SPOON_TEMPLATE), mappings={}).toprettyxml())
    spoon = yourdfpy.URDF.load(str(spoon_path), build_scene_graph=True, load_meshes=False)
    handle_end = spoon.get_transform(SPOON_HANDLE_END, "spoon")[:3, 3]

    cid, body, joints, _, _ = bullet
    set_arm(bullet, random_configs(n=1, seed=3)[0])
    for name in FINGER_JOINTS:  # the feeding grip
        pb.resetJointState(body, joints[name], part.gripper["right"].positions["spoon"], physicsClientId=cid)
    mount = link_pose(bullet, "right_gripper_base")
    t_spoon = mount @ origin_matrix(grip.position_m, grip.rpy_rad)
    end_world = (t_spoon @ np.append(handle_end, 1.0))[:3]

    # Fingertip paddle centres: 0.0977 m along each finger frame's z, 0.01275 m inwards of it.
    pads = []
    for name, s in (("r_gripper_l_finger", 1), ("r_gripper_r_finger", -1)):
        pads.append((link_pose(bullet, name) @ np.array([0, 0.01275 * s, 0.0977, 1.0]))[:3])
    mid = (pads[0] + pads[1]) / 2
    assert np.linalg.norm(end_world - mid) < 0.002

    approach = mount[:3, 2]  # out of the hand
    closing = pads[0] - pads[1]  # the fingers close along this line
    closing /= np.linalg.norm(closing)
    np.testing.assert_allclose(t_spoon[:3, 1], approach, atol=1e-6)  # spoon +y along approach
    assert abs(float(t_spoon[:3, 2] @ closing)) < 1e-6  # bowl opening ⟂ closing
    # The 12 mm handle fits between the closed paddles (16 mm apart).
    assert np.linalg.norm(pads[0] - pads[1]) - 0.0065 == pytest.approx(0.016, abs=1e-6)


# --------------------------------------------------------------------------------------------
# physics


def test_position_control_holds_a_random_pose(urdf_path):
    cid = pb.connect(pb.DIRECT)
    try:
        body = pb.loadURDF(
            str(urdf_path),
            [0, 0, BASE_HEIGHT],
            [0, 0, 0, 1],
            useFixedBase=True,
            flags=pb.URDF_USE_INERTIA_FROM_FILE,
            physicsClientId=cid,
        )
        pb.setGravity(0, 0, 0, physicsClientId=cid)
        idx = {
            pb.getJointInfo(body, j, physicsClientId=cid)[1].decode(): j
            for j in range(pb.getNumJoints(body, physicsClientId=cid))
        }
        ee = idx["right_endpoint"]  # joint index == child link index (right_gripper)
        arm = [idx[j] for j in ARM_JOINTS]
        q = random_configs(n=1, seed=4)[0]
        for i, v in zip(arm, q):
            pb.resetJointState(body, i, float(v), physicsClientId=cid)
        start = np.array(pb.getLinkState(body, ee, computeForwardKinematics=True, physicsClientId=cid)[4])
        pb.setJointMotorControlArray(
            body,
            arm,
            pb.POSITION_CONTROL,
            targetPositions=list(q),
            forces=[LIMITS[j][2] for j in ARM_JOINTS],
            physicsClientId=cid,
        )
        for _ in range(50):
            pb.stepSimulation(physicsClientId=cid)
        end = np.array(pb.getLinkState(body, ee, computeForwardKinematics=True, physicsClientId=cid)[4])
        assert np.linalg.norm(end - start) < 0.001
        # Stricter: with gravity on, the motors still hold the arm (and the fingers' default
        # velocity motors hold them) within 1 mm over another 50 steps.
        pb.setGravity(0, 0, -9.81, physicsClientId=cid)
        for _ in range(50):
            pb.stepSimulation(physicsClientId=cid)
        sagged = np.array(pb.getLinkState(body, ee, computeForwardKinematics=True, physicsClientId=cid)[4])
        assert np.linalg.norm(sagged - start) < 0.001
    finally:
        pb.disconnect(cid)
