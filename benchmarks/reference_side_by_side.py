"""Measure the reference implementation beside ours, with the machine probe, and print the figures
``bench`` stores (``assistive_compiler/cli/bench.py``: ``REFERENCE_STEPS_PER_S`` and
``REFERENCE_PROBE_STEPS_PER_S``).

Usage::

    python benchmarks/reference_side_by_side.py --harness DIR --reference DIR --rounds 3 --out lines.jsonl
    python benchmarks/reference_side_by_side.py --summarize lines.jsonl

``--harness`` is the reference harness's folder (its ``measure.py`` and ``agshim.py``);
``--reference`` the folder holding the reference's ``assistive_gym/`` and the virtual environment
``venv/`` it runs in (the harness's README says how to make both). Each round runs every env
once on each side, interleaved, each run in a fresh process pinned to one core (``--core``), and
the machine probe after each pair, on the same core. Keep the other core idle: work there slows
the measured core too.

The output lines are the harness's own (``--reference-json`` of ``bench`` reads them), plus one
line per probe run. The summary gives, per env, the reference on its own pybullet fork (the
harness's ``steps_per_s / (1 - gravity_shim_share)``), ours, and their ratio (medians over the
rounds), then the lines to store in ``bench``. An env the reference cannot load (its Baxter and
Sawyer meshes are missing from some copies of its source) is reported and left out.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
from pathlib import Path

from assistive_compiler.cli.bench import reference_on_fork
from assistive_compiler.gym_ids import shipped_tasks

RIGID_TASKS = ("feeding", "scratch_itch", "drinking", "bed_bathing", "arm_manipulation")
"""The reference's tasks that run on stock pybullet (its Dressing needs its fork)."""


def env_names() -> dict[str, tuple[str, str]]:
    """Harness env name (a Gymnasium id's, ``FeedingJaco``) -> (task, robot), for the rigid tasks."""
    return {
        env_id.rpartition("/")[2].removesuffix("-v1"): (task.name, robot)
        for task in shipped_tasks()
        if task.name in RIGID_TASKS
        for robot, env_id in zip(task.robots, task.ids)
    }


PROBE = (
    "import json; from assistive_compiler.machine_probe import PROBE_VERSION, probe_steps_per_s; "
    "print(json.dumps({'side': 'probe', 'probe_version': PROBE_VERSION, 'steps_per_s': round(probe_steps_per_s(), 1)}))"
)


def _last_json(stdout: str) -> dict | None:
    for line in reversed(stdout.splitlines()):
        start = line.find("{")
        if start >= 0:
            try:
                return json.loads(line[start:])
            except json.JSONDecodeError:
                return None
    return None


def _run(cmd: list[str], cwd: Path, env_path: str | None = None) -> tuple[dict | None, str]:
    env = os.environ | ({"PYTHONPATH": env_path} if env_path else {})
    done = subprocess.run(cmd, cwd=cwd, env=env, capture_output=True, text=True, timeout=1800)
    row = _last_json(done.stdout) if done.returncode == 0 else None
    return row, (done.stderr.strip().splitlines() or ["(no output)"])[-1]


def measure(harness: Path, reference: Path, envs: list[str], rounds: int, core: int) -> list[dict]:
    """The interleaved rounds; every line as measured (failed runs are printed and skipped)."""
    repo = Path(__file__).resolve().parents[1]
    pin = ["taskset", "-c", str(core)]
    lines: list[dict] = []
    for r in range(rounds):
        for name in envs:
            runs = {
                "ag": (
                    pin + [str(reference / "venv" / "bin" / "python"), str(harness / "measure.py"), "ag", name],
                    reference,
                    f"{harness}:{reference}",
                ),
                "ours": (pin + [sys.executable, str(harness / "measure.py"), "ours", name], repo, None),
                "probe": (pin + [sys.executable, "-c", PROBE], repo, None),
            }
            for side, (cmd, cwd, path) in runs.items():
                row, last_error = _run(cmd, cwd, path)
                if row is None:
                    print(f"round {r + 1}, {name}, {side}: failed ({last_error})", file=sys.stderr)
                    continue
                lines.append(row)
                print(json.dumps(row), flush=True)
    return lines


def summarize(lines: list[dict]) -> dict:
    """Per env: the reference on its fork, ours, and their ratio (medians over the lines); the
    probe's median and version; envs measured on one side only are left out of the ratios."""
    ref: dict[str, list[float]] = {}
    ours: dict[str, list[float]] = {}
    probes: list[float] = []
    versions = set()
    for row in lines:
        if row.get("side") == "probe":
            probes.append(float(row["steps_per_s"]))
            versions.add(row.get("probe_version"))
        elif row.get("side") == "ag":
            ref.setdefault(row["env"], []).append(reference_on_fork(row))
        elif row.get("side") == "ours":
            ours.setdefault(row["env"], []).append(float(row["steps_per_s"]))
    envs = {}
    for name in ref:
        if name in ours:
            r, o = statistics.median(ref[name]), statistics.median(ours[name])
            envs[name] = {
                "reference": round(r, 1),
                "ours": round(o, 1),
                "ratio": round(o / r, 2),
                "rounds": len(ref[name]),
            }
    return {
        "envs": envs,
        "probe_steps_per_s": round(statistics.median(probes), 1) if probes else None,
        "probe_runs": len(probes),
        "probe_versions": sorted(v for v in versions if v is not None),
    }


def task_robot(env_name: str) -> tuple[str, str] | None:
    """(task, robot) of a harness env name, e.g. ``ArmManipulationPR2`` -> ("arm_manipulation", "pr2")."""
    return env_names().get(env_name)


def stored_lines(summary: dict) -> list[str]:
    """The ``REFERENCE_STEPS_PER_S`` entries and ``REFERENCE_PROBE_STEPS_PER_S`` to paste into bench."""
    out = []
    for name, fig in summary["envs"].items():
        pair = task_robot(name)
        if pair is not None:
            out.append(f'    ("{pair[0]}", "{pair[1]}"): {fig["reference"]},')
    if summary["probe_steps_per_s"] is not None and len(summary["probe_versions"]) == 1:
        out.append(f"REFERENCE_PROBE_STEPS_PER_S = ({summary['probe_steps_per_s']}, {summary['probe_versions'][0]})")
    return out


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--harness", type=Path, help="the reference harness's folder (measure.py, agshim.py)")
    parser.add_argument("--reference", type=Path, help="the folder with the reference's assistive_gym/ and venv/")
    parser.add_argument(
        "--envs",
        default=",".join(name for robot in ("jaco", "pr2") for name, pair in env_names().items() if pair[1] == robot),
        help="harness env names, comma-separated (default: the five rigid tasks with Jaco and PR2)",
    )
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--core", type=int, default=1, help="the core every run is pinned to")
    parser.add_argument("--out", type=Path, help="write the measured lines here (JSON lines)")
    parser.add_argument(
        "--summarize", type=Path, metavar="LINES", help="summarize lines measured before; measure nothing"
    )
    args = parser.parse_args()
    if args.summarize:
        lines = [json.loads(line) for line in args.summarize.read_text().splitlines() if line.strip()]
    else:
        problems = []
        if args.harness is None or not (args.harness / "measure.py").is_file():
            problems.append(f"--harness {args.harness}: no measure.py there (the reference harness's folder)")
        if args.reference is None or not (args.reference / "venv" / "bin" / "python").is_file():
            problems.append(f"--reference {args.reference}: no venv/bin/python there (see the harness's README)")
        if problems:
            print("\n".join(problems), file=sys.stderr)
            return 2
        lines = measure(args.harness, args.reference, args.envs.split(","), args.rounds, args.core)
        if args.out:
            args.out.write_text("".join(json.dumps(row) + "\n" for row in lines))
    summary = summarize(lines)
    print("\n| env | reference (fork) | ours | ratio | rounds |\n|---|---|---|---|---|")
    for name, fig in summary["envs"].items():
        print(f"| {name} | {fig['reference']} | {fig['ours']} | {fig['ratio']}× | {fig['rounds']} |")
    print(f"\nmachine probe: {summary['probe_steps_per_s']} probe steps/s, median of {summary['probe_runs']} runs")
    print("\nto store in assistive_compiler/cli/bench.py:\n" + "\n".join(stored_lines(summary)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
