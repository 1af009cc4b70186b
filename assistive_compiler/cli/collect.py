"""``collect``: demonstration datasets in Minari (the ``datasets`` extra); the work is
:func:`assistive_compiler.datasets.collect`."""

from __future__ import annotations

import argparse
import os
import sys

from .common import EXIT_BAD_INPUT, EXIT_FAILED, EXIT_OK, add_spec_arguments


def cmd_collect(args: argparse.Namespace) -> int:
    try:
        import minari  # noqa: F401
    except ImportError:
        print(
            'collect: Minari datasets need the "datasets" extra: pip install "assistive-compiler[datasets]"',
            file=sys.stderr,
        )
        return EXIT_FAILED
    from ..datasets import collect
    from .output import progress

    if args.episodes < 1:
        print(f"collect: --episodes must be at least 1, got {args.episodes}", file=sys.stderr)
        return EXIT_BAD_INPUT
    with progress(f"collect {args.out}", args.episodes, enabled=not args.quiet) as tracker:
        try:
            dataset = collect(
                args.spec,
                args.robot,
                args.out,
                policy=args.policy,
                episodes=args.episodes,
                seed=args.seed,
                root=args.root,
                out=args.artifact,
                progress=lambda k, ok: tracker.done(f"episode {k}: success {'yes' if ok else 'no'}"),
            )
        except ValueError as exc:  # Minari: the id is malformed or already taken
            print(f"collect: {exc}", file=sys.stderr)
            return EXIT_BAD_INPUT
    meta = dataset.storage.metadata["assistive_compiler"]
    print(
        f"wrote Minari dataset {args.out} ({dataset.total_episodes} episodes, {dataset.total_steps} steps, "
        f"{sum(meta['successes'])} successful) under {os.environ.get('MINARI_DATASETS_PATH', '~/.minari/datasets')}"
    )
    print(
        f"load it with: minari.load_dataset({args.out!r})"
        + (f" and MINARI_DATASETS_PATH={args.root}" if args.root else "")
    )
    return EXIT_OK


def add_commands(sub) -> None:
    p = sub.add_parser(
        "collect",
        help="play a policy and write a Minari dataset (offline RL) with the spec's content hash and success flags",
    )
    add_spec_arguments(p)
    p.add_argument("--episodes", type=int, default=10)
    p.add_argument(
        "--out",
        required=True,
        metavar="DATASET",
        help="Minari dataset id, e.g. assistive_compiler/feeding-jaco/scripted-v0",
    )
    p.add_argument("--root", help="datasets directory (default $MINARI_DATASETS_PATH, else ~/.minari/datasets)")
    p.add_argument("--artifact", help="artifact directory (default generated/<task>-<robot>)")
    p.add_argument("--quiet", action="store_true", help="no progress on stderr")
    p.set_defaults(func=cmd_collect)
