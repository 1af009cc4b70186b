"""``view``: look at a task's episode in the browser (viser on localhost) or in pybullet's GUI.

The work is :func:`assistive_compiler.viewer.view`; this module parses arguments and says
clearly when the ``view`` extra is not installed.
"""

from __future__ import annotations

import argparse
import sys

from .common import EXIT_BAD_INPUT, EXIT_FAILED, add_artifact_argument, add_spec_arguments


def cmd_view(args: argparse.Namespace) -> int:
    try:
        import viser  # noqa: F401
    except ImportError:
        print(
            'view: the browser viewer needs the "view" extra: pip install "assistive-compiler[view]"', file=sys.stderr
        )
        return EXIT_FAILED
    from ..viewer import view

    def ready(url: str) -> None:
        print(f"viewing {args.spec} at {url}  (Ctrl-C to stop)", flush=True)

    from .run import trace_fits

    if not trace_fits("view", args):
        return EXIT_BAD_INPUT
    if (args.coop or args.trace) and args.replay:
        print("view: --coop and --trace play an episode; a --replay shows a recorded one", file=sys.stderr)
        return EXIT_BAD_INPUT
    human_policy = None
    if args.coop:
        from .run import human_policy_for

        human_policy = human_policy_for(args.policy or "scripted", args.human_policy)
    status = view(
        args.spec,
        args.robot,
        policy=args.policy,
        human_policy=human_policy,
        trace=args.trace,
        replay=args.replay,
        seed=args.seed,
        out=args.out,
        host=args.host,
        port=args.port,
        gui=args.gui,
        speed=args.speed,
        on_ready=ready,
    )
    if status == 0:
        print("viewer stopped", flush=True)
    return status


def add_commands(sub) -> None:
    p = sub.add_parser(
        "view", help="view an episode in the browser (3D scene, timeline, per-term reward plots), or --gui"
    )
    add_spec_arguments(p, policy=False)
    source = p.add_mutually_exclusive_group()
    from ..policies import POLICY_HELP

    source.add_argument(
        "--policy", help=f"play this policy headless first: {POLICY_HELP} (default scripted); the page can play more"
    )
    source.add_argument("--replay", metavar="FILE", help="show a recording (run --record DIR) of this spec and robot")
    p.add_argument("--host", default="127.0.0.1", help="address to serve on (default 127.0.0.1: this machine only)")
    p.add_argument("--port", type=int, default=8080, help="port (default 8080)")
    p.add_argument("--speed", type=float, default=1.0, help="playback speed, × real time (default 1)")
    p.add_argument(
        "--gui", action="store_true", help="pybullet's own GUI window instead of the browser (needs a display)"
    )
    add_artifact_argument(p)
    from .render import COOP_PICTURE_HELP
    from .run import TRACE_HELP, add_coop_arguments

    add_coop_arguments(p, COOP_PICTURE_HELP)

    p.add_argument("--trace", action="store_true", help=TRACE_HELP + ", for each episode it plays")
    p.set_defaults(func=cmd_view)
