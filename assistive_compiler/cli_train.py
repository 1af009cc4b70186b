"""The learning commands of the CLI: ``train``, ``evaluate`` and ``table``.

They need the optional ``train`` extra (torch, stable-baselines3, ray[rllib]); the package itself
never imports it, and without it these commands say how to install it.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

EXIT_OK, EXIT_FAILED, EXIT_BAD_INPUT, EXIT_INTERRUPTED = 0, 1, 2, 130
INSTALL_HINT = ("the learning commands need the 'train' extra: install torch's CPU build first "
                "(pip install torch --index-url https://download.pytorch.org/whl/cpu), then pip install -e '.[train]'")


def _require_extra(*modules: str) -> bool:
    import importlib.util

    missing = [m for m in modules if importlib.util.find_spec(m) is None]
    if missing:
        print(f"error: {', '.join(missing)} not installed; {INSTALL_HINT}", file=sys.stderr)
    return not missing


def training_config_path(name: str) -> str:
    """A config path as given, or a shipped config by name (``ppo_quick`` -> specs/training/ppo_quick.yaml)."""
    from .paths import specs_dir

    if Path(name).exists() or "/" in name or name.endswith((".yaml", ".yml")):
        return name
    return str(specs_dir() / "training" / f"{name}.yaml")


def cmd_train(args: argparse.Namespace) -> int:
    from .training.train import choose_engine

    engine = choose_engine(args.engine, args.coop, args.address)  # a bad --engine is reported before imports
    if not _require_extra("torch", "stable_baselines3" if engine == "sb3" else "ray"):
        return EXIT_FAILED
    from .training.train import train

    summary = train(args.spec, robot=args.robot, config_path=training_config_path(args.config), coop=args.coop, engine=engine,
                    steps=args.steps, seed=args.seed, envs=args.envs, out=args.out, resume=args.resume,
                    address=args.address, quiet=args.quiet)
    if args.json:
        print(json.dumps(summary, indent=1))
    else:
        ret = summary["final_mean_return"]
        rate = summary["final_success_rate"]
        print(f"{summary['gym_id']}: {summary['steps']:,} steps in {summary['wall_s']:.0f} s "
              f"({summary['steps_per_s_including_learning']:.0f} steps/s including learning); "
              f"last mean return {'—' if ret is None else f'{ret:.1f}'}, success {'—' if rate is None else f'{rate:.2f}'}; "
              f"checkpoint {summary['checkpoint']}")
    if summary["interrupted"]:
        print("interrupted: checkpoint written; continue with the same command and --resume", file=sys.stderr)
        return EXIT_INTERRUPTED
    return EXIT_OK


def cmd_evaluate(args: argparse.Namespace) -> int:
    from .training.run_dir import RunDir

    engine = RunDir(args.run_dir).info().engine
    if not _require_extra("torch", "stable_baselines3" if engine == "sb3" else "ray"):
        return EXIT_FAILED
    from .training.evaluate import evaluate, format_report, save_evaluation

    result = evaluate(args.run_dir, episodes=args.episodes, seed=args.seed, render=args.render)
    save_evaluation(RunDir(args.run_dir), result)
    print(json.dumps(result, indent=1) if args.json else format_report(result))
    return EXIT_OK


def cmd_table(args: argparse.Namespace) -> int:
    if not _require_extra("torch", "matplotlib"):
        return EXIT_FAILED
    from .training.table import make_tables

    print(make_tables(args.run_dirs, out=args.out, episodes=args.episodes, seed=args.seed))
    return EXIT_OK


def add_commands(sub) -> None:
    p = sub.add_parser("train", help="learn a policy with PPO (SB3 on one machine; RLlib for --coop and Ray clusters)")
    p.add_argument("spec", help="task spec file")
    p.add_argument("--robot", help="robot name (default: the spec's default robot)")
    p.add_argument("--config", required=True,
                   help="training config: a file, or a shipped one by name (ppo_paper, ppo_laptop, ppo_quick, ppo_rllib_reference)")
    p.add_argument("--coop", action="store_true", help="co-optimisation: train the robot and the person (policies robot and human)")
    p.add_argument("--engine", default="auto", help="sb3 | rllib | auto (default: rllib for --coop or --address, else sb3)")
    p.add_argument("--address", help="attach to a running Ray cluster at HOST:PORT (or ray://HOST:PORT, or auto)")
    p.add_argument("--steps", type=int, help="total env steps (overrides the config's total_steps)")
    p.add_argument("--seed", type=int, help="seed (overrides the config's)")
    p.add_argument("--envs", type=int, help="env processes (overrides the config's)")
    p.add_argument("--out", help="run directory (default: runs/<task>-<robot>[-coop]-s<seed>)")
    p.add_argument("--resume", action="store_true", help="continue the run in --out from its newest checkpoint")
    p.add_argument("--quiet", action="store_true", help="no progress bar or reward table")
    p.add_argument("--json", action="store_true", help="print the run's summary as JSON")
    p.set_defaults(func=cmd_train)

    p = sub.add_parser("evaluate", help="roll out a run's trained policy: mean ± std return, success rate, force on the person")
    p.add_argument("run_dir", help="a run directory written by train")
    p.add_argument("--episodes", type=int, help="episodes (default: the run config's eval_episodes; the paper: 100)")
    p.add_argument("--seed", type=int, default=0, help="seed of the first episode (episode k: seed + k)")
    p.add_argument("--render", metavar="OUT", help="also write one rollout as OUT (.gif, or .png for a strip)")
    p.add_argument("--json", action="store_true", help="print JSON (with every episode)")
    p.set_defaults(func=cmd_evaluate)

    p = sub.add_parser("table", help="the paper's Tables I/II from run directories, ours beside the paper's")
    p.add_argument("run_dirs", nargs="+", help="run directories (static runs fill Table I, --coop runs Table II)")
    p.add_argument("--out", help="write OUT (.md) with OUT's .csv and .png (learning curves) beside it")
    p.add_argument("--episodes", type=int, help="episodes for runs not yet evaluated (default: each run's eval_episodes)")
    p.add_argument("--seed", type=int, default=0, help="seed for runs not yet evaluated")
    p.set_defaults(func=cmd_table)
