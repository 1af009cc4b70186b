"""Kinematics of templates/robots/pr2.urdf.xacro (Willow Garage PR2 as the reference uses it)
against the published PR2 kinematics (pr2_description) and paper §III-A

Independent formulation: the published joint table (ERD-PR2, §2.1 and §2.3-2.5) is typed in
below and multiplied out with numpy (every arm-chain origin has rpy 0, so each joint is a
translation followed by a rotation about its axis); the torso sits where the reference's
pr2_no_torso_lift_tall.urdf fixes it (§2.9). PyBullet's FK of the rendered template must match
that product within 3 mm over 30 seeded random configurations per arm (it matches to ~1e-6 m).
Two reference numbers computed by others are checked too: the tool frame at q = 0 and the
reference's tucked pose, which puts the right tool frame at (0.1179, -0.6055, 0.3292).
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
from frames import body_indices

from assistive_compiler.compile.external_checks import captured_c_output
from assistive_compiler.compile.lint import lint_urdf
from assistive_compiler.library import Library

ROOT = Path(__file__).resolve().parents[2]
TEMPLATE = ROOT / "templates" / "robots" / "pr2.urdf.xacro"
SPOON = ROOT / "templates" / "tools" / "spoon.urdf.xacro"
CHECK_URDF = Path(sys.executable).parent / "check_urdf"
PI = math.pi
TWO_PI = 2 * PI

ARM = ["shoulder_pan", "shoulder_lift", "upper_arm_roll", "elbow_flex", "forearm_roll", "wrist_flex", "wrist_roll"]
FINGERS = ["l_finger", "l_finger_tip", "r_finger", "r_finger_tip"]


def arm_joints(s: str) -> list[str]:
    return [f"{s}_{n}_joint" for n in ARM]


def finger_joints(s: str) -> list[str]:
    return [f"{s}_gripper_{f}_joint" for f in FINGERS]


# ---------------------------------------------------------------------------- the facts
# Frames above the arms (base_footprint -> torso_lift_link): ERD base_footprint_joint and the
# reference's fixed torso (ERD 0.739675 + 0.33).
BASE_TO_TORSO = [(0.0, 0.0, 0.051), (-0.05, 0.0, 1.069675)]


# Arm chain (§2.3/2.4): (joint, origin xyz, axis); None = fixed. Every rpy is 0.
def arm_chain(s: str):
    y = -0.188 if s == "r" else 0.188
    return [
        (f"{s}_shoulder_pan_joint", (0, y, 0), (0, 0, 1)),
        (f"{s}_shoulder_lift_joint", (0.1, 0, 0), (0, 1, 0)),
        (f"{s}_upper_arm_roll_joint", (0, 0, 0), (1, 0, 0)),
        (f"{s}_upper_arm_joint", (0, 0, 0), None),
        (f"{s}_elbow_flex_joint", (0.4, 0, 0), (0, 1, 0)),
        (f"{s}_forearm_roll_joint", (0, 0, 0), (1, 0, 0)),
        (f"{s}_forearm_joint", (0, 0, 0), None),
        (f"{s}_wrist_flex_joint", (0.321, 0, 0), (0, 1, 0)),
        (f"{s}_wrist_roll_joint", (0, 0, 0), (1, 0, 0)),
        (f"{s}_gripper_palm_joint", (0, 0, 0), None),
        (f"{s}_gripper_tool_joint", (0.18, 0, 0), None),
    ]


# Gripper (§2.5): joint -> (parent link suffix, origin xyz, axis).
def gripper_chain(s: str):
    return {
        f"{s}_gripper_l_finger_joint": ("gripper_palm_link", (0.07691, 0.01, 0), (0, 0, 1)),
        f"{s}_gripper_l_finger_tip_joint": ("gripper_l_finger_link", (0.09137, 0.00495, 0), (0, 0, -1)),
        f"{s}_gripper_r_finger_joint": ("gripper_palm_link", (0.07691, -0.01, 0), (0, 0, -1)),
        f"{s}_gripper_r_finger_tip_joint": ("gripper_r_finger_link", (0.09137, -0.00495, 0), (0, 0, 1)),
    }


# Hard limits (rad), effort, velocity. Wrist flex lower is the reference's -2.18 (ERD -2.094).
def arm_limits(s: str):
    pan = (-2.2853981634, 0.714601836603) if s == "r" else (-0.714601836603, 2.2853981634)
    roll = (-3.9, 0.8) if s == "r" else (-0.8, 3.9)
    return {
        f"{s}_shoulder_pan_joint": (*pan, 30, 2.088),
        f"{s}_shoulder_lift_joint": (-0.5236, 1.3963, 30, 2.082),
        f"{s}_upper_arm_roll_joint": (*roll, 30, 3.27),
        f"{s}_elbow_flex_joint": (-2.3213, 0.0, 30, 3.3),
        f"{s}_forearm_roll_joint": (-TWO_PI, TWO_PI, 30, 3.6),
        f"{s}_wrist_flex_joint": (-2.18, 0.0, 10, 3.078),
        f"{s}_wrist_roll_joint": (-TWO_PI, TWO_PI, 10, 3.6),
    }


# Published link masses and COMs (ERD) for the links modelled one to one.
def arm_inertia(s: str):
    ua_com = (0.21398, -0.01621, -0.0002) if s == "r" else (0.21405, 0.01658, -0.00057)
    return {
        f"{s}_shoulder_pan_link": (25.799322, (-0.001201, 0.024513, -0.098231)),
        f"{s}_shoulder_lift_link": (2.74988, (0.02195, -0.02664, -0.03127)),
        f"{s}_upper_arm_roll_link": (0.1, (0, 0, 0)),
        f"{s}_upper_arm_link": (6.01769, ua_com),
        f"{s}_elbow_flex_link": (1.90327, (0.01014, 0.00032, -0.01211)),
        f"{s}_forearm_roll_link": (0.1, (0, 0, 0)),
        f"{s}_forearm_link": (2.57968, (0.18791, -0.00017, -0.00912)),
        f"{s}_wrist_flex_link": (0.61402, (-0.00157, 0, -0.00075)),
        f"{s}_wrist_roll_link": (0.1, (0, 0, 0)),
        f"{s}_gripper_l_finger_link": (0.17126, (0.03598, 0.0173, -0.00164)),
        f"{s}_gripper_l_finger_tip_link": (0.04419, (0.00423, 0.00284, 0)),
        f"{s}_gripper_r_finger_link": (0.17389, (0.03576, -0.01736, -0.00095)),
        f"{s}_gripper_r_finger_tip_link": (0.04419, (0.00423, -0.00284, 0)),
    }


BODY_INERTIA = {
    "base_footprint": (1.0, (0, 0, 0)),
    "head_pan_link": (1.611118, (-0.005717, 0.010312, -0.029649)),
}
# Group masses (§2.2).
TOTAL_MASS = 257.164
ARM_MASS = 41.334  # shoulder_pan_link and everything below it
GRIPPER_MASS = 1.360  # palm and below
BASE_GROUP_MASS = 134.416
HEAD_MASS = 3.781
ARM_GROUP_SUFFIXES = [
    "shoulder_pan_link",
    "shoulder_lift_link",
    "upper_arm_roll_link",
    "upper_arm_link",
    "elbow_flex_link",
    "forearm_roll_link",
    "forearm_link",
    "wrist_flex_link",
    "wrist_roll_link",
]
GRIPPER_SUFFIXES = [
    "gripper_palm_link",
    "gripper_tool_frame",
    "gripper_l_finger_link",
    "gripper_l_finger_tip_link",
    "gripper_r_finger_link",
    "gripper_r_finger_tip_link",
]

# The reference's tucked pose (§2.9) and where it puts the tool frames.
TUCKED = {"r": (-1.75, 1.25, -1.5, -0.5, -1, 0, -1), "l": (1.75, 1.25, 1.5, -0.5, 1, 0, 1)}
TUCKED_TOOL = {"r": (0.1179, -0.6055, 0.3292), "l": (0.1179, 0.6055, 0.3292)}
SHOULDER_Z = 1.120675
FEEDING_GRIP = 0.03


# ---------------------------------------------------------------------------- numpy FK
def rot(axis, q) -> np.ndarray:
    """Rodrigues rotation about a unit axis."""
    k = np.array(axis, dtype=float)
    kx = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + math.sin(q) * kx + (1 - math.cos(q)) * kx @ kx


def joint_tf(xyz, axis, q) -> np.ndarray:
    t = np.eye(4)
    t[:3, 3] = xyz
    if axis is not None:
        t[:3, :3] = rot(axis, q)
    return t


def facts_fk(s: str, q) -> dict[str, np.ndarray]:
    """Published-table FK: pose of every arm joint's child frame in base_footprint."""
    t = np.eye(4)
    for xyz in BASE_TO_TORSO:
        t = t @ joint_tf(xyz, None, 0.0)
    out = {"torso": t.copy()}
    values = iter(q)
    for name, xyz, axis in arm_chain(s):
        t = t @ joint_tf(xyz, axis, next(values) if axis is not None else 0.0)
        out[name] = t.copy()
    return out


def facts_tool(s: str, q) -> np.ndarray:
    return facts_fk(s, q)[f"{s}_gripper_tool_joint"]


# ---------------------------------------------------------------------------- fixtures


@pytest.fixture(scope="module")
def bullet(urdf_path):
    """(client, body, joint index by name, link index by name, what loadURDF printed)."""
    cid = pb.connect(pb.DIRECT)
    with captured_c_output() as out:
        body = pb.loadURDF(
            str(urdf_path),
            [0, 0, 0],
            [0, 0, 0, 1],
            useFixedBase=True,
            flags=pb.URDF_USE_INERTIA_FROM_FILE,
            physicsClientId=cid,
        )
    joints, links = body_indices(cid, body)
    yield cid, body, joints, links, out[0]
    pb.disconnect(cid)


def set_arm(bullet, s, q, grip=0.0):
    cid, body, joints, _, _ = bullet
    for name, v in zip(arm_joints(s), q):
        pb.resetJointState(body, joints[name], float(v), physicsClientId=cid)
    for name in finger_joints(s):
        pb.resetJointState(body, joints[name], grip, physicsClientId=cid)


def link_tf(bullet, link) -> np.ndarray:
    cid, body, _, links, _ = bullet
    ls = pb.getLinkState(body, links[link], computeForwardKinematics=True, physicsClientId=cid)
    t = np.eye(4)
    t[:3, :3] = np.array(pb.getMatrixFromQuaternion(ls[5])).reshape(3, 3)
    t[:3, 3] = ls[4]
    return t


def random_configs(s, n=30, seed=0):
    """Seeded configurations within the hard limits (roll joints in [-pi, pi])."""
    rng = np.random.default_rng(seed)
    lim = arm_limits(s)
    lo = [max(lim[j][0], -PI) for j in arm_joints(s)]
    hi = [min(lim[j][1], PI) for j in arm_joints(s)]
    return [rng.uniform(lo, hi) for _ in range(n)]


# ---------------------------------------------------------------------------- validity
def test_check_urdf_passes(urdf_path):
    res = subprocess.run([str(CHECK_URDF), str(urdf_path)], capture_output=True, text=True, timeout=30)
    assert res.returncode == 0, res.stdout + res.stderr
    assert "Successfully Parsed XML" in res.stdout


def test_lint_clean(urdf_text):
    assert lint_urdf(urdf_text, template="robots/pr2.urdf.xacro") == []


def test_pybullet_loads_without_warnings(bullet):
    *_, printed = bullet
    assert "warning" not in printed.lower(), printed
    assert "error" not in printed.lower(), printed


def test_yourdfpy_valid_and_primitives_only(model, urdf_text):
    assert model.validate()
    assert "<mesh" not in urdf_text and "<capsule" not in urdf_text


def test_library_part():
    part = Library().get("robots", "pr2").part
    assert part.title == "PR2" and part.base_link == "base_footprint"
    assert part.mountable is False and part.base_height_m == 0.0
    for side, s in (("right", "r"), ("left", "l")):
        assert part.arms[side].joints == arm_joints(s)
        assert part.arms[side].end_effector == part.arms[side].tool_mount == f"{s}_gripper_tool_frame"
        assert part.arms[side].rest_rad == list(TUCKED[s])
        assert part.gripper[side].joints == finger_joints(s)
        assert {k: part.gripper[side].positions[k] for k in ("spoon", "none")} == {"spoon": FEEDING_GRIP, "none": 0.0}


# ---------------------------------------------------------------------------- structure
def test_tree_names_and_axes(model):
    assert model.base_link == "base_footprint"
    assert model.joint_map["torso_lift_joint"].type == "fixed"
    for name in ("head_pan_joint", "head_tilt_joint"):
        assert model.joint_map[name].type == "fixed"
    np.testing.assert_allclose(model.joint_map["torso_lift_joint"].origin[:3, 3], BASE_TO_TORSO[1], atol=1e-12)
    np.testing.assert_allclose(model.joint_map["base_footprint_joint"].origin[:3, 3], BASE_TO_TORSO[0], atol=1e-12)
    np.testing.assert_allclose(model.joint_map["head_pan_joint"].origin[:3, 3], (-0.01707, 0, 0.38145), atol=1e-12)
    np.testing.assert_allclose(model.joint_map["head_tilt_joint"].origin[:3, 3], (0.068, 0, 0), atol=1e-12)
    movable = {n for n, j in model.joint_map.items() if j.type != "fixed"}
    assert movable == {j for s in "rl" for j in arm_joints(s) + finger_joints(s)}
    for s in "rl":
        for name, xyz, axis in arm_chain(s):
            j = model.joint_map[name]
            np.testing.assert_allclose(j.origin, joint_tf(xyz, None, 0), atol=1e-12, err_msg=name)
            if axis is None:
                assert j.type == "fixed", name
            else:
                assert j.type == "revolute", name
                np.testing.assert_allclose(j.axis, axis, err_msg=name)
        for name, (parent, xyz, axis) in gripper_chain(s).items():
            j = model.joint_map[name]
            assert j.parent == f"{s}_{parent}" and j.type == "revolute"
            np.testing.assert_allclose(j.origin, joint_tf(xyz, None, 0), atol=1e-12, err_msg=name)
            np.testing.assert_allclose(j.axis, axis, err_msg=name)


def test_joint_limits(model):
    for s in "rl":
        for name, (lo, hi, effort, vel) in arm_limits(s).items():
            lim = model.joint_map[name].limit
            assert (lim.lower, lim.upper) == pytest.approx((lo, hi), abs=1e-9), name
            assert (lim.effort, lim.velocity) == pytest.approx((effort, vel)), name
        for name in finger_joints(s):
            lim = model.joint_map[name].limit
            assert (lim.lower, lim.upper, lim.effort, lim.velocity) == pytest.approx((0, 0.548, 1000, 0.5)), name


# ---------------------------------------------------------------------------- masses
def test_link_masses_and_coms(model):
    table = dict(BODY_INERTIA)
    for s in "rl":
        table |= arm_inertia(s)
    for name, (mass, com) in table.items():
        inertial = model.link_map[name].inertial
        assert inertial.mass == pytest.approx(mass, abs=1e-9), name
        np.testing.assert_allclose(inertial.origin[:3, 3], com, atol=1e-9, err_msg=name)
    # Lumped links (template header): the published parts add up.
    mass = lambda n: model.link_map[n].inertial.mass  # noqa: E731
    assert mass("base_link") == pytest.approx(116 + 4 * 3.473082 + 8 * 0.44036 + 0.001, abs=1e-9)
    assert mass("torso_lift_link") == pytest.approx(36.248046 + 0.001 + 0.051, abs=1e-9)
    assert mass("head_pan_link") + mass("head_tilt_link") == pytest.approx(HEAD_MASS, abs=1e-9)
    for s in "rl":
        assert mass(f"{s}_gripper_palm_link") == pytest.approx(0.58007 + 0.17126 + 0.17389, abs=1e-9)
        # The lumped COM stays near the palm's own (0.06623, 0.00053, -0.00119).
        com = model.link_map[f"{s}_gripper_palm_link"].inertial.origin[:3, 3]
        assert np.linalg.norm(com - (0.06623, 0.00053, -0.00119)) < 0.012
    com = model.link_map["base_link"].inertial.origin[:3, 3]
    assert np.linalg.norm(com - (-0.061, 0, 0.293)) < 0.03


def test_group_and_total_masses(model):
    mass = lambda n: model.link_map[n].inertial.mass  # noqa: E731
    total = sum(link.inertial.mass for link in model.robot.links)
    # Unmodelled sensor frames (forearm cameras, fingertip frames, ~0.01 kg per arm) are missing.
    assert total == pytest.approx(TOTAL_MASS, abs=0.03)
    assert mass("base_footprint") + mass("base_link") == pytest.approx(
        BASE_GROUP_MASS, abs=1e-3
    )  # the table rounds to 1 g
    for s in "rl":
        arm = sum(mass(f"{s}_{x}") for x in ARM_GROUP_SUFFIXES)
        grip = sum(mass(f"{s}_{x}") for x in GRIPPER_SUFFIXES)
        assert grip == pytest.approx(GRIPPER_MASS, abs=0.002)
        assert arm + grip == pytest.approx(ARM_MASS, abs=0.015)


def test_pybullet_masses(bullet, model):
    cid, body, _, links, _ = bullet
    for name, j in links.items():
        assert pb.getDynamicsInfo(body, j, physicsClientId=cid)[0] == pytest.approx(model.link_map[name].inertial.mass)


# ---------------------------------------------------------------------------- FK
def test_zero_pose_frames(bullet):
    for s, y in (("r", -0.188), ("l", 0.188)):
        set_arm(bullet, s, [0] * 7)
        t = link_tf(bullet, f"{s}_gripper_tool_frame")
        np.testing.assert_allclose(t[:3, 3], (0.951, y, SHOULDER_Z), atol=1e-6)
        np.testing.assert_allclose(t[:3, :3], np.eye(3), atol=1e-9)
        np.testing.assert_allclose(link_tf(bullet, f"{s}_shoulder_pan_link")[:3, 3], (-0.05, y, SHOULDER_Z), atol=1e-6)
        # Fingertip joints (§2.5 column, raised by the reference's 0.33 m torso).
        tip = link_tf(bullet, f"{s}_gripper_l_finger_tip_link")[:3, 3]
        np.testing.assert_allclose(tip, (0.9393, y + 0.01495, SHOULDER_Z), atol=1e-4)
    np.testing.assert_allclose(link_tf(bullet, "head_pan_link")[:3, 3], (-0.06707, 0, 1.502125), atol=1e-6)


def test_fk_matches_published_chain(bullet):
    worst_p, worst_r = 0.0, 0.0
    for s in "rl":
        for q in random_configs(s, seed=1 if s == "r" else 2):
            set_arm(bullet, s, q)
            t_pb = link_tf(bullet, f"{s}_gripper_tool_frame")
            t_ref = facts_tool(s, q)
            worst_p = max(worst_p, float(np.linalg.norm(t_pb[:3, 3] - t_ref[:3, 3])))
            worst_r = max(worst_r, float(np.abs(t_pb[:3, :3] - t_ref[:3, :3]).max()))
            # The wrist too (independent of the tool offset).
            w_pb = link_tf(bullet, f"{s}_wrist_flex_link")[:3, 3]
            w_ref = facts_fk(s, q)[f"{s}_wrist_flex_joint"][:3, 3]
            worst_p = max(worst_p, float(np.linalg.norm(w_pb - w_ref)))
    assert worst_p < 0.003
    assert worst_p < 1e-4  # in fact exact
    assert worst_r < 1e-4


def test_tucked_pose_matches_reference(bullet):
    for s in "rl":
        set_arm(bullet, s, TUCKED[s])
        p = link_tf(bullet, f"{s}_gripper_tool_frame")[:3, 3]
        np.testing.assert_allclose(p, TUCKED_TOOL[s], atol=1e-3)
        np.testing.assert_allclose(facts_tool(s, TUCKED[s])[:3, 3], TUCKED_TOOL[s], atol=1e-3)


def test_reach(bullet):
    """Straight arm: pan origin -> tool frame 1.0010 m, lift origin -> tool frame 0.9010 m."""
    set_arm(bullet, "r", [0.3, 0, -1.0, 0, 0.5, 0, 0.2])
    tool = link_tf(bullet, "r_gripper_tool_frame")[:3, 3]
    pan = link_tf(bullet, "r_shoulder_pan_link")[:3, 3]
    lift = link_tf(bullet, "r_shoulder_lift_link")[:3, 3]
    assert np.linalg.norm(tool - pan) == pytest.approx(1.0010, abs=1e-4)
    assert np.linalg.norm(tool - lift) == pytest.approx(0.9010, abs=1e-4)


# ---------------------------------------------------------------------------- gripper and spoon
def test_fingertips_parallel_and_centred(bullet):
    """All four finger joints at one value keep the tips parallel to the approach axis and
    symmetric about the tool frame's x axis."""
    for q in (0.0, FEEDING_GRIP, 0.3, 0.548):
        set_arm(bullet, "r", [0.2, 0.4, -0.7, -1.0, 0.6, -0.8, 1.1], grip=q)
        tool = link_tf(bullet, "r_gripper_tool_frame")
        inv = np.linalg.inv(tool)
        tl = inv @ link_tf(bullet, "r_gripper_l_finger_tip_link")
        tr = inv @ link_tf(bullet, "r_gripper_r_finger_tip_link")
        np.testing.assert_allclose(tl[:3, :3], np.eye(3), atol=1e-6)
        np.testing.assert_allclose(tr[:3, :3], np.eye(3), atol=1e-6)
        np.testing.assert_allclose(tl[:3, 3] * (1, -1, 1), tr[:3, 3], atol=1e-6)
        # Opening grows with q: tip joint at y = 0.01 + 0.09137 sin q + 0.00495 cos q.
        assert tl[1, 3] == pytest.approx(0.01 + 0.09137 * math.sin(q) + 0.00495 * math.cos(q), abs=1e-6)
        # The tool frame lies along the pads (tip box x from -0.0255 to 0.0315 about the tip joint).
        assert tl[0, 3] - 0.0255 < 0 < tl[0, 3] + 0.0315


def test_spoon_grip(bullet):
    """grips.spoon puts the spoon's handle end centred between the fingertips, the handle ->
    bowl direction (+y) along the approach axis and the bowl opening (+z) perpendicular to the
    closing direction."""
    grip = Library().get("robots", "pr2").part.grips["spoon"]
    doc = xacro.process_file(str(SPOON), mappings={})
    handle = next(j for j in doc.getElementsByTagName("joint") if j.getAttribute("name") == "spoon_handle_end_joint")
    h = np.array([float(v) for v in handle.getElementsByTagName("origin")[0].getAttribute("xyz").split()])
    r, p, y = grip.rpy_rad
    t_grip = np.eye(4)
    t_grip[:3, :3] = rot((0, 0, 1), y) @ rot((0, 1, 0), p) @ rot((1, 0, 0), r)
    t_grip[:3, 3] = grip.position_m
    set_arm(bullet, "r", [-0.4, 0.3, -1.2, -1.4, 0.9, -0.6, 2.0], grip=FEEDING_GRIP)
    tool = link_tf(bullet, "r_gripper_tool_frame")
    spoon_w = tool @ t_grip
    handle_w = spoon_w @ np.append(h, 1.0)
    # Centre between the two fingertip joints, projected on the closing axis, is the tool frame.
    tl = link_tf(bullet, "r_gripper_l_finger_tip_link")[:3, 3]
    tr = link_tf(bullet, "r_gripper_r_finger_tip_link")[:3, 3]
    closing = (tl - tr) / np.linalg.norm(tl - tr)
    np.testing.assert_allclose(handle_w[:3], tool[:3, 3], atol=1e-5)
    assert abs(np.dot(handle_w[:3] - (tl + tr) / 2, closing)) < 1e-5
    approach = tool[:3, 0]
    assert np.dot(spoon_w[:3, 1], approach) == pytest.approx(1.0, abs=1e-6)
    assert abs(np.dot(spoon_w[:3, 2], closing)) < 1e-6
    # Bowl opening along the hand's +z (up when the hand is level).
    assert np.dot(spoon_w[:3, 2], tool[:3, 2]) == pytest.approx(1.0, abs=1e-6)


# ---------------------------------------------------------------------------- physics
def test_position_control_holds_pose_without_gravity(urdf_path):
    """Arm joints position-controlled at a random pose, gravity off (the reference compensates
    it), default motors off as the runtime does: after 50 steps of 0.02 s the tool frames have
    not moved more than 1 mm."""
    cid = pb.connect(pb.DIRECT)
    try:
        body = pb.loadURDF(
            str(urdf_path),
            [0, 0, 0],
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
        sim = (cid, body, joints, links, "")
        pb.setGravity(0, 0, 0, physicsClientId=cid)
        pb.setTimeStep(0.02, physicsClientId=cid)
        all_j = list(range(pb.getNumJoints(body, physicsClientId=cid)))
        pb.setJointMotorControlArray(body, all_j, pb.VELOCITY_CONTROL, forces=[0.0] * len(all_j), physicsClientId=cid)
        start = {}
        for s, seed in (("r", 11), ("l", 12)):
            q = random_configs(s, n=1, seed=seed)[0]
            set_arm(sim, s, q, grip=FEEDING_GRIP)
            pb.setJointMotorControlArray(
                body,
                [joints[j] for j in arm_joints(s)],
                pb.POSITION_CONTROL,
                targetPositions=list(q),
                forces=[arm_limits(s)[j][2] for j in arm_joints(s)],
                physicsClientId=cid,
            )
            pb.setJointMotorControlArray(
                body,
                [joints[j] for j in finger_joints(s)],
                pb.POSITION_CONTROL,
                targetPositions=[FEEDING_GRIP] * 4,
                positionGains=[0.05] * 4,
                forces=[500.0] * 4,
                physicsClientId=cid,
            )
            start[s] = link_tf(sim, f"{s}_gripper_tool_frame")[:3, 3]
        for _ in range(50):
            pb.stepSimulation(physicsClientId=cid)
        for s in "rl":
            moved = float(np.linalg.norm(link_tf(sim, f"{s}_gripper_tool_frame")[:3, 3] - start[s]))
            assert moved < 0.001, (s, moved)
    finally:
        pb.disconnect(cid)
