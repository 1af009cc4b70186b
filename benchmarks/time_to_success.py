"""Success on the 100 test seeds against wall-clock hours of training, one line per run.

Every checkpoint of each run is evaluated twice on the same seeds (1,000,000 onwards, which
training never uses): with the policy's mean action (``evaluate``'s default) and with actions
sampled from its Gaussian (``evaluate --stochastic``, the reference code's protocol). A
checkpoint's wall time is read from the run's ``curve.csv`` (the training session's own clock,
resumed sessions added up). Evaluations are cached in ``RUN/time_to_success/`` so the plot can be
drawn again, or extended as a run goes on, without evaluating a checkpoint twice.

    python benchmarks/time_to_success.py --title "Feeding × Jaco" \\
        --run "PPO (ppo_fast_envs)=runs/feeding-jaco-ppo-fast" --run "SAC (sac_laptop)=runs/feeding-jaco-sac" \\
        --target 0.68 --target-label "shipped feeding-jaco (SAC, 1.9 h)" --target-hours 1.9 \\
        --paper 0.88 --out docs/results/time_to_success/feeding-jaco.png

It prints a Markdown table (per run: env steps/s including learning, and the first checkpoint
whose success reaches ``--target`` under each protocol, with its wall time) and writes the plot
and a CSV of every point beside it.
"""

from __future__ import annotations

import argparse
import csv
import json
import sys
from pathlib import Path

PROTOCOLS = {"mean": False, "sampled": True}


def checkpoint_hours(run_dir: Path, steps: int) -> float:
    """Wall-clock hours of training at ``steps`` env steps, interpolated on the run's curve."""
    from assistive_compiler.training.bookkeeping.curves import read_curve

    rows = read_curve(run_dir / "curve.csv")
    if not rows:
        raise SystemExit(f"{run_dir}: no curve.csv rows")
    points = [(0, 0.0)] + [(int(r["steps"]), float(r["wall_s"])) for r in rows]
    for (s0, w0), (s1, w1) in zip(points, points[1:]):
        if s0 <= steps <= s1:
            return (w0 + (w1 - w0) * (steps - s0) / max(1, s1 - s0)) / 3600
    last_steps, last_wall = points[-1]
    return last_wall * steps / max(1, last_steps) / 3600


def evaluated(run_dir: Path, steps: int, protocol: str, episodes: int, seed: int) -> dict:
    """The cached (or new) evaluation of the checkpoint at ``steps`` under ``protocol``."""
    from assistive_compiler.training.trained.evaluate import evaluate

    cache = run_dir / "time_to_success" / f"step_{steps}-{protocol}-{episodes}x{seed}.json"
    if cache.is_file():
        return json.loads(cache.read_text())
    result = evaluate(run_dir, episodes=episodes, seed=seed, checkpoint_steps=steps, stochastic=PROTOCOLS[protocol])
    figures = {k: result[k] for k in ("trained_steps", "success_rate", "mean_return", "std_return")}
    cache.parent.mkdir(exist_ok=True)
    cache.write_text(json.dumps(figures, indent=1))
    return figures


def run_points(
    label: str, run_dir: Path, episodes: int, seed: int, every: int, rate: float | None = None
) -> list[dict]:
    """The run's evaluated checkpoints; ``rate`` (env steps/s): place them at steps / rate hours
    instead of the run's own clock (a run whose core was shared part of the time)."""
    from assistive_compiler.run_dir import RunDir

    run = RunDir(run_dir)
    steps_list = sorted(run.complete_checkpoints())
    cached = {int(f.name.split("-")[0][len("step_") :]) for f in (run_dir / "time_to_success").glob("step_*.json")}
    steps_list = [
        s for i, s in enumerate(steps_list) if s > 0 and (i % every == 0 or s == steps_list[-1] or s in cached)
    ]
    points = []
    for steps in steps_list:
        hours = steps / rate / 3600 if rate else checkpoint_hours(run_dir, steps)
        row = {"run": label, "steps": steps, "hours": round(hours, 4)}
        for protocol in PROTOCOLS:
            row[protocol] = evaluated(run_dir, steps, protocol, episodes, seed)["success_rate"]
        print(
            f"{label}: {steps:,} steps, {row['hours']:.2f} h: mean {row['mean']:.2f}, sampled {row['sampled']:.2f}",
            file=sys.stderr,
        )
        points.append(row)
    return points


def first_reaching(points: list[dict], protocol: str, target: float) -> dict | None:
    return next((p for p in points if p[protocol] >= target - 1e-9), None)


def plot(runs: dict[str, list[dict]], args: argparse.Namespace) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(8, 4.8))
    colors = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    for color, (label, points) in zip(colors, runs.items()):
        hours = [0.0] + [p["hours"] for p in points]
        ax.plot(hours, [0.0] + [p["mean"] for p in points], "-o", ms=3, color=color, label=f"{label}: mean action")
        ax.plot(hours, [0.0] + [p["sampled"] for p in points], "--", color=color, alpha=0.8, label=f"{label}: sampled")
    for i, item in enumerate(args.point or []):
        label, _, where = item.rpartition("=")
        hours, success = (float(v) for v in where.split(","))
        ax.plot(
            [hours], [success], marker="*", ms=12, ls="none", color=colors[(len(runs) + i) % len(colors)], label=label
        )
    if args.target is not None:
        ax.axhline(args.target, color="black", lw=1, ls=":", label=args.target_label or f"target {args.target:.0%}")
        if args.target_hours:
            ax.axvline(args.target_hours / 5, color="grey", lw=1, ls=":", label="1/5 of the shipped run's wall time")
    if args.paper is not None:
        ax.axhline(args.paper, color="tab:red", lw=1, ls="-.", label=f"paper, best robot ({args.paper:.0%})")
    ax.set_xlabel("wall-clock hours of training, one core")
    ax.set_ylabel("success on 100 test seeds")
    ax.set_ylim(-0.02, 1.02)
    ax.set_xlim(left=0)
    ax.set_title(args.title)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, loc="best")
    fig.tight_layout()
    args.out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(args.out, dpi=110)


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument(
        "--run",
        action="append",
        required=True,
        metavar="LABEL=RUN_DIR[@STEPS_PER_S]",
        help="a run; with @STEPS_PER_S its checkpoints stand at steps / that rate (say so in LABEL) instead of "
        "its own clock, for a run whose core was shared part of the time",
    )
    p.add_argument("--title", required=True)
    p.add_argument("--out", type=Path, required=True, help="the plot (.png); a .csv of the points goes beside it")
    p.add_argument("--episodes", type=int, default=100)
    p.add_argument("--seed", type=int, default=1_000_000)
    p.add_argument(
        "--every",
        type=int,
        default=1,
        help="evaluate every k-th checkpoint (and the newest; those evaluated before are drawn too)",
    )
    p.add_argument("--target", type=float, help="success to reach (e.g. the shipped policy's)")
    p.add_argument("--target-label")
    p.add_argument("--target-hours", type=float, help="the shipped run's wall time: a line at a fifth of it")
    p.add_argument("--paper", type=float, help="the paper's best-robot success")
    p.add_argument(
        "--point",
        action="append",
        metavar="LABEL=HOURS,SUCCESS",
        help="a single measured point, e.g. a shipped policy's success at its run's wall time",
    )
    p.add_argument(
        "--points",
        action="append",
        type=Path,
        default=[],
        metavar="CSV",
        help="points written by an earlier call (its .csv), drawn beside the runs: runs no longer on this machine",
    )
    args = p.parse_args(argv)
    runs: dict[str, list[dict]] = {}
    for earlier in args.points:
        with earlier.open() as f:
            for row in csv.DictReader(f):
                point = {"run": row["run"], "steps": int(row["steps"]), "hours": float(row["hours"])}
                point.update({protocol: float(row[protocol]) for protocol in PROTOCOLS})
                runs.setdefault(row["run"], []).append(point)
    for item in args.run:
        label, _, where = item.rpartition("=")
        path, _, rate = where.partition("@")
        runs[label] = run_points(label, Path(path), args.episodes, args.seed, args.every, float(rate) if rate else None)
    plot(runs, args)
    with args.out.with_suffix(".csv").open("w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=["run", "steps", "hours", "mean", "sampled"])
        w.writeheader()
        for points in runs.values():
            w.writerows(points)
    print("| run | checkpoints | best mean | best sampled | first ≥ target (mean) | first ≥ target (sampled) |")
    print("|---|---|---|---|---|---|")
    for label, points in runs.items():
        cells = []
        for protocol in PROTOCOLS:
            hit = first_reaching(points, protocol, args.target) if args.target is not None else None
            cells.append(f"{hit['hours'] * 60:.0f} min ({hit['steps']:,} steps)" if hit else "not reached")
        best = {k: max((q[k] for q in points), default=0.0) for k in PROTOCOLS}
        print(f"| {label} | {len(points)} | {best['mean']:.0%} | {best['sampled']:.0%} | {cells[0]} | {cells[1]} |")
    print(f"plot: {args.out}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
