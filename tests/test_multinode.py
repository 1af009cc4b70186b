"""Training on a Ray cluster of two nodes whose worker cannot see the driver's files, as a second
machine cannot: the head node has no CPUs, so every env runner runs on the worker node, which is
started inside its own mount namespace with an empty tmpfs over the folder holding the driver's
run directory and compile cache. ``train --address`` finishes a single-agent and a co-optimised
run there (the compiled task travels with the job), and ``evaluate`` works on both results.

The test starts and stops its own Ray processes (by their process groups), with their own HOME
and authentication token; it skips where mount namespaces are unavailable."""

from __future__ import annotations

import json
import os
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import pytest

pytest.importorskip("ray", reason='needs the "train" extra (README: Training); CI installs it')
# Ray clusters run one at a time: under pytest-xdist every Ray test goes to the same worker.
pytestmark = pytest.mark.xdist_group("ray")

REPO = Path(__file__).resolve().parents[1]
FEEDING = REPO / "specs" / "tasks" / "feeding.yaml"
TINY = """\
algorithm: ppo
network: {hidden: [32, 32]}
ppo: {rollout_steps: 100, minibatch_size: 100, epochs: 1, normalize_observations: false, normalize_rewards: false}
total_steps: 200
envs: 2
checkpoint_every_steps: 200
eval_episodes: 1
"""


def _namespaces_work(tmp_path: Path) -> str | None:
    if shutil.which("unshare") is None:
        return "no unshare command"
    probe = tmp_path / "probe"
    probe.mkdir()
    result = subprocess.run(["unshare", "--mount", "--propagation", "private", "sh", "-c", f"mount -t tmpfs tmpfs {probe}"],
                            capture_output=True, text=True)
    return None if result.returncode == 0 else f"mount namespaces unavailable here ({result.stderr.strip() or result.returncode})"


def forget_cluster(port: int) -> None:
    """Remove Ray's record of the latest cluster (``/tmp/ray/ray_current_cluster``) where it names
    ours: a later plain ``ray.init()`` would otherwise try to join the stopped cluster."""
    record = Path("/tmp/ray/ray_current_cluster")
    if record.is_file() and f":{port}" in record.read_text():
        record.unlink()


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _wait_for_port(port: int, seconds: float = 60) -> None:
    deadline = time.time() + seconds
    while time.time() < deadline:
        try:
            socket.create_connection(("127.0.0.1", port), timeout=1).close()
            return
        except OSError:
            time.sleep(0.5)
    raise TimeoutError(f"nothing listens on port {port} after {seconds} s")


@pytest.fixture(scope="module")
def cluster(tmp_path_factory):
    """(address, hidden folder, env for the driver): a head node without CPUs and a worker node
    with 2, the worker unable to see ``hidden``."""
    root = tmp_path_factory.mktemp("cluster")
    reason = _namespaces_work(root)
    if reason:
        pytest.skip(reason)
    home, hidden = root / "home", root / "hidden"
    (home / ".ray").mkdir(parents=True)
    (home / ".ray" / "auth_token").write_text("c" * 64)
    hidden.mkdir()
    env = {k: v for k, v in os.environ.items() if not k.startswith("RAY_")}
    env.update(HOME=str(home), RAY_AUTH_MODE="token")
    port = _free_port()
    ray_cli = [sys.executable, "-m", "ray.scripts.scripts", "start", "--block", "--object-store-memory=150000000"]
    temp = tempfile.mkdtemp(prefix="rayt-", dir="/tmp")  # short (Unix socket paths); keeps the address file out of /tmp/ray
    log = root / "ray.log"
    with log.open("w") as out:
        head = subprocess.Popen(ray_cli + ["--head", f"--port={port}", "--num-cpus=0", "--include-dashboard=false", f"--temp-dir={temp}"], env=env,
                                stdout=out, stderr=out,
                                start_new_session=True)
        procs = [head]
        try:
            _wait_for_port(port)
            worker_cmd = " ".join(ray_cli + [f"--address=127.0.0.1:{port}", "--num-cpus=2"])
            worker_env = {**env, "ASSISTIVE_COMPILER_CACHE": str(hidden / "worker-cache")}
            worker = subprocess.Popen(["unshare", "--mount", "--propagation", "private", "sh", "-c",
                                       f"mount -t tmpfs tmpfs {hidden} && exec {worker_cmd}"],
                                      env=worker_env, stdout=out, stderr=out, start_new_session=True)
            procs.append(worker)
            _wait_for_worker_node(port, env, log)
            yield f"127.0.0.1:{port}", hidden, {**env, "ASSISTIVE_COMPILER_CACHE": str(hidden / "cache")}
        finally:
            for proc in reversed(procs):
                os.killpg(proc.pid, signal.SIGTERM)
            for proc in procs:
                proc.wait(timeout=60)
            forget_cluster(port)
            shutil.rmtree(temp, ignore_errors=True)


def _wait_for_worker_node(port: int, env: dict, log: Path, seconds: float = 90) -> None:
    """Until the head counts 2 CPUs (the worker node's); fails with the nodes' log otherwise."""
    probe = ("import ray, time, sys\n"
             f"ray.init(address='127.0.0.1:{port}', log_to_driver=False)\n"
             f"deadline = time.time() + {seconds}\n"
             "while ray.cluster_resources().get('CPU', 0) < 2 and time.time() < deadline:\n"
             "    time.sleep(1)\n"
             "sys.exit(0 if ray.cluster_resources().get('CPU', 0) >= 2 else 1)\n")
    result = subprocess.run([sys.executable, "-c", probe], env=env, capture_output=True, text=True, timeout=seconds + 60)
    assert result.returncode == 0, f"the worker node did not join: {log.read_text()[-2000:]}"


def _train(address: str, out: Path, env: dict, config: Path, *extra: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "assistive_compiler.cli", "train", str(FEEDING), "--robot", "jaco", "--config",
                           str(config), "--engine", "rllib", "--address", address, "--out", str(out), "--quiet", "--json", *extra],
                          env=env, capture_output=True, text=True, timeout=300, cwd=REPO)


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
    evaluation = subprocess.run([sys.executable, "-m", "assistive_compiler.cli", "evaluate", str(out), "--episodes", "1", "--json"],
                                env=env, capture_output=True, text=True, timeout=300, cwd=REPO)
    assert evaluation.returncode == 0, evaluation.stderr[-3000:]
    assert json.loads(evaluation.stdout)["coop"] is coop
