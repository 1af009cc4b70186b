"""Minari demonstration datasets: ``collect`` writes a dataset that ``minari.load_dataset`` loads,
equal to what ``run --json`` reports and to a direct rollout of the same seeds."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from conftest import FEEDING

minari = pytest.importorskip("minari", reason='needs the "datasets" extra')
REPO = Path(__file__).resolve().parents[2]
DATASET = "assistive_compiler/feeding-jaco/scripted-v0"


@pytest.fixture(scope="module")
def dataset(artifact, tmp_path_factory, monkeypatch_module):
    root = tmp_path_factory.mktemp("minari")
    monkeypatch_module.setenv("MINARI_DATASETS_PATH", str(root))
    result = subprocess.run(
        [
            sys.executable,
            "-m",
            "assistive_compiler.cli",
            "collect",
            str(FEEDING),
            "--robot",
            "jaco",
            "--policy",
            "scripted",
            "--episodes",
            "5",
            "--out",
            DATASET,
            "--root",
            str(root),
            "--artifact",
            str(artifact),
            "--quiet",
        ],
        cwd=REPO,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert result.returncode == 0, result.stderr
    assert f"wrote Minari dataset {DATASET} (5 episodes, 1000 steps" in result.stdout
    return minari.load_dataset(DATASET)


@pytest.fixture(scope="module")
def monkeypatch_module():
    mp = pytest.MonkeyPatch()
    yield mp
    mp.undo()


@pytest.mark.slow
def test_dataset_matches_run_json(dataset, artifact):
    run = subprocess.run(
        [
            sys.executable,
            "-m",
            "assistive_compiler.cli",
            "run",
            str(FEEDING),
            "--robot",
            "jaco",
            "--policy",
            "scripted",
            "--episodes",
            "5",
            "--seed",
            "0",
            "--out-dir",
            str(artifact),
            "--json",
            "--quiet",
        ],
        cwd=REPO,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert run.returncode == 0, run.stderr
    report = json.loads(run.stdout)
    meta = dataset.storage.metadata["assistive_compiler"]
    from assistive_compiler.artifact import Manifest

    assert meta["content_hash"] == Manifest.read(artifact).content_hash
    assert meta["seeds"] == [0, 1, 2, 3, 4] and meta["policy"] == "scripted"
    assert meta["successes"] == [e["success"] for e in report["episodes"]]
    assert meta["term_weights"] == report["term_weights"]
    episodes = list(dataset.iterate_episodes())
    assert [ep.id for ep in episodes] == [0, 1, 2, 3, 4]
    for ep, e in zip(episodes, report["episodes"]):
        assert ep.rewards.sum() == pytest.approx(e["return"], abs=1e-9)  # summation order differs, nothing else
        assert bool(ep.infos["task_success"][-1]) == e["success"]
        assert ep.infos["success_metric"][-1] == e["success_metric"]


@pytest.mark.slow
def test_dataset_equals_a_direct_rollout(dataset, artifact):
    from assistive_compiler.policies import make_policy
    from assistive_compiler.runtime.env import AssistiveEnv

    env = AssistiveEnv(artifact)
    policy = make_policy("scripted", env)
    assert dataset.observation_space == env.observation_space and dataset.action_space == env.action_space
    for ep in dataset.iterate_episodes():
        obs, _ = env.reset(seed=int(ep.id))  # episodes 0..4 were played from seeds 0..4
        observations, actions, rewards, terminations, truncations = [obs], [], [], [], []
        done = False
        while not done:
            action = policy(obs)
            obs, reward, terminated, truncated, _ = env.step(action)
            observations.append(obs), actions.append(action), rewards.append(reward)
            terminations.append(terminated), truncations.append(truncated)
            done = terminated or truncated
        assert np.array_equal(ep.observations, np.asarray(observations))
        assert np.array_equal(ep.actions, np.asarray(actions, dtype=np.float32))
        assert np.array_equal(ep.rewards, rewards)
        assert np.array_equal(ep.terminations, terminations) and np.array_equal(ep.truncations, truncations)
        assert ep.truncations[-1] and not ep.terminations.any() and len(ep.rewards) == 200
    env.close()
    recovered = dataset.recover_environment()
    assert type(recovered.unwrapped).__name__ == "AssistiveEnv"
    recovered.close()


def test_collect_into_an_existing_id_is_a_clear_error(dataset, artifact):
    result = subprocess.run(
        [
            sys.executable,
            "-m",
            "assistive_compiler.cli",
            "collect",
            str(FEEDING),
            "--robot",
            "jaco",
            "--episodes",
            "1",
            "--out",
            DATASET,
            "--artifact",
            str(artifact),
            "--quiet",
        ],
        cwd=REPO,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert result.returncode == 2 and "Traceback" not in result.stderr
    assert f"collect: A Minari dataset with ID {DATASET} already exists and it cannot be overridden" in result.stderr
