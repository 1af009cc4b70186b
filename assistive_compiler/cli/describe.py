"""``describe``: a compiled task's scene after a reset, every body, link, frame, target and tool."""

from __future__ import annotations

import argparse
import json

from .common import EXIT_OK, add_spec_arguments, make_env


def cmd_describe(args: argparse.Namespace) -> int:
    from ..describe import describe_scene, describe_text

    env = make_env(args.spec, args.robot, args.out_dir)
    try:
        env.reset(seed=args.seed)
        scene = describe_scene(env)
    finally:
        env.close()
    print(json.dumps(scene, indent=1) if args.json else describe_text(scene))
    return EXIT_OK


def add_commands(sub) -> None:
    p = sub.add_parser(
        "describe",
        help="every body and link of a task's scene after a reset: world positions, frame axes, "
        "targets, tools, markers",
    )
    add_spec_arguments(p, policy=False)
    p.add_argument("--json", action="store_true", help="print JSON")
    p.add_argument("--out-dir", dest="out_dir", help="artifact directory")
    p.set_defaults(func=cmd_describe)
