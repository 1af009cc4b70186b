"""Kinematics of templates/robots/baxter.urdf.xacro (Rethink Baxter) against the facts in
shared/reference/robot-kinematics-more.md §3: joint origins, limits, masses and centres of mass,
PyBullet forward kinematics against two independent formulations written from the published
numbers, the reference's own FK checkpoints, the standard-URDF checks, the library part
(specs/robots/baxter.yaml) and its spoon grip, and a position-hold check.

Independent formulations used for FK (neither re-reads the URDF):

* the product of the published joint transforms (§3.1, §3.3, §3.4 tables, typed in below);
* a standard Denavit-Hartenberg chain built from the same lengths, in the s0 joint frame at
  q = 0 (the arm mount translated by (0.055695, 0, 0.011038)):

      i   theta        d                                   a       alpha
      1   q1           0.27035                             0.069   -pi/2
      2   q2 + pi/2    0                                   0        pi/2
      3   q3           0.102 + 0.26242                     0.069   -pi/2
      4   q4           0                                   0        pi/2
      5   q5           0.10359 + 0.2707                    0.010   -pi/2
      6   q6           0                                   0        pi/2
      7   q7           0.115975 + 0.11355 + 0.025 + 0.1327 0        0

  Its frame 7 coincides with the `*_gripper` endpoint (same orientation), which the test checks.
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
TEMPLATE = ROOT / "templates" / "robots" / "baxter.urdf.xacro"
SPOON = ROOT / "templates" / "tools" / "spoon.urdf.xacro"
CHECK_URDF = Path(sys.executable).parent / "check_urdf"
PI = math.pi
HALF = 1.57079632679  # the literal the source file writes for pi/2

SIDES = ("right", "left")
ARM_SUFFIXES = ("s0", "s1", "e0", "e1", "w0", "w1", "w2")
ARM_JOINTS = {side: [f"{side}_{s}" for s in ARM_SUFFIXES] for side in SIDES}
FINGER_PREFIX = {"right": "r", "left": "l"}


def side_sign(side: str) -> int:
    return -1 if side == "right" else 1


# Published chain (§3.3 / §3.4): joint -> (xyz, rpy) in the parent link frame. The only
# left/right difference is the mount (y and yaw mirrored).
def arm_chain(side: str) -> list[tuple[str, tuple, tuple]]:
    s = side_sign(side)
    return [
        (f"{side}_torso_arm_mount", (0.024645, s * 0.219645, 0.118588), (0, 0, s * 0.7854)),
        (f"{side}_s0", (0.055695, 0, 0.011038), (0, 0, 0)),
        (f"{side}_s1", (0.069, 0, 0.27035), (-HALF, 0, 0)),
        (f"{side}_e0", (0.102, 0, 0), (HALF, 0, HALF)),
        (f"{side}_e1", (0.069, 0, 0.26242), (-HALF, -HALF, 0)),
        (f"{side}_w0", (0.10359, 0, 0), (HALF, 0, HALF)),
        (f"{side}_w1", (0.01, 0, 0.2707), (-HALF, -HALF, 0)),
        (f"{side}_w2", (0.115975, 0, 0), (HALF, 0, HALF)),
        (f"{side}_hand", (0, 0, 0.11355), (0, 0, 0)),  # ERD right_hand_joint
        (f"{side}_gripper_base", (0, 0, 0.025), (0, 0, 0)),  # ERD right_gripper_base_joint
        (f"{side}_endpoint", (0, 0, 0.1327), (0, 0, 0)),
    ]


OTHER_ORIGINS = {
    "torso_t0": ((0, 0, 0), (0, 0, 0)),
    "pedestal_fixed": ((0, 0, 0), (0, 0, 0)),
    "head_pan": ((0.06, 0, 0.686), (0, 0, 0)),
    "r_gripper_l_finger_joint": ((0, -0.0015, 0.02), (0, 0, 0)),
    "r_gripper_r_finger_joint": ((0, 0.0015, 0.02), (0, 0, 0)),
    "l_gripper_l_finger_joint": ((0, -0.0015, 0.02), (0, 0, 0)),
    "l_gripper_r_finger_joint": ((0, 0.0015, 0.02), (0, 0, 0)),
}

# (lower, upper, effort, velocity) from §3.3 (left identical).
ARM_LIMITS = {
    "s0": (-1.70167993878, 1.70167993878, 50, 1.5),
    "s1": (-2.147, 1.047, 50, 1.5),
    "e0": (-3.05417993878, 3.05417993878, 50, 1.5),
    "e1": (-0.05, 2.618, 50, 1.5),
    "w0": (-3.059, 3.059, 15, 4),
    "w1": (-1.57079632679, 2.094, 15, 4),
    "w2": (-3.059, 3.059, 15, 4),
}
OTHER_LIMITS = {
    "head_pan": (-1.3963, 1.3963, 50000, 10000),
    "r_gripper_l_finger_joint": (0.0, 0.020833, 20, 5),
    "r_gripper_r_finger_joint": (-0.020833, 0.0, 20, 5),
    "l_gripper_l_finger_joint": (0.0, 0.020833, 20, 5),
    "l_gripper_r_finger_joint": (-0.020833, 0.0, 20, 5),
}

# link suffix -> (mass, COM) from §3.3.
ARM_INERTIA = {
    "upper_shoulder": (5.70044, (0.01783, 0.00086, 0.19127)),
    "lower_shoulder": (3.22698, (0.06845, 0.00269, -0.00529)),
    "upper_elbow": (4.31272, (-0.00276, 0.00132, 0.18086)),
    "lower_elbow": (2.07206, (0.02611, 0.00159, -0.01117)),
    "upper_forearm": (2.24665, (-0.00168, 0.0046, 0.13952)),
    "lower_forearm": (1.60979, (0.06041, 0.00697, 0.006)),
    "wrist": (0.35093, (0.00198, 0.00125, 0.01855)),
    "hand": (0.19125, (0.01093, 0.00042, -0.01532)),
    "gripper_base": (0.3, (0, 0, 0)),
}

# DH (see the module docstring).
DH_D = [0.27035, 0.0, 0.102 + 0.26242, 0.0, 0.10359 + 0.2707, 0.0, 0.115975 + 0.11355 + 0.025 + 0.1327]
DH_A = [0.069, 0.0, 0.069, 0.0, 0.010, 0.0, 0.0]
DH_ALPHA = [-PI / 2, PI / 2, -PI / 2, PI / 2, -PI / 2, PI / 2, 0.0]
DH_THETA0 = [0.0, PI / 2, 0.0, 0.0, 0.0, 0.0, 0.0]

TUCKED = {"right": [-0.75, 1, -0.5, 0.5, -1, -0.5, 0], "left": [0.75, 1, 0.5, 0.5, 1, -0.5, 0]}


# --------------------------------------------------------------------------------------------
# numpy helpers


def chain_fk(side: str, q) -> np.ndarray:
    """`<side>_gripper` in `base` by the product of the published joint transforms."""
    t = np.eye(4)
    qs = iter(q)
    for name, xyz, rpy in arm_chain(side):
        t = t @ origin_matrix(xyz, rpy)
        if name.split("_", 1)[1] in ARM_SUFFIXES:
            joint = np.eye(4)
            joint[:3, :3] = rot_z(next(qs))
            t = t @ joint
    return t


def dh_fk(side: str, q) -> np.ndarray:
    """`<side>_gripper` in `base` by the DH chain (standard convention)."""
    s = side_sign(side)
    t = origin_matrix((0.024645, s * 0.219645, 0.118588), (0, 0, s * 0.7854))
    t = t @ origin_matrix((0.055695, 0, 0.011038), (0, 0, 0))
    for th0, qi, d, a, alpha in zip(DH_THETA0, q, DH_D, DH_A, DH_ALPHA):
        th = th0 + qi
        ct, st, ca, sa = math.cos(th), math.sin(th), math.cos(alpha), math.sin(alpha)
        t = t @ np.array(
            [[ct, -st * ca, st * sa, a * ct], [st, ct * ca, -ct * sa, a * st], [0.0, sa, ca, d], [0.0, 0.0, 0.0, 1.0]]
        )
    return t


# --------------------------------------------------------------------------------------------
# fixtures


@pytest.fixture(scope="module")
def bullet(urdf_path):
    """(client, body, joint index by name, link index by name, text printed while loading).
    Loaded at the origin, identity orientation: world frame == `base`."""
    cid = pb.connect(pb.DIRECT)
    with captured_c_output() as out:
        body = pb.loadURDF(str(urdf_path), [0, 0, 0], [0, 0, 0, 1], useFixedBase=True, physicsClientId=cid)
    joints, links = body_indices(cid, body)
    yield cid, body, joints, links, out[0]
    pb.disconnect(cid)


def set_arm(bullet, side, q):
    cid, body, joints, _, _ = bullet
    for name, v in zip(ARM_JOINTS[side], q):
        pb.resetJointState(body, joints[name], float(v), physicsClientId=cid)


def link_pose(bullet, link) -> np.ndarray:
    cid, body, _, links, _ = bullet
    ls = pb.getLinkState(body, links[link], computeForwardKinematics=True, physicsClientId=cid)
    t = np.eye(4)
    t[:3, :3] = np.array(pb.getMatrixFromQuaternion(ls[5])).reshape(3, 3)
    t[:3, 3] = ls[4]
    return t


def random_configs(n=30, seed=0):
    rng = np.random.default_rng(seed)
    lo = [ARM_LIMITS[s][0] for s in ARM_SUFFIXES]
    hi = [ARM_LIMITS[s][1] for s in ARM_SUFFIXES]
    return [rng.uniform(lo, hi) for _ in range(n)]


# --------------------------------------------------------------------------------------------
# structure, origins, limits, masses


def test_names_and_tree(model):
    assert model.base_link == "base"
    for side in SIDES:
        p = FINGER_PREFIX[side]
        for name in ARM_JOINTS[side]:
            j = model.joint_map[name]
            assert j.type == "revolute"
            np.testing.assert_allclose(j.axis, [0, 0, 1])
        for name in (f"{side}_torso_arm_mount", f"{side}_hand", f"{side}_gripper_base", f"{side}_endpoint"):
            assert model.joint_map[name].type == "fixed"
        assert model.joint_map[f"{side}_endpoint"].child == f"{side}_gripper"
        assert model.joint_map[f"{side}_gripper_base"].child == f"{side}_gripper_base"
        for finger in ("l", "r"):
            j = model.joint_map[f"{p}_gripper_{finger}_finger_joint"]
            assert j.type == "prismatic" and j.parent == f"{side}_gripper_base"
            np.testing.assert_allclose(j.axis, [0, 1, 0])
    assert model.joint_map["head_pan"].type == "revolute"
    assert model.joint_map["head_pan"].parent == "torso"
    # Modest link count: body 4 + 13 per arm.
    assert len(model.robot.links) == 30


def test_joint_origins_exact(model):
    expected = dict(OTHER_ORIGINS)
    for side in SIDES:
        expected |= {name: (xyz, rpy) for name, xyz, rpy in arm_chain(side)}
    for name, (xyz, rpy) in expected.items():
        np.testing.assert_allclose(model.joint_map[name].origin, origin_matrix(xyz, rpy), atol=1e-9, err_msg=name)


def test_joint_limits(model):
    expected = dict(OTHER_LIMITS)
    for side in SIDES:
        expected |= {f"{side}_{s}": v for s, v in ARM_LIMITS.items()}
    for name, (lo, hi, effort, velocity) in expected.items():
        lim = model.joint_map[name].limit
        assert (lim.lower, lim.upper) == pytest.approx((lo, hi), abs=1e-12), name
        assert (lim.effort, lim.velocity) == pytest.approx((effort, velocity)), name


def test_link_masses_and_coms(model):
    for side in SIDES:
        for suffix, (mass, com) in ARM_INERTIA.items():
            inertial = model.link_map[f"{side}_{suffix}"].inertial
            assert inertial.mass == pytest.approx(mass, abs=1e-9), suffix
            np.testing.assert_allclose(inertial.origin[:3, 3], com, atol=1e-9, err_msg=suffix)
            np.testing.assert_allclose(inertial.origin[:3, :3], np.eye(3), atol=1e-12)
        # Finger 0.02 kg at its origin + fingertip 0.01 kg at (0, +-0.01725, 0.1127).
        for finger, f in (("l", 1), ("r", -1)):
            inertial = model.link_map[f"{FINGER_PREFIX[side]}_gripper_{finger}_finger"].inertial
            assert inertial.mass == pytest.approx(0.03, abs=1e-12)
            np.testing.assert_allclose(inertial.origin[:3, 3], [0, f * 0.01725 / 3, 0.1127 / 3], atol=1e-9)
    assert model.link_map["torso"].inertial.mass == pytest.approx(35.336455, abs=1e-9)
    assert model.link_map["pedestal"].inertial.mass == pytest.approx(60.86397744, abs=1e-9)
    # Head 0.547767 at (0, 0, 0) + screen 0.440171 at the head_nod origin (0.1227, 0, 0).
    head = model.link_map["head"].inertial
    assert head.mass == pytest.approx(0.547767 + 0.440171, abs=1e-9)
    np.testing.assert_allclose(head.origin[:3, 3], [0.1227 * 0.440171 / 0.987938, 0, 0], atol=1e-9)


def _subtree_mass(model, link: str) -> float:
    total = model.link_map[link].inertial.mass
    for j in model.robot.joints:
        if j.parent == link:
            total += _subtree_mass(model, j.child)
    return total


def test_masses_vs_facts(model):
    total = sum(link.inertial.mass for link in model.robot.links)
    # Facts §3.2: 137.333 kg, of which ~0.0025 kg are 0.0001 kg frames this model leaves out.
    assert total == pytest.approx(137.333, abs=0.005)
    for side in SIDES:
        assert _subtree_mass(model, f"{side}_upper_shoulder") == pytest.approx(20.072, abs=0.002)
        assert _subtree_mass(model, f"{side}_hand") == pytest.approx(0.552, abs=0.001)


# --------------------------------------------------------------------------------------------
# forward kinematics


@pytest.mark.parametrize("side", SIDES)
def test_fk_matches_published_chain(bullet, side):
    worst_p, worst_r = 0.0, 0.0
    for q in random_configs(seed=1 if side == "right" else 2):
        set_arm(bullet, side, q)
        t_pb = link_pose(bullet, f"{side}_gripper")
        t_ref = chain_fk(side, q)
        worst_p = max(worst_p, float(np.linalg.norm(t_pb[:3, 3] - t_ref[:3, 3])))
        worst_r = max(worst_r, float(np.abs(t_pb[:3, :3] - t_ref[:3, :3]).max()))
    set_arm(bullet, side, [0] * 7)
    assert worst_p < 1e-4  # requirement: 3 mm
    assert worst_r < 1e-4


@pytest.mark.parametrize("side", SIDES)
def test_fk_matches_dh(bullet, side):
    worst_p, worst_r = 0.0, 0.0
    for q in random_configs(seed=3 if side == "right" else 4):
        set_arm(bullet, side, q)
        t_pb = link_pose(bullet, f"{side}_gripper")
        t_dh = dh_fk(side, q)
        worst_p = max(worst_p, float(np.linalg.norm(t_pb[:3, 3] - t_dh[:3, 3])))
        worst_r = max(worst_r, float(np.abs(t_pb[:3, :3] - t_dh[:3, :3]).max()))
    set_arm(bullet, side, [0] * 7)
    assert worst_p < 0.003
    assert worst_r < 1e-3


def test_fk_reference_checkpoints(bullet):
    # q = 0: joint origins in `base` from the facts' last column, and the endpoint.
    at_zero = {
        "s0": (0.064, 0.259, 0.1296),
        "s1": (0.1128, 0.3078, 0.4),
        "e0": (0.1849, 0.3799, 0.4),
        "e1": (0.3705, 0.5655, 0.331),
        "w0": (0.4437, 0.6388, 0.331),
        "w1": (0.6352, 0.8302, 0.321),
        "w2": (0.7172, 0.9122, 0.321),
    }
    child = {
        "s0": "upper_shoulder",
        "s1": "lower_shoulder",
        "e0": "upper_elbow",
        "e1": "lower_elbow",
        "w0": "upper_forearm",
        "w1": "lower_forearm",
        "w2": "wrist",
    }
    for side in SIDES:
        s = side_sign(side)
        set_arm(bullet, side, [0] * 7)
        for j, (x, y, z) in at_zero.items():
            np.testing.assert_allclose(link_pose(bullet, f"{side}_{child[j]}")[:3, 3], [x, s * y, z], atol=1e-4)
        np.testing.assert_allclose(link_pose(bullet, f"{side}_hand")[:3, 3], [0.7975, s * 0.9925, 0.321], atol=1e-4)
        np.testing.assert_allclose(
            link_pose(bullet, f"{side}_gripper_base")[:3, 3], [0.8151, s * 1.0101, 0.321], atol=1e-4
        )
        np.testing.assert_allclose(link_pose(bullet, f"{side}_gripper")[:3, 3], [0.909, s * 1.104, 0.321], atol=1e-3)
    # The reference's tucked pose puts right_gripper at (0.048, -0.587, -0.666) in `base`.
    set_arm(bullet, "right", TUCKED["right"])
    np.testing.assert_allclose(link_pose(bullet, "right_gripper")[:3, 3], [0.048, -0.587, -0.666], atol=1e-3)
    # ... and the left arm mirrors it.
    set_arm(bullet, "left", TUCKED["left"])
    np.testing.assert_allclose(link_pose(bullet, "left_gripper")[:3, 3], [0.048, 0.587, -0.666], atol=1e-3)
    for side in SIDES:
        set_arm(bullet, side, [0] * 7)


def test_reach_matches_facts(bullet):
    """The facts' maximum s0 -> endpoint distance (1.4116 m, §3.7): random configurations never
    exceed it and a seeded hill climb from the best of them gets within 5 mm of it."""
    rng = np.random.default_rng(5)
    lo = np.array([ARM_LIMITS[s][0] for s in ARM_SUFFIXES])
    hi = np.array([ARM_LIMITS[s][1] for s in ARM_SUFFIXES])

    def reach(q):
        set_arm(bullet, "right", q)
        return float(
            np.linalg.norm(link_pose(bullet, "right_gripper")[:3, 3] - link_pose(bullet, "right_upper_shoulder")[:3, 3])
        )

    samples = [rng.uniform(lo, hi) for _ in range(300)]
    dists = [reach(q) for q in samples]
    assert max(dists) <= 1.4116 + 1e-4
    best_q, best = samples[int(np.argmax(dists))], max(dists)
    for step in np.geomspace(0.5, 0.002, 400):
        q = np.clip(best_q + rng.normal(0, step, 7), lo, hi)
        d = reach(q)
        if d > best:
            best_q, best = q, d
    set_arm(bullet, "right", [0] * 7)
    assert 1.4116 - 0.005 < best <= 1.4116 + 1e-4


def test_head_pan_turns_the_screen(bullet):
    cid, body, joints, _, _ = bullet
    before = link_pose(bullet, "head")
    np.testing.assert_allclose(before[:3, 3], [0.06, 0, 0.686], atol=1e-9)
    pb.resetJointState(body, joints["head_pan"], 1.0, physicsClientId=cid)
    after = link_pose(bullet, "head")
    np.testing.assert_allclose(after[:3, :3], rot_z(1.0), atol=1e-6)
    pb.resetJointState(body, joints["head_pan"], 0.0, physicsClientId=cid)


# --------------------------------------------------------------------------------------------
# standard URDF checks


def test_check_urdf(urdf_path):
    res = subprocess.run([str(CHECK_URDF), str(urdf_path)], capture_output=True, text=True, timeout=30)
    assert res.returncode == 0, res.stdout + res.stderr
    assert "Successfully Parsed XML" in res.stdout


def test_yourdfpy_validates(model):
    assert model.validate()


def test_pybullet_loads_without_warnings(bullet):
    text = bullet[4]
    assert bullet[1] >= 0
    assert "warning" not in text.lower(), text
    assert "error" not in text.lower(), text


def test_lint_clean(urdf_text):
    assert lint_urdf(urdf_text, template="robots/baxter.urdf.xacro") == []


def test_primitives_and_valid_inertias(model):
    for link in model.robot.links:
        assert link.inertial.mass > 0
        ev = np.linalg.eigvalsh(link.inertial.inertia)
        assert ev.min() > 0 and ev[0] + ev[1] >= ev[2] * (1 - 1e-9), link.name
        for shape in list(link.collisions) + list(link.visuals):
            g = shape.geometry
            assert g.mesh is None and (g.box or g.cylinder or g.sphere), link.name


# --------------------------------------------------------------------------------------------
# library part


@pytest.fixture(scope="module")
def part():
    return Library().get("robots", "baxter").part


def test_library_part(part):
    assert part.title == "Baxter" and part.base_link == "base" and not part.mountable
    for side in SIDES:
        arm = part.arms[side]
        assert arm.joints == ARM_JOINTS[side]
        assert arm.end_effector == f"{side}_gripper" and arm.tool_mount == f"{side}_gripper_base"
        assert arm.rest_rad == TUCKED[side]
        p = FINGER_PREFIX[side]
        assert part.gripper[side].joints == [f"{p}_gripper_l_finger_joint", f"{p}_gripper_r_finger_joint"]
        assert {k: part.gripper[side].positions[k] for k in ("spoon", "none")} == {
            "spoon": 0.0,
            "none": 0.0,
        }  # reference: feeding (0, 0)


def test_base_height_puts_the_pedestal_on_the_floor(part, urdf_path):
    assert part.base_height_m == pytest.approx(0.925)  # the reference's load height
    cid = pb.connect(pb.DIRECT)
    try:
        body = pb.loadURDF(
            str(urdf_path), [0, 0, part.base_height_m], [0, 0, 0, 1], useFixedBase=True, physicsClientId=cid
        )
        pb.performCollisionDetection(physicsClientId=cid)
        lowest = min(
            pb.getAABB(body, j, physicsClientId=cid)[0][2]
            for j in range(-1, pb.getNumJoints(body, physicsClientId=cid))
        )
        # AABBs carry Bullet's collision margin (a few mm); the foot's bottom face is at 0.
        assert -0.01 < lowest <= 0.0
        # s0 ends up 1.0546 m above the floor (paper §III-A).
        s0 = pb.getLinkState(body, 4, computeForwardKinematics=True, physicsClientId=cid)[4]
        assert s0[2] == pytest.approx(1.0546, abs=1e-3)
    finally:
        pb.disconnect(cid)


def test_spoon_grip(part, bullet, tmp_path):
    """The spoon's handle end sits centred between the fingertip pads, the handle points out of
    the hand (+y_spoon = +z_gripper_base) and the bowl opening is perpendicular to the fingers."""
    grip = part.grips["spoon"]
    t_grip = origin_matrix(grip.position_m, grip.rpy_rad)
    spoon_path = tmp_path / "spoon.urdf"
    spoon_path.write_text(xacro.process_file(str(SPOON), mappings={}).toprettyxml(indent="  "))
    spoon = yourdfpy.URDF.load(str(spoon_path), build_scene_graph=True, load_meshes=False)
    handle_end = t_grip @ spoon.get_transform("spoon_handle_end", "spoon")

    # Fingertip pads (the finger's last collision box), in the gripper-base frame, from PyBullet.
    cid, body, _, _, _ = bullet
    set_arm(bullet, "right", [0.3, -0.4, 0.5, 1.0, -0.6, 0.7, 0.2])
    base = link_pose(bullet, "right_gripper_base")
    pads = []
    for finger in ("l", "r"):
        link = bullet[3][f"r_gripper_{finger}_finger"]
        shapes = pb.getCollisionShapeData(body, link, physicsClientId=cid)
        pad = max(shapes, key=lambda s: s[3][0])  # the 0.042-wide paddle box
        com_pos, com_orn = pb.getLinkState(body, link, computeForwardKinematics=True, physicsClientId=cid)[:2]
        world, _ = pb.multiplyTransforms(com_pos, com_orn, pad[5], pad[6])
        pads.append(np.linalg.solve(base, np.array([*world, 1.0]))[:3])
    set_arm(bullet, "right", [0] * 7)
    centre = (pads[0] + pads[1]) / 2
    np.testing.assert_allclose(centre, [0, 0, 0.1177], atol=1e-6)
    np.testing.assert_allclose(handle_end[:3, 3], centre, atol=1e-5)
    r = t_grip[:3, :3]
    np.testing.assert_allclose(r[:, 1], [0, 0, 1], atol=1e-9)  # handle -> bowl = approach
    assert abs(r[:, 2] @ np.array([0, 1, 0])) < 1e-9  # opening _|_ finger axis
    # The 12 mm handle fits between the closed pads (inner faces 16 mm apart).
    assert abs(pads[0][1] - pads[1][1]) - 0.0065 > 0.012


# --------------------------------------------------------------------------------------------
# physics


def test_position_hold_without_gravity(urdf_path):
    """Arm joints position-controlled at a random pose, gravity off: after 50 steps neither
    end effector has moved more than 1 mm."""
    cid = pb.connect(pb.DIRECT)
    try:
        pb.setGravity(0, 0, 0, physicsClientId=cid)
        body = pb.loadURDF(
            str(urdf_path),
            [0, 0, 0.925],
            [0, 0, 0, 1],
            useFixedBase=True,
            flags=pb.URDF_USE_INERTIA_FROM_FILE,
            physicsClientId=cid,
        )
        joints, links = {}, {}
        for j in range(pb.getNumJoints(body, physicsClientId=cid)):
            info = pb.getJointInfo(body, j, physicsClientId=cid)
            joints[info[1].decode()] = j
            links[info[12].decode()] = j
        rng = np.random.default_rng(7)
        start = {}
        for side in SIDES:
            q = random_configs(1, seed=int(rng.integers(1000)))[0]
            idx = [joints[n] for n in ARM_JOINTS[side]]
            for i, v in zip(idx, q):
                pb.resetJointState(body, i, float(v), physicsClientId=cid)
            pb.setJointMotorControlArray(
                body,
                idx,
                pb.POSITION_CONTROL,
                targetPositions=list(q),
                forces=[ARM_LIMITS[s][2] for s in ARM_SUFFIXES],
                physicsClientId=cid,
            )
            start[side] = np.array(
                pb.getLinkState(body, links[f"{side}_gripper"], computeForwardKinematics=True, physicsClientId=cid)[4]
            )
        for _ in range(50):
            pb.stepSimulation(physicsClientId=cid)
        for side in SIDES:
            end = np.array(
                pb.getLinkState(body, links[f"{side}_gripper"], computeForwardKinematics=True, physicsClientId=cid)[4]
            )
            assert np.linalg.norm(end - start[side]) < 1e-3, side
    finally:
        pb.disconnect(cid)
