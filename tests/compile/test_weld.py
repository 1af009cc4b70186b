"""`weld_joints`: moving joints made fixed at a value, checked in real pybullet (DIRECT) against
the unwelded URDF with the joints reset to that value; its refusals; and the compiler welding a
robot's undriven joints (Jaco in Scratch Itch: fingers at the grip, finger tips at 0)."""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pybullet as pb
import pytest

from assistive_compiler.compile.compiler import compile_task
from assistive_compiler.compile.weld import weld_joints

REPO = Path(__file__).resolve().parents[2]

# A chain with a tilted revolute axis, a prismatic and a continuous joint, each with an origin
# that both shifts and turns, and a leaf link on a fixed joint after them.
CHAIN = """<?xml version="1.0"?>
<robot name="chain">
  <link name="base"><inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>
  <joint name="hinge" type="revolute">
    <parent link="base"/><child link="a"/>
    <origin xyz="0.1 0.02 0.3" rpy="0.3 -0.2 0.5"/>
    <axis xyz="0.2 1 -0.4"/>
    <limit lower="-2" upper="2" effort="10" velocity="1"/>
  </joint>
  <link name="a"><inertial><mass value="0.5"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>
  <joint name="slide" type="prismatic">
    <parent link="a"/><child link="b"/>
    <origin xyz="0 0.2 0" rpy="0 0.7 0"/>
    <axis xyz="0.6 0 0.8"/>
    <limit lower="-0.5" upper="0.5" effort="10" velocity="1"/>
    <dynamics damping="0.1"/>
  </joint>
  <link name="b"><inertial><mass value="0.5"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>
  <joint name="spin" type="continuous">
    <parent link="b"/><child link="c"/>
    <origin xyz="0.05 0 0.1" rpy="-0.4 0 1.1"/>
    <axis xyz="0 0 1"/>
  </joint>
  <link name="c"><inertial><mass value="0.5"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>
  <joint name="tip_mount" type="fixed">
    <parent link="c"/><child link="tip"/>
    <origin xyz="0 0.1 0.05" rpy="0 0 0"/>
  </joint>
  <link name="tip"><inertial><mass value="0.1"/><inertia ixx="0.001" ixy="0" ixz="0" iyy="0.001" iyz="0" izz="0.001"/></inertial></link>
</robot>
"""
VALUES = {"hinge": 1.1, "slide": -0.23, "spin": 2.9}


def _frames(cid, path: Path, reset: dict[str, float]) -> dict[str, tuple]:
    """World frame (position, orientation) of every link, after resetting the named joints."""
    body = pb.loadURDF(
        str(path), [0.2, -0.1, 0.5], pb.getQuaternionFromEuler([0.1, 0.2, -0.3]), useFixedBase=True, physicsClientId=cid
    )
    names = {
        pb.getJointInfo(body, j, physicsClientId=cid)[1].decode(): j
        for j in range(pb.getNumJoints(body, physicsClientId=cid))
    }
    for name, q in reset.items():
        pb.resetJointState(body, names[name], q, physicsClientId=cid)
    out = {}
    for j in range(pb.getNumJoints(body, physicsClientId=cid)):
        info = pb.getJointInfo(body, j, physicsClientId=cid)
        state = pb.getLinkState(body, j, computeForwardKinematics=True, physicsClientId=cid)
        out[info[12].decode()] = (np.array(state[4]), np.array(state[5]), info[2])
    return out


def test_welded_links_sit_where_the_joints_held_them(cid, tmp_path):
    original, welded = tmp_path / "chain.urdf", tmp_path / "welded.urdf"
    original.write_text(CHAIN)
    welded.write_text(weld_joints(CHAIN, VALUES))
    moving = _frames(cid, original, VALUES)
    fixed = _frames(cid, welded, {})
    assert moving.keys() == fixed.keys() == {"a", "b", "c", "tip"}
    for link, (pos, orn, _) in moving.items():
        assert np.allclose(fixed[link][0], pos, atol=1e-9), link
        assert np.allclose(pb.getMatrixFromQuaternion(fixed[link][1]), pb.getMatrixFromQuaternion(orn), atol=1e-7), link
        assert fixed[link][2] == pb.JOINT_FIXED
    for joint in ET.fromstring(welded.read_text()).findall("joint"):  # no motion elements left on a welded joint
        assert joint.get("type") == "fixed" and sorted(e.tag for e in joint) == ["child", "origin", "parent"], (
            joint.get("name")
        )


def test_welding_only_some_joints_keeps_the_others_moving(cid, tmp_path):
    path = tmp_path / "some.urdf"
    path.write_text(weld_joints(CHAIN, {"slide": 0.1}))
    body = pb.loadURDF(str(path), useFixedBase=True, physicsClientId=cid)
    kinds = {
        pb.getJointInfo(body, j, physicsClientId=cid)[1].decode(): pb.getJointInfo(body, j, physicsClientId=cid)[2]
        for j in range(pb.getNumJoints(body, physicsClientId=cid))
    }
    assert kinds == {
        "hinge": pb.JOINT_REVOLUTE,
        "slide": pb.JOINT_FIXED,
        "spin": pb.JOINT_REVOLUTE,
        "tip_mount": pb.JOINT_FIXED,
    }
    assert weld_joints(CHAIN, {"slide": 0.1}) == weld_joints(CHAIN, {"slide": 0.1})  # deterministic bytes


@pytest.mark.parametrize(
    "values, message",
    [
        ({"hing": 0.1}, "no joint named 'hing' in the document"),
        (
            {"tip_mount": 0.0},
            "joint 'tip_mount' is 'fixed'; only revolute, continuous and prismatic joints can be welded",
        ),
        ({"hinge": math.nan}, "joint 'hinge': value nan is not a finite number"),
    ],
)
def test_weld_refusals(values, message):
    with pytest.raises(ValueError) as err:
        weld_joints(CHAIN, values)
    assert str(err.value) == message


def test_the_compiler_welds_the_joints_a_task_never_drives(tmp_path):
    """Jaco in Scratch Itch drives its 7 arm joints; its 3 fingers are welded at the scratcher
    grip (0.9 rad) and the 3 passive finger tips at 0, so pybullet sees 7 moving joints."""
    out = compile_task(REPO / "specs" / "tasks" / "scratch_itch.yaml", "jaco", tmp_path / "scratch-jaco").out_dir
    import json

    robot = json.loads((out / "manifest.json").read_text())["robot"]
    assert robot["welded_joints"] == {
        "j2s7s300_joint_finger_1": 0.9,
        "j2s7s300_joint_finger_2": 0.9,
        "j2s7s300_joint_finger_3": 0.9,
        "j2s7s300_joint_finger_tip_1": 0.0,
        "j2s7s300_joint_finger_tip_2": 0.0,
        "j2s7s300_joint_finger_tip_3": 0.0,
    }
    cid = pb.connect(pb.DIRECT)
    try:
        body = pb.loadURDF(str(out / "urdf" / "robot.urdf"), useFixedBase=True, physicsClientId=cid)
        moving = [
            pb.getJointInfo(body, j, physicsClientId=cid)[1].decode()
            for j in range(pb.getNumJoints(body, physicsClientId=cid))
            if pb.getJointInfo(body, j, physicsClientId=cid)[2] != pb.JOINT_FIXED
        ]
    finally:
        pb.disconnect(cid)
    assert moving == robot["arm_joints"] == [f"j2s7s300_joint_{i}" for i in range(1, 8)]
