"""``evaluate``: roll out a run's trained policy (SB3 or RLlib, static or co-optimised) as the
reference evaluates: mean ± std return, success rate, mean force on the person; deterministic
for a seed; optionally a GIF of one rollout. Needs the ``train`` extra."""

from __future__ import annotations

import argparse
import json

from .common import EXIT_FAILED, EXIT_OK, engine_modules, require_extra


def cmd_evaluate(args: argparse.Namespace) -> int:
    from ..training.run_dir import RunDir

    run = RunDir(args.run_dir)
    if not require_extra(*engine_modules(run.info().engine)):
        return EXIT_FAILED
    from ..training.evaluate import evaluate, format_report, save_evaluation

    result = evaluate(args.run_dir, episodes=args.episodes, seed=args.seed, render=args.render)
    save_evaluation(run, result)
    print(json.dumps(result, indent=1) if args.json else format_report(result))
    return EXIT_OK


def add_commands(sub) -> None:
    p = sub.add_parser("evaluate", help="roll out a run's trained policy: mean ± std return, success rate, force on the person")
    p.add_argument("run_dir", help="a run directory written by train")
    p.add_argument("--episodes", type=int, help="episodes (default: the run config's eval_episodes; the paper: 100)")
    p.add_argument("--seed", type=int, default=0, help="seed of the first episode (episode k: seed + k)")
    p.add_argument("--render", metavar="OUT", help="also write one rollout as OUT (.gif, or .png for a strip)")
    p.add_argument("--json", action="store_true", help="print JSON (with every episode)")
    p.set_defaults(func=cmd_evaluate)
