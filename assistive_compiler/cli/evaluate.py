"""``evaluate``: roll out a trained policy — a run directory (SB3 or RLlib, static or
co-optimised; needs the ``train`` extra), a shipped one (``pretrained:<task>-<robot>``) or an
exported folder (NumPy only) — as the reference evaluates: mean ± std return, success rate, mean
force on the person; deterministic for a seed; optionally a GIF of one rollout."""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from ..run_dir import engine_modules
from .common import EXIT_BAD_INPUT, EXIT_FAILED, EXIT_OK, require_extra


def cmd_evaluate(args: argparse.Namespace) -> int:
    from ..policies.mlp import POLICY_FILE
    from ..policies.pretrained import PREFIX
    from ..run_dir import RunDir
    from ..training.trained.evaluate import evaluate_exported, format_report

    source = args.policy or args.run_dir
    if source is None:
        print(
            "evaluate: give a run directory, or --policy pretrained:<task>-<robot> (or a run directory)",
            file=sys.stderr,
        )
        return EXIT_BAD_INPUT
    if source.startswith(PREFIX) or (Path(source) / POLICY_FILE).is_file():  # shipped or exported: NumPy only
        if args.checkpoint is not None:
            print(
                f"evaluate: --checkpoint picks a checkpoint of a run directory; {source} is an exported policy (one checkpoint)",
                file=sys.stderr,
            )
            return EXIT_BAD_INPUT
        result = evaluate_exported(
            source, episodes=args.episodes or 100, seed=args.seed, render=args.render, stochastic=args.stochastic
        )
        print(json.dumps(result, indent=1) if args.json else format_report(result))
        return EXIT_OK
    run = RunDir(source)
    info = run.info()
    if not require_extra(*engine_modules(info.engine, info.library)):
        return EXIT_FAILED
    from ..training.trained.evaluate import evaluate, save_evaluation

    result = evaluate(
        source,
        episodes=args.episodes,
        seed=args.seed,
        render=args.render,
        checkpoint_steps=args.checkpoint,
        stochastic=args.stochastic,
    )
    if not args.stochastic and (args.checkpoint is None or args.checkpoint == run.latest_checkpoint()[0]):
        save_evaluation(run, result)  # evaluation.json (what `table` reads): the newest checkpoint, deterministic
    print(json.dumps(result, indent=1) if args.json else format_report(result))
    return EXIT_OK


def add_commands(sub) -> None:
    p = sub.add_parser(
        "evaluate", help="roll out a trained policy: mean ± std return, success rate, force on the person"
    )
    p.add_argument("run_dir", nargs="?", help="a run directory written by train (or give --policy)")
    p.add_argument(
        "--policy",
        help="instead of RUN_DIR: pretrained:<task>-<robot> (shipped), an exported policy folder or a run directory",
    )
    p.add_argument("--episodes", type=int, help="episodes (default: the run config's eval_episodes; the paper: 100)")
    p.add_argument("--seed", type=int, default=0, help="seed of the first episode (episode k: seed + k)")
    p.add_argument("--render", metavar="OUT", help="also write one rollout as OUT (.gif, or .png for a strip)")
    p.add_argument(
        "--checkpoint",
        type=int,
        metavar="STEPS",
        help="a run's checkpoint at this many env steps (default: the "
        "newest), e.g. to compare two runs at the same budget",
    )
    p.add_argument(
        "--stochastic",
        action="store_true",
        help="actions sampled as in training (seeded by --seed) instead of deterministic: a run directory's, or an "
        "exported policy's that kept its log-std; a run's evaluation.json is left as it is",
    )
    p.add_argument("--json", action="store_true", help="print JSON (with every episode)")
    p.set_defaults(func=cmd_evaluate)
