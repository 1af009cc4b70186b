"""``compare``: one task compiled for several robots, side by side.

Per robot: where it stands (mounted, or the base search's goals reached and JLWKI), the compile
time and a policy's success rate and mean return (``--policy``: the scripted baseline by default,
``pretrained`` for each robot's shipped trained policy, or any one policy source for one robot). :func:`compare_robot` measures one
robot and is a plain function other commands may reuse.
"""

from __future__ import annotations

import argparse
import json
from collections.abc import Callable
from pathlib import Path

import numpy as np

from ..artifact import BaseSearch, Mounted
from ..episode import rollout
from .common import EXIT_OK, SPEC_HELP, add_artifact_argument, add_library_argument

COLUMNS = ("robot", "placement", "goals_reached", "jlwki", "compile_s", "success", "return")
#: ``--policy pretrained``: each robot plays its own shipped policy, ``pretrained:<task>-<robot>``.
EACH_PRETRAINED = "pretrained"
JLWKI_NOTE = (
    "jlwki: joint-limit-weighted kinematic isotropy (0 to 1 per goal; higher: farther from singularities "
    "and joint limits) summed over the goals the arm reaches from the searched base pose, mean over person "
    "variants; '-' for a robot mounted on furniture (no base search)."
)


def compare_robot(spec: str, robot: str, episodes: int, seed: int, out: Path | None, policy: str = "scripted") -> dict:
    """One robot's row: placement quality, compile time (s) and ``policy``'s results (``error``
    instead when the task does not compile for it; no results where the robot has no such policy:
    no ``scripted:`` section, or no shipped policy under ``pretrained``)."""
    from ..compile.compiler import compile_task
    from ..errors import SpecError
    from ..policies import make_policy
    from ..runtime.env import AssistiveEnv

    row: dict = {"robot": robot}
    try:
        result = compile_task(spec, robot, out, force=True)
    except SpecError as exc:
        row["error"] = "; ".join(p.message for p in exc.problems)
        return row
    m = result.manifest
    row["compile_s"] = round(result.seconds, 2)
    placements = list(m.robot.placement.values())
    mounts = [p for p in placements if isinstance(p, Mounted)]
    if len(mounts) == len(placements):
        row["placement"] = f"mounted on {mounts[0].mounted_on}"
    else:
        best = [p.base_poses[0] for p in placements if isinstance(p, BaseSearch)]
        row["placement"] = "base search"
        row["goals_reached"] = f"{min(b.goals_reached for b in best)}/{best[0].goals}"
        row["jlwki"] = round(float(np.mean([b.jlwki for b in best])), 3)
    if policy == EACH_PRETRAINED:
        from ..policies.pretrained import PREFIX, shipped_names

        name = f"{m.task}-{robot}"
        policy = f"{PREFIX}{name}" if name in shipped_names() else None
    elif policy == "scripted" and m.scripted is None:
        policy = None
    env = AssistiveEnv.from_compiled(result)
    if policy is not None:
        act = make_policy(policy, env, seed=seed)
        runs = [rollout(env, act, seed + k) for k in range(episodes)]
        row["success"] = sum(r["success"] for r in runs) / len(runs)
        row["return"] = round(float(np.mean([r["return"] for r in runs])), 1)
    env.close()
    return row


def compare(
    spec: str,
    robots: list[str],
    episodes: int,
    seed: int,
    out_root: str | None,
    on_row: Callable[[dict], None] | None = None,
    policy: str = "scripted",
) -> list[dict]:
    """Per robot: placement quality, compile time and ``policy``'s results (each row also handed
    to ``on_row`` as soon as it is measured)."""
    from ..errors import UsageError
    from ..policies import POLICIES

    if policy not in POLICIES + (EACH_PRETRAINED,) and len(robots) > 1:
        raise UsageError(
            f"compare --policy {policy}: a trained policy plays one robot; compare it with --robots <its robot>, "
            f"or use --policy {EACH_PRETRAINED} (each robot's shipped policy)"
        )
    rows = []
    for robot in robots:
        rows.append(compare_robot(spec, robot, episodes, seed, Path(out_root) / robot if out_root else None, policy))
        if on_row is not None:
            on_row(rows[-1])
    return rows


def _finished(row: dict) -> str:
    """The progress line of a robot's row."""
    if "error" in row:
        return f"{row['robot']}: failed to compile"
    success = f", success {row['success']:.2f}" if "success" in row else ""
    return f"{row['robot']}: compiled in {row['compile_s']} s ({row['placement']}){success}"


def print_comparison(rows: list[dict]) -> None:
    """The rows as a table (success rates to two decimals), robots that failed to compile below it."""
    from .output import cell, print_table

    digits = {"success": 2}
    table = [
        [cell(row.get(c), digits.get(c)) for c in COLUMNS]
        if "error" not in row
        else [row["robot"], "failed to compile"] + ["-"] * (len(COLUMNS) - 2)
        for row in rows
    ]
    print_table(COLUMNS, table, left=("robot", "placement"), caption=JLWKI_NOTE)
    for row in rows:
        if "error" in row:
            print(f"{row['robot']}: failed to compile: {row['error']}")


def cmd_compare(args: argparse.Namespace) -> int:
    from .output import progress

    robots = [r.strip() for r in args.robots.split(",") if r.strip()]
    with progress(f"compare {Path(args.spec).name}", len(robots)) as tracker:
        rows = compare(
            args.spec,
            robots,
            args.episodes,
            args.seed,
            args.out,
            on_row=lambda row: tracker.done(_finished(row)),
            policy=args.policy,
        )
    if args.json:
        print(json.dumps(rows, indent=1))
        return EXIT_OK
    print(f"{args.spec}: {args.episodes} episodes of the {args.policy} policy per robot from seed {args.seed}")
    print_comparison(rows)
    return EXIT_OK


def add_commands(sub) -> None:
    p = sub.add_parser("compare", help="compile a task for several robots and compare placement and scripted results")
    add_library_argument(p)
    p.add_argument("spec", help=SPEC_HELP)
    p.add_argument("--robots", required=True, help="comma-separated robot names, e.g. pr2,jaco,baxter,sawyer,panda")
    p.add_argument("--episodes", type=int, default=10, help="episodes per robot")
    p.add_argument(
        "--policy",
        default="scripted",
        help="scripted (default), random, zero, pretrained (each robot's shipped policy), or for one robot "
        "pretrained:<task>-<robot> or a training run directory",
    )
    p.add_argument("--seed", type=int, default=0)
    add_artifact_argument(p, "artifact root")
    p.add_argument("--json", action="store_true")
    p.set_defaults(func=cmd_compare)
