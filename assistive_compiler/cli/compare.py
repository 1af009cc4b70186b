"""``compare``: one task compiled for several robots, side by side.

Per robot: where it stands (mounted, or the base search's goals reached and JLWKI), the compile
time and the scripted policy's success rate and mean return. :func:`compare_robot` measures one
robot and is a plain function other commands may reuse.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Callable

import numpy as np

from .common import EXIT_OK, add_library_argument
from .run import rollout

COLUMNS = ("robot", "placement", "goals_reached", "jlwki", "compile_s", "scripted_success", "scripted_return")
JLWKI_NOTE = ("jlwki: joint-limit-weighted kinematic isotropy (0 to 1 per goal; higher: farther from singularities "
              "and joint limits) summed over the goals the arm reaches from the searched base pose, mean over person "
              "variants; '-' for a robot mounted on furniture (no base search).")


def compare_robot(spec: str, robot: str, episodes: int, seed: int, out: Path | None) -> dict:
    """One robot's row: placement quality, compile time (s) and the scripted policy's results
    (``error`` instead when the task does not compile for it)."""
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
    if all("mounted_on" in p for p in placements):
        row["placement"] = f"mounted on {placements[0]['mounted_on']}"
    else:
        best = [p["base_poses"][0] for p in placements]
        row["placement"] = "base search"
        row["goals_reached"] = f"{min(b['goals_reached'] for b in best)}/{best[0]['goals']}"
        row["jlwki"] = round(float(np.mean([b["jlwki"] for b in best])), 3)
    env = AssistiveEnv.from_compiled(result)
    if m.scripted is not None:
        policy = make_policy("scripted", env)
        runs = [rollout(env, policy, seed + k) for k in range(episodes)]
        row["scripted_success"] = sum(r["success"] for r in runs) / len(runs)
        row["scripted_return"] = round(float(np.mean([r["return"] for r in runs])), 1)
    env.close()
    return row


def compare(spec: str, robots: list[str], episodes: int, seed: int, out_root: str | None,
            on_row: Callable[[dict], None] | None = None) -> list[dict]:
    """Per robot: placement quality, compile time and the scripted policy's results (each row
    also handed to ``on_row`` as soon as it is measured)."""
    rows = []
    for robot in robots:
        rows.append(compare_robot(spec, robot, episodes, seed, Path(out_root) / robot if out_root else None))
        if on_row is not None:
            on_row(rows[-1])
    return rows


def _finished(row: dict) -> str:
    """The progress line of a robot's row."""
    if "error" in row:
        return f"{row['robot']}: failed to compile"
    success = f", scripted success {row['scripted_success']:.2f}" if "scripted_success" in row else ""
    return f"{row['robot']}: compiled in {row['compile_s']} s ({row['placement']}){success}"


def print_comparison(rows: list[dict]) -> None:
    """The rows as a table (success rates to two decimals), robots that failed to compile below it."""
    from .output import cell, print_table

    digits = {"scripted_success": 2}
    table = [[cell(row.get(c), digits.get(c)) for c in COLUMNS] if "error" not in row
             else [row["robot"], "failed to compile"] + ["-"] * (len(COLUMNS) - 2) for row in rows]
    print_table(COLUMNS, table, left=("robot", "placement"), caption=JLWKI_NOTE)
    for row in rows:
        if "error" in row:
            print(f"{row['robot']}: failed to compile: {row['error']}")


def cmd_compare(args: argparse.Namespace) -> int:
    from .output import progress

    robots = [r.strip() for r in args.robots.split(",") if r.strip()]
    with progress(f"compare {Path(args.spec).name}", len(robots)) as tracker:
        rows = compare(args.spec, robots, args.episodes, args.seed, args.out, on_row=lambda row: tracker.done(_finished(row)))
    if args.json:
        print(json.dumps(rows, indent=1))
        return EXIT_OK
    print(f"{args.spec}: {args.episodes} scripted episodes per robot from seed {args.seed}")
    print_comparison(rows)
    return EXIT_OK


def add_commands(sub) -> None:
    p = sub.add_parser("compare", help="compile a task for several robots and compare placement and scripted results")
    add_library_argument(p)
    p.add_argument("spec", help="task spec file")
    p.add_argument("--robots", required=True, help="comma-separated robot names, e.g. pr2,jaco,baxter,sawyer,panda")
    p.add_argument("--episodes", type=int, default=10, help="scripted episodes per robot")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--out", help="artifact root (default generated/<task>-<robot>)")
    p.add_argument("--json", action="store_true")
    p.set_defaults(func=cmd_compare)
