"""The person as an agent (runtime/human.py): policy joints driven by human actions, the hard and
γ-scaled joint limits and the pose-dependent arm limits enforced after every physics step,
weakness as a weaker motor, tremor on a policy joint, the human spaces and observation,
determinism, and the ``person.control.arm_limits`` spec field.

Real pybullet and real compiled artifacts: ``tests/data/human/arm.yaml`` is Feeding with the
right arm under a human policy; variants of it are written into tmp dirs and extend it.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pybullet as pb
import pytest

from assistive_compiler.cli import main
from assistive_compiler.compile.compiler import compile_task
from assistive_compiler.errors import SpecError
from assistive_compiler.paths import display
from assistive_compiler.person.arm_limits import ARM_LIMIT_JOINTS, AnalyticArmLimits, MLPArmLimits
from assistive_compiler.runtime.env import AssistiveEnv

DATA = Path(__file__).resolve().parents[1] / "data" / "human"
ARM = DATA / "arm.yaml"
ARM_GRAVITY = DATA / "arm_gravity.yaml"
ROBOT_ZERO = np.zeros(7, dtype=np.float32)


def build(tmp_path_factory, name: str, extra: str = "", base: Path = ARM) -> AssistiveEnv:
    """Compile ``base`` (plus ``extra`` YAML laid over it) for Jaco and build the env."""
    tmp = tmp_path_factory.mktemp(name)
    spec = base
    if extra:
        spec = tmp / f"{name}.yaml"
        spec.write_text(f"extends: {base}\n{extra}")
    return AssistiveEnv(compile_task(spec, "jaco", tmp / "out").out_dir)


@pytest.fixture(scope="module")
def arm_env(tmp_path_factory):
    e = build(tmp_path_factory, "arm")
    yield e
    e.close()


@pytest.fixture(scope="module")
def limited_env(tmp_path_factory):
    e = build(
        tmp_path_factory,
        "limited",
        "person:\n  impairments:\n    choices: [{kind: limited_range, joints: [person.right_arm], scale: 0.6}]\n",
    )
    yield e
    e.close()


def person(env):
    w = env.world
    return w.variant_bodies[w.active_variant.name]


def angles(env, joints) -> np.ndarray:
    p = person(env)
    return np.array([s[0] for s in pb.getJointStates(p.id, [p.joints[j] for j in joints], physicsClientId=env.client)])


def watch_physics_steps(env, check):
    """Run ``check()`` after the person's own after-physics-step work, at every physics step."""
    original = type(env.human).after_physics_step.__get__(env.human)

    def hooked():
        original()
        check()

    env.human.after_physics_step = hooked  # apply() installs the instance attribute in the world
    return lambda: env.human.__dict__.pop("after_physics_step", None)


# ---------------------------------------------------------------------------------------------
# spaces, observation, plain step


def test_human_spaces_and_observation(arm_env):
    m = arm_env.manifest
    policy = m.person.policy_joints
    assert policy == [
        "right_pecs_x",
        "right_pecs_y",
        "right_pecs_z",
        "right_shoulder_x",
        "right_shoulder_y",
        "right_shoulder_z",
        "right_elbow",
        "right_forearm",
        "right_wrist_x",
        "right_wrist_y",
    ]
    assert arm_env.human_action_space.shape == (len(policy),)
    assert np.all(arm_env.human_action_space.low == -1) and np.all(arm_env.human_action_space.high == 1)
    size = sum(t.size for t in m.observations["human"])
    assert size == 17 and arm_env.human_observation_space.shape == (size,)
    arm_env.reset(seed=0)
    obs = arm_env.observe_human()
    assert obs.shape == (size,) and obs.dtype == np.float32 and np.all(np.isfinite(obs))
    np.testing.assert_allclose(obs[3:13], angles(arm_env, policy), atol=1e-6)  # the policy joints' angles
    out = arm_env.step_agents(ROBOT_ZERO, arm_env.human_action_space.sample())
    assert len(out) == 6
    robot_obs, human_obs, reward, terminated, truncated, info = out
    assert robot_obs.shape == arm_env.observation_space.shape and human_obs.shape == (size,)
    assert np.all(np.isfinite(human_obs)) and np.isfinite(reward) and not terminated and not truncated
    assert {"terms", "task_success"} <= set(info)


def test_feeding_human_spaces(artifact):
    env = AssistiveEnv(artifact)
    try:
        assert env.human_action_space.shape == (4,)  # neck and head
        env.reset(seed=0)
        assert env.observe_human().shape == (23,) == env.human_observation_space.shape
    finally:
        env.close()


def test_without_a_human_action_the_person_holds(arm_env):
    """step() is step_agents(·, None): the same trajectory, the arm held at its start."""
    rng = np.random.default_rng(0)
    actions = rng.uniform(-1, 1, (15, 7)).astype(np.float32)
    arm_env.reset(seed=4)
    start = angles(arm_env, arm_env.manifest.person.policy_joints)
    plain = [arm_env.step(a)[0] for a in actions]
    held = angles(arm_env, arm_env.manifest.person.policy_joints)
    arm_env.reset(seed=4)
    agents = [arm_env.step_agents(a, None)[0] for a in actions]
    np.testing.assert_array_equal(np.array(plain), np.array(agents))
    assert np.abs(held - start).max() < 1e-3
    assert arm_env.world.after_physics_step is None  # nothing to enforce: no per-physics-step cost


def test_human_action_of_the_wrong_shape_is_refused(arm_env):
    arm_env.reset(seed=0)
    with pytest.raises(ValueError, match=r"human action must have shape \(10,\)"):
        arm_env.step_agents(ROBOT_ZERO, np.zeros(3))


# ---------------------------------------------------------------------------------------------
# limits


def saturated_actions(n_joints: int, seed: int = 0) -> list[np.ndarray]:
    """100 steps of +1, 100 of −1, then 200 random ±1."""
    rng = np.random.default_rng(seed)
    return (
        [np.ones(n_joints)] * 100 + [-np.ones(n_joints)] * 100 + [rng.choice([-1.0, 1.0], n_joints) for _ in range(200)]
    )


@pytest.mark.parametrize("which", ["urdf", "limited_range"])
def test_limits_hold_at_every_physics_step_under_saturated_actions(which, arm_env, limited_env):
    env = arm_env if which == "urdf" else limited_env
    policy = env.manifest.person.policy_joints
    info = env.reset(seed=1)[1]
    p = person(env)
    c = env.client
    urdf = np.array([pb.getJointInfo(p.id, p.joints[j], physicsClientId=c)[8:10] for j in policy])
    lo, hi = urdf[:, 0], urdf[:, 1]
    if which == "limited_range":
        assert info["impairment"]["kind"] == "limited_range" and info["impairment"]["scale"] == 0.6
        scaled = np.array([info["impairment"]["limits"][j] for j in policy])
        np.testing.assert_allclose(scaled, 0.6 * urdf)
        lo, hi = np.maximum(lo, scaled[:, 0]), np.minimum(hi, scaled[:, 1])  # γ-scaled (within the URDF's)
    seen: list[np.ndarray] = []

    def check():
        q = angles(env, policy)
        seen.append(q)
        assert np.all(q >= lo - 1e-6) and np.all(q <= hi + 1e-6), (q, lo, hi)

    undo = watch_physics_steps(env, check)
    try:
        for a in saturated_actions(len(policy)):
            env.step_agents(ROBOT_ZERO, a)
    finally:
        undo()
    seen = np.array(seen)
    assert len(seen) == 400 * env.manifest.sim.frame_skip
    # The actions did push joints to their bounds (the check is not vacuous).
    at_bound = (np.abs(seen - hi) < 1e-3) | (np.abs(seen - lo) < 1e-3)
    assert at_bound.any(axis=0).sum() >= 6


def test_targets_are_clamped_to_the_scaled_limits(limited_env):
    """A limited range narrows the policy joints' targets too (the reference implementation (Assistive Gym v1.0): clamp to the limits)."""
    env = limited_env
    env.reset(seed=2)
    env.step_agents(ROBOT_ZERO, np.ones(10))
    h = env.human
    assert np.all(h._base <= h._pol_upper + 1e-12) and np.all(h._base >= h._pol_lower - 1e-12)
    elbow = env.manifest.person.policy_joints.index("right_elbow")
    assert h._pol_upper[elbow] == 0.0 and math.isclose(h._pol_lower[elbow], 0.6 * math.radians(-128), rel_tol=1e-6)


# ---------------------------------------------------------------------------------------------
# weakness


def test_weaker_arm_reaches_less(tmp_path_factory):
    """Lifting the arm forward against gravity (shoulder flexion to 60°, the rest held by the same
    policy): with strength β = 0.25 the motors give a quarter of the torque and the elbow gets
    clearly less high than at full strength, for both body variants."""
    strong = build(
        tmp_path_factory, "strong", "person:\n  impairments:\n    choices: [{kind: none}]\n", base=ARM_GRAVITY
    )
    weak = build(
        tmp_path_factory,
        "weak",
        "person:\n  impairments:\n    choices: [{kind: weakness, strength: 0.25}]\n",
        base=ARM_GRAVITY,
    )
    try:
        policy = strong.manifest.person.policy_joints
        assert weak.human.m.person.max_force == 12.0
        for seed in (0, 1):
            rise = {}
            for name, env in (("strong", strong), ("weak", weak)):
                info = env.reset(seed=seed)[1]
                if name == "weak":
                    assert info["impairment"]["strength"] == 0.25
                    assert env.human.policy_forces == [3.0] * len(policy)
                p = person(env)
                c = env.client
                z0 = pb.getLinkState(p.id, p.links["right_elbow"], physicsClientId=c)[4][2]
                goal = angles(env, policy)
                goal[policy.index("right_shoulder_y")] = math.radians(-60)
                for _ in range(10):
                    a = np.clip((goal - angles(env, policy)) / env.human.delta_scale, -1, 1)
                    env.step_agents(ROBOT_ZERO, a)
                rise[name] = pb.getLinkState(p.id, p.links["right_elbow"], physicsClientId=c)[4][2] - z0
            assert rise["strong"] > 0.06, rise
            assert rise["weak"] < rise["strong"] - 0.04, rise
    finally:
        strong.close()
        weak.close()


# ---------------------------------------------------------------------------------------------
# pose-dependent arm limits


def test_arm_limit_guard_reverts_invalid_poses_in_the_running_sim(arm_env):
    """External rotation of the hanging arm with the elbow at 90°: the analytic model allows about
    60°, the box 90°. Every physics step ends in a valid pose; each invalid one is replaced by
    the last valid pose, at rest."""
    env = arm_env
    env.reset(seed=0)
    model = AnalyticArmLimits()
    arm = list(ARM_LIMIT_JOINTS["right"])
    p = person(env)
    c = env.client
    assert env.human.arm_side == "right" and isinstance(env.human.guard.model, AnalyticArmLimits)
    guard = env.human.guard
    events = {"reverted": 0, "steps": 0}
    original = type(env.human).after_physics_step.__get__(env.human)

    def hooked():
        before = angles(env, arm)
        last = guard.last_valid
        original()
        after = angles(env, arm)
        events["steps"] += 1
        assert bool(model.valid(after, "right")), np.degrees(after)
        if not model.valid(before, "right"):
            events["reverted"] += 1
            np.testing.assert_array_equal(after, last)
            velocities = [s[1] for s in pb.getJointStates(p.id, [p.joints[j] for j in arm], physicsClientId=c)]
            assert velocities == [0.0] * 4

    env.human.after_physics_step = hooked
    try:
        a = np.zeros(10)
        a[env.manifest.person.policy_joints.index("right_shoulder_z")] = -1.0  # external rotation
        for _ in range(40):
            env.step_agents(ROBOT_ZERO, a)
    finally:
        del env.human.after_physics_step
    assert events["steps"] == 40 * env.manifest.sim.frame_skip
    assert events["reverted"] > 10 and env.arm_limit_reverts == events["reverted"]
    z = angles(env, ["right_shoulder_z"])[0]
    assert math.radians(-75) < z < math.radians(-50)  # stopped near the model's bound, not the box's −90°


def test_a_user_mlp_from_the_spec_limits_the_arm(tmp_path_factory):
    """arm_limits: a .npz network (relative to the spec), copied into the artifact and evaluated
    with the reference's input convention: this one calls a pose valid while the elbow is flexed
    more than 1.2 rad, so extending it stops there."""
    tmp = tmp_path_factory.mktemp("mlp")
    (tmp / "nets").mkdir()
    k = 40.0  # sigmoid(k·(qe' − 1.2)), qe' = −elbow for a flexed elbow
    np.savez(tmp / "nets" / "elbow.npz", W0=np.array([[0.0], [0.0], [0.0], [k]]), b0=np.array([-1.2 * k]))
    spec = tmp / "mlp.yaml"
    spec.write_text(f"extends: {ARM}\nperson:\n  control:\n    arm_limits: nets/elbow.npz\n")
    result = compile_task(spec, "jaco", tmp / "out")
    person_m = result.manifest.person
    assert person_m.arm_limits == "arm_limits.npz" and (result.out_dir / "arm_limits.npz").is_file()
    assert person_m.arm_limits_sha256 and len(person_m.arm_limits_sha256) == 64
    env = AssistiveEnv(result.out_dir)
    try:
        assert isinstance(env.human.guard.model, MLPArmLimits)
        env.reset(seed=0)
        a = np.zeros(10)
        a[env.manifest.person.policy_joints.index("right_elbow")] = 1.0  # extend the elbow (towards 0)
        for _ in range(30):
            env.step_agents(ROBOT_ZERO, a)
        elbow = angles(env, ["right_elbow"])[0]
        assert -1.3 < elbow < -1.19 and env.arm_limit_reverts > 0
    finally:
        env.close()


# ---------------------------------------------------------------------------------------------
# tremor on a policy joint, determinism


def test_tremor_on_policy_joints_flips_every_step(tmp_path_factory):
    env = build(
        tmp_path_factory, "tremor", "person:\n  impairments:\n    choices: [{kind: tremor, amplitude_deg: 10}]\n"
    )
    try:
        env.reset(seed=0)
        assert env.world.after_physics_step is not None  # a tremoring person is checked every physics step
        elbow = [angles(env, ["right_elbow"])[0]]
        for _ in range(8):
            env.step_agents(ROBOT_ZERO, np.zeros(10))  # no intent: only the tremor moves it
            elbow.append(angles(env, ["right_elbow"])[0])
        moves = np.sign(np.diff(elbow))
        assert moves[0] > 0 and all(a == -b for a, b in zip(moves, moves[1:])), np.degrees(elbow)
        # The joint lags its target (gain 0.025) but keeps oscillating about the held −90° without drifting.
        assert np.ptp(elbow[2:]) > math.radians(0.5) and abs(np.mean(elbow[1:]) - math.radians(-90)) < math.radians(1)
    finally:
        env.close()


def test_same_seed_same_actions_same_trajectory(arm_env):
    rng = np.random.default_rng(7)
    robot = rng.uniform(-1, 1, (25, 7))
    human = rng.uniform(-1, 1, (25, 10))

    def rollout():
        obs, _ = arm_env.reset(seed=11)
        out = [obs, arm_env.observe_human()]
        for a, h in zip(robot, human):
            o, oh, r, *_ = arm_env.step_agents(a, h)
            out += [o, oh, np.array([r])]
        return np.concatenate(out)

    first = rollout()
    arm_env.step_agents(robot[0], -human[0])  # some other history in between
    second = rollout()
    np.testing.assert_array_equal(first, second)


# ---------------------------------------------------------------------------------------------
# the spec field


def test_a_wrong_arm_limits_value_is_located(tmp_path, capsys):
    text = f"extends: {ARM}\nperson:\n  control:\n    arm_limits: analytical\n"
    path = tmp_path / "bad.yaml"
    path.write_text(text)
    assert main(["validate", str(path)]) == 2
    err = capsys.readouterr().err
    assert "Traceback" not in err
    assert err.strip().splitlines() == [
        f"{display(path)}:4:17: person.control.arm_limits: must be 'analytic', 'none' or the path of a .npz file, "
        "got 'analytical' (did you mean 'analytic'?)"
    ]


def test_a_missing_arm_limits_file_is_located(tmp_path):
    path = tmp_path / "missing.yaml"
    path.write_text(f"extends: {ARM}\nperson:\n  control:\n    arm_limits: nets/none_here.npz\n")
    with pytest.raises(SpecError) as exc:
        compile_task(path, "jaco", tmp_path / "out")
    assert str(exc.value).startswith(f"{display(path)}:4:17: person.control.arm_limits: ")
    assert "none_here.npz: no such file" in str(exc.value)
    assert not (tmp_path / "out").exists()
