"""A Ray cluster on this machine for the multi-node tests and the cluster throughput benchmark:
a head without CPUs and worker nodes, each worker in a private mount namespace where the driver's
run directories and cache are hidden (as a second machine cannot see them). It starts and stops
its own Ray processes (by their process groups), with their own HOME and authentication token."""

from __future__ import annotations

import os
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
FEEDING = REPO / "specs" / "tasks" / "feeding.yaml"


def train_command(address: str, out: Path, config: Path, *extra: str) -> list[str]:
    """``train`` of Feeding × Jaco with ``config`` on the cluster at ``address`` (RLlib), into
    ``out``, printing its summary as JSON; ``extra``: more options (``--coop``, ``--resume``)."""
    return [
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
    ]


def namespaces_unavailable(tmp_path: Path) -> str | None:
    """Why a worker cannot get a private mount namespace here (None: it can)."""
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
