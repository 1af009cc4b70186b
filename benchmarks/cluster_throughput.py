"""Does spreading env runners over machines cost throughput? (README: Training on several machines.)

On this machine, a Ray head without CPUs and either one worker node with 2 CPUs or two worker nodes
with 1 CPU each (every worker in its own mount namespace that cannot see the driver's files, as
a second machine cannot: tests/ray_cluster.py). ``train --address`` runs the same short PPO job
on each layout — Feeding × Jaco, 2×64 network, 2 env runners, 400-step rollouts, 4 epochs —
``--repeats`` times, the two layouts alternating so a change of load falls on both. Prints each
run's env steps/s including learning (the run's own figure, ``train --json``), the medians and
their ratio (two nodes / one node), and the steps/s per env runner.

    python benchmarks/cluster_throughput.py --repeats 3 --steps 8000 [--json]

Needs the ``train`` extra and mount namespaces (``unshare``, root); run it on an otherwise idle
machine, nothing else training.
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "tests"))

from ray_cluster import Cluster, namespaces_unavailable, train_command  # noqa: E402

CONFIG = """\
algorithm: ppo
description: "cluster throughput benchmark: the paper's 2x64 PPO, short rollouts"
network: {{hidden: [64, 64], activation: tanh}}
ppo: {{rollout_steps: 400, minibatch_size: 200, epochs: 4}}
total_steps: {steps}
envs: 2
checkpoint_every_steps: {steps}
eval_episodes: 1
"""

LAYOUTS = {"one node, 2 CPUs": [2], "two nodes, 1 CPU each": [1, 1]}


def run_once(root: Path, cpus: list[int], config: Path) -> float:
    """Env steps/s including learning of one ``train --address`` run on a fresh cluster."""
    cluster = Cluster(root)
    try:
        for k, n in enumerate(cpus):
            cluster.add_worker(cpus=n, cluster_cpus=sum(cpus[: k + 1]))
        result = subprocess.run(
            train_command(cluster.address, cluster.hidden / "run", config),
            env=cluster.driver_env,
            capture_output=True,
            text=True,
            timeout=1200,
            cwd=REPO,
        )
        if result.returncode != 0:
            raise SystemExit(f"train failed on {cpus}: {result.stderr[-2000:]}")
        return float(json.loads(result.stdout)["steps_per_s_including_learning"])
    finally:
        cluster.stop()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3, help="runs per layout (default 3)")
    parser.add_argument("--steps", type=int, default=8000, help="env steps per run (default 8000)")
    parser.add_argument("--json", action="store_true", help="print the figures as JSON")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory(prefix="cluster-bench-") as tmp:
        root = Path(tmp)
        reason = namespaces_unavailable(root)
        if reason:
            raise SystemExit(f"cannot hide the driver's files from a worker: {reason}")
        config = root / "ppo_bench.yaml"
        config.write_text(CONFIG.format(steps=args.steps))
        rates: dict[str, list[float]] = {name: [] for name in LAYOUTS}
        for k in range(args.repeats):
            order = list(LAYOUTS.items())
            for name, cpus in order if k % 2 == 0 else order[::-1]:
                where = root / f"{k}-{len(cpus)}"
                where.mkdir()
                rates[name].append(run_once(where, cpus, config))
                if not args.json:
                    print(f"run {k + 1}: {name}: {rates[name][-1]:.1f} env steps/s", flush=True)
    one, two = (statistics.median(rates[name]) for name in LAYOUTS)
    figures = {
        "steps": args.steps,
        "repeats": args.repeats,
        "runs": rates,
        "median_one_node": one,
        "median_two_nodes": two,
        "two_nodes_vs_one": two / one,
        "per_env_runner": two / 2,
    }
    if args.json:
        print(json.dumps(figures, indent=1))
    else:
        print(
            f"medians: one node {one:.1f}, two nodes {two:.1f} env steps/s ({two / one:.2f}x); "
            f"{two / 2:.1f} env steps/s per env runner"
        )


if __name__ == "__main__":
    main()
