"""The robot's fixed links merged at compile time (:mod:`assistive_compiler.compile.robot`): every
link the manifest names survives, nothing else hangs on a fixed joint, and the robot's dynamics
(mass matrix, gravity torques) are those of the robot as emitted, with its tool welded on, before
the merge."""

from __future__ import annotations

import xml.etree.ElementTree as ET

import numpy as np
import pybullet as pb
import pytest
from conftest import REPO

from assistive_compiler.compile.compiler import compile_task
from assistive_compiler.compile.emit import emit_props
from assistive_compiler.compile.robot import _names_in, _weld
from assistive_compiler.library import Library
from assistive_compiler.resolve import resolve
from assistive_compiler.spec.load import load_spec
from assistive_compiler.urdf import urdf_info

ITCH = REPO / "specs" / "tasks" / "scratch_itch.yaml"


@pytest.fixture(scope="module", params=["pr2", "jaco"])
def merged_and_emitted(request, tmp_path_factory):
    """(the artifact's robot URDF, the robot URDF as stage 1 emits it with the artifact's welded
    tools on it and unmerged, the manifest)."""
    robot = request.param
    tmp = tmp_path_factory.mktemp(f"robot-merge-{robot}")
    result = compile_task(ITCH, robot, tmp / "artifact")
    loaded = load_spec(ITCH)
    scene = emit_props(
        resolve(loaded, robot, Library.for_spec(loaded.path)), tmp / "emitted", Library.for_spec(loaded.path)
    )
    merged = (result.out_dir / result.manifest.body("robot").urdf).read_text()
    emitted = ET.fromstring(scene.written["robot"].read_text())
    for att in result.manifest.tools:
        assert att.welded  # the scratcher: nothing rests in it
        _weld(emitted, att, ET.parse(scene.written[att.body]).getroot())
    return merged, ET.tostring(emitted, encoding="unicode"), result.manifest


def test_named_links_survive_and_no_other_hangs_on_a_fixed_joint(merged_and_emitted):
    merged, emitted, manifest = merged_and_emitted
    before, after = urdf_info(emitted), urdf_info(merged)
    named = set(_names_in(manifest.model_dump(mode="json"))) & set(before.links)
    assert set(manifest.robot.links.values()) <= named <= set(after.links)
    assert len(after.links) < len(before.links)  # fingers, sensor frames, welded arms: gone
    fixed_children = {j.child for j in after.joints.values() if j.type == "fixed"}
    assert fixed_children <= named  # a fixed link left is one the manifest names
    movable = {n for n, j in before.joints.items() if j.type != "fixed"}
    assert movable == {n for n, j in after.joints.items() if j.type != "fixed"}


def test_the_merged_robot_has_the_emitted_robots_dynamics(merged_and_emitted, tmp_path):
    merged, emitted, _ = merged_and_emitted
    c = pb.connect(pb.DIRECT)
    pb.setGravity(0, 0, -9.81, physicsClientId=c)
    try:
        found = []
        for name, text in (("emitted", emitted), ("merged", merged)):
            path = tmp_path / f"{name}.urdf"
            path.write_text(text)
            body = pb.loadURDF(str(path), useFixedBase=True, flags=pb.URDF_USE_INERTIA_FROM_FILE, physicsClientId=c)
            n = pb.getNumJoints(body, physicsClientId=c)
            joints = {pb.getJointInfo(body, j, physicsClientId=c)[1].decode(): j for j in range(n)}
            movable = sorted(
                k for k, j in joints.items() if pb.getJointInfo(body, j, physicsClientId=c)[2] != pb.JOINT_FIXED
            )
            q = np.linspace(0.2, 0.9, len(movable))
            for name_, value in zip(movable, q):
                pb.resetJointState(body, joints[name_], value, physicsClientId=c)
            order = sorted(joints[k] for k in movable)  # pybullet's order: by joint index
            angles = [pb.getJointState(body, j, physicsClientId=c)[0] for j in order]
            # What moves: its inertia (the mass matrix) and its weight's torques (masses and centres).
            zero = [0.0] * len(angles)
            gravity = np.array(pb.calculateInverseDynamics(body, angles, zero, zero, physicsClientId=c))
            names = [pb.getJointInfo(body, j, physicsClientId=c)[1].decode() for j in order]
            matrix = np.array(pb.calculateMassMatrix(body, angles, physicsClientId=c))
            found.append((gravity, names, matrix))
        (gravity_a, names_a, m_a), (gravity_b, names_b, m_b) = found
        assert names_a == names_b
        assert np.allclose(m_a, m_b, rtol=1e-8, atol=1e-10)
        assert np.abs(gravity_a).max() > 1.0 and np.allclose(gravity_a, gravity_b, rtol=1e-8, atol=1e-9)
    finally:
        pb.disconnect(c)
