"""Ray RLlib: multi-agent PPO (policies robot and human) on a co-optimised task against a local
Ray instance the test starts — one tiny iteration, a checkpoint, a resume, an evaluation of the
checkpoint — and an unreachable cluster address failing fast with a message."""

from __future__ import annotations

import contextlib
import json
import re
import time
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

pytest.importorskip("ray", reason='needs the "train" extra (README: Training); CI installs it')
# Ray clusters run one at a time: under pytest-xdist every Ray test goes to the same worker
# (tests/conftest.py gives the group to the scheduler, which xdist 3.8 alone fails to under pytest 9.2).
pytestmark = pytest.mark.xdist_group("ray")

from helpers import assert_exported_pair_acts_as  # noqa: E402 (after the importorskip)

from assistive_compiler.cli import main  # noqa: E402 (after the importorskip)
from assistive_compiler.run_dir import RunDir  # noqa: E402 (after the importorskip)
from assistive_compiler.training.train import train  # noqa: E402 (after the importorskip)
from assistive_compiler.training.trained.evaluate import evaluate  # noqa: E402 (after the importorskip)

REPO = Path(__file__).resolve().parents[2]
FEEDING = REPO / "specs" / "tasks" / "feeding.yaml"
REACH = REPO / "specs" / "examples" / "reach.yaml"

TINY = """\
algorithm: ppo
network: {hidden: [32, 32]}
ppo: {rollout_steps: 200, minibatch_size: 100, epochs: 2, normalize_observations: false, normalize_rewards: false}
total_steps: 200
envs: 1
checkpoint_every_steps: 200
eval_episodes: 1
"""


@pytest.fixture(scope="module")
def local_ray():
    import ray

    # "local": a private instance, even while a multi-node test's cluster runs on this machine
    ray.init(address="local", num_cpus=2, include_dashboard=False, log_to_driver=False)
    yield
    ray.shutdown()


@pytest.mark.slow
def test_multi_agent_ppo_iteration_checkpoint_resume_evaluate(local_ray, tmp_path):
    config = tmp_path / "tiny.yaml"
    config.write_text(TINY)
    out = tmp_path / "feeding-coop"
    first = train(str(FEEDING), robot="jaco", config_path=str(config), coop=True, out=str(out), quiet=True)
    run = RunDir(out)
    info = run.info()
    assert (info.engine, info.coop, first["steps"]) == ("rllib", True, 200)
    steps, checkpoint = run.latest_checkpoint()
    modules = checkpoint / "algo" / "learner_group" / "learner" / "rl_module"
    assert steps == 200 and (modules / "robot").is_dir() and (modules / "human").is_dir()

    # A driver killed while writing its next checkpoint leaves a partial directory and a torn curve row.
    partial = run.checkpoints / ".partial-step_0000000400"
    (partial / "algo").mkdir(parents=True)
    (partial / "algo" / "rllib_checkpoint.json").write_text('{"trunc')
    with (out / "curve.csv").open("a") as f:
        f.write("400,12.5,")
    assert run.latest_checkpoint()[0] == 200
    resumed = train(
        str(FEEDING), robot="jaco", config_path=str(config), coop=True, out=str(out), resume=True, steps=400, quiet=True
    )
    assert not partial.exists()
    assert resumed["steps"] == 400 and run.latest_checkpoint()[0] == 400
    rows = (out / "curve.csv").read_text().splitlines()
    assert [int(r.split(",")[0]) for r in rows[1:]] == [200, 400]

    strip = tmp_path / "coop.png"
    result = evaluate(out, episodes=1, seed=0, render=str(strip))
    assert result["engine"] == "rllib" and result["coop"] and result["trained_steps"] == 400
    assert Image.open(strip).size == (4 * 480, 360)  # a rollout of both trained policies, as a strip of 4 frames
    assert np.isfinite(result["mean_return"]) and result["per_episode"][0]["seed"] == 0
    assert evaluate(out, episodes=1, seed=0)["mean_return"] == result["mean_return"]  # deterministic for a seed
    summary = json.loads((out / "summary.json").read_text())
    assert summary["engine"] == "rllib" and summary["steps"] == 400

    # Deterministic actions are the Gaussian's means clipped to the action bounds (the env clips them
    # for the motion, but the action penalty sees them raw), and the NumPy export gives the same.
    import torch

    from assistive_compiler.policies.checkpoint import RLlibPolicy
    from assistive_compiler.training.trained.export import export_run

    pair = RLlibPolicy(checkpoint.parent / f"step_{400:010d}", coop=True, algorithm="ppo")
    with torch.no_grad():  # a head whose means leave the bounds
        for weight in pair.modules["robot"].pi.parameters():
            weight.mul_(1e3)
    obs = np.random.default_rng(0).normal(0.0, 1.0, (8, pair.modules["robot"].observation_space.shape[0]))
    actions = np.array([pair.agent("robot")(o) for o in obs])
    assert np.abs(actions).max() == 1.0 and (np.abs(actions) == 1.0).mean() > 0.5
    record = export_run(out, tmp_path / "ppo-pair", episodes=1, seed=0)
    assert record["coop"] and record["export_max_action_difference"] < 1e-4

    # --stochastic samples each agent's Gaussian from a seeded generator: the same seed, the same
    # actions; not the means.
    ckpt = checkpoint.parent / f"step_{400:010d}"
    sampled = [RLlibPolicy(ckpt, coop=True, algorithm="ppo", stochastic=True, seed=3) for _ in range(2)]
    mean = RLlibPolicy(ckpt, coop=True, algorithm="ppo")
    human_obs = np.zeros(mean.modules["human"].observation_space.shape[0])
    first, again = (p(obs[0], human_obs) for p in sampled)
    assert all(np.array_equal(a, b) for a, b in zip(first, again, strict=True))
    assert not np.array_equal(first[0], mean(obs[0], human_obs)[0])
    # The exported pair samples as the checkpoint does: the same means and σs (the head's second
    # half), the noise drawn in turn from one generator of the same seed: the same actions.
    from assistive_compiler.policies.pretrained import load_trained

    exported, _ = load_trained(str(tmp_path / "ppo-pair"))
    theirs = RLlibPolicy(ckpt, coop=True, algorithm="ppo", stochastic=True, seed=3)
    ours = exported.sampling(3)
    for o in obs:
        for a, b in zip(ours(o, human_obs), theirs(o, human_obs), strict=True):
            assert np.allclose(a, b, atol=1e-4)


def test_unreachable_ray_address_fails_fast_with_a_message(tmp_path, capsys):
    out = tmp_path / "run"
    t0 = time.perf_counter()
    code = main(
        ["train", str(REACH), "--config", "ppo_quick", "--address", "127.0.0.1:1", "--out", str(out), "--quiet"]
    )
    elapsed = time.perf_counter() - t0
    err = capsys.readouterr().err
    assert code == 2 and elapsed < 20
    assert "error: --address: no Ray cluster reachable at 127.0.0.1:1" in err
    assert not out.exists()


SAC_TINY = """\
algorithm: sac
network: {hidden: [16, 16], activation: relu}
sac: {learning_starts: 40, buffer_size: 2000, batch_size: 16}
total_steps: 100
envs: 1
checkpoint_every_steps: 100
eval_episodes: 1
"""


@pytest.mark.slow
def test_multi_agent_sac_trains_and_exports_a_pair_that_plays_under_coop(local_ray, tmp_path, capsys):
    """Co-optimisation with SAC on RLlib: robot and human modules learn, the pair exports to NumPy
    (each agent's actions equal the checkpoint's) and plays both agents from `run --coop`."""
    from assistive_compiler.training.trained.export import export_run

    config = tmp_path / "sac_tiny.yaml"
    config.write_text(SAC_TINY)
    out = tmp_path / "feeding-coop-sac"
    figures = train(str(FEEDING), robot="jaco", config_path=str(config), coop=True, out=str(out), quiet=True)
    assert figures["steps"] >= 100 and RunDir(out).info().algorithm == "sac"
    record = export_run(out, tmp_path / "pair", episodes=1, seed=7)
    assert record["coop"] and record["export_max_action_difference"] < 1e-4
    assert {p.name for p in (tmp_path / "pair").iterdir()} >= {"policy.json", "robot", "human"}
    from assistive_compiler.policies.checkpoint import load_policy
    from assistive_compiler.policies.pretrained import load_trained

    run = RunDir(out)
    checkpoint_pair = load_policy(run.info(), run.latest_checkpoint()[1])
    exported, _ = load_trained(str(tmp_path / "pair"))
    assert_exported_pair_acts_as(checkpoint_pair, exported, run.artifact)
    capsys.readouterr()
    assert (
        main(
            [
                "run",
                str(FEEDING),
                "--robot",
                "jaco",
                "--coop",
                "--policy",
                str(tmp_path / "pair"),
                "--episodes",
                "1",
                "--seed",
                "7",
                "--json",
                "--quiet",
            ]
        )
        == 0
    )
    report = json.loads(capsys.readouterr().out)
    assert report["human_policy"] == str(tmp_path / "pair")  # the pair plays the person too
    assert report["episodes"][0]["return"] == pytest.approx(record["evaluation"]["returns"][0], abs=1e-3)
    strip = tmp_path / "pair.png"
    assert (
        main(
            [
                "render",
                str(FEEDING),
                "--robot",
                "jaco",
                "--policy",
                str(tmp_path / "pair"),
                "--seed",
                "7",
                "--out",
                str(strip),
            ]
        )
        == 0
    )
    # both agents acted, as in run --coop: the picture's episode has the evaluation's return (printed
    # to one decimal, so a return near a rounding edge may print either neighbour)
    printed = re.search(r"return (-?[0-9.]+)", capsys.readouterr().out)
    assert printed and float(printed.group(1)) == pytest.approx(record["evaluation"]["returns"][0], abs=0.06)


def _free_port() -> int:
    import socket

    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _ray_home(where: Path, token: str) -> Path:
    """A HOME whose ~/.ray/auth_token is ``token`` (64 characters)."""
    (where / ".ray").mkdir(parents=True)
    (where / ".ray" / "auth_token").write_text(token)
    return where


@contextlib.contextmanager
def _head_node(home: Path):
    """A head node without CPUs, as a user's plain ``ray start --head`` runs it (Ray's default temp
    folder, so it becomes this machine's "latest cluster"), with ``home``'s token; yields its
    port and stops it by its process group, forgetting it as the latest cluster."""
    import os
    import signal
    import socket
    import subprocess
    import sys

    from ray_cluster import forget_cluster

    port = _free_port()
    base = {k: v for k, v in os.environ.items() if not k.startswith("RAY_")}
    head = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "ray.scripts.scripts",
            "start",
            "--head",
            f"--port={port}",
            "--num-cpus=0",
            "--include-dashboard=false",
            "--block",
        ],
        env={**base, "HOME": str(home), "RAY_AUTH_MODE": "token"},
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        start_new_session=True,
    )
    try:
        deadline = time.time() + 60
        while time.time() < deadline:
            try:
                socket.create_connection(("127.0.0.1", port), timeout=1).close()
                break
            except OSError:
                time.sleep(0.5)
        latest = Path("/tmp/ray/ray_current_cluster")  # written once the head is up, after its port opens
        while time.time() < deadline and not (latest.is_file() and f":{port}" in latest.read_text()):
            time.sleep(0.5)
        yield port
    finally:
        os.killpg(head.pid, signal.SIGTERM)
        head.wait(timeout=60)
        forget_cluster(port)


@pytest.mark.slow
def test_local_training_starts_its_own_ray_while_a_cluster_runs_here(tmp_path):
    """Without --address, training starts a private Ray instance with the CPUs it asks for. Ray's
    own default (a plain ``ray.init()``) joins the latest ``ray start`` cluster on this machine and
    then refuses the CPU count ("When connecting to an existing cluster, num_cpus ... must not be
    provided"): a cluster started here must not break local training."""
    import os
    import subprocess
    import sys

    home = _ray_home(tmp_path / "home", "c" * 64)
    probe = (
        "import ray\n"
        "from assistive_compiler.training.engines.rllib import init_ray\n"
        "init_ray(None, 2)\n"
        "print(ray.get_runtime_context().gcs_address, ray.cluster_resources().get('CPU'))\n"
    )
    with _head_node(home) as port:
        result = subprocess.run(
            [sys.executable, "-c", probe],
            env={**{k: v for k, v in os.environ.items() if not k.startswith("RAY_")}, "HOME": str(home)},
            capture_output=True,
            text=True,
            timeout=120,
            cwd=REPO,
        )
    assert result.returncode == 0, result.stderr[-3000:]
    gcs, cpus = result.stdout.split()[-2:]
    assert not gcs.endswith(f":{port}") and float(cpus) == 3.0  # its own instance, max(2, envs + 1) CPUs


@pytest.mark.slow
def test_a_refused_authentication_token_says_so_and_names_rays_remedy(tmp_path):
    """A Ray cluster that answers but rejects this machine's token (a stale ~/.ray/auth_token from an
    earlier local ray.init()) is not 'no cluster': the message says the token was refused and how to
    fix it. The test starts its own head node (its own HOME and token) and stops it by its id."""
    import os
    import subprocess
    import sys

    head_home = _ray_home(tmp_path / "head", "a" * 64)
    driver_home = _ray_home(tmp_path / "driver", "b" * 64)
    with _head_node(head_home) as port:
        proc = subprocess.run(
            [
                sys.executable,
                "-m",
                "assistive_compiler.cli",
                "train",
                str(REACH),
                "--config",
                "ppo_quick",
                "--address",
                f"127.0.0.1:{port}",
                "--out",
                str(tmp_path / "run"),
                "--quiet",
            ],
            env={**{k: v for k, v in os.environ.items() if not k.startswith("RAY_")}, "HOME": str(driver_home)},
            capture_output=True,
            text=True,
            timeout=120,
        )
    assert proc.returncode == 2
    assert (
        f"error: --address: the Ray cluster at 127.0.0.1:{port} refused this machine's authentication token "
        "(~/.ray/auth_token, $RAY_AUTH_TOKEN or $RAY_AUTH_TOKEN_PATH). Ray's remedy: every machine uses the cluster's token"
    ) in proc.stderr
    assert not (tmp_path / "run" / "run.json").exists()  # nothing written for a run that never started
