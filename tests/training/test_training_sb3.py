"""Stable-Baselines3 training end to end on the reach example (specs/examples/reach.yaml): PPO
really learns (the trained policy beats random actions by a wide margin on the same seeds), the
run directory describes itself, checkpoints resume, Ctrl-C leaves a resumable checkpoint, and
``evaluate`` and ``table`` work on the real run."""

from __future__ import annotations

import csv
import hashlib
import json
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

pytest.importorskip("stable_baselines3", reason='needs the "train" extra (README: Training); CI installs it')

from conftest import built_once
from helpers import assert_each_agent_acts_on_its_own_observation, assert_exported_pair_acts_as

from assistive_compiler.artifact import Manifest
from assistive_compiler.cli import main
from assistive_compiler.cli.run import rollout
from assistive_compiler.errors import SpecError
from assistive_compiler.policies import make_policy
from assistive_compiler.run_dir import RunDir
from assistive_compiler.runtime.env import AssistiveEnv
from assistive_compiler.training.bookkeeping.resume import check_resumable
from assistive_compiler.training.trained.evaluate import evaluate, evaluate_exported

pytestmark = pytest.mark.slow

REPO = Path(__file__).resolve().parents[2]
REACH = REPO / "specs" / "examples" / "reach.yaml"
EVAL_SEED, EVAL_EPISODES = 100, 20


@pytest.fixture(scope="module")
def reach_run(tmp_path_factory, worker_id) -> Path:
    """PPO (ppo_quick: 2 env processes, 30k steps) trained on reach for Jaco, once per test session
    (the module's tests may run on both xdist workers; each gets a copy)."""

    def train(out: Path) -> None:
        assert (
            main(["train", str(REACH), "--robot", "jaco", "--config", "ppo_quick", "--out", str(out), "--quiet"]) == 0
        )

    return built_once(tmp_path_factory, worker_id, "reach-jaco", train)


def test_ppo_learns_to_reach(reach_run):
    trained = evaluate(reach_run, episodes=EVAL_EPISODES, seed=EVAL_SEED)
    env = AssistiveEnv(RunDir(reach_run).artifact)
    policy = make_policy("random", env, seed=EVAL_SEED)
    random = [rollout(env, policy, EVAL_SEED + k) for k in range(EVAL_EPISODES)]
    env.close()
    random_return = float(np.mean([e["return"] for e in random]))
    # Random actions leave the spoon ~0.5 m from the mouth (return ≈ -20); the scripted IK
    # baseline gets ≈ -6.7; a policy that learned to reach gets within a few units of it.
    assert random_return < -15
    assert trained["mean_return"] > random_return + 10, (trained["mean_return"], random_return)
    # Within a few units of the scripted baseline's return, and ending a few centimetres from the
    # mouth where random actions end ~0.5 m away. Success (within 5 cm at the last step) is a knife
    # edge at this budget: the deterministic policy stops 5-6 cm out, and 0-55% of these seeds fall
    # inside depending on library versions and last-digit physics (0% since the robot's fixed links
    # were merged, every episode ending 5.6-6.3 cm out), so the test asks for the distance instead.
    assert trained["mean_return"] > -9.0, trained["mean_return"]
    final_m = [-e["success_metric"] for e in trained["per_episode"]]  # the reach term: minus the distance
    random_m = [-e["success_metric"] for e in random]
    assert float(np.mean(final_m)) < 0.08 and float(np.mean(random_m)) > 0.3, (final_m, random_m)


def test_run_directory_describes_itself(reach_run):
    run = RunDir(reach_run)
    info = run.info()
    manifest = json.loads((run.artifact / "manifest.json").read_text())
    assert info.content_hash == manifest["content_hash"] and info.engine == "sb3" and info.robot == "jaco"
    assert info.versions["torch"] and info.versions["stable-baselines3"]
    assert "total_steps: 30000" in (run.path / "config.yaml").read_text()
    rows = list(csv.DictReader(run.curve_csv.open()))
    steps = [int(r["steps"]) for r in rows]
    assert steps == sorted(steps) and steps[-1] >= 30000
    assert float(rows[-1]["mean_return"]) > float(rows[0]["mean_return"]) + 5  # the curve rises
    events = b"".join(p.read_bytes() for p in run.tb.rglob("events.out.tfevents.*"))
    for tag in (b"Episode_Reward/reach", b"Episode_Reward/action", b"Episode/success_rate", b"Episode/return"):
        assert tag in events
    assert Image.open(run.curve_png).size[0] > 500
    summary = json.loads(run.summary_json.read_text())
    assert summary["steps"] == steps[-1] and summary["interrupted"] is False
    assert run.latest_checkpoint()[0] == summary["steps"]


def test_evaluation_is_deterministic_for_a_seed(reach_run):
    first = evaluate(reach_run, episodes=3, seed=7)
    again = evaluate(reach_run, episodes=3, seed=7)
    other = evaluate(reach_run, episodes=3, seed=8)
    assert [e["return"] for e in first["per_episode"]] == [e["return"] for e in again["per_episode"]]
    assert [e["return"] for e in first["per_episode"]] != [e["return"] for e in other["per_episode"]]


def test_stochastic_evaluation_samples_as_training_did_and_is_seeded(reach_run, capsys):
    """--stochastic samples the policy's actions (the same seed, the same episodes; not the
    deterministic ones) and leaves the run's evaluation.json alone; a policy exported by an
    earlier version, which kept only the mean, refuses it with what to do."""
    saved = (reach_run / "evaluation.json").read_text() if (reach_run / "evaluation.json").is_file() else None
    deterministic = evaluate(reach_run, episodes=2, seed=5)
    sampled = evaluate(reach_run, episodes=2, seed=5, stochastic=True)
    assert sampled["actions"] == "stochastic" and deterministic["actions"] == "deterministic"
    assert sampled["per_episode"] == evaluate(reach_run, episodes=2, seed=5, stochastic=True)["per_episode"]
    assert [e["return"] for e in sampled["per_episode"]] != [e["return"] for e in deterministic["per_episode"]]
    assert main(["evaluate", str(reach_run), "--episodes", "1", "--seed", "5", "--stochastic"]) == 0
    assert "stochastic actions" in capsys.readouterr().out
    assert ((reach_run / "evaluation.json").read_text() if saved is not None else None) == saved
    assert main(["evaluate", "--policy", "pretrained:feeding-jaco", "--stochastic"]) == 2
    assert capsys.readouterr().err.strip() == (
        "error: evaluate --stochastic: pretrained:feeding-jaco was exported without its policy's log-std (by an "
        "earlier version), so it keeps only the deterministic action; evaluate its run directory, or export the run again"
    )


def test_export_ships_a_chosen_checkpoint_with_its_curve_up_to_it(reach_run, tmp_path, capsys):
    """export --checkpoint ships an earlier checkpoint (e.g. at the budget of the cell it is
    compared with): its steps, its evaluation, the learning curve cut at it; a missing one is a
    clear error naming those there are."""
    done = list(RunDir(reach_run).complete_checkpoints())
    first, out = done[0], tmp_path / "early"
    assert len(done) >= 2
    args = ["export", str(reach_run), "--out", str(out), "--checkpoint", str(first), "--episodes", "2"]
    assert main(args) == 0
    record = json.loads((out / "policy.json").read_text())
    assert record["trained_steps"] == first and record["evaluation"]["episodes"] == 2
    with (out / "curve.csv").open() as f:
        steps = [int(row["steps"]) for row in csv.DictReader(f)]
    assert steps and max(steps) <= first
    capsys.readouterr()
    assert main(["export", str(reach_run), "--out", str(tmp_path / "none"), "--checkpoint", "7"]) == 2
    have = ", ".join(f"{s:,}" for s in done)
    assert capsys.readouterr().err.strip().endswith(f"no complete checkpoint at 7 env steps; it has {have}")
    assert not (tmp_path / "none").exists()


def test_evaluate_command_json_and_render(reach_run, tmp_path, capsys):
    gif = tmp_path / "reach.gif"
    assert main(["evaluate", str(reach_run), "--episodes", "2", "--seed", "3", "--json", "--render", str(gif)]) == 0
    result = json.loads(capsys.readouterr().out)
    assert result["episodes"] == 2 and [e["seed"] for e in result["per_episode"]] == [3, 4]
    assert set(result) >= {"mean_return", "std_return", "success_rate", "mean_force_on_human_n", "std_force_on_human_n"}
    assert Image.open(gif).n_frames == 21  # 40 steps, every 2nd frame, plus the first
    assert json.loads((reach_run / "evaluation.json").read_text())["seed"] == 3


def test_evaluate_picks_an_earlier_checkpoint_and_keeps_the_runs_evaluation(reach_run, capsys):
    saved = (reach_run / "evaluation.json").read_text() if (reach_run / "evaluation.json").is_file() else None
    steps = list(RunDir(reach_run).complete_checkpoints())
    assert len(steps) == 3 and steps[-1] >= 30000  # every 10,000 env steps, at the end of an 800-step batch
    assert main(["evaluate", str(reach_run), "--checkpoint", str(steps[0]), "--episodes", "2", "--json"]) == 0
    early = json.loads(capsys.readouterr().out)
    assert early["trained_steps"] == steps[0] and early["checkpoint"].endswith(f"step_{steps[0]:010d}")
    newest = evaluate(reach_run, episodes=2)
    assert newest["trained_steps"] == steps[-1] and newest["per_episode"] != early["per_episode"]
    assert ((reach_run / "evaluation.json").read_text() if (reach_run / "evaluation.json").is_file() else None) == saved
    assert main(["evaluate", str(reach_run), "--checkpoint", "12345"]) == 2
    have = ", ".join(f"{s:,}" for s in steps)
    assert capsys.readouterr().err.strip().endswith(f"no complete checkpoint at 12,345 env steps; it has {have}")


def test_table_from_a_real_run(reach_run, tmp_path, capsys):
    out = tmp_path / "results.md"
    assert main(["table", str(reach_run), "--out", str(out)]) == 0
    evaluation = json.loads((reach_run / "evaluation.json").read_text())
    text = out.read_text()
    assert "| Task | PR2 | Jaco | Baxter | Sawyer | Success | Best robot as the paper's |" in text
    assert (
        "| Feeding | — (100.5) | — (83.8) | — (108.5) | — (95.6) | — (88% Baxter) | — |" in text
    )  # the paper's Table I beside ours
    assert f"| reach | — (—) | {evaluation['mean_return']:.1f} (—) |" in text
    rows = list(csv.DictReader((tmp_path / "results.csv").open()))
    mine = [r for r in rows if r["task"] == "reach" and r["robot"] == "jaco"][0]
    assert float(mine["mean_return"]) == pytest.approx(evaluation["mean_return"])
    assert Image.open(tmp_path / "results.png").size[0] > 500


def test_resume_continues_from_the_newest_checkpoint(reach_run, tmp_path):
    copy = tmp_path / "resumed"
    shutil.copytree(reach_run, copy)
    before = RunDir(copy).latest_checkpoint()[0]
    assert (
        main(
            [
                "train",
                str(REACH),
                "--robot",
                "jaco",
                "--config",
                "ppo_quick",
                "--out",
                str(copy),
                "--resume",
                "--steps",
                str(before + 800),
                "--quiet",
            ]
        )
        == 0
    )
    after = RunDir(copy).latest_checkpoint()[0]
    assert after == before + 800
    rows = list(csv.DictReader((copy / "curve.csv").open()))
    assert int(rows[-1]["steps"]) == after and int(rows[-1]["episodes"]) > int(rows[-2]["episodes"])


def test_resume_refuses_a_run_of_another_spec(reach_run, tmp_path, capsys):
    other = tmp_path / "reach_short.yaml"
    other.write_text(REACH.read_text().replace("episode_steps: 40", "episode_steps: 30"))
    copy = tmp_path / "run"
    shutil.copytree(reach_run, copy)
    code = main(
        ["train", str(other), "--robot", "jaco", "--config", "ppo_quick", "--out", str(copy), "--resume", "--quiet"]
    )
    err = capsys.readouterr().err
    assert code == 2
    assert f"{copy / 'run.json'}:1:1: --resume: this run trained a different compiled task" in err


def test_resume_accepts_the_same_task_compiled_by_another_compiler_version(reach_run, tmp_path):
    """A run recorded before content hashes left the input hash out (which covers the compiler
    source; the hash then covered the manifest file's JSON) resumes when today's compile of its spec
    gives the same files; an edited artifact does not."""
    copy = tmp_path / "older"
    shutil.copytree(reach_run, copy)
    run = RunDir(copy)
    today = Manifest.read(run.artifact).content_hash
    data = json.loads((run.artifact / "manifest.json").read_text()) | {"input_hash": "0" * 64, "content_hash": ""}
    bodies = sorted(data["bodies"], key=lambda b: b["urdf"])
    files = b"".join((run.artifact / b["urdf"]).read_bytes() for b in bodies)
    older_hash = hashlib.sha256(files + (json.dumps(data, indent=1, sort_keys=True) + "\n").encode()).hexdigest()
    (run.artifact / "manifest.json").write_text(json.dumps(data | {"content_hash": older_hash}, indent=1) + "\n")
    info = json.loads((copy / "run.json").read_text())
    (copy / "run.json").write_text(json.dumps({**info, "content_hash": older_hash}))
    assert older_hash != today and Manifest.read(run.artifact, verify=True).content_hash == older_hash
    assert check_resumable(run, today, "jaco", False, "sb3").content_hash == older_hash
    urdf = next(run.artifact.rglob("*.urdf"))
    urdf.write_text(urdf.read_text().replace("<robot ", "<robot  ", 1))
    with pytest.raises(SpecError, match="--resume: this run trained a different compiled task"):
        check_resumable(run, today, "jaco", False, "sb3")


def test_a_run_written_before_the_canonical_content_hash_resumes(tmp_path):
    """A real run directory written by the code before the canonical hash (tests/data/
    run_before_hash_rule: reach for Jaco, ppo_quick, 800 steps) resumes with today's compile of its
    spec and trains on from its checkpoint."""
    copy = tmp_path / "before"
    shutil.copytree(REPO / "tests" / "data" / "run_before_hash_rule", copy)
    recorded = RunDir(copy).info().content_hash
    args = ["train", str(REACH), "--robot", "jaco", "--config", "ppo_quick", "--out", str(copy)]
    assert main([*args, "--resume", "--steps", "1600", "--quiet"]) == 0
    newest = sorted(p.name for p in (copy / "checkpoints").iterdir())[-1]
    assert newest == "step_0000001600", newest
    assert RunDir(copy).info().content_hash == recorded  # the run keeps the task it was started on
    # its policy is shipped with the hash today's code gives that task, not the older rule's number
    from assistive_compiler.training.trained.export import export_run

    exported = export_run(copy, tmp_path / "exported", episodes=1, seed=0)
    today = Manifest.read(RunDir(copy).artifact)
    assert exported["content_hash"] == today.hash_of(RunDir(copy).artifact) != recorded


@pytest.mark.parametrize("stop", [signal.SIGINT, signal.SIGTERM], ids=["ctrl-c", "sigterm"])
def test_ctrl_c_or_sigterm_leaves_a_resumable_checkpoint(tmp_path, stop):
    out = tmp_path / "interrupted"
    proc = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "assistive_compiler.cli",
            "train",
            str(REACH),
            "--config",
            "ppo_quick",
            "--envs",
            "1",
            "--steps",
            "1000000",
            "--out",
            str(out),
            "--quiet",
        ],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    deadline = time.time() + 120
    while time.time() < deadline and not (
        (out / "curve.csv").is_file() and len((out / "curve.csv").read_text().splitlines()) > 1
    ):
        time.sleep(0.5)
    proc.send_signal(stop)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 130, err
    assert "interrupted: checkpoint written; continue with the same command and --resume" in err
    steps, checkpoint = RunDir(out).latest_checkpoint()
    assert 400 <= steps < 1_000_000 and (checkpoint / "model.zip").is_file()
    assert json.loads((out / "summary.json").read_text())["interrupted"] is True


# --------------------------------------------------------------------------------------------
# SAC (the recipe's algorithm), export to a NumPy policy, and trained policies by source

SAC_TINY = """algorithm: sac
network: {hidden: [32, 32], activation: relu}
sac: {learning_starts: 100, buffer_size: 5000, batch_size: 32}
total_steps: 600
envs: 1
seed: 3
checkpoint_every_steps: 400
eval_episodes: 2
"""


@pytest.fixture(scope="module")
def sac_run(tmp_path_factory) -> Path:
    """A few hundred SAC steps on reach: enough to update the networks, checkpoint and resume."""
    root = tmp_path_factory.mktemp("sac")
    config = root / "sac_tiny.yaml"
    config.write_text(SAC_TINY)
    out = root / "reach-sac"
    assert main(["train", str(REACH), "--robot", "jaco", "--config", str(config), "--out", str(out), "--quiet"]) == 0
    return out


def test_sac_run_checkpoints_with_its_replay_buffer_and_resumes(sac_run, tmp_path):
    run = RunDir(sac_run)
    steps = sorted(int(p.name.split("_")[1]) for p in run.checkpoints.glob("step_*"))
    assert steps == [400, 600]
    # Only the newest checkpoint keeps the replay buffer (the bulk of a checkpoint).
    assert not (run.checkpoint_dir(400) / "replay_buffer.pkl").exists()
    assert (run.checkpoint_dir(600) / "replay_buffer.pkl").is_file()
    assert json.loads((run.checkpoint_dir(600) / "COMPLETE").read_text())["algorithm"] == "sac"
    assert run.info().algorithm == "sac" and "ppo" not in (sac_run / "config.yaml").read_text()
    copy = tmp_path / "resumed"
    shutil.copytree(sac_run, copy)
    assert (
        main(
            [
                "train",
                str(REACH),
                "--robot",
                "jaco",
                "--config",
                str(sac_run / "config.yaml"),
                "--out",
                str(copy),
                "--resume",
                "--steps",
                "800",
                "--quiet",
            ]
        )
        == 0
    )
    from stable_baselines3 import SAC

    model = SAC.load(str(RunDir(copy).latest_checkpoint()[1] / "model.zip"))
    assert model.num_timesteps == 800
    model.load_replay_buffer(str(RunDir(copy).latest_checkpoint()[1] / "replay_buffer.pkl"))
    assert model.replay_buffer.size() == 800  # the resumed run kept the first 600 transitions


@pytest.mark.parametrize(("engine", "alpha"), [("sb3", 1.0), ("sb3", 0.01), ("rllib", 0.01)])
def test_a_learned_temperature_starts_where_the_config_says(sac_run, tmp_path, engine, alpha):
    """sac.initial_ent_coef: the α that ent_coef 'auto' starts from (SB3's and RLlib's default 1.0)."""
    from assistive_compiler.training.config import load_training_config
    from assistive_compiler.training.engines import sb3
    from assistive_compiler.training.learners.choice import new_model

    path = tmp_path / "sac.yaml"
    path.write_text(SAC_TINY.replace("batch_size: 32}", f"batch_size: 32, initial_ent_coef: {alpha}}}"))
    config = load_training_config(path)
    if engine == "sb3":
        venv = sb3.make_vec_env(RunDir(sac_run).artifact, 1, 0)
        model = new_model(venv, config, RunDir(tmp_path / "run"))
        venv.close()
        assert float(model.log_ent_coef.exp()) == pytest.approx(alpha)
    else:
        pytest.importorskip("ray")
        from assistive_compiler.training.engines.rllib import build_sac_config

        assert build_sac_config(RunDir(sac_run), config, {}, False).initial_alpha == alpha


def test_layer_normed_critics_train_resume_and_stay_bounded_where_plain_ones_grow(sac_run, tmp_path):
    """sac.critic_layer_norm: every hidden layer of both critics (and their targets) is
    Linear → LayerNorm → ReLU; the run trains, checkpoints, loads back with that policy class and
    resumes. Their point: a layer-normalised critic's value cannot grow with its input (far from
    the data it stays within what its last layer allows), where the plain critic's grows with it."""
    import torch
    from stable_baselines3 import SAC
    from torch import nn

    from assistive_compiler.training.learners.critics import LayerNormSACPolicy

    config = tmp_path / "sac_ln.yaml"
    config.write_text(SAC_TINY.replace("batch_size: 32}", "batch_size: 32, critic_layer_norm: true}"))
    out = tmp_path / "reach-sac-ln"
    args = ["train", str(REACH), "--robot", "jaco", "--config", str(config), "--out", str(out), "--quiet"]
    assert main(args) == 0
    assert main([*args, "--resume", "--steps", "800"]) == 0
    run = RunDir(out)
    normed = SAC.load(str(run.checkpoint_dir(800) / "model.zip"), device="cpu")
    assert isinstance(normed.policy, LayerNormSACPolicy) and normed.num_timesteps == 800
    for critic in (normed.critic, normed.critic_target):
        for q in critic.q_networks:
            kinds = [type(m) for m in q]
            assert kinds == [nn.Linear, nn.LayerNorm, nn.ReLU, nn.Linear, nn.LayerNorm, nn.ReLU, nn.Linear]
    assert SAC.load(str(run.checkpoint_dir(400) / "model.zip"), device="cpu").policy.critic.state_dict().keys() == (
        normed.critic.state_dict().keys()
    )
    plain = SAC.load(str(RunDir(sac_run).latest_checkpoint()[1] / "model.zip"), device="cpu")
    assert not any(isinstance(m, nn.LayerNorm) for m in plain.critic.modules())
    obs = torch.as_tensor(
        np.random.default_rng(0).normal(size=(64, normed.observation_space.shape[0])), dtype=torch.float32
    )
    act = torch.zeros(64, normed.action_space.shape[0])

    def growth(model) -> float:
        with torch.no_grad():
            near, far = (torch.min(*model.critic(obs * k, act)).abs().mean() for k in (1e3, 1e6))
        return float(far / near)

    assert growth(normed) == pytest.approx(1.0, abs=0.01)  # bounded: the same value ever further out
    assert growth(plain) > 100.0  # a ReLU critic is linear far out: ×1000 input, ~×1000 value
    evaluated = evaluate(out, episodes=2, seed=EVAL_SEED)  # a run directory's policy evaluates as any other
    assert evaluated["trained_steps"] == 800


@pytest.mark.parametrize(
    ("setting", "message"),
    [
        (
            "ent_coef: 0.1",
            "sac.ent_coef 0.1: the rllib engine learns the entropy temperature; use ent_coef: auto",
        ),
        (
            "critic_layer_norm: true",
            "sac.critic_layer_norm: layer-normalised critics are built for the sb3 engine only; "
            "use --engine sb3, or set critic_layer_norm: false",
        ),
        (
            "conservative_weight: 5",
            "sac.conservative_weight: conservative critics are built for the sb3 engine only; "
            "use --engine sb3, or set conservative_weight: 0",
        ),
        (
            "actor_average_tau: 0.001",
            "sac.actor_average_tau: the averaged actor is built for the sb3 engine only; "
            "use --engine sb3, or set actor_average_tau: 0",
        ),
    ],
    ids=["fixed-temperature", "layer-norm", "conservative", "averaged-actor"],
)
def test_sb3_only_sac_settings_are_refused_on_rllib_before_the_run_directory_is_written(
    tmp_path, capsys, setting, message
):
    """The refusal comes before compiling, starting Ray or writing anything: no half-made run
    directory is left for a later --resume to trip over."""
    pytest.importorskip("ray")
    path = tmp_path / "sac.yaml"
    path.write_text(SAC_TINY.replace("batch_size: 32}", f"batch_size: 32, {setting}}}"))
    out = tmp_path / "refused"
    code = main(
        [
            "train",
            str(REACH),
            "--robot",
            "jaco",
            "--config",
            str(path),
            "--engine",
            "rllib",
            "--out",
            str(out),
            "--quiet",
        ]
    )
    assert code == 2
    assert message in capsys.readouterr().err
    assert not out.exists()


def test_an_actor_learning_rate_of_its_own_slows_the_actor_and_not_the_critics(sac_run, tmp_path):
    """sac.actor_learning_rate: with the same seed and steps as sac_run, an actor at a thousandth of
    the rate barely moves between the checkpoints at 400 and 600 steps, while its critics learn
    as sac_run's do; a resumed run keeps the actor's rate."""
    import torch
    from stable_baselines3 import SAC

    config = tmp_path / "sac_slow_actor.yaml"
    config.write_text(SAC_TINY.replace("batch_size: 32}", "batch_size: 32, actor_learning_rate: 3.0e-7}"))
    out = tmp_path / "slow-actor"
    train = ["train", str(REACH), "--robot", "jaco", "--config", str(config), "--out", str(out), "--quiet"]
    assert main(train) == 0

    def movement(run: Path, part: str) -> float:
        weights = []
        for step in (400, 600):
            model = SAC.load(
                str(RunDir(run).checkpoint_dir(step) / "model.zip"),
                device="cpu",
                custom_objects={"replay_buffer_class": None},
            )
            weights.append(torch.cat([p.detach().view(-1) for p in getattr(model, part).parameters()]))
        return float((weights[1] - weights[0]).norm() / weights[0].norm())

    assert movement(out, "actor") < movement(sac_run, "actor") / 100
    assert movement(out, "critic") == pytest.approx(movement(sac_run, "critic"), rel=0.5)
    assert main([*train[:-1], "--resume", "--steps", "700", "--quiet"]) == 0
    resumed = SAC.load(str(RunDir(out).checkpoint_dir(700) / "model.zip"), device="cpu")
    assert resumed.actor.optimizer.param_groups[0]["lr"] == 3.0e-7  # the last actor step's rate
    assert resumed.critic.optimizer.param_groups[0]["lr"] == 3.0e-4
    pytest.importorskip("ray")
    from assistive_compiler.training.config import load_training_config
    from assistive_compiler.training.engines.rllib import build_sac_config

    rllib = build_sac_config(RunDir(out), load_training_config(config), {}, False)  # RLlib has the setting itself
    assert (rllib.actor_lr, rllib.critic_lr, rllib.alpha_lr) == (3.0e-7, 3.0e-4, 3.0e-4)


def test_the_averaged_actor_follows_the_actor_by_polyak_steps(sac_run):
    """sac.actor_average_tau: after each actor step, average ← (1 − τ)·average + τ·actor, exactly."""
    import torch
    from stable_baselines3 import SAC

    from assistive_compiler.training.learners.averaging import averaged, make_averaged

    checkpoint = RunDir(sac_run).latest_checkpoint()[1]
    model = SAC.load(str(checkpoint / "model.zip"), device="cpu", custom_objects={"replay_buffer_class": None})
    make_averaged(model, 0.25, None)
    average = averaged(model)
    assert average is not None
    before = [p.detach().clone() for p in model.actor.parameters()]
    obs = torch.as_tensor(
        np.random.default_rng(0).normal(size=(8, model.observation_space.shape[0])), dtype=torch.float32
    )
    model.actor.optimizer.zero_grad()
    mean, log_std, _ = model.actor.get_action_dist_params(obs)
    (mean.square().sum() + log_std.sum()).backward()
    model.actor.optimizer.step()
    after = [p.detach() for p in model.actor.parameters()]
    assert all(not torch.equal(b, a) for b, a in zip(before, after))  # the actor moved
    for b, a, mixed in zip(before, after, average.average.parameters(), strict=True):
        assert torch.allclose(mixed, 0.75 * b + 0.25 * a, atol=1e-7)


def test_a_run_with_an_averaged_actor_acts_evaluates_exports_and_resumes_with_the_average(tmp_path, capsys):
    """The checkpoints carry the average; evaluation, export and --policy RUN_DIR act with it, not
    with the actor; a resumed run continues the same average, and refuses to start a new one."""
    import torch
    from stable_baselines3 import SAC

    from assistive_compiler.policies.checkpoint import SB3Policy
    from assistive_compiler.policies.mlp import MLPPolicy
    from assistive_compiler.training.trained.export import export_run

    config = tmp_path / "sac_averaged.yaml"
    config.write_text(SAC_TINY.replace("batch_size: 32}", "batch_size: 32, actor_average_tau: 0.002}"))
    out = tmp_path / "averaged"
    train = ["train", str(REACH), "--robot", "jaco", "--config", str(config), "--out", str(out), "--quiet"]
    assert main(train) == 0
    run = RunDir(out)
    assert (run.checkpoint_dir(400) / "actor_average.pt").is_file()
    checkpoint = run.checkpoint_dir(600)
    average = torch.load(checkpoint / "actor_average.pt", weights_only=True)
    live = SAC.load(str(checkpoint / "model.zip"), device="cpu", custom_objects={"replay_buffer_class": None})
    # 500 updates at τ 0.002: the average lags the actor
    distance = sum(float((average[k] - v).norm()) for k, v in live.actor.state_dict().items())
    assert distance > 1e-3
    acting = SB3Policy(checkpoint, "sac")
    obs = np.random.default_rng(3).normal(0, 2, (20, live.observation_space.shape[0])).astype(np.float32)
    with torch.no_grad():
        live_actions = np.stack([live.predict(o, deterministic=True)[0] for o in obs])
    assert all(torch.equal(acting.model.actor.state_dict()[k], v) for k, v in average.items())
    assert not np.allclose([acting(o) for o in obs], live_actions, atol=1e-4)
    exported = export_run(out, tmp_path / "exported", episodes=2, seed=100)
    assert exported["trained_steps"] == 600
    numpy_policy = MLPPolicy.load(tmp_path / "exported")
    assert np.allclose([numpy_policy(o) for o in obs], [acting(o) for o in obs], atol=1e-5)
    # resumed: the same average goes on (its first update starts from the saved one)
    resumed = tmp_path / "resumed"
    shutil.copytree(out, resumed)
    again = [*train[:-2], str(resumed), "--resume", "--steps", "800", "--quiet"]
    assert main(again) == 0
    after = torch.load(RunDir(resumed).checkpoint_dir(800) / "actor_average.pt", weights_only=True)
    moved = sum(float((after[k] - v).norm()) for k, v in average.items())
    # 200 more updates keep 0.998^200 ≈ 2/3 of the saved average: it moved a fraction of its lag
    # behind the actor; an average restarted from the actor would have jumped the whole lag
    assert 0 < moved < 0.5 * distance
    # a checkpoint that lost its average is not silently restarted from the actor
    missing = RunDir(resumed).checkpoint_dir(800) / "actor_average.pt"
    missing.unlink()
    capsys.readouterr()
    assert main([*again[:-3], "--steps", "900", "--quiet"]) == 2
    assert (
        f"{missing}: --resume of a run with sac.actor_average_tau needs the checkpoint's averaged actor, which is missing"
        in capsys.readouterr().err
    )


def test_sac_resume_without_the_replay_buffer_is_refused(sac_run, tmp_path, capsys):
    copy = tmp_path / "no-buffer"
    shutil.copytree(sac_run, copy)
    buffer = RunDir(copy).latest_checkpoint()[1] / "replay_buffer.pkl"
    buffer.unlink()
    code = main(
        [
            "train",
            str(REACH),
            "--robot",
            "jaco",
            "--config",
            str(sac_run / "config.yaml"),
            "--out",
            str(copy),
            "--resume",
            "--steps",
            "800",
            "--quiet",
        ]
    )
    assert code == 2
    assert (
        f"{buffer}: --resume of a SAC run needs the newest checkpoint's replay buffer, which is missing"
        in capsys.readouterr().err
    )


@pytest.mark.parametrize("which", ["ppo", "sac"])
def test_export_gives_the_checkpoints_actions_in_numpy(which, reach_run, sac_run, tmp_path):
    """An exported policy (NumPy) acts as its checkpoint does: same actions to float precision,
    the same episodes; its policy.json carries the evaluation on unseen seeds."""
    from assistive_compiler.policies.checkpoint import SB3Policy
    from assistive_compiler.policies.mlp import MLPPolicy
    from assistive_compiler.training.trained.export import export_run

    run_dir = reach_run if which == "ppo" else sac_run
    record = export_run(run_dir, tmp_path / which, episodes=3, seed=100, label=f"{which} tiny")
    exported = MLPPolicy.load(tmp_path / which)
    steps, checkpoint = RunDir(run_dir).latest_checkpoint()
    original = SB3Policy(checkpoint, which)
    rng = np.random.default_rng(1)
    for obs in rng.normal(0, 2, (50, exported.obs_dim)).astype(np.float32):
        assert np.allclose(exported(obs), original(obs), atol=1e-5)
    assert (exported.head, record["algorithm"], record["trained_steps"], record["label"]) == (
        "clip" if which == "ppo" else "tanh",
        which,
        steps,
        f"{which} tiny",
    )
    assert (exported.obs_mean is not None) == (which == "ppo")  # ppo_quick normalises observations
    # The export keeps the Gaussian's σ (SAC's a layer of the state, PPO's one vector), so it can also
    # act as in training: the same mean and σ as the checkpoint's distribution, before the squashing.
    import torch

    policy = original.model.policy
    for obs in rng.normal(0, 2, (20, exported.obs_dim)).astype(np.float32):
        mean, std = exported.mean_and_std(obs)
        if original.obs_rms is not None:  # the checkpoint's network sees normalised observations
            obs = np.clip((obs - original.obs_rms.mean) / np.sqrt(original.obs_rms.var + original.eps), -10, 10)
        with torch.no_grad():
            given = policy.obs_to_tensor(obs.astype(np.float32))[0]
            if which == "sac":
                want_mean, want_log_std, _ = policy.actor.get_action_dist_params(given)
                want_std = want_log_std.exp()
            else:
                dist = policy.get_distribution(given).distribution
                want_mean, want_std = dist.mean, dist.stddev
        assert np.allclose(mean, want_mean.numpy()[0], atol=1e-5) and np.allclose(std, want_std.numpy()[0], rtol=1e-5)
    sampled = [evaluate_exported(str(tmp_path / which), episodes=2, seed=100, stochastic=True) for _ in range(2)]
    assert sampled[0]["actions"] == "stochastic" and sampled[0]["per_episode"] == sampled[1]["per_episode"]
    assert [e["return"] for e in sampled[0]["per_episode"]] != record["evaluation"]["returns"][:2]
    # export recorded the sampled-action protocol too: the same episodes as evaluate --stochastic
    recorded_sampled = record["evaluation_sampled"]
    assert recorded_sampled["episodes"] == 3 and recorded_sampled["seed"] == 100
    assert recorded_sampled["returns"][:2] == [round(e["return"], 3) for e in sampled[0]["per_episode"]]
    ours = evaluate(run_dir, episodes=3, seed=100)
    assert [round(e["return"], 3) for e in ours["per_episode"]] == record["evaluation"]["returns"]
    assert record["evaluation"]["success_rate"] == ours["success_rate"]
    assert (tmp_path / which / "curve.csv").read_text() == (run_dir / "curve.csv").read_text()


def test_run_render_and_evaluate_take_a_run_directory_or_an_exported_policy(reach_run, tmp_path, capsys):
    from assistive_compiler.training.trained.export import export_run

    export_run(reach_run, tmp_path / "exported", episodes=2, seed=5)
    returns = {}
    for source in (str(reach_run), str(tmp_path / "exported")):
        assert (
            main(
                [
                    "run",
                    str(REACH),
                    "--robot",
                    "jaco",
                    "--policy",
                    source,
                    "--episodes",
                    "2",
                    "--seed",
                    "5",
                    "--json",
                    "--out",
                    str(tmp_path / "artifact"),
                    "--quiet",
                ]
            )
            == 0
        )
        report = json.loads(capsys.readouterr().out)
        returns[source] = [round(e["return"], 4) for e in report["episodes"]]
        assert report["policy"] == source
    assert returns[str(reach_run)] == returns[str(tmp_path / "exported")]
    gif = tmp_path / "exported.gif"
    assert (
        main(
            [
                "render",
                str(REACH),
                "--robot",
                "jaco",
                "--policy",
                str(tmp_path / "exported"),
                "--seed",
                "5",
                "--out",
                str(gif),
                "--out-dir",
                str(tmp_path / "artifact"),
            ]
        )
        == 0
    )
    assert Image.open(gif).n_frames > 10
    capsys.readouterr()
    assert main(["evaluate", "--policy", str(tmp_path / "exported"), "--episodes", "2", "--seed", "5", "--json"]) == 0
    assert [round(e["return"], 4) for e in json.loads(capsys.readouterr().out)["per_episode"]] == returns[
        str(reach_run)
    ]


FEEDING = REPO / "specs" / "tasks" / "feeding.yaml"
#: Feeding × Jaco co-optimised: the robot's and the person's observation sizes, then their action sizes.
FEEDING_JACO_PAIR = (25, 23, 7, 4)


def _train_coop_pair(tmp_path: Path, config_text: str, algorithm: str):
    """``train --coop --engine sb3`` on Feeding × Jaco with the config ``config_text``: the run
    directory, its :class:`RunDir`, the train command (to resume with) and the checkpoint's pair."""
    from assistive_compiler.policies.checkpoint import load_policy

    config = tmp_path / f"{algorithm}_tiny.yaml"
    config.write_text(config_text)
    out = tmp_path / f"feeding-coop-{algorithm}"
    train = ["train", str(FEEDING), "--robot", "jaco", "--coop", "--engine", "sb3", "--config", str(config)]
    assert main([*train, "--out", str(out), "--quiet"]) == 0
    run = RunDir(out)
    assert (run.info().engine, run.info().coop, run.info().algorithm) == ("sb3", True, algorithm)
    return out, run, train, load_policy(run.info(), run.latest_checkpoint()[1])


def test_a_coop_pair_trains_on_sb3_with_one_critic_and_each_agent_acts_on_its_own_observation(tmp_path, capsys):
    """``--coop --engine sb3``: SAC with one actor per agent and one critic for the pair. The critic
    sees both observations and both actions; each actor reads only its agent's observation, so the
    pair exports to two NumPy policies that act as the checkpoint does, play under ``run --coop``,
    and the run resumes."""
    import torch

    from assistive_compiler.policies.checkpoint import load_policy
    from assistive_compiler.policies.pretrained import load_trained
    from assistive_compiler.training.learners.factored_actor import FactoredActor
    from assistive_compiler.training.trained.export import export_run

    out, run, train, pair = _train_coop_pair(tmp_path, SAC_TINY, "sac")
    model = pair.model
    robot_obs, human_obs, robot_act, human_act = FEEDING_JACO_PAIR
    assert isinstance(model.actor, FactoredActor) and model.actor.agent_split == (robot_obs, robot_act)
    # One critic for the pair: both observations and both actions in.
    assert model.critic.q_networks[0][0].in_features == robot_obs + human_obs + robot_act + human_act
    # Each actor learnt (its weights moved from their start) and reads only its own observation.
    assert_each_agent_acts_on_its_own_observation(pair, FEEDING_JACO_PAIR)
    first = {k: v.clone() for k, v in model.actor.state_dict().items()}

    # Export: two NumPy policies, each acting as the checkpoint's on a real co-optimised episode.
    record = export_run(out, tmp_path / "pair", episodes=1, seed=7)
    assert record["coop"] and record["engine"] == "sb3" and record["export_max_action_difference"] < 1e-4
    exported, _ = load_trained(str(tmp_path / "pair"))
    assert_exported_pair_acts_as(pair, exported, run.artifact)
    capsys.readouterr()
    played = ["run", str(FEEDING), "--robot", "jaco", "--coop", "--policy", str(tmp_path / "pair")]
    assert main([*played, "--episodes", "1", "--seed", "7", "--json", "--quiet"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["human_policy"] == str(tmp_path / "pair")  # the pair plays the person too
    assert report["episodes"][0]["return"] == pytest.approx(record["evaluation"]["returns"][0], abs=1e-3)

    # Resume: the same factored actor goes on learning from the checkpoint, with its replay buffer.
    assert main([*train, "--out", str(out), "--resume", "--steps", "800", "--quiet"]) == 0
    steps, newest = run.latest_checkpoint()
    resumed = load_policy(run.info(), newest).model
    assert steps == 800 and isinstance(resumed.actor, FactoredActor)
    assert any(not torch.equal(first[k], v) for k, v in resumed.actor.state_dict().items())


PPO_TINY_IN_PROCESS = """algorithm: ppo
network: {hidden: [32, 32], activation: tanh}
ppo: {rollout_steps: 100, minibatch_size: 50, epochs: 2}
total_steps: 400
envs: 2
vec_env: in_process
seed: 3
checkpoint_every_steps: 200
eval_episodes: 1
"""


def test_a_coop_pair_trains_with_ppo_on_sb3_with_one_value_function(tmp_path, capsys):
    """``--coop --engine sb3`` with PPO: one actor per agent (each its own hidden layers and mean
    on its own observation, its own entries of the log-std) and one value function on both
    observations. The pair exports to two NumPy policies (each with its slice of the observation
    normalisation) that act as the checkpoint does and play under ``run --coop``; ``--resume``
    continues the same factored policy; ``evaluate --stochastic`` samples both agents."""
    import torch

    from assistive_compiler.policies.checkpoint import load_policy
    from assistive_compiler.policies.pretrained import load_trained
    from assistive_compiler.training.learners.factored_actor_critic import FactoredActorCriticPolicy
    from assistive_compiler.training.trained.export import export_run

    out, run, train, pair = _train_coop_pair(tmp_path, PPO_TINY_IN_PROCESS, "ppo")
    policy = pair.model.policy
    robot_obs, human_obs, robot_act, human_act = FEEDING_JACO_PAIR
    assert isinstance(policy, FactoredActorCriticPolicy) and policy.agent_split == (robot_obs, robot_act)
    heads = policy.mlp_extractor.policy_heads
    assert (heads["robot"][0].in_features, heads["human"][0].in_features) == (robot_obs, human_obs)
    assert policy.mlp_extractor.value_net[0].in_features == robot_obs + human_obs  # one critic, both observations
    assert (policy.action_net.heads["robot"].out_features, policy.action_net.heads["human"].out_features) == (
        robot_act,
        human_act,
    )
    # the optimiser updates every network the policy acts and values with, the replaced means' included
    optimised = {id(p) for group in policy.optimizer.param_groups for p in group["params"]}
    assert optimised == {id(p) for p in policy.parameters()}
    assert_each_agent_acts_on_its_own_observation(pair, FEEDING_JACO_PAIR)
    first = {k: v.clone() for k, v in policy.state_dict().items()}

    record = export_run(out, tmp_path / "pair", episodes=1, seed=7)
    assert record["coop"] and record["algorithm"] == "ppo" and record["export_max_action_difference"] < 1e-4
    exported, _ = load_trained(str(tmp_path / "pair"))
    assert_exported_pair_acts_as(pair, exported, run.artifact)
    capsys.readouterr()
    played = ["run", str(FEEDING), "--robot", "jaco", "--coop", "--policy", str(tmp_path / "pair")]
    assert main([*played, "--episodes", "1", "--seed", "7", "--json", "--quiet"]) == 0
    assert json.loads(capsys.readouterr().out)["episodes"][0]["return"] == pytest.approx(
        record["evaluation"]["returns"][0], abs=1e-3
    )
    assert record["evaluation_sampled"]["episodes"] == 1  # exported with each agent's log-std: both protocols

    assert main([*train, "--out", str(out), "--resume", "--steps", "600", "--quiet"]) == 0
    steps, newest = run.latest_checkpoint()
    resumed = load_policy(run.info(), newest).model.policy
    assert steps == 600 and isinstance(resumed, FactoredActorCriticPolicy)
    assert any(not torch.equal(first[k], v) for k, v in resumed.state_dict().items())


def test_coop_on_sb3_is_without_demonstrations(tmp_path, capsys):
    """SB3 co-optimises with its own PPO and SAC (SBX's refusal: test_training_sbx.py), not from
    demonstrations (a dataset holds the robot's actions alone). Refused before the run directory is
    written."""
    out = tmp_path / "run"
    train = ["train", str(FEEDING), "--robot", "jaco", "--coop", "--engine", "sb3", "--out", str(out)]
    assert main([*train, "--config", "sac_demos", "--demonstrations", "assistive_compiler/feeding-jaco/any-v0"]) == 2
    assert capsys.readouterr().err.strip().splitlines()[-1] == (
        "error: --demonstrations: starting from demonstrations is for single-agent SB3 SAC (--engine sb3)"
    )
    assert not out.exists()


def test_a_trained_policy_of_another_task_is_refused(reach_run, capsys):
    code = main(
        [
            "run",
            str(REPO / "specs" / "tasks" / "feeding.yaml"),
            "--robot",
            "jaco",
            "--policy",
            str(reach_run),
            "--episodes",
            "1",
        ]
    )
    assert code == 2
    assert (
        capsys.readouterr()
        .err.strip()
        .endswith(f"error: --policy {reach_run}: trained for reach with jaco, but the env is feeding with jaco")
    )


def test_training_needs_only_the_declared_train_extra(tmp_path):
    """The training path imports nothing the train extra does not declare (tqdm was one): a run
    with tqdm made unimportable still trains and writes its curve."""
    out = tmp_path / "no-tqdm"
    code = (
        "import sys; sys.modules['tqdm'] = None\n"
        "from assistive_compiler.cli import main\n"
        f"sys.exit(main(['train', {str(REACH)!r}, '--robot', 'jaco', '--config', 'ppo_quick', '--envs', '1', '--steps', '800', "
        f"'--out', {str(out)!r}]))"
    )
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr
    assert RunDir(out).latest_checkpoint()[0] == 800 and (out / "curve.csv").is_file()


PPO_OFTEN = """algorithm: ppo
network: {hidden: [32, 32], activation: tanh}
ppo: {rollout_steps: 200, minibatch_size: 50, epochs: 2}
total_steps: 1000000
envs: 1
seed: 0
checkpoint_every_steps: 400
eval_episodes: 2
"""


def test_a_driver_killed_outright_leaves_a_resumable_run(tmp_path):
    """SIGKILL (no chance to checkpoint) at any moment, a checkpoint write included: checkpoints are
    written into a hidden partial directory and renamed into place, run files are replaced
    atomically, and --resume continues from the newest complete checkpoint with a clean curve."""
    out = tmp_path / "killed"
    config = tmp_path / "ppo_often.yaml"  # checkpoints every 400 steps (ppo_quick's 10,000 took ~50 s each here)
    config.write_text(PPO_OFTEN)
    cmd = [
        sys.executable,
        "-m",
        "assistive_compiler.cli",
        "train",
        str(REACH),
        "--config",
        str(config),
        "--envs",
        "1",
        "--steps",
        "1000000",
        "--out",
        str(out),
        "--quiet",
    ]
    proc = subprocess.Popen(cmd + [], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.time() + 180
    run = RunDir(out)
    while time.time() < deadline and not (run.checkpoints.is_dir() and len(list(run.checkpoints.iterdir())) >= 2):
        time.sleep(0.05)  # poll fast: the kill lands at a random point, often mid-write
    proc.kill()
    proc.wait(timeout=60)
    latest = run.latest_checkpoint()
    assert latest is not None and (latest[1] / "model.zip").is_file()
    assert all(p.name.startswith(("step_", ".partial-")) for p in run.checkpoints.iterdir())
    json.loads((out / "run.json").read_text())  # readable
    target = latest[0] + 800
    assert (
        subprocess.run(
            cmd[:-5] + ["--steps", str(target), "--out", str(out), "--resume", "--quiet"],
            capture_output=True,
            text=True,
            timeout=300,
        ).returncode
        == 0
    )
    assert run.latest_checkpoint()[0] == target and not list(run.checkpoints.glob(".partial-*"))
    rows = list(csv.DictReader((out / "curve.csv").open()))
    steps = [int(r["steps"]) for r in rows]
    assert steps == sorted(set(steps)) and steps[-1] == target  # no row repeated from before the kill


# --------------------------------------------------------------------------------------------
# Starting a SAC run from demonstrations (train --demonstrations: a Minari dataset of the task)

DEMOS = "assistive_compiler/reach-jaco/scripted-v0"
# A fixed, small temperature: the critics' soft values are then the returns (the test reads them)
SAC_FROM_DEMOS = (
    SAC_TINY.replace("total_steps: 600", "total_steps: 200").replace(
        "batch_size: 32}", "batch_size: 32, ent_coef: 0.001}"
    )
    + "demonstrations: {clone_epochs: 200, clone_batch_size: 32}\n"
)


@pytest.fixture(scope="module")
def demos_root(tmp_path_factory) -> Path:
    """8 episodes of the scripted policy on reach × Jaco (every one reaches), as `collect` writes them."""
    pytest.importorskip("minari", reason='needs the "datasets" extra')
    from assistive_compiler.datasets import collect

    root = tmp_path_factory.mktemp("demos")
    collect(str(REACH), "jaco", DEMOS, episodes=8, seed=0, root=root, out=str(root / "artifact"))
    return root


@pytest.fixture(scope="module")
def demo_run(demos_root) -> Path:
    config = demos_root / "sac_from_demos.yaml"
    config.write_text(SAC_FROM_DEMOS)
    out = demos_root / "reach-sac-demos"
    args = ["train", str(REACH), "--robot", "jaco", "--config", str(config), "--out", str(out), "--quiet"]
    assert main([*args, "--demonstrations", DEMOS, "--demonstrations-root", str(demos_root)]) == 0
    return out


def test_a_run_from_demonstrations_starts_from_the_cloned_policy_and_replays_every_step(demo_run, demos_root):
    import minari

    run = RunDir(demo_run)
    dataset = minari.load_dataset(DEMOS)
    assert sorted(int(p.name.split("_")[1]) for p in run.checkpoints.glob("step_*")) == [0, 200]
    started = json.loads((demo_run / "demonstrations.json").read_text())
    assert (started["dataset"], started["policy"], started["episodes"], started["successful_episodes"]) == (
        DEMOS,
        "scripted",
        8,
        8,
    )
    assert started["steps"] == started["cloned_steps"] == started["replayed_steps"] == dataset.total_steps
    assert started["clone_mse_after"] < 0.5 * started["clone_mse_before"]
    # σ fitted to how far the clone misses, not left at the initial ~1 (noise that undoes it)
    assert started["clone_std_before"] > 0.9 and started["clone_std_after"] < 0.5
    assert json.loads(run.summary_json.read_text())["demonstrations"] == started
    assert run.info().config["demonstrations"]["dataset"] == DEMOS  # the run says what it started from
    # Behaviour: the step-0 checkpoint (cloned, no env step yet) reaches far better than random
    # actions on the same unseen seeds.
    cloned = evaluate(demo_run, episodes=10, seed=EVAL_SEED, checkpoint_steps=0)
    assert cloned["trained_steps"] == 0
    env = AssistiveEnv(run.artifact)
    policy = make_policy("random", env, seed=EVAL_SEED)
    random_return = float(np.mean([rollout(env, policy, EVAL_SEED + k)["return"] for k in range(10)]))
    env.close()
    assert cloned["mean_return"] > random_return + 4.0, (cloned["mean_return"], random_return)
    # ... and so does its sampled behaviour, which is what SAC goes on collecting with.
    sampled = evaluate(demo_run, episodes=10, seed=EVAL_SEED, checkpoint_steps=0, stochastic=True)
    assert sampled["mean_return"] > random_return + 4.0, (sampled["mean_return"], random_return)
    # The critics warmed up on the demonstrations: they value the demonstrated (state, action)
    # pairs as costly (reach pays -0.17 a step on them; untrained critics say ~0 with a spread of
    # ~0.02) and tell them apart. 5,000 steps do not reach the values' fixed point (~-16 at
    # γ = 0.99); they set their sign and shape before the first actor update. The temperature is
    # small here, so the soft values are the plain ones.
    import torch
    from stable_baselines3 import SAC

    assert started["critic_warmup_steps"] == 5000
    model = SAC.load(str(run.checkpoint_dir(0) / "model.zip"), device="cpu")
    values = []
    for episode in dataset.iterate_episodes():
        obs = torch.as_tensor(np.asarray(episode.observations[:-1], dtype=np.float32))
        act = torch.as_tensor(model.policy.scale_action(np.asarray(episode.actions)), dtype=torch.float32)
        with torch.no_grad():
            values += torch.min(*model.critic(obs, act)).ravel().tolist()
    assert np.mean(values) < -2.0 and np.std(values) > 0.1, (np.mean(values), np.std(values))


def _against_demonstrations(checkpoint: Path) -> tuple[float, float]:
    """(mean squared miss of the checkpoint's deterministic action, its largest σ per action
    dimension — the mean over steps of each dimension's σ, the widest dimension) on the
    dataset's steps ([-1, 1] scale, σ before the squashing)."""
    import minari
    import torch
    from stable_baselines3 import SAC

    model = SAC.load(str(checkpoint / "model.zip"), device="cpu")
    dataset = minari.load_dataset(DEMOS)
    obs = np.concatenate([np.asarray(e.observations[:-1], dtype=np.float32) for e in dataset.iterate_episodes()])
    actions = np.concatenate([np.asarray(e.actions) for e in dataset.iterate_episodes()])
    chosen, _ = model.predict(obs, deterministic=True)
    target = model.policy.scale_action(np.clip(actions, model.action_space.low, model.action_space.high))
    with torch.no_grad():
        _, log_std, _ = model.actor.get_action_dist_params(torch.as_tensor(obs))
    widest = float(log_std.exp().mean(dim=0).max())
    return float(np.mean((model.policy.scale_action(chosen) - target) ** 2)), widest


def test_a_cloning_term_kept_in_the_actors_loss_holds_it_to_the_demonstrations_new_or_resumed(demos_root, tmp_path):
    """demonstrations.clone_weight > 0 keeps behaviour cloning in SAC's actor loss. With a large
    fixed temperature SAC's own actor loss drives the cloned actor away from the demonstrations
    within a few hundred steps; with the term it stays on them, after a --resume too."""
    config = (
        SAC_TINY.replace("total_steps: 600", "total_steps: 300")
        .replace("learning_starts: 100", "learning_starts: 0")
        .replace("batch_size: 32}", "batch_size: 32, ent_coef: 1.0}")
    )
    misses = {}
    for weight in (0, 10):
        path = tmp_path / f"weight{weight}.yaml"
        path.write_text(
            config + f"demonstrations: {{clone_epochs: 200, clone_batch_size: 32, clone_weight: {weight}}}\n"
        )
        out = tmp_path / f"run{weight}"
        args = ["train", str(REACH), "--robot", "jaco", "--config", str(path), "--out", str(out), "--quiet"]
        assert main([*args, "--demonstrations", DEMOS, "--demonstrations-root", str(demos_root)]) == 0
        run = RunDir(out)
        misses[weight] = [_against_demonstrations(run.checkpoint_dir(s)) for s in (0, 300)]
        assert json.loads(run.demonstrations_json.read_text())["clone_weight"] == weight
    (miss0, sigma0), (miss, _) = misses[0]
    (miss0_kept, sigma0_kept), (miss_kept, _) = misses[10]
    assert miss0 == miss0_kept < 0.02 and sigma0 == sigma0_kept < 0.5  # the same start: cloned alike
    assert miss > 0.2 and miss_kept < 0.02, misses  # SAC alone left the demonstrations; the term holds them
    # a resumed run reads the dataset again and keeps the term (it is not in the checkpoint)
    out = tmp_path / "run10"
    resume = ["train", str(REACH), "--robot", "jaco", "--config", str(tmp_path / "weight10.yaml"), "--out", str(out)]
    assert main([*resume, "--resume", "--steps", "450", "--quiet"]) == 0
    assert _against_demonstrations(RunDir(out).checkpoint_dir(450))[0] < 0.02


def test_a_held_actor_waits_for_the_critics_then_learns(demos_root, tmp_path):
    """demonstrations.hold_actor_steps: SAC's first updates leave the actor as cloned (every
    parameter) while the critics learn; after them, it learns — on --resume too."""
    import torch
    from stable_baselines3 import SAC

    config = tmp_path / "held.yaml"
    config.write_text(
        SAC_FROM_DEMOS.replace("total_steps: 200", "total_steps: 100")
        .replace("learning_starts: 100", "learning_starts: 0")
        .replace("clone_batch_size: 32}", "clone_batch_size: 32, critic_warmup_steps: 0, hold_actor_steps: 150}")
    )
    out = tmp_path / "run"
    args = ["train", str(REACH), "--robot", "jaco", "--config", str(config), "--out", str(out), "--quiet"]
    assert main([*args, "--demonstrations", DEMOS, "--demonstrations-root", str(demos_root)]) == 0
    assert main([*args, "--resume", "--steps", "300"]) == 0
    run = RunDir(out)
    models = {s: SAC.load(str(run.checkpoint_dir(s) / "model.zip"), device="cpu") for s in (0, 100, 300)}

    def same(a, b) -> bool:
        return all(torch.equal(x, y) for x, y in zip(a.parameters(), b.parameters(), strict=True))

    assert same(models[0].actor, models[100].actor) and not same(models[0].critic, models[100].critic)
    assert not same(models[100].actor, models[300].actor)  # held for 150 updates, then learning
    assert json.loads(run.demonstrations_json.read_text())["hold_actor_steps"] == 150


def _margin_over_untried_actions(checkpoint: Path) -> float:
    """Mean over the demonstrated states of Q(s, a_demonstrated) − Q(s, a uniform in the action
    box) (min over the twin critics, 16 uniform actions a state)."""
    import minari
    import torch
    from stable_baselines3 import SAC

    model = SAC.load(str(checkpoint / "model.zip"), device="cpu")
    dataset = minari.load_dataset(DEMOS)
    obs = torch.as_tensor(
        np.concatenate([np.asarray(e.observations[:-1], dtype=np.float32) for e in dataset.iterate_episodes()])
    )
    taken = np.concatenate([np.asarray(e.actions) for e in dataset.iterate_episodes()])
    taken = torch.as_tensor(model.policy.scale_action(taken).clip(-1, 1), dtype=torch.float32)
    generator = torch.Generator().manual_seed(0)
    uniform = torch.rand(len(obs) * 16, taken.shape[1], generator=generator) * 2 - 1
    with torch.no_grad():
        q_taken = torch.min(*model.critic(obs, taken)).view(-1)
        q_untried = torch.min(*model.critic(obs.repeat_interleave(16, 0), uniform)).view(-1, 16).mean(dim=1)
    return float((q_taken - q_untried).mean())


def test_a_conservative_critic_values_untried_actions_below_the_demonstrated_ones(demo_run, demos_root, tmp_path):
    """sac.conservative_weight (CQL): after the same critic warm-up on the demonstrations, the
    conservative critics value actions nobody took (uniform in the action box) well below the
    demonstrated ones, where SAC's own critics barely tell them apart; it stays on --resume."""
    config = tmp_path / "conservative.yaml"
    config.write_text(SAC_FROM_DEMOS.replace("ent_coef: 0.001}", "ent_coef: 0.001, conservative_weight: 5}"))
    out = tmp_path / "run"
    args = ["train", str(REACH), "--robot", "jaco", "--config", str(config), "--out", str(out), "--quiet"]
    assert main([*args, "--demonstrations", DEMOS, "--demonstrations-root", str(demos_root)]) == 0
    plain = _margin_over_untried_actions(RunDir(demo_run).checkpoint_dir(0))
    conservative = _margin_over_untried_actions(RunDir(out).checkpoint_dir(0))
    assert conservative > plain + 1.0 and conservative > 1.0, (plain, conservative)
    assert main([*args, "--resume", "--steps", "300"]) == 0
    assert _margin_over_untried_actions(RunDir(out).checkpoint_dir(300)) > 1.0


def test_the_cloning_loss_fits_sigma_per_action_dimension_to_the_misses():
    """The spread part of the cloning loss, the mean held: each action dimension's σ goes to the
    root mean square of that dimension's misses, from too wide and from too narrow alike."""
    import gymnasium as gym
    import torch
    from stable_baselines3 import SAC

    from assistive_compiler.training.learners.demonstrations import cloning_loss

    env = gym.make("Pendulum-v1")  # one action dimension
    model = SAC("MlpPolicy", env, policy_kwargs={"net_arch": [16]}, seed=0, device="cpu")
    actor = model.actor
    obs = torch.as_tensor(np.random.default_rng(0).normal(size=(512, 3)), dtype=torch.float32)
    for start_log_std, misses in ((1.5, 0.05), (-4.0, 0.2)):
        with torch.no_grad():
            actor.log_std.bias.fill_(start_log_std)
            actor.log_std.weight.zero_()
            target = torch.tanh(actor.mu(actor.latent_pi(obs))) + misses * torch.randn(
                512, 1, generator=torch.Generator().manual_seed(1)
            )
        optimiser = torch.optim.Adam(actor.log_std.parameters(), lr=0.05)
        for _ in range(400):
            _, spread = cloning_loss(actor, obs, target)
            optimiser.zero_grad()
            spread.backward()
            optimiser.step()
        with torch.no_grad():
            sigma = float(torch.exp(actor.log_std(actor.latent_pi(obs))).mean())
        assert sigma == pytest.approx(misses, rel=0.15), (start_log_std, sigma)
    env.close()


def test_a_cloned_target_entropy_is_the_clones_own_and_stays_with_the_run(demos_root, tmp_path):
    """sac.target_entropy: cloned — SAC tunes its temperature toward the cloned policy's entropy on
    the demonstrations (measured after cloning, recorded in demonstrations.json), kept in every
    checkpoint and on --resume, instead of −(action dimensions)."""
    import torch
    from stable_baselines3 import SAC

    config = tmp_path / "cloned.yaml"
    config.write_text(
        SAC_FROM_DEMOS.replace("ent_coef: 0.001}", "initial_ent_coef: 0.01, target_entropy: cloned}").replace(
            "total_steps: 200", "total_steps: 100"
        )
    )
    out = tmp_path / "run"
    args = ["train", str(REACH), "--robot", "jaco", "--config", str(config), "--out", str(out), "--quiet"]
    assert main([*args, "--demonstrations", DEMOS, "--demonstrations-root", str(demos_root)]) == 0
    assert main([*args, "--resume", "--steps", "150"]) == 0
    run = RunDir(out)
    target = json.loads(run.demonstrations_json.read_text())["target_entropy"]
    cloned = SAC.load(str(run.checkpoint_dir(0) / "model.zip"), device="cpu")
    # the clone's entropy, estimated again with other samples of its actions
    import minari

    obs = torch.as_tensor(
        np.concatenate(
            [np.asarray(e.observations[:-1], dtype=np.float32) for e in minari.load_dataset(DEMOS).iterate_episodes()]
        )
    )
    with torch.no_grad():
        log_probs = torch.cat([cloned.actor.action_log_prob(obs)[1] for _ in range(20)])
    assert target == pytest.approx(float(-log_probs.mean()), abs=0.5)  # a sampled estimate over 320 steps
    assert abs(target - (-7.0)) > 1.0  # not the 'auto' target of the 7 joints
    for steps in (0, 100, 150):
        assert SAC.load(str(run.checkpoint_dir(steps) / "model.zip"), device="cpu").target_entropy == target


def _train_from_demos(demos_root: Path, out: Path, *extra: str) -> int:
    config = demos_root / "sac_from_demos.yaml"
    config.write_text(SAC_FROM_DEMOS)
    return main(
        ["train", str(REACH), "--config", str(config), "--out", str(out), "--quiet", "--demonstrations-root"]
        + [str(demos_root), *extra]
    )


def test_demonstrations_of_another_task_or_robot_are_refused_before_the_run_is_written(demos_root, tmp_path, capsys):
    out = tmp_path / "panda-from-jaco-demos"
    assert _train_from_demos(demos_root, out, "--robot", "panda", "--demonstrations", DEMOS) == 2
    err = capsys.readouterr().err
    jaco_hash = Manifest.read(demos_root / "artifact").content_hash
    assert f"--demonstrations {DEMOS}: collected on reach × jaco, compiled task {jaco_hash[:12]}; " in err
    assert "Collect demonstrations on this task and robot (assistive-compiler collect SPEC --robot ROBOT)" in err
    assert not out.exists()


def test_a_missing_dataset_names_those_there_are(demos_root, tmp_path, capsys):
    out = tmp_path / "missing"
    assert _train_from_demos(demos_root, out, "--robot", "jaco", "--demonstrations", DEMOS.replace("v0", "v9")) == 2
    err = capsys.readouterr().err
    assert f"--demonstrations {DEMOS.replace('v0', 'v9')}: no such Minari dataset under {demos_root}" in err
    assert f"datasets there: {DEMOS}" in err
    assert not out.exists()


def test_demonstrations_need_sac_on_one_env_and_a_new_run(demos_root, demo_run, tmp_path, capsys):
    args = ["train", str(REACH), "--robot", "jaco", "--quiet", "--demonstrations", DEMOS]
    assert main([*args, "--config", "ppo_quick", "--out", str(tmp_path / "ppo")]) == 2
    assert (
        "@demonstrations: starting from demonstrations fits SAC's actor and fills its replay buffer; algorithm is 'ppo'"
        in (capsys.readouterr().err)
    )
    assert main([*args, "--config", "sac_laptop", "--envs", "2", "--out", str(tmp_path / "two")]) == 2
    assert "starting from demonstrations needs envs: 1" in capsys.readouterr().err
    assert main([*args, "--config", str(demo_run / "config.yaml"), "--out", str(demo_run), "--resume"]) == 2
    assert "--demonstrations starts a new run; --resume continues one with the demonstrations it started from" in (
        capsys.readouterr().err
    )
    assert not (tmp_path / "ppo").exists() and not (tmp_path / "two").exists()
    # The shipped config for such runs needs the dataset named.
    assert main(["train", str(REACH), "--robot", "jaco", "--config", "sac_demos", "--out", str(tmp_path / "none")]) == 2
    assert (
        "specs/training/sac_demos.yaml: this config starts from demonstrations; name the dataset with "
        "--demonstrations DATASET (a `collect` dataset of this task)" in capsys.readouterr().err
    )
    assert not (tmp_path / "none").exists()


def test_results_from_demonstrations_say_so_in_every_table(demo_run, tmp_path):
    """`table` marks the cell, an exported policy records the dataset, and the results doc's row
    names what the run started from: a demonstration start is never passed off as pure RL."""
    from assistive_compiler.training.results.results_page import results_block
    from assistive_compiler.training.results.table import make_tables
    from assistive_compiler.training.trained.export import export_run

    copy = tmp_path / "run"
    shutil.copytree(demo_run, copy)
    text = make_tables([str(copy)], episodes=2, seed=EVAL_SEED)
    assert " † (" in text and "† started from demonstrations (`train --demonstrations`)." in text
    record = export_run(copy, tmp_path / "exported", episodes=2, seed=EVAL_SEED)
    assert record["demonstrations"]["dataset"] == DEMOS and record["demonstrations"]["episodes"] == 8
    block = results_block([record])
    assert f"{record['label']} from 8 scripted demonstrations (320 steps)" in block
    assert f"Started from `{DEMOS}`: 8 episodes of the scripted policy (8 successful, 320 steps); the actor " in block
    assert "320 steps in the replay buffer, the critics warmed up for 5,000 gradient steps." in block
    # a run that kept the cloning term in SAC's actor loss says so in its row and its paragraph
    record["demonstrations"]["clone_weight"] = 0.4
    block = results_block([record])
    assert "(320 steps), cloning kept in the actor's loss (weight 0.4)" in block
    assert "; SAC learned with the cloning term kept in its actor loss (weight 0.4 × the demonstrated" in block
    record["demonstrations"]["hold_actor_steps"] = 10_000
    block = results_block([record])
    assert "(weight 0.4), the actor held for SAC's first 10,000 updates" in block
    assert "; the actor then held for SAC's first 10,000 updates (the critics learning the cloned policy's" in block
