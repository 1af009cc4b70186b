"""Markers on the person (:mod:`assistive_compiler.runtime.markers`), on Bed Bathing's wipe spots:
they ride on their limb, a contact of the clearing tool clears exactly the markers within the
set's radius of it, each marker once an episode, and a reset brings them all back."""

from __future__ import annotations

import numpy as np
import pybullet as pb
import pytest
from conftest import REPO

from assistive_compiler.compile.compiler import compile_task
from assistive_compiler.rotation import quat_rotate
from assistive_compiler.runtime.env import AssistiveEnv


@pytest.fixture(scope="module")
def bathing(tmp_path_factory):
    result = compile_task(REPO / "specs" / "tasks" / "bed_bathing.yaml", "jaco", tmp_path_factory.mktemp("bathing"))
    env = AssistiveEnv.from_compiled(result)
    yield env
    env.close()


def test_markers_ride_on_their_limb(bathing):
    env = bathing
    env.reset(seed=0)
    where, _ = env.marker_state("wipe_spots")
    for k, marker in enumerate(env.active_variant.markers["wipe_spots"]):
        pos, orn = env.link_pose("person", marker.link)
        assert np.allclose(where[k], np.asarray(pos) + quat_rotate(np.asarray(orn), marker.offset), atol=1e-9)


def _touch(env, marker: int) -> list[tuple]:
    """Put the clearing tool onto marker ``marker`` (no physics step: a collision pass) and return its
    contact points with the person."""
    ms = env.manifest.markers[0]
    where, _ = env.marker_state(ms.name)
    c, tool, person = env.client, env.body_id(ms.tool), env.body_id("person")
    link = env.link_index(ms.tool, ms.tool_link)
    pos, orn = env.link_pose(ms.tool, ms.tool_link)
    base_pos, base_orn = pb.getBasePositionAndOrientation(tool, physicsClientId=c)
    shift = where[marker] - np.asarray(pos)  # move the whole tool so that its surface link is at the marker
    pb.resetBasePositionAndOrientation(tool, np.asarray(base_pos) + shift, base_orn, physicsClientId=c)
    pb.performCollisionDetection(physicsClientId=c)
    return pb.getContactPoints(bodyA=tool, bodyB=person, linkIndexA=link, physicsClientId=c)


def test_a_contact_clears_the_markers_within_the_radius_once(bathing):
    env = bathing
    env.reset(seed=0)
    ms = env.manifest.markers[0]
    markers, snap = env.markers, env.snap
    count = len(env.active_variant.markers[ms.name])
    target = count // 2
    contacts = _touch(env, target)
    assert contacts, "the tool put on a marker touches the arm"
    where, remaining = env.marker_state(ms.name)
    on_arm = np.array([cp[6] for cp in contacts])
    near = np.linalg.norm(where[:, None, :] - on_arm[None, :, :], axis=2).min(axis=1) <= ms.radius
    markers.after_step()
    cleared = ~env.marker_state(ms.name)[1]
    assert cleared.any() and np.array_equal(cleared, near) and remaining.all()
    assert snap.markers_cleared(ms.name) == int(near.sum())  # what the reward term reads this step
    assert 0 < near.sum() < count  # a wiper's width, not the whole arm
    markers.after_step()  # the same contact again: nothing left there to clear
    assert snap.markers_cleared(ms.name) == 0 and np.array_equal(~env.marker_state(ms.name)[1], cleared)
    env.reset(seed=0)
    assert env.marker_state(ms.name)[1].all() and snap.markers_cleared(ms.name) == 0
