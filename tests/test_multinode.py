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
    result = subprocess.run(
        ["unshare", "--mount", "--propagation", "private", "sh", "-c", f"mount -t tmpfs tmpfs {probe}"],
        capture_output=True,
        text=True,
    )
    return (
        None
        if result.returncode == 0
        else f"mount namespaces unavailable here ({result.stderr.strip() or result.returncode})"
    )


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


class Cluster:
    """A Ray head without CPUs and worker nodes with 2 CPUs each, every worker in a private mount
    namespace where ``hidden`` (the driver's run directories and cache) is an empty tmpfs. Its own
    processes only, stopped by their process groups."""

    def __init__(self, root: Path):
        self.root, self.hidden = root, root / "hidden"
        home = root / "home"
        (home / ".ray").mkdir(parents=True)
        (home / ".ray" / "auth_token").write_text("c" * 64)
        self.hidden.mkdir()
        self.env = {k: v for k, v in os.environ.items() if not k.startswith("RAY_")}
        self.env.update(HOME=str(home), RAY_AUTH_MODE="token")
        self.port = _free_port()
        self.address = f"127.0.0.1:{self.port}"
        self.ray_cli = [
            sys.executable,
            "-m",
            "ray.scripts.scripts",
            "start",
            "--block",
            "--object-store-memory=150000000",
        ]
        self.temp = tempfile.mkdtemp(
            prefix="rayt-", dir="/tmp"
        )  # short (Unix socket paths); keeps the address file out of /tmp/ray
        self.log = root / "ray.log"
        self.procs: list[subprocess.Popen] = []
        self._start(
            self.ray_cli
            + ["--head", f"--port={self.port}", "--num-cpus=0", "--include-dashboard=false", f"--temp-dir={self.temp}"]
        )
        _wait_for_port(self.port)

    @property
    def driver_env(self) -> dict:
        return {**self.env, "ASSISTIVE_COMPILER_CACHE": str(self.hidden / "cache")}

    def _start(self, command: list[str]) -> subprocess.Popen:
        with self.log.open("a") as out:
            proc = subprocess.Popen(
                command,
                env=self.env
                if command[0] != "unshare"
                else {**self.env, "ASSISTIVE_COMPILER_CACHE": str(self.hidden / "worker-cache")},
                stdout=out,
                stderr=out,
                start_new_session=True,
            )
        self.procs.append(proc)
        return proc

    def add_worker(self, cpus: int = 2, cluster_cpus: int = 2) -> subprocess.Popen:
        """A worker node with ``cpus`` CPUs that cannot see ``hidden``; returns once the head counts
        ``cluster_cpus`` in all."""
        worker_cmd = " ".join(self.ray_cli + [f"--address={self.address}", f"--num-cpus={cpus}"])
        worker = self._start(
            [
                "unshare",
                "--mount",
                "--propagation",
                "private",
                "sh",
                "-c",
                f"mount -t tmpfs tmpfs {self.hidden} && exec {worker_cmd}",
            ]
        )
        _wait_for_worker_node(self.port, self.env, self.log, cpus=cluster_cpus)
        return worker

    def kill(self, proc: subprocess.Popen) -> None:
        """The node dies at once: SIGKILL to its whole process group (raylet and its workers)."""
        os.killpg(proc.pid, signal.SIGKILL)
        proc.wait(timeout=60)

    def stop(self) -> None:
        """SIGTERM to every node's process group; what is still running 5 s later gets SIGKILL (a head
        that lost a node otherwise spent ~30 s of each test's teardown waiting on it)."""
        for proc in reversed(self.procs):
            if proc.poll() is None:
                os.killpg(proc.pid, signal.SIGTERM)
        deadline = time.time() + 5
        for proc in self.procs:
            try:
                proc.wait(timeout=max(0.1, deadline - time.time()))
            except subprocess.TimeoutExpired:
                pass
            try:  # the group's leader may be gone with some of its children still there
                os.killpg(proc.pid, signal.SIGKILL)
            except ProcessLookupError:
                pass
            proc.wait(timeout=60)
        forget_cluster(self.port)
        shutil.rmtree(self.temp, ignore_errors=True)


@pytest.fixture(scope="module")
def cluster(tmp_path_factory):
    """(address, hidden folder, env for the driver): a head node without CPUs and a worker node
    with 2, the worker unable to see ``hidden``."""
    root = tmp_path_factory.mktemp("cluster")
    reason = _namespaces_work(root)
    if reason:
        pytest.skip(reason)
    c = Cluster(root)
    try:
        c.add_worker()
        yield c.address, c.hidden, c.driver_env
    finally:
        c.stop()


def _wait_for_worker_node(port: int, env: dict, log: Path, seconds: float = 90, cpus: int = 2) -> None:
    """Until the head counts ``cpus`` CPUs (the worker nodes'); fails with the nodes' log otherwise."""
    probe = (
        "import ray, time, sys\n"
        f"ray.init(address='127.0.0.1:{port}', log_to_driver=False)\n"
        f"deadline = time.time() + {seconds}\n"
        f"while ray.cluster_resources().get('CPU', 0) < {cpus} and time.time() < deadline:\n"
        "    time.sleep(1)\n"
        f"sys.exit(0 if ray.cluster_resources().get('CPU', 0) >= {cpus} else 1)\n"
    )
    result = subprocess.run(
        [sys.executable, "-c", probe], env=env, capture_output=True, text=True, timeout=seconds + 60
    )
    assert result.returncode == 0, f"the worker node did not join: {log.read_text()[-2000:]}"


def _train(address: str, out: Path, env: dict, config: Path, *extra: str) -> subprocess.CompletedProcess:
    return subprocess.run(
        [
            sys.executable,
            "-m",
            "assistive_compiler.cli",
            "train",
            str(FEEDING),
            "--robot",
            "jaco",
            "--config",
            str(config),
            "--engine",
            "rllib",
            "--address",
            address,
            "--out",
            str(out),
            "--quiet",
            "--json",
            *extra,
        ],
        env=env,
        capture_output=True,
        text=True,
        timeout=300,
        cwd=REPO,
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
    command = [
        sys.executable,
        "-m",
        "assistive_compiler.cli",
        "train",
        str(FEEDING),
        "--robot",
        "jaco",
        "--config",
        str(config),
        "--engine",
        "rllib",
        "--address",
        c.address,
        "--out",
        str(out),
        "--quiet",
        "--json",
    ]
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
    reason = _namespaces_work(tmp_path)
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
    reason = _namespaces_work(tmp_path)
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
