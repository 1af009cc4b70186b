"""The co-optimisation face (PettingZoo): names, spaces against the reference's table, the
PettingZoo API and seed tests for every shipped task × robot, the shared reward and joint episode
end, bit-for-bit replay, the located error for a person with nothing to control, the fixed-partner
Gymnasium wrapper and the coop rollout. Real compiles, real pybullet.

Envs made by name compile into the session's shared cache (conftest's ``shared_cache``), which
``test_all_envs.py`` also uses, so each shipped task × robot compiles once per session, not once
per file and xdist worker.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env
from helpers import at
from pettingzoo.test import parallel_api_test, parallel_seed_test

import assistive_compiler
from assistive_compiler import coop
from assistive_compiler.coop import AssistiveParallelEnv, FixedPartner, rollout_coop
from assistive_compiler.errors import SpecError
from assistive_compiler.gym_ids import shipped_ids
from assistive_compiler.paths import display
from assistive_compiler.runtime.env import AssistiveEnv

TASKS = Path(__file__).resolve().parents[2] / "specs" / "tasks"
NAMES = coop.ids()

#: The reference's human action and observation sizes (paper §III-B).
REFERENCE_HUMAN = {
    "Feeding": (4, 23),
    "Drinking": (4, 23),
    "ScratchItch": (10, 34),
    "BedBathing": (10, 28),
    "Dressing": (10, 28),
    "ArmManipulation": (10, 42),
}


@pytest.fixture(scope="module")
def feeding(artifact):
    env = AssistiveParallelEnv(artifact)
    yield env
    env.close()


def test_names_follow_the_reference():
    assert len(NAMES) == 36 == len(shipped_ids())
    assert (
        "FeedingJacoHuman-v1" in NAMES and "ScratchItchPR2Human-v1" in NAMES and "ArmManipulationPandaHuman-v1" in NAMES
    )
    assert coop.coop_name("assistive_compiler/BedBathingSawyer-v1") == "BedBathingSawyerHuman-v1"
    assert coop.spec_of("assistive_compiler/DressingBaxterHuman-v1") == (TASKS / "dressing.yaml", "baxter")
    with pytest.raises(
        ValueError, match=r"unknown co-optimisation env 'FeedingJacoHuman-v2' \(did you mean 'FeedingJacoHuman-v1'\?\)"
    ):
        coop.make("FeedingJacoHuman-v2")


def test_package_attributes():
    assert assistive_compiler.coop is coop
    assert callable(assistive_compiler.parallel_env)


@pytest.mark.parametrize("task", sorted(REFERENCE_HUMAN))
def test_human_sizes_match_the_reference(task, shared_cache):
    with shared_cache(f"{task}JacoHuman-v1"):
        env = coop.make(f"{task}JacoHuman-v1")
    try:
        assert env.possible_agents == ["robot", "human"]
        assert (env.action_space("human").shape[0], env.observation_space("human").shape[0]) == REFERENCE_HUMAN[task]
        assert env.action_space("robot") is env.env.action_space  # the single-agent env's
        assert env.state_space.shape[0] == env.observation_space("robot").shape[0] + REFERENCE_HUMAN[task][1]
        obs, _ = env.reset(seed=0)
        assert all(env.observation_space(a).contains(obs[a]) for a in env.agents)
    finally:
        env.close()


@pytest.mark.slow
@pytest.mark.parametrize("name", NAMES)
def test_pettingzoo_api_and_seed(name, shared_cache):
    with shared_cache(name):
        env = coop.make(name)
    try:
        parallel_api_test(env, num_cycles=4)
    finally:
        env.close()
    parallel_seed_test(lambda: coop.make(name))


def test_shared_reward_and_joint_episode_end(feeding):
    env = feeding
    obs, infos = env.reset(seed=0)
    assert set(infos) == {"robot", "human"} and "impairment" in infos["human"]
    steps = env.env.manifest.sim.episode_steps
    for k in range(steps):
        actions = {agent: env.action_space(agent).sample() for agent in env.agents}
        obs, rewards, terminations, truncations, infos = env.step(actions)
        assert rewards["robot"] == rewards["human"] and np.isfinite(rewards["robot"])
        assert terminations == {"robot": False, "human": False}
        assert truncations["robot"] == truncations["human"] == (k == steps - 1)
        for agent in ("robot", "human"):
            assert {"terms", "task_success", "success_metric", "total_force_on_human"} <= set(infos[agent])
        assert infos["human"]["terms"]["action"] == pytest.approx(
            np.linalg.norm(np.concatenate([actions["robot"], actions["human"]]))
        )
    assert env.agents == []
    with pytest.raises(RuntimeError, match="call reset"):
        env.step({"robot": np.zeros(7), "human": np.zeros(4)})


def test_actions_must_name_both_agents(feeding):
    feeding.reset(seed=0)
    with pytest.raises(ValueError, match="actions has no entry for 'human'"):
        feeding.step({"robot": np.zeros(7)})
    with pytest.raises(
        ValueError, match=r"unknown agent 'humans' in actions; expected 'robot' and 'human' \(did you mean 'human'\?\)"
    ):
        feeding.step({"robot": np.zeros(7), "humans": np.zeros(4)})


def test_reset_with_a_seed_replays_both_agents(feeding):
    env = feeding
    rng = np.random.default_rng(5)
    actions = [{"robot": rng.uniform(-1, 1, 7), "human": rng.uniform(-1, 1, 4)} for _ in range(30)]

    def episode():
        obs, _ = env.reset(seed=9)
        out = [obs["robot"], obs["human"], env.state()]
        for a in actions:
            obs, rewards, _, _, infos = env.step(a)
            out += [obs["robot"], obs["human"], np.array([rewards["robot"], infos["human"]["success_metric"]])]
        return np.concatenate(out)

    first = episode()
    env.reset()
    env.step({"robot": -actions[0]["robot"], "human": -actions[0]["human"]})  # another history in between
    np.testing.assert_array_equal(first, episode())


def test_a_holding_person_is_the_single_agent_env(feeding, artifact):
    """actions['human'] = None: the person holds, exactly the single-agent env's episode."""
    single = AssistiveEnv(artifact)
    try:
        rng = np.random.default_rng(1)
        robot = rng.uniform(-1, 1, (20, 7)).astype(np.float32)
        single.reset(seed=2)
        expected = [single.step(a)[:2] for a in robot]
        feeding.reset(seed=2)
        for a, (obs, reward) in zip(robot, expected):
            got, rewards, *_ = feeding.step({"robot": a, "human": None})
            np.testing.assert_array_equal(got["robot"], obs)
            assert rewards["human"] == reward
    finally:
        single.close()


def test_state_and_render(artifact):
    env = AssistiveParallelEnv(artifact, render_mode="rgb_array", render_size=(96, 72))
    try:
        obs, _ = env.reset(seed=0)
        np.testing.assert_array_equal(env.state(), np.concatenate([obs["robot"], obs["human"]]))
        frame = env.render()
        assert frame.shape == (72, 96, 3) and frame.dtype == np.uint8 and frame.std() > 5
    finally:
        env.close()


def test_a_person_with_nothing_to_control_is_a_located_error(tmp_path):
    text = f"extends: {TASKS / 'feeding.yaml'}\nperson:\n  control:\n    policy_joints: []\n"
    path = tmp_path / "static.yaml"
    path.write_text(text)
    with pytest.raises(SpecError) as exc:
        assistive_compiler.parallel_env(path, robot="jaco", out_dir=tmp_path / "out")
    assert str(exc.value) == (
        f"{display(path)}:{at(text, '[]')}: person.control.policy_joints: the person controls no joints, so it cannot be a "
        "co-optimisation agent; list the joint groups a human policy moves, e.g. [person.head] or [person.right_arm]"
    )
    assert not (tmp_path / "out").exists()  # refused before compiling


def test_fixed_human_partner_is_a_gymnasium_env(feeding):
    env = FixedPartner(feeding, fixed="human", policy="random")
    assert env.observation_space is feeding.observation_space("robot") and env.action_space.shape == (7,)
    check_env(env, skip_render_check=True)

    def episode():
        obs, _ = env.reset(seed=4)
        out = [obs]
        for _ in range(10):
            obs, reward, terminated, truncated, info = env.step(np.full(7, 0.5, np.float32))
            out += [obs, np.array([reward])]
        return np.concatenate(out)

    np.testing.assert_array_equal(episode(), episode())  # the random partner is reseeded with the env


def test_fixed_robot_partner_exposes_the_human(feeding):
    seen = []

    def robot_policy(obs):
        seen.append(obs.shape)
        return np.zeros(7, dtype=np.float32)

    env = FixedPartner(feeding, fixed="robot", policy=robot_policy)
    assert env.action_space.shape == (4,) and env.observation_space.shape == (23,)
    obs, _ = env.reset(seed=0)
    assert obs.shape == (23,)
    head = feeding.env.manifest.person.policy_joints
    obs2, reward, terminated, truncated, info = env.step(np.ones(4, dtype=np.float32))
    assert seen == [(25,)] and "arm_limit_reverts" in info and not (terminated or truncated)
    assert not np.array_equal(
        obs[3 : 3 + len(head)], obs2[3 : 3 + len(head)]
    )  # the head moved (its joint angles are observed)
    with pytest.raises(ValueError, match="unknown robot policy 'hold'; expected one of random, zero, scripted"):
        FixedPartner(feeding, fixed="robot", policy="hold")


def test_rollout_coop_with_a_holding_person_is_the_single_agent_rollout(feeding, artifact):
    from assistive_compiler.cli.run import rollout
    from assistive_compiler.policies import make_policy

    single = AssistiveEnv(artifact)
    try:
        expected = rollout(single, make_policy("scripted", single), seed=3)
    finally:
        single.close()
    got = rollout_coop(feeding, "scripted", "hold", seed=3)
    assert (
        got["return"] == expected["return"]
        and got["success"] == expected["success"]
        and got["terms"] == expected["terms"]
    )
    moving = rollout_coop(feeding, "scripted", "random", seed=3)
    assert moving["return"] != expected["return"]


# ---------------------------------------------------------------------------------------------
# the CLI


def test_cli_run_coop(artifact, capsys):
    from assistive_compiler.cli import main

    base = [
        "run",
        str(TASKS / "feeding.yaml"),
        "--robot",
        "jaco",
        "--episodes",
        "1",
        "--seed",
        "3",
        "--json",
        "--quiet",
        "--out-dir",
        str(artifact),
    ]
    assert main(base) == 0
    plain = json.loads(capsys.readouterr().out)
    assert main(base + ["--coop", "--human-policy", "hold"]) == 0
    held = json.loads(capsys.readouterr().out)
    assert held["human_policy"] == "hold" and held["episodes"][0]["return"] == plain["episodes"][0]["return"]
    assert main(base + ["--coop", "--human-policy", "random"]) == 0
    moving = json.loads(capsys.readouterr().out)
    assert moving["episodes"][0]["return"] != plain["episodes"][0]["return"]


def test_cli_bench_coop(capsys):
    from assistive_compiler.cli import main

    assert (
        main(
            [
                "bench",
                str(TASKS / "feeding.yaml"),
                "--robot",
                "jaco",
                "--coop",
                "--steps",
                "20",
                "--repeats",
                "1",
                "--json",
            ]
        )
        == 0
    )
    out = json.loads(capsys.readouterr().out)
    assert out["name"] == "FeedingJacoHuman-v1" and (out["human_action_size"], out["human_obs_size"]) == (4, 23)
    assert out["single_agent_env_steps_per_s"] > 0 and out["multi_agent_env_steps_per_s"] > 0
    assert out["multi_over_single"] == pytest.approx(
        out["multi_agent_env_steps_per_s"] / out["single_agent_env_steps_per_s"], rel=1e-2
    )


def test_bench_coop_goes_on_past_the_end_of_an_episode(tmp_path):
    """bench's default --steps (400) is longer than an episode (200): both envs start a new one
    when it ends, rather than the PettingZoo env refusing to step a finished episode."""
    from assistive_compiler.compile.compiler import compile_task
    from assistive_compiler.coop import bench_coop

    spec = tmp_path / "short.yaml"
    spec.write_text(f"extends: {TASKS / 'feeding.yaml'}\nsim:\n  episode_steps: 15\n")
    out = bench_coop(compile_task(spec, "jaco", tmp_path / "short").out_dir, steps=40, repeats=1, chunk=10)
    assert out["steps_per_repeat"] == 40
    assert out["single_agent_env_steps_per_s"] > 0 and out["multi_agent_env_steps_per_s"] > 0


def test_cli_coop_refuses_a_person_with_nothing_to_control(tmp_path, capsys):
    from assistive_compiler.cli import main

    text = f"extends: {TASKS / 'feeding.yaml'}\nperson:\n  control:\n    policy_joints: []\n"
    path = tmp_path / "static.yaml"
    path.write_text(text)
    assert main(["run", str(path), "--robot", "jaco", "--coop", "--out-dir", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert "Traceback" not in err
    assert err.strip().startswith(
        f"{display(path)}:{at(text, '[]')}: person.control.policy_joints: the person controls no joints"
    )
