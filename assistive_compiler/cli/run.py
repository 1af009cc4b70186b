"""The rollout commands: ``run`` (a policy over episodes: returns, success, largest terms) and
``demo`` (the README's main job: Feeding on Jaco, scripted, with a picture).

Both play episodes with :func:`assistive_compiler.episode.rollout`, the one episode loop that
training, evaluation and export use too.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

from ..episode import rollout
from .common import EXIT_BAD_INPUT, EXIT_OK, add_artifact_argument, add_library_argument, add_spec_arguments, make_env


def _yes_no(flag: bool) -> str:
    return "yes" if flag else "no"


def _default_human_policy(robot_policy: str) -> str:
    """Under --coop without --human-policy: a co-optimised pair plays its own person, else random."""
    from ..policies import POLICIES

    if robot_policy not in POLICIES:
        from ..policies.pretrained import load_trained

        if load_trained(robot_policy)[1].get("coop"):
            return robot_policy
    return "random"


def _check_human_policy(name: str) -> None:
    """A bad --human-policy is a usage error (the trained-policy loader says what is expected)."""
    from ..policies import HUMAN_POLICIES

    if name not in HUMAN_POLICIES:
        from ..policies.pretrained import load_trained

        load_trained(name)


def human_policy_for(robot_policy: str, human_policy: str | None) -> str:
    """The person's policy under --coop: ``--human-policy`` as given, else a co-optimised pair's own
    person, else random; checked (a bad one is a usage error)."""
    chosen = human_policy or _default_human_policy(robot_policy)
    _check_human_policy(chosen)
    return chosen


def add_coop_arguments(p: argparse.ArgumentParser, coop_help: str) -> None:
    """``--coop`` (helped by ``coop_help``) and ``--human-policy``: the person acts too."""
    from ..policies import HUMAN_POLICIES

    p.add_argument("--coop", action="store_true", help=coop_help)
    p.add_argument(
        "--human-policy",
        dest="human_policy",
        default=None,
        help=f"with --coop: {', '.join(HUMAN_POLICIES)} (zero: keep still by acting; hold: no human action, the static "
        "person), or a co-optimised pair (pretrained:<task>-<robot>-coop, a --coop run directory); default: the "
        "pair's own person when --policy is one, else random",
    )


TRACE_HELP = (
    "with --policy scripted: print each waypoint event (reached within tolerance_m, stalled, where the "
    "episode ended) with its goal (world, m), the distance left and what the robot and its tools touch"
)


def trace_fits(command: str, args: argparse.Namespace) -> bool:
    """Whether ``--trace`` (if given) can follow the policy: the scripted one, robot alone; says why not."""
    policy = getattr(args, "policy", None) or "scripted"
    if args.trace and (policy != "scripted" or args.coop):
        print(
            f"{command}: --trace follows the scripted policy's waypoints; it needs --policy scripted"
            f"{' without --coop' if args.coop else f' (not {policy})'}",
            file=sys.stderr,
        )
        return False
    return True


def cmd_run(args: argparse.Namespace) -> int:
    from ..policies import make_policy
    from .output import print_table, progress

    if args.coop and args.record:
        print("run: --record writes single-agent episodes; it cannot be combined with --coop", file=sys.stderr)
        return EXIT_BAD_INPUT
    if not trace_fits("run", args):
        return EXIT_BAD_INPUT
    if args.coop:  # both agents act (co-optimisation); the person by --human-policy
        from ..coop import parallel_env, rollout_coop

        coop_env = parallel_env(args.spec, args.robot, out_dir=args.out)
        args.human_policy = human_policy_for(args.policy, args.human_policy)
        env, label = coop_env.env, f"{args.policy}, human {args.human_policy}"

        def play(seed: int) -> dict:
            return rollout_coop(coop_env, args.policy, args.human_policy, seed)
    else:
        env, label = make_env(args.spec, args.robot, args.out), args.policy
        policy = make_policy(args.policy, env, seed=args.seed, trace=args.trace)
        player = env
        if args.record:  # every episode also written as DIR/episode-NNNN.npz (reads only: same episodes)
            from ..record import RecordEpisodes

            player = RecordEpisodes(env, args.record, policy=args.policy)

        def play(seed: int) -> dict:
            e = rollout(player, policy, seed)
            if args.trace:  # the scripted policy's waypoint events (reading only: the same episode)
                policy.end_episode()
                e["trace"] = list(policy.trace)
            return e

    weights = {t.name: t.weight for t in env.manifest.reward}
    episodes = []
    with progress(f"{env.manifest.label} {label}", args.episodes, enabled=not args.quiet) as tracker:
        for k in range(args.episodes):
            e = play(args.seed + k)
            episodes.append(e)
            tracker.done(
                f"episode {k} (seed {e['seed']}): return {e['return']:.1f}, success {_yes_no(e['success'])}; "
                f"{sum(x['success'] for x in episodes)}/{len(episodes)} successful so far"
            )
    env.close()
    rate = sum(e["success"] for e in episodes) / len(episodes)
    if args.json:
        print(
            json.dumps(
                {
                    "task": env.manifest.task,
                    "robot": env.manifest.robot_name,
                    "policy": args.policy,
                    **({"human_policy": args.human_policy} if args.coop else {}),
                    "term_weights": weights,
                    "episodes": episodes,
                    "success_rate": rate,
                    "mean_return": float(np.mean([e["return"] for e in episodes])),
                },
                indent=1,
            )
        )
        return EXIT_OK
    human = f"  human-policy={args.human_policy}" if args.coop else ""
    print(f"{env.manifest.label}  policy={args.policy}{human}  episodes={len(episodes)}  seed={args.seed}")
    if args.trace:
        for k, e in enumerate(episodes):
            print(f"trace of episode {k} (seed {e['seed']}):")
            for event in e["trace"]:
                print(f"  {event['line']}")
    rows = []
    for k, e in enumerate(episodes):
        top = sorted(e["terms"].items(), key=lambda kv: -abs(weights[kv[0]] * kv[1]))[:3]
        shown = ", ".join(f"{name} {weights[name] * value:+.1f}" for name, value in top)
        rows.append([str(k), str(e["seed"]), f"{e['return']:.1f}", _yes_no(e["success"]), shown])
    largest = "largest weighted terms (episode sums)"
    print_table(["ep", "seed", "return", "success", largest], rows, left=["success", largest])
    print(f"success rate {rate:.2f}   mean return {np.mean([e['return'] for e in episodes]):.1f}")
    return EXIT_OK


def cmd_demo(args: argparse.Namespace) -> int:
    from ..compile.compiler import compile_task
    from ..pictures import episode_frames, write_picture
    from ..policies import make_policy
    from ..runtime.env import AssistiveEnv

    spec = str(Path(args.spec))
    result = compile_task(spec, args.robot)
    m = result.manifest
    print(
        f"{'cache hit' if result.cache_hit else 'compiled'}: {m.task} for {m.robot_name} -> {result.out_dir}/ ({result.seconds:.2f} s)"
    )
    env = AssistiveEnv(result.out_dir, render_mode="rgb_array")
    policy = make_policy("scripted", env)
    outcomes = []
    for k in range(args.episodes):
        frames = None
        if k == 0:
            frames, _ = episode_frames(env, policy, args.seed, every=10)
            env.reset(seed=args.seed)
        e = rollout(env, policy, args.seed + k)
        outcomes.append(e)
        eaten = e["success_metric"]
        print(
            f"episode {k}: return {e['return']:7.1f}  success {'yes' if e['success'] else 'no '}  "
            f"{m.success.term} {eaten:g} (need {m.success.threshold:g})  mean force on person {e['mean_force_on_human_n']:.2f} N"
        )
        if frames is not None:
            write_picture(frames, Path(args.picture), fps=1)
    env.close()
    rate = sum(o["success"] for o in outcomes) / len(outcomes)
    print(f"scripted success {rate:.0%} over {len(outcomes)} episodes; picture: {args.picture}")
    return EXIT_OK


def add_commands(sub) -> None:

    p = sub.add_parser("run", help="roll out a policy and report returns, success and the largest terms")
    add_spec_arguments(p)
    p.add_argument("--episodes", type=int, default=5)
    add_artifact_argument(p)
    p.add_argument("--json", action="store_true", help="print JSON instead of a table")
    p.add_argument("--quiet", action="store_true", help="no progress on stderr")
    p.add_argument("--trace", action="store_true", help=TRACE_HELP + " (with --json: each episode's 'trace' list)")
    add_coop_arguments(p, "co-optimisation: the person acts too (by --human-policy), shared reward")
    p.add_argument(
        "--record",
        metavar="DIR",
        help="also write each episode to DIR/episode-NNNN.npz (poses, actions, per-term "
        "rewards, success; see assistive_compiler.record.format); view one with: view SPEC --replay FILE",
    )
    p.set_defaults(func=cmd_run)

    p = sub.add_parser("demo", help="the main job: compile Feeding for Jaco, run the scripted policy, write a picture")
    add_library_argument(p)
    p.add_argument("--spec", default="feeding", help="task spec (default: the shipped task feeding)")
    p.add_argument("--robot", default="jaco")
    p.add_argument("--episodes", type=int, default=3)
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--picture", default="feeding.png", help="picture of the first episode (.png strip or .gif)")
    p.set_defaults(func=cmd_demo)
