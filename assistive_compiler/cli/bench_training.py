"""``bench --training CONFIG ...``: env steps per second *including learning*, side by side for
the configs compared, with the shares of env step, learner update and the rest
(:mod:`assistive_compiler.training.throughput`). Needs the ``train`` extra."""

from __future__ import annotations

import argparse
import json

from .common import EXIT_OK

TRAINING_TABLE = (
    "task",
    "robot",
    "config",
    "algorithm",
    "library",
    "network",
    "envs",
    "vec_env",
    "updates_per_env_step",
    "env_steps_per_s",
    "env_steps_per_hour_millions",
    "env_share",
    "update_share",
    "rest_share",
)


def cmd_bench_training(args: argparse.Namespace, pairs: list[tuple[str, str | None]]) -> int:
    """Measure every config in ``args.training`` on every spec × robot pair, one after another in
    this process (run it on an otherwise idle core: ``taskset -c 1 assistive-compiler bench ...``)."""
    from ..run_dir import engine_modules
    from ..training.config import load_training_config
    from .common import EXIT_FAILED, require_extra
    from .train import training_config_path

    configs = [training_config_path(name) for name in args.training]
    needed = dict.fromkeys(m for c in configs for m in engine_modules("sb3", load_training_config(c).library))
    if not require_extra(*needed):
        return EXIT_FAILED
    from ..training.throughput import measure_training
    from .output import cell, print_table, progress

    results = []
    with progress("bench --training", len(pairs) * len(configs)) as tracker:
        for spec, robot in pairs:
            for config in configs:
                r = measure_training(spec, robot, config, args.training_steps)
                tracker.done(
                    f"{r['task']}/{r['robot']} {r['config']}: {r['env_steps_per_s']} env steps/s with learning"
                )
                results.append(r)
    if args.json:
        print(json.dumps(results, indent=1))
        return EXIT_OK
    print_table(
        list(TRAINING_TABLE),
        [[cell(r[k]) for k in TRAINING_TABLE] for r in results],
        left=("task", "robot", "config", "algorithm", "vec_env"),
        caption=f"{args.training_steps:,} env steps each, measured one after another in one process; "
        "shares of the learning loop's wall time (env: stepping the envs; update: the learner's updates; "
        "rest: acting, buffers, normalisation, logging)",
    )
    return EXIT_OK


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--training",
        action="append",
        metavar="CONFIG",
        help="measure training instead: env steps/s including learning of this training config (a file, or a "
        "shipped one by name, e.g. ppo_one_core); give several to compare them side by side. Needs the train extra",
    )
    p.add_argument(
        "--training-steps",
        type=int,
        default=8_000,
        help="env steps each --training config trains for (PPO: at least one rollout batch; default 8,000)",
    )
