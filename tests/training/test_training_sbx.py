"""SAC learned by SBX (``sac.library: sbx``, the SB3 team's JAX port; ``sac_one_core`` trains
with it): a run checkpoints with its replay buffer, resumes from it, exports to NumPy and plays as
``--policy RUN_DIR`` exactly as its checkpoint acts, and samples seeded actions for ``evaluate
--stochastic``; the options built on SB3's PyTorch SAC are refused with what to do."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import yaml

pytest.importorskip("sbx", reason='needs the "train" extra (README: Training); CI installs it')

from helpers import REACH, train_reach

from assistive_compiler.cli import main
from assistive_compiler.errors import SpecError
from assistive_compiler.run_dir import RunDir
from assistive_compiler.training.config import load_training_config
from assistive_compiler.training.trained.evaluate import evaluate

pytestmark = pytest.mark.slow

REPO = Path(__file__).resolve().parents[2]
CHECKPOINT_EVERY = 300


def _config(tmp: Path, total_steps: int, **sac) -> Path:
    """sac_one_core's settings, small: a 2×32 network, 200 random steps, a checkpoint every 300."""
    config = yaml.safe_load((REPO / "specs" / "training" / "sac_one_core.yaml").read_text())
    config["network"]["hidden"] = [32, 32]
    config["sac"].update(learning_starts=200, buffer_size=10_000, batch_size=64, **sac)
    config.update(total_steps=total_steps, checkpoint_every_steps=CHECKPOINT_EVERY, seed=5)
    path = tmp / "sbx.yaml"
    path.write_text(yaml.safe_dump(config))
    return path


@pytest.fixture(scope="module")
def sbx_run(tmp_path_factory) -> Path:
    tmp = tmp_path_factory.mktemp("sbx")
    train_reach(_config(tmp, 2 * CHECKPOINT_EVERY), tmp / "run")
    return tmp / "run"


def test_the_shipped_config_learns_with_sbx():
    config = load_training_config(REPO / "specs" / "training" / "sac_one_core.yaml")
    assert (config.algorithm, config.library, config.envs) == ("sac", "sbx", 1)


def test_an_sbx_run_resumes_with_its_replay_buffer_exports_and_plays_as_its_checkpoint(sbx_run, tmp_path, capsys):
    import sbx

    from assistive_compiler.policies.checkpoint import SB3Policy
    from assistive_compiler.policies.mlp import MLPPolicy
    from assistive_compiler.training.trained.export import export_run

    run = RunDir(sbx_run)
    assert run.info().library == "sbx"
    steps, checkpoint = run.latest_checkpoint()
    assert steps == 2 * CHECKPOINT_EVERY and (checkpoint / "replay_buffer.pkl").is_file()
    model = sbx.SAC.load(str(checkpoint / "model.zip"), device="cpu")
    model.load_replay_buffer(str(checkpoint / "replay_buffer.pkl"))
    assert model.replay_buffer.size() == 2 * CHECKPOINT_EVERY  # every transition so far, none lost

    # resume: the step count goes on, and the replay buffer holds the first session's data too
    train_reach(_config(tmp_path, 2 * CHECKPOINT_EVERY), sbx_run, "--resume", "--steps", str(3 * CHECKPOINT_EVERY))
    steps, checkpoint = run.latest_checkpoint()
    assert steps == 3 * CHECKPOINT_EVERY
    model.load_replay_buffer(str(checkpoint / "replay_buffer.pkl"))
    assert model.replay_buffer.size() == 3 * CHECKPOINT_EVERY
    assert not (run.path / "checkpoints" / f"step_{2 * CHECKPOINT_EVERY}" / "replay_buffer.pkl").exists()

    # export: NumPy actions (tanh of the mean) equal the checkpoint's as SBX itself computes them,
    # and the log-std goes with them
    record = export_run(sbx_run, tmp_path / "exported", episodes=2, seed=11, label="sbx")
    exported, original = MLPPolicy.load(tmp_path / "exported"), SB3Policy(checkpoint, "sac", library="sbx")
    assert record["trained_steps"] == steps and exported.samples and record["export_max_action_difference"] < 1e-5
    jax_actor = sbx.SAC.load(str(checkpoint / "model.zip"), device="cpu", custom_objects={"replay_buffer_class": None})
    for obs in np.random.default_rng(0).normal(0, 2, (40, exported.obs_dim)).astype(np.float32):
        assert np.allclose(exported(obs), original(obs), atol=1e-5)
        assert np.allclose(exported(obs), jax_actor.predict(obs, deterministic=True)[0], atol=1e-5)  # SBX's own

    # --policy RUN_DIR plays the newest checkpoint: the same episodes as evaluate and the export
    capsys.readouterr()
    argv = ["run", str(REACH), "--robot", "jaco", "--policy", str(sbx_run), "--episodes", "2", "--seed", "11"]
    assert main([*argv, "--json", "--out", str(tmp_path / "artifact"), "--quiet"]) == 0
    played = [round(e["return"], 3) for e in json.loads(capsys.readouterr().out)["episodes"]]
    assert played == [round(e["return"], 3) for e in evaluate(sbx_run, episodes=2, seed=11)["per_episode"]]
    assert played == record["evaluation"]["returns"]


def test_sampled_actions_are_seeded(sbx_run):
    first = evaluate(sbx_run, episodes=2, seed=3, stochastic=True)["per_episode"]
    again = evaluate(sbx_run, episodes=2, seed=3, stochastic=True)["per_episode"]
    mean = evaluate(sbx_run, episodes=2, seed=3)["per_episode"]
    assert [e["return"] for e in first] == [e["return"] for e in again]
    assert [e["return"] for e in first] != [e["return"] for e in mean]


def test_options_built_on_pytorch_sac_are_refused_with_what_to_do(tmp_path):
    with pytest.raises(SpecError) as raised:
        load_training_config(_config(tmp_path, 600, critic_layer_norm=True, actor_average_tau=0.01))
    assert (
        "critic_layer_norm, actor_average_tau are built on SB3's PyTorch SAC; library 'sbx' does not have it: "
        "set library: sb3, or leave them at the default"
    ) in str(raised.value)


@pytest.mark.parametrize(
    ("extra", "message"),
    [
        (["--engine", "rllib"], "sac.library: sbx is the SB3 engine's JAX SAC; use --engine sb3, or set library: sb3"),
        (["--coop", "--engine", "sb3"], "learns with sbx (sac.library): use a config with library: sb3"),
    ],
)
def test_rllib_and_coop_refuse_sbx_before_the_run_directory_is_written(tmp_path, capsys, extra, message):
    out = tmp_path / "run"
    argv = ["train", str(REPO / "specs" / "tasks" / "feeding.yaml"), "--robot", "jaco"]
    assert main([*argv, "--config", str(_config(tmp_path, 600)), "--out", str(out), *extra]) == 2
    assert message in capsys.readouterr().err
    assert not out.exists()
