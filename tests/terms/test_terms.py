"""Every registered observation, reward and preference term on a constructed state, against a value
computed by hand.

States are built on a real :class:`Snapshot` of the compiled Feeding/Jaco world: handles are bound
with ``snap.point`` / ``snap.joints``, then the snapshot's arrays are written directly (positions,
orientations, velocities, frames, actions, particle events), or bodies are placed in pybullet and
the snapshot refreshed (joint angles, contacts). Contact-force expectations are sums over
``pybullet.getContactPoints`` / ``getClosestPoints`` computed here, independently of the terms.
Terms are called through the registry, ``terms(category)[name].fn(snap, params)``, with params the
term's own parameter model validated from its defaults plus the handles and values given.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pybullet as pb
import pytest

from assistive_compiler.references import LinkPoint, TargetPoint
from assistive_compiler.runtime.snapshot import Snapshot
from assistive_compiler.terms.catalog import terms
from assistive_compiler.terms.reads import ParticleEvents

REPO = Path(__file__).resolve().parents[2]
SPEC = REPO / "specs" / "tasks" / "feeding.yaml"

S = math.sqrt(0.5)
ROT_Z90 = (0.0, 0.0, S, S)  # 90° about +z: x → y, y → −x
ROT_ZM90 = (0.0, 0.0, -S, S)  # −90° about +z: x → −y, y → x
ROT_X90 = (S, 0.0, 0.0, S)
IDENTITY = (0.0, 0.0, 0.0, 1.0)
MOUTH_OFFSET = (0.0, -0.11, 0.03)


# ---------------------------------------------------------------------------------------------
# fixtures and helpers


def call(category: str, name: str, snap: Snapshot, **given):
    """Call registered term ``name`` with the model's defaults overridden by ``given``."""
    tdef = terms(category)[name]
    fields = tdef.params.model_fields
    assert set(given) <= set(fields), f"{name}: unknown params {set(given) - set(fields)}"
    values = {k: f.get_default(call_default_factory=True) for k, f in fields.items() if not f.is_required()}
    values.update(given)
    assert set(values) == set(fields), f"{name}: missing params {set(fields) - set(values)}"
    return tdef.fn(snap, tdef.params.model_validate(values))


def point(snap: Snapshot, body: str, link: str):
    return snap.point(LinkPoint(body=body, link=link))


def contacts(env, a: str, b: str) -> tuple:
    snap_ids = {"person": env.snap.handle("person").id}
    ida = snap_ids.get(a) or env.body_id(a)
    idb = snap_ids.get(b) or env.body_id(b)
    return pb.getContactPoints(bodyA=ida, bodyB=idb, physicsClientId=env.client)


def press_spoon_into_face(env, snap: Snapshot, depth: float = 0.01, steps: int = 2) -> None:
    """Move the (fixed-base) person so the mouth lies ``depth`` beyond the spoon, towards the head
    centre, and run physics: the spoon, held by the arm, pushes on the face. Then refresh."""
    w = env.world
    person = env.snap.handle("person")
    head, mouth, spoon = (
        env.snap.point(LinkPoint(body="person", link="head")),
        env.snap.point(TargetPoint(target="mouth")),
        env.snap.point(LinkPoint(body="spoon", link="spoon")),
    )
    hp, mp, sp = (np.array(env.snap.position(h), dtype=float) for h in (head, mouth, spoon))
    inward = (hp - mp) / np.linalg.norm(hp - mp)
    base_pos, base_orn = w.base_frame(person)
    w.set_base_frame(person, tuple(np.asarray(base_pos) + sp - mp - inward * depth), base_orn)
    for _ in range(steps):
        w.step_physics()
    snap.refresh()


def spoon_face_forces(env) -> list[float]:
    return [cp[9] for cp in contacts(env, "spoon", "person")]


def same_rotation(q, expected) -> bool:
    q, expected = np.asarray(q, dtype=float), np.asarray(expected, dtype=float)
    return bool(np.allclose(q, expected, atol=1e-12) or np.allclose(q, -expected, atol=1e-12))


# ---------------------------------------------------------------------------------------------
# observations


def test_position_in_world_robot_base_and_person_base_frames(snap):
    p = point(snap, "spoon", "spoon")
    snap.pos[p.slot] = (1.0, 2.0, 3.0)
    snap.set_frame("robot_base", (1.0, 0.0, 0.0), ROT_Z90)
    snap.set_frame("person_base", (0.5, -1.0, 2.0), ROT_ZM90)
    # world: unchanged
    np.testing.assert_allclose(call("observation", "position", snap, of=p, frame="world"), (1, 2, 3), atol=1e-12)
    # robot_base: p − t = (0, 2, 3); frame x = world y, frame y = world −x → (2, 0, 3)
    np.testing.assert_allclose(call("observation", "position", snap, of=p, frame="robot_base"), (2, 0, 3), atol=1e-12)
    # person_base: p − t = (0.5, 3, 1); frame x = world −y, frame y = world x → (−3, 0.5, 1)
    np.testing.assert_allclose(
        call("observation", "position", snap, of=p, frame="person_base"), (-3, 0.5, 1), atol=1e-12
    )
    # the default frame is the robot's base
    np.testing.assert_allclose(call("observation", "position", snap, of=p), (2, 0, 3), atol=1e-12)


def test_orientation_in_frame(snap):
    p = point(snap, "spoon", "spoon")
    snap.orn[p.slot] = ROT_X90
    snap.set_frame("robot_base", (7.0, -3.0, 1.0), ROT_Z90)
    snap.set_frame("person_base", (0.0, 0.0, 0.0), ROT_ZM90)
    assert same_rotation(call("observation", "orientation", snap, of=p, frame="world"), ROT_X90)
    # conj(q_frame)·q with q_frame = (0, 0, s, s), q = (s, 0, 0, s), s² = ½:
    #   x = s·s = ½; y = −s·s = −½; z = −s·s = −½; w = s·s = ½
    assert same_rotation(call("observation", "orientation", snap, of=p, frame="robot_base"), (0.5, -0.5, -0.5, 0.5))
    # with q_frame = (0, 0, −s, s): conj = (0, 0, s, s) → (½, ½, ½, ½)
    assert same_rotation(call("observation", "orientation", snap, of=p, frame="person_base"), (0.5, 0.5, 0.5, 0.5))


def test_displacement_is_a_vector(snap):
    of, to = point(snap, "spoon", "spoon"), point(snap, "person", "head")
    snap.pos[of.slot] = (1.0, 2.0, 3.0)
    snap.pos[to.slot] = (4.0, 6.0, 3.0)
    np.testing.assert_allclose(
        call("observation", "displacement", snap, of=of, to=to, frame="world"), (-3, -4, 0), atol=1e-12
    )
    snap.set_frame("robot_base", (0.0, 0.0, 0.0), ROT_Z90)
    at_origin = call("observation", "displacement", snap, of=of, to=to, frame="robot_base")
    # (−3, −4, 0) in a frame whose x is world y and whose y is world −x → (−4, 3, 0)
    np.testing.assert_allclose(at_origin, (-4, 3, 0), atol=1e-12)
    snap.set_frame("robot_base", (100.0, -50.0, 7.0), ROT_Z90)  # translation must not matter
    np.testing.assert_allclose(
        call("observation", "displacement", snap, of=of, to=to, frame="robot_base"), (-4, 3, 0), atol=1e-12
    )


def test_joint_angles_with_and_without_wrap(env, snap):
    m, w = env.manifest, env.world
    raw = [3 * math.pi / 2, 4.0, -3 * math.pi / 2, 1.0, 5.0, 2.0, 0.25]
    for name, q, lo, hi in zip(m.robot.arm_joints, raw, m.robot.joint_lower, m.robot.joint_upper):
        assert lo <= q <= hi
        pb.resetJointState(w.robot.id, w.robot.joints[name], q, physicsClientId=w.client)
    arm = snap.joints(m.joint_groups["robot.arm"])
    snap.refresh()
    np.testing.assert_allclose(call("observation", "joint_angles", snap, joints=arm, wrap=False), raw, atol=1e-12)
    wrapped = [-math.pi / 2, 4.0 - 2 * math.pi, math.pi / 2, 1.0, 5.0 - 2 * math.pi, 2.0, 0.25]
    np.testing.assert_allclose(call("observation", "joint_angles", snap, joints=arm, wrap=True), wrapped, atol=1e-12)
    np.testing.assert_allclose(
        call("observation", "joint_angles", snap, joints=arm), wrapped, atol=1e-12
    )  # wrap by default


def test_contact_force_observation_and_reward(env, snap):
    press_spoon_into_face(env, snap)
    spoon_face = sum(spoon_face_forces(env))
    arm_face = sum(cp[9] for cp in contacts(env, "robot", "person"))
    assert spoon_face > 0  # the construction pressed
    obs = call("observation", "contact_force", snap, a=["spoon"], b=["person"])
    assert obs.shape == (1,)
    assert obs[0] == pytest.approx(spoon_face, rel=1e-12)
    pooled = call("observation", "contact_force", snap, a=["robot", "spoon"], b=["person"])
    assert pooled[0] == pytest.approx(arm_face + spoon_face, rel=1e-12)
    reward = call("reward", "contact_force", snap, a=["spoon"], b=["person"])
    assert isinstance(reward, float) and reward == pytest.approx(spoon_face, rel=1e-12)
    # nothing touches the table: exactly zero
    assert call("reward", "contact_force", snap, a=["spoon"], b=["table"]) == 0.0


# ---------------------------------------------------------------------------------------------
# rewards


def test_distance_between_points_and_to_a_target(snap):
    a, b = point(snap, "spoon", "spoon"), point(snap, "person", "head")
    mouth = snap.point(TargetPoint(target="mouth"))
    snap.pos[a.slot] = (1.0, 2.0, 3.0)
    snap.pos[b.slot] = (4.0, 6.0, 3.0)
    assert call("reward", "distance", snap, a=a, b=b) == pytest.approx(5.0, abs=1e-12)
    # the mouth: head position + offset (identity orientation) placed at (4, 6, 3)
    snap.target_offsets["mouth"] = np.array(MOUTH_OFFSET)
    snap.pos[b.slot] = (4.0, 6.11, 2.97)
    snap.orn[b.slot] = IDENTITY
    assert call("reward", "distance", snap, a=a, b=mouth) == pytest.approx(5.0, abs=1e-12)


def test_action_norm_by_agent(snap):
    snap.actions = {"robot": np.array([3.0, 4.0]), "human": np.array([12.0])}
    assert call("reward", "action_norm", snap, agent="robot") == pytest.approx(5.0, abs=1e-12)
    assert call("reward", "action_norm", snap, agent="human") == pytest.approx(12.0, abs=1e-12)
    assert call("reward", "action_norm", snap, agent="all") == pytest.approx(13.0, abs=1e-12)
    assert call("reward", "action_norm", snap) == pytest.approx(13.0, abs=1e-12)  # all by default


def test_particle_counts(snap):
    snap.events["food"] = ParticleEvents(consumed=3, lost=2, hit=1, consumed_speed_sum=0.75)
    assert call("reward", "particles_consumed", snap, particles="food") == 3.0
    assert call("reward", "particles_lost", snap, particles="food") == 2.0
    snap.events["food"] = ParticleEvents()
    assert call("reward", "particles_consumed", snap, particles="food") == 0.0
    assert call("reward", "particles_lost", snap, particles="food") == 0.0


# ---------------------------------------------------------------------------------------------
# preferences (c_k ≤ 0)


def test_velocity_cost(snap):
    ee, spoon = point(snap, "robot", "j2s7s300_end_effector"), point(snap, "spoon", "spoon")
    snap.vel[ee.slot] = (2.0, 2.0, 1.0)  # speed 3
    snap.vel[spoon.slot] = (0.0, 0.0, -4.0)  # speed 4
    assert call("preference", "velocity", snap, of=[ee, spoon]) == pytest.approx(-7.0, abs=1e-12)
    assert call("preference", "velocity", snap, of=[ee]) == pytest.approx(-3.0, abs=1e-12)


def test_force_nontarget_without_and_with_a_target(env, snap):
    centre = point(snap, "wheelchair", next(iter(env.links("wheelchair"))))  # placed below
    press_spoon_into_face(env, snap)
    spoon_cps = contacts(env, "spoon", "person")
    total = sum(cp[9] for cp in spoon_cps) + sum(cp[9] for cp in contacts(env, "robot", "person"))
    assert total > 0
    assert call("preference", "force_nontarget", snap, onto=["person"], by=["robot", "spoon"]) == pytest.approx(
        -total, rel=1e-12
    )

    # Target: the point on the spoon of its strongest contact; only contacts within the radius count.
    strongest = max(spoon_cps, key=lambda cp: cp[9])
    snap.pos[centre.slot] = strongest[5]
    radius = 1e-4
    at_target = sum(cp[9] for cp in spoon_cps if np.linalg.norm(np.subtract(cp[5], strongest[5])) <= radius)
    assert 0 < at_target <= total
    value = call(
        "preference",
        "force_nontarget",
        snap,
        onto=["person"],
        by=["robot", "spoon"],
        target_tool=["spoon"],
        target=centre,
        target_radius_m=radius,
    )
    assert value == pytest.approx(-(total - at_target), abs=1e-12)
    # a radius that takes every contact leaves only the arm's force (none here)
    value = call(
        "preference",
        "force_nontarget",
        snap,
        onto=["person"],
        by=["robot", "spoon"],
        target_tool=["spoon"],
        target=centre,
        target_radius_m=10.0,
    )
    assert value == pytest.approx(-(total - sum(cp[9] for cp in spoon_cps)), abs=1e-12)


def test_high_force_below_and_above_threshold(env, snap):
    press_spoon_into_face(env, snap)
    force = sum(spoon_face_forces(env))
    assert force > 0
    assert call("preference", "high_force", snap, tool=["spoon"], onto=["person"], threshold_n=2 * force) == 0.0
    assert call(
        "preference", "high_force", snap, tool=["spoon"], onto=["person"], threshold_n=force / 2
    ) == pytest.approx(-force, rel=1e-12)
    assert (
        call("preference", "high_force", snap, tool=["spoon"], onto=["person"], threshold_n=10.0) == 0.0
    )  # the default 10 N


def test_food_hit_and_food_velocity(snap):
    snap.events["food"] = ParticleEvents(consumed=2, lost=1, hit=3, consumed_speed_sum=0.75)
    assert call("preference", "food_hit", snap, particles="food") == -3.0
    assert call("preference", "food_velocity", snap, particles="food") == pytest.approx(-0.75, abs=1e-15)
    snap.events["food"] = ParticleEvents()
    assert call("preference", "food_hit", snap, particles="food") == 0.0
    assert call("preference", "food_velocity", snap, particles="food") == 0.0


def test_dressing_force(env, snap):
    press_spoon_into_face(env, snap)
    force = sum(spoon_face_forces(env))
    assert force > 0
    assert call("preference", "dressing_force", snap, cloth=["spoon"], onto=["person"]) == pytest.approx(
        -force, rel=1e-12
    )
    assert call("preference", "dressing_force", snap, cloth=["spoon"], onto=["table"]) == 0.0


def test_pressure(env, snap):
    c = env.client
    spoon_id, person_id = env.body_id("spoon"), env.snap.handle("person").id
    # apart (just reset): no closest points within 1 cm → exactly 0
    snap.refresh()
    assert not pb.getClosestPoints(spoon_id, person_id, 0.01, physicsClientId=c)
    assert call("preference", "pressure", snap, tools=["spoon"], onto=["person"]) == 0.0
    # pressed: force / number of closest points within contact_distance_m
    press_spoon_into_face(env, snap)
    force = sum(spoon_face_forces(env))
    for distance in (0.01, 0.05):  # 4 and 19 closest points here
        count = len(pb.getClosestPoints(spoon_id, person_id, distance, physicsClientId=c))
        assert force > 0 and count > 0
        value = call("preference", "pressure", snap, tools=["spoon"], onto=["person"], contact_distance_m=distance)
        assert value == pytest.approx(-force / count, rel=1e-12)


# ---------------------------------------------------------------------------------------------
# targets with offsets


def test_target_offset_on_a_rotated_link(snap):
    head = point(snap, "person", "head")
    mouth = snap.point(TargetPoint(target="mouth"))
    assert mouth.slot == head.slot  # a target reads its link
    snap.target_offsets["mouth"] = np.array(MOUTH_OFFSET)
    snap.pos[head.slot] = (1.0, 2.0, 3.0)
    snap.orn[head.slot] = ROT_Z90
    # R_z(90°)·(0, −0.11, 0.03) = (0.11, 0, 0.03)
    np.testing.assert_allclose(snap.position(mouth), (1.11, 2.0, 3.03), atol=1e-12)
    np.testing.assert_allclose(
        call("observation", "position", snap, of=mouth, frame="world"), (1.11, 2.0, 3.03), atol=1e-12
    )
    snap.orn[head.slot] = IDENTITY
    np.testing.assert_allclose(snap.position(mouth), (1.0, 1.89, 3.03), atol=1e-12)


def test_target_offset_follows_the_person_variant(env):
    """After reset the env's mouth is the drawn variant's offset on its real head pose."""
    expected = {v.name: v.target_offsets["mouth"] for v in env.manifest.person.variants}
    assert expected == {"male_50th": (0.0, -0.11, 0.03), "female_50th": (0.0, -0.1, 0.03)}
    mouth = env.snap.point(TargetPoint(target="mouth"))
    seen = set()
    for seed in range(20):
        _, info = env.reset(seed=seed)
        variant = info["person_variant"]
        seen.add(variant)
        person = env.snap.handle("person")
        state = pb.getLinkState(
            person.id, person.links["head"], computeForwardKinematics=True, physicsClientId=env.client
        )
        rot = np.array(pb.getMatrixFromQuaternion(state[5])).reshape(3, 3)
        np.testing.assert_allclose(
            env.snap.position(mouth), np.array(state[4]) + rot @ np.array(expected[variant]), atol=1e-9
        )
        if len(seen) == 2:
            break
    assert seen == {"male_50th", "female_50th"}


# ---------------------------------------------------------------------------------------------
# the whole reward


def test_reward_is_the_weighted_sum_on_a_constructed_state(env):
    env.reset(seed=0)
    snap = env.snap
    # nothing touches the person after a reset
    for body in ("robot", "spoon"):
        assert not contacts(env, body, "person")
    spoon = snap.point(LinkPoint(body="spoon", link="spoon"))
    head = snap.point(LinkPoint(body="person", link="head"))
    snap.refresh()
    snap.pos[spoon.slot] = (0.0, 0.0, 1.0)
    snap.target_offsets["mouth"] = np.array(MOUTH_OFFSET)
    snap.pos[head.slot] = (0.3, 0.51, 0.97)  # mouth at (0.3, 0.4, 1.0): 0.5 m from the spoon
    snap.orn[head.slot] = IDENTITY
    snap.vel[:] = 0.0
    snap.vel[env.tool_point.slot] = (0.6, 0.8, 0.0)  # end effector at 1 m/s
    snap.actions = {"robot": np.array([0.3, 0.4, 0.0, 0.0, 0.0, 0.0, 1.2]), "human": np.zeros(0)}  # ‖a‖ = 1.3
    snap.events["food"] = ParticleEvents(consumed=2, lost=1, hit=1, consumed_speed_sum=0.5)

    values = {name: float(fn(snap)) for name, _, fn in env.reward_fns}
    expected_values = {
        "distance_to_mouth": 0.5,
        "action": 1.3,
        "food_eaten": 2.0,
        "food_spilled": 1.0,
        "preference_velocity": -1.0,
        "preference_force_nontarget": 0.0,
        "preference_high_force": 0.0,
        "preference_food_hit": -1.0,
        "preference_food_velocity": -0.5,
    }
    assert values == pytest.approx(expected_values, abs=1e-12)
    weights = {name: weight for name, weight, _ in env.reward_fns}
    assert weights == {t.name: t.weight for t in env.manifest.reward}
    assert weights == pytest.approx(
        {
            "distance_to_mouth": -1.0,
            "action": -0.01,
            "food_eaten": 20.0,
            "food_spilled": -5.0,
            "preference_velocity": 0.25,
            "preference_force_nontarget": 0.01,
            "preference_high_force": 0.05,
            "preference_food_hit": 1.0,
            "preference_food_velocity": 1.0,
        }
    )
    # −0.5 − 0.013 + 40 − 5 − 0.25 − 0 + 0 − 1 − 0.5
    reward = sum(weight * fn(snap) for _, weight, fn in env.reward_fns)
    assert reward == pytest.approx(32.737, abs=1e-12)
