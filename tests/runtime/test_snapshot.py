"""The per-step snapshot every term reads (:mod:`assistive_compiler.runtime.snapshot`): one slot per
bound link, refreshed in one batched read to what pybullet reports, frames that invert exactly,
contact queries made once a step, and ``person`` following the episode's variant."""

from __future__ import annotations

import numpy as np
import pybullet as pb

from assistive_compiler.references import LinkPoint, TargetPoint
from assistive_compiler.rotation import quat_mul, quat_rotate

S = np.sqrt(0.5)


def test_one_slot_per_link_however_it_is_referenced(snap):
    spoon = snap.point(LinkPoint(body="spoon", link="spoon"))
    assert snap.point(LinkPoint(body="spoon", link="spoon")) == spoon
    head = snap.point(LinkPoint(body="person", link="head"))
    mouth = snap.point(TargetPoint(target="mouth"))  # a target on the head: the head's slot, an offset
    target = snap.world.m.targets["mouth"]
    assert (target.body, target.link) == ("person", "head")
    assert mouth.slot == head.slot and mouth.target == "mouth" and head.target is None
    assert snap.link_slot("person_male_50th", "head") == head.slot  # any variant's name is 'person'
    assert snap.pos.shape == snap.vel.shape == (2, 3) and snap.orn.shape == (2, 4)


def test_refresh_reads_link_frames_base_frames_and_targets_as_pybullet_has_them(env, snap):
    ee_name = env.manifest.robot.links["tool_mount"]
    ee = snap.point(LinkPoint(body="robot", link=ee_name))
    chest = snap.point(LinkPoint(body="person", link="chest"))  # the person's base link
    mouth = snap.point(TargetPoint(target="mouth"))
    for _ in range(3):
        env.step(env.action_space.sample())
    snap.refresh()
    c, robot = env.client, env.body_id("robot")
    state = pb.getLinkState(
        robot, env.link_index("robot", ee_name), computeLinkVelocity=1, computeForwardKinematics=1, physicsClientId=c
    )
    assert np.array_equal(snap.position(ee), state[4]) and np.array_equal(snap.orientation(ee), state[5])
    assert np.array_equal(snap.velocity(ee), state[6])
    # A base link is its URDF frame, not pybullet's centre of mass.
    frame = env.base_pose("person")
    assert np.allclose(snap.position(chest), frame[0], atol=1e-12)
    assert np.allclose(snap.orientation(chest), frame[1], atol=1e-12)
    com = pb.getBasePositionAndOrientation(env.body_id("person"), physicsClientId=c)[0]
    assert np.linalg.norm(np.asarray(com) - snap.position(chest)) > 0.1  # the chest's inertial is 0.23 m off
    # A target: its link's pose and the offset turned with it.
    head_pos, head_orn = env.link_pose("person", "head")
    offset = env.manifest.targets["mouth"].offset
    assert np.allclose(
        snap.position(mouth), np.asarray(head_pos) + quat_rotate(np.asarray(head_orn), offset), atol=1e-12
    )
    assert np.array_equal(snap.normal(mouth), np.zeros(3))  # not drawn on a surface: no normal


def test_frames_turn_and_translate_points_but_only_turn_vectors(snap):
    origin, turn = np.array([1.0, -2.0, 0.5]), np.array([0.0, 0.0, S, S])  # 90° about z
    snap.set_frame("robot_base", origin, turn)
    p = np.array([1.0, -1.0, 0.5])  # one metre along world y from the origin: the frame's −x
    assert np.allclose(snap.point_in_frame("robot_base", p), (1.0, 0.0, 0.0), atol=1e-12)
    assert np.allclose(snap.vector_in_frame("robot_base", np.array([0.0, 1.0, 0.0])), (1.0, 0.0, 0.0), atol=1e-12)
    q = np.array([0.1, 0.7, -0.2, 0.6]) / np.linalg.norm([0.1, 0.7, -0.2, 0.6])
    assert np.allclose(quat_mul(turn, snap.quat_in_frame("robot_base", q)), q, atol=1e-12)
    assert snap.point_in_frame("world", p) is p  # the world frame is no work


def test_contacts_are_queried_once_a_step(env, snap):
    env.reset(seed=0)
    calls = []
    real = pb.getContactPoints

    def counting(*args, **kwargs):
        calls.append(kwargs.get("bodyA"))
        return real(*args, **kwargs)

    snap.refresh()
    pb.getContactPoints = counting
    try:
        first = snap.contacts(["spoon"], ["person", "wheelchair"])
        again = snap.contacts(["spoon"], ["person", "wheelchair"])
        assert again is first and len(calls) == 2  # spoon–person, spoon–wheelchair: once each
        snap.contact_force(["spoon"], ["person", "wheelchair"])
        assert len(calls) == 2
        snap.refresh()  # a new step asks again
        snap.contacts(["spoon"], ["person", "wheelchair"])
        assert len(calls) == 4
    finally:
        pb.getContactPoints = real


def test_closest_distance_is_the_true_minimum_with_or_without_its_hint(env, snap):
    env.reset(seed=0)
    snap.begin_episode()
    c = env.client
    spoon, person = env.body_id("spoon"), env.body_id("person")
    truth = min(cp[8] for cp in pb.getClosestPoints(spoon, person, 2.0, physicsClientId=c))
    assert snap.closest_distance("spoon", ["person"], 2.0) == truth  # no hint yet
    assert snap.closest_distance("spoon", ["person"], 2.0) == truth  # from the hint
    assert snap.closest_distance("spoon", ["person"], truth / 2) == truth / 2  # nothing that near: the cap


def test_person_follows_the_episode_variant(env, snap):
    for variant in ("female_50th", "male_50th"):
        env.reset(seed=1, options={"person_variant": variant})
        snap.begin_episode()
        assert [h.id for h in snap.body_handles(["person"])] == [env.body_id(f"person_{variant}")]
        assert snap.handle("person").id == env.body_id("person")
