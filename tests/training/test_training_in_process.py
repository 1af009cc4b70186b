"""The one-core path (``vec_env: in_process``: every env stepped in the trainer's own process, as
``ppo_one_core`` trains) and ``bench --training``: a run on it checkpoints, resumes, exports and
plays as ``--policy RUN_DIR`` exactly as its checkpoint acts; the training benchmark's figures add
up and count the updates the config implies."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np
import pytest
import yaml

pytest.importorskip("stable_baselines3", reason='needs the "train" extra (README: Training); CI installs it')

from helpers import REACH, train_reach

from assistive_compiler.cli import main
from assistive_compiler.run_dir import RunDir
from assistive_compiler.training.trained.evaluate import evaluate

pytestmark = pytest.mark.slow

REPO = Path(__file__).resolve().parents[2]
ROLLOUT, ENVS = 256, 2
BATCH = ROLLOUT * ENVS


def _config(tmp: Path, total_steps: int) -> Path:
    """ppo_one_core's shape, small: 2 envs in the trainer's process, 512-step batches."""
    config = yaml.safe_load((REPO / "specs" / "training" / "ppo_one_core.yaml").read_text())
    config["ppo"].update(rollout_steps=ROLLOUT, epochs=2)
    config.update(total_steps=total_steps, checkpoint_every_steps=BATCH * 2, seed=3)
    path = tmp / "in_process.yaml"
    path.write_text(yaml.safe_dump(config))
    return path


@pytest.fixture(scope="module")
def in_process_run(tmp_path_factory) -> Path:
    tmp = tmp_path_factory.mktemp("in-process")
    train_reach(_config(tmp, BATCH * 4), tmp / "run")
    return tmp / "run"


def test_the_envs_step_in_the_trainers_process_each_seeded_apart(tmp_path):
    from stable_baselines3.common.vec_env import DummyVecEnv

    from assistive_compiler.training.engines.sb3 import make_vec_env
    from assistive_compiler.training.train import compile_for_run

    result, _ = compile_for_run(str(REACH), "jaco", coop=False)
    venv = make_vec_env(result.out_dir, 3, seed=7, in_process=True)
    try:
        assert isinstance(venv, DummyVecEnv) and venv.num_envs == 3
        first = venv.reset()
        assert not np.allclose(first[0], first[1]) and not np.allclose(first[1], first[2])
    finally:
        venv.close()


def test_an_in_process_run_resumes_exports_and_plays_as_its_checkpoint(in_process_run, tmp_path, capsys):
    from assistive_compiler.policies.checkpoint import SB3Policy
    from assistive_compiler.policies.mlp import MLPPolicy
    from assistive_compiler.training.trained.export import export_run

    run = RunDir(in_process_run)
    assert run.info().config["vec_env"] == "in_process"
    steps, checkpoint = run.latest_checkpoint()
    assert steps == BATCH * 4 and sorted(run.complete_checkpoints()) == [BATCH * 2, BATCH * 4]

    # resume: the step count and the curve go on from the newest checkpoint
    train_reach(_config(tmp_path, BATCH * 4), in_process_run, "--resume", "--steps", str(BATCH * 6))
    assert run.latest_checkpoint()[0] == BATCH * 6
    rows = list(csv.DictReader((in_process_run / "curve.csv").open()))
    assert [int(r["steps"]) for r in rows] == [BATCH * k for k in range(1, 7)]
    steps, checkpoint = run.latest_checkpoint()

    # export: NumPy actions equal the checkpoint's, observation normalisation included
    record = export_run(in_process_run, tmp_path / "exported", episodes=2, seed=11, label="one core")
    exported, original = MLPPolicy.load(tmp_path / "exported"), SB3Policy(checkpoint, "ppo")
    assert record["trained_steps"] == steps and exported.obs_mean is not None
    for obs in np.random.default_rng(0).normal(0, 2, (40, exported.obs_dim)).astype(np.float32):
        assert np.allclose(exported(obs), original(obs), atol=1e-5)

    # --policy RUN_DIR plays the newest checkpoint: the same episodes as evaluate and the export
    capsys.readouterr()
    assert (
        main(
            ["run", str(REACH), "--robot", "jaco", "--policy", str(in_process_run), "--episodes", "2", "--seed", "11"]
            + ["--json", "--out", str(tmp_path / "artifact"), "--quiet"]
        )
        == 0
    )
    played = [round(e["return"], 3) for e in json.loads(capsys.readouterr().out)["episodes"]]
    assert played == [round(e["return"], 3) for e in evaluate(in_process_run, episodes=2, seed=11)["per_episode"]]
    assert played == record["evaluation"]["returns"]


def test_in_process_envs_are_refused_on_rllib_before_the_run_directory_is_written(tmp_path, capsys):
    out = tmp_path / "run"
    argv = ["train", str(REACH), "--robot", "jaco", "--config", str(_config(tmp_path, BATCH)), "--out", str(out)]
    assert main([*argv, "--engine", "rllib"]) == 2
    assert "vec_env: in_process steps every env in the trainer's process, which is built for the sb3 engine only" in (
        capsys.readouterr().err
    )
    assert not out.exists()


def test_bench_training_reports_throughput_and_where_the_time_goes(tmp_path, capsys):
    config = _config(tmp_path, BATCH)
    assert main(["bench", str(REACH), "--robot", "jaco", "--training", str(config), "--training-steps", "1024"]) == 0
    table = capsys.readouterr().out
    assert "env_steps_per_s" in table and "in_process" in table
    assert (
        main(["bench", str(REACH), "--robot", "jaco", "--training", str(config), "--training-steps", "1024", "--json"])
        == 0
    )
    (row,) = json.loads(capsys.readouterr().out)
    assert (row["config"], row["algorithm"], row["envs"], row["vec_env"], row["env_steps"]) == (
        "in_process",
        "ppo",
        ENVS,
        "in_process",
        1024,
    )
    assert row["updates"] == 1024 // BATCH  # one PPO update per 512-step batch
    assert row["updates_per_env_step"] == round(2 * (BATCH // 64) / BATCH, 3)  # 2 epochs of 8 minibatches
    assert row["env_share"] > 0.2 and row["update_share"] > 0.01
    assert row["env_share"] + row["update_share"] + row["rest_share"] == pytest.approx(1.0, abs=0.002)
    assert row["env_steps_per_s"] == pytest.approx(1024 / row["wall_s"], rel=0.01)
