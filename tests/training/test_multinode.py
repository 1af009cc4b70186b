"""Training on a Ray cluster of two nodes whose worker cannot see the driver's files, as a second
machine cannot: the head node has no CPUs, so every env runner runs on the worker node, which is
started inside its own mount namespace with an empty tmpfs over the folder holding the driver's
run directory and compile cache. ``train --address`` finishes a single-agent and a co-optimised
run there (the compiled task travels with the job), and ``evaluate`` works on both results.

The test starts and stops its own Ray processes (by their process groups), with their own HOME
and authentication token; it skips where mount namespaces are unavailable."""

from __future__ import annotations

import json
import subprocess
import sys
import time
from pathlib import Path

import pytest
from ray_cluster import REPO, Cluster, namespaces_unavailable, train_command

pytest.importorskip("ray", reason='needs the "train" extra (README: Training); CI installs it')
# Ray clusters run one at a time: under pytest-xdist every Ray test goes to the same worker.
pytestmark = pytest.mark.xdist_group("ray")

TINY = """\
algorithm: ppo
network: {hidden: [32, 32]}
ppo: {rollout_steps: 100, minibatch_size: 100, epochs: 1, normalize_observations: false, normalize_rewards: false}
total_steps: 200
envs: 2
checkpoint_every_steps: 200
eval_episodes: 1
"""


@pytest.fixture(scope="module")
def cluster(tmp_path_factory):
    """(address, hidden folder, env for the driver): a head node without CPUs and a worker node
    with 2, the worker unable to see ``hidden``."""
    root = tmp_path_factory.mktemp("cluster")
    reason = namespaces_unavailable(root)
    if reason:
        pytest.skip(reason)
    c = Cluster(root)
    try:
        c.add_worker()
        yield c.address, c.hidden, c.driver_env
    finally:
        c.stop()


def _train(address: str, out: Path, env: dict, config: Path, *extra: str) -> subprocess.CompletedProcess:
    return subprocess.run(
        train_command(address, out, config, *extra), env=env, capture_output=True, text=True, timeout=300, cwd=REPO
    )


@pytest.mark.slow
@pytest.mark.parametrize("coop", [False, True], ids=["single-agent", "co-optimised"])
def test_train_on_a_worker_that_cannot_see_the_drivers_files(cluster, coop, tmp_path):
    address, hidden, env = cluster
    config = tmp_path / "tiny.yaml"
    config.write_text(TINY)
    out = hidden / f"run-{'coop' if coop else 'single'}"
    result = _train(address, out, env, config, *(["--coop"] if coop else []))
    assert result.returncode == 0, result.stderr[-3000:]
    summary = json.loads(result.stdout)
    assert summary["steps"] >= 200 and summary["engine"] == "rllib"
    evaluation = subprocess.run(
        [sys.executable, "-m", "assistive_compiler.cli", "evaluate", str(out), "--episodes", "1", "--json"],
        env=env,
        capture_output=True,
        text=True,
        timeout=300,
        cwd=REPO,
    )
    assert evaluation.returncode == 0, evaluation.stderr[-3000:]
    assert json.loads(evaluation.stdout)["coop"] is coop


def _train_and_kill_a_node_mid_run(c: Cluster, config: Path, out: Path, node: subprocess.Popen):
    """Start ``train --address`` in the background, SIGKILL ``node`` once the run's first checkpoint
    is written (the run still going), and wait for the driver: (driver, stdout, stderr)."""
    command = train_command(c.address, out, config)
    driver = subprocess.Popen(
        command, env=c.driver_env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=REPO
    )
    try:
        deadline = time.time() + 240
        while not list((out / "checkpoints").glob("step_*")) and time.time() < deadline and driver.poll() is None:
            time.sleep(1)
        assert list((out / "checkpoints").glob("step_*")), "no checkpoint before the node was killed"
        assert driver.poll() is None, "the run ended before the node was killed"
        c.kill(node)
        stdout, stderr = driver.communicate(timeout=300)
    finally:
        if driver.poll() is None:
            driver.kill()
    return driver, stdout, stderr


@pytest.mark.slow
def test_a_worker_node_lost_mid_run_stops_with_a_checkpoint_and_resume_finishes(tmp_path):
    """The only worker node dies (SIGKILL to its raylet and env runners) during a run: training
    stops with a checkpoint and says why instead of waiting for a node; with a new worker node,
    --resume goes on from that checkpoint and finishes."""
    reason = namespaces_unavailable(tmp_path)
    if reason:
        pytest.skip(reason)
    c = Cluster(tmp_path)
    try:
        worker = c.add_worker()
        config = tmp_path / "long.yaml"
        config.write_text(TINY.replace("total_steps: 200", "total_steps: 1000000"))
        out = c.hidden / "run"
        driver, stdout, stderr = _train_and_kill_a_node_mid_run(c, config, out, worker)
        assert driver.returncode == 130, stderr[-3000:]
        assert (
            "stopped: all 2 env runners were lost (the node they ran on died or left the cluster); checkpoint written: "
            "start a worker node again and run the same command with --resume" in stderr
        ), stderr[-3000:]
        summary = json.loads(stdout)
        assert summary["interrupted"] and 200 <= summary["steps"] < 1_000_000
        stopped_at = summary["steps"]
        assert (out / "checkpoints" / f"step_{stopped_at:010d}" / "COMPLETE").is_file()

        c.add_worker()
        resumed = _train(c.address, out, c.driver_env, config, "--resume", "--steps", str(stopped_at + 200))
        assert resumed.returncode == 0, resumed.stderr[-3000:]
        assert json.loads(resumed.stdout)["steps"] >= stopped_at + 200
    finally:
        c.stop()


@pytest.mark.slow
def test_a_run_goes_on_with_the_env_runners_left_when_one_of_two_nodes_dies(tmp_path):
    """Two worker nodes of one CPU each, one env runner on each: the first dies mid-run, and
    training goes on with the other's samples to the end of the run."""
    reason = namespaces_unavailable(tmp_path)
    if reason:
        pytest.skip(reason)
    c = Cluster(tmp_path)
    try:
        first = c.add_worker(cpus=1, cluster_cpus=1)
        c.add_worker(cpus=1, cluster_cpus=2)
        config = tmp_path / "longer.yaml"
        config.write_text(TINY.replace("total_steps: 200", "total_steps: 1400"))
        out = c.hidden / "run"
        driver, stdout, stderr = _train_and_kill_a_node_mid_run(c, config, out, first)
        assert driver.returncode == 0 and stdout.startswith("{"), (stdout[:3000], stderr[-3000:])
        summary = json.loads(stdout)
        assert summary["steps"] >= 1400 and not summary["interrupted"]
    finally:
        c.stop()
