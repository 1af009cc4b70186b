"""``table``: the paper's Tables I and II from run directories, our values beside the paper's,
as Markdown (printed, or ``--out results.md``) with a CSV and a learning-curve figure beside it.
Needs the ``train`` extra."""

from __future__ import annotations

import argparse

from .common import EXIT_FAILED, EXIT_OK, require_extra


def cmd_table(args: argparse.Namespace) -> int:
    if not require_extra("torch", "matplotlib"):
        return EXIT_FAILED
    from ..training.results.table import make_tables

    print(make_tables(args.run_dirs, out=args.out, episodes=args.episodes, seed=args.seed))
    return EXIT_OK


def add_commands(sub) -> None:
    p = sub.add_parser("table", help="the paper's Tables I/II from run directories, ours beside the paper's")
    p.add_argument("run_dirs", nargs="+", help="run directories (static runs fill Table I, --coop runs Table II)")
    p.add_argument("--out", help="write OUT (.md) with OUT's .csv and .png (learning curves) beside it")
    p.add_argument(
        "--episodes", type=int, help="episodes for runs not yet evaluated (default: each run's eval_episodes)"
    )
    p.add_argument("--seed", type=int, default=0, help="seed for runs not yet evaluated")
    p.set_defaults(func=cmd_table)
