"""A tool welded to the robot at compile time (:func:`assistive_compiler.compile.robot.weld_tools`):
which tools are, where a welded tool is, and that its contacts and distances stay its own although
its links are links of the robot's pybullet body."""

from __future__ import annotations

import xml.etree.ElementTree as ET

import gymnasium as gym
import numpy as np
import pybullet as pb
import pytest

import assistive_compiler  # noqa: F401  (registers the ids)
from assistive_compiler.artifact import Manifest
from assistive_compiler.describe import describe_scene, describe_text
from assistive_compiler.policies import make_policy
from assistive_compiler.runtime.env import AssistiveEnv


@pytest.fixture(scope="module")
def itch(itch_artifact):
    env = AssistiveEnv(itch_artifact)
    yield env
    env.close()


def test_a_tool_nothing_with_weight_presses_on_is_welded_and_a_loaded_one_is_not(itch_artifact, artifact, shared_cache):
    itch = Manifest.read(itch_artifact, verify=True)
    (scratcher,) = itch.tools
    assert scratcher.welded and itch.body("scratcher").urdf == itch.body("robot").urdf
    assert not (itch_artifact / "urdf" / "scratcher.urdf").exists()
    joints = {j.get("name"): j for j in ET.parse(itch_artifact / itch.body("robot").urdf).getroot().iter("joint")}
    grip = joints["scratcher_grip"]
    assert (grip.get("type"), grip.find("parent").get("link"), grip.find("child").get("link")) == (
        "fixed",
        scratcher.parent_link,
        scratcher.links["base"],
    )
    feeding = Manifest.read(artifact)
    (spoon,) = feeding.tools
    assert not spoon.welded and (artifact / feeding.body("spoon").urdf).is_file()  # the food rests in it
    with shared_cache("assistive_compiler/ArmManipulationJaco-v1"):
        arm = gym.make("assistive_compiler/ArmManipulationJaco-v1").unwrapped  # the limp arm's weight on the scooper
    assert [t.welded for t in arm.manifest.tools] == [False] and arm.body_id("scooper_right") != arm.body_id("robot")
    arm.close()


def test_the_welded_tool_is_at_its_grip_on_the_robots_body(itch):
    itch.reset(seed=0)
    m = itch.manifest
    (att,) = m.tools
    tool_links = itch.links("scratcher")
    assert set(tool_links) == {"scratcher", "scratcher_tip"} and min(tool_links.values()) >= 0
    assert not set(tool_links) & set(itch.links("robot"))  # each link is one body's
    assert itch.body_id("scratcher") == itch.body_id("robot")
    hand = itch.link_pose("robot", att.parent_link)
    expected = pb.multiplyTransforms(*hand, att.position, att.orientation)
    for pose in (itch.base_pose("scratcher"), itch.link_pose("scratcher", "scratcher")):  # pybullet reads: float32
        assert np.allclose(pose[0], expected[0], atol=1e-6)
        assert abs(abs(float(np.dot(pose[1], expected[1]))) - 1.0) < 1e-6  # the grip's quaternion has 6 digits
    assert (
        f"tool scratcher: held by robot.{att.parent_link} (welded to it: links of the robot's body)"
        in describe_text(describe_scene(itch))
    )
    with pytest.raises(ValueError, match="'scratcher' is welded to the robot: it moves with the robot's hand"):
        itch.world.set_base_frame(itch.world.bodies["scratcher"], (0, 0, 1), (0, 0, 0, 1))


def test_contacts_and_distances_stay_the_tools_own(itch):
    """The scripted policy scratches: every contact of the robot's pybullet body with the person is
    either the scratcher's (on its links) or the arm's, never both, and distances follow."""
    policy = make_policy("scripted", itch)
    obs, _ = itch.reset(seed=0)
    snap, person = itch.snap, itch.body_id("person")  # this episode's variant
    tool_set = set(itch.links("scratcher").values())
    touched = 0
    for _ in range(itch.manifest.sim.episode_steps):
        obs, *_ = itch.step(policy(obs))
        every = pb.getContactPoints(bodyA=itch.body_id("robot"), bodyB=person, physicsClientId=itch.client)
        tool = snap.contacts(["scratcher"], ["person"])
        arm = snap.contacts(["robot"], ["person"])
        assert len(tool) + len(arm) == len(every)
        assert {cp[3] for cp in tool} <= tool_set and not {cp[3] for cp in arm} & tool_set
        if tool:
            touched += 1
            near = pb.getClosestPoints(itch.body_id("robot"), person, 0.5, physicsClientId=itch.client)
            tool_min = min(cp[8] for cp in near if cp[3] in tool_set)
            assert snap.closest_distance("scratcher", ["person"], 0.5) == pytest.approx(tool_min, abs=1e-12)
            assert itch.link_owner(tool[0][1], tool[0][3]) == "scratcher"
    assert touched >= 10  # it scratched
    near = pb.getClosestPoints(itch.body_id("robot"), person, 0.5, physicsClientId=itch.client)
    arm_only = [cp[8] for cp in near if cp[3] not in tool_set]
    assert snap.closest_distance("robot", ["person"], 0.5) == pytest.approx(min(arm_only, default=0.5))
