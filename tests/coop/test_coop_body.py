"""The acting person obeys the body model (issue: co-optimisation), on Scratch Itch (right arm)
and Dressing (left arm) through the PettingZoo env, with real pybullet and real compiles:

* saturated human actions over a whole episode (200 env steps): no movable joint ever past its limit (the URDF's,
  or γ-scaled under a limited range) and no pose the pose-dependent arm-limit model calls
  invalid outlives the physics sub-step it appeared in, checked at every sub-step;
* a weak person (β = 0.25) gets the hand measurably less far than a strong one under the same actions;
* internal rotation of the shoulder swings the forearm into the chest, which stops it (self-collision).
"""

from __future__ import annotations

import itertools
from pathlib import Path

import numpy as np
import pybullet as pb
import pytest
from helpers import person

from assistive_compiler.coop import parallel_env
from assistive_compiler.person.arm_limits import ARM_LIMIT_JOINTS, AnalyticArmLimits

TASKS = Path(__file__).resolve().parents[2] / "specs" / "tasks"
SIDE = {"scratch_itch": "right", "dressing": "left"}  # the arm each task's person controls
IMPAIRMENTS = {
    "none": "{kind: none}",
    "limited_range": "{kind: limited_range, joints: [person.%s_arm], scale: 0.6}",
    "weak": "{kind: weakness, joints: [person.%s_arm], strength: 0.25}",
}
ROBOT_ZERO = np.zeros(7, dtype=np.float32)


@pytest.fixture(scope="module")
def coop_envs(tmp_path_factory):
    """(task, impairment) → the task's co-optimisation env for Jaco with that one impairment, built on first use."""
    made = {}

    def get(task: str, impairment: str):
        if (task, impairment) not in made:
            tmp = tmp_path_factory.mktemp(f"{task}-{impairment}")
            choice = IMPAIRMENTS[impairment].replace("%s", SIDE[task])
            spec = tmp / f"{task}.yaml"
            spec.write_text(f"extends: {TASKS / f'{task}.yaml'}\nperson:\n  impairments:\n    choices: [{choice}]\n")
            made[task, impairment] = parallel_env(spec, robot="jaco", out_dir=tmp / "out")
        return made[task, impairment]

    yield get
    for env in made.values():
        env.close()


def angles(env, joints) -> np.ndarray:
    p = person(env.env)
    return np.array(
        [s[0] for s in pb.getJointStates(p.id, [p.joints[j] for j in joints], physicsClientId=env.env.client)]
    )


def wrist(env, side: str) -> np.ndarray:
    p = person(env.env)
    return np.array(pb.getLinkState(p.id, p.links[f"{side}_wrist"], physicsClientId=env.env.client)[4])


def saturated_actions(n: int, seed: int) -> list[np.ndarray]:
    """40 env steps of +1 on every policy joint, 40 of −1, then 120 of random ±1: a whole episode (200)."""
    rng = np.random.default_rng(seed)
    return [np.ones(n)] * 40 + [-np.ones(n)] * 40 + [rng.choice([-1.0, 1.0], n) for _ in range(120)]


@pytest.mark.parametrize("impairment", ["none", "limited_range"])
@pytest.mark.parametrize("task", ["scratch_itch", "dressing"])
def test_saturated_actions_never_leave_the_limits(task, impairment, coop_envs):
    env = coop_envs(task, impairment)
    side = SIDE[task]
    _, infos = env.reset(seed=3)
    variant = env.env.active_variant
    movable = variant.movable_joints
    p, c = person(env.env), env.env.client
    urdf = np.array([pb.getJointInfo(p.id, p.joints[j], physicsClientId=c)[8:10] for j in movable])
    lo, hi = urdf[:, 0].copy(), urdf[:, 1].copy()
    drawn = infos["human"]["impairment"]
    assert drawn["kind"] == impairment
    if impairment == "limited_range":  # γ-scaled, within the URDF's (the paper's limits × γ)
        assert drawn["scale"] == 0.6 and set(ARM_LIMIT_JOINTS[side]) <= set(drawn["limits"])
        for k, j in enumerate(movable):
            if j in drawn["limits"]:
                a, b = drawn["limits"][j]
                np.testing.assert_allclose((a, b), 0.6 * urdf[k])
                lo[k], hi[k] = max(lo[k], a), min(hi[k], b)
    arm = list(ARM_LIMIT_JOINTS[side])
    model = AnalyticArmLimits()
    assert env.env.human.arm_side == side and isinstance(env.env.human.guard.model, AnalyticArmLimits)
    assert model.valid(angles(env, arm), side)  # the start is valid: the guard has a pose to revert to
    seen = []
    original = type(env.env.human).after_physics_step.__get__(env.env.human)

    def checked():  # at the end of every physics sub-step, after the body model has acted
        original()
        q = angles(env, movable)
        seen.append(q)
        assert np.all(q >= lo - 1e-6) and np.all(q <= hi + 1e-6), dict(zip(movable, np.degrees(q)))
        assert model.valid(angles(env, arm), side), np.degrees(angles(env, arm))

    env.env.human.after_physics_step = checked  # the world calls the instance attribute installed at each step
    try:
        for a in saturated_actions(len(env.action_space("human").low), seed=3):
            env.step({"robot": ROBOT_ZERO, "human": a})
        assert env.agents == []  # the episode's last step
    finally:
        del env.env.human.after_physics_step
    seen = np.array(seen)
    assert len(seen) == 200 * env.env.manifest.sim.frame_skip
    at_bound = (np.abs(seen - hi) < 1e-3) | (np.abs(seen - lo) < 1e-3)
    assert at_bound.any(axis=0).sum() >= 4  # the actions did drive joints to their limits
    assert env.env.arm_limit_reverts > 10  # and into poses the arm-limit model refused


@pytest.mark.parametrize("task, at_most", [("scratch_itch", 0.8), ("dressing", 0.9)])
def test_a_weak_person_reaches_less_far(task, at_most, coop_envs):
    """Shoulder flexion at full action for 5 env steps, the rest of the arm held by zero actions:
    the hand of a person with strength β = 0.25 travels clearly less than at full strength.
    Dressing runs the reference's 8 solver sub-steps (docs/physics.md): the motor pulls towards
    its target 8 times per physics step, so the weak arm comes closer (about 80%) to the full one."""
    side = SIDE[task]
    for seed in (0, 1):  # both body variants
        travel = {}
        for name in ("none", "weak"):
            env = coop_envs(task, name)
            _, infos = env.reset(seed=seed)
            if name == "weak":
                assert infos["human"]["impairment"]["strength"] == 0.25
                assert env.env.human.policy_forces == [0.25 * env.env.manifest.person.max_force] * 10
            start = wrist(env, side)
            a = np.zeros(10)
            a[env.env.manifest.person.policy_joints.index(f"{side}_shoulder_y")] = -1.0
            for _ in range(5):
                env.step({"robot": ROBOT_ZERO, "human": a})
            travel[name] = float(np.linalg.norm(wrist(env, side) - start))
        assert travel["none"] > 0.05 and travel["weak"] < at_most * travel["none"], travel


def into_chest(env, side: str, seed: int, self_collision: bool = True) -> tuple[float, int, float]:
    """Internal rotation of the shoulder with the elbow bent swings the forearm into the belly:
    60 env steps (``self_collision=False``: with every pair of the person's links switched off
    first, until the next seeded reset rebuilds the world). Returns the deepest penetration of forearm or hand into the chest's rigid link
    (m, negative), the number of self-contact points and their largest normal force (N)."""
    env.reset(seed=seed)
    p, c = person(env.env), env.env.client
    if not self_collision:
        for i, j in itertools.combinations(sorted(p.links.values()), 2):
            pb.setCollisionFilterPair(p.id, p.id, i, j, 0, physicsClientId=c)
    a = np.zeros(10)
    a[env.env.manifest.person.policy_joints.index(f"{side}_shoulder_z")] = 1.0 if side == "right" else -1.0
    deepest, contacts, force = 0.0, 0, 0.0
    for _ in range(60):
        env.step({"robot": ROBOT_ZERO, "human": a})
        for link in (f"{side}_elbow", f"{side}_wrist"):
            for cp in pb.getClosestPoints(p.id, p.id, 0.0, p.links[link], -1, physicsClientId=c):
                deepest = min(deepest, cp[8])
        points = pb.getContactPoints(p.id, p.id, physicsClientId=c)
        contacts += len(points)
        force = max([force] + [cp[9] for cp in points])
    return deepest, contacts, force


@pytest.mark.parametrize("task", ["scratch_itch", "dressing"])
def test_the_arm_does_not_pass_through_the_chest(task, coop_envs):
    env = coop_envs(task, "none")
    side = SIDE[task]
    pairs = env.env.manifest.person.self_collision
    assert {("chest", f"{side}_elbow"), ("chest", f"{side}_wrist")} <= set(
        pairs
    )  # forearm and hand vs the torso (head merged in)
    for seed in (0, 1):
        deepest, contacts, force = into_chest(env, side, seed)
        assert deepest > -0.01 and contacts > 0 and force > 1.0, (seed, deepest, contacts, force)
    # Without the pairs the same motion goes straight through (so the check above is not vacuous).
    try:
        deepest, contacts, _ = into_chest(env, side, 0, self_collision=False)
    finally:
        env.reset(seed=0)  # a seeded reset after stepping rebuilds the world: the pairs are back
    assert deepest < -0.03 and contacts == 0, deepest
