"""Self-collision of the person (paper §III-A): the reference's groups (each arm and leg against the
rest of the body) for the links that move in a task, exact after the compiler merges static links
(it keeps the girdle, stomach and hips, or a static thigh, out of a rigid link they would spoil),
without the pairs that already touch at the rest pose, and nothing at all when no limb moves
(Feeding: only the head moves, so its person and its physics are unchanged).

Real pybullet and real compiled artifacts (``tests/data/human/arm.yaml``: Feeding with the right
arm under a human policy; a right-leg variant written into a tmp dir).
"""

from __future__ import annotations

import itertools
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pybullet as pb
import pytest
from helpers import person

from assistive_compiler.compile.compiler import compile_task
from assistive_compiler.compile.self_collision import person_self_collision
from assistive_compiler.person.skeleton import SELF_COLLISION_GROUPS, self_collision_pairs
from assistive_compiler.runtime.env import AssistiveEnv

DATA = Path(__file__).resolve().parents[1] / "data" / "human"
ARM = DATA / "arm.yaml"
ROBOT_ZERO = np.zeros(7, dtype=np.float32)
ARM_LINKS = set(SELF_COLLISION_GROUPS["right_arm"].links)


@pytest.fixture(scope="module")
def arm_env(tmp_path_factory):
    """The right-arm person without the pose-dependent limits: only physics stops the arm."""
    tmp = tmp_path_factory.mktemp("arm")
    spec = tmp / "arm_free.yaml"
    spec.write_text(f"extends: {ARM}\nperson:\n  control:\n    arm_limits: none\n")
    e = AssistiveEnv(compile_task(spec, "jaco", tmp / "out").out_dir)
    yield e
    e.close()


@pytest.fixture(scope="module")
def leg_env(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("leg")
    spec = tmp / "leg.yaml"
    spec.write_text(f"extends: {ARM}\nperson:\n  control:\n    policy_joints: [person.right_leg]\n")
    e = AssistiveEnv(compile_task(spec, "jaco", tmp / "out").out_dir)
    yield e
    e.close()


def merged_links(env, variant: int = 0) -> list[str]:
    m = env.manifest
    root = ET.parse(env.artifact_dir / m.body(m.person.variants[variant].body).urdf).getroot()
    return [link.get("name") for link in root.findall("link")]


def self_contacts(env) -> list[tuple]:
    p = person(env)
    return pb.getContactPoints(p.id, p.id, physicsClientId=env.client)


def touching(env) -> list[tuple]:
    """Self-contact points that touch: penetrating or pushing. (pybullet also lists speculative
    points a little apart, with no force: the male forearm rests 1.2 mm from the belly.)"""
    return [(cp[3], cp[4], cp[8], cp[9]) for cp in self_contacts(env) if cp[8] < 0 or cp[9] > 0]


# ---------------------------------------------------------------------------------------------
# which pairs


def test_feeding_person_is_unchanged(env):
    """Only the head moves: no limb group moves, so no pair, no extra link, no flag."""
    m = env.manifest
    assert m.person.self_collision == []
    assert merged_links(env) == ["chest", "neck", "head_x_link", "head_y_link", "head"]
    env.reset(seed=0)
    for _ in range(5):
        env.step(np.zeros(7, dtype=np.float32))
    assert self_contacts(env) == ()


def test_arm_pairs_are_the_reference_groups_minus_touching_at_rest(arm_env):
    pairs = set(arm_env.manifest.person.self_collision)
    assert pairs, "a moving arm collides with the body"
    assert pairs <= self_collision_pairs()  # link names of the reference's groups
    assert all(ARM_LINKS & set(pair) for pair in pairs)  # only the moving arm's group
    assert {
        ("chest", "right_elbow"),
        ("chest", "right_wrist"),
        ("head", "right_wrist"),
    } <= pairs  # forearm, hand vs torso/legs; hand vs head
    assert ("chest", "right_shoulder") not in pairs  # the upper arm overlaps the chest capsule at rest
    assert not any("pecs" in a or "pecs" in b for a, b in pairs)  # girdles never collide


def test_moving_legs_keep_stomach_hips_and_the_other_thigh_apart(leg_env):
    """The right thigh must not collide with the stomach and hips it overlaps, but must with the
    chest, the arms and the left leg: the compiler keeps 'stomach' (hips merged into it) and the
    left thigh as links of their own instead of merging them into the chest."""
    links = merged_links(leg_env)
    assert {"stomach", "left_hip"} <= set(links) and "waist" not in links and "left_knee" not in links
    pairs = set(leg_env.manifest.person.self_collision)
    assert {("chest", "right_hip"), ("left_hip", "right_hip"), ("left_hip", "right_knee")} <= pairs
    assert not any("stomach" in pair for pair in pairs)


def test_the_plan_is_exact_on_the_unmerged_body():
    """person_self_collision on a rendered body: every pair of geometry links lands on surviving
    links whose pair decision is the reference's (for the moving groups)."""
    from assistive_compiler.library import PERSON_TEMPLATE_RELPATH
    from assistive_compiler.paths import templates_dir
    from assistive_compiler.person.body import body_measurements, format_fixed_joints
    from assistive_compiler.person.skeleton import REVOLUTE_JOINTS
    from assistive_compiler.templates import expand_template

    movable = {"right_elbow", "head_x", "head_y", "head_z"}  # only the forearm of the right arm moves
    fixed = {j: 0.0 for j in REVOLUTE_JOINTS if j not in movable}
    args = body_measurements("male").xacro_args(fixed_joints=format_fixed_joints(fixed))
    xml = expand_template(templates_dir() / PERSON_TEMPLATE_RELPATH, args)
    keep, pairs = person_self_collision(xml, set())
    # The static upper arm (forearm's neighbour, same group) and the girdle (excluded from the arm's
    # group) stay out of the chest, which the forearm must collide with.
    assert {"right_shoulder", "right_pecs"} <= keep
    assert ("chest", "right_elbow_link") in pairs and ("right_elbow_link", "right_shoulder") not in pairs
    nothing_moves = {j: 0.0 for j in REVOLUTE_JOINTS}
    xml = expand_template(
        templates_dir() / PERSON_TEMPLATE_RELPATH,
        body_measurements("male").xacro_args(fixed_joints=format_fixed_joints(nothing_moves)),
    )
    assert person_self_collision(xml, set()) == (set(), [])


# ---------------------------------------------------------------------------------------------
# physics


@pytest.mark.parametrize("which", ["arm", "leg"])
def test_no_self_contact_at_the_rest_pose(which, arm_env, leg_env):
    env = arm_env if which == "arm" else leg_env
    n = env.human_action_space.shape[0]
    for seed in range(4):
        env.reset(seed=seed)
        assert touching(env) == []
        for _ in range(5):
            env.step(ROBOT_ZERO)
            assert touching(env) == []
        for _ in range(5):
            env.step_agents(ROBOT_ZERO, np.zeros(n))
            assert touching(env) == []


def forearm_into_torso(env, seed: int, self_collision: bool) -> tuple[float, int, float]:
    """Internal rotation with the elbow at 90° swings the forearm into the belly: 60 env steps.
    Returns the deepest penetration of forearm or hand into the chest's rigid link (m, negative),
    the number of self-contact points and their largest normal force (N)."""
    env.reset(seed=seed)
    p = person(env)
    c = env.client
    if not self_collision:  # as before: no pair collides
        for a, b in itertools.combinations(sorted(p.links.values()), 2):
            pb.setCollisionFilterPair(p.id, p.id, a, b, 0, physicsClientId=c)
    action = np.zeros(10)
    action[env.manifest.person.policy_joints.index("right_shoulder_z")] = 1.0
    deepest, contacts, force = 0.0, 0, 0.0
    for _ in range(60):
        env.step_agents(ROBOT_ZERO, action)
        for link in ("right_elbow", "right_wrist"):
            for cp in pb.getClosestPoints(p.id, p.id, 0.0, p.links[link], -1, physicsClientId=c):
                deepest = min(deepest, cp[8])
        points = self_contacts(env)
        contacts += len(points)
        force = max([force] + [cp[9] for cp in points])
    if not self_collision:
        for a, b in env.manifest.person.self_collision:
            pb.setCollisionFilterPair(p.id, p.id, p.links[a], p.links[b], 1, physicsClientId=c)
    return deepest, contacts, force


@pytest.mark.parametrize("seed", [0, 1])  # female, male
def test_the_forearm_stops_at_the_torso(arm_env, seed):
    deepest, contacts, force = forearm_into_torso(arm_env, seed, self_collision=True)
    assert deepest > -0.02 and contacts > 0 and force > 1.0, (deepest, contacts, force)
    deepest, contacts, force = forearm_into_torso(arm_env, seed, self_collision=False)
    assert deepest < -0.05 and contacts == 0, (deepest, contacts)  # without it, straight through
